"""Given: ground truth — the exact first intersection of the view ray with the bilinear height field."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d

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
    i = _first_sample(H, u0, v0, du, dv, m)  # per pixel; the samples before are all above the surface
    while alive.size:  # sequential along the ray; vectorised over the pixels still marching
        done = f(alive, i / m) >= 0
        hit[alive[done]] = i[done]
        alive, i = alive[~done], i[~done] + 1
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


def _first_sample(H, u0, v0, du, dv, m: int, pieces: int = 16) -> np.ndarray:
    """Per pixel, a march sample ``i`` such that ``f(j / m) < 0`` for every ``j < i`` (``(P,)`` int64).

    The depths ``[p / K, (p + 1) / K]`` of piece ``p`` of the ray (``K = pieces``) read a box of texels;
    the bilinear height there is at most the box's highest texel ``hmax``, so ``f(d) = d - (1 - h) < 0``
    for ``d < 1 - hmax``. The march starts in the first piece that may reach the surface, past its
    samples above ``1 - hmax``: it skips only samples it would pass (the hit, its depth and uv are the
    same as from 0), most of a march on a map with low regions. Margins: a texel around each box, a
    sample and 1e-9 in depth for rounding.
    """
    P = u0.size
    if not (np.isfinite(du).all() and np.isfinite(dv).all()):
        return np.zeros(P, dtype=np.int64)
    s = H.shape[0]
    d = np.arange(pieces + 1) / pieces
    # texel columns and rows the lookup reads (see height_lookup) at the pieces' ends, (P, K + 1)
    x = np.clip((u0[:, None] + d * du[:, None]) * s - 0.5, 0.0, s - 1.0).astype(np.intp)
    y = np.clip((1.0 - (v0[:, None] + d * dv[:, None])) * s - 0.5, 0.0, s - 1.0).astype(np.intp)
    c0 = np.maximum(np.minimum(x[:, :-1], x[:, 1:]) - 1, 0)
    r0 = np.maximum(np.minimum(y[:, :-1], y[:, 1:]) - 1, 0)
    # one box size for all (the largest; a larger box only lowers the start), odd for the centred
    # filters: the max over columns c0 .. c0 + w - 1 sits at c0 + w // 2 of the filtered map
    w = int(np.max(np.maximum(x[:, :-1], x[:, 1:]) - c0)) + 3 | 1
    h = int(np.max(np.maximum(y[:, :-1], y[:, 1:]) - r0)) + 3 | 1
    Hp = np.pad(H, ((0, 1), (0, 1)), mode="edge")
    top = maximum_filter1d(maximum_filter1d(Hp, w, axis=1, mode="nearest"), h, axis=0, mode="nearest")
    hmax = top[np.minimum(r0 + h // 2, s), np.minimum(c0 + w // 2, s)]  # (P, K)
    above = d[1:] <= 1.0 - hmax - 1e-9  # the whole piece lies above the surface
    k = np.where(above.all(axis=1), pieces - 1, np.argmin(above, axis=1))  # first piece that may reach it
    inside = np.floor((1.0 - hmax[np.arange(P), k] - 1e-9) * m)
    start = np.maximum(np.floor(k / pieces * m), inside).astype(np.int64) - 1
    return np.maximum(start, 0)


def uv_error_texels(uv, uv_true, s: int) -> np.ndarray:
    """Distance between two uv arrays in texels of an ``s x s`` map: ``s * |uv - uv_true|``."""
    return s * np.linalg.norm(np.asarray(uv) - np.asarray(uv_true), axis=-1)
