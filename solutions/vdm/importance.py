"""Tasks 4 and 5: where does the grid need more samples?

Task 4 scores every vertex by the sharpest crease it touches. For an interior edge ``e`` with face
normals ``n1``, ``n2``::

    s(e) = 0.5 - 0.5 * n1 . n2 = sin^2(theta / 2)            (theta = dihedral angle)

is 0 on a flat edge, 0.5 on a 90 degree crease and 1 on a fold. The vertex importance is
``I(v) = max_{e interior, v in e} s(e)`` (0 for vertices with no interior edge).

Task 5 moves these scores to the parameter domain: an importance *field* sampled on a
``res x res`` pixel grid over ``[0, 1]^2`` (pixel ``(i, j)`` centred at
``((j + 0.5) / res, (i + 0.5) / res)``, row i = v, column j = u). Each vertex spreads its
importance with a Gaussian of width ``sigma`` (in uv units) and the field keeps the strongest
contribution, plus a constant background::

    field(x) = background + max_v I(v) * exp(-|x - uv_v|^2 / (2 sigma^2))

The maximum (instead of a sum) makes the field independent of how finely the mesh is tessellated;
the background sets how many samples flat regions keep (large background -> nearly uniform grid).

The background may vary: with ``density`` = the parameterization's *area stretch* (3-D area per uv
area, :func:`area_density`), regions without features get samples in proportion to their surface
area rather than their uv area — a steep flank that the parameterization squeezes into a thin uv
strip gets its fair share.
"""

from __future__ import annotations

import numpy as np

from geomlib import topology
from geomlib.geometry import face_areas, face_normals
from geomlib.validate import MeshError, as_array, check_float, check_int, check_mesh

from .sampling import locate_uv

__all__ = ["edge_sharpness", "vertex_importance", "area_density", "importance_field"]


def edge_sharpness(V, F) -> tuple[np.ndarray, np.ndarray]:
    """Interior edges and their sharpness ``s(e) = 0.5 - 0.5 n1 . n2`` (given helper).

    Returns
    -------
    E : (e, 2) int64
        Interior edges (smaller index first).
    s : (e,) float64
        Sharpness in ``[0, 1]``.
    """
    V, F = check_mesh(V, F, where="edge_sharpness")
    E, EF = topology.edge_faces(F)
    interior = (EF >= 0).all(axis=1)
    N = face_normals(V, F)
    s = 0.5 - 0.5 * np.einsum("ij,ij->i", N[EF[interior, 0]], N[EF[interior, 1]])
    return E[interior], np.clip(s, 0.0, 1.0)


def vertex_importance(V, F) -> np.ndarray:
    """Per-vertex importance ``I(v) = max over interior edges e at v of 0.5 - 0.5 n1(e) . n2(e)``.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
        Consistently oriented triangles.

    Returns
    -------
    I : (n,) float64
        Values in ``[0, 1]``: 0 where every incident edge is flat (and at vertices without interior
        edges), 0.5 at a vertex on a 90 degree crease, 1 at a 180 degree fold.

    Examples
    --------
    Two triangles folded by 90 degrees along edge (0, 1):

    >>> V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]
    >>> F = [[0, 1, 2], [1, 0, 3]]
    >>> vertex_importance(V, F).round(3).tolist()
    [0.5, 0.5, 0.0, 0.0]
    """
    where = "vertex_importance"
    V, F = check_mesh(V, F, where=where)
    # BEGIN SOLUTION: Task 4 (importance): I(v) = max over interior edges at v of 0.5 - 0.5 n1.n2
    E, s = edge_sharpness(V, F)
    imp = np.zeros(len(V))
    np.maximum.at(imp, E[:, 0], s)
    np.maximum.at(imp, E[:, 1], s)
    return imp
    # END SOLUTION


def area_density(V, F, UV, res: int) -> np.ndarray:
    """Area stretch of the parameterization on a ``res x res`` pixel grid (given helper).

    ``density = (A_3d(f) / sum A_3d) / (A_uv(f) / sum A_uv)`` of the triangle ``f`` under each pixel
    centre, so a uniform-area map gives 1 everywhere and the mean over the square is about 1.
    Values are clipped to ``[0.01, 100]`` (degenerate uv triangles).

    Returns
    -------
    (res, res) float64
    """
    where = "area_density"
    V, F = check_mesh(V, F, where=where)
    UV = as_array(UV, "UV", shape=(len(V), 2), where=where)
    res = check_int(res, "res", minimum=2, maximum=4096, where=where)
    a3 = face_areas(V, F)
    T = UV[F]
    a2 = 0.5 * np.abs(
        (T[:, 1, 0] - T[:, 0, 0]) * (T[:, 2, 1] - T[:, 0, 1]) - (T[:, 1, 1] - T[:, 0, 1]) * (T[:, 2, 0] - T[:, 0, 0])
    )
    ratio = (a3 / a3.sum()) / np.maximum(a2 / a2.sum(), 1e-300)
    c = (np.arange(res) + 0.5) / res
    v, u = np.meshgrid(c, c, indexing="ij")
    face, _ = locate_uv(UV, F, np.stack([u.ravel(), v.ravel()], axis=1))
    return np.clip(ratio[face], 0.01, 100.0).reshape(res, res)


def importance_field(
    UV, I, res: int, background: float = 0.3, sigma: float | None = None, *, density=None
) -> np.ndarray:
    """Splat vertex importances into a ``res x res`` field over the unit square.

    ``field[i, j] = background * density[i, j] + max_v I[v] * exp(-|x_ij - UV[v]|^2 / (2 sigma^2))``
    with pixel centres ``x_ij = ((j + 0.5) / res, (i + 0.5) / res)``.

    Parameters
    ----------
    UV : (n, 2) float64
        Vertex positions in the parameter domain.
    I : (n,) float64
        Non-negative vertex importances (e.g. :func:`vertex_importance`).
    res : int
        Field resolution (pixels per side, >= 2).
    background : float
        Constant added everywhere (> 0, so the density never vanishes and every region keeps some
        samples). Small -> samples crowd onto features; large -> nearly uniform.
    sigma : float, optional
        Kernel width in uv units (> 0). Default ``1.5 / res``.
    density : (res, res) float64, optional
        Positive weights of the background (default 1 everywhere), e.g. :func:`area_density`.

    Returns
    -------
    field : (res, res) float64
        Strictly positive; rows are v (row 0 at v = 0), columns u.

    Notes
    -----
    The kernel is cut off at ``|x - uv_v| > 3 sigma`` (exactly zero there; its value at the cut is
    1.1% of the peak), so only pixels within ``3 sigma`` of a vertex with ``I > 0`` get a
    contribution.
    """
    where = "importance_field"
    UV = as_array(UV, "UV", shape=(None, 2), where=where)
    I = as_array(I, "I", shape=(len(UV),), where=where)  # noqa: E741
    res = check_int(res, "res", minimum=2, maximum=4096, where=where)
    background = check_float(background, "background", minimum=1e-9, where=where)
    sigma = 1.5 / res if sigma is None else check_float(sigma, "sigma", minimum=1e-9, maximum=10.0, where=where)
    if density is None:
        density = np.ones((res, res))
    else:
        density = as_array(density, "density", shape=(res, res), where=where)
        if (density <= 0).any():
            raise MeshError(f"{where}: density must be > 0 everywhere (got min {density.min():.6g})")
    if (I < 0).any():
        v = int(np.flatnonzero(I < 0)[0])
        raise MeshError(f"{where}: I[{v}] = {I[v]:.6g} is negative; importances must be >= 0")
    # BEGIN SOLUTION: Task 5 (field): field = background * density + max_v I_v exp(-|x - uv_v|^2 / (2 sigma^2))
    field = np.zeros(res * res)
    act = np.flatnonzero(I > 0)
    if len(act):
        r = int(np.ceil(3 * sigma * res)) + 1
        off = np.arange(-r, r + 1)
        # Pixel nearest to each vertex, then a (2r+1)^2 stamp around it, all vertices at once.
        cj = np.floor(UV[act, 0] * res).astype(np.int64)
        ci = np.floor(UV[act, 1] * res).astype(np.int64)
        oi, oj = np.meshgrid(off, off, indexing="ij")
        chunk = max(1, 4_000_000 // oi.size)  # bound the temporary arrays
        for s in range(0, len(act), chunk):  # chunks of vertices, not single vertices
            a = act[s : s + chunk]
            pi = ci[s : s + chunk, None] + oi.ravel()[None, :]
            pj = cj[s : s + chunk, None] + oj.ravel()[None, :]
            inside = (pi >= 0) & (pi < res) & (pj >= 0) & (pj < res)
            du = (pj + 0.5) / res - UV[a, 0:1]
            dv = (pi + 0.5) / res - UV[a, 1:2]
            d2 = du**2 + dv**2
            inside &= d2 <= (3 * sigma) ** 2
            val = I[a, None] * np.exp(-d2 / (2 * sigma**2))
            np.maximum.at(field, (pi * res + pj)[inside], val[inside])
    return background * density + field.reshape(res, res)
    # END SOLUTION
