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
    raise NotImplementedError('Task 11 (curvature): H = |Δx| / 2 (cotangent Laplacian), K = angle defect / A, κ = |H| + sqrt(max(H² − K, 0))')


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
    raise NotImplementedError('Task 11 (adaptive target length): smooth κ over 1-rings, h = sqrt(6 ε r − 3 ε²) with r = 1/κ, clamp')
