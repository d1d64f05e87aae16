"""Sphere tracing (Task 8) and a small renderer built on it (given).

A ray ``x(t) = o + t d`` (``|d| = 1``) may safely advance by ``phi(x(t))``: no surface is closer
than that. Sphere tracing repeats ``t += max(phi, eps)`` until ``phi < eps`` (a hit), ``t`` leaves
``[0, t_max]`` or the step budget runs out (misses). Near silhouettes rays graze the surface and
take many small steps: the step-count image shows where the time goes.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array, check_float, check_int

from .analytic import as_points
from .gradient import gradient_tetra
from .scene import as_field

__all__ = ["sphere_trace", "camera_rays", "render_sdf"]


def sphere_trace(sdf, origins, directions, *, max_steps: int = 64, eps: float = 1e-4, t_max: float | None = None):
    """March every ray through the field.

    Parameters
    ----------
    sdf : field (see ``scene.as_field``)
    origins : (n, 3) array_like
    directions : (n, 3) array_like
        Non-zero; normalised here.
    max_steps : int
        Most field evaluations per ray (>= 1).
    eps : float
        Hit threshold and smallest step, ``> 0``.
    t_max : float, optional
        Rays with ``t > t_max`` miss (default: no limit but the step budget).

    Returns
    -------
    t : (n,) float64
        Ray parameter of the hit (distance along the unit direction); ``inf`` for misses.
    hit : (n,) bool
    steps : (n,) int64
        Field evaluations used by each ray (1 .. max_steps).

    Notes
    -----
    Per ray: ``t = 0``; repeat up to ``max_steps`` times: ``d = phi(o + t dir)``, ``steps += 1``;
    if ``d < eps``: hit, stop; ``t += max(d, eps)``; if ``t > t_max``: miss, stop. Evaluate only the
    rays still marching (active-ray compaction), one ``phi`` call per step for all of them.
    """
    where = "sphere_trace"
    phi = as_field(sdf, where)
    O = as_points(origins, where, "origins")
    D = as_array(directions, "directions", shape=(len(O), 3), where=where)
    L = np.linalg.norm(D, axis=1)
    if np.any(L == 0):
        raise MeshError(f"{where}: directions must be non-zero (row {int(np.flatnonzero(L == 0)[0])})")
    D = D / L[:, None]
    max_steps = check_int(max_steps, "max_steps", minimum=1, where=where)
    eps = check_float(eps, "eps", positive=True, where=where)
    t_max = np.inf if t_max is None else check_float(t_max, "t_max", minimum=0.0, where=where)
    raise NotImplementedError('Task 8 (sphere tracing): keep an index array of active rays; each step: d = phi(o + t dir) for them, steps += 1, d < eps -> hit; t += max(d, eps); t > t_max -> miss; drop finished rays')


def camera_rays(M, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """World-space rays through the pixel centres of a camera ``M`` (clip from world), row 0 at the top.

    Returns ``(origins, directions)``, both ``(height * width, 3)`` in row-major pixel order; the
    origins lie on the near plane, directions are unit length. The same pixel centres as
    :func:`geomlib.raster.rasterize`.
    """
    M = as_array(M, "M", shape=(4, 4), where="camera_rays")
    width = check_int(width, "width", minimum=1, where="camera_rays")
    height = check_int(height, "height", minimum=1, where="camera_rays")
    xs = (np.arange(width) + 0.5) / width * 2 - 1
    ys = 1 - (np.arange(height) + 0.5) / height * 2
    X, Y = np.meshgrid(xs, ys)
    Minv = np.linalg.inv(M)

    def unproject(z):
        C = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z), np.ones(X.size)], axis=1) @ Minv.T
        return C[:, :3] / C[:, 3:]

    near, far = unproject(-1.0), unproject(1.0)
    D = far - near
    return near, D / np.linalg.norm(D, axis=1, keepdims=True)


def render_sdf(
    sdf,
    M,
    width: int,
    height: int,
    *,
    light_dir=(0.3, -0.6, 0.75),
    max_steps: int = 64,
    eps: float = 1e-4,
    h: float = 1e-3,
):
    """Sphere-trace a whole image and shade it with a Lambert term (given).

    Returns a dict: ``hit (H, W) bool``, ``depth (H, W)`` (distance along the ray, inf on misses),
    ``normal (H, W, 3)`` (4-tap gradient at hits), ``steps (H, W)``, ``image (H, W, 3)`` in [0, 1]
    (``0.15 + 0.85 max(n . l, 0)`` on hits, white background) and ``points (H, W, 3)``. Rays
    stop beyond the camera's far plane.
    """
    O, D = camera_rays(M, width, height)
    far = np.linalg.inv(np.asarray(M, float)) @ np.array([0.0, 0.0, 1.0, 1.0])
    t_max = 2 * float(np.linalg.norm(far[:3] / far[3] - O.mean(axis=0)))  # beyond the far plane
    t, hit, steps = sphere_trace(sdf, O, D, max_steps=max_steps, eps=eps, t_max=t_max)
    X = np.where(hit[:, None], O + np.where(hit, t, 0)[:, None] * D, np.nan)
    N = np.zeros_like(O)
    if hit.any():
        N[hit] = gradient_tetra(sdf, X[hit], h)
    ell = np.asarray(light_dir, float) / np.linalg.norm(light_dir)
    shade = 0.15 + 0.85 * np.clip(N @ ell, 0, None)
    img = np.where(hit[:, None], shade[:, None] * np.array([0.85, 0.8, 0.72]), 1.0)
    sh = (height, width)
    return {
        "hit": hit.reshape(sh),
        "depth": t.reshape(sh),
        "normal": N.reshape(*sh, 3),
        "steps": steps.reshape(sh),
        "image": img.reshape(*sh, 3),
        "points": X.reshape(*sh, 3),
    }
