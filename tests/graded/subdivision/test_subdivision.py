"""Graded tests of the subdivision lab: ``test_references`` runs ``cases.py``; the tests below check the matrix
rows, connectivity and boundary rules of Loop and Catmull-Clark on a triangle, a square, a quad, a tetrahedron
and an octahedron, level counts and errors (answers worked out by hand in each docstring; see
``tests/graded/__init__.py``).
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, topology
from geomlib.grading import expect_close, expect_raises, graded, reference_tests
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import marked_picture, picture_context

from ..common import expect_rejected
from .cases import CASES
from .support import (
    EVEN_BOUNDARY_NEIGHBOUR,
    EVEN_BOUNDARY_SELF,
    OCTA_F,
    OCTA_V,
    ODD_BOUNDARY,
    ODD_ENDS,
    ODD_OPPOSITE,
    QUAD_F,
    QUAD_V,
    REG_TET_F,
    REG_TET_V,
    SQUARE_F,
    SQUARE_V,
    TET_F,
    TET_V,
    TRIANGLE_F,
    TRIANGLE_V,
    as_dense,
    centroids,
    faces_mismatch,
    loop_beta,
    matrix_mismatch,
    matrix_picture,
    warren_weight,
)

test_references = reference_tests(CASES)


def expect_matrix(label: str, got, expected, name: str = "S", mesh=None) -> None:
    """Compare a subdivision matrix; on failure, the rows that are wrong are marked on ``mesh = (V, F)``."""
    msg = matrix_mismatch(name, np.asarray(expected, float), got)
    if msg:
        picture = matrix_picture(picture_context(label, name), *mesh, expected, got, name) if mesh else None
        raise Mismatch(f"{label}: {msg}", picture)


def expect_distinct(label: str, V, faces) -> None:
    """Subdivision makes a new point for every vertex, edge and face: no two vertices of the result coincide."""
    from scipy.spatial import cKDTree

    V = np.asarray(V, float)
    d, _ = cKDTree(V).query(V, k=2)
    same = d[:, 1] <= 1e-9
    if same.any():
        raise Mismatch(
            f"{label}: {int(same.sum())} of {len(V)} vertices sit on another vertex; every new vertex has a place of its own",
            marked_picture(label, V, faces, V[same], "vertices on top of another"),
        )


def expect_faces(label: str, got, expected, name: str = "F") -> None:
    msg = faces_mismatch(name, np.asarray(expected), got)
    if msg:
        raise Mismatch(f"{label}: {msg}")


# --------------------------------------------------------------------------------------------
# Task 1: odd vertices


@graded(points=2, part="odd vertices")
def test_tetrahedron_odd_rows(lab):
    """tetrahedron: every edge (a, b) gets 3/8, 3/8 on its ends and 1/8, 1/8 on the two other vertices"""
    S = lab.loop_odd_matrix(TET_V, TET_F)
    # Edges in sorted order (0,1), (0,2), (0,3), (1,2), (1,3), (2,3); in a tetrahedron the two
    # vertices opposite an edge are simply the two vertices not on it.
    E = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    expected = np.full((6, 4), ODD_OPPOSITE)
    for i, (a, b) in enumerate(E):
        expected[i, [a, b]] = ODD_ENDS
    expect_matrix("loop_odd_matrix on the tetrahedron", S, expected, "S_odd", mesh=(TET_V, TET_F))


@graded(points=1, part="odd vertices")
def test_octahedron_odd_positions(lab):
    """octahedron: the new vertex on edge (+x, +y) is 3/8 (x + y) + 1/8 (z + (-z)) = (3/8, 3/8, 0)"""
    S = as_dense(lab.loop_odd_matrix(OCTA_V, OCTA_F), "S_odd")
    E = topology.unique_edges(OCTA_F)
    # Every edge joins two unit vectors on different axes; its opposite vertices are the two
    # antipodes on the third axis, which cancel: odd = 3/8 (a + b).
    expected = ODD_ENDS * (OCTA_V[E[:, 0]] + OCTA_V[E[:, 1]])
    expect_close(
        "loop_odd_matrix(octahedron) @ V", S @ OCTA_V, expected, atol=1e-12, name="odd vertices", mesh=(OCTA_V, OCTA_F)
    )


# --------------------------------------------------------------------------------------------
# Task 2: even vertices


@graded(points=1, part="even vertices")
def test_weights_by_hand(lab):
    """loop_weight: both rules give 3/16 at n = 3 and 1/16 at n = 6; at n = 4 Warren 3/32, Loop 31/256"""
    # beta(4) = (5/8 - (3/8 + cos(pi/2)/4)^2) / 4 = (5/8 - 9/64) / 4 = 31/256
    expect_close("loop_weight([3, 4, 6], 'warren')", lab.loop_weight([3, 4, 6], "warren"), warren_weight([3, 4, 6]))
    expect_close("loop_weight([3, 4, 6], 'loop')", lab.loop_weight([3, 4, 6], "loop"), loop_beta([3, 4, 6]))


def _face_split(V, F, point):
    """``(V, F)`` with face 0 split at a new last vertex ``point``: mixed valences (3 at the new vertex)."""
    V = np.r_[np.asarray(V, float), [point]]
    n, (a, b, c) = len(V) - 1, F[0]
    return V, np.r_[[[a, b, n], [b, c, n], [c, a, n]], F[1:]]


def _even_rows(F, n, rule):
    """The even rows by the handout's rule: 1 - k u(k) on v, u(k) on each of its k neighbours."""
    A = np.zeros((n, n))
    for i, j in topology.unique_edges(F):
        A[i, j] = A[j, i] = 1
    k = A.sum(axis=1)
    u = rule(k)
    return A * u[:, None] + np.diag(1 - k * u)


@graded(points=2, part="even vertices")
def test_octahedron_even_rows(lab):
    """octahedron, valence 4: row v = (1 - 4u) on v and u on its 4 neighbours (every vertex but its antipode);
    with face 0 split at its centre (valences 3, 4, 5), each row takes the weight of its own valence"""
    for weights, u in (("warren", warren_weight(4)), ("loop", loop_beta(4))):
        expected = np.full((6, 6), u)
        np.fill_diagonal(expected, 1 - 4 * u)
        for k in range(3):
            expected[2 * k, 2 * k + 1] = expected[2 * k + 1, 2 * k] = 0.0  # antipodes are not neighbours
        S = lab.loop_even_matrix(OCTA_V, OCTA_F, weights)
        expect_matrix(
            f"loop_even_matrix(octahedron, weights={weights!r})", S, expected, "S_even", mesh=(OCTA_V, OCTA_F)
        )
    V, F = _face_split(OCTA_V, OCTA_F, [0.4, 0.4, 0.4])
    for weights, rule in (("warren", warren_weight), ("loop", loop_beta)):
        expect_matrix(
            f"loop_even_matrix(octahedron with face 0 split, weights={weights!r})",
            lab.loop_even_matrix(V, F, weights),
            _even_rows(F, len(V), rule),
            "S_even",
            mesh=(V, F),
        )


@graded(points=1, part="even vertices")
def test_tetrahedron_even_rows(lab):
    """tetrahedron, valence 3: both rules give u = 3/16, so each row is 7/16 on v and 3/16 on the others;
    with face 0 split at its centre (valences 3 and 4), the rules differ on the rows of valence 4"""
    expected = np.full((4, 4), 3 / 16)
    np.fill_diagonal(expected, 7 / 16)
    V, F = _face_split(TET_V, TET_F, np.mean(TET_V[TET_F[0]], axis=0) * 1.2)
    for weights, rule in (("warren", warren_weight), ("loop", loop_beta)):
        expect_matrix(
            f"loop_even_matrix(tetrahedron, {weights!r})",
            lab.loop_even_matrix(TET_V, TET_F, weights),
            expected,
            "S_even",
            mesh=(TET_V, TET_F),
        )
        expect_matrix(
            f"loop_even_matrix(tetrahedron with face 0 split, {weights!r})",
            lab.loop_even_matrix(V, F, weights),
            _even_rows(F, len(V), rule),
            "S_even",
            mesh=(V, F),
        )


# --------------------------------------------------------------------------------------------
# Task 3: connectivity


@graded(points=2, part="connectivity")
def test_one_triangle_faces(lab):
    """one triangle (0, 1, 2): edges (0,1), (0,2), (1,2) become vertices 3, 4, 5 -> four oriented triangles"""
    F = lab.loop_faces(TRIANGLE_F)
    # m01 = 3, m20 = 4, m12 = 5: corners (0, m01, m20), (1, m12, m01), (2, m20, m12) and the middle one.
    expect_faces("loop_faces on one triangle", F, [[0, 3, 4], [1, 5, 3], [2, 4, 5], [3, 5, 4]])


@graded(points=1, part="connectivity")
def test_closed_mesh_stays_closed(lab):
    """icosphere: 4x the faces, every edge in exactly two faces with opposite directions, chi unchanged"""
    V, F = datasets.icosphere(1)
    F1 = np.asarray(lab.loop_faces(F))
    if F1.shape != (4 * len(F), 3):
        raise Mismatch(f"loop_faces(icosphere(1)) has shape {F1.shape}, expected {(4 * len(F), 3)}")
    he = np.stack([F1, np.roll(F1, -1, axis=1)], -1).reshape(-1, 2)
    if len(np.unique(he, axis=0)) != len(he) or not topology.is_closed(F1):
        raise Mismatch("loop_faces(icosphere(1)): the refined mesh is not closed and consistently oriented")
    chi0, chi1 = topology.euler_characteristic(F), topology.euler_characteristic(F1)
    if chi0 != chi1:
        raise Mismatch(f"loop_faces(icosphere(1)): Euler characteristic changed from {chi0} to {chi1}")


# --------------------------------------------------------------------------------------------
# Task 4: boundary rules


@graded(points=1, part="boundary rules")
def test_one_triangle_boundary_rows(lab):
    """one triangle: odd rows are midpoints, even rows 3/4 on the vertex and 1/8 on each other corner"""
    expect_matrix(
        "loop_odd_matrix on one triangle",
        lab.loop_odd_matrix(TRIANGLE_V, TRIANGLE_F),
        np.array([[1, 1, 0], [1, 0, 1], [0, 1, 1]]) * ODD_BOUNDARY,  # edges (0,1), (0,2), (1,2)
        "S_odd",
        mesh=(TRIANGLE_V, TRIANGLE_F),
    )
    expected = np.full((3, 3), EVEN_BOUNDARY_NEIGHBOUR)
    np.fill_diagonal(expected, EVEN_BOUNDARY_SELF)
    expect_matrix(
        "loop_even_matrix on one triangle",
        lab.loop_even_matrix(TRIANGLE_V, TRIANGLE_F, "loop"),
        expected,
        "S_even",
        mesh=(TRIANGLE_V, TRIANGLE_F),
    )


@graded(points=2, part="boundary rules")
def test_square_interior_edge_between_boundary_vertices(lab):
    """square split along 0-2: the interior edge keeps the 3/8-1/8 rule; vertex 0 ignores its interior neighbour 2"""
    # Edges (0,1), (0,2), (0,3), (1,2), (2,3). Only (0,2) is interior (opposite vertices 1 and 3).
    h, e, o = ODD_BOUNDARY, ODD_ENDS, ODD_OPPOSITE
    odd = [[h, h, 0, 0], [e, o, e, o], [h, 0, 0, h], [0, h, h, 0], [0, 0, h, h]]
    S = lab.loop_odd_matrix(SQUARE_V, SQUARE_F)
    expect_matrix("loop_odd_matrix on the split square", S, odd, "S_odd", mesh=(SQUARE_V, SQUARE_F))
    # Every vertex is on the boundary: 3/4 on itself, 1/8 on its two boundary neighbours only.
    # Vertex 0's boundary neighbours are 1 and 3; vertex 2 is a neighbour too, but across the interior edge.
    v, n = EVEN_BOUNDARY_SELF, EVEN_BOUNDARY_NEIGHBOUR
    even = [[v, n, 0, n], [n, v, n, 0], [0, n, v, n], [n, 0, n, v]]
    for weights in ("warren", "loop"):
        S = lab.loop_even_matrix(SQUARE_V, SQUARE_F, weights)
        expect_matrix(
            f"loop_even_matrix on the split square ({weights!r})", S, even, "S_even", mesh=(SQUARE_V, SQUARE_F)
        )


@graded(points=1, part="boundary rules", tasks=(4, 7, 8))  # the boundary branches of Tasks 7 and 8's functions
def test_one_quad_boundary_points(lab):
    """one quad: Catmull-Clark edge points are the midpoints, vertex points 3/4 P + 1/8 (two neighbours)"""
    fp = centroids(QUAD_V, QUAD_F)
    # edges (0,1), (0,3), (1,2), (2,3): their midpoints.
    # vertex 0 = (0,0): 1/8 ((2,0) + (0,2)) = (0.25, 0.25); the others by symmetry
    for function, name, expected in (
        ("cc_edge_points", "edge points", [[1, 0, 0], [0, 1, 0], [2, 1, 0], [1, 2, 0]]),
        ("cc_vertex_points", "vertex points", [[0.25, 0.25, 0], [1.75, 0.25, 0], [1.75, 1.75, 0], [0.25, 1.75, 0]]),
    ):
        got = getattr(lab, function)(QUAD_V, QUAD_F, fp)
        expect_close(f"{function} on one quad", got, expected, atol=1e-12, name=name, mesh=(QUAD_V, QUAD_F))


# --------------------------------------------------------------------------------------------
# Task 5: several levels


@graded(points=1, part="several levels")
def test_levels_zero_is_identity(lab):
    """levels=0 returns the input mesh unchanged (and levels=1 does not: n + e vertices, 4m faces)"""
    V, F = datasets.icosphere(1)
    V0, F0 = lab.loop_subdivide(V, F, 0)
    expect_close("loop_subdivide(levels=0) vertices", V0, V, atol=0.0, name="V", mesh=(V, F))
    expect_close("loop_subdivide(levels=0) faces", F0, F, atol=0.0, name="F")
    V1, F1 = lab.loop_subdivide(V, F, 1)
    n1 = len(V) + len(topology.unique_edges(F))
    if np.shape(V1) != (n1, 3) or np.shape(F1) != (4 * len(F), 3):
        raise Mismatch(
            f"loop_subdivide(icosphere(1), levels=1): got V {np.shape(V1)}, F {np.shape(F1)}; expected ({n1}, 3) and "
            f"({4 * len(F)}, 3)"
        )


@graded(points=2, part="several levels")
def test_subdivision_matrix_identity(lab):
    """return_matrix=True: S @ V equals the returned vertices, rows sum to 1, counts n + e per level"""
    V, F = datasets.icosphere(1)
    V2, F2, S = lab.loop_subdivide(V, F, 2, "loop", return_matrix=True)
    n1 = len(V) + len(topology.unique_edges(F))  # 42 + 120
    n2 = n1 + 3 * 4 * len(F) // 2  # e after one level = 3 * 4m / 2
    V2 = np.asarray(V2)
    if V2.shape != (n2, 3) or np.asarray(F2).shape != (16 * len(F), 3):
        raise Mismatch(
            f"loop_subdivide(icosphere(1), 2): got V {V2.shape}, F {np.asarray(F2).shape}; expected ({n2}, 3) and ({16 * len(F)}, 3)"
        )
    S = as_dense(S, "S")
    if S.shape != (n2, len(V)):
        raise Mismatch(f"loop_subdivide(..., return_matrix=True): S has shape {S.shape}, expected ({n2}, {len(V)})")
    expect_close("S @ V (return_matrix=True)", S @ V, V2, atol=1e-10, name="S @ V", mesh=(V2, F2))
    expect_close("row sums of S", S.sum(axis=1), np.ones(n2), atol=1e-10, name="row sums", mesh=(V2, F2))
    expect_distinct("loop_subdivide(icosphere(1), 2)", V2, F2)


@graded(points=1, part="several levels")
def test_planar_mesh_stays_planar(lab):
    """a flat open grid stays in its plane through three levels (both weight rules), every triangle facing up"""
    V, F = datasets.grid_patch(4)
    up = np.sign(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])[:, 2])
    assert (up == up[0]).all() and up[0] != 0, "the grid's triangles all face one way"
    for weights in ("warren", "loop"):
        V3, F3 = lab.loop_subdivide(V, F, 3, weights)
        expect_close(
            f"z of loop_subdivide(flat grid, 3, {weights!r})",
            np.asarray(V3)[:, 2],
            np.zeros(len(V3)),
            atol=1e-12,
            name="z",
            mesh=(V3, F3),
        )
        # Positive weights on a flat grid keep every triangle proper and facing the input's way.
        V3, F3 = np.asarray(V3, float), np.asarray(F3)
        if F3.shape != (64 * len(F), 3):
            raise Mismatch(
                f"loop_subdivide(flat grid, 3, {weights!r}): F has shape {F3.shape}, expected ({64 * len(F)}, 3): "
                "each level splits every triangle in 4"
            )
        z = np.cross(V3[F3[:, 1]] - V3[F3[:, 0]], V3[F3[:, 2]] - V3[F3[:, 0]])[:, 2] * up[0]
        if not (z > 1e-12).all():
            raise Mismatch(
                f"loop_subdivide(flat grid, 3, {weights!r}): {int((z <= 1e-12).sum())} of {len(z)} triangles are "
                "flat or flipped; refining a flat grid keeps every triangle proper and facing the same way",
                marked_picture("loop_subdivide(flat grid)", V3, F3, V3[np.unique(F3[z <= 1e-12])], "bad triangles"),
            )


@graded(points=1, part="several levels")
def test_old_vertices_keep_valence(lab):
    """after one level: V' = V + E, chi unchanged, old vertices keep their valence, new ones have 6 (interior)"""
    V, F = datasets.torus(n_major=8, n_minor=6)
    V1, F1 = lab.loop_subdivide(V, F)
    n, e = len(V), len(topology.unique_edges(F))
    V1, F1 = np.asarray(V1), np.asarray(F1)
    if len(V1) != n + e:
        raise Mismatch(f"loop_subdivide(torus): {len(V1)} vertices, expected V + E = {n} + {e} = {n + e}")
    val0 = np.sort(topology.valence(F, n))
    val1 = np.sort(topology.valence(F1, len(V1)))
    expected = np.sort(np.concatenate([val0, np.full(e, 6)]))
    if not np.array_equal(val1, expected) or topology.euler_characteristic(F1) != topology.euler_characteristic(F):
        raise Mismatch("loop_subdivide(torus): the valences or the Euler characteristic changed")


# --------------------------------------------------------------------------------------------
# Tasks 6-8: Catmull-Clark points


@graded(points=2, part="catmull-clark points")
def test_cube_by_hand(lab):
    """unit cube [-1/2, 1/2]^3: face points = face centres, edge points at 3/8, corner vertex points at 5/18"""
    V, Q = datasets.quad_cube()
    FP = lab.cc_face_points(V, Q)
    expect_close("cc_face_points(cube)", FP, centroids(V, Q), atol=1e-12, name="face points", mesh=(V, Q))
    # Edge (0, 1) runs along x at y = z = -1/2 between the faces y = -1/2 and z = -1/2:
    # ((-1/2,-1/2,-1/2) + (1/2,-1/2,-1/2) + (0,-1/2,0) + (0,0,-1/2)) / 4 = (0, -3/8, -3/8).
    E = topology.unique_edges(Q)
    EP = np.asarray(lab.cc_edge_points(V, Q, centroids(V, Q)))
    i = int(np.flatnonzero((E == [0, 1]).all(axis=1))[0])
    expect_close(
        "cc_edge_points(cube), edge (0, 1)", EP[i], [0, -3 / 8, -3 / 8], atol=1e-12, name="edge point", mesh=(V, Q)
    )
    # Corner -1/2 (1,1,1), valence 3: Q = mean face centre = -1/6 (1,1,1), R = mean edge midpoint
    # = -1/3 (1,1,1); (Q + 2R + 0 P) / 3 = -5/18 (1,1,1). All corners by symmetry: 5/9 of P.
    VP = lab.cc_vertex_points(V, Q, centroids(V, Q))
    expect_close("cc_vertex_points(cube)", VP, V * (5 / 9), atol=1e-12, name="vertex points", mesh=(V, Q))


@graded(points=2, part="catmull-clark points")
def test_regular_torus_is_bicubic_bspline(lab):
    """on a quad torus (every vertex regular) one step equals tensor-product cubic B-spline refinement"""
    nu, nv = 10, 6
    V, Q = datasets.quad_torus(n_major=nu, n_minor=nv)
    V = datasets.add_noise(V, 0.02, seed=1)
    P = V.reshape(nv, nu, 3)  # vertex i + nu * j

    def refine(P, axis):  # 1-D periodic rule: even (p- + 6p + p+)/8, odd (p + p+)/2
        Pm, Pp = np.roll(P, 1, axis), np.roll(P, -1, axis)
        out = np.stack([(Pm + 6 * P + Pp) / 8, (P + Pp) / 2], axis + 1)
        shape = list(P.shape)
        shape[axis] *= 2
        return out.reshape(shape)

    expected = refine(refine(P, 0), 1).reshape(-1, 3)
    V1, Q1 = lab.catmull_clark(V, Q)
    V1 = np.asarray(V1)
    if V1.shape != expected.shape:
        raise Mismatch(f"catmull_clark(quad torus): {len(V1)} vertices, expected {len(expected)}")
    from scipy.spatial import cKDTree

    d, _ = cKDTree(V1).query(expected)
    if d.max() > 1e-10:
        missing = expected[d > 1e-10]
        raise Mismatch(
            f"catmull_clark(quad torus): {len(missing)} of {len(expected)} B-spline points have no matching "
            f"vertex (worst off by {d.max():.3g}) — check the edge and vertex point rules on regular quads",
            marked_picture("catmull_clark(quad torus)", V1, Q1, missing, "B-spline points with no matching vertex"),
        )
    # The quads are the cells of the refined (2 nv) x (2 nu) periodic grid of those points.
    _, j = cKDTree(expected).query(V1)  # vertex of V1 -> index i + 2 nu * r in the refined grid
    Q1 = np.asarray(Q1)
    gu, gv = 2 * nu, 2 * nv
    i, r = np.meshgrid(np.arange(gu), np.arange(gv))
    cells = np.stack([i + gu * r, (i + 1) % gu + gu * r, (i + 1) % gu + gu * ((r + 1) % gv), i + gu * ((r + 1) % gv)])
    want = {frozenset(c) for c in cells.reshape(4, -1).T.tolist()}
    got = {frozenset(q) for q in j[Q1].tolist()} if Q1.ndim == 2 and Q1.shape[1] == 4 and Q1.size else set()
    if got != want or len(Q1) != len(want):
        raise Mismatch(
            f"catmull_clark(quad torus): {len(want - got)} of the {len(want)} cells of the refined grid are not "
            "among the quads — check cc_quads (corner, edge point, face point, edge point)"
        )


# --------------------------------------------------------------------------------------------
# Task 9 and non-quad input


@graded(points=2, part="non-quad input")
def test_regular_tetrahedron_by_hand(lab):
    """regular tetrahedron (vertex sum 0): face points -w/3, edge points (a + b)/3, vertex points 7/27 P"""
    V, F = REG_TET_V, REG_TET_F
    # The face without vertex w has centroid (sum - w)/3 = -w/3. Edge (a, b) lies in the faces
    # without c and without d: (a + b - c/3 - d/3) / 4 = (a + b)(1 + 1/3)/4 = (a + b)/3.
    # Vertex P, valence 3: Q = mean of -w/3 over the other three = P/9, R = mean of (P + w)/2 = P/3,
    # (Q + 2R + 0 P)/3 = 7P/27.
    V1, Q1 = lab.catmull_clark(V, F)
    E = topology.unique_edges(F)
    expected = np.concatenate([7 * V / 27, (V[E[:, 0]] + V[E[:, 1]]) / 3, -V[[3, 2, 1, 0]] / 3])
    from scipy.spatial import cKDTree

    V1 = np.asarray(V1)
    if V1.shape != expected.shape:
        raise Mismatch(f"catmull_clark(tetrahedron): {len(V1)} vertices, expected V + E + F = 4 + 6 + 4 = 14")
    d, j = cKDTree(V1).query(expected)
    if d.max() > 1e-12:
        i = int(np.argmax(d))
        raise Mismatch(
            f"catmull_clark(tetrahedron): expected a vertex at {np.round(expected[i], 6).tolist()}, nearest is {np.round(V1[j[i]], 6).tolist()}",
            marked_picture(
                "catmull_clark(tetrahedron)", V1, Q1, expected[d > 1e-12], "expected vertices with no match"
            ),
        )
    Q1 = np.asarray(Q1)
    if Q1.shape != (12, 4):
        raise Mismatch(f"catmull_clark(tetrahedron): quads have shape {Q1.shape}, expected (12, 4): one per corner")
    # Each quad is (vertex point, edge point, face point, edge point) around one corner: rows of
    # `expected` 0-3 are vertex points, 4-9 edge points, 10-13 face points.
    _, at = cKDTree(expected).query(V1)  # row of `expected` each vertex of V1 is
    kind = np.repeat([0, 1, 2], [4, 6, 4])[at]
    Q1 = np.clip(Q1.astype(np.int64), 0, len(V1) - 1)
    cycles = {tuple(np.roll(kind[q], -int(np.argmin(kind[q])))) for q in Q1}
    corners = {(int(at[q[np.argmin(kind[q])]]), int(at[q[np.argmax(kind[q])]])) for q in Q1}
    if cycles != {(0, 1, 2, 1)} or len(corners) != 12:
        raise Mismatch(
            "catmull_clark(tetrahedron): each quad must go vertex point, edge point, face point, edge point "
            "around one corner (v, f) of the input, one quad per corner"
        )


@graded(points=1, part="non-quad input")
def test_cage_counts_and_extraordinary_vertices(lab):
    """mixed cage: V' = V + E + F, one quad per corner, old valences kept, extraordinary count constant, points distinct and moved"""
    V, faces = datasets.polygon_cage()
    n, e, m = len(V), len(topology.unique_edges(faces)), len(faces)
    corners = sum(len(f) for f in faces)
    V1, Q1 = (np.asarray(a) for a in lab.catmull_clark(V, faces, 1))
    if V1.shape != (n + e + m, 3) or Q1.shape != (corners, 4):
        raise Mismatch(
            f"catmull_clark(cage): got V {V1.shape}, Q {Q1.shape}; expected ({n + e + m}, 3), ({corners}, 4)"
        )
    if not np.array_equal(topology.valence(Q1, len(V1))[:n], topology.valence(faces, n)):
        raise Mismatch("catmull_clark(cage): the old vertices (first n rows) must keep their valence")
    V2, Q2 = (np.asarray(a) for a in lab.catmull_clark(V, faces, 2))
    x1 = int((topology.valence(Q1, len(V1)) != 4).sum())
    x2 = int((topology.valence(Q2, len(V2)) != 4).sum())
    # extraordinary after one step: old vertices of valence != 4 plus face points of non-quads
    x_expected = int((topology.valence(faces, n) != 4).sum()) + sum(len(f) != 4 for f in faces)
    if not (x1 == x2 == x_expected):
        raise Mismatch(
            f"catmull_clark(cage): {x1} extraordinary vertices after level 1 and {x2} after level 2; expected {x_expected} both times"
        )
    if not topology.is_closed(Q1):
        raise Mismatch("catmull_clark(cage): the refined mesh should still be closed")
    expect_distinct("catmull_clark(cage)", V1, Q1)
    moved = np.linalg.norm(V1[:n] - V, axis=1) > 1e-9
    if not moved.all():
        raise Mismatch(
            f"catmull_clark(cage): {int((~moved).sum())} old vertices did not move; on this cage every vertex point "
            "(Q + 2R + (k - 3) P) / k differs from P"
        )


# --------------------------------------------------------------------------------------------
# bad input (validation is given code: these make sure it stays in place; no points)


@graded(points=0, part="bad input")
def test_rejects_quads_for_loop(lab):
    """Loop subdivision rejects quads with a message about triangles"""
    V, Q = datasets.quad_cube()
    expect_rejected(lab, "loop_subdivide", V, Q, match="triangles", label="loop_subdivide(quads)")


@graded(points=0, part="bad input")
def test_rejects_non_manifold(lab):
    """an edge shared by three triangles is rejected, naming the edge"""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    expect_raises(
        lambda: lab.loop_odd_matrix(V, F), "MeshError", match=r"edge \(0, 1\).*3 faces", label="loop_odd_matrix"
    )
    expect_raises(lambda: lab.catmull_clark(V, F), "MeshError", match=r"edge \(0, 1\)", label="catmull_clark")


@graded(points=0, part="bad input")
def test_rejects_bad_levels(lab):
    """levels must be an integer >= 0"""
    V, F = datasets.icosphere(0)
    expect_rejected(lab, "loop_subdivide", V, F, -1, match=">= 0", label="loop_subdivide(levels=-1)")
    expect_rejected(lab, "loop_subdivide", V, F, 1.5, match="integer", label="loop_subdivide(levels=1.5)")
    expect_rejected(lab, "catmull_clark", V, F, "2", match="integer", label="catmull_clark(levels='2')")


@graded(points=0, part="bad input")
def test_rejects_unknown_weights_and_nan(lab):
    """unknown weight rule and NaN coordinates are rejected with a message naming them"""
    V, F = datasets.icosphere(0)
    expect_rejected(
        lab, "loop_subdivide", V, F, 1, "butterfly", match="weights", label="loop_subdivide(weights='butterfly')"
    )
    Vn = V.copy()
    Vn[3, 0] = np.nan
    expect_rejected(lab, "loop_subdivide", Vn, F, match="row 3", label="loop_subdivide(V with NaN)")
    expect_rejected(lab, "catmull_clark", V, [[0, 1, 2], [2, 3]], match="face 1", label="catmull_clark(2-gon)")
