"""Exact point-triangle distance, vectorised over points x triangles, and the brute-force mesh distance (Task 2).

The closest point of a triangle ``abc`` to ``p`` lies in one of seven Voronoi regions of the
triangle: a vertex (3), an edge (3) or the interior (1). Ericson's method (Real-Time Collision
Detection, 5.1.5) decides the region from six dot products ``d1..d6`` and three "barycentric"
areas, testing the vertex regions first, then the edges, and falls through to the interior. The
region matters twice in this lab: it gives the closest point, and it tells the pseudonormal sign
(Task 4) whether to use a face, an edge or a vertex normal.

Region codes: ``0`` interior, ``1, 2, 3`` vertices ``a, b, c``, ``4, 5, 6`` edges ``ab, bc, ca``.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import as_array, check_int, check_mesh

from .analytic import as_points

__all__ = ["REGIONS", "point_triangle_distance", "brute_force_distance"]

#: Names of the region codes.
REGIONS = ("interior", "vertex a", "vertex b", "vertex c", "edge ab", "edge bc", "edge ca")


def point_triangle_distance(P, T) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of every triangle to every point.

    Parameters
    ----------
    P : (n, 3) array_like
        Query points.
    T : (m, 3, 3) array_like
        Triangles, ``T[j] = (a, b, c)``.

    Returns
    -------
    sq_dist : (n, m) float64
        Squared distances ``|p_i - q_ij|^2``.
    closest : (n, m, 3) float64
        The closest points ``q_ij`` on triangle ``j``.
    region : (n, m) int64
        Voronoi region of ``q_ij`` (see :data:`REGIONS`).

    Notes
    -----
    With ``ab = b - a``, ``ac = c - a``, ``ap = p - a`` (and ``bp``, ``cp`` likewise)::

        d1 = ab.ap  d2 = ac.ap   d3 = ab.bp  d4 = ac.bp   d5 = ab.cp  d6 = ac.cp
        vertex a:  d1 <= 0 and d2 <= 0
        vertex b:  d3 >= 0 and d4 <= d3
        edge ab:   vc = d1 d4 - d3 d2 <= 0, d1 >= 0, d3 <= 0      -> a + d1/(d1 - d3) ab
        vertex c:  d6 >= 0 and d5 <= d6
        edge ca:   vb = d5 d2 - d1 d6 <= 0, d2 >= 0, d6 <= 0      -> a + d2/(d2 - d6) ac
        edge bc:   va = d3 d6 - d5 d4 <= 0, d4 - d3 >= 0, d5 - d6 >= 0
                                                 -> b + (d4 - d3)/((d4 - d3) + (d5 - d6)) (c - b)
        interior:  a + ab vb/(va + vb + vc) + ac vc/(va + vb + vc)

    Test the regions **in this order** (each test assumes the earlier ones failed). Vectorised:
    compute every candidate and pick with ``np.select`` in the same order.
    """
    where = "point_triangle_distance"
    P = as_points(P, where)
    T = as_array(T, "T", dtype=np.float64, shape=(None, 3, 3), where=where)
    raise NotImplementedError('Task 2 (point-triangle distance): point-triangle: broadcast P[:, None] against T[None]; d1..d6, va, vb, vc as in the Notes; pick the first true region with np.select (vertex a, vertex b, edge ab, vertex c, edge ca, edge bc, interior)')


def brute_force_distance(V, F, P, *, chunk: int = 1 << 20) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Closest point on a mesh by testing every triangle: the ``O(n m)`` baseline.

    Parameters
    ----------
    V, F : (k, 3) float, (m, 3) int
        The mesh.
    P : (n, 3) array_like
        Query points.
    chunk : int
        Largest number of point-triangle pairs held at once (memory stays ``O(chunk)``).

    Returns
    -------
    sq_dist : (n,) float64
    face : (n,) int64
        Index of the closest triangle; on exact ties the lowest index.
    closest : (n, 3) float64
    region : (n,) int64
        Region of the closest point on that triangle.
    """
    where = "brute_force_distance"
    V, F = check_mesh(V, F, where=where)
    P = as_points(P, where)
    chunk = check_int(chunk, "chunk", minimum=1, where=where)
    T = V[F]
    n = len(P)
    sq, face = np.empty(n), np.empty(n, np.int64)
    C, region = np.empty((n, 3)), np.empty(n, np.int64)
    if n == 0:
        return sq, face, C, region
    step = max(1, chunk // len(F))
    raise NotImplementedError('Task 2 (point-triangle distance): mesh distance: for chunks of `step` points: point_triangle_distance against all triangles, then argmin over triangles (the first on ties)')
