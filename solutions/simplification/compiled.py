"""The greedy loop of Task 4, compiled with numba: the same algorithm at C++ speed (given code).

``method="fast"`` of :func:`~solutions.simplification.simplify.qem_simplify` runs this module. It is
the heap loop of :func:`~solutions.simplification.greedy.greedy_collapse` — pop the cheapest pair,
skip it when stale (lazy invalidation by versions), test the link condition and the flips,
contract, push the survivor's pairs, rebuild once when the heap runs dry — written as plain loops
over arrays so that numba can compile it to machine code (``@njit``). A Python heap loop pays
about a millisecond of interpreter and NumPy call overhead per contraction; compiled, one
contraction costs a few microseconds.

Two things differ from the lab's :class:`~solutions.simplification.contraction.SimplifyState`,
because numba compiles arrays, numbers and lists well but not a list of Python ``set`` objects:

* **faces around a vertex** are a singly linked list of *corners* (corner ``c = 3 f + k`` is corner
  ``k`` of face ``f``): ``head[v]`` is the first corner of ``v``, ``next_corner[c]`` the next one,
  ``tail[v]`` the last. Contracting ``j`` into ``i`` renames ``j``'s corners and appends ``j``'s
  list to ``i``'s in O(1); corners of dead faces are unlinked the next time a list is walked.
* **positions are not stored in the heap**: an entry is ``(cost, tie-breaker, i, j, version_i,
  version_j)``. An entry that passes the version check was pushed with the same quadrics and
  positions as now, so its position is recomputed from them (cheaper than moving three more
  floats through every heap operation).

Everything else — the placement rules of :func:`~solutions.simplification.placement.optimal_contraction`,
the link condition, the flip test with the input normals and the degeneracy test, the tie-breaker
order — is the lab's, so on a mesh without cost ties both loops contract the same pairs in the
same order (``tests/solutions/test_simplification.py`` checks it).

Debugging: with the environment variable ``NUMBA_DISABLE_JIT=1`` numba leaves the functions as
they are and the module runs as ordinary Python (slowly: use a small mesh), so ``print`` and a
debugger work inside it. Compiled code is cached on disk (``cache=True``), so only the first call
on a machine compiles (a few seconds); see :mod:`geomlib.jit` for where the cache goes.
"""

from __future__ import annotations

import heapq

import numpy as np
from numba import njit

from geomlib.jit import use_cache_folder
from geomlib.topology import boundary_edges

from .contraction import DEGENERATE_RTOL, _cross
from .placement import SINGULAR_RCOND, TIE_RTOL

__all__ = ["compiled_collapse"]

use_cache_folder(__name__, __file__)  # before the first @njit(cache=True): see geomlib.jit


# ----------------------------------------------------------------------------- placement


@njit(cache=True)
def vec(V: np.ndarray, k) -> tuple:
    """Row ``k`` of ``V`` as a 3-tuple (tuples live on the stack: no allocation in compiled code)."""
    return (V[k, 0], V[k, 1], V[k, 2])


@njit(cache=True)
def sub(a: tuple, b: tuple) -> tuple:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True)
def dot(a: tuple, b: tuple) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def cross(a: tuple, b: tuple) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def quadric_cost(Q: np.ndarray, x: tuple) -> float:
    """``vᵀ Q v`` for ``v = (x, 1)``; Q (4, 4)."""
    v = (x[0], x[1], x[2], 1.0)
    total = 0.0
    for a in range(4):
        for b in range(4):
            total += v[a] * Q[a, b] * v[b]
    return total


@njit(cache=True)
def place(Q: np.ndarray, v1: tuple, v2: tuple) -> tuple:
    """:func:`~solutions.simplification.placement.optimal_contraction` for one pair, same rules.

    ``Q = [[A, b], [bᵀ, c]]`` (4, 4); returns ``(position, cost)``, the position a 3-tuple.
    ``A x = -b`` is solved with the adjugate of ``A`` (its cofactors also give the determinant
    for the singularity test).
    """
    # rows of A, not vec(Q, 0): numba compiles a kernel called with a constant once more, for the literal
    A0, A1, A2 = (Q[0, 0], Q[0, 1], Q[0, 2]), (Q[1, 0], Q[1, 1], Q[1, 2]), (Q[2, 0], Q[2, 1], Q[2, 2])
    b = (Q[0, 3], Q[1, 3], Q[2, 3])
    c = Q[3, 3]
    adj0, adj1, adj2 = cross(A1, A2), cross(A2, A0), cross(A0, A1)  # A⁻¹ = [adj0 adj1 adj2] / det
    det = dot(A0, adj0)
    norm = np.sqrt(dot(A0, A0) + dot(A1, A1) + dot(A2, A2))
    if abs(det) > SINGULAR_RCOND * (norm * norm * norm):  # not norm**3: pow's last bit varies (libm, numba)
        s = -1.0 / det  # x = -A⁻¹ b, A symmetric
        position = (
            s * (adj0[0] * b[0] + adj1[0] * b[1] + adj2[0] * b[2]),
            s * (adj0[1] * b[0] + adj1[1] * b[1] + adj2[1] * b[2]),
            s * (adj0[2] * b[0] + adj1[2] * b[1] + adj2[2] * b[2]),
        )
    else:
        # Singular: the minimum on the segment v1 + t d, or, when the cost is flat along it, the
        # best of the midpoint, v1 and v2 (ties within round-off in that order of preference).
        d = sub(v2, v1)
        Ad = (dot(A0, d), dot(A1, d), dot(A2, d))
        dAd = dot(d, Ad)
        slope = dot(Ad, v1) + dot(d, b)
        trace = A0[0] + A1[1] + A2[2]
        length2 = dot(d, d)
        reach = max(dot(v1, v1), dot(v2, v2)) + length2
        scale = trace * reach + abs(c)
        if dAd > TIE_RTOL * trace * length2:
            t = min(max(-slope / dAd, 0.0), 1.0)
            position = (v1[0] + t * d[0], v1[1] + t * d[1], v1[2] + t * d[2])
        else:
            mid = (0.5 * (v1[0] + v2[0]), 0.5 * (v1[1] + v2[1]), 0.5 * (v1[2] + v2[2]))
            c_mid, c_1, c_2 = quadric_cost(Q, mid), quadric_cost(Q, v1), quadric_cost(Q, v2)
            best = min(c_mid, c_1, c_2) + TIE_RTOL * scale
            position = mid if c_mid <= best else (v1 if c_1 <= best else v2)
    return position, max(quadric_cost(Q, position), 0.0)


# ----------------------------------------------------------------------------- faces around a vertex


@njit(cache=True)
def link_corner_lists(F: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``head``, ``tail`` (n,) and ``next_corner`` (3m,): the corners of each vertex as a linked list (-1 ends)."""
    head = np.full(n, -1, np.int64)
    tail = np.full(n, -1, np.int64)
    next_corner = np.full(3 * len(F), -1, np.int64)
    for c in range(3 * len(F)):
        v = F[c // 3, c % 3]
        if head[v] == -1:
            head[v] = c
        else:
            next_corner[tail[v]] = c
        tail[v] = c
    return head, tail, next_corner


@njit(cache=True)
def faces_around(v, face_alive, head, tail, next_corner) -> np.ndarray:
    """The alive faces that use vertex ``v``; unlinks the corners of dead faces on the way."""
    count, previous, c = 0, -1, head[v]
    while c != -1:
        following = next_corner[c]
        if face_alive[c // 3]:
            count += 1
            previous = c
        else:  # drop the corner: after a walk the list holds alive faces only
            if previous == -1:
                head[v] = following
            else:
                next_corner[previous] = following
            if following == -1:
                tail[v] = previous
        c = following
    faces = np.empty(count, np.int64)
    k, c = 0, head[v]
    while c != -1:
        faces[k] = c // 3
        k += 1
        c = next_corner[c]
    return faces


@njit(cache=True)
def uses(F: np.ndarray, f, v) -> bool:
    """Whether face ``f`` has ``v`` as a corner."""
    return F[f, 0] == v or F[f, 1] == v or F[f, 2] == v


@njit(cache=True)
def ring(v, faces: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Sorted vertices that share one of ``faces`` with ``v`` (its 1-ring when ``faces`` are all of v's)."""
    out = np.empty(2 * len(faces), np.int64)
    k = 0
    for f in faces:
        for c in range(3):
            w = F[f, c]
            if w == v:
                continue
            at = k  # insertion sort of a handful of values, skipping repeats
            while at > 0 and out[at - 1] > w:
                at -= 1
            if at > 0 and out[at - 1] == w:
                continue
            for m in range(k, at, -1):
                out[m] = out[m - 1]
            out[at] = w
            k += 1
    return out[:k]


@njit(cache=True)
def count_common(a: np.ndarray, b: np.ndarray) -> int:
    """Number of values in both sorted arrays of distinct values (a merge)."""
    i = j = common = 0
    while i < len(a) and j < len(b):
        if a[i] == b[j]:
            common += 1
            i += 1
            j += 1
        elif a[i] < b[j]:
            i += 1
        else:
            j += 1
    return common


# ----------------------------------------------------------------------------- the tests and one contraction


@njit(cache=True)
def link_condition(i, j, faces_i, faces_j, F, on_boundary) -> bool:
    """:func:`~solutions.simplification.contraction.link_condition` for an edge ``(i, j)``."""
    on_edge = 0  # faces that use both ends
    for f in faces_i:
        on_edge += uses(F, f, j)
    if on_edge == 0:
        return False  # not an edge: this loop contracts edges only
    Ni, Nj = ring(i, faces_i, F), ring(j, faces_j, F)
    both_boundary = on_boundary[i] and on_boundary[j]
    if count_common(Ni, Nj) + both_boundary != on_edge + (on_edge == 1):
        return False
    degree_i = len(Ni) + on_boundary[i]
    degree_j = len(Nj) + on_boundary[j]
    return not (degree_i <= 3 and degree_j <= 3)


@njit(cache=True)
def turns_over(f, moved, position, V, F, normal0, min_cos) -> bool:
    """Whether face ``f`` flips when its corner ``moved`` goes to ``position`` (the test of ``flips_normal``)."""
    p0, p1, p2 = vec(V, F[f, 0]), vec(V, F[f, 1]), vec(V, F[f, 2])  # corners before the move
    n_old = cross(sub(p1, p0), sub(p2, p0))
    if F[f, 0] == moved:
        p0 = position
    elif F[f, 1] == moved:
        p1 = position
    else:
        p2 = position
    n_new = cross(sub(p1, p0), sub(p2, p0))
    len_new = np.sqrt(dot(n_new, n_new))
    for n_ref in (n_old, vec(normal0, f)):
        len_ref = np.sqrt(dot(n_ref, n_ref))
        if len_ref > 0 and dot(n_new, n_ref) <= min_cos * len_new * len_ref:
            return True
    e0, e1, e2 = sub(p1, p0), sub(p2, p1), sub(p0, p2)
    edges2 = dot(e0, e0) + dot(e1, e1) + dot(e2, e2)
    return len_new <= DEGENERATE_RTOL * edges2 and abs(n_old[0]) + abs(n_old[1]) + abs(n_old[2]) > 0


@njit(cache=True)
def flips_normal(i, j, position, faces_i, faces_j, V, F, normal0, min_cos) -> bool:
    """:func:`~solutions.simplification.contraction.flips_normal`: the faces that use exactly one of ``i``, ``j``."""
    for f in faces_i:
        if not uses(F, f, j) and turns_over(f, i, position, V, F, normal0, min_cos):
            return True
    for f in faces_j:
        if not uses(F, f, i) and turns_over(f, j, position, V, F, normal0, min_cos):
            return True
    return False


@njit(cache=True)
def contract(i, j, position, faces_i, faces_j, V, F, Q, face_alive, vertex_alive, on_boundary, head, tail, next_corner):
    """:func:`~solutions.simplification.contraction.contract_pair`: ``j`` into ``i``; returns faces removed."""
    removed = 0
    for f in faces_i:
        if uses(F, f, j):
            face_alive[f] = False  # its corners leave the lists lazily (faces_around)
            removed += 1
    for f in faces_j:
        if face_alive[f]:
            for k in range(3):
                if F[f, k] == j:
                    F[f, k] = i
    if head[j] != -1:  # hand j's corners over to i
        if head[i] == -1:
            head[i] = head[j]
        else:
            next_corner[tail[i]] = head[j]
        tail[i] = tail[j]
        head[j] = -1
        tail[j] = -1
    V[i, 0], V[i, 1], V[i, 2] = position
    Q[i] += Q[j]
    on_boundary[i] = on_boundary[i] or on_boundary[j]
    vertex_alive[j] = False
    return removed


# ----------------------------------------------------------------------------- the greedy loop


@njit(cache=True)
def all_edges(F: np.ndarray, face_alive: np.ndarray, n: int) -> np.ndarray:
    """Edges of the alive faces, smaller index first, sorted (as ``geomlib.topology.unique_edges``)."""
    alive = np.flatnonzero(face_alive)
    keys = np.empty(3 * len(alive), np.int64)
    for k in range(len(alive)):
        for c in range(3):
            a, b = F[alive[k], c], F[alive[k], (c + 1) % 3]
            keys[3 * k + c] = min(a, b) * n + max(a, b)
    return np.unique(keys)


@njit(cache=True)
def heap_of_all_edges(V, F, Q, face_alive, version, tiebreak):
    """A heap entry ``(cost, tie-breaker, i, j, version_i, version_j)`` for every current edge; the next tie-breaker."""
    n = len(V)
    heap = []
    for key in all_edges(F, face_alive, n):
        a, b = key // n, key % n
        _, cost = place(Q[a] + Q[b], vec(V, a), vec(V, b))
        heap.append((cost, tiebreak, a, b, version[a], version[b]))
        tiebreak += 1
    heapq.heapify(heap)
    return heap, tiebreak


@njit(cache=True)
def greedy_collapse(V, F, Q, normal0, on_boundary, target_faces, min_cos) -> np.ndarray:
    """Contract the cheapest allowed edge until at most ``target_faces`` faces are left.

    The algorithm of :func:`~solutions.simplification.greedy.greedy_collapse` (edges only).
    ``V``, ``F``, ``Q`` and ``on_boundary`` are changed in place like the fields of a
    ``SimplifyState``.

    Returns
    -------
    face_alive : (m,) bool
    """
    n, m = len(V), len(F)
    face_alive = np.ones(m, np.bool_)
    vertex_alive = np.ones(n, np.bool_)
    version = np.zeros(n, np.int64)
    head, tail, next_corner = link_corner_lists(F, n)
    n_faces = m
    # equal costs pop in push order; np.int64(0), not 0: a constant argument would make numba compile
    # heap_of_all_edges twice (for the literal 0, then for the int64 of the later calls)
    heap, tiebreak = heap_of_all_edges(V, F, Q, face_alive, version, np.int64(0))
    contracted_since_rebuild = 0
    while n_faces > target_faces:
        if len(heap) == 0:
            if contracted_since_rebuild == 0:
                break  # nothing left that keeps the mesh manifold and unflipped
            heap, tiebreak = heap_of_all_edges(V, F, Q, face_alive, version, tiebreak)
            contracted_since_rebuild = 0
            continue
        _, _, i, j, vi, vj = heapq.heappop(heap)
        if not (vertex_alive[i] and vertex_alive[j]) or version[i] != vi or version[j] != vj:
            continue  # stale entry
        position, _ = place(Q[i] + Q[j], vec(V, i), vec(V, j))  # as when pushed: nothing changed since
        faces_i = faces_around(i, face_alive, head, tail, next_corner)
        faces_j = faces_around(j, face_alive, head, tail, next_corner)
        if not link_condition(i, j, faces_i, faces_j, F, on_boundary):
            continue
        if flips_normal(i, j, position, faces_i, faces_j, V, F, normal0, min_cos):
            continue
        n_faces -= contract(
            i, j, position, faces_i, faces_j, V, F, Q, face_alive, vertex_alive, on_boundary, head, tail, next_corner
        )
        contracted_since_rebuild += 1
        version[i] += 1
        for k in ring(i, faces_around(i, face_alive, head, tail, next_corner), F):
            _, cost = place(Q[i] + Q[k], vec(V, i), vec(V, k))
            heapq.heappush(heap, (cost, tiebreak, i, k, version[i], version[k]))
            tiebreak += 1
    return face_alive


# ----------------------------------------------------------------------------- entry point


def compiled_collapse(
    V: np.ndarray, F: np.ndarray, Q: np.ndarray, target_faces: int, min_cos: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Simplify a validated mesh with the compiled greedy loop (edges only).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
        A validated manifold triangle mesh (not changed).
    Q : (n, 4, 4) float64
        Vertex quadrics (:func:`~solutions.simplification.quadrics.vertex_quadrics`).
    target_faces : int
    min_cos : float
        Flip test threshold (see :func:`~solutions.simplification.contraction.flips_normal`).

    Returns
    -------
    V : (n', 3) float64
    F : (m', 3) int64
        The result, compact (every vertex used), ``m' <= target_faces`` when reachable.
    normals0 : (m', 3) float64
        Each output face's normal in the input mesh (for the refit's flip guard).
    """
    V = np.array(V, dtype=np.float64, order="C")
    F = np.array(F, dtype=np.int64, order="C")
    Q = np.array(Q, dtype=np.float64, order="C")
    normal0 = _cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    on_boundary = np.zeros(len(V), dtype=np.bool_)
    on_boundary[boundary_edges(F).ravel()] = True
    alive = greedy_collapse(V, F, Q, normal0, on_boundary, np.int64(target_faces), np.float64(min_cos))
    F = F[alive]
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    return V[used], (np.cumsum(used) - 1)[F], normal0[alive]
