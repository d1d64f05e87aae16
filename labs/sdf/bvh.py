"""A bounding-volume hierarchy over triangles and closest-point queries through it (Task 3).

The BVH is stored as flat arrays (no node objects), the layout a GPU or a compiled loop wants:
node boxes ``lo, hi``, children ``left, right`` (``-1`` for a leaf) and, for leaves, a range
``start, count`` into ``order``, the triangle indices sorted so that every leaf's triangles are
contiguous. A closest-point query walks it with a stack, skipping every node whose box is farther
than the best distance found so far, and visits the nearer child first so the best distance shrinks
early. For ``n`` points and ``m`` triangles this is ``O(n log m)`` in practice, against ``O(n m)``
for the brute force of Task 2.

A *narrow band* of radius ``r`` starts the search with ``best = r^2``: nodes farther than ``r`` are
never opened, and points with nothing within ``r`` come back with ``face = -1``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.validate import MeshError, check_float, check_int, check_mesh

from .analytic import as_points

__all__ = ["BVH", "bvh_arrays", "build_bvh", "bvh_closest"]


@dataclass(frozen=True)
class BVH:
    """Flat-array BVH (see the module docstring). ``k`` nodes over ``m`` triangles.

    Attributes
    ----------
    lo, hi : (k, 3) float64
        Node boxes.
    left, right : (k,) int64
        Children; ``-1`` for leaves.
    start, count : (k,) int64
        Range of the node's triangles in ``order`` (every node has one; leaves use it).
    order : (m,) int64
        Triangle indices in leaf order.
    """

    lo: np.ndarray
    hi: np.ndarray
    left: np.ndarray
    right: np.ndarray
    start: np.ndarray
    count: np.ndarray
    order: np.ndarray


def bvh_arrays(bvh) -> tuple:
    """The seven arrays of a :class:`BVH` (or any object or dict with its fields), in kernel dtypes (given)."""
    names = ("lo", "hi", "left", "right", "start", "count", "order")
    try:
        raw = [bvh[k] if isinstance(bvh, dict) else getattr(bvh, k) for k in names]
    except (KeyError, AttributeError) as e:
        raise MeshError(f"bvh must have the fields {', '.join(names)}; missing {e}") from None
    return tuple(np.ascontiguousarray(a, np.float64 if i < 2 else np.int64) for i, a in enumerate(raw))


def build_bvh(V, F, leaf_size: int = 4) -> BVH:
    """Build a median-split BVH over the triangles of ``(V, F)``.

    Parameters
    ----------
    V : (n, 3) array_like
    F : (m, 3) array_like of int
    leaf_size : int
        Largest number of triangles in a leaf (1 .. 64).

    Returns
    -------
    BVH
        Node 0 is the root. Each node's box is the smallest box holding its triangles; a node with
        more than ``leaf_size`` triangles is split at the median centroid along the longest axis of
        its centroids' box.

    Notes
    -----
    The build itself is in :func:`kernels.build_bvh_kernel` (Task 3, compiled with numba). Here the
    per-triangle boxes and centroids are computed with NumPy and handed over.
    """
    where = "build_bvh"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    leaf_size = check_int(leaf_size, "leaf_size", minimum=1, maximum=64, where=where)
    from . import kernels

    T = V[F]
    return BVH(*kernels.build_bvh_kernel(T.min(axis=1), T.max(axis=1), T.mean(axis=1), leaf_size))


def bvh_closest(
    bvh: BVH, V, F, P, *, band: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Closest point on the mesh to every query point, through the BVH (Task 3, compiled kernel).

    Parameters
    ----------
    bvh : BVH
        From :func:`build_bvh` on the same ``(V, F)``.
    V, F : the mesh
    P : (n, 3) array_like
    band : float, optional
        Search radius ``r > 0``: only closer triangles are found; the rest get ``sq_dist = r^2`` and
        ``face = -1``.

    Returns
    -------
    sq_dist : (n,) float64
    face : (n,) int64
        Closest triangle (on exact ties the lowest index among the tied leaves visited first); ``-1``
        outside the band.
    closest : (n, 3) float64
        Closest points (``P`` itself outside the band).
    region : (n,) int64
        Voronoi region of the closest point (see ``triangle.REGIONS``); ``-1`` outside the band.
    """
    where = "bvh_closest"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    P = as_points(P, where)
    upper = np.inf
    if band is not None:
        band = check_float(band, "band", positive=True, where=where)
        upper = band * band
    from . import kernels

    arrays = bvh_arrays(bvh)
    T = np.ascontiguousarray(V[F[arrays[-1]]].reshape(-1, 9))  # corners in leaf order
    return kernels.closest_kernel(P, T, *arrays, upper)
