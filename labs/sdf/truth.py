"""Ground truths for soft shadows (given): an analytic sphere occluder and a Monte-Carlo area light.

The visibility of a uniformly bright spherical light from ``p`` is the fraction of the light's disk
(its cone of half-angle ``alpha = asin(R / D)``) that is not covered by occluders. Both truths
integrate over that cone with the same stratified directions (uniform in solid angle):

* :func:`sphere_occluder_visibility` intersects each direction with a sphere in closed form;
* :func:`mesh_visibility` casts each direction against a mesh with geomlib's watertight ray caster.
"""

from __future__ import annotations

import numpy as np

from geomlib.geometry import ray_cast
from geomlib.validate import MeshError, as_array, check_float, check_int, check_mesh

from .analytic import as_points

__all__ = ["cone_directions", "sphere_occluder_visibility", "mesh_visibility"]


def cone_directions(axis, alpha, n: int, seed: int = 0, rows=None) -> np.ndarray:
    """``n`` unit directions per row, stratified uniformly in solid angle in the cone (``axis (k, 3)``, ``alpha (k,)``).

    Returns ``(k, n, 3)``, or only the given ``rows`` (indices into the k rows) of it: the random
    numbers are drawn for all k rows either way, so a row is the same as in the full result.
    """
    rng = np.random.default_rng(seed)
    s = int(np.ceil(np.sqrt(n)))
    i, j = np.divmod(np.arange(n), s)
    u1 = (i + rng.random((len(axis), n))) / s  # stratified in cos(theta) x phi
    u2 = (j + rng.random((len(axis), n))) / s
    if rows is not None:
        axis, alpha, u1, u2 = axis[rows], alpha[rows], u1[rows], u2[rows]
    ca = np.cos(alpha)[:, None]
    cos_t = 1 - u1 * (1 - ca)
    sin_t = np.sqrt(np.maximum(1 - cos_t**2, 0))
    ph = 2 * np.pi * u2
    a = axis / np.linalg.norm(axis, axis=1, keepdims=True)
    helper = np.where(np.abs(a[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = np.cross(a, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(a, e1)
    return (
        (sin_t * np.cos(ph))[..., None] * e1[:, None]
        + (sin_t * np.sin(ph))[..., None] * e2[:, None]
        + cos_t[..., None] * a[:, None]
    )


def _light_cone(P, c, R, where):
    P = as_points(P, where)
    c = as_array(c, "light_center", shape=(3,), where=where)
    R = check_float(R, "light_radius", where=where)
    L = c - P
    D = np.linalg.norm(L, axis=1)
    if R <= 0 or np.any(D <= R):
        raise MeshError(f"{where}: need light_radius > 0 and every point outside the light")
    return P, L, D, np.arcsin(R / D)


def sphere_occluder_visibility(P, light_center, light_radius, occ_center, occ_radius, *, n: int = 4096, seed: int = 0):
    """Visible fraction of a spherical light behind one sphere occluder (ray-sphere tests, ``n`` directions).

    Returns ``(k,)`` in [0, 1]; its sampling error is below ``~1/n`` (stratified).
    """
    where = "sphere_occluder_visibility"
    P, L, D, alpha = _light_cone(P, light_center, light_radius, where)
    n = check_int(n, "n", minimum=1, where=where)
    oc = as_array(occ_center, "occ_center", shape=(3,), where=where)
    r = check_float(occ_radius, "occ_radius", where=where)
    Dir = cone_directions(L, alpha, n, seed)  # (k, n, 3)
    m = oc - P  # ray o + t d hits the sphere when the closest approach is < r and in front (t > 0)
    tc = np.einsum("knj,kj->kn", Dir, m)
    miss2 = np.einsum("kj,kj->k", m, m)[:, None] - tc**2
    blocked = (tc > 0) & (miss2 < r * r) & (tc < D[:, None])
    return 1.0 - blocked.mean(axis=1)


def mesh_visibility(V, F, P, light_center, light_radius, *, n: int = 256, seed: int = 0, t_min: float | None = None):
    """Monte-Carlo visible fraction of a spherical light from points ``P`` over the mesh ``(V, F)``.

    Casts ``n`` stratified rays per point into the light's cone with
    :func:`geomlib.geometry.ray_cast` (watertight); a ray is blocked when it hits the mesh before
    reaching the light. Standard error about ``sqrt(V (1 - V) / n)``. The rays of a point whose cone
    misses the mesh's bounding sphere are not cast (they would all miss): the same numbers, sooner.
    """
    where = "mesh_visibility"
    V, F = check_mesh(V, F, where=where, allow_duplicate=True)
    P, L, D, alpha = _light_cone(P, light_center, light_radius, where)
    n = check_int(n, "n", minimum=1, where=where)
    # A point whose whole cone misses the mesh's bounding sphere (with a margin far above rounding) sees
    # the whole light: its rays would all miss, so they are not cast (most points, under a small occluder).
    c = 0.5 * (V.max(axis=0) + V.min(axis=0))
    r = np.sqrt(((V - c) ** 2).sum(axis=1).max()) * (1 + 1e-6) + 1e-12
    to_c = c - P
    dc = np.linalg.norm(to_c, axis=1)
    cos_ac = np.clip((to_c * L).sum(axis=1) / (dc * D), -1.0, 1.0)
    misses = dc > r
    misses[misses] = np.arccos(cos_ac[misses]) > alpha[misses] + np.arcsin(r / dc[misses]) + 1e-6
    cast = np.flatnonzero(~misses)
    Dir = cone_directions(L, alpha, n, seed, rows=cast).reshape(-1, 3)  # drawn for every point: the same stream
    O = np.repeat(P[cast], n, axis=0)
    tmax = np.repeat(D[cast] - float(light_radius), n)  # stop at the light's near side (no self-hits there)
    eps = 1e-6 * float(np.linalg.norm(V.max(0) - V.min(0))) if t_min is None else t_min
    _, t, face, _ = ray_cast(V, F, O, Dir, t_min=eps)
    blocked = np.zeros((len(P), n), bool)
    blocked[cast] = ((face >= 0) & (t < tmax)).reshape(len(cast), n)
    return 1.0 - blocked.mean(axis=1)
