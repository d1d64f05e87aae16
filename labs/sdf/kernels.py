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
    raise NotImplementedError('Task 3 (BVH): BVH query, leaf test: your Task 2 for one point and one triangle, in scalars: Voronoi regions of a, b, c, then edges ab, ca, bc, else the interior (barycentric v = vb/(va+vb+vc), w = vc/(va+vb+vc))')


@njit(cache=True)
def build_bvh_kernel(lo, hi, cen, leaf_size):
    """Median-split BVH over boxes ``lo, hi`` with centroids ``cen`` (all ``(m, 3)``).

    Returns ``(node_lo, node_hi, left, right, start, count, order)``: ``left[k] = -1`` marks a leaf,
    whose triangles are ``order[start[k] : start[k] + count[k]]``. Node 0 is the root; nodes are
    numbered in depth-first order, left child first.
    """
    raise NotImplementedError('Task 3 (BVH): BVH build: stack of (node, start, end); node box = union of its triangle boxes; leaf when end - start <= leaf_size, else sort the range by centroid along the longest centroid-box axis and split at the median')


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
            raise NotImplementedError("Task 3 (BVH): BVH query: best = upper_sq (warm start: first test the previous point's triangle prev, a row of T); pop a node, skip it when its box is at least best away; leaves test their triangles with closest_on_triangle; inner nodes push the children closer than best, the farther first; set prev to the row found; face = order[row]")
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
            raise NotImplementedError('Task 4 (sign): vote: walk the BVH with a slab test per box (t_far >= max(t_near, 0)); count every triangle hit with t > 0')
    return out
