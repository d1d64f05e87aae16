"""Analytic signed distance functions and constructive solid geometry (Task 1).

A signed distance function (SDF) ``phi`` gives, at every point ``p``, the distance to a surface,
negative inside the solid: ``phi(p) = -dist(p, S)`` inside and ``+dist(p, S)`` outside. Simple
solids have closed forms; combining them with ``min``/``max`` gives CSG. ``min`` and ``max`` of exact
SDFs are exact *outside* a union and *inside* an intersection and only a lower bound on the distance
elsewhere, which is all sphere tracing needs (it never steps past the surface).
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array, check_float

__all__ = [
    "as_points",
    "sd_sphere",
    "sd_box",
    "sd_plane",
    "sd_capsule",
    "sd_torus",
    "op_union",
    "op_intersection",
    "op_difference",
    "smooth_union",
]


def as_points(P, where: str, name: str = "P") -> np.ndarray:
    """Query points as a float64 ``(n, 3)`` array (given). NaN and inf are rejected."""
    P = as_array(P, name, dtype=np.float64, shape=(None, 3), where=where)
    if not np.all(np.isfinite(P)):
        r = int(np.flatnonzero(~np.isfinite(P).all(axis=1))[0])
        raise MeshError(f"{where}: {name} contains NaN or inf (row {r})")
    return P


def _vec3(x, name: str, where: str) -> np.ndarray:
    x = as_array(x, name, dtype=np.float64, shape=(3,), where=where)
    if not np.all(np.isfinite(x)):
        raise MeshError(f"{where}: {name} must be finite, got {x}")
    return x


def sd_sphere(P, center, radius: float) -> np.ndarray:
    """Signed distance to a sphere: ``phi(p) = |p - c| - r``.

    Parameters
    ----------
    P : (n, 3) array_like
        Query points.
    center : (3,) array_like
    radius : float
        ``> 0``.

    Returns
    -------
    d : (n,) float64
    """
    where = "sd_sphere"
    P = as_points(P, where)
    c = _vec3(center, "center", where)
    r = check_float(radius, "radius", positive=True, where=where)
    raise NotImplementedError('Task 1 (analytic SDFs): phi(p) = |p - c| - r')


def sd_box(P, center, half_size) -> np.ndarray:
    """Exact signed distance to an axis-aligned box (the course formula).

    With ``q = |p - c| - b`` (component-wise, ``b`` the half sizes)::

        phi(p) = |max(q, 0)|  +  min(max(q_x, q_y, q_z), 0)
                 ^ outside term    ^ inside term

    Outside the box only the first term is non-zero (distance to the nearest face, edge or corner);
    inside only the second (minus the distance to the nearest face).

    Parameters
    ----------
    P : (n, 3) array_like
    center : (3,) array_like
    half_size : (3,) array_like
        Half extents, all ``> 0``.

    Returns
    -------
    d : (n,) float64
    """
    where = "sd_box"
    P = as_points(P, where)
    c = _vec3(center, "center", where)
    b = _vec3(half_size, "half_size", where)
    if np.any(b <= 0):
        raise MeshError(f"{where}: half_size must be > 0 on every axis, got {b}")
    raise NotImplementedError('Task 1 (analytic SDFs): q = |p - c| - b; phi = |max(q, 0)| + min(max_i q_i, 0)')


def sd_plane(P, normal, offset: float = 0.0) -> np.ndarray:
    """Signed distance to the plane ``n . p = offset`` (the solid is the half-space ``n . p < offset``).

    Parameters
    ----------
    P : (n, 3) array_like
    normal : (3,) array_like
        Need not be unit length (it is normalised); non-zero.
    offset : float
        Signed distance of the plane from the origin along the *unit* normal.

    Returns
    -------
    d : (n,) float64
        ``P @ n_hat - offset``.
    """
    where = "sd_plane"
    P = as_points(P, where)
    n = _vec3(normal, "normal", where)
    off = check_float(offset, "offset", where=where)
    if np.linalg.norm(n) == 0:
        raise MeshError(f"{where}: normal must be non-zero")
    raise NotImplementedError('Task 1 (analytic SDFs): phi(p) = p . n/|n| - offset')


def sd_capsule(P, a, b, radius: float) -> np.ndarray:
    """Signed distance to a capsule: the points within ``radius`` of the segment ``ab``.

    ``h = clamp((p - a).(b - a) / |b - a|^2, 0, 1)``, ``phi(p) = |p - a - h (b - a)| - r``.
    ``a == b`` gives a sphere.

    Returns
    -------
    d : (n,) float64
    """
    where = "sd_capsule"
    P = as_points(P, where)
    a = _vec3(a, "a", where)
    b = _vec3(b, "b", where)
    r = check_float(radius, "radius", positive=True, where=where)
    raise NotImplementedError('Task 1 (analytic SDFs): h = clamp((p-a).(b-a)/|b-a|^2, 0, 1); phi = |p - a - h(b-a)| - r')


def sd_torus(P, center, major: float, minor: float) -> np.ndarray:
    """Signed distance to a torus around the z axis through ``center``.

    ``phi(p) = | (sqrt(x^2 + y^2) - R, z) | - r`` with ``(x, y, z) = p - c``.

    Returns
    -------
    d : (n,) float64
    """
    where = "sd_torus"
    P = as_points(P, where)
    c = _vec3(center, "center", where)
    R = check_float(major, "major", where=where)
    r = check_float(minor, "minor", where=where)
    if not 0 < r < R:
        raise MeshError(f"{where}: need 0 < minor < major, got major={R}, minor={r}")
    raise NotImplementedError('Task 1 (analytic SDFs): phi = |(sqrt(x^2 + y^2) - R, z)| - r')


def _pair(a, b, where: str) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise MeshError(f"{where}: the two distance arrays differ in shape: {a.shape} and {b.shape}")
    return a, b


def op_union(a, b) -> np.ndarray:
    """Union of two solids: ``min(a, b)``."""
    a, b = _pair(a, b, "op_union")
    raise NotImplementedError('Task 1 (analytic SDFs): CSG: union = min(a, b)')


def op_intersection(a, b) -> np.ndarray:
    """Intersection of two solids: ``max(a, b)``."""
    a, b = _pair(a, b, "op_intersection")
    raise NotImplementedError('Task 1 (analytic SDFs): CSG: intersection = max(a, b)')


def op_difference(a, b) -> np.ndarray:
    """``a`` minus ``b``: ``max(a, -b)`` (inside ``a`` and outside ``b``)."""
    a, b = _pair(a, b, "op_difference")
    raise NotImplementedError('Task 1 (analytic SDFs): CSG: difference = max(a, -b)')


def smooth_union(a, b, k: float = 0.1) -> np.ndarray:
    """Polynomial smooth minimum (given): blends the two surfaces over a width ``k``.

    ``h = clamp(0.5 + 0.5 (b - a) / k, 0, 1)``, ``d = b + (a - b) h - k h (1 - h)``. Equals
    ``min(a, b)`` where ``|a - b| >= k``; it is a bound, not an exact distance, in the blend.
    """
    a, b = _pair(a, b, "smooth_union")
    k = check_float(k, "k", positive=True, where="smooth_union")
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b + (a - b) * h - k * h * (1.0 - h)
