"""Normals and per-corner vertex attributes: smooth, flat and crease-preserving shading."""

from __future__ import annotations

import numpy as np

__all__ = ["unit", "vertex_normals", "crease_normals", "srgb_to_linear"]


def unit(v: np.ndarray, eps: float = 1e-300) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, eps)


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    # pyrender's lit shader writes pow(linear, 1/2.2); inverting that exactly keeps colours as given.
    return np.asarray(c, dtype=np.float64) ** 2.2


def vertex_normals(n: int, T: np.ndarray, tri_n: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals from unnormalised triangle normals ``tri_n`` (twice the area)."""
    acc = np.zeros((n, 3))
    for k in range(3):
        for c in range(3):
            acc[:, c] += np.bincount(T[:, k], weights=tri_n[:, c], minlength=n)
    return acc


def crease_normals(T: np.ndarray, tri_n: np.ndarray, vert_n: np.ndarray, crease_deg: float) -> np.ndarray | None:
    """Per-corner normals ``(3m, 3)`` that keep edges sharper than ``crease_deg`` sharp.

    Each corner averages (area-weighted) the faces around its vertex whose normal is within
    ``crease_deg`` of its own face's. Where every face around a vertex lies within half that angle
    of the vertex normal, all pairs pass and the result is the vertex normal, so only the other
    vertices are worked out pair by pair. Returns None when no vertex needs splitting, or when the
    pairs would take too much memory (then plain vertex normals are used).
    """
    vc = T.ravel()
    fc = np.repeat(np.arange(len(T)), 3)
    un = unit(tri_n)
    close = np.einsum("ij,ij->i", un[fc], unit(vert_n)[vc]) >= np.cos(np.radians(crease_deg / 2))
    simple = np.ones(len(vert_n), dtype=bool)
    simple[vc[~close]] = False
    cand = np.flatnonzero(~simple[vc])  # corners at vertices that may need split normals
    if len(cand) == 0:
        return None
    order = cand[np.argsort(vc[cand], kind="stable")]
    sorted_v = vc[order]
    first = np.searchsorted(sorted_v, sorted_v)  # where each corner's vertex group starts in `order`
    d = np.bincount(sorted_v)[sorted_v]  # size of that group
    total = int(np.sum(d))
    if total > 3e7:
        return None
    # All ordered pairs (a, b) of corners at the same vertex.
    a = np.repeat(order, d)
    b = order[np.repeat(first, d) + np.arange(total) - np.repeat(np.cumsum(d) - d, d)]
    keep = np.einsum("ij,ij->i", un[fc[a]], un[fc[b]]) >= np.cos(np.radians(crease_deg)) - 1e-9
    a, fb = a[keep], fc[b[keep]]
    out = vert_n[vc].copy()
    for c in range(3):
        out[cand, c] = np.bincount(a, weights=tri_n[fb, c], minlength=len(vc))[cand]
    return out
