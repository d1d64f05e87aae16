"""Given: ground truth — the exact first intersection of the view ray with the bilinear height field."""

from __future__ import annotations

import numpy as np

from .inputs import check_layers, check_view_ray, height_lookup

__all__ = ["exact_uv", "uv_error_texels"]


def exact_uv(height, uv, view, *, scale: float, samples: int = 2048, bisections: int = 48):
    """The ray/height-field intersection to round-off: a fine march, then bisection.

    Marches ``f(d) = d - (1 - h(uv(d)))`` (see :func:`relief_uv`) at ``samples + 1`` equal
    depths regardless of the angle, then bisects the first sign change ``bisections`` times. A
    texel of an ``s``-texel map spans ``s * scale * tan(theta)`` of the march's ``[0, 1]`` at most,
    so with ``samples >= 8 s scale tan(theta)`` every bilinear patch is sampled several times
    and no crossing is missed.

    Returns
    -------
    uv : (..., 2) float64, depth : (...) float64
    """
    where = "exact_uv"
    H, uv, V, scale = check_view_ray(height, uv, view, scale, where)
    m = check_layers(samples, "samples", where=where)
    shape = uv.shape[:-1]
    u0, v0 = uv[..., 0].ravel(), uv[..., 1].ravel()
    du = (-scale * V[..., 0] / V[..., 2]).ravel()
    dv = (-scale * V[..., 1] / V[..., 2]).ravel()

    h = height_lookup(H)

    def f(k, d):
        return d - (1.0 - h(u0[k] + d * du[k], v0[k] + d * dv[k]))

    P = u0.size
    hit = np.zeros(P, dtype=np.int64)
    alive = np.arange(P)
    i = 0
    while alive.size:  # sequential along the ray; vectorised over the pixels still marching
        done = f(alive, np.full(alive.size, i / m)) >= 0
        hit[alive[done]] = i
        alive = alive[~done]
        i += 1
    ref = np.flatnonzero(hit > 0)
    lo, hi = (hit[ref] - 1) / m, hit[ref] / m
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        below = f(ref, mid) >= 0
        hi = np.where(below, mid, hi)
        lo = np.where(below, lo, mid)
    d = np.zeros(P)
    d[ref] = 0.5 * (lo + hi)
    out = np.stack([u0 + d * du, v0 + d * dv], axis=-1).reshape(*shape, 2)
    return out, (scale * d).reshape(shape)


def uv_error_texels(uv, uv_true, s: int) -> np.ndarray:
    """Distance between two uv arrays in texels of an ``s x s`` map: ``s * |uv - uv_true|``."""
    return s * np.linalg.norm(np.asarray(uv) - np.asarray(uv_true), axis=-1)
