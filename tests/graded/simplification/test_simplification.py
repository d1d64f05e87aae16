"""Graded tests of the simplification lab: ``test_references`` runs ``cases.py``; the tests below check quadrics,
placement, the link condition and contractions on a fan, a grid, a tetrahedron and an octahedron, the greedy
loop's face counts and errors (answers worked out by hand in each docstring; see
``tests/graded/__init__.py``).
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, topology
from geomlib.grading import expect_close, expect_raises, graded, reference_tests
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import marked_picture

from ..common import expect_rejected, expect_true
from .cases import CASES
from .support import (
    FAN_F,
    FAN_V,
    GRID_F,
    GRID_V,
    OCTA_F,
    OCTA_V,
    TET_F,
    TET_V,
    cracked_sheet,
    noisy_icosphere,
    random_quadrics,
    rename_and_drop,
    two_tetrahedra,
    validity_problem,
)

test_references = reference_tests(CASES)

#: The triangle through (1, 0, 0), (0, 1, 0), (0, 0, 1): plane x + y + z = 1, area √3 / 2.
TILTED_V = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1]])
TILTED_F = np.array([[0, 1, 2]])
TILTED_P = np.array([1.0, 1.0, 1.0, -1.0]) / np.sqrt(3)  # unit normal, d = -n · v0


def expect_tilted_face_quadric(lab) -> None:
    """The area-weighted quadric of the tilted triangle: K = (√3 / 2) p pᵀ."""
    K = lab.face_quadrics(TILTED_V, TILTED_F)
    expect_close(
        "face_quadrics on the tilted triangle",
        np.asarray(K)[0],
        np.sqrt(3) / 2 * np.outer(TILTED_P, TILTED_P),
        name="K[0]",
    )


# --------------------------------------------------------------------------------------------
# Task 1: quadrics


@graded(points=1, part="quadrics")
def test_face_quadric_of_a_tilted_triangle(lab):
    """plane x + y + z = 1: p = (1, 1, 1, -1)/√3, K = area · p pᵀ with area √3/2"""
    expect_tilted_face_quadric(lab)
    K = lab.face_quadrics(TILTED_V, TILTED_F, weighting="uniform")
    expect_close(
        'face_quadrics(weighting="uniform") on the tilted triangle',
        np.asarray(K)[0],
        np.outer(TILTED_P, TILTED_P),
        name="K[0]",
        hint="uniform weighting has no area factor",
    )


@graded(points=1, part="quadrics")
def test_boundary_quadrics_of_one_triangle(lab):
    """triangle (0,0,0), (1,0,0), (0,1,0) facing +z, weight 2: vertex 0 gets the walls y = 0 and x = 0

    Edge 0→1: m = (1,0,0) × (0,0,1) = (0,-1,0), |e|² = 1 → 2 · diag(0, 1, 0, 0).
    Edge 2→0: m = (0,-1,0) × (0,0,1) = (-1,0,0), |e|² = 1 → 2 · diag(1, 0, 0, 0).
    Edge 1→2: m = (1,1,0)/√2 through (1,0,0), |e|² = 2 → q = (1,1,0,-1)/√2, 2 · 2 · q qᵀ.
    """
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    Q = np.asarray(lab.boundary_quadrics(V, [[0, 1, 2]], weight=2.0))
    q = np.array([1.0, 1.0, 0.0, -1.0]) / np.sqrt(2)
    expect_close("boundary_quadrics at vertex 0", Q[0], 2 * np.diag([1.0, 1.0, 0, 0]), name="Q[0]")
    expect_close("boundary_quadrics at vertex 1", Q[1], 2 * np.diag([0, 1.0, 0, 0]) + 4 * np.outer(q, q), name="Q[1]")


@graded(points=1, part="quadrics")
def test_vertex_quadrics_vanish_at_their_vertex(lab):
    """vᵀ Q_v v = 0 at each vertex's own position (it lies on all its planes); Q is symmetric PSD"""
    V, F = noisy_icosphere(2, 0.02, 1)
    Q = np.asarray(lab.vertex_quadrics(V, F))
    Vh = np.c_[V, np.ones(len(V))]
    expect_close(
        "vertex_quadrics: vᵀ Q_v v at every vertex",
        np.einsum("ki,kij,kj->k", Vh, Q, Vh),
        np.zeros(len(V)),
        atol=1e-12,
        mesh=(V, F),
    )
    expect_close("vertex_quadrics: Q - Qᵀ", Q - np.swapaxes(Q, 1, 2), np.zeros_like(Q), mesh=(V, F))
    # the quadric of a vertex sums the quadrics of its faces: at any point x, xᵀ Q_v x = Σ area · dist²
    x = np.array([0.3, -0.2, 0.9, 1.0])
    v = 7
    faces = F[(F == v).any(axis=1)]
    n = np.cross(V[faces[:, 1]] - V[faces[:, 0]], V[faces[:, 2]] - V[faces[:, 0]])
    area = 0.5 * np.linalg.norm(n, axis=1)
    dist = np.einsum("ij,ij->i", x[:3] - V[faces[:, 0]], n / (2 * area[:, None]))
    expect_close("vertex_quadrics: xᵀ Q_7 x", x @ Q[v] @ x, np.sum(area * dist**2), atol=1e-12)


@graded(points=1, part="quadrics")
def test_quadrics_reject_an_unknown_weighting(lab):
    """a correct result on valid input, then a MeshError naming the bad weighting"""
    expect_tilted_face_quadric(lab)
    expect_raises(lambda: lab.face_quadrics(TILTED_V, TILTED_F, weighting="volume"), "MeshError", match="weighting")


# --------------------------------------------------------------------------------------------
# Task 2: placement


def planes(*ps) -> np.ndarray:
    return sum(np.outer(p, p) for p in np.asarray(ps, dtype=float))


def expect_contraction(lab, label, Q, v1, v2, position, cost, *, atol, cost_atol=None, hint=None) -> None:
    """``optimal_contraction(Q, v1, v2)`` gives ``position`` (within ``atol``) and ``cost``."""
    pos, c = lab.optimal_contraction(Q, v1, v2)
    expect_close(f"optimal_contraction, {label}", pos, position, atol=atol, name="position", hint=hint)
    expect_close(f"optimal_contraction, {label}", c, cost, atol=atol if cost_atol is None else cost_atol, name="cost")


@graded(points=1, part="placement")
def test_placement_regular_system(lab):
    """planes x = 0, y = 0, z = 0 and x = 1: A = diag(2, 1, 1), b = (-1, 0, 0) → x = (1/2, 0, 0), cost 1/4 + 1/4"""
    Q = planes([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, -1])
    expect_contraction(lab, "regular A", Q, [5.0, 5, 5], [6.0, 6, 6], [0.5, 0, 0], 0.5, atol=1e-12)


@graded(points=1, part="placement")
def test_placement_flat_neighbourhood_takes_the_midpoint(lab):
    """all planes z = 0: A singular and the cost 0 along the whole segment → the midpoint"""
    expect_contraction(
        lab, "flat neighbourhood", planes([0, 0, 1, 0]), [0.0, 0, 0], [1.0, 2, 0], [0.5, 1, 0], 0.0, atol=1e-12,
        hint="A is singular and the cost is constant on the segment: ties go to the midpoint",
    )  # fmt: skip


@graded(points=1, part="placement")
def test_placement_linear_neighbourhood_searches_the_segment(lab):
    """planes x = 0 and y = 0 (a line of minimisers): on v1 + t(v2 - v1) the cost is (4t - 1)² + 1/4 → t = 1/4"""
    Q = planes([1, 0, 0, 0], [0, 1, 0, 0])
    expect_contraction(
        lab, "linear neighbourhood", Q, [-1.0, 0.5, 0], [3.0, 0.5, 2], [0.0, 0.5, 0.5], 0.25, atol=1e-9,
        hint="t* = -dᵀ(A v1 + b) / (dᵀ A d), clipped to [0, 1]",
    )  # fmt: skip
    # t* = 5 for the line x = 5, y = 0 and the segment (0,0,0)-(1,0,0): clipped to t = 1, cost 16
    expect_contraction(
        lab, "minimiser beyond v2", planes([1, 0, 0, -5], [0, 1, 0, 0]), [0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], 16.0,
        atol=1e-12, cost_atol=1e-9, hint="clip t to [0, 1]",
    )  # fmt: skip


@graded(points=1, part="placement")
def test_placement_batched_equals_one_by_one(lab):
    """k pairs at once give the same answers as k single calls (regular, flat and linear mixed); cost = quadric error at p"""
    Q = np.concatenate(
        [random_quadrics(4, seed=3) + 0.1 * np.eye(4), [planes([0, 0, 1, 0])], [planes([1, 0, 0, 0], [0, 1, 0, 0])]]
    )
    rng = np.random.default_rng(4)
    v1, v2 = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    pos, cost = lab.optimal_contraction(Q, v1, v2)
    expect_true(
        "optimal_contraction on 6 pairs",
        np.shape(pos) == (6, 3) and np.shape(cost) == (6,),
        f"expected shapes (6, 3) and (6,), got {np.shape(pos)} and {np.shape(cost)}",
    )
    for k in range(6):
        p1, c1 = lab.optimal_contraction(Q[k], v1[k], v2[k])
        expect_close(f"optimal_contraction: pair {k} alone vs in the batch", pos[k], p1, atol=1e-9, name="position")
        expect_close(f"optimal_contraction: pair {k} alone vs in the batch", cost[k], c1, atol=1e-9, name="cost")
    # The cost is the quadric error at the position returned: cost = [p, 1]ᵀ Q [p, 1].
    ph = np.c_[np.asarray(pos, float), np.ones(6)]
    expect_close(
        "optimal_contraction: cost vs [p, 1]ᵀ Q [p, 1] at the returned p",
        np.asarray(cost, float),
        np.einsum("ki,kij,kj->k", ph, Q, ph),
        atol=1e-9,
        name="cost",
    )


# --------------------------------------------------------------------------------------------
# Task 3: contraction


@graded(points=1, part="contraction")
def test_link_condition_tetrahedron_and_octahedron(lab):
    """tetrahedron: every edge fails (two copies of a triangle would remain); octahedron: every edge passes"""
    E = topology.unique_edges(TET_F)
    link, _ = lab.check_contractions(TET_V, TET_F, E, 0.5 * (TET_V[E[:, 0]] + TET_V[E[:, 1]]))
    expect_true(
        "link condition on a tetrahedron", not np.any(link), f"got {np.asarray(link).tolist()}, expected all False"
    )
    E = topology.unique_edges(OCTA_F)
    link, _ = lab.check_contractions(OCTA_V, OCTA_F, E, OCTA_V[E[:, 0]])
    expect_true(
        "link condition on an octahedron",
        np.all(link),
        f"got {np.asarray(link).tolist()}, expected all True (each edge has exactly its 2 opposite vertices in common)",
    )
    # check_contractions also runs the flip test. Contracting (0, 2) onto vertex 0 turns its two surviving faces by
    # 55 degrees (normal (-1, 1, 1) of face (2, 1, 4) becomes (0, 1, 0)): no flip. Onto vertex 1 = (-1, 0, 0), face
    # (2, 1, 4) becomes (1, 1, 4) with two equal corners: degenerate, which counts as flipped.
    _, flips = lab.check_contractions(OCTA_V, OCTA_F, [[0, 2], [0, 2]], OCTA_V[[0, 1]])
    expect_true(
        "flip test on the octahedron, edge (0, 2) onto vertex 0 / onto vertex 1",
        np.asarray(flips).tolist() == [False, True],
        f"got {np.asarray(flips).tolist()}, expected [False, True] (a face with two equal corners is degenerate)",
    )


@graded(points=1, part="contraction")
def test_link_condition_on_a_boundary(lab):
    """3 x 3 grid: boundary edges pass; interior edges between two boundary vertices would pinch the disk"""
    E = topology.unique_edges(GRID_F)
    link, _ = lab.check_contractions(GRID_V, GRID_F, E, GRID_V[E[:, 0]])
    B = {tuple(sorted(e)) for e in topology.boundary_edges(GRID_F).tolist()}
    expected = []
    for a, b in E.tolist():
        if (a, b) in B:  # a boundary edge: common neighbours = the opposite vertex (+ the outside)
            expected.append(True)
        else:  # interior edges: those touching the centre vertex 4 pass, the others join two boundary vertices
            expected.append(4 in (a, b))
    got = np.asarray(link).tolist()
    bad = [tuple(e) for e, g, x in zip(E.tolist(), got, expected) if g != x]
    expect_true(
        "link condition on the 3 x 3 grid",
        not bad,
        f"edges {bad} are wrong (expected {[x for e, x in zip(E.tolist(), expected) if tuple(e) in bad]}); "
        "count the outside of the boundary as one extra vertex next to every boundary vertex",
    )
    # check_contractions also runs the flip test: moving 1 onto 0 keeps the flat faces (0, 4, 3), (1, 2, 5) and
    # (1, 5, 4) facing up; moving both onto vertex 2 squashes face (1, 2, 5) to a segment (degenerate: flipped).
    # Non-edge pairs: (0, 2) share vertex 1, joined to both by boundary edges (zipping them is fine); (4, 2) share 1
    # and 5, joined to 4 by interior edges (an edge would end up in three faces).
    link, _ = lab.check_contractions(GRID_V, GRID_F, [[0, 2], [4, 2]], GRID_V[[0, 4]])
    expect_true(
        "link condition on the 3 x 3 grid, non-edge pairs (0, 2) and (4, 2)",
        np.asarray(link).tolist() == [True, False],
        f"got {np.asarray(link).tolist()}, expected [True, False]: a non-edge pair passes only when every common "
        "neighbour is joined to both ends by boundary edges (one face each)",
    )
    _, flips = lab.check_contractions(GRID_V, GRID_F, [[0, 1], [0, 1]], GRID_V[[0, 2]])
    expect_true(
        "flip test on the 3 x 3 grid, edge (0, 1) onto vertex 0 / onto vertex 2",
        np.asarray(flips).tolist() == [False, True],
        f"got {np.asarray(flips).tolist()}, expected [False, True] (a face with two equal corners is degenerate)",
    )


@graded(points=1, part="contraction")
def test_flip_test_on_a_fan(lab):
    """fan around vertex 0: moving (0, 1) to (0.5, 0) is fine; (-2, 2) turns face (0, 2, 3) over; (-0.5, 0.5) flattens it"""
    # A fourth pair, the non-edge pair (1, 3) moved onto vertex 0: face (0, 1, 2) gets two equal corners (flipped),
    # and the pair fails the link condition (its common neighbour 0 is joined to 1 by an interior edge).
    link, flips = lab.check_contractions(
        FAN_V, FAN_F, [[0, 1]] * 3 + [[1, 3]], [[0.5, 0, 0], [-2.0, 2.0, 0], [-0.5, 0.5, 0], [0, 0, 0]]
    )
    expect_true(
        "flip test on the fan",
        np.asarray(flips).tolist() == [False, True, True, True],
        f"got {np.asarray(flips).tolist()}, expected [False, True, True, True] (a face on the line through vertices 2 "
        "and 3 is degenerate and counts as flipped, as is a face with two equal corners)",
    )
    expect_true(
        "link condition on the fan",
        np.asarray(link).tolist() == [True, True, True, False],
        f"got {np.asarray(link).tolist()}, expected [True, True, True, False]: edge (0, 1) has exactly its 2 opposite "
        "vertices in common; the non-edge pair (1, 3) shares vertex 0 through interior edges",
    )
    # The degeneracy threshold, 1e-10 x the sum of the face's three squared edge lengths: two faces (0, 1, 2) and
    # (2, 1, 3); contracting (2, 3) to (0.5, h, 0) leaves (0, 1, p) with base 1 and height h, |n'| = h, squared edges
    # 1 + 0.25 + 0.25 = 1.5 (+ h^2): degenerate (flipped) for h = 1.1e-10 <= 1.5e-10, not for h = 3e-10.
    V2 = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 2, 0]])
    _, flips = lab.check_contractions(V2, [[0, 1, 2], [2, 1, 3]], [[2, 3]] * 2, [[0.5, 1.1e-10, 0], [0.5, 3e-10, 0]])
    expect_true(
        "flip test: a face squashed to height 1.1e-10 / 3e-10 over a base of length 1",
        np.asarray(flips).tolist() == [True, False],
        f"got {np.asarray(flips).tolist()}, expected [True, False]: degenerate means |n'| <= 1e-10 x (sum of the "
        "face's three squared edge lengths)",
    )
    # Flip and degeneracy tests are relative (|n'| against the face's squared edge lengths): the same fan shrunk
    # by 1e-6 gives the same answers.
    _, flips = lab.check_contractions(
        FAN_V * 1e-6, FAN_F, [[0, 1]] * 3, np.array([[0.5, 0, 0], [-2.0, 2.0, 0], [-0.5, 0.5, 0]]) * 1e-6
    )
    expect_true(
        "flip test on the fan shrunk by 1e-6",
        np.asarray(flips).tolist() == [False, True, True],
        f"got {np.asarray(flips).tolist()}, expected [False, True, True] as on the full-size fan: compare |n'| with "
        "1e-10 x the sum of the face's squared edge lengths, not with an absolute number",
    )


@graded(points=1, part="contraction")
def test_contract_one_octahedron_edge(lab):
    """contracting (0, 2) of the octahedron: the two faces on the edge die, 2 becomes 0, Q[0] = Q0 + Q2"""
    Q = random_quadrics(6, seed=1)
    V, F, Q2, removed = lab.contract_pairs(OCTA_V, OCTA_F, Q, [[0, 2]], [[0.5, 0.5, 0.0]])
    expect_close("contract_pairs: removed faces", removed, [2], name="removed")
    expected_F = rename_and_drop(OCTA_F, [(0, 2)])
    if np.shape(F) != expected_F.shape or not np.array_equal(F, expected_F):
        raise Mismatch(
            f"contract_pairs on the octahedron: F should be {expected_F.tolist()}, got {np.asarray(F).tolist()}"
        )
    expect_close("contract_pairs: V[0]", np.asarray(V)[0], [0.5, 0.5, 0.0], name="V[0]", mesh=(OCTA_V, OCTA_F))
    expect_close("contract_pairs: Q[0]", np.asarray(Q2)[0], Q[0] + Q[2], name="Q[0]")


@graded(points=1, part="contraction")
def test_contraction_chain_keeps_the_bookkeeping(lab):
    """three contractions in a row around one vertex: each must see the faces the previous one gave it"""
    V, F = datasets.icosphere(1)
    Q = random_quadrics(len(V), seed=2)
    A = topology.vertex_adjacency(F)
    ring = A.indices[A.indptr[0] : A.indptr[1]]
    pairs = [(0, int(ring[0])), (0, int(ring[2])), (0, int(ring[4]))]
    _, F2, Q2, removed = lab.contract_pairs(V, F, Q, pairs, np.repeat(V[:1], 3, axis=0))
    expected_F = rename_and_drop(F, pairs)
    if np.shape(F2) != expected_F.shape or not np.array_equal(F2, expected_F):
        raise Mismatch(
            f"contract_pairs, 3 contractions into vertex 0: expected {len(expected_F)} faces (kept in their original order, "
            f"renamed), got {np.shape(F2)[0] if np.ndim(F2) == 2 else F2}; update vertex_faces of the survivor"
        )
    expect_close("contract_pairs: faces removed by each", removed, [2, 2, 2], name="removed")
    expect_close(
        "contract_pairs: Q[0] after three merges",
        np.asarray(Q2)[0],
        Q[[0, *[j for _, j in pairs]]].sum(axis=0),
        name="Q[0]",
    )


# --------------------------------------------------------------------------------------------
# Task 4: the greedy loop


@graded(points=1, part="greedy loop")
def test_face_count_is_within_two_of_the_target(lab):
    """targets 200, 101 and 40 on a torus of 576 faces: each result within 2, valid, no flips"""
    V, F = datasets.torus(n_major=24, n_minor=12)
    for target in (200, 101, 40):
        V2, F2 = lab.qem_simplify(V, F, target)
        problem = validity_problem(V, F, V2, F2, target)
        if problem:
            raise Mismatch(f"qem_simplify(torus, {target}): {problem}")


@graded(points=1, part="greedy loop")
def test_box_simplifies_to_twelve_exact_triangles(lab):
    """a sharp box of 432 faces needs only 12 triangles: the 8 corners stay where they are (zero cost)"""
    V, F = datasets.sharp_box(n=6)
    V2, F2 = lab.qem_simplify(V, F, 12)
    problem = validity_problem(V, F, V2, F2, 12)
    if problem:
        raise Mismatch(f"qem_simplify(sharp box, 12): {problem}")
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    V2 = np.asarray(V2, float)
    d = np.linalg.norm(V2[:, None] - corners[None], axis=2).min(axis=0)
    if d.max() >= 1e-6:
        raise Mismatch(
            f"qem_simplify(sharp box, 12): a box corner has no vertex within 1e-6 (nearest at {d.max():.3g}); three "
            "planes meet in each corner, so the optimal position of a pair there is the corner itself",
            marked_picture("qem_simplify(sharp box, 12)", V2, F2, corners[d >= 1e-6], "box corners with no vertex"),
        )


@graded(points=1, part="greedy loop")
def test_unreachable_target_gives_a_clear_error(lab):
    """two tetrahedra (8 faces) cannot lose a face without breaking the link condition; an icosahedron beside a
    tetrahedron stops at 8 too, once the icosahedron is down to a tetrahedron"""
    V, F = two_tetrahedra()
    expect_rejected(lab, "qem_simplify", V, F, 4, match="stopped at 8", label="qem_simplify(two tetrahedra, 4)")
    # The same stop after real work (a loop that does nothing stops at the icosahedron's 20 + 4 faces).
    Vi, Fi = datasets.icosphere(0)
    V, F = np.r_[Vi, TET_V + 3.0], np.r_[Fi, TET_F + len(Vi)]
    expect_rejected(
        lab, "qem_simplify", V, F, 4, match="stopped at 8", label="qem_simplify(icosahedron and tetrahedron, 4)"
    )


@graded(points=1, part="greedy loop")
def test_non_edge_pairs_close_a_crack(lab):
    """two sheets 0.02 apart: with pair_threshold = 0.05 the crack is zipped into one piece"""
    V, F = cracked_sheet()
    V2, F2 = lab.qem_simplify(V, F, 20, pair_threshold=0.05, preserve_boundary=False)
    F2 = np.asarray(F2)
    count = topology.connected_components_faces(F2)[0]
    expect_true(
        "qem_simplify(cracked sheet, 20, pair_threshold=0.05)",
        count == 1 and topology.is_edge_manifold(F2) and abs(len(F2) - 20) <= 2,
        f"got {count} piece(s) and {len(F2)} faces, edge-manifold: {topology.is_edge_manifold(F2)}; expected one "
        "piece of about 20 faces: non-edge pairs closer than the threshold must be in the heap too",
    )


@graded(points=1, part="greedy loop")
def test_flat_sheet_contracts_into_the_midpoint(lab):
    """a flat 4 x 4 grid, boundary not kept: every pair costs 0 and the placement's ties go to the midpoint, so the
    one contraction down to 31 faces leaves one new vertex, the midpoint of an edge of the grid"""
    V, F = datasets.grid_patch(4)
    V2, F2 = lab.qem_simplify(V, F, len(F) - 1, preserve_boundary=False)
    V2 = np.asarray(V2, float)
    new = V2[np.linalg.norm(V2[:, None] - V[None], axis=2).min(axis=1) > 1e-9]
    E = topology.unique_edges(F)
    mids = 0.5 * (V[E[:, 0]] + V[E[:, 1]])
    at_mid = len(new) == 1 and np.linalg.norm(mids - new[0], axis=1).min() <= 1e-9
    expect_true(
        f"qem_simplify(flat 4 x 4 grid, {len(F) - 1}, preserve_boundary=False)",
        at_mid,
        f"got {len(new)} vertices not in the input ({np.round(new[:3], 4).tolist()}); expected exactly one, at the "
        "midpoint of the contracted edge: on a flat sheet A is singular and the cost is 0 along every edge, so "
        "optimal_contraction picks the midpoint — the heap's positions (also the first ones) come from it",
    )


@graded(points=1, part="greedy loop")
def test_bad_targets(lab):
    """a valid call first, then MeshErrors for target < 4, target > faces and a non-integer target"""
    V, F = noisy_icosphere(1, 0.01, 0)
    V2, F2 = lab.qem_simplify(V, F, 40)
    problem = validity_problem(V, F, V2, F2, 40)
    if problem:
        raise Mismatch(f"qem_simplify(icosphere, 40): {problem}")
    expect_rejected(lab, "qem_simplify", V, F, 3, match=">= 4", label="qem_simplify(target_faces=3)")
    expect_rejected(lab, "qem_simplify", V, F, 81, match="more than", label="qem_simplify(target_faces=81)")
    expect_rejected(lab, "qem_simplify", V, F, 40.5, match="integer", label="qem_simplify(target_faces=40.5)")
