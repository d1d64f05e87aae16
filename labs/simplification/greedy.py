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
    raise NotImplementedError('Task 4 (greedy loop): min-heap of (cost, pair), lazy invalidation by versions, link + flip tests, contract, push new pairs')
