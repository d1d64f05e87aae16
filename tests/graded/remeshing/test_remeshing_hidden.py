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

from ..common import expect_true  # noqa: E402
from .support import bumpy_sphere, halfedges, validity_problem, wavy_patch  # noqa: E402


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


# --------------------------------------------------------------------------------------------
# hidden: the collapse and flip passes (Tasks 5 and 6) on inputs whose answer the rules fix, so
# that the bookkeeping the kernels keep between operations (valences, vertex classes) is graded.
# 120 s per call: the first call of a pass in a grading run compiles its kernels (seconds of CPU).


def _isolated_short_edges(n=8):
    """The wavy patch with five edges shrunk to a tenth, no two in one face: two pairs of free
    vertices at the end of a row (the next index is on the boundary), two interior vertices beside
    the left boundary with their boundary neighbour, one free pair in the middle."""
    V, F = wavy_patch(n)
    N = n + 1
    pairs = [(j * N + n - 2, j * N + n - 1) for j in (2, 5)] + [(j * N, j * N + 1) for j in (2, 5)]
    pairs.append((4 * N + 4, 4 * N + 5))
    V = V.copy()
    for a, b in pairs:
        V[b] = V[a] + 0.1 * (V[b] - V[a])
    return V, F, pairs


@graded(points=2, part="stages", visibility="hidden", timeout=120)
def test_hidden_collapse_isolated_short_edges(lab):
    """five short edges far apart on a patch: two free ends meet at the midpoint, an interior end
    moves onto its boundary neighbour, every other vertex stays; 2 faces fewer per collapse"""
    V, F, pairs = _isolated_short_edges()
    V2, F2 = lab.collapse_short_edges(V, F, 0.3 / 8, 10.0)  # grid step 1/8: only the shrunk edges are short
    H = halfedges(V, F)
    W, gone = V.copy(), []
    for a, b in pairs:
        if H.boundary_vertex[a] != H.boundary_vertex[b]:
            gone.append(a if H.boundary_vertex[b] else b)
        else:
            W[a] = 0.5 * (V[a] + V[b])
            gone.append(b)
    W = np.delete(W, gone, axis=0)
    V2, F2 = np.asarray(V2, float), np.asarray(F2)
    if V2.shape != W.shape or len(F2) != len(F) - 2 * len(pairs):
        raise Mismatch(
            f"collapse_short_edges: {len(V2)} vertices and {len(F2)} faces, expected {len(W)} and "
            f"{len(F) - 2 * len(pairs)} (each of the {len(pairs)} short edges collapsed once)"
        )
    dist, match = cKDTree(W).query(V2)
    if dist.max() > 1e-9 or len(np.unique(match)) != len(match):
        i = int(np.argmax(dist))
        raise Mismatch(
            f"collapse_short_edges: vertex {i} at {np.round(V2[i], 6).tolist()} is not where the rules put it "
            "(two free ends meet at the midpoint, a boundary end stays where it is)"
        )


@graded(points=1, part="stages", visibility="hidden", timeout=120)
def test_hidden_collapse_pass_goes_on(lab):
    """the wavy patch with low = 1.2 x its mean edge: collapses go on across the patch (valences
    updated after each collapse); at most 27 of its 81 vertices stay (solution: 22)"""
    V, F = wavy_patch(8)
    L = float(np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean())
    V2, F2 = lab.collapse_short_edges(V, F, 1.2 * L, 3.0 * L)
    problem = validity_problem(V, F, V2, F2)
    if problem:
        raise Mismatch(f"collapse_short_edges on the wavy patch: {problem}")
    expect_true(
        "collapse_short_edges on the wavy patch",
        len(V2) <= 27,
        f"{len(V2)} vertices stay, expected at most 27: collapses stopped early (is each vertex's valence "
        "kept right after a collapse, on the boundary too?)",
    )


def _flip_one_edge(F, f=0):
    """``F`` with the first edge of face ``f``, (a, b) with faces (a, b, c), (b, a, d), flipped to c-d."""
    F = np.array(F)
    a, b, c = F[f]
    g = [i for i in np.flatnonzero(((F == a) | (F == b)).sum(axis=1) == 2).tolist() if i != f][0]
    d = [v for v in F[g].tolist() if v not in (a, b)][0]
    F[f], F[g] = (c, a, d), (d, b, c)
    return F


@graded(points=2, part="stages", visibility="hidden", timeout=120)
def test_hidden_equalize_restores_a_regular_torus(lab):
    """a torus of valence 6 everywhere is left as it is; with one edge flipped (two 5s, two 7s),
    flipping it back is the one flip that lowers the deviation: the torus comes back"""
    V, F = datasets.torus(n_major=24, n_minor=16)
    for label, F_in in (("the regular torus", F), ("the torus with one edge flipped", _flip_one_edge(F, 40))):
        V2, F2 = lab.equalize_valences(V, F_in)
        expect_true(f"equalize_valences on {label}", np.array_equal(np.asarray(V2), V), "a flip moves no vertex")
        expect_true(
            f"equalize_valences on {label}",
            _canonical(F2) == _canonical(F),
            "the faces are not the regular torus's: "
            + ("a flip was made although every valence is 6" if F_in is F else "the flipped edge was not flipped back"),
        )
