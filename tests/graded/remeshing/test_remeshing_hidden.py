"""Hidden graded cases (not shipped to students): the same rules on other meshes."""

from geomlib.grading import reference_tests

from .cases_hidden import CASES as HIDDEN_CASES

test_hidden_references = reference_tests(HIDDEN_CASES)


# --------------------------------------------------------------------------------------------
# hidden: chains of local operations on realistic meshes, every invariant checked after each

import numpy as np  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

from geomlib import datasets, topology  # noqa: E402
from geomlib.grading import graded  # noqa: E402
from geomlib.grading.errors import Mismatch, StudentError  # noqa: E402

from .support import bumpy_sphere, halfedges, wavy_patch  # noqa: E402


def _canonical(F) -> list:
    """Faces as vertex triples rotated to start at their smallest index (orientation kept), sorted."""
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    r = np.argmin(F, axis=1)
    rows = np.arange(len(F))[:, None]
    return sorted(map(tuple, F[rows, (r[:, None] + np.arange(3)) % 3].tolist()))


def _expected(op, V, F, a, b, boundary_vertex):
    """What ``op`` on edge (a, b) must return, worked out from the rule (the stubs' docstrings):
    ``(positions, faces)`` with faces indexing the positions. Split: the midpoint is the last row,
    each face (u, v, c) of the edge becomes (u, m, c), (m, v, c). Flip: faces (a, b, c), (b, a, d)
    become (c, a, d), (d, b, c). Collapse: b merges into a at the midpoint (at the boundary end when
    only one end is on the boundary), the edge's faces disappear."""
    F = np.asarray(F, dtype=np.int64)
    both = np.flatnonzero((F == a).any(axis=1) & (F == b).any(axis=1))
    keep = [f for i, f in enumerate(F.tolist()) if i not in set(both.tolist())]
    around = []
    for f in F[both].tolist():  # rotate to (u, v, c) with u -> v the edge
        while {f[0], f[1]} != {a, b}:
            f = f[1:] + f[:1]
        around.append(f)
    if op == "split_edge":
        m = len(V)
        new = [g for u, v, c in around for g in ([u, m, c], [m, v, c])]
        return np.r_[V, [0.5 * (V[a] + V[b])]], keep + new
    if op == "flip_edge":
        (u, v, c), (_, _, d) = around
        return V, keep + [[c, u, d], [d, v, c]]
    if boundary_vertex[a] != boundary_vertex[b]:
        kept, gone = (a, b) if boundary_vertex[a] else (b, a)
        p = V[kept]
    else:
        kept, gone, p = a, b, 0.5 * (V[a] + V[b])
    W = V.copy()
    W[kept] = p
    order = np.delete(np.arange(len(V)), gone)
    index = np.full(len(V), -1)
    index[order] = np.arange(len(order))
    index[gone] = index[kept]
    return W[order], index[np.asarray(keep, dtype=np.int64)].tolist()


def _effect_problem(op, V, F, a, b, boundary_vertex, V2, F2) -> str | None:
    """How ``(V2, F2)`` differs from what ``op`` on edge (a, b) of ``(V, F)`` must give (None: no difference).
    Vertices are matched by position (a collapse may renumber them), faces compared as oriented triples."""
    Ve, Fe = _expected(op, V, F, a, b, boundary_vertex)
    V2 = np.asarray(V2, dtype=float)
    if V2.shape != Ve.shape or len(F2) != len(Fe):
        what = {"split_edge": "one more vertex", "flip_edge": "the same vertices", "collapse_edge": "one fewer vertex"}
        return (
            f"{len(V2)} vertices and {len(F2)} faces, expected {len(Ve)} and {len(Fe)} ({what[op]}, "
            f"{len(Fe) - len(F):+d} face(s))"
        )
    dist, match = cKDTree(Ve).query(V2)
    if dist.max() > 1e-9 or len(np.unique(match)) != len(match):
        i = int(np.argmax(dist))
        new = {"split_edge": "the new vertex must be the midpoint of the edge", "flip_edge": "a flip moves no vertex"}
        return (
            f"vertex {i} at {np.round(V2[i], 6).tolist()} is not where the operation puts a vertex "
            f"({new.get(op, 'the merged vertex must be at the midpoint, or at the end on the boundary')})"
        )
    if _canonical(match[np.asarray(F2)]) != _canonical(Fe):
        if op == "flip_edge":
            return f"the faces are not the flipped ones: edge ({a}, {b}) must be replaced by the edge between its opposite vertices"
        return "the faces around the edge are not the ones the operation makes"
    return None


def _chain(lab, op, V, F, picks, label, *, refusals=True):
    """Apply ``op`` to edge ``pick % n_edges`` repeatedly; every result must pass check_halfedges and
    be what the operation makes (:func:`_effect_problem`): an operation that changes nothing fails."""
    H = halfedges(V, F)
    chi = topology.euler_characteristic(F)
    done = 0
    for pick in picks:
        e = int(pick % len(H.E))
        a, b = (int(x) for x in H.E[e])
        try:
            V2, H2 = getattr(lab, op)(V, H, e)
        except StudentError as exc:
            if refusals and exc.exc_type == "MeshError" and "cannot be" in exc.exc_message:
                continue  # a refused operation is fine
            raise
        try:
            topology.check_halfedges(H2)
        except Exception as exc:  # noqa: BLE001
            raise Mismatch(f"{op} on {label}, edge {e}: the structure is broken: {exc}") from None
        F2 = np.asarray(H2.idx).reshape(-1, 3)
        if topology.euler_characteristic(F2) != chi:
            raise Mismatch(f"{op} on {label}, edge {e}: the Euler characteristic changed")
        problem = _effect_problem(op, np.asarray(V, float), np.asarray(F), a, b, H.boundary_vertex, V2, F2)
        if problem:
            raise Mismatch(f"{op} on {label}, edge {e} = ({a}, {b}), operation {done + 1}: {problem}")
        V, F = np.asarray(V2, float), F2
        H = topology.halfedge_mesh(F2, len(V), manifold=True)
        done += 1
    if done == 0:
        raise Mismatch(f"{op} on {label}: every operation was refused")


@graded(points=3, part="local operations", visibility="hidden")
def test_hidden_split_chain(lab):
    """eight splits in a row on a bumpy sphere and a wavy patch: each adds the midpoint and its faces, keeps every invariant"""
    rng = np.random.default_rng(11)
    _chain(lab, "split_edge", *bumpy_sphere(2, 3), rng.integers(0, 10**6, 8), "a bumpy sphere", refusals=False)
    _chain(lab, "split_edge", *wavy_patch(6), rng.integers(0, 10**6, 8), "a wavy patch", refusals=False)


@graded(points=3, part="local operations", visibility="hidden")
def test_hidden_flip_chain(lab):
    """eight flips in a row on a torus: each replaces the edge by the other diagonal (refusals allowed)"""
    rng = np.random.default_rng(12)
    _chain(lab, "flip_edge", *datasets.torus(n_major=12, n_minor=8), rng.integers(0, 10**6, 8), "a torus")


@graded(points=4, part="local operations", visibility="hidden")
def test_hidden_collapse_chain(lab):
    """eight collapses in a row on a bumpy sphere and a wavy patch: each merges the ends and drops its faces (refusals allowed)"""
    rng = np.random.default_rng(13)
    _chain(lab, "collapse_edge", *bumpy_sphere(2, 3), rng.integers(0, 10**6, 8), "a bumpy sphere")
    _chain(lab, "collapse_edge", *wavy_patch(6), rng.integers(0, 10**6, 8), "a wavy patch")
