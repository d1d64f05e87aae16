"""Isotropic remeshing (Botsch & Kobbelt 2004): the local operations, the loop's stages, the loop.

The local operations run on a mutable corner table in compiled kernels (:mod:`.kernels`); the
public functions take ``(V, F)`` or geomlib's :class:`~geomlib.topology.HalfEdgeMesh`, build the
table, run the kernels and rebuild a checked structure around the result.

References
----------
M. Botsch, L. Kobbelt, "A remeshing approach to multiresolution modeling", SGP 2004.
"""

from __future__ import annotations

import igl
import numpy as np
from scipy.spatial import cKDTree

from geomlib import topology
from geomlib.errors import MeshError
from geomlib.geometry import closest_points
from geomlib.validate import check_float, check_int, check_mesh

from . import kernels as K

__all__ = [
    "RemeshState",
    "make_state",
    "state_mesh",
    "split_edge",
    "collapse_edge",
    "flip_edge",
    "sharp_edges",
    "split_long_edges",
    "collapse_short_edges",
    "equalize_valences",
    "tangential_relaxation",
    "project_to_surface",
    "isotropic_remesh",
    "max_curvature",
    "adaptive_target_length",
    "SurfaceProjector",
]

REASONS = {
    K.LINK: "it breaks the link condition (the two ends share a neighbour that is not opposite the edge)",
    K.FLIP: "a face around it would turn over or become degenerate",
    K.LONG: "it would create an edge longer than the split bound",
    K.CONSTRAINED: "the edge is on the boundary or a feature line",
    K.VALENCE: "a vertex would be left with fewer than 3 edges",
}


# --------------------------------------------------------------------------------------------
# given: the mutable state and its conversion from / to (V, F)


class RemeshState:
    """The arrays the kernels edit (see :mod:`.kernels`); ``args`` passes them in kernel order."""

    def __init__(self, V, F, T, cls, feat):
        n, m = len(V), len(F)
        self.V = np.zeros((max(2 * n, 16), 3))
        self.V[:n] = V
        self.F = np.zeros((max(2 * m, 16), 3), np.int64)
        self.F[:m] = F
        self.T = np.full(3 * len(self.F), -1, np.int64)
        self.T[: 3 * m] = T
        self.feat = np.zeros(3 * len(self.F), bool)
        self.feat[: 3 * m] = feat
        self.falive = np.zeros(len(self.F), bool)
        self.falive[:m] = True
        self.VH = np.full(len(self.V), -1, np.int64)
        self.VH[F.ravel()[::-1]] = np.arange(3 * m - 1, -1, -1)
        self.val = np.zeros(len(self.V), np.int64)
        self.val[:n] = np.bincount(topology.unique_edges(F).ravel(), minlength=n)
        self.cls = np.zeros(len(self.V), np.int64)
        self.cls[:n] = cls
        self.cnt = np.array([n, m], np.int64)
        # per-vertex split / collapse bounds (the stages and the loop fill them)
        self.high = np.full(len(self.V), np.inf)
        self.low = np.zeros(len(self.V))

    def grow(self):
        """Double the room for vertices and faces (a split pass stopped for room)."""
        nv, nf = len(self.V), len(self.F)
        self.V = np.r_[self.V, np.zeros((nv, 3))]
        self.F = np.r_[self.F, np.zeros((nf, 3), np.int64)]
        self.T = np.r_[self.T, np.full(3 * nf, -1, np.int64)]
        self.feat = np.r_[self.feat, np.zeros(3 * nf, bool)]
        self.falive = np.r_[self.falive, np.zeros(nf, bool)]
        self.VH = np.r_[self.VH, np.full(nv, -1, np.int64)]
        self.val = np.r_[self.val, np.zeros(nv, np.int64)]
        self.cls = np.r_[self.cls, np.zeros(nv, np.int64)]
        self.high = np.r_[self.high, np.full(nv, np.inf)]
        self.low = np.r_[self.low, np.zeros(nv)]

    def compact(self):
        """Drop dead faces and vertices from the rows the passes visit (:func:`.kernels.compact`)."""
        K.compact(*_args(self), self.high, self.low)

    def faces(self) -> np.ndarray:
        """Live faces (vertex indices of the state, removed vertices unused)."""
        nf = self.cnt[1]
        return self.F[:nf][self.falive[:nf]]

    def feature_halfedges(self) -> np.ndarray:
        nf = self.cnt[1]
        h = np.flatnonzero(self.feat[: 3 * nf] & np.repeat(self.falive[:nf], 3))
        return h


def _edge_lookup(F: np.ndarray, n: int, pairs: np.ndarray) -> np.ndarray:
    """Half-edge flags: True where the half-edge's undirected edge is one of ``pairs``."""
    a, b = F.ravel(), F[:, [1, 2, 0]].ravel()
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    if len(pairs) == 0:
        return np.zeros(len(keys), bool)
    pk = np.minimum(pairs[:, 0], pairs[:, 1]) * n + np.maximum(pairs[:, 0], pairs[:, 1])
    return np.isin(keys, pk)


def make_state(V, F, feature_edges=None, *, preserve_boundary: bool = True, where: str = "make_state") -> RemeshState:
    """Build the kernels' state of a checked manifold triangle mesh.

    ``feature_edges`` (k, 2) vertex pairs are kept as feature lines; with ``preserve_boundary``
    the boundary edges are too. A vertex on two feature edges slides along them (class 1) unless
    the line turns there by more than 45°; there, and on one or more than two feature edges, it is
    a corner (class 2) and stays put.
    """
    H = topology.halfedge_mesh(F, len(V), manifold=True, checked=True, where=where)
    T = H.twin
    fe = np.zeros((0, 2), np.int64) if feature_edges is None else np.asarray(feature_edges, np.int64).reshape(-1, 2)
    feat = _edge_lookup(F, len(V), fe)
    if preserve_boundary:
        feat |= T < 0
    a, b = F.ravel(), F[:, [1, 2, 0]].ravel()
    first = feat & ((T < 0) | (np.arange(len(T)) < T))  # each feature edge once
    count = np.bincount(np.r_[a[first], b[first]], minlength=len(V))
    cls = np.where(count == 0, 0, np.where(count == 2, 1, 2))
    # a line that turns by more than 45 degrees at a vertex (a square's corner) has a corner there:
    # |d1 + d2|^2 = 2 + 2 cos(angle between the two edge directions) > 2 - sqrt(2)
    ea, eb = a[first], b[first]
    d = V[eb] - V[ea]
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    s = np.zeros((len(V), 3))
    np.add.at(s, ea, d)
    np.add.at(s, eb, -d)
    cls[(cls == 1) & ((s**2).sum(axis=1) > 2 - np.sqrt(2))] = 2
    return RemeshState(V, F, T, cls, feat)


def state_mesh(S: RemeshState) -> tuple[np.ndarray, np.ndarray]:
    """The state's mesh as compact ``(V, F)``: removed vertices dropped, indices renumbered."""
    F = S.faces()
    used = np.zeros(S.cnt[0], bool)
    used[F.ravel()] = True
    new = np.cumsum(used) - 1
    return S.V[: S.cnt[0]][used].copy(), new[F]


def _state_feature_edges(S: RemeshState, F_old_to_new=None) -> np.ndarray:
    h = S.feature_halfedges()
    a, b = S.F[h // 3, h % 3], S.F[h // 3, (h % 3 + 1) % 3]
    return np.unique(np.sort(np.c_[a, b], axis=1), axis=0) if len(h) else np.zeros((0, 2), np.int64)


def _positive(x, name, where):
    x = check_float(x, name, where=where)
    if x <= 0:
        raise MeshError(f"{where}: {name} must be > 0, got {x}")
    return x


def _args(S: RemeshState):
    return S.V, S.F, S.T, S.VH, S.val, S.cls, S.feat, S.falive, S.cnt


def _check_edge(H, edge, where):
    e = check_int(edge, "edge", where=where, minimum=0)
    if e >= H.n_edges:
        raise MeshError(f"{where}: edge {e} does not exist (the mesh has {H.n_edges} edges)")
    if (np.diff(H.off) != 3).any():
        raise MeshError(f"{where}: the mesh must be made of triangles")
    return e


def _from_halfedges(V, H, where):
    V = np.array(V, dtype=np.float64)
    if V.ndim != 2 or V.shape != (H.n_vertices, 3):
        raise MeshError(f"{where}: V has shape {V.shape}, expected ({H.n_vertices}, 3)")
    F = H.idx.reshape(-1, 3)
    S = make_state(V, F, preserve_boundary=False, where=where)
    return S, F


def _halfedge_of(H, e):
    return int(H.EH[e, 0] if H.EH[e, 0] >= 0 else H.EH[e, 1])


# --------------------------------------------------------------------------------------------
# Task 1-3: the local operations on geomlib's half-edge structure


def split_edge(V, H, edge):
    """Split edge ``edge`` of ``H`` at its midpoint.

    Parameters
    ----------
    V : (n, 3) float
    H : HalfEdgeMesh
        A manifold triangle mesh (:func:`geomlib.topology.halfedge_mesh`).
    edge : int
        Row of ``H.E``.

    Returns
    -------
    V : (n + 1, 3) float
        The new vertex is the last row.
    H : HalfEdgeMesh
        Two more faces (one on a boundary edge); passes :func:`geomlib.topology.check_halfedges`.
    """
    where = "split_edge"
    e = _check_edge(H, edge, where)
    S, F = _from_halfedges(V, H, where)
    a, b = H.E[e]
    K.split(*_args(S), _halfedge_of(H, e), 0.5 * (S.V[a] + S.V[b]))
    V2, F2 = S.V[: S.cnt[0]].copy(), S.faces()
    return V2, topology.halfedge_mesh(F2, len(V2), checked=True)


def collapse_edge(V, H, edge, *, high=np.inf):
    """Collapse edge ``(a, b) = H.E[edge]``: ``b`` merges into ``a`` at the midpoint, or at the
    position of the end on the boundary when only one end is.

    Raises :class:`MeshError` naming the rule when the collapse is not allowed: the link condition
    (``N(a) ∩ N(b)`` must be exactly the vertices opposite the edge), a face turning over, an edge
    longer than ``high`` appearing, an interior edge joining two boundary vertices, a vertex left
    with fewer than 3 edges.

    Returns
    -------
    V : (n - 1, 3) float
        Row ``b`` removed (later vertices move down one index).
    H : HalfEdgeMesh
    """
    where = "collapse_edge"
    e = _check_edge(H, edge, where)
    high = _positive(high, "high", where) if np.isfinite(high) else np.inf
    S, F = _from_halfedges(V, H, where)
    h = _halfedge_of(H, e)
    a, b = int(F.ravel()[h]), int(F[h // 3, (h % 3 + 1) % 3])
    bnd = H.boundary_vertex
    if bnd[b] and not bnd[a]:
        if S.T[h] < 0:
            raise MeshError(f"{where}: internal error (boundary edge with an interior end)")
        h = int(S.T[h])
        a, b = b, a
    p = S.V[a].copy() if bnd[a] != bnd[b] else 0.5 * (S.V[a] + S.V[b])
    hes, n1, n2 = (np.empty(K.RING, np.int64) for _ in range(3))
    code = K.collapse_check(*_args(S)[:7], h, p, high, hes, n1, n2)
    if code != K.OK:
        raise MeshError(f"{where}: edge ({H.E[e, 0]}, {H.E[e, 1]}) cannot be collapsed: {REASONS[code]}")
    K.collapse(*_args(S)[:8], h, p, hes)
    V2, F2 = state_mesh(S)
    return V2, topology.halfedge_mesh(F2, len(V2), checked=True)


def flip_edge(V, H, edge):
    """Flip interior edge ``a-b`` of faces ``(a, b, c)``, ``(b, a, d)`` to ``c-d``.

    Raises :class:`MeshError` when the edge is on the boundary, ``c-d`` is already an edge, ``a``
    or ``b`` would keep fewer than 3 edges, or a new face would turn over or be degenerate.

    Returns
    -------
    V : (n, 3) float (unchanged)
    H : HalfEdgeMesh
        Same faces rows ``f`` and ``f2`` now ``(c, a, d)`` and ``(d, b, c)``.
    """
    where = "flip_edge"
    e = _check_edge(H, edge, where)
    S, F = _from_halfedges(V, H, where)
    h = _halfedge_of(H, e)
    hes, nb = np.empty(K.RING, np.int64), np.empty(K.RING, np.int64)
    code = K.flip_check(S.V, S.F, S.T, S.VH, S.val, S.feat, h, hes, nb)
    if code != K.OK:
        raise MeshError(f"{where}: edge ({H.E[e, 0]}, {H.E[e, 1]}) cannot be flipped: {REASONS[code]}")
    K.flip(S.V, S.F, S.T, S.VH, S.val, S.feat, h)
    V2, F2 = S.V[: S.cnt[0]].copy(), S.faces()
    return V2, topology.halfedge_mesh(F2, len(V2), checked=True)


# --------------------------------------------------------------------------------------------
# Task 7: features


def sharp_edges(V, F, feature_angle):
    """Edges whose dihedral angle (between the two face normals) exceeds ``feature_angle`` degrees.

    Returns
    -------
    E : (k, 2) int64
        Sorted vertex pairs, rows in lexicographic order.
    """
    where = "sharp_edges"
    V, F = check_mesh(V, F, where=where, manifold=True)
    angle = check_float(feature_angle, "feature_angle", where=where, minimum=0.0, maximum=180.0)
    # BEGIN SOLUTION: Task 7 (features): angle between the normals of the two faces of an interior edge > feature_angle
    H = topology.halfedge_mesh(F, len(V), checked=True)
    inner = H.edge_size == 2
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    f0, f1 = H.EF[inner, 0], H.EF[inner, 1]
    cos = np.clip(np.einsum("ij,ij->i", N[f0], N[f1]), -1.0, 1.0)
    return H.E[inner][np.degrees(np.arccos(cos)) > angle]
    # END SOLUTION


# --------------------------------------------------------------------------------------------
# Tasks 4-6 and 8-9: the stages


def _stage_input(V, F, feature_edges, where):
    V, F = check_mesh(V, F, where=where, manifold=True)
    if feature_edges is not None:
        fe = np.asarray(feature_edges)
        if fe.size and (fe.ndim != 2 or fe.shape[1] != 2 or fe.min() < 0 or fe.max() >= len(V)):
            raise MeshError(f"{where}: feature_edges must be (k, 2) vertex indices below {len(V)}")
    return V, F


def _split_all(S: RemeshState) -> int:
    total, h, stop = 0, 0, 3 * int(S.cnt[1])
    while True:
        done, h = K.split_pass(*_args(S), S.high, S.low, h, stop)
        total += done
        if h >= stop:
            return total
        S.grow()


def split_long_edges(V, F, high, *, feature_edges=None, preserve_boundary=True):
    """Split every edge longer than ``high`` at its midpoint, in one pass over the input's edges (stage 1).

    Edges created by the pass are not split again in it (the next iteration of the loop sees
    them); an edge longer than ``2 high`` therefore leaves two halves longer than ``high``.

    Returns
    -------
    V, F : the refined mesh; the input vertices keep their indices and positions, new vertices follow.
    """
    where = "split_long_edges"
    V, F = _stage_input(V, F, feature_edges, where)
    high = _positive(high, "high", where)
    S = make_state(V, F, feature_edges, preserve_boundary=preserve_boundary, where=where)
    S.high[:] = high
    _split_all(S)
    return state_mesh(S)


def collapse_short_edges(V, F, low, high, *, feature_edges=None, preserve_boundary=True):
    """Collapse edges shorter than ``low`` when the collapse is allowed (stage 2).

    Constrained ends (boundary, feature lines, corners) keep their position; two free ends meet
    at the midpoint. A collapse never creates an edge longer than ``high``.
    """
    where = "collapse_short_edges"
    V, F = _stage_input(V, F, feature_edges, where)
    low = _positive(low, "low", where)
    high = _positive(high, "high", where)
    S = make_state(V, F, feature_edges, preserve_boundary=preserve_boundary, where=where)
    S.high[:], S.low[:] = high, low
    while K.collapse_pass(*_args(S), S.high, S.low):
        pass
    return state_mesh(S)


def equalize_valences(V, F, *, feature_edges=None):
    """Flip edges while that lowers Σ|valence − target| (target 6 inside, 4 on the boundary) (stage 3).

    On a tie in that sum, a flip that lowers Σ(valence − target)² is made too; a flip whose new faces
    turn by more than 60° from the old ones is not (see :func:`.kernels.flip_check`).
    """
    where = "equalize_valences"
    V, F = _stage_input(V, F, feature_edges, where)
    S = make_state(V, F, feature_edges, preserve_boundary=True, where=where)
    for _ in range(10):
        if not K.flip_pass(*_args(S)):
            break
    return state_mesh(S)


def _line_tangents(V, E_feat, n):
    """Unit tangent of the feature line at every vertex (principal direction of its feature edges)."""
    d = V[E_feat[:, 1]] - V[E_feat[:, 0]]
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    M = np.zeros((n, 3, 3))
    outer = d[:, :, None] * d[:, None, :]
    np.add.at(M, E_feat[:, 0], outer)
    np.add.at(M, E_feat[:, 1], outer)
    t = np.zeros((n, 3))
    on = np.unique(E_feat)  # only the line's vertices have a direction
    t[on] = np.linalg.eigh(M[on])[1][:, :, 2]
    return t


def _relax(V, F, cls, E_feat, damping):
    """Tangential relaxation on faces ``F`` of ``V`` (rows no face uses are left alone)."""
    n = len(V)
    # BEGIN SOLUTION: Task 8 (tangential relaxation): p += λ (I - n nᵀ)(c - p), c = Σ A_f c_f / Σ A_f; feature vertices along their line
    X = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    A = 0.5 * np.linalg.norm(X, axis=1)
    C = V[F].mean(axis=1)
    w = np.bincount(F.ravel(), np.repeat(A, 3), minlength=n)
    c = np.stack([np.bincount(F.ravel(), np.repeat(A * C[:, k], 3), minlength=n) for k in range(3)], axis=1)
    N = np.stack([np.bincount(F.ravel(), np.repeat(X[:, k], 3), minlength=n) for k in range(3)], axis=1)
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    used = w > 0
    D = np.zeros_like(V)
    D[used] = c[used] / w[used, None] - V[used]
    D -= np.einsum("ij,ij->i", D, N)[:, None] * N
    if len(E_feat):  # along the line, toward the midpoint of the two line neighbours
        t = _line_tangents(V, E_feat, n)
        s = np.zeros_like(V)
        np.add.at(s, E_feat[:, 0], V[E_feat[:, 1]])
        np.add.at(s, E_feat[:, 1], V[E_feat[:, 0]])
        k = np.bincount(E_feat.ravel(), minlength=n)
        line = cls == 1
        mid = s[line] / np.maximum(k[line], 1)[:, None] - V[line]
        D[line] = np.einsum("ij,ij->i", mid, t[line])[:, None] * t[line]
    D[cls == 2] = 0.0
    return V + damping * D
    # END SOLUTION


def tangential_relaxation(V, F, *, damping=0.5, feature_edges=None, preserve_boundary=True):
    """Move every vertex toward the area-weighted centroid of its faces, within its tangent plane (stage 4).

    ``p ← p + λ (I − n nᵀ)(c − p)`` with ``c = Σ A_f c_f / Σ A_f`` over the faces around ``p``
    (``c_f`` centroids, ``A_f`` areas), ``n`` the area-weighted vertex normal, ``λ = damping``.
    Vertices on a feature line or the preserved boundary move along it toward the midpoint of their
    two line neighbours; corners stay.

    Returns
    -------
    V : (n, 3) float
    """
    where = "tangential_relaxation"
    V, F = _stage_input(V, F, feature_edges, where)
    lam = check_float(damping, "damping", where=where, minimum=0.0, maximum=1.0)
    S = make_state(V, F, feature_edges, preserve_boundary=preserve_boundary, where=where)
    return _relax(V, F, S.cls[: len(V)], _state_feature_edges(S), lam)


def _closest_on_segments(P, A, B, k=8, chunk=2048):
    """Closest point of every row of ``P`` on the segments ``A[i]B[i]``.

    The ``k`` segments with the nearest midpoints (a k-d tree) are measured exactly; the answer is
    certain when the ``k``-th nearest midpoint is farther than the best distance plus the longest
    half segment (no other segment can come closer). The other rows are measured against every
    segment, in chunks.
    """
    out = np.empty_like(P)
    if len(P) == 0:
        return out
    AB = B - A
    L2 = np.maximum(np.einsum("ij,ij->i", AB, AB), 1e-300)

    def nearest_of(Q, S):  # S (q, s) candidate segments per row
        t = np.clip(np.einsum("qsj,qsj->qs", Q[:, None, :] - A[S], AB[S]) / L2[S], 0.0, 1.0)
        X = A[S] + t[:, :, None] * AB[S]
        d = ((X - Q[:, None, :]) ** 2).sum(axis=2)
        j = d.argmin(axis=1)
        r = np.arange(len(Q))
        return X[r, j], np.sqrt(d[r, j])

    k = min(k, len(A))
    dmid, S = cKDTree(0.5 * (A + B)).query(P, k)
    S, dmid = S.reshape(len(P), k), dmid.reshape(len(P), k)
    out[:], best = nearest_of(P, S)
    unsure = np.flatnonzero(dmid[:, -1] <= best + 0.5 * np.sqrt(L2.max())) if k < len(A) else []
    step = max(1, chunk * 256 // len(A))
    everything = np.arange(len(A))
    for s in range(0, len(unsure), step):
        rows = unsure[s : s + step]
        out[rows] = nearest_of(P[rows], np.broadcast_to(everything, (len(rows), len(A))))[0]
    return out


class SurfaceProjector:
    """Closest points on a fixed surface ``(V0, F0)``, its AABB tree built once (given).

    :func:`geomlib.geometry.closest_points` builds libigl's tree at every call; the loop projects
    onto the same input tens of times, and building the tree costs about four queries.
    """

    def __init__(self, V0, F0):
        self.V0 = np.ascontiguousarray(V0, np.float64)
        self.F0 = np.ascontiguousarray(F0, np.int64)
        self.tree = igl.AABB()
        self.tree.init(self.V0, self.F0)

    def __call__(self, P) -> np.ndarray:
        return self.closest(P)[1]

    def closest(self, P) -> tuple[np.ndarray, np.ndarray]:
        """Face of the input holding the closest point ``(k,)`` and the closest points ``(k, 3)``."""
        if len(P) == 0:
            return np.zeros(0, np.int64), np.zeros((0, 3))
        _, face, C = self.tree.squared_distance(self.V0, self.F0, np.ascontiguousarray(P, np.float64))
        return np.asarray(face, np.int64).ravel(), np.asarray(C)

    def interpolate(self, values, face, C) -> np.ndarray:
        """Per-vertex ``values`` of the input, linearly interpolated at points ``C`` of faces ``face``."""
        A, B, D = (self.V0[self.F0[face, k]] for k in range(3))
        e0, e1, e2 = B - A, D - A, C - A
        d00, d01, d11 = (np.einsum("ij,ij->i", x, y) for x, y in ((e0, e0), (e0, e1), (e1, e1)))
        d20, d21 = np.einsum("ij,ij->i", e2, e0), np.einsum("ij,ij->i", e2, e1)
        det = np.maximum(d00 * d11 - d01 * d01, 1e-300)
        v = np.clip((d11 * d20 - d01 * d21) / det, 0.0, 1.0)
        w = np.clip((d00 * d21 - d01 * d20) / det, 0.0, 1.0 - v)
        x = values[self.F0[face]]
        return (1.0 - v - w) * x[:, 0] + v * x[:, 1] + w * x[:, 2]


def project_to_surface(P, V0, F0):
    """Closest point of every row of ``P`` on the input surface ``(V0, F0)`` (stage 5).

    Uses :func:`geomlib.geometry.closest_points` (libigl's AABB tree), which the lab gives.
    """
    where = "project_to_surface"
    V0, F0 = check_mesh(V0, F0, where=where, vname="V0", fname="F0")
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 3 or not np.isfinite(P).all():
        raise MeshError(f"{where}: P must be a finite (k, 3) array, got shape {P.shape}")
    # BEGIN SOLUTION: Task 9 (projection): the closest point on the input surface
    return closest_points(V0, F0, P)[2]
    # END SOLUTION


# --------------------------------------------------------------------------------------------
# Task 11 (extension): adaptive target length from curvature


def max_curvature(V, F):
    """Largest absolute principal curvature ``κ = max(|k1|, |k2|)`` at every vertex (1 / length units).

    From the discrete mean and Gaussian curvature of the lecture, with ``A_i`` a third of the area
    of the faces around vertex ``i`` (barycentric area):

    * ``H_i = |Δx_i| / 2`` with ``Δx_i = 1 / (2 A_i) Σ_j (cot α_ij + cot β_ij)(x_j − x_i)`` (cotangent
      Laplacian: ``α_ij``, ``β_ij`` are the angles opposite edge ``ij``);
    * ``K_i = (2π − Σ θ_i) / A_i`` (angle defect: ``θ_i`` the corner angles at ``i``);
    * ``k1,2 = H ± sqrt(H² − K)``, so ``κ = |H| + sqrt(max(H² − K, 0))``.

    Boundary vertices have neither (their Laplacian and angle defect measure the boundary, not the
    surface): ``κ`` is NaN there.

    Returns
    -------
    kappa : (n,) float
    """
    where = "max_curvature"
    V, F = check_mesh(V, F, where=where, manifold=True)
    # BEGIN SOLUTION: Task 11 (curvature): H = |Δx| / 2 (cotangent Laplacian), K = angle defect / A, κ = |H| + sqrt(max(H² − K, 0))
    n = len(V)
    theta = np.empty(F.shape)
    cot = np.empty(F.shape)
    for k in range(3):  # corner k of every face: angle between its two edges
        u, w = V[np.roll(F, -1, axis=1)[:, k]] - V[F[:, k]], V[np.roll(F, -2, axis=1)[:, k]] - V[F[:, k]]
        cos_k = (u * w).sum(axis=1)
        sin_k = np.linalg.norm(np.cross(u, w), axis=1)
        theta[:, k] = np.arctan2(sin_k, cos_k)
        cot[:, k] = cos_k / np.maximum(sin_k, 1e-300)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    A = np.maximum(np.bincount(F.ravel(), np.repeat(area / 3.0, 3), minlength=n), 1e-300)
    lap = np.zeros((n, 3))
    for k in range(3):  # edge (i, j) opposite corner k carries cot of that corner's angle
        i, j = F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        d = cot[:, k, None] * (V[j] - V[i])
        np.add.at(lap, i, d)
        np.add.at(lap, j, -d)
    H = np.linalg.norm(lap, axis=1) / (4.0 * A)
    K = (2.0 * np.pi - np.bincount(F.ravel(), theta.ravel(), minlength=n)) / A
    kappa = H + np.sqrt(np.maximum(H * H - K, 0.0))
    kappa[topology.halfedge_mesh(F, n, checked=True).boundary_vertex] = np.nan
    return kappa
    # END SOLUTION


def adaptive_target_length(V, F, target_length, *, error=None, min_length=None, max_length=None, smoothing=2):
    """Per-vertex target edge length from curvature: short where the surface bends, long where it is flat.

    An equilateral triangle of side ``h`` on a sphere of radius ``r`` leaves the sphere by
    ``ε = r − sqrt(r² − h²/3)`` (the height of the cap over its circumcircle), so the longest edge
    that keeps the error at ``ε`` is

        ``h = sqrt(6 ε r − 3 ε²)``  with ``r = 1 / κ`` (``h = √3 ε`` when ``ε ≥ r``).

    Steps: ``κ`` = :func:`max_curvature`; ``smoothing`` times, replace every ``κ`` by the mean over
    the vertex and its neighbours (NaN boundary values are left out, and so filled from inside);
    ``h`` from the formula; clamp to ``[min_length, max_length]``.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    target_length : float
        ``L``: the length at the median curvature ``κ̃`` when ``error`` is not given.
    error : float, optional
        ``ε`` (length units). Default ``L² κ̃ / 6``: ``h ≈ L`` where ``κ = κ̃``.
    min_length, max_length : float, optional
        Default ``L / 4`` and ``2 L``.
    smoothing : int
        Smoothing steps of ``κ``.

    Returns
    -------
    lengths : (n,) float
        Target edge length per vertex, within ``[min_length, max_length]``.
    """
    where = "adaptive_target_length"
    V, F = check_mesh(V, F, where=where, manifold=True)
    L = _positive(target_length, "target_length", where)
    lo = L / 4.0 if min_length is None else _positive(min_length, "min_length", where)
    hi = 2.0 * L if max_length is None else _positive(max_length, "max_length", where)
    if lo > hi:
        raise MeshError(f"{where}: min_length ({lo:g}) must not exceed max_length ({hi:g})")
    eps = None if error is None else _positive(error, "error", where)
    steps = check_int(smoothing, "smoothing", where=where, minimum=0)
    # BEGIN SOLUTION: Task 11 (adaptive target length): smooth κ over 1-rings, h = sqrt(6 ε r − 3 ε²) with r = 1/κ, clamp
    kappa = max_curvature(V, F)
    n = len(V)
    ij = topology.unique_edges(F)
    rows = np.r_[ij[:, 0], ij[:, 1], np.arange(n)]  # closed 1-ring: both directions and the vertex itself
    cols = np.r_[ij[:, 1], ij[:, 0], np.arange(n)]
    for _ in range(steps):  # mean over the closed 1-ring, known values only
        known = np.isfinite(kappa)
        k0 = np.where(known, kappa, 0.0)
        total = np.bincount(rows, k0[cols], minlength=n)
        count = np.bincount(rows, known[cols].astype(float), minlength=n)
        kappa = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    kappa = np.where(np.isfinite(kappa), kappa, 0.0)  # a vertex with no known value counts as flat
    if eps is None:
        eps = L * L * float(np.median(kappa)) / 6.0
    with np.errstate(divide="ignore"):
        r = np.where(kappa > 0, 1.0 / np.maximum(kappa, 1e-300), np.inf)
    h = np.where(eps < r, np.sqrt(np.maximum(6.0 * eps * r - 3.0 * eps * eps, 0.0)), np.sqrt(3.0) * eps)
    h = np.where(np.isfinite(h), h, hi)  # flat (r = inf): as long as allowed
    return np.clip(h, lo, hi)
    # END SOLUTION


# --------------------------------------------------------------------------------------------
# the loop


def _target_field(target_length, n, adaptive, V0, F0, where):
    """``(L, field)``: the scalar target (mean of a field) and the per-vertex field or None."""
    if np.ndim(target_length) == 0:
        L = _positive(target_length, "target_length", where)
        return L, (adaptive_target_length(V0, F0, L) if adaptive else None)
    if adaptive:
        raise MeshError(f"{where}: adaptive=True computes the lengths itself: give one target_length, not an array")
    field = np.asarray(target_length, dtype=np.float64)
    if field.shape != (n,):
        raise MeshError(
            f"{where}: target_length must be a number or one length per vertex, shape ({n},); got {field.shape}"
        )
    bad = ~(np.isfinite(field) & (field > 0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{where}: target_length must be finite and > 0 at every vertex; vertex {i} has {field[i]}")
    return float(field.mean()), field


def isotropic_remesh(
    V,
    F,
    target_length,
    *,
    iterations=10,
    feature_angle=None,
    preserve_boundary=True,
    damping=0.5,
    relax_steps=3,
    adaptive=False,
):
    """Remesh a triangle mesh toward equilateral triangles with edges of about ``target_length``.

    Each iteration: split edges longer than ``4/3 L``; collapse edges shorter than ``4/5 L``;
    flip edges to bring valences toward 6 (4 on the boundary); ``relax_steps`` steps of tangential
    relaxation; projection of the vertices back onto the input (feature-line and boundary vertices
    onto the input's lines, the others onto its surface).

    With a target per vertex (an array, or ``adaptive=True``), an edge's ``L`` is the smaller of its
    two ends'; the loop's vertices take the target of their closest point on the input (linear
    over its triangle) after every projection.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
        A manifold, consistently oriented triangle mesh.
    target_length : float or (n,) float
        ``L`` (same units as ``V``), one value or one per input vertex.
    iterations : int
    feature_angle : float, optional
        Edges whose dihedral angle exceeds it (degrees) are kept as feature lines.
    preserve_boundary : bool
        Keep the boundary on the input boundary (boundary vertices slide along it).
    damping : float
        ``λ`` of the relaxation, in [0, 1].
    relax_steps : int
        Relaxation steps per iteration. One damped step does not undo the distortion that the
        iteration's splits, collapses and flips leave (the last iteration's would stay in the
        result); three do, at the cost of two more relaxations (the projection runs once).
    adaptive : bool
        Use :func:`adaptive_target_length` of the input with ``L = target_length``.

    Returns
    -------
    V, F : the remeshed surface (compact: every vertex used).
    """
    where = "isotropic_remesh"
    V0, F0 = check_mesh(V, F, where=where, manifold=True)
    its = check_int(iterations, "iterations", where=where, minimum=0)
    lam = check_float(damping, "damping", where=where, minimum=0.0, maximum=1.0)
    steps = check_int(relax_steps, "relax_steps", where=where, minimum=0)
    L, field = _target_field(target_length, len(V0), bool(adaptive), V0, F0, where)
    fe = None if feature_angle is None else sharp_edges(V0, F0, feature_angle)
    # BEGIN SOLUTION: Task 10 (the loop): split > 4/3 L, collapse < 4/5 L, flip, relax, project; repeat
    S = make_state(V0, F0, fe, preserve_boundary=preserve_boundary, where=where)
    E0 = _state_feature_edges(S)
    A0, B0 = V0[E0[:, 0]], V0[E0[:, 1]]
    project = SurfaceProjector(V0, F0)
    n0 = len(V0)
    S.high[:n0] = 4.0 / 3.0 * (L if field is None else field)
    S.low[:n0] = 4.0 / 5.0 * (L if field is None else field)
    for _ in range(its):
        _split_all(S)
        while K.collapse_pass(*_args(S), S.high, S.low):
            pass
        S.compact()  # the collapses left dead rows: the next passes skip them
        for _ in range(3):
            if not K.flip_pass(*_args(S)):
                break
        n = S.cnt[0]
        Fl = S.faces()
        cls = S.cls[:n]
        Ef = _state_feature_edges(S)
        Vn = S.V[:n]
        for _ in range(steps):
            Vn = _relax(Vn, Fl, cls, Ef, lam)
        free = cls == 0  # after compact() every vertex is used
        face, Vn[free] = project.closest(Vn[free])
        if field is not None:  # the target where the vertex now is
            h = project.interpolate(field, face, Vn[free])
            S.high[:n][free], S.low[:n][free] = 4.0 / 3.0 * h, 4.0 / 5.0 * h
        line = cls == 1
        if line.any() and len(E0):
            Vn[line] = _closest_on_segments(Vn[line], A0, B0)
        S.V[:n] = Vn
    return state_mesh(S)
    # END SOLUTION
