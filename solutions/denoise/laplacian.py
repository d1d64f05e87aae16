"""Tasks 1 and 2: Laplacian offsets and their component along the normal.

The Laplacian offset of a vertex is how far it sticks out of its neighbourhood,
``delta_i = p_i - (weighted mean of its neighbours)``. Noise makes it large and random; on a
smooth clean surface it is small and points along the normal (it measures curvature). Denoising
moves each vertex back along its (clean) normal by part of ``<delta_i, n_i>``.
"""

from __future__ import annotations

import igl
import numpy as np
import scipy.sparse as sp

from geomlib.validate import MeshError, check_mesh

from .inputs import as_offsets, as_unit_normals, check_weights, check_weld
from .seams import weld_seams

__all__ = ["laplacian_offsets", "normal_offsets"]


def _check_cotan_faces(V: np.ndarray, F: np.ndarray, where: str) -> None:
    """Cotangent weights divide by triangle areas: zero-area triangles are rejected."""
    if len(F) == 0:
        return
    area2 = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) or 1.0
    bad = area2 <= 1e-14 * diag**2
    if bad.any():
        f = int(np.flatnonzero(bad)[0])
        raise MeshError(
            f"{where}: face {f} {tuple(int(i) for i in F[f])} has zero area, so its cotangent weights are undefined "
            f"({int(bad.sum())} such faces); remove degenerate triangles or use weights='uniform'"
        )


def laplacian_offsets(V, F, weights: str = "uniform", *, weld: bool = True) -> np.ndarray:
    """Laplacian offset of every vertex: its position minus the weighted mean of its neighbours.

    ``delta_i = p_i - sum_j w_ij p_j / sum_j w_ij`` over the edge neighbours ``j`` of ``i``:

    * ``weights="uniform"``: ``w_ij = 1``, so ``delta_i = p_i - (1 / |N(i)|) sum_{j in N(i)} p_j``.
    * ``weights="cotan"``: ``w_ij = (cot alpha_ij + cot beta_ij) / 2``, the angles opposite the
      edge ``ij`` in its two triangles (one on a boundary edge). These are the off-diagonal
      entries of libigl's ``igl.cotmatrix(V, F)`` ``L``, whose diagonal is ``L_ii = -sum_j w_ij``,
      so ``delta = -(L V) / (-L_ii)`` row by row. Dividing by the weight sum keeps ``delta`` a
      displacement in units of ``V`` (``M^-1 L V`` with the mass matrix would be the mean-curvature
      normal, in units of 1/length). Cotangent weights depend only on the surface's shape, not on
      how it is triangulated: on a flat mesh every interior ``delta_i`` is exactly 0, and on a
      curved one ``delta_i`` points along the normal.

    A vertex without neighbours (used by no face) gets ``delta_i = 0``.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions.
    F : (m, 3) int
        Triangles.
    weights : {"uniform", "cotan"}
    weld : bool
        Treat vertices at the same position (the copies a UV seam creates) as one vertex, so a
        seam vertex sees its neighbours on both sides of the seam (:func:`weld_seams`). All copies
        get the same offset. Needs Task 6; pass ``weld=False`` before you have done it (meshes
        without seams give the same result either way).

    Returns
    -------
    delta : (n, 3) float64

    Raises
    ------
    MeshError
        Invalid mesh, unknown ``weights``, zero-area triangles with ``"cotan"``.

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0, 0, 1.0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])  # a pyramid's apex and base
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    >>> laplacian_offsets(V, F)[0]                 # apex minus the mean of the 4 base corners
    array([0., 0., 1.])
    """
    where = "laplacian_offsets"
    V, F = check_mesh(V, F, where=where)
    check_weights(weights, where)
    group = None
    if check_weld(weld, where):
        V, F, group = weld_seams(V, F)  # compute on the welded mesh, copy back to every seam copy
    n = len(V)
    if weights == "uniform":
        # BEGIN PROMPT
        # delta = ...  # (n, 3): p_i minus the mean of its neighbours
        # END PROMPT
        # BEGIN SOLUTION: Task 1a (uniform offsets): delta_i = p_i - (1/|N(i)|) sum_{j in N(i)} p_j, with a sparse 0/1 adjacency matrix A
        # Directed edges of every triangle, both ways; an interior edge appears twice, so set entries to 1.
        i = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
        j = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
        A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
        A.data[:] = 1.0
        degree = np.diff(A.indptr).astype(np.float64)
        mean = (A @ V) / np.maximum(degree, 1.0)[:, None]
        delta = np.where(degree[:, None] > 0, V - mean, 0.0)
        # END SOLUTION
    else:
        _check_cotan_faces(V, F, where)
        # BEGIN PROMPT
        # delta = ...  # (n, 3): p_i minus the cotangent-weighted mean of its neighbours
        # END PROMPT
        # BEGIN SOLUTION: Task 1b (cotan offsets): L = igl.cotmatrix(V, F); delta = -(L V)_i / (-L_ii), and 0 where L_ii = 0
        L = igl.cotmatrix(V, F)
        wsum = -L.diagonal()
        LV = np.asarray(L @ V)
        delta = np.where(wsum[:, None] > 0, -LV / np.where(wsum > 0, wsum, 1.0)[:, None], 0.0)
        # END SOLUTION
    return delta if group is None else delta[group]


def normal_offsets(delta, N) -> np.ndarray:
    """Signed length of each Laplacian offset along the vertex normal: ``s_i = <delta_i, n_i>``.

    ``s_i n_i`` is the part of ``delta_i`` that leaves the surface (noise plus curvature);
    the rest, ``delta_i - s_i n_i``, slides along the surface and is ignored by the denoiser.

    Parameters
    ----------
    delta : (n, 3) float
        Laplacian offsets (:func:`laplacian_offsets`).
    N : (n, 3) float
        Vertex normals (normalised here; a zero row is an error).

    Returns
    -------
    s : (n,) float64
        Positive where the vertex sticks out along ``n_i``, negative where it sinks in.

    Examples
    --------
    >>> normal_offsets([[0.5, 0.0, 2.0]], [[0.0, 0.0, 4.0]])   # N is normalised first
    array([2.])
    """
    where = "normal_offsets"
    delta = as_offsets(delta, where)
    N = as_unit_normals(N, len(delta), where, ref="delta")
    # BEGIN PROMPT
    # s = ...  # (n,)
    # END PROMPT
    # BEGIN SOLUTION: Task 2 (projection on normals): s_i = <delta_i, n_i> (a row-wise dot product)
    s = np.einsum("ij,ij->i", delta, N)
    # END SOLUTION
    return s
