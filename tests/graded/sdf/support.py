"""Inputs and checks shared by the graded tests of the lab "sdf" (built from geomlib, NumPy and libigl only).

Nothing here calls the lab: closest points come from libigl, BVHs from a small median split written
here, grids from closed-form fields, brick tables are random. So each case tests one task.
"""

from __future__ import annotations

import igl
import numpy as np

from geomlib import datasets, portable
from geomlib.grading.checks import Context, as_output_array

# ------------------------------------------------------------------------------------ meshes


def torus_small():
    return datasets.torus(1.0, 0.35, 24, 12)


def sphere_small():
    return datasets.icosphere(1)


def box_mesh():
    return datasets.sharp_box((1.0, 0.8, 0.6), n=2)


def wedge():
    """A closed, thin concave solid: an L-shaped prism (sharp convex and concave edges)."""
    P2 = np.array([[0, 0], [2, 0], [2, 0.3], [0.3, 0.3], [0.3, 1.5], [0, 1.5]], float)
    n = len(P2)
    V = np.vstack([np.c_[P2, np.zeros(n)], np.c_[P2, np.full(n, 0.8)]])
    side = []
    for i in range(n):
        j = (i + 1) % n
        side += [[i, j, n + j], [i, n + j, n + i]]
    bottom = [[0, 3, 1], [1, 3, 2], [0, 5, 4], [0, 4, 3]]
    top = [[n + a, n + b, n + c] for a, c, b in bottom]
    return V, np.array(side + bottom + top, np.int64)


def thin_prism():
    """A closed prism over a 20-degree sliver triangle: its sharp edge fools the face-normal sign."""
    T = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0 * portable.tan(np.radians(20))]])
    V = np.vstack([np.c_[T, np.zeros(3)], np.c_[T, np.full(3, 0.5)]])
    F = [[0, 2, 1], [3, 4, 5]]
    for i in range(3):
        j = (i + 1) % 3
        F += [[i, j, 3 + j], [i, 3 + j, 3 + i]]
    return V, np.array(F, np.int64)


def random_points(V, n, seed, margin=0.3):
    rng = np.random.default_rng(seed)
    lo, hi = V.min(0) - margin, V.max(0) + margin
    return lo + rng.random((n, 3)) * (hi - lo)


# ------------------------------------------------------------------- closest points (libigl)


def closest_with_regions(V, F, P):
    """Closest face, point and Voronoi region with libigl's AABB tree and barycentric coordinates."""
    sq, face, C = igl.point_mesh_squared_distance(P, V, F)
    face = np.asarray(face, np.int64).ravel()
    T = V[F[face]]
    B = igl.barycentric_coordinates(C, T[:, 0].copy(), T[:, 1].copy(), T[:, 2].copy())
    zero = B < 1e-9
    nz = zero.sum(axis=1)
    region = np.zeros(len(P), np.int64)
    vert = nz >= 2
    region[vert] = 1 + np.argmax(~zero[vert], axis=1)
    edge = nz == 1
    # the zero coordinate is opposite the edge: 0 -> bc (5), 1 -> ca (6), 2 -> ab (4)
    region[edge] = np.array([5, 6, 4])[np.argmax(zero[edge], axis=1)]
    return face, np.asarray(C, np.float64), region


# --------------------------------------------------------------------------------- BVH


def simple_bvh(V, F, leaf_size=4):
    """A valid median-split BVH written independently of the lab (Python recursion, small meshes only)."""
    T = V[F]
    tl, th, cen = T.min(1), T.max(1), T.mean(1)
    nodes = []  # (lo, hi, left, right, start, count)
    order = []

    def build(idx):
        k = len(nodes)
        nodes.append(None)
        start = len(order)
        lo, hi = tl[idx].min(0), th[idx].max(0)
        if len(idx) <= leaf_size:
            order.extend(idx.tolist())
            nodes[k] = (lo, hi, -1, -1, start, len(idx))
            return k
        ax = int(np.argmax(np.ptp(cen[idx], axis=0)))
        s = idx[np.argsort(cen[idx, ax], kind="stable")]
        a = build(s[: len(s) // 2])
        b = build(s[len(s) // 2 :])
        nodes[k] = (lo, hi, a, b, start, len(idx))
        return k

    build(np.arange(len(F)))
    lo, hi, left, right, start, count = zip(*nodes, strict=True)
    return {
        "lo": np.array(lo),
        "hi": np.array(hi),
        "left": np.array(left, np.int64),
        "right": np.array(right, np.int64),
        "start": np.array(start, np.int64),
        "count": np.array(count, np.int64),
        "order": np.array(order, np.int64),
    }


def check_bvh(bvh, V, F, leaf_size: int | None = None) -> str | None:
    """Why ``bvh`` is not a valid BVH of ``(V, F)``, or ``None`` (given; used by the graded tests).

    Checks: array shapes; ``order`` is a permutation; every leaf's range lies inside ``order`` and
    the leaves cover every triangle exactly once; every node's box holds all triangles below it;
    every inner node's children exist and their ranges split the parent's range.
    """
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    m = len(F)
    if isinstance(bvh, dict):
        bvh = type("BVH", (), bvh)
    try:
        lo, hi = np.asarray(bvh.lo, float), np.asarray(bvh.hi, float)
        left, right = np.asarray(bvh.left, np.int64), np.asarray(bvh.right, np.int64)
        start, count = np.asarray(bvh.start, np.int64), np.asarray(bvh.count, np.int64)
        order = np.asarray(bvh.order, np.int64)
    except Exception as e:  # a student object without the fields
        return f"the BVH lacks a field (lo, hi, left, right, start, count, order) or one is not numeric ({e})"
    k = len(lo)
    if k == 0 or hi.shape != (k, 3) or lo.shape != (k, 3):
        return f"lo and hi must be (k, 3) with k >= 1, got {lo.shape} and {hi.shape}"
    for name, a in (("left", left), ("right", right), ("start", start), ("count", count)):
        if a.shape != (k,):
            return f"{name} has shape {a.shape}, expected ({k},)"
    if order.shape != (m,) or not np.array_equal(np.sort(order), np.arange(m)):
        return "order is not a permutation of the triangle indices"
    leaf = left < 0
    if np.any((right < 0) != leaf):
        return "a node has exactly one child"
    inner = np.flatnonzero(~leaf)
    if np.any((left[inner] >= k) | (right[inner] >= k) | (left[inner] == 0) | (right[inner] == 0)):
        return "a child index is out of range"
    if np.any((start < 0) | (count < 0) | (start + count > m)):
        return "a node's triangle range leaves order"
    if start[0] != 0 or count[0] != m:
        return f"the root must cover all {m} triangles (start 0, count {m})"
    li, ri = left[inner], right[inner]
    if np.any(start[li] != start[inner]) or np.any(start[ri] != start[li] + count[li]):
        return "the children's ranges do not split the parent's range"
    if np.any(count[li] + count[ri] != count[inner]) or np.any(count[li] == 0) or np.any(count[ri] == 0):
        return "the children's ranges do not split the parent's range (or one is empty)"
    if leaf_size is not None and np.any(count[leaf] > leaf_size):
        return f"a leaf holds {int(count[leaf].max())} triangles, more than leaf_size={leaf_size}"
    cover = np.zeros(m, np.int64)
    for s, c in zip(start[leaf], count[leaf], strict=True):  # checking only: a loop over leaves is fine
        cover[s : s + c] += 1
    if np.any(cover != 1):
        return "the leaves do not cover every triangle exactly once"
    # every node's box must hold its triangles: check at the leaves and box nesting above them
    T = V[F]
    tl, th = T.min(axis=1), T.max(axis=1)
    slack = 1e-12 * (1 + np.abs(V).max())
    node_of = np.repeat(np.flatnonzero(leaf), count[leaf])
    tri = order[np.concatenate([np.arange(s, s + c) for s, c in zip(start[leaf], count[leaf], strict=True)])]
    if np.any(tl[tri] < lo[node_of] - slack) or np.any(th[tri] > hi[node_of] + slack):
        return "a leaf's box does not hold one of its triangles"
    for ch in (li, ri):
        if np.any(lo[ch] < lo[inner] - slack) or np.any(hi[ch] > hi[inner] + slack):
            return "a child's box sticks out of its parent's box"
    return None


# ------------------------------------------------------------------------------- fields


def sphere_grid(n, radius=0.7, center=(0.05, -0.03, 0.02), lo=-1.0, hi=1.0):
    """A closed-form sphere field sampled on an n^3 grid over [lo, hi]^3: (values, origin, spacing)."""
    x = np.linspace(lo, hi, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    c = np.asarray(center)
    values = np.sqrt((X - c[0]) ** 2 + (Y - c[1]) ** 2 + (Z - c[2]) ** 2) - radius
    return values, np.full(3, lo), (hi - lo) / (n - 1)


def random_bricks(table_shape, n_stored, seed):
    """Random uint8 bricks and a table mixing stored rows and both sentinels (independent of Task 5)."""
    rng = np.random.default_rng(seed)
    codes = rng.integers(0, 256, size=(n_stored, 8, 8, 8), dtype=np.uint8)
    nb = int(np.prod(table_shape))
    table = rng.choice([-1, -2], size=nb).astype(np.int32)
    table[rng.permutation(nb)[:n_stored]] = np.arange(n_stored, dtype=np.int32)
    return codes, table.reshape(table_shape)


def scene(kind="balls"):
    """Scene dicts of spheres and planes (evaluated by the lab's given ``scene_distance``)."""
    if kind == "balls":
        return {
            "spheres": np.array([[0.0, 0.0, 0.5, 0.5], [1.1, 0.4, 0.35, 0.35]]),
            "planes": np.array([[0.0, 0.0, 1.0, 0.0]]),
        }
    return {
        "spheres": np.array([[-0.6, 0.2, 0.7, 0.45], [0.5, -0.5, 0.3, 0.3], [0.4, 0.6, 0.9, 0.25]]),
        "planes": np.array([[0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, -1.5]]),
    }


# ------------------------------------------------------------------------------- checks


def close_outputs(names, atol):
    """Allclose on some outputs only (others, e.g. the face on ties, are not compared)."""

    def fn(expected, got, ctx: Context):
        from geomlib.grading.checks import compare_arrays

        for name in names:
            e = np.asarray(expected[name])
            g = as_output_array(got.get(name), name, ctx, like=e)
            compare_arrays(name, e, g, ctx, atol=atol)

    return fn


def close_with_inf(name, atol):
    """Allclose where ``inf`` (a miss) must sit exactly where the reference has it."""

    def fn(expected, got, ctx: Context):
        from geomlib.grading.checks import compare_arrays

        e = np.asarray(expected[name], np.float64)
        try:
            g = np.asarray(got.get(name), np.float64)
        except (TypeError, ValueError):
            return f"{name} is not a numeric array"
        if g.shape != e.shape:
            return f"{name} has shape {g.shape}, expected {e.shape}"
        inf_e, inf_g = np.isinf(e), np.isinf(g)
        if np.any(inf_e != inf_g):
            r = int(np.flatnonzero(inf_e != inf_g)[0])
            return f"{name}[{r}] expected {e[r]:.6g}, got {g[r]:.6g} (misses must be inf, hits finite)"
        if np.any(np.isnan(g)):
            return f"{name} contains NaN (row {int(np.flatnonzero(np.isnan(g))[0])})"
        compare_arrays(name, e[~inf_e], g[~inf_e], ctx, atol=atol)

    return fn
