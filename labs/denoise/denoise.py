"""Task 3: direct denoising, p'_i = p_i - lam <delta_i, n_i> n_i, along the clean normals."""

from __future__ import annotations

import numpy as np

from geomlib.validate import check_float, check_int, check_mesh

from .inputs import as_unit_normals, check_weights, check_weld, normalize_rows
from .laplacian import laplacian_offsets, normal_offsets
from .seams import seam_mean, weld_seams

__all__ = ["denoise_vertices"]


def denoise_vertices(
    V, F, N, lam: float, *, weights: str = "uniform", iterations: int = 1, weld: bool = True
) -> np.ndarray:
    """Move every vertex back along its normal by ``lam`` times its normal Laplacian offset.

    ``p'_i = p_i - lam s_i n_i`` with ``s_i = <delta_i, n_i>`` (:func:`normal_offsets`) and
    ``delta`` the Laplacian offsets of the current positions (:func:`laplacian_offsets`). Only
    the normal part of ``delta`` is removed, so vertices do not slide along the surface and the
    triangulation keeps its shape. ``lam = 0`` changes nothing, ``lam = 1`` puts each vertex at
    the height of its neighbours' mean, measured along ``n_i``.

    With ``iterations > 1`` the step is repeated, with ``delta`` recomputed from the moved
    vertices each time and the same normals ``N`` (the clean surface's normals do not change).

    Curvature leaks into ``delta``: on a clean sphere of radius ``R`` whose vertices have
    neighbours at distance ``h``, ``s_i`` is about ``h^2 / (2R)``, so every pass also shrinks
    the surface by ``lam h^2 / (2R)``. Strong or repeated smoothing of a curved mesh with little
    noise therefore makes it worse, not better.

    Parameters
    ----------
    V : (n, 3) float
        Noisy vertex positions.
    F : (m, 3) int
        Triangles.
    N : (n, 3) float
        Normals of the clean surface, one per vertex (normalised here).
    lam : float
        Step ``lambda`` in ``[0, 1]``.
    weights : {"uniform", "cotan"}
        Laplacian weights (:func:`laplacian_offsets`).
    iterations : int
        Number of passes (>= 1).
    weld : bool
        Seam fix (Task 6): copies of a vertex on a UV seam are welded for the Laplacian and moved
        with the mean of their normals, so they stay together. ``weld=False`` treats them as
        separate vertices.

    Returns
    -------
    V_new : (n, 3) float64

    Raises
    ------
    MeshError
        Invalid mesh or normals, ``lam`` outside ``[0, 1]``, bad ``iterations`` or ``weights``.
    """
    where = "denoise_vertices"
    V, F = check_mesh(V, F, where=where)
    N = as_unit_normals(N, len(V), where)
    lam = check_float(lam, "lam", minimum=0.0, maximum=1.0, where=where)
    check_weights(weights, where)
    iterations = check_int(iterations, "iterations", minimum=1, maximum=10_000, where=where)
    if check_weld(weld, where):
        X, Fw, group = weld_seams(V, F)
        Nw = normalize_rows(seam_mean(N, group))
    else:
        X, Fw, group, Nw = V, F, np.arange(len(V)), N
    for _ in range(iterations):  # sequential by nature: each pass smooths the result of the previous one
        raise NotImplementedError('Task 3 (direct denoising): s = normal_offsets(laplacian_offsets(X, Fw, weights, weld=False), Nw); X = X - lam s n')
    return X[group]
