"""Compiled kernels of the lab: the BVH build, closest-point walks and ray-crossing counts (Tasks 3 and 4).

These are tree walks: one point follows its own path through the hierarchy, so they cannot be
written as whole-array NumPy operations without either wasting work (every point visits every
level) or memory (the prototype's level-by-level NumPy walk took 2.8-5.4 GB). They are written as
plain loops and compiled with numba (``@njit(cache=True)``: compiled once, then loaded from the
``__pycache__`` folder by every later process). With ``NUMBA_DISABLE_JIT=1`` the same functions run
as ordinary Python, which is how you debug them (slowly: use a few points).

Region codes of the closest point on a triangle ``(a, b, c)``: ``0`` interior, ``1, 2, 3`` the
vertices ``a, b, c``, ``4, 5, 6`` the edges ``ab, bc, ca``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from geomlib.jit import use_cache_folder

# numba's cache refers to this module by its import name, and the grader imports the lab under
# another name than your notebook does: one cache folder per import name (given; see geomlib.jit).
use_cache_folder(__name__, __file__)

STACK = 128  # deeper than any median-split tree over < 2**100 triangles needs
BLOCK = 64  # consecutive query points walked by one thread, warm-started from each other


@njit(cache=True)
def closest_on_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point on one triangle and its Voronoi region (Ericson, Real-Time Collision Detection, 5.1.5).

    Returns ``(qx, qy, qz, region)``.
    """
    # BEGIN SOLUTION: Task 3 (BVH): BVH query, leaf test: your Task 2 for one point and one triangle, in scalars: Voronoi regions of a, b, c, then edges ab, ca, bc, else the interior (barycentric v = vb/(va+vb+vc), w = vc/(va+vb+vc))
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az, 1
    bpx, bpy, bpz = px - bx, py - by, pz - bz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz, 2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz, 4
    cpx, cpy, cpz = px - cx, py - cy, pz - cz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz, 3
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz, 6
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz), 5
    denom = va + vb + vc
    if denom <= 0.0:  # zero-area triangle that no edge test caught: fall back to vertex a
        return ax, ay, az, 1
    v = vb / denom
    w = vc / denom
    return ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w, 0
    # END SOLUTION


@njit(cache=True)
def build_bvh_kernel(lo, hi, cen, leaf_size):
    """Median-split BVH over boxes ``lo, hi`` with centroids ``cen`` (all ``(m, 3)``).

    Returns ``(node_lo, node_hi, left, right, start, count, order)``: ``left[k] = -1`` marks a leaf,
    whose triangles are ``order[start[k] : start[k] + count[k]]``. Node 0 is the root; nodes are
    numbered in depth-first order, left child first.
    """
    # BEGIN SOLUTION: Task 3 (BVH): BVH build: stack of (node, start, end); node box = union of its triangle boxes; leaf when end - start <= leaf_size, else sort the range by centroid along the longest centroid-box axis and split at the median
    m = lo.shape[0]
    cap = 2 * m + 1
    node_lo = np.empty((cap, 3))
    node_hi = np.empty((cap, 3))
    left = np.full(cap, -1, np.int64)
    right = np.full(cap, -1, np.int64)
    start = np.zeros(cap, np.int64)
    count = np.zeros(cap, np.int64)
    order = np.arange(m)
    stack = np.empty((STACK, 3), np.int64)
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, 0, m
    top = 1
    n_nodes = 1
    while top > 0:
        top -= 1
        k, s, e = stack[top, 0], stack[top, 1], stack[top, 2]
        cmin = np.full(3, np.inf)
        cmax = np.full(3, -np.inf)
        for a in range(3):
            node_lo[k, a] = np.inf
            node_hi[k, a] = -np.inf
        for j in range(s, e):
            t = order[j]
            for a in range(3):
                node_lo[k, a] = min(node_lo[k, a], lo[t, a])
                node_hi[k, a] = max(node_hi[k, a], hi[t, a])
                cmin[a] = min(cmin[a], cen[t, a])
                cmax[a] = max(cmax[a], cen[t, a])
        start[k] = s
        count[k] = e - s
        if e - s <= leaf_size:
            continue
        ext = cmax - cmin
        axis = 0
        if ext[1] > ext[axis]:
            axis = 1
        if ext[2] > ext[axis]:
            axis = 2
        seg = order[s:e].copy()
        keys = cen[seg, axis]
        order[s:e] = seg[np.argsort(keys, kind="mergesort")]
        mid = (s + e) // 2
        l_id, r_id = n_nodes, n_nodes + 1
        n_nodes += 2
        left[k], right[k] = l_id, r_id
        stack[top, 0], stack[top, 1], stack[top, 2] = r_id, mid, e
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = l_id, s, mid
        top += 2
    return (
        node_lo[:n_nodes].copy(),
        node_hi[:n_nodes].copy(),
        left[:n_nodes].copy(),
        right[:n_nodes].copy(),
        start[:n_nodes].copy(),
        count[:n_nodes].copy(),
        order,
    )
    # END SOLUTION


@njit(cache=True, inline="always")
def _corners(T, j):
    return T[j, 0], T[j, 1], T[j, 2], T[j, 3], T[j, 4], T[j, 5], T[j, 6], T[j, 7], T[j, 8]


@njit(cache=True, inline="always")
def box_sq_dist(px, py, pz, node_lo, node_hi, k):
    """Squared distance from a point to the box of node ``k`` (0 inside)."""
    dx = max(node_lo[k, 0] - px, 0.0, px - node_hi[k, 0])
    dy = max(node_lo[k, 1] - py, 0.0, py - node_hi[k, 1])
    dz = max(node_lo[k, 2] - pz, 0.0, pz - node_hi[k, 2])
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, parallel=True)
def closest_kernel(P, T, node_lo, node_hi, left, right, start, count, order, upper_sq):
    """Closest point on the mesh for each row of ``P``, searching only within ``sqrt(upper_sq)``.

    ``T (m, 9)`` holds the corners of the triangles **in leaf order**: row ``j`` is triangle
    ``order[j]`` as ``(ax, ay, az, bx, by, bz, cx, cy, cz)`` (contiguous memory for the leaf loop).

    Returns ``(sq_dist, face, closest, region)``; points with nothing closer than the bound get
    ``sq_dist = upper_sq``, ``face = -1``, region ``-1`` and their own position as closest point.

    Points are processed in blocks of :data:`BLOCK` consecutive rows (in parallel over blocks).
    Consecutive rows are usually neighbours (grid samples, pixels), so each point first measures the
    triangle that was closest to the previous point of its block: that warm start makes ``best``
    small from the beginning, and the walk prunes far more.
    """
    n = P.shape[0]
    sq = np.empty(n)
    face = np.empty(n, np.int64)
    C = np.empty((n, 3))
    region = np.empty(n, np.int64)
    n_blocks = (n + BLOCK - 1) // BLOCK
    for blk in prange(n_blocks):
        stack = np.empty(STACK, np.int64)
        prev = -1
        for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):  # noqa: B007 (its body is your task)
            # BEGIN SOLUTION: Task 3 (BVH): BVH query: best = upper_sq (warm start: first test the previous point's triangle prev, a row of T); pop a node, skip it when its box is at least best away; leaves test their triangles with closest_on_triangle; inner nodes push the children closer than best, the farther first; set prev to the row found; face = order[row]
            px, py, pz = P[i, 0], P[i, 1], P[i, 2]
            best = upper_sq
            bf = -1
            bx, by, bz = px, py, pz
            br = -1
            if prev >= 0:
                qx, qy, qz, r = closest_on_triangle(px, py, pz, *_corners(T, prev))
                d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
                if d < best:
                    best, bf, bx, by, bz, br = d, prev, qx, qy, qz, r
            stack[0] = 0
            top = 1
            while top > 0:
                top -= 1
                k = stack[top]
                if box_sq_dist(px, py, pz, node_lo, node_hi, k) >= best:
                    continue
                if left[k] < 0:
                    for j in range(start[k], start[k] + count[k]):
                        qx, qy, qz, r = closest_on_triangle(px, py, pz, *_corners(T, j))
                        d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
                        if d < best:
                            best, bf, bx, by, bz, br = d, j, qx, qy, qz, r
                else:
                    lk, rk = left[k], right[k]
                    dl = box_sq_dist(px, py, pz, node_lo, node_hi, lk)
                    dr = box_sq_dist(px, py, pz, node_lo, node_hi, rk)
                    if dl > dr:
                        lk, rk, dl, dr = rk, lk, dr, dl
                    if dr < best:  # farther child first, so the nearer one is popped next
                        stack[top] = rk
                        top += 1
                    if dl < best:
                        stack[top] = lk
                        top += 1
            sq[i], face[i], region[i] = best, order[bf] if bf >= 0 else -1, br
            C[i, 0], C[i, 1], C[i, 2] = bx, by, bz
            if bf >= 0:
                prev = bf
            # END SOLUTION
    return sq, face, C, region


@njit(cache=True)
def ray_triangle_t(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Möller-Trumbore: the ray parameter of the hit with triangle ``abc``, or ``-1`` when there is none."""
    e1x, e1y, e1z = bx - ax, by - ay, bz - az
    e2x, e2y, e2z = cx - ax, cy - ay, cz - az
    hx, hy, hz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * hx + e1y * hy + e1z * hz
    if det == 0.0:
        return -1.0
    inv = 1.0 / det
    sx, sy, sz = ox - ax, oy - ay, oz - az
    u = (sx * hx + sy * hy + sz * hz) * inv
    if u < 0.0 or u > 1.0:
        return -1.0
    qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return -1.0
    return (e2x * qx + e2y * qy + e2z * qz) * inv


@njit(cache=True, parallel=True)
def crossings_kernel(P, D, V, F, node_lo, node_hi, left, right, start, count, order):
    """Number of triangles each ray ``P[i] + t D[j]`` (``t > 0``) crosses: ``(n, k)`` int64."""
    n, k = P.shape[0], D.shape[0]
    out = np.zeros((n, k), np.int64)
    for i in prange(n):  # noqa: B007 (its body is your task)
        stack = np.empty(STACK, np.int64)
        for j in range(k):  # noqa: B007
            # BEGIN SOLUTION: Task 4 (sign): vote: walk the BVH with a slab test per box (t_far >= max(t_near, 0)); count every triangle hit with t > 0
            ox, oy, oz = P[i, 0], P[i, 1], P[i, 2]
            dx, dy, dz = D[j, 0], D[j, 1], D[j, 2]
            ix = 1.0 / dx if dx != 0.0 else np.inf
            iy = 1.0 / dy if dy != 0.0 else np.inf
            iz = 1.0 / dz if dz != 0.0 else np.inf
            c = 0
            stack[0] = 0
            top = 1
            while top > 0:
                top -= 1
                nd = stack[top]
                t0x, t1x = (node_lo[nd, 0] - ox) * ix, (node_hi[nd, 0] - ox) * ix
                t0y, t1y = (node_lo[nd, 1] - oy) * iy, (node_hi[nd, 1] - oy) * iy
                t0z, t1z = (node_lo[nd, 2] - oz) * iz, (node_hi[nd, 2] - oz) * iz
                tn = max(min(t0x, t1x), min(t0y, t1y), min(t0z, t1z))
                tf = min(max(t0x, t1x), max(t0y, t1y), max(t0z, t1z))
                if tf < max(tn, 0.0):
                    continue
                if left[nd] < 0:
                    for q in range(start[nd], start[nd] + count[nd]):
                        t = order[q]
                        a, b, cc = F[t, 0], F[t, 1], F[t, 2]
                        th = ray_triangle_t(
                            ox, oy, oz, dx, dy, dz,
                            V[a, 0], V[a, 1], V[a, 2], V[b, 0], V[b, 1], V[b, 2], V[cc, 0], V[cc, 1], V[cc, 2],
                        )  # fmt: skip
                        if th > 0.0:
                            c += 1
                else:
                    stack[top] = left[nd]
                    stack[top + 1] = right[nd]
                    top += 2
            out[i, j] = c
            # END SOLUTION
    return out
