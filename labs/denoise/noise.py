"""Given helpers: the lab's seeded noisy inputs and the error measure.

The experiment of this lab starts from a clean mesh, adds Gaussian noise along random
directions, keeps the clean normals, denoises, and measures how far the vertices are from the
clean surface. Seam copies get the same noise (a noisy mesh with cracks would be a different
problem), and the same normal.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.geometry import bbox_diagonal, closest_points, mean_edge_length, vertex_normals
from geomlib.textures import weld_by_position
from geomlib.validate import check_float, check_int, check_mesh

__all__ = ["make_noisy", "surface_error", "error_stats"]


def _welded(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    group, k = weld_by_position(V)
    first = np.full(k, len(V), np.int64)
    np.minimum.at(first, group, np.arange(len(V)))
    return V[first], group[F], group


def make_noisy(V, F, sigma_rel: float = 0.3, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Given: a noisy copy of a clean mesh, and the clean mesh's normals.

    ``p_i + g_i d_i`` with ``g_i ~ N(0, sigma^2)``, ``sigma = sigma_rel`` times the mean edge
    length, and ``d_i`` a uniformly random unit direction
    (:func:`geomlib.datasets.add_noise`). Vertices at the same position (UV seam copies) are
    treated as one vertex: they get the same noise and the same normal.

    Parameters
    ----------
    V, F : (n, 3) float, (m, 3) int
        The clean mesh.
    sigma_rel : float
        Noise level relative to the mean edge length (>= 0).
    seed : int
        Seed of the noise (>= 0); the same seed gives the same noise.

    Returns
    -------
    V_noisy : (n, 3) float64
    N_clean : (n, 3) float64
        Area-weighted unit vertex normals of the clean mesh, computed across seams.
    """
    where = "make_noisy"
    V, F = check_mesh(V, F, where=where)
    sigma_rel = check_float(sigma_rel, "sigma_rel", minimum=0.0, where=where)
    seed = check_int(seed, "seed", minimum=0, where=where)
    Vw, Fw, group = _welded(V, F)
    sigma = sigma_rel * mean_edge_length(Vw, Fw)
    Vn = datasets.add_noise(Vw, sigma, seed=seed, direction="random")
    Nw = vertex_normals(Vw, Fw)
    return Vn[group], Nw[group]


def surface_error(V_clean, F_clean, V) -> np.ndarray:
    """Given: distance of every vertex of ``V`` to the clean surface, relative to its bbox diagonal.

    ``e_i = min_{x on (V_clean, F_clean)} |p_i - x| / diag(V_clean)``, with exact closest points
    (:func:`geomlib.geometry.closest_points`).

    Returns
    -------
    e : (n,) float64
    """
    V_clean, F_clean = check_mesh(V_clean, F_clean, where="surface_error")
    d2, _, _ = closest_points(V_clean, F_clean, V)
    return np.sqrt(d2) / bbox_diagonal(V_clean)


def error_stats(V_clean, F_clean, V) -> dict[str, float]:
    """Given: ``{"mean": ..., "max": ...}`` of :func:`surface_error`."""
    e = surface_error(V_clean, F_clean, V)
    return {"mean": float(e.mean()), "max": float(e.max())}
