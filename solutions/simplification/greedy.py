"""The greedy contraction loop of Garland & Heckbert, with a min-heap and lazy invalidation.

Every valid pair sits in a min-heap keyed by its cost. We pop the cheapest pair, check that it is
still current and still allowed, contract it, and push fresh entries for the pairs of the
surviving vertex (their quadric and position changed). Entries that went stale are not searched
for and removed (that would cost O(heap size)); each entry carries the *version* of both
vertices at the time it was pushed, and a popped entry whose versions no longer match is simply
skipped. That is *lazy invalidation*.
"""

from __future__ import annotations

import heapq
from itertools import count

import numpy as np
from scipy.spatial import cKDTree

from geomlib.topology import unique_edges

from .contraction import SimplifyState, contract_pair, flips_normal, link_condition, neighbors
from .placement import optimal_contraction

__all__ = ["candidate_pairs", "pair_costs", "greedy_collapse"]


def candidate_pairs(V: np.ndarray, F: np.ndarray, threshold: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The valid pairs of Garland & Heckbert (a given helper).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    threshold : float
        Non-edge pairs closer than this (``|v_i - v_j| < threshold``) are valid too; 0 gives edges only.

    Returns
    -------
    edges : (e, 2) int64
        The mesh edges, smaller index first.
    others : (p, 2) int64
        Non-edge pairs closer than ``threshold``, smaller index first (empty when 0).
    """
    E = unique_edges(F)
    if threshold <= 0:
        return E, np.zeros((0, 2), np.int64)
    used = np.unique(F)
    close = cKDTree(V[used]).query_pairs(threshold, output_type="ndarray")
    close = np.sort(used[close], axis=1) if len(close) else np.zeros((0, 2), np.int64)
    n = len(V)
    is_edge = np.isin(close[:, 0] * n + close[:, 1], E[:, 0] * n + E[:, 1])
    return E, close[~is_edge].astype(np.int64)


def pair_costs(state: SimplifyState, i: int, partners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Optimal positions and costs of the pairs ``(i, k)`` for every ``k`` in ``partners`` (a given helper).

    Returns
    -------
    positions : (p, 3) float64
    costs : (p,) float64
    """
    Q = state.Q[i][None] + state.Q[partners]
    return optimal_contraction(Q, np.broadcast_to(state.V[i], (len(partners), 3)), state.V[partners])


def greedy_collapse(state: SimplifyState, others: np.ndarray, target_faces: int, min_cos: float = 0.0) -> int:
    """Contract the cheapest valid pair until at most ``target_faces`` faces are left.

    Algorithm (Garland & Heckbert 1997, §4):

    1. Push every edge ``(i, j)`` of the mesh and every non-edge pair of ``others`` onto a min-heap
       with its cost and optimal position (:func:`pair_costs`), and the versions of ``i`` and ``j``.
    2. Pop the cheapest entry. Skip it if ``i`` or ``j`` is dead or either version changed since
       the push (lazy invalidation). Skip it if :func:`link_condition` fails or
       :func:`flips_normal` is True.
    3. Otherwise :func:`contract_pair` (``j`` into ``i``), bump the version of ``i``, and push fresh
       entries for ``i`` with each of its current neighbours and non-edge partners.
    4. When the heap runs empty before the target is reached, rebuild it from every current pair
       (a skipped pair may have become valid since); stop if a whole rebuilt heap gives no
       contraction.

    Stops as soon as ``state.n_faces <= target_faces``. An interior edge removes 2 faces and a
    boundary edge 1, so the result has ``target_faces`` or ``target_faces - 1`` faces when the
    target is reachable.

    Parameters
    ----------
    state : SimplifyState
        Changed in place.
    others : (p, 2) int64
        Non-edge pairs (see :func:`candidate_pairs`); may be empty.
    target_faces : int
    min_cos : float
        Passed to :func:`flips_normal`.

    Returns
    -------
    int
        The number of faces left (``state.n_faces``).
    """
    # BEGIN SOLUTION: Task 4 (greedy loop): min-heap of (cost, pair), lazy invalidation by versions, link + flip tests, contract, push new pairs
    # Inherently sequential: each contraction changes the costs and the validity of the pairs around it,
    # so the next choice depends on the last one. Work per contraction is vectorised over the 1-ring.
    n = len(state.V)
    version = np.zeros(n, dtype=np.int64)
    partners: list[set[int]] = [set() for _ in range(n)]  # non-edge partners of each vertex
    for a, b in others.tolist():
        partners[a].add(b)
        partners[b].add(a)
    tiebreak = count()  # equal costs pop in push order; the tuples never compare positions
    heap: list = []

    def entries(i: int, ks: np.ndarray) -> list:
        if len(ks) == 0:
            return []
        positions, costs = pair_costs(state, i, ks)
        vi = int(version[i])
        return [
            (c, next(tiebreak), i, k, vi, int(version[k]), p) for k, p, c in zip(ks.tolist(), positions, costs.tolist())
        ]

    def pairs_of(i: int) -> np.ndarray:
        extra = [k for k in partners[i] if state.vertex_alive[k]]
        return np.union1d(neighbors(state, i), np.array(extra, dtype=np.int64))

    def rebuild() -> None:
        # All current pairs in one vectorised batch: edges of the alive faces plus non-edge partners.
        edges = unique_edges(state.F[state.face_alive])
        extra = [(a, b) for a in np.flatnonzero(state.vertex_alive).tolist() for b in partners[a] if a < b]
        pairs = np.concatenate([edges, np.array(extra, dtype=np.int64).reshape(-1, 2)])
        Q = state.Q[pairs[:, 0]] + state.Q[pairs[:, 1]]
        positions, costs = optimal_contraction(Q, state.V[pairs[:, 0]], state.V[pairs[:, 1]])
        heap[:] = [
            (c, next(tiebreak), i, k, int(version[i]), int(version[k]), p)
            for (i, k), p, c in zip(pairs.tolist(), positions, costs.tolist())
        ]
        heapq.heapify(heap)

    rebuild()
    contracted_since_rebuild = 0
    while state.n_faces > target_faces:
        if not heap:
            if contracted_since_rebuild == 0:
                break  # nothing left that keeps the mesh manifold and unflipped
            rebuild()
            contracted_since_rebuild = 0
            continue
        _, _, i, j, vi, vj, p = heapq.heappop(heap)
        if not (state.vertex_alive[i] and state.vertex_alive[j]) or version[i] != vi or version[j] != vj:
            continue  # stale entry
        if not link_condition(state, i, j) or flips_normal(state, i, j, p, min_cos):
            continue
        contract_pair(state, i, j, p)
        contracted_since_rebuild += 1
        for k in partners[j]:  # hand j's non-edge partners over to i
            partners[k].discard(j)
            if k != i:
                partners[k].add(i)
                partners[i].add(k)
        partners[j] = set()
        partners[i].discard(i)
        version[i] += 1
        for entry in entries(i, pairs_of(i)):
            heapq.heappush(heap, entry)
    return state.n_faces
    # END SOLUTION
