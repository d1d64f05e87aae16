"""Catmull-Clark subdivision of polygon meshes (triangles, quads, pentagons, ... mixed).

One step adds a *face point* per face and an *edge point* per edge, moves every old vertex to
its *vertex point*, and replaces every ``k``-gon by ``k`` quads (one per corner). After one step
all faces are quads; vertices of valence != 4 ("extraordinary" vertices) stay extraordinary and
no new ones appear, so their number is constant from level 1 on. On regular quad regions the
scheme is uniform bicubic B-spline refinement.

Vertex order (the convention of this lab): vertex points ``0..n-1`` (old indices), then edge
points ``n + i`` for edge ``i`` of :func:`geomlib.topology.unique_edges`, then face points
``n + e + f``. Quad ``j`` comes from corner ``j`` of the ragged face list.

References
----------
E. Catmull and J. Clark, *Recursively generated B-spline surfaces on arbitrary topological
meshes*, Computer-Aided Design 10(6), 1978.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_faces, as_vertices, check_int, check_polygon_mesh

from .connectivity import MeshTopology, mesh_topology

__all__ = [
    "polygon_topology",
    "scatter_sum",
    "cc_face_points",
    "cc_edge_points",
    "cc_vertex_points",
    "cc_quads",
    "catmull_clark_step",
    "catmull_clark",
]


def polygon_topology(V, faces, *, where: str = "polygon_topology") -> tuple[np.ndarray, MeshTopology]:
    """Validate a polygon mesh and compute its connectivity (given).

    Parameters
    ----------
    V : (n, 3) array_like of float
    faces : (m, k) int array, list of index sequences (mixed sizes), or ``(idx, off)`` ragged pair
        Manifold, consistently oriented polygons with at least 3 corners each.
    where : str
        Name of the calling function for error messages.

    Returns
    -------
    V : (n, 3) float64
    topo : MeshTopology
        ``topo.idx``/``topo.off`` ragged faces, ``topo.he_face``/``topo.he_edge`` the face and edge of
        every half-edge (= corner), ``topo.E``, ``topo.EF`` the faces on both sides of every edge
        (``-1`` on the boundary), ``topo.boundary_edge``, ``topo.boundary_vertex``, ``topo.valence``.
    """
    if isinstance(faces, tuple) and len(faces) == 2 and isinstance(faces[1], np.ndarray) and faces[1].ndim == 1:
        idx, off = faces  # a ragged (idx, off) pair: validate it as a list of polygons
        faces = np.split(np.asarray(idx), np.asarray(off)[1:-1])
    if isinstance(faces, np.ndarray) and faces.ndim == 2 and faces.dtype != object:
        # Same checks as check_polygon_mesh, vectorised for (m, k) arrays; duplicate faces are
        # caught by mesh_topology's orientation check.
        V = as_vertices(V, where=where)
        if faces.shape[1] < 3:
            raise MeshError(f"{where}: faces has shape {faces.shape}; a polygon needs at least 3 vertices")
        F = as_faces(faces, len(V), name="faces", k=None, allow_duplicate=True, where=where)
        if len(F) == 0:
            raise MeshError(f"{where}: faces is empty, expected at least one polygon")
        return V, mesh_topology(F, len(V), where=where, name="faces")
    V, idx, off = check_polygon_mesh(V, faces, where=where)
    return V, mesh_topology((idx, off), len(V), where=where, name="faces")


def scatter_sum(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Sum rows of ``values`` into ``n`` bins (given): ``out[index[j]] += values[j]``.

    Parameters
    ----------
    index : (k,) int
    values : (k, d) float
    n : int

    Returns
    -------
    out : (n, d) float64
        Same as ``np.add.at(out, index, values)`` but one ``np.bincount`` per column (much faster).
    """
    values = np.asarray(values, dtype=np.float64)
    return np.stack([np.bincount(index, weights=values[:, c], minlength=n) for c in range(values.shape[1])], axis=1)


def cc_face_points(V, faces, *, topo: MeshTopology | None = None) -> np.ndarray:
    """Face points: the centroid of every face.

    Parameters
    ----------
    V : (n, 3) array_like of float
    faces : (m, k) int array or list of polygons
    topo : MeshTopology, optional
        Connectivity from :func:`polygon_topology` (computed when omitted).

    Returns
    -------
    FP : (m, 3) float64
        ``FP[f] = (1/k_f) * sum of the k_f corners of face f``.
    """
    if topo is None:
        V, topo = polygon_topology(V, faces, where="cc_face_points")
    V = np.asarray(V, dtype=np.float64)
    idx, off = topo.idx, topo.off
    raise NotImplementedError('Task 6 (face points): FP[f] = mean of the corners of face f (faces may have any size)')


def cc_edge_points(V, faces, face_points=None, *, topo: MeshTopology | None = None) -> np.ndarray:
    """Edge points, one per edge in ``topo.E`` order.

    Parameters
    ----------
    V : (n, 3) array_like of float
    faces : (m, k) int array or list of polygons
    face_points : (m, 3) array_like of float, optional
        From :func:`cc_face_points` (computed when omitted).
    topo : MeshTopology, optional

    Returns
    -------
    EP : (e, 3) float64
        - interior edge ``(a, b)`` between faces ``f0``, ``f1``: ``(a + b + FP[f0] + FP[f1]) / 4``;
        - boundary edge: the midpoint ``(a + b) / 2`` (the boundary is refined as a cubic B-spline curve).
    """
    if topo is None:
        V, topo = polygon_topology(V, faces, where="cc_edge_points")
    V = np.asarray(V, dtype=np.float64)
    FP = cc_face_points(V, faces, topo=topo) if face_points is None else np.asarray(face_points, dtype=np.float64)
    E, EF = topo.E, topo.EF
    inner = ~topo.boundary_edge
    EP = np.zeros((len(E), 3))
    raise NotImplementedError('Task 7 (edge points): interior edge (a, b) with faces f0, f1 -> (a + b + FP[f0] + FP[f1]) / 4')
    if not inner.all():
        raise NotImplementedError('Task 4 (boundary rules): boundary edge (a, b) -> midpoint (a + b) / 2')
    return EP


def cc_vertex_points(V, faces, face_points=None, *, topo: MeshTopology | None = None) -> np.ndarray:
    """Vertex points: the new position of every old vertex.

    Parameters
    ----------
    V : (n, 3) array_like of float
    faces : (m, k) int array or list of polygons
    face_points : (m, 3) array_like of float, optional
        From :func:`cc_face_points` (computed when omitted).
    topo : MeshTopology, optional

    Returns
    -------
    VP : (n, 3) float64
        - interior vertex ``P`` of valence ``k`` (``k`` edges and ``k`` faces around it):
          ``(Q + 2 R + (k - 3) P) / k`` with ``Q`` the mean of the adjacent face points and ``R`` the
          mean of the midpoints of the adjacent edges;
        - boundary vertex with boundary neighbours ``A``, ``B``: ``3/4 P + 1/8 (A + B)``;
        - a vertex no face uses stays where it is.
    """
    if topo is None:
        V, topo = polygon_topology(V, faces, where="cc_vertex_points")
    V = np.asarray(V, dtype=np.float64)
    FP = cc_face_points(V, faces, topo=topo) if face_points is None else np.asarray(face_points, dtype=np.float64)
    n = len(V)
    E, k = topo.E, topo.valence
    inner = (~topo.boundary_vertex) & (k > 0)
    VP = V.copy()
    raise NotImplementedError('Task 8 (vertex points): interior P of valence k -> (Q + 2R + (k - 3) P) / k')
    if topo.boundary_vertex.any():
        raise NotImplementedError('Task 4 (boundary rules): boundary vertex P, boundary neighbours A, B -> 3/4 P + 1/8 (A + B)')
    return VP


def cc_quads(faces, *, n_vertices: int | None = None, topo: MeshTopology | None = None) -> np.ndarray:
    """Connectivity of the refined mesh: one quad per corner of every face.

    Parameters
    ----------
    faces : (m, k) int array or list of polygons
    n_vertices : int, optional
        Number ``n`` of old vertices (default: largest index + 1).
    topo : MeshTopology, optional

    Returns
    -------
    Q : (h, 4) int64
        ``h`` = number of corners. Corner ``j`` (vertex ``v = idx[j]`` of face ``f``, with outgoing
        edge ``e_out`` and incoming edge ``e_in``) gives the quad
        ``(v, n + e_out, n + e + f, n + e_in)`` — vertex point, edge point, face point, edge point,
        with the orientation of ``f``.
    """
    if topo is None:
        idx = np.concatenate([np.ravel(f) for f in faces]) if not isinstance(faces, np.ndarray) else faces.ravel()
        n = int(n_vertices) if n_vertices is not None else (int(np.max(idx)) + 1 if len(idx) else 0)
        _, topo = polygon_topology(np.zeros((n, 3)), faces, where="cc_quads")
    n, e = topo.n_vertices, len(topo.E)
    raise NotImplementedError('Task 9 (quads): corner j of face f -> (idx[j], n + he_edge[j], n + e + f, n + he_edge[prv[j]])')


def catmull_clark_step(V, faces, *, topo: MeshTopology | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One Catmull-Clark step (given; combines Tasks 4 and 6-9).

    Returns
    -------
    V_new : (n + e + m, 3) float64
        Vertex points, edge points, face points.
    Q : (h, 4) int64
        Quads, see :func:`cc_quads`.
    """
    if topo is None:
        V, topo = polygon_topology(V, faces, where="catmull_clark_step")
    FP = cc_face_points(V, faces, topo=topo)
    EP = cc_edge_points(V, faces, FP, topo=topo)
    VP = cc_vertex_points(V, faces, FP, topo=topo)
    return np.concatenate([VP, EP, FP]), cc_quads(faces, topo=topo)


def catmull_clark(V, faces, levels: int = 1) -> tuple[np.ndarray, np.ndarray | list[np.ndarray]]:
    """Catmull-Clark subdivision of a manifold polygon mesh, ``levels`` times.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    faces : (m, k) int array, or a list of polygons of mixed sizes (triangles, quads, pentagons, ...)
        Manifold, consistently oriented faces. Boundary edges follow the cubic B-spline curve rules.
    levels : int, >= 0
        Number of subdivision steps.

    Returns
    -------
    V_new : (n_L, 3) float64
        Per level ``n + e + m`` vertices: vertex points (old indices), edge points
        (:func:`geomlib.topology.unique_edges` order), face points.
    Q : (q, 4) int64
        Quads; one level turns an ``m``-face mesh with ``h`` corners into ``h`` quads, every further
        level multiplies the count by 4. With ``levels == 0`` the input faces are returned (an
        ``(m, k)`` array, or a list of arrays when sizes are mixed).

    Raises
    ------
    MeshError
        Faces with fewer than 3 corners or a repeated corner, bad indices or values, a non-manifold
        or inconsistently oriented mesh, ``levels`` not an integer >= 0.

    Examples
    --------
    >>> V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> V1, Q1 = catmull_clark(V, [[0, 1, 2, 3]])
    >>> V1.shape, Q1.shape
    ((9, 3), (4, 4))
    """
    levels = check_int(levels, "levels", minimum=0, where="catmull_clark")
    V, topo = polygon_topology(V, faces, where="catmull_clark")
    if levels == 0:
        sizes = np.diff(topo.off)
        if (sizes == sizes[0]).all():
            return V.copy(), topo.idx.reshape(-1, int(sizes[0])).copy()
        return V.copy(), np.split(topo.idx.copy(), topo.off[1:-1])
    Q = (topo.idx, topo.off)
    for level in range(levels):  # levels are sequential by nature
        if level:
            topo = mesh_topology(Q, len(V), where="catmull_clark", name="faces")
        V, Q = catmull_clark_step(V, Q, topo=topo)
    return V, Q
