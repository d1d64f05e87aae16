"""Task 2: sample the surface at arbitrary uv points (point location in the parameter domain).

Given a parameterization ``UV`` of the mesh, a point ``x`` of the square lies in one uv-triangle
``(a, b, c)`` with barycentric coordinates ``(l_a, l_b, l_c)``, ``l >= 0``, ``sum l = 1``,
``x = l_a uv_a + l_b uv_b + l_c uv_c``. The surface point at ``x`` is the same combination of the
3-D corners: ``p(x) = l_a V_a + l_b V_b + l_c V_c``.

Finding the triangle must not be a loop over triangles: we bucket triangles into a uniform grid of
cells over the uv bounding box (each triangle goes to every cell its bounding box touches), so a
query only tests the few triangles of its own cell.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from geomlib.validate import MeshError, as_array, check_mesh

__all__ = ["locate_uv", "sample_surface", "barycentric_2d"]


def barycentric_2d(X: np.ndarray, A: np.ndarray, B: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of 2-D points ``X`` in triangles ``(A, B, C)`` (all ``(k, 2)``).

    Given helper. Returns ``(k, 3)``; rows sum to 1. Degenerate triangles give non-finite rows.
    """
    v0, v1, v2 = B - A, C - A, X - A
    den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        lb = (v2[:, 0] * v1[:, 1] - v1[:, 0] * v2[:, 1]) / den
        lc = (v0[:, 0] * v2[:, 1] - v2[:, 0] * v0[:, 1]) / den
    return np.stack([1.0 - lb - lc, lb, lc], axis=1)


def _closest_on_triangles(X, A, B, C):
    """Closest points of triangles (A, B, C) to X in 2-D, as clamped barycentric coordinates."""
    lam = barycentric_2d(X, A, B, C)
    inside = (lam >= 0).all(axis=1)
    best = np.where(inside[:, None], lam, np.nan)
    best_d = np.where(inside, 0.0, np.inf)
    # Otherwise the closest point is on one of the three edges.
    for P, Q, i, j in ((A, B, 0, 1), (B, C, 1, 2), (C, A, 2, 0)):
        d = Q - P
        t = np.clip(np.einsum("ij,ij->i", X - P, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0, 1)
        dist = np.linalg.norm(P + t[:, None] * d - X, axis=1)
        better = dist < best_d
        lam_e = np.zeros_like(lam)
        lam_e[:, i] = 1 - t
        lam_e[:, j] = t
        best = np.where(better[:, None], lam_e, best)
        best_d = np.where(better, dist, best_d)
    return best, best_d


def locate_uv(UV, F, uv_points, *, eps: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
    """Find the uv-triangle containing each query point.

    Parameters
    ----------
    UV : (n, 2) float64
        Parameterization (one uv per vertex).
    F : (m, 3) int64
        Triangles.
    uv_points : (k, 2) float64
        Query points.
    eps : float
        Barycentric tolerance: a point is inside when every coordinate is ``>= -eps``.

    Returns
    -------
    face : (k,) int64
        Containing triangle. A point outside every triangle (outside the parameter domain, or in a
        gap left by round-off) gets the triangle nearest to it in uv.
    bary : (k, 3) float64
        Barycentric coordinates in ``face`` (clamped to the triangle for points outside), rows sum to 1.
    """
    UV = np.asarray(UV, np.float64)
    F = np.asarray(F, np.int64)
    X = np.asarray(uv_points, np.float64).reshape(-1, 2)
    k = len(X)
    face = np.full(k, -1, np.int64)
    bary = np.zeros((k, 3))
    if k == 0:
        return face, bary
    raise NotImplementedError("Task 2a (point location): bucket triangles in a uniform uv grid, test only the query's cell, lambda >= 0")
    return face, bary


def sample_surface(V, F, UV, uv_points) -> np.ndarray:
    """Surface points at given uv positions: ``p(x) = sum_i l_i(x) V_{f_i}``.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    F : (m, 3) int64
        Triangles.
    UV : (n, 2) float64
        A bijective parameterization of the mesh (e.g. from :func:`parameterize_square`).
    uv_points : (..., 2) float64
        Query points, any leading shape (e.g. a ``(res, res, 2)`` grid).

    Returns
    -------
    P : (..., 3) float64
        The surface point at every query; a query outside the parameter domain gets the surface
        point at the nearest uv location on the domain's boundary.

    Raises
    ------
    MeshError
        Bad mesh, ``UV`` not ``(n, 2)`` finite, queries not ``(..., 2)`` finite.
    """
    where = "sample_surface"
    V, F = check_mesh(V, F, where=where)
    UV = as_array(UV, "UV", shape=(len(V), 2), where=where)
    X = as_array(uv_points, "uv_points", where=where)
    if X.ndim < 1 or X.shape[-1] != 2:
        raise MeshError(f"{where}: uv_points has shape {X.shape}, expected (..., 2)")
    lead = X.shape[:-1]
    raise NotImplementedError('Task 2b (sampling): p = l_a V_a + l_b V_b + l_c V_c in the containing uv triangle')
