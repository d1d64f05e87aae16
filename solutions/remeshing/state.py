"""The kernels' state (given): the mutable corner table of :mod:`.kernels` and its conversion from / to ``(V, F)``.

The local operations and the stages edit these arrays in compiled kernels; the public functions
take ``(V, F)`` or geomlib's :class:`~geomlib.topology.HalfEdgeMesh`, build the state with
:func:`make_state`, run the kernels and return :func:`state_mesh` (or a checked structure around it).
"""

from __future__ import annotations

import numpy as np

from geomlib import topology
from geomlib.errors import MeshError

from . import kernels as K

__all__ = ["RemeshState", "make_state", "state_mesh"]


class RemeshState:
    """The arrays the kernels edit (see :mod:`.kernels`); ``args`` passes them in kernel order."""

    def __init__(self, V, F, T, cls, feat, val=None):
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
        self.val[:n] = np.bincount(topology.unique_edges(F).ravel(), minlength=n) if val is None else val
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
        K.compact(*self.args(), self.high, self.low)

    def args(self) -> tuple:
        """The arrays in the kernels' argument order: ``(V, F, T, VH, val, cls, feat, falive, cnt)``."""
        return self.V, self.F, self.T, self.VH, self.val, self.cls, self.feat, self.falive, self.cnt

    def faces(self) -> np.ndarray:
        """Live faces (vertex indices of the state, removed vertices unused)."""
        nf = self.cnt[1]
        return self.F[:nf][self.falive[:nf]]

    def feature_halfedges(self) -> np.ndarray:
        """Half-edges of the live faces that lie on a feature line (or the preserved boundary)."""
        nf = self.cnt[1]
        return np.flatnonzero(self.feat[: 3 * nf] & np.repeat(self.falive[:nf], 3))

    def feature_edges(self) -> np.ndarray:
        """The feature edges of the live faces: sorted vertex pairs ``(k, 2)``, rows in lexicographic order."""
        h = self.feature_halfedges()
        if not len(h):
            return np.zeros((0, 2), np.int64)
        a, b = self.F[h // 3, h % 3], self.F[h // 3, (h % 3 + 1) % 3]
        return np.unique(np.sort(np.c_[a, b], axis=1), axis=0)


def _edge_lookup(F: np.ndarray, n: int, pairs: np.ndarray) -> np.ndarray:
    """Half-edge flags: True where the half-edge's undirected edge is one of ``pairs``."""
    a, b = F.ravel(), F[:, [1, 2, 0]].ravel()
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    if len(pairs) == 0:
        return np.zeros(len(keys), bool)
    pk = np.minimum(pairs[:, 0], pairs[:, 1]) * n + np.maximum(pairs[:, 0], pairs[:, 1])
    return np.isin(keys, pk)


def make_state(
    V, F, feature_edges=None, *, preserve_boundary: bool = True, where: str = "make_state", H=None
) -> RemeshState:
    """Build the kernels' state of a checked manifold triangle mesh.

    ``H`` is the mesh's :class:`~geomlib.topology.HalfEdgeMesh` when the caller has built it already
    (a public entry validates its mesh by building it: it is not built again here).

    ``feature_edges`` (k, 2) vertex pairs are kept as feature lines; with ``preserve_boundary``
    the boundary edges are too. A vertex on two feature edges slides along them (class 1) unless
    the line turns there by more than 45°; there, and on one or more than two feature edges, it is
    a corner (class 2) and stays put.
    """
    if H is None:
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
    return RemeshState(V, F, T, cls, feat, H.valence)


def state_mesh(S: RemeshState) -> tuple[np.ndarray, np.ndarray]:
    """The state's mesh as compact ``(V, F)``: removed vertices dropped, indices renumbered.

    Raises
    ------
    MeshError
        When the kernels' valence count ``val`` disagrees with the mesh at a vertex: the local
        operations keep it by hand (split, collapse and flip each add or remove edges), and a wrong
        count steers later checks and flips without breaking the mesh, so it is caught here.
    """
    F = S.faces()
    n = int(S.cnt[0])
    used = np.zeros(n, bool)
    used[F.ravel()] = True
    a, b = F.ravel(), F[:, [1, 2, 0]].ravel()
    key = np.unique(np.minimum(a, b) * n + np.maximum(a, b))
    edges_at = np.bincount(np.r_[key // n, key % n], minlength=n)
    wrong = np.flatnonzero(used & (edges_at != S.val[:n]))
    if len(wrong):
        v = int(wrong[0])
        more = len(wrong) - 1
        others = f"; {more} more {'vertex disagrees' if more == 1 else 'vertices disagree'}" if more else ""
        raise MeshError(
            f"the local operations' valence count val[{v}] is {int(S.val[v])}, but {int(edges_at[v])} edges meet "
            f"at vertex {v}{others}: each operation must keep val[v] = the number of edges at v (Task 1 edge "
            "split, Task 2 edge collapse, Task 3 edge flip)"
        )
    new = np.cumsum(used) - 1
    return S.V[: S.cnt[0]][used].copy(), new[F]
