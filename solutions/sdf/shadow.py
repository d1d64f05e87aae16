"""Soft shadows, ambient occlusion and collision push-out from a distance field (Task 9).

**Soft shadows.** March from a surface point ``p`` toward the centre ``c`` of a spherical light of
radius ``R`` (``D = |c - p|``). Seen from ``p`` the light is a disk of half-angle ``alpha`` with
``tan alpha = R / sqrt(D^2 - R^2)``. At a march sample ``x(t)`` the nearest occluder is ``phi(x)``
away, so it hides the part of the cone of half-angle ``atan(phi / t)``; the course formula takes
the ratio of that cone to the light's as the visible fraction::

    V = clamp(min_t phi(x(t)) / (t tan alpha), 0, 1)

This is an estimate, not the true area-light visibility (the handout compares both). The
*improved* variant (Aaltonen's) uses the previous sample: with ``y = phi^2 / (2 phi_prev)`` and
``e = sqrt(phi^2 - y^2)`` it evaluates ``e / ((t - y) tan alpha)``, the distance to the point where
the two unbounding spheres meet, which removes the banding of the plain formula.

**Ambient occlusion.** Sample the field at ``k`` taps ``p + i delta n``: an open surface has
``phi = i delta`` there, anything nearer is occluding.
``AO = clamp(1 - sum_i w_i (i delta - phi_i) / (i delta), 0, 1)``, ``w_i = 2^-i / sum_j 2^-j``.

**Push-out.** A point that penetrates (``phi(p) < radius``) moves along the normal by the missing
distance: ``p <- p + (radius - phi(p)) n(p)`` (4-tap normal), a few times.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array, check_float, check_int

from .analytic import as_points
from .gradient import gradient_tetra
from .scene import as_field

__all__ = ["soft_shadow", "ambient_occlusion", "push_out"]


def soft_shadow(
    sdf,
    P,
    light_center,
    light_radius: float,
    *,
    max_steps: int = 32,
    improved: bool = False,
    eps: float = 1e-4,
    t_start: float | None = None,
) -> np.ndarray:
    """Visibility of a spherical light from points ``P`` by marching the field.

    Parameters
    ----------
    sdf : field (see ``scene.as_field``)
    P : (n, 3) array_like
        Shading points (already lifted off the surface by the caller, e.g. ``p + 1e-3 n``).
    light_center : (3,) array_like
    light_radius : float
        ``R > 0``; every point must be farther than ``R`` from the centre.
    max_steps : int
        Field evaluations per point.
    improved : bool
        Use the previous-sample variant.
    eps : float
        Smallest step; a sample with ``phi < eps`` means full shadow (``V = 0``).
    t_start : float, optional
        First march parameter (default ``1e-3 * D``).

    Returns
    -------
    V : (n,) float64 in [0, 1]

    Notes
    -----
    March ``t`` from ``t_start`` while ``t < D - R`` (the light's near side): ``d = phi(p + t l)``,
    ``l = (c - p) / D``; ``d < eps`` -> ``V = 0``, stop; else ``V = min(V, d / (t tan alpha))``
    (improved: ``y = d^2 / (2 d_prev)``, ``e = sqrt(max(d^2 - y^2, 0))``,
    ``V = min(V, e / (max(t - y, 0) tan alpha))``; ``d_prev = 1e20`` at the first step), then
    ``t += max(d, eps)``. Finally clamp ``V`` to ``[0, 1]``.
    """
    where = "soft_shadow"
    phi = as_field(sdf, where)
    P = as_points(P, where)
    c = as_array(light_center, "light_center", shape=(3,), where=where)
    R = check_float(light_radius, "light_radius", positive=True, where=where)
    max_steps = check_int(max_steps, "max_steps", minimum=1, where=where)
    eps = check_float(eps, "eps", positive=True, where=where)
    Lv = c - P
    Dist = np.linalg.norm(Lv, axis=1)
    if np.any(Dist <= R):
        i = int(np.flatnonzero(Dist <= R)[0])
        raise MeshError(f"{where}: point {i} lies inside the light (distance {Dist[i]:.4g} <= radius {R})")
    Ldir = Lv / Dist[:, None]
    tan_a = R / np.sqrt(Dist**2 - R**2)
    t0 = 1e-3 * Dist if t_start is None else np.full(len(P), check_float(t_start, "t_start", minimum=0.0, where=where))
    # BEGIN SOLUTION: Task 9 (soft shadows): soft shadow: march active points; d = phi(p + t l); d < eps -> V = 0; V = min(V, d/(t tan a)) or the improved e/((t - y) tan a); t += max(d, eps) while t < D - R; clamp to [0, 1]
    n = len(P)
    V = np.ones(n)
    t = t0.copy()
    prev = np.full(n, 1e20)
    active = np.flatnonzero(t < Dist - R)
    for _ in range(max_steps):  # sequential march, vectorised over points
        if len(active) == 0:
            break
        d = np.asarray(phi(P[active] + t[active, None] * Ldir[active]), np.float64)
        blocked = d < eps
        V[active[blocked]] = 0.0
        a, d = active[~blocked], d[~blocked]
        ta = t[a] * tan_a[a]
        if improved:
            y = d * d / (2 * prev[a])
            e = np.sqrt(np.maximum(d * d - y * y, 0.0))
            den = np.maximum(t[a] - y, 0.0) * tan_a[a]
            with np.errstate(divide="ignore", invalid="ignore"):
                est = np.where(den > 0, e / den, np.inf)
        else:
            est = d / ta
        V[a] = np.minimum(V[a], est)
        prev[a] = d
        t[a] += np.maximum(d, eps)
        active = a[t[a] < Dist[a] - R]
    return np.clip(V, 0.0, 1.0)
    # END SOLUTION


def ambient_occlusion(sdf, P, N, *, taps: int = 5, delta: float = 0.05) -> np.ndarray:
    """Distance-field ambient occlusion from ``taps`` samples along the normal.

    Parameters
    ----------
    sdf : field
    P : (n, 3) surface points
    N : (n, 3) unit normals
    taps : int
        ``k >= 1`` samples at ``p + i delta n``, ``i = 1..k``.
    delta : float
        Tap spacing ``> 0``.

    Returns
    -------
    AO : (n,) float64 in [0, 1], 1 = open.
    """
    where = "ambient_occlusion"
    phi = as_field(sdf, where)
    P = as_points(P, where)
    N = as_array(N, "N", shape=(len(P), 3), where=where)
    taps = check_int(taps, "taps", minimum=1, maximum=64, where=where)
    delta = check_float(delta, "delta", positive=True, where=where)
    # BEGIN SOLUTION: Task 9 (ambient occlusion): AO: w_i = 2^-i / sum_j 2^-j; AO = clamp(1 - sum_i w_i (i delta - phi(p + i delta n)) / (i delta), 0, 1)
    i = np.arange(1, taps + 1)
    w = 0.5**i / np.sum(0.5**i)
    occ = np.zeros(len(P))
    for k, wk in zip(i, w, strict=True):  # a few taps, each vectorised over points
        occ += wk * (k * delta - np.asarray(phi(P + k * delta * N), np.float64)) / (k * delta)
    return np.clip(1.0 - occ, 0.0, 1.0)
    # END SOLUTION


def push_out(sdf, P, *, radius: float = 0.0, iterations: int = 4, h: float = 1e-3) -> np.ndarray:
    """Move penetrating points out of the solid along the field's normal.

    Parameters
    ----------
    sdf : field
    P : (n, 3) points (e.g. particle centres)
    radius : float
        Points end at ``phi >= radius`` (a sphere of that radius touches the surface), ``>= 0``.
    iterations : int
        Fixed-point iterations ``p <- p + max(radius - phi(p), 0) n(p)`` with the 4-tap normal
        (:func:`gradient_tetra` with step ``h``).

    Returns
    -------
    P_out : (n, 3) float64 (points with ``phi >= radius`` do not move)
    """
    where = "push_out"
    phi = as_field(sdf, where)
    P = as_points(P, where).copy()
    radius = check_float(radius, "radius", minimum=0.0, where=where)
    iterations = check_int(iterations, "iterations", minimum=1, maximum=100, where=where)
    # BEGIN SOLUTION: Task 9 (push-out): push-out: repeat: pen = max(radius - phi(p), 0); p += pen * gradient_tetra(sdf, p, h) for the penetrating points
    for _ in range(iterations):  # fixed-point iterations, vectorised over points
        pen = np.maximum(radius - np.asarray(phi(P), np.float64), 0.0)
        m = pen > 0
        if not m.any():
            break
        P[m] += pen[m, None] * gradient_tetra(sdf, P[m], h)
    return P
    # END SOLUTION
