"""Task 11 (extension): a target edge length per vertex from curvature, for ``isotropic_remesh(..., adaptive=True)``."""

from __future__ import annotations

import numpy as np

from geomlib import topology
from geomlib.errors import MeshError
from geomlib.validate import check_float, check_int, check_mesh

__all__ = ["max_curvature", "adaptive_target_length"]


def max_curvature(V, F):
    """Largest absolute principal curvature ``κ = max(|k1|, |k2|)`` at every vertex (1 / length units).

    From the discrete mean and Gaussian curvature of the lecture, with ``A_i`` a third of the area
    of the faces around vertex ``i`` (barycentric area):

    * ``H_i = |Δx_i| / 2`` with ``Δx_i = 1 / (2 A_i) Σ_j (cot α_ij + cot β_ij)(x_j − x_i)`` (cotangent
      Laplacian: ``α_ij``, ``β_ij`` are the angles opposite edge ``ij``);
    * ``K_i = (2π − Σ θ_i) / A_i`` (angle defect: ``θ_i`` the corner angles at ``i``);
    * ``k1,2 = H ± sqrt(H² − K)``, so ``κ = |H| + sqrt(max(H² − K, 0))``.

    Boundary vertices have neither (their Laplacian and angle defect measure the boundary, not the
    surface): ``κ`` is NaN there.

    Returns
    -------
    kappa : (n,) float
    """
    where = "max_curvature"
    V, F = check_mesh(V, F, where=where, manifold=True)
    # BEGIN SOLUTION: Task 11 (curvature): H = |Δx| / 2 (cotangent Laplacian), K = angle defect / A, κ = |H| + sqrt(max(H² − K, 0))
    n = len(V)
    theta = np.empty(F.shape)
    cot = np.empty(F.shape)
    for k in range(3):  # corner k of every face: angle between its two edges
        u, w = V[np.roll(F, -1, axis=1)[:, k]] - V[F[:, k]], V[np.roll(F, -2, axis=1)[:, k]] - V[F[:, k]]
        cos_k = (u * w).sum(axis=1)
        sin_k = np.linalg.norm(np.cross(u, w), axis=1)
        theta[:, k] = np.arctan2(sin_k, cos_k)
        cot[:, k] = cos_k / np.maximum(sin_k, 1e-300)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    A = np.maximum(np.bincount(F.ravel(), np.repeat(area / 3.0, 3), minlength=n), 1e-300)
    lap = np.zeros((n, 3))
    for k in range(3):  # edge (i, j) opposite corner k carries cot of that corner's angle
        i, j = F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        d = cot[:, k, None] * (V[j] - V[i])
        np.add.at(lap, i, d)
        np.add.at(lap, j, -d)
    H = np.linalg.norm(lap, axis=1) / (4.0 * A)
    K = (2.0 * np.pi - np.bincount(F.ravel(), theta.ravel(), minlength=n)) / A
    kappa = H + np.sqrt(np.maximum(H * H - K, 0.0))
    kappa[topology.halfedge_mesh(F, n, checked=True).boundary_vertex] = np.nan
    return kappa
    # END SOLUTION


def adaptive_target_length(V, F, target_length, *, error=None, min_length=None, max_length=None, smoothing=2):
    """Per-vertex target edge length from curvature: short where the surface bends, long where it is flat.

    An equilateral triangle of side ``h`` on a sphere of radius ``r`` leaves the sphere by
    ``ε = r − sqrt(r² − h²/3)`` (the height of the cap over its circumcircle), so the longest edge
    that keeps the error at ``ε`` is

        ``h = sqrt(6 ε r − 3 ε²)``  with ``r = 1 / κ`` (``h = √3 ε`` when ``ε ≥ r``).

    Steps: ``κ`` = :func:`max_curvature`; ``smoothing`` times, replace every ``κ`` by the mean over
    the vertex and its neighbours (NaN boundary values are left out, and so filled from inside);
    ``h`` from the formula; clamp to ``[min_length, max_length]``.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    target_length : float
        ``L``: the length at the median curvature ``κ̃`` when ``error`` is not given.
    error : float, optional
        ``ε`` (length units). Default ``L² κ̃ / 6``: ``h ≈ L`` where ``κ = κ̃``.
    min_length, max_length : float, optional
        Default ``L / 4`` and ``2 L``.
    smoothing : int
        Smoothing steps of ``κ``.

    Returns
    -------
    lengths : (n,) float
        Target edge length per vertex, within ``[min_length, max_length]``.
    """
    where = "adaptive_target_length"
    V, F = check_mesh(V, F, where=where, manifold=True)
    L = check_float(target_length, "target_length", positive=True, where=where)
    lo = L / 4.0 if min_length is None else check_float(min_length, "min_length", positive=True, where=where)
    hi = 2.0 * L if max_length is None else check_float(max_length, "max_length", positive=True, where=where)
    if lo > hi:
        raise MeshError(f"{where}: min_length ({lo:g}) must not exceed max_length ({hi:g})")
    eps = None if error is None else check_float(error, "error", positive=True, where=where)
    steps = check_int(smoothing, "smoothing", where=where, minimum=0)
    # BEGIN SOLUTION: Task 11 (adaptive target length): smooth κ over 1-rings, h = sqrt(6 ε r − 3 ε²) with r = 1/κ, clamp
    kappa = max_curvature(V, F)
    n = len(V)
    ij = topology.unique_edges(F)
    rows = np.r_[ij[:, 0], ij[:, 1], np.arange(n)]  # closed 1-ring: both directions and the vertex itself
    cols = np.r_[ij[:, 1], ij[:, 0], np.arange(n)]
    for _ in range(steps):  # mean over the closed 1-ring, known values only
        known = np.isfinite(kappa)
        k0 = np.where(known, kappa, 0.0)
        total = np.bincount(rows, k0[cols], minlength=n)
        count = np.bincount(rows, known[cols].astype(float), minlength=n)
        kappa = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    kappa = np.where(np.isfinite(kappa), kappa, 0.0)  # a vertex with no known value counts as flat
    if eps is None:
        eps = L * L * float(np.median(kappa)) / 6.0
    with np.errstate(divide="ignore"):
        r = np.where(kappa > 0, 1.0 / np.maximum(kappa, 1e-300), np.inf)
    h = np.where(eps < r, np.sqrt(np.maximum(6.0 * eps * r - 3.0 * eps * eps, 0.0)), np.sqrt(3.0) * eps)
    h = np.where(np.isfinite(h), h, hi)  # flat (r = inf): as long as allowed
    return np.clip(h, lo, hi)
    # END SOLUTION
