"""Given helpers: vectorised 2-D segment intersection with a uniform bucket grid."""

from __future__ import annotations

import numpy as np

__all__ = ["candidate_pairs", "segment_intersections"]


def _cells(lo: np.ndarray, hi: np.ndarray, origin: np.ndarray, size: float, g: int) -> tuple[np.ndarray, np.ndarray]:
    """All (item, cell id) pairs for boxes [lo, hi] on a g x g grid of square cells."""
    c0 = np.clip(np.floor((lo - origin) / size).astype(np.int64), 0, g - 1)
    c1 = np.clip(np.floor((hi - origin) / size).astype(np.int64), 0, g - 1)
    nx, ny = c1[:, 0] - c0[:, 0] + 1, c1[:, 1] - c0[:, 1] + 1
    cnt = nx * ny
    item = np.repeat(np.arange(len(lo)), cnt)
    local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    cell = (c0[item, 1] + local // nx[item]) * g + c0[item, 0] + local % nx[item]
    return item, cell


def candidate_pairs(lo_a, hi_a, lo_b, hi_b) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(i, k)`` of 2-D boxes (a: ``(na, 2)``, b: ``(nb, 2)``) that share a bucket cell.

    Every pair of overlapping boxes is returned (once); some non-overlapping neighbours too.
    The bucket size is the median box extent, so each box touches a few cells.
    """
    lo_a, hi_a, lo_b, hi_b = (np.asarray(x, np.float64).reshape(-1, 2) for x in (lo_a, hi_a, lo_b, hi_b))
    if len(lo_a) == 0 or len(lo_b) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    origin = np.minimum(lo_a.min(0), lo_b.min(0))
    top = np.maximum(hi_a.max(0), hi_b.max(0))
    ext = np.r_[hi_a - lo_a, hi_b - lo_b].max(axis=1)
    size = max(float(np.median(ext)), float((top - origin).max()) / 1024, 1e-12)
    g = int(np.ceil(float((top - origin).max()) / size)) + 1
    ia, ca = _cells(lo_a, hi_a, origin, size, g)
    ib, cb = _cells(lo_b, hi_b, origin, size, g)
    order = np.argsort(cb, kind="stable")
    ib, cb = ib[order], cb[order]
    start = np.searchsorted(cb, ca, side="left")
    stop = np.searchsorted(cb, ca, side="right")
    cnt = stop - start
    pa = np.repeat(ia, cnt)
    pb = ib[np.repeat(start, cnt) + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)]
    if len(pa) == 0:
        return pa, pb
    key = np.unique(pa * len(lo_b) + pb)
    return key // len(lo_b), key % len(lo_b)


def segment_intersections(P0, P1, Q0, Q1, *, eps: float = 1e-12):
    """Intersections of segments ``P0-P1`` (``(np, 2)``) with segments ``Q0-Q1`` (``(nq, 2)``).

    Solves ``P0 + t (P1 - P0) = Q0 + s (Q1 - Q0)``; parallel pairs are skipped.

    Returns
    -------
    ip, iq : (k,) int64
        Indices of intersecting pairs (``0 <= t, s <= 1`` up to ``eps``).
    t, s : (k,) float64
        Parameters along P and Q.
    X : (k, 2) float64
        Intersection points.
    """
    P0, P1, Q0, Q1 = (np.asarray(x, np.float64).reshape(-1, 2) for x in (P0, P1, Q0, Q1))
    ip, iq = candidate_pairs(np.minimum(P0, P1), np.maximum(P0, P1), np.minimum(Q0, Q1), np.maximum(Q0, Q1))
    r = P1[ip] - P0[ip]
    w = Q1[iq] - Q0[iq]
    d = Q0[iq] - P0[ip]
    den = r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0]
    scale = np.linalg.norm(r, axis=1) * np.linalg.norm(w, axis=1)
    ok = np.abs(den) > 1e-12 * np.maximum(scale, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (d[:, 0] * w[:, 1] - d[:, 1] * w[:, 0]) / den
        s = (d[:, 0] * r[:, 1] - d[:, 1] * r[:, 0]) / den
    ok &= (t >= -eps) & (t <= 1 + eps) & (s >= -eps) & (s <= 1 + eps)
    t, s = np.clip(t[ok], 0, 1), np.clip(s[ok], 0, 1)
    ip, iq = ip[ok], iq[ok]
    return ip, iq, t, s, P0[ip] + t[:, None] * (P1[ip] - P0[ip])
