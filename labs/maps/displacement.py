"""Task 5: scalar displacement mapping, P' = P + lam (bias + scale h(uv)) n, with welded UV seams."""

from __future__ import annotations

import numpy as np

from geomlib.geometry import vertex_normals
from geomlib.textures import WRAP_MODES, sample_bilinear, weld_by_position
from geomlib.validate import MeshError, check_choice, check_float, check_mesh

from .inputs import as_height_map, as_unit_vectors, check_uv, normalize_rows

__all__ = ["displace", "welded_vertex_normals", "group_mean"]


def group_mean(values: np.ndarray, group: np.ndarray, n_groups: int) -> np.ndarray:
    """Given: the mean of ``values`` (``(n,)`` or ``(n, k)``) over each group, ``(n_groups,)`` or ``(n_groups, k)``."""
    count = np.bincount(group, minlength=n_groups).astype(np.float64)
    count[count == 0] = 1.0
    if values.ndim == 1:
        return np.bincount(group, weights=values, minlength=n_groups) / count
    cols = [np.bincount(group, weights=values[:, k], minlength=n_groups) for k in range(values.shape[1])]
    return np.stack(cols, axis=1) / count[:, None]


def welded_vertex_normals(V, F, group: np.ndarray | None = None) -> np.ndarray:
    """Given: area-weighted vertex normals that ignore UV seams.

    Vertices in the same ``group`` (default: :func:`geomlib.textures.weld_by_position`, i.e. the
    copies a seam creates) are treated as one vertex, so both sides of a seam get the same normal
    and the surface shades smoothly across it. Vertices without faces get ``(0, 0, 1)``.

    Returns
    -------
    (n, 3) float64 unit normals.
    """
    V, F = check_mesh(V, F, where="welded_vertex_normals")
    if group is None:
        group, k = weld_by_position(V)
    else:
        group = np.asarray(group, np.int64)
        k = int(group.max()) + 1 if len(group) else 0
    first = np.full(k, -1, np.int64)
    first[group[::-1]] = np.arange(len(V))[::-1]  # first vertex of every group
    Vw = V[np.maximum(first, 0)]
    Nw = vertex_normals(Vw, group[F])
    return normalize_rows(Nw[group], fallback=(0.0, 0.0, 1.0))


def checked_displace_inputs(V, F, UV, N, height, lam, bias, scale, weld_seams, wrap, where: str):
    """Given: the arguments of displacement mapping, checked once for both routes (NumPy
    :func:`displace` and GLSL :func:`~solutions.maps.glsl.glsl_displace`).

    Returns
    -------
    V, F, UV, n, Hm, lam, bias, scale, group, k
        ``n`` the unit displacement directions ((n, 3), welded normals when ``N`` is None),
        ``Hm`` the map as floats in [0, 1], ``group``/``k`` the seam groups
        (:func:`geomlib.textures.weld_by_position`; every vertex its own group without ``weld_seams``).
    """
    V, F = check_mesh(V, F, where=where)
    check_choice(wrap, "wrap", WRAP_MODES, where=where)
    UV = check_uv(UV, len(V), where, in_range=(wrap == "clamp"))
    Hm = as_height_map(height, where, name="height", unit_range=True, what="displacement map")
    lam = check_float(lam, "lam", where=where)
    bias = check_float(bias, "bias", where=where)
    scale = check_float(scale, "scale", where=where)
    if not isinstance(weld_seams, bool | np.bool_):
        raise MeshError(f"{where}: weld_seams must be True or False, got {weld_seams!r}")
    group, k = weld_by_position(V) if weld_seams else (np.arange(len(V)), len(V))
    n = welded_vertex_normals(V, F, group) if N is None else as_unit_vectors(N, len(V), where)
    return V, F, UV, n, Hm, lam, bias, scale, group, k


def displace(
    V,
    F,
    UV,
    N,
    height,
    lam: float = 1.0,
    bias: float = 0.0,
    scale: float = 1.0,
    *,
    weld_seams: bool = True,
    wrap: str = "clamp",
    return_normals: bool = False,
):
    """Move every vertex along its normal by the displacement map: ``P' = P + lam (bias + scale h(uv)) n``.

    The map value ``h`` in ``[0, 1]`` (black = 0) is read with bilinear filtering at the vertex's
    UV (:func:`geomlib.textures.sample_bilinear`); ``bias + scale h`` maps ``[0, 1]`` onto
    ``[bias, bias + scale]`` (e.g. ``(bias, scale) = (-1, 2)`` gives offsets in ``[-1, 1]``) and
    ``lam`` scales the result into mesh units. This is a vertex-shader operation: only vertices
    move, so the mesh must be dense enough to show the map's detail.

    UV seams: a vertex on a seam exists once per chart (same position, different UV), and the copies
    read different texels. With ``weld_seams`` the copies (found by
    :func:`geomlib.textures.weld_by_position`) get the MEAN of their offsets ``bias + scale h`` and
    the mean of their normals, so they move together and the seam does not crack open. Copies whose
    normals cancel (a mean of zero length) move along ``(0, 0, 1)``.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    UV : (n, 2) float
        In ``[0, 1]^2`` (any finite values with ``wrap="repeat"``).
    N : (n, 3) float or None
        Displacement directions (normalised here). ``None``: area-weighted vertex normals computed
        across seams (:func:`welded_vertex_normals`).
    height : (s, s) float in [0, 1], uint8 or uint16
        Square displacement map.
    lam, bias, scale : float
        ``lam`` in mesh units; ``bias`` and ``scale`` map the texel range.
    weld_seams : bool
        Move the copies of a seam vertex together.
    wrap : {"clamp", "repeat"}
        Map lookups outside the texture (see :func:`geomlib.textures.sample_bilinear`).
    return_normals : bool
        Also return the recomputed normals of the displaced mesh (area-weighted, welded across
        seams when ``weld_seams``): the old normals are wrong once the surface has moved.

    Returns
    -------
    V_new : (n, 3) float64
    N_new : (n, 3) float64
        Only with ``return_normals=True``.

    Raises
    ------
    MeshError
        Invalid mesh, missing or out-of-range UVs, bad map, zero normals, bad parameters.
    """
    V, F, UV, n, Hm, lam, bias, scale, group, k = checked_displace_inputs(
        V, F, UV, N, height, lam, bias, scale, weld_seams, wrap, "displace"
    )
    h = sample_bilinear(Hm, UV, wrap=wrap)
    V_new = ...  # (n, 3) displaced positions
    raise NotImplementedError("Task 5 (displace): d = bias + scale h; seam copies (same group) share the mean d and mean n; P' = P + lam d n")
    if not return_normals:
        return V_new
    if weld_seams:
        return V_new, welded_vertex_normals(V_new, F, group)
    return V_new, normalize_rows(vertex_normals(V_new, F), fallback=(0.0, 0.0, 1.0))
