"""Quadric error metrics: the plane quadrics of faces, boundary edges and vertices.

A plane ``p = (a, b, c, d)`` with unit normal ``(a, b, c)`` holds the points ``x`` with
``a x + b y + c z + d = 0``. The squared distance of a point ``v = (x, y, z, 1)`` to it is

    (pᵀ v)² = vᵀ (p pᵀ) v = vᵀ K_p v,

so the *fundamental quadric* ``K_p = p pᵀ`` (a symmetric 4×4 matrix) measures squared distance
to the plane, and a sum of quadrics measures the sum of squared distances to many planes with a
single 4×4 matrix. This is the idea of Garland & Heckbert, "Surface simplification using quadric
error metrics" (SIGGRAPH 1997).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from geomlib import portable
from geomlib.topology import boundary_edges, edge_faces
from geomlib.validate import check_choice, check_float, check_mesh

__all__ = ["face_planes", "face_quadrics", "boundary_quadrics", "crease_quadrics", "vertex_quadrics", "quadric_error"]

WEIGHTINGS = ("area", "uniform")


def face_planes(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Plane of every triangle and its area (a given helper).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64

    Returns
    -------
    P : (m, 4) float64
        ``(a, b, c, d)`` with ``(a, b, c)`` the unit normal ``(v1 - v0) × (v2 - v0) / |…|`` and
        ``d = -(a, b, c) · v0``. Zero-area triangles get ``P = 0`` (they carry no plane).
    A : (m,) float64
        Triangle areas ``|(v1 - v0) × (v2 - v0)| / 2``.
    """
    v0, v1, v2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    c = np.cross(v1 - v0, v2 - v0)
    length = np.linalg.norm(c, axis=1)
    n = np.divide(c, length[:, None], out=np.zeros_like(c), where=length[:, None] > 0)
    d = -np.einsum("ij,ij->i", n, v0)
    return np.concatenate([n, d[:, None]], axis=1), 0.5 * length


def face_quadrics(V, F, weighting: str = "area") -> np.ndarray:
    """Fundamental quadric ``K_f = w_f · p_f p_fᵀ`` of every face.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles.
    weighting : {"area", "uniform"}
        ``"area"``: ``w_f`` = triangle area (big faces count more, and the result does not depend on
        how finely a flat region is triangulated); ``"uniform"``: ``w_f = 1`` (the 1997 paper).

    Returns
    -------
    K : (m, 4, 4) float64
        Symmetric positive semi-definite. ``vᵀ K_f v = w_f · dist(v, plane of f)²`` for
        ``v = (x, y, z, 1)``. Zero-area faces give ``K_f = 0``.

    Examples
    --------
    The triangle in the plane z = 0 with area 1/2 gives ``K = 1/2 · e_z e_zᵀ``:

    >>> K = face_quadrics([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> K[0, 2, 2], K[0].sum()
    (0.5, 0.5)
    """
    V, F = check_mesh(V, F, where="face_quadrics")
    check_choice(weighting, "weighting", WEIGHTINGS, where="face_quadrics")
    P, area = face_planes(V, F)
    # BEGIN SOLUTION: Task 1 (quadrics): K_f = w_f * p pᵀ with p = (n, -n·v0), w_f = area or 1
    w = area if weighting == "area" else np.ones(len(F))
    return w[:, None, None] * P[:, :, None] * P[:, None, :]
    # END SOLUTION


def boundary_quadrics(V, F, weight: float = 1000.0) -> np.ndarray:
    """Penalty quadrics that keep boundary vertices on their boundary curves.

    For every boundary edge ``a → b`` of face ``f`` (unit normal ``n_f``) take the plane through
    ``a`` that contains the edge and is perpendicular to the face: its normal is
    ``m = (b - a) × n_f / |…|``. Its quadric ``weight · |b - a|² · q qᵀ`` with ``q = (m, -m·a)``
    is added to *both* edge ends. Moving a boundary vertex off its boundary then costs about
    ``weight`` times as much as moving it off the surface; the ``|b - a|²`` factor gives the
    penalty the units of an area, like area-weighted face quadrics.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
    weight : float, >= 0

    Returns
    -------
    Q : (n, 4, 4) float64
        Sum of the penalty quadrics at each vertex (zero away from the boundary; all zero for a
        closed mesh).
    """
    V, F = check_mesh(V, F, where="boundary_quadrics")
    weight = check_float(weight, "weight", minimum=0.0, where="boundary_quadrics")
    # Directed boundary edges (a, b) and the face each belongs to (given: topology bookkeeping).
    B = boundary_edges(F)
    if len(B) == 0:
        return np.zeros((len(V), 4, 4))  # a closed mesh: no boundary to protect
    he_face = np.repeat(np.arange(len(F)), 3)
    he = np.stack([F.ravel(), F[:, [1, 2, 0]].ravel()], axis=1)
    n_vertices = len(V)
    he_key = he[:, 0] * n_vertices + he[:, 1]
    order = np.argsort(he_key)
    B_face = he_face[order[np.searchsorted(he_key[order], B[:, 0] * n_vertices + B[:, 1])]]
    P, _ = face_planes(V, F)
    # BEGIN SOLUTION: Task 1 (quadrics): boundary plane normal m = (b - a) × n_f / |…|, K = weight |b - a|² q qᵀ
    a, b = V[B[:, 0]], V[B[:, 1]]
    e = b - a
    m = np.cross(e, P[B_face, :3])
    length = np.linalg.norm(m, axis=1)
    m = np.divide(m, length[:, None], out=np.zeros_like(m), where=length[:, None] > 0)
    q = np.concatenate([m, -np.einsum("ij,ij->i", m, a)[:, None]], axis=1)
    K = (weight * np.einsum("ij,ij->i", e, e))[:, None, None] * q[:, :, None] * q[:, None, :]
    Q = np.zeros((n_vertices, 4, 4))
    np.add.at(Q, B[:, 0], K)
    np.add.at(Q, B[:, 1], K)
    return Q
    # END SOLUTION


def crease_quadrics(V, F, angle_deg: float = 30.0, weight: float = 1.0) -> np.ndarray:
    """Penalty quadrics that keep sharp feature edges (creases) in place (a given helper).

    An interior edge ``a - b`` whose two faces meet at a dihedral angle of more than ``angle_deg``
    (their unit normals ``n_1``, ``n_2`` have ``n_1 · n_2 < cos(angle_deg)``) is a crease. For each
    of its two faces take the plane that contains the edge and is perpendicular to the face (normal
    ``m = (b - a) × n_f / |…|``), as :func:`boundary_quadrics` does for boundary edges, and add
    ``weight · |b - a|² · q qᵀ`` with ``q = (m, -m·a)`` to both edge ends. Together with the face
    quadrics this pins a crease vertex to its crease line, and a corner (where creases meet) to its
    point: the feature-preserving constraint planes of Garland & Heckbert (1997, §6).

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
    angle_deg : float in [0, 180]
        Dihedral angle above which an edge is a crease (0 between coplanar faces).
    weight : float, >= 0

    Returns
    -------
    Q : (n, 4, 4) float64
        Zero away from creases.
    """
    where = "crease_quadrics"
    V, F = check_mesh(V, F, where=where)
    angle_deg = check_float(angle_deg, "angle_deg", minimum=0.0, maximum=180.0, where=where)
    weight = check_float(weight, "weight", minimum=0.0, where=where)
    Q = np.zeros((len(V), 4, 4))
    E, EF = edge_faces(F)
    inner = (EF >= 0).all(axis=1)
    E, EF = E[inner], EF[inner]
    P, _ = face_planes(V, F)
    N1, N2 = P[EF[:, 0], :3], P[EF[:, 1], :3]
    # geomlib.portable's dot (not einsum or BLAS): which edges are creases must not depend on the CPU.
    cos = portable.dot(N1, N2)
    sharp = cos < np.cos(np.radians(angle_deg))
    if weight == 0 or not sharp.any():
        return Q
    E, EF = E[sharp], EF[sharp]
    a, e = V[E[:, 0]], V[E[:, 1]] - V[E[:, 0]]
    e2 = portable.dot(e, e)
    for side in (0, 1):  # the constraint plane of each of the two faces
        m = np.cross(e, P[EF[:, side], :3])
        length = portable.norm(m)
        m = np.divide(m, length[:, None], out=np.zeros_like(m), where=length[:, None] > 0)
        q = np.concatenate([m, -portable.dot(m, a)[:, None]], axis=1)
        K = (weight * e2)[:, None, None] * q[:, :, None] * q[:, None, :]
        np.add.at(Q, E[:, 0], K)
        np.add.at(Q, E[:, 1], K)
    return Q


def vertex_quadrics(V, F, weighting: str = "area", boundary_weight: float = 0.0) -> np.ndarray:
    """Quadric of every vertex: the sum of the quadrics of its faces.

    ``Q_v = Σ_{f ∋ v} K_f`` (plus the boundary penalty quadrics when ``boundary_weight > 0``), so
    ``vᵀ Q_v v`` is the (weighted) sum of squared distances of ``v`` to the planes of the faces
    around the vertex; it is 0 at the vertex's own position.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
    weighting : {"area", "uniform"}
        See :func:`face_quadrics`.
    boundary_weight : float, >= 0
        Weight of :func:`boundary_quadrics`; 0 (default) adds none.

    Returns
    -------
    Q : (n, 4, 4) float64
        Unreferenced vertices get zeros.
    """
    V, F = check_mesh(V, F, where="vertex_quadrics")
    check_choice(weighting, "weighting", WEIGHTINGS, where="vertex_quadrics")
    boundary_weight = check_float(boundary_weight, "boundary_weight", minimum=0.0, where="vertex_quadrics")
    K = face_quadrics(V, F, weighting)
    # BEGIN SOLUTION: Task 1 (quadrics): Q_v = sum of K_f over the faces f around v, + boundary_quadrics(V, F, boundary_weight) when > 0
    # The vertex-face incidence matrix A (A[v, f] = 1 when v is a corner of f) sums the 16 entries
    # of the face quadrics onto the vertices in one sparse product (np.add.at works too, 4x slower).
    m = len(F)
    A = sp.csr_matrix((np.ones(3 * m), (F.ravel(), np.repeat(np.arange(m), 3))), shape=(len(V), m))
    Q = (A @ K.reshape(m, 16)).reshape(len(V), 4, 4)
    if boundary_weight > 0:
        Q += boundary_quadrics(V, F, boundary_weight)
    return Q
    # END SOLUTION


def quadric_error(Q: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``vᵀ Q v`` with ``v = (x, y, z, 1)``, batched (a given helper).

    Parameters
    ----------
    Q : (..., 4, 4) float64
    X : (..., 3) float64
        Points; the leading shapes broadcast.

    Returns
    -------
    (...) float64
    """
    Xh = np.concatenate([X, np.ones((*np.shape(X)[:-1], 1))], axis=-1)
    return np.einsum("...i,...ij,...j->...", Xh, Q, Xh)
