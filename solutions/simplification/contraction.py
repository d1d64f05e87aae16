"""One pair contraction and the tests that decide whether it is allowed.

The greedy loop works on a :class:`SimplifyState`: the mesh arrays plus the bookkeeping that makes
one contraction cheap (which faces are still alive, which faces touch each vertex). Removed faces
and vertices are only *marked* dead, so indices never shift during simplification; the mesh is
compacted once at the end (:func:`state_mesh`).

Before contracting a pair ``(i, j)`` we check two things:

* the **link condition** (Dey et al. 1999; Hoppe 1993): the vertices adjacent to both ``i`` and
  ``j`` must be exactly the vertices opposite the edge, otherwise the contraction glues two
  sheets together along an edge or a vertex (the result is no longer a manifold);
* **no flipped faces**: every face that survives the contraction must keep facing the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.topology import boundary_edges
from geomlib.validate import MeshError, as_array, check_float, check_mesh

__all__ = [
    "SimplifyState",
    "make_state",
    "neighbors",
    "edge_faces",
    "state_mesh",
    "refresh_boundary",
    "link_condition",
    "flips_normal",
    "contract_pair",
    "check_contractions",
    "contract_pairs",
]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (k, 3) arrays (np.cross is slow on small arrays)."""
    return np.stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ],
        axis=1,
    )


#: A face is degenerate when ``|n| <= DEGENERATE_RTOL · (sum of its squared edge lengths)``.
DEGENERATE_RTOL = 1e-10


@dataclass
class SimplifyState:
    """A triangle mesh being simplified in place.

    Attributes
    ----------
    V : (n, 3) float64
        Positions; rows of removed vertices keep stale values.
    F : (m, 3) int64
        Triangles; rows of removed faces keep stale indices.
    Q : (n, 4, 4) float64
        Quadric of each vertex (accumulated over contractions).
    face_alive : (m,) bool
    face_normal0 : (m, 3) float64
        Normal ``(v1 - v0) × (v2 - v0)`` of every face in the *input* mesh (not normalised); faces keep
        it while their corners move, so the flip test can also compare with where a face started.
    vertex_alive : (n,) bool
    on_boundary : (n,) bool
        The vertex lies on a boundary loop (a contraction keeps the flag of either end).
    vertex_faces : list of set of int
        ``vertex_faces[v]`` = the alive faces that use vertex ``v``.
    n_faces : int
        Number of alive faces.
    """

    V: np.ndarray
    F: np.ndarray
    Q: np.ndarray
    face_alive: np.ndarray
    face_normal0: np.ndarray
    vertex_alive: np.ndarray
    on_boundary: np.ndarray
    vertex_faces: list
    n_faces: int


def make_state(V: np.ndarray, F: np.ndarray, Q: np.ndarray) -> SimplifyState:
    """Build the bookkeeping for a validated mesh (arrays are copied, the caller's stay intact)."""
    V = np.array(V, dtype=np.float64)
    F = np.array(F, dtype=np.int64)
    n = len(V)
    vertex_faces: list[set[int]] = [set() for _ in range(n)]
    corners = np.argsort(F.ravel(), kind="stable")
    starts = np.searchsorted(F.ravel()[corners], np.arange(n + 1))
    face_of = corners // 3
    for v in np.flatnonzero(np.diff(starts)):  # one set per vertex: Python containers need a loop
        vertex_faces[v] = set(face_of[starts[v] : starts[v + 1]].tolist())
    on_boundary = np.zeros(n, dtype=bool)
    on_boundary[boundary_edges(F).ravel()] = True
    return SimplifyState(
        V=V,
        F=F,
        Q=np.array(Q, dtype=np.float64),
        face_alive=np.ones(len(F), dtype=bool),
        face_normal0=_cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
        vertex_alive=np.ones(n, dtype=bool),
        on_boundary=on_boundary,
        vertex_faces=vertex_faces,
        n_faces=len(F),
    )


def neighbors(state: SimplifyState, i: int) -> np.ndarray:
    """Sorted vertices that share an alive face with ``i`` (its 1-ring), int64."""
    faces = list(state.vertex_faces[i])
    ring = np.unique(state.F[faces]) if faces else np.zeros(0, np.int64)
    return ring[ring != i]


def edge_faces(state: SimplifyState, i: int, j: int) -> set[int]:
    """Alive faces that use both ``i`` and ``j``: 2 for an interior edge, 1 for a boundary edge, 0 otherwise."""
    return state.vertex_faces[i] & state.vertex_faces[j]


def refresh_boundary(state: SimplifyState, vertices) -> None:
    """Recompute ``on_boundary`` of ``vertices``: on the boundary iff one of its edges has a single face."""
    for v in np.asarray(vertices).tolist():
        faces = list(state.vertex_faces[v])
        others = state.F[faces][state.F[faces] != v] if faces else np.zeros(0, np.int64)
        _, uses = np.unique(others, return_counts=True)  # faces per edge (v, x)
        state.on_boundary[v] = bool((uses == 1).any())


def state_mesh(state: SimplifyState) -> tuple[np.ndarray, np.ndarray]:
    """The alive part as a compact mesh: unreferenced vertices dropped, indices renumbered in order."""
    F = state.F[state.face_alive]
    used = np.zeros(len(state.V), dtype=bool)
    used[F.ravel()] = True
    new_index = np.cumsum(used) - 1
    return state.V[used].copy(), new_index[F]


def link_condition(state: SimplifyState, i: int, j: int) -> bool:
    """Whether contracting ``(i, j)`` keeps the mesh manifold.

    For an edge (1 or 2 faces use both ends) the condition is

        |N(i) ∩ N(j)| + [i and j on the boundary] = (faces on the edge) + [boundary edge],

    i.e. the common neighbours are exactly the vertices opposite the edge. The bracket terms treat
    the outside of each boundary loop as one virtual vertex joined to every boundary vertex: it is a
    common neighbour whenever both ends lie on a boundary, and it belongs to the link of a boundary
    edge. So an interior edge joining two boundary vertices is refused (it would pinch the surface),
    as is any edge of a boundary triangle whose third vertex is also next to both ends.

    One more case passes that count and still breaks the mesh: when both ends have only 3
    neighbours (counting the virtual vertex), the pair sits in a tetrahedron, which would collapse
    into two copies of one triangle; it is refused.

    For a non-edge pair (no face uses both) every common neighbour ``x`` must be joined to both
    ``i`` and ``j`` by *boundary* edges: the two edges then merge into one edge with two faces
    (closing a crack, like a zip). Any other common neighbour would leave an edge in three or
    four faces. Without common neighbours the two pieces touch in one vertex.

    Parameters
    ----------
    state : SimplifyState
    i, j : int
        Alive vertices, ``i != j``.

    Returns
    -------
    bool
        True when the contraction is allowed.
    """
    # BEGIN SOLUTION: Task 3 (contraction): link condition |N(i) ∩ N(j)| + [both on boundary] == faces on edge + [boundary edge]
    Ni, Nj = neighbors(state, i), neighbors(state, j)
    k = len(edge_faces(state, i, j))
    if k == 0:
        vf = state.vertex_faces
        shared = np.intersect1d(Ni, Nj, assume_unique=True).tolist()
        return all(len(vf[i] & vf[x]) == 1 and len(vf[j] & vf[x]) == 1 for x in shared)
    common = len(np.intersect1d(Ni, Nj, assume_unique=True))
    both_boundary = bool(state.on_boundary[i] and state.on_boundary[j])
    if common + both_boundary != k + (k == 1):
        return False
    degree_i = len(Ni) + bool(state.on_boundary[i])
    degree_j = len(Nj) + bool(state.on_boundary[j])
    return not (degree_i <= 3 and degree_j <= 3)
    # END SOLUTION


def flips_normal(state: SimplifyState, i: int, j: int, position, min_cos: float = 0.0) -> bool:
    """Whether moving ``i`` and ``j`` to ``position`` turns a surviving face over.

    Every alive face around ``i`` or ``j`` that does not use both (those disappear) is compared
    before and after the move: with ``n = (v1 - v0) × (v2 - v0)`` before and ``n'`` after, the
    face flips when

        n' · n <= min_cos · |n'| |n|    or    n' · n0 <= min_cos · |n'| |n0|,

    where ``n0 = state.face_normal0[f]`` is the face's normal in the input mesh: the first test
    catches a turn by 90° or more in this contraction (``min_cos = 0``), the second a face that
    turned over a little at a time over many contractions. A face also counts as flipped when it
    becomes degenerate: ``|n'| <= 1e-10 · (sum of its squared edge lengths)`` (three points on a
    line; round-off makes ``n'`` tiny rather than exactly 0, so the dot products alone can miss
    it). Faces that had zero area before are not tested (they have no orientation to lose).

    Parameters
    ----------
    state : SimplifyState
    i, j : int
    position : (3,) array_like of float
    min_cos : float
        Smallest allowed cosine between old and new normals.

    Returns
    -------
    bool
        True when some face would flip (the contraction must be rejected).
    """
    # BEGIN SOLUTION: Task 3 (contraction): flip test n' · n <= min_cos |n'| |n| for n before the move and n0 in the input, or degenerate
    around = state.vertex_faces[i] ^ state.vertex_faces[j]  # faces using exactly one of the two
    if not around:
        return False
    faces = np.fromiter(around, dtype=np.int64, count=len(around))
    T = state.F[faces]
    P = state.V[T]  # (k, 3, 3) corners before
    n_old = _cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    P[(T == i) | (T == j)] = position
    n_new = _cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    len_new = np.sqrt((n_new * n_new).sum(axis=1))
    flipped = np.zeros(len(T), dtype=bool)
    for n_ref in (n_old, state.face_normal0[faces]):
        len_ref = np.sqrt((n_ref * n_ref).sum(axis=1))
        flipped |= ((n_new * n_ref).sum(axis=1) <= min_cos * len_new * len_ref) & (len_ref > 0)
    edges2 = ((P - P[:, [1, 2, 0]]) ** 2).sum(axis=(1, 2))
    flipped |= (len_new <= DEGENERATE_RTOL * edges2) & (np.abs(n_old).sum(axis=1) > 0)
    return bool(flipped.any())
    # END SOLUTION


def contract_pair(state: SimplifyState, i: int, j: int, position) -> int:
    """Contract ``j`` into ``i`` at ``position``, updating all bookkeeping.

    After the call:

    * the faces that used both ``i`` and ``j`` are dead (``face_alive`` False) and no longer listed
      in ``vertex_faces`` of any vertex;
    * every other face of ``j`` uses ``i`` instead and is listed in ``vertex_faces[i]``;
    * ``V[i] = position``, ``Q[i] = Q[i] + Q[j]``, ``on_boundary[i] |= on_boundary[j]`` (a
      non-edge pair can zip boundary edges shut: then call :func:`refresh_boundary` on ``i`` and
      its neighbours instead);
    * ``j`` is dead (``vertex_alive[j]`` False, ``vertex_faces[j]`` empty); its rows stay stale;
    * ``n_faces`` drops by the number of faces removed.

    Parameters
    ----------
    state : SimplifyState
        Changed in place.
    i, j : int
        The surviving and the removed vertex.
    position : (3,) array_like of float

    Returns
    -------
    int
        Number of faces removed: 2 for an interior edge, 1 for a boundary edge, 0 for a non-edge pair.
    """
    # BEGIN SOLUTION: Task 3 (contraction): kill faces using both, rename j -> i in the others, V[i] = position, Q[i] += Q[j]
    vf = state.vertex_faces
    dead = vf[i] & vf[j]
    for f in dead:  # at most two faces
        state.face_alive[f] = False
        for v in state.F[f].tolist():
            vf[v].discard(f)
    moved = np.fromiter(vf[j], dtype=np.int64, count=len(vf[j]))
    Fm = state.F[moved]
    Fm[Fm == j] = i
    state.F[moved] = Fm
    vf[i] |= vf[j]
    vf[j] = set()
    state.V[i] = position
    state.Q[i] += state.Q[j]
    state.on_boundary[i] |= state.on_boundary[j]
    state.vertex_alive[j] = False
    state.n_faces -= len(dead)
    if not dead:  # a non-edge pair may zip boundary edges together: boundary flags can turn off
        refresh_boundary(state, np.r_[i, neighbors(state, i)])
    return len(dead)
    # END SOLUTION


def _pairs_positions(state_V: np.ndarray, pairs, positions, where: str) -> tuple[np.ndarray, np.ndarray]:
    n = len(state_V)
    pairs = as_array(pairs, "pairs", shape=(None, 2), dtype=np.int64, where=where)
    positions = as_array(positions, "positions", shape=(len(pairs), 3), where=where)
    if len(pairs) and (pairs.min() < 0 or pairs.max() >= n):
        raise MeshError(
            f"{where}: pairs index vertex {int(pairs.max() if pairs.max() >= n else pairs.min())}, valid indices are 0..{n - 1}"
        )
    if (pairs[:, 0] == pairs[:, 1]).any():
        k = int(np.flatnonzero(pairs[:, 0] == pairs[:, 1])[0])
        raise MeshError(f"{where}: pair {k} contracts vertex {int(pairs[k, 0])} with itself")
    return pairs, positions


def check_contractions(V, F, pairs, positions, min_cos: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Run :func:`link_condition` and :func:`flips_normal` for several pairs of one mesh (a given wrapper).

    Each pair is tested on the *unchanged* mesh (nothing is contracted).

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A manifold triangle mesh.
    pairs : (k, 2) array_like of int
    positions : (k, 3) array_like of float
        Where each pair would go.
    min_cos : float

    Returns
    -------
    link_ok : (k,) bool
        :func:`link_condition` of each pair.
    flips : (k,) bool
        :func:`flips_normal` of each pair.
    """
    V, F = check_mesh(V, F, where="check_contractions", manifold=True)
    pairs, positions = _pairs_positions(V, pairs, positions, "check_contractions")
    min_cos = check_float(min_cos, "min_cos", minimum=-1.0, maximum=1.0, where="check_contractions")
    state = make_state(V, F, np.zeros((len(V), 4, 4)))
    link_ok = np.array([link_condition(state, int(a), int(b)) for a, b in pairs], dtype=bool)
    flips = np.array(
        [flips_normal(state, int(a), int(b), p, min_cos) for (a, b), p in zip(pairs, positions)], dtype=bool
    )
    return link_ok, flips


def contract_pairs(V, F, Q, pairs, positions) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Apply :func:`contract_pair` to several pairs *in sequence* on one state (a given wrapper).

    Pair ``k`` is ``(i, j)``: ``j`` is contracted into ``i`` at ``positions[k]``; both must still
    be alive when it is its turn. No validity test is made here.

    Returns
    -------
    V : (n, 3) float64
        All rows kept (rows of removed vertices are stale), so indices are those of the input.
    F : (m', 3) int64
        The alive faces in their original order, with removed vertices renamed.
    Q : (n, 4, 4) float64
    removed : (k,) int64
        Faces removed by each contraction.
    """
    V, F = check_mesh(V, F, where="contract_pairs", manifold=True)
    Q = as_array(Q, "Q", shape=(len(V), 4, 4), where="contract_pairs")
    pairs, positions = _pairs_positions(V, pairs, positions, "contract_pairs")
    state = make_state(V, F, Q)
    removed = np.zeros(len(pairs), dtype=np.int64)
    for k, ((a, b), p) in enumerate(zip(pairs.tolist(), positions)):
        if not (state.vertex_alive[a] and state.vertex_alive[b]):
            raise MeshError(f"contract_pairs: pair {k} ({a}, {b}) uses a vertex removed by an earlier pair")
        removed[k] = contract_pair(state, a, b, p)
    return state.V, state.F[state.face_alive], state.Q, removed
