"""Tasks 1-3 on geomlib's half-edge structure (given): :func:`split_edge`, :func:`collapse_edge`, :func:`flip_edge`.

Each builds the kernels' state (:mod:`.state`) from a :class:`~geomlib.topology.HalfEdgeMesh`, runs
*your* kernel of :mod:`.kernels` once and rebuilds a checked structure around the result, so the
tests can check every invariant after each operation.
"""

from __future__ import annotations

import numpy as np

from geomlib import topology
from geomlib.errors import MeshError
from geomlib.validate import check_float, check_int

from . import kernels as K
from .state import make_state, state_mesh

__all__ = ["split_edge", "collapse_edge", "flip_edge"]

REASONS = {
    K.LINK: "it breaks the link condition (the two ends share a neighbour that is not opposite the edge)",
    K.FLIP: "a face around it would turn over or become degenerate",
    K.LONG: "it would create an edge longer than the split bound",
    K.CONSTRAINED: "the edge is on the boundary or a feature line",
    K.VALENCE: "a vertex would be left with fewer than 3 edges",
}


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
    K.split(*S.args(), _halfedge_of(H, e), 0.5 * (S.V[a] + S.V[b]))
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
    high = check_float(high, "high", positive=True, where=where) if np.isfinite(high) else np.inf
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
    code = K.collapse_check(*S.args()[:7], h, p, high, hes, n1, n2)
    if code != K.OK:
        raise MeshError(f"{where}: edge ({H.E[e, 0]}, {H.E[e, 1]}) cannot be collapsed: {REASONS[code]}")
    K.collapse(*S.args()[:8], h, p, hes)
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
