"""Tests for geomlib.topology on tiny hand-made meshes.

Every expected value is worked out by hand in the comment next to it (edges listed, V - E + F
counted), so these tests check the library against arithmetic, not against itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from geomlib import topology as tp
from geomlib.validate import MeshError, check_manifold

TRIANGLE = np.array([[0, 1, 2]])
# Unit square, two triangles sharing the diagonal 0-2, both counter-clockwise seen from +z.
SQUARE = np.array([[0, 1, 2], [0, 2, 3]])
# Tetrahedron with outward orientation: every directed edge appears once, its reverse once.
TETRA = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
# Cube: vertex x + 2y + 4z, six outward quads.
CUBE_Q = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
# Bowtie: two triangles touching only at vertex 0.
BOWTIE = np.array([[0, 1, 2], [0, 3, 4]])


def rows(a):
    return sorted(map(tuple, np.asarray(a).tolist()))


# --------------------------------------------------------------------------------------------
# representations


def test_to_ragged_accepts_every_face_representation():
    want_idx = np.array(CUBE_Q).ravel()
    want_off = np.arange(0, 25, 4)
    for faces in (np.array(CUBE_Q), CUBE_Q, [tuple(f) for f in CUBE_Q], (want_idx, want_off)):
        idx, off = tp.to_ragged(faces)
        assert idx.dtype == np.int64 and off.dtype == np.int64
        np.testing.assert_array_equal(idx, want_idx)
        np.testing.assert_array_equal(off, want_off)


def test_mixed_polygons_sizes_and_halfedges():
    faces = [[0, 1, 2, 3], [3, 2, 4]]
    np.testing.assert_array_equal(tp.face_sizes(faces), [4, 3])
    # corner i -> i + 1 in each face, wrapping around
    np.testing.assert_array_equal(tp.halfedges(faces), [[0, 1], [1, 2], [2, 3], [3, 0], [3, 2], [2, 4], [4, 3]])


def test_unique_rows_matches_numpy():
    rng = np.random.default_rng(0)
    E = rng.integers(0, 7, size=(200, 2))
    u, inv, cnt = tp.unique_rows(E, return_inverse=True, return_counts=True)
    nu, ninv, ncnt = np.unique(E, axis=0, return_inverse=True, return_counts=True)
    np.testing.assert_array_equal(u, nu)
    np.testing.assert_array_equal(inv, ninv.ravel())
    np.testing.assert_array_equal(cnt, ncnt)
    np.testing.assert_array_equal(u[inv], E)


# --------------------------------------------------------------------------------------------
# one triangle


def test_triangle():
    np.testing.assert_array_equal(tp.unique_edges(TRIANGLE), [[0, 1], [0, 2], [1, 2]])
    E, EF = tp.edge_faces(TRIANGLE)
    # the face runs 0->1 and 1->2 forwards, and 2->0, i.e. edge (0, 2) backwards
    np.testing.assert_array_equal(EF, [[0, -1], [-1, 0], [0, -1]])
    np.testing.assert_array_equal(tp.valence(TRIANGLE), [2, 2, 2])
    np.testing.assert_array_equal(tp.boundary_edges(TRIANGLE), [[0, 1], [1, 2], [2, 0]])
    loops = tp.boundary_loops(TRIANGLE)
    assert len(loops) == 1
    np.testing.assert_array_equal(loops[0], [0, 1, 2])
    assert tp.euler_characteristic(TRIANGLE) == 1  # 3 - 3 + 1
    assert tp.genus(TRIANGLE) == 0  # (2 - 1 - 1) / 2
    assert not tp.is_closed(TRIANGLE)
    assert tp.is_edge_manifold(TRIANGLE)
    np.testing.assert_array_equal(tp.vertex_fan_counts(TRIANGLE), [1, 1, 1])


# --------------------------------------------------------------------------------------------
# a square of two triangles


def test_square():
    # edges: 4 sides + the diagonal (0, 2)
    np.testing.assert_array_equal(tp.unique_edges(SQUARE), [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]])
    E, EF = tp.edge_faces(SQUARE)
    # diagonal: face 1 runs 0->2, face 0 runs 2->0
    np.testing.assert_array_equal(EF[1], [1, 0])
    # boundary edges have exactly one face
    assert ((EF >= 0).sum(axis=1) == np.array([1, 2, 1, 1, 1])).all()
    np.testing.assert_array_equal(tp.valence(SQUARE), [3, 2, 3, 2])
    A = tp.vertex_adjacency(SQUARE)
    assert (A != A.T).nnz == 0
    np.testing.assert_array_equal(A.indices[A.indptr[0] : A.indptr[1]], [1, 2, 3])
    loops = tp.boundary_loops(SQUARE)
    assert len(loops) == 1
    np.testing.assert_array_equal(loops[0], [0, 1, 2, 3])  # counter-clockwise, like the faces
    assert tp.euler_characteristic(SQUARE) == 1  # 4 - 5 + 2
    assert tp.genus(SQUARE) == 0
    n, labels = tp.connected_components_faces(SQUARE)
    assert n == 1 and (labels == 0).all()


def test_square_as_one_quad_triangulates_to_the_same_fan():
    F, src = tp.triangulate_polygons([[0, 1, 2, 3]])
    np.testing.assert_array_equal(F, SQUARE)
    np.testing.assert_array_equal(src, [0, 0])


# --------------------------------------------------------------------------------------------
# closed meshes


def test_tetrahedron():
    assert len(tp.unique_edges(TETRA)) == 6
    E, EF = tp.edge_faces(TETRA)
    assert (EF >= 0).all()  # every edge has a face on each side
    np.testing.assert_array_equal(tp.valence(TETRA), [3, 3, 3, 3])
    assert len(tp.boundary_edges(TETRA)) == 0
    assert tp.boundary_loops(TETRA) == []
    assert tp.euler_characteristic(TETRA) == 2  # 4 - 6 + 4
    assert tp.genus(TETRA) == 0
    assert tp.is_closed(TETRA) and tp.is_edge_manifold(TETRA)
    np.testing.assert_array_equal(tp.vertex_fan_counts(TETRA), [1, 1, 1, 1])
    check_manifold(TETRA, 4)  # no error


def test_cube_of_quads():
    for faces in (CUBE_Q, np.array(CUBE_Q)):
        assert len(tp.unique_edges(faces)) == 12
        np.testing.assert_array_equal(tp.valence(faces), [3] * 8)
        assert tp.euler_characteristic(faces) == 2  # 8 - 12 + 6
        assert tp.genus(faces) == 0
        assert tp.is_closed(faces)
        np.testing.assert_array_equal(tp.vertex_fan_counts(faces), [1] * 8)
    F, src = tp.triangulate_polygons(CUBE_Q)
    np.testing.assert_array_equal(src, np.repeat(np.arange(6), 2))
    # the fan split keeps each quad's orientation, so the triangles form a closed oriented mesh
    assert tp.is_closed(F) and tp.euler_characteristic(F) == 2  # 8 - 18 + 12
    check_manifold(F, 8)


def test_torus_of_quads_has_genus_one():
    # 3 x 3 grid of quads with both directions wrapped: V = 9, E = 18, F = 9, chi = 0
    idx = lambda i, j: (i % 3) + 3 * (j % 3)
    Q = [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)] for j in range(3) for i in range(3)]
    assert tp.euler_characteristic(Q) == 0
    assert tp.genus(Q) == 1
    assert tp.is_closed(Q)


# --------------------------------------------------------------------------------------------
# boundaries with several loops


def test_annulus_has_two_loops_longest_first():
    # outer square 0..3, inner triangle 4..6 punched out: ring of 7 triangles
    outer, inner = [0, 1, 2, 3], [4, 5, 6]
    F = [[0, 1, 4], [1, 5, 4], [1, 2, 5], [2, 6, 5], [2, 3, 6], [3, 0, 6], [0, 4, 6]]
    loops = tp.boundary_loops(F)
    assert [len(lp) for lp in loops] == [4, 3]
    assert sorted(loops[0].tolist()) == outer and sorted(loops[1].tolist()) == inner
    assert tp.euler_characteristic(F) == 0  # 7 - 14 + 7
    assert tp.genus(F) == 0  # (2 - 0 - 2) / 2


# --------------------------------------------------------------------------------------------
# non-manifold configurations


def test_bowtie_vertex_has_two_fans():
    np.testing.assert_array_equal(tp.vertex_fan_counts(BOWTIE), [2, 1, 1, 1, 1])
    # an unreferenced vertex has no fan
    np.testing.assert_array_equal(tp.vertex_fan_counts(BOWTIE, n_vertices=6), [2, 1, 1, 1, 1, 0])
    assert tp.is_edge_manifold(BOWTIE)  # the problem is the vertex, not an edge
    n, _ = tp.connected_components_faces(BOWTIE)
    assert n == 2  # touching at a vertex does not connect faces
    with pytest.raises(MeshError, match="vertex 0 is non-manifold .*2 separate fans"):
        check_manifold(BOWTIE, 5)
    with pytest.raises(MeshError, match="boundary vertex 0 has 2 outgoing boundary edges"):
        tp.boundary_loops(BOWTIE)


def test_edge_shared_by_three_faces():
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert not tp.is_edge_manifold(F)
    assert not tp.is_closed(F)
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is shared by 3 faces \(0, 1, 2\)"):
        check_manifold(F, 5)


def test_inconsistent_orientation_is_reported():
    F = np.array([[0, 1, 2], [0, 1, 3]])  # both run 0 -> 1
    assert tp.is_edge_manifold(F)
    with pytest.raises(MeshError, match=r"faces 0 and 1 both traverse edge \(0, 1\).*not consistently oriented"):
        check_manifold(F, 4)


def test_two_components():
    F = np.array([[0, 1, 2], [3, 4, 5], [3, 5, 6]])
    n, labels = tp.connected_components_faces(F)
    assert n == 2
    assert labels[1] == labels[2] != labels[0]


def test_empty_faces():
    empty = np.zeros((0, 3), np.int64)
    assert tp.unique_edges(empty).shape == (0, 2)
    assert tp.boundary_loops(empty) == []


@pytest.mark.parametrize("one_per_row", [False, True])
def test_corner_fans_split_a_bowtie_vertex_into_two_fans(one_per_row):
    # Two triangle pairs meet only at vertex 0: each pair shares an edge through 0 (0-2 and 0-5).
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 4, 5], [0, 5, 6]])
    idx = F.ravel()  # corner 3 f + i is corner i of face f
    # faces 0 and 1 link their corners at vertices 0 and 2; faces 2 and 3 those at 0 and 5
    rows = np.array([0, 2, 6, 8])
    cols = np.array([3, 4, 9, 10])
    labels, owner = tp.corner_fans(idx, rows, cols, one_per_row=one_per_row)
    fans = np.bincount(owner, minlength=7)
    assert fans[0] == 2  # the bowtie vertex
    assert fans[2] == 1 and fans[5] == 1
    assert labels[0] == labels[3] and labels[6] == labels[9] and labels[0] != labels[6]


def test_vertex_fans_count_cycles_paths_and_pinches_as_the_connected_components_do():
    # vertex_fans counts the fans of a paired mesh by pointer doubling, fans() by scipy's connected
    # components: they agree on closed fans of 3, 4 (a power of two: a doubling lands on the corner
    # itself) and 5 corners, open fans, and pinches of two closed or open fans at one vertex.
    octa = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    pyramid5 = np.array([[0, 1, 5], [1, 2, 5], [2, 3, 5], [3, 4, 5], [4, 0, 5], [1, 0, 6], [2, 1, 6], [3, 2, 6],
                         [4, 3, 6], [0, 4, 6]])  # fmt: skip
    pinch = np.r_[octa, octa + 5]  # vertex 5 is the apex of both: two closed fans of 4 corners
    open_pinch = np.r_[octa[:3], octa[:3] + 4]  # vertex 4 is in both: two open fans
    for F in (TETRA, octa, pyramid5, pinch, open_pinch, octa[:5], SQUARE):
        F = np.asarray(F, np.int64)
        H = tp.halfedge_mesh(F)
        expected = np.bincount(H.fans()[1], minlength=H.n_vertices)
        np.testing.assert_array_equal(H.vertex_fans, expected)
    assert tp.halfedge_mesh(pinch).vertex_fans[5] == 2
    assert tp.halfedge_mesh(open_pinch).vertex_fans[4] == 2


# --------------------------------------------------------------------------------------------
# the half-edge structure


def test_halfedge_mesh_of_the_square_by_hand():
    # corners 0..5 = F.ravel() = 0 1 2 | 0 2 3; half-edges 0->1, 1->2, 2->0, 0->2, 2->3, 3->0
    H = tp.halfedge_mesh(SQUARE)
    np.testing.assert_array_equal(H.nxt, [1, 2, 0, 4, 5, 3])
    np.testing.assert_array_equal(H.prv, [2, 0, 1, 5, 3, 4])
    np.testing.assert_array_equal(H.he_face, [0, 0, 0, 1, 1, 1])
    # edges sorted: (0,1) (0,2) (0,3) (1,2) (2,3)
    np.testing.assert_array_equal(H.E, [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]])
    np.testing.assert_array_equal(H.he_edge, [0, 3, 1, 1, 4, 2])
    # the diagonal 0-2: half-edge 3 runs 0->2 (face 1), half-edge 2 runs 2->0 (face 0)
    np.testing.assert_array_equal(H.EH[1], [3, 2])
    np.testing.assert_array_equal(H.EF[1], [1, 0])
    np.testing.assert_array_equal(H.twin, [-1, -1, 3, 2, -1, -1])
    np.testing.assert_array_equal(H.boundary_edge, [True, False, True, True, True])
    np.testing.assert_array_equal(H.valence, [3, 2, 3, 2])
    np.testing.assert_array_equal(H.vertex_fans, [1, 1, 1, 1])
    # every vertex is on the boundary: its outgoing corner is its boundary half-edge
    np.testing.assert_array_equal(H.vertex_corner, [0, 1, 4, 5])
    tp.check_halfedges(H)


def test_halfedge_mesh_on_closed_meshes_and_polygons():
    for faces, n in ((TETRA, 4), (CUBE_Q, 8), ([[0, 1, 2, 3], [3, 2, 4]], 5)):
        H = tp.halfedge_mesh(faces, n, manifold=True)
        tp.check_halfedges(H)
        paired = H.twin >= 0
        np.testing.assert_array_equal(H.twin[H.twin[paired]], np.flatnonzero(paired))
        np.testing.assert_array_equal(H.idx[H.twin[paired]], H.idx[H.nxt[paired]])
    assert (tp.halfedge_mesh(TETRA).twin >= 0).all()  # closed: every half-edge has a twin


def test_check_halfedges_names_a_broken_invariant():
    import dataclasses

    H = tp.halfedge_mesh(TETRA)
    bad_nxt = H.nxt.copy()
    bad_nxt[[0, 1]] = bad_nxt[[1, 0]]
    with pytest.raises(MeshError, match=r"nxt\[0\] is 2, not the next corner"):
        tp.check_halfedges(dataclasses.replace(H, nxt=bad_nxt))
    bad_EH = H.EH.copy()
    bad_EH[0] = bad_EH[0, ::-1]  # swap the directions of edge 0
    with pytest.raises(MeshError, match=r"EH\[0, 0\] = .* is not a half-edge running 0 -> 1"):
        tp.check_halfedges(dataclasses.replace(H, EH=bad_EH))
    bad_edge = H.he_edge.copy()
    bad_edge[0] = (bad_edge[0] + 1) % H.n_edges
    with pytest.raises(MeshError, match="half-edge 0 runs"):
        tp.check_halfedges(dataclasses.replace(H, he_edge=bad_edge))
    with pytest.raises(MeshError, match="vertex 0 has 2 fans"):
        tp.check_halfedges(tp.halfedge_mesh(BOWTIE))
    tp.check_halfedges(tp.halfedge_mesh(BOWTIE), manifold=False)


def test_manifold_build_reports_duplicates_and_orientation():
    with pytest.raises(MeshError, match=r"f: F: faces 0 and 1 are duplicates \(same corners\)"):
        tp.halfedge_mesh([[0, 1, 2], [0, 1, 2]], manifold=True, where="f", name="F")
    with pytest.raises(MeshError, match=r"faces 0 and 1 both traverse edge \(0, 1\).*not consistently oriented"):
        tp.halfedge_mesh([[0, 1, 2], [0, 1, 3]], manifold=True)
    # a third face on an edge is named with the edge, and a duplicate among them as the likely cause
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is shared by 3 faces \(0, 1, 2\) \(faces 0 and 2 are dup"):
        tp.halfedge_mesh([[0, 1, 2], [1, 0, 3], [2, 1, 0]], manifold=True)


def test_fans_on_a_non_manifold_edge_match_the_general_rule():
    # three triangles on edge (0, 1): all their corners at 0 form one fan, and all at 1
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    np.testing.assert_array_equal(tp.vertex_fan_counts(F), [1, 1, 1, 1, 1])
    labels, owner = tp.halfedge_mesh(F).fans()
    assert len(set(labels[[0, 4, 6]].tolist())) == 1  # the corners at vertex 0
    assert (owner[labels] == F.ravel()).all()


# --------------------------------------------------------------------------------------------
# bad input to the public functions


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: tp.valence([[0, 1, -1]]), r"^valence: faces: face 0 \(0, 1, -1\) has a negative index"),
        (lambda: tp.valence(TRIANGLE, n_vertices=2), r"^valence: faces: face 0 uses vertex 2, but V has only 2"),
        (lambda: tp.valence(TRIANGLE, n_vertices=-1), r"^valence: n_vertices must be an integer >= 0"),
        (lambda: tp.is_closed([[0, 1]]), r"^is_closed: faces: face 0 has 2 vertices, a polygon needs at least 3"),
        (lambda: tp.is_closed(np.array([0, 1, 2])), r"^is_closed: faces has shape \(3,\)"),
        (lambda: tp.is_closed(np.zeros((2, 0), int)), r"^is_closed: faces: face 0 has 0 vertices"),
        (lambda: tp.euler_characteristic([[0, 1.5, 2]]), r"^euler_characteristic: faces: face 0 holds a non-integer"),
        (lambda: tp.euler_characteristic(np.array([[0, 1, 2.5]])), r"holds a non-integer value 2.5"),
        (lambda: tp.triangulate_polygons([[0, 1, 2], [3, 4]]), r"^triangulate_polygons: faces: face 1 has 2 vertices"),
        (lambda: tp.triangulate_polygons(np.array([["a", "b", "c"]])), r"faces has dtype <U1, expected integers"),
        (lambda: tp.boundary_loops(None), r"^boundary_loops: faces is missing"),
        (lambda: tp.boundary_loops(5), r"^boundary_loops: faces must be an \(m, k\) int array or a list"),
        (lambda: tp.boundary_loops([[0, 1, 2], [0, 1, 3]]), r"^boundary_loops: boundary vertex 1 has 2 outgoing"),
        (lambda: tp.valence(np.array([[0, 1, 2**63]], np.uint64)), r"2\*\*63|9223372036854775808 .*too large"),
    ],
)
def test_public_functions_reject_bad_faces_clearly(call, message):
    with pytest.raises(MeshError, match=message):
        call()


def test_boundary_loops_of_a_flipped_face_is_an_error_not_a_hang():
    # face 1 is flipped: the boundary half-edges do not chain into loops
    F = [[0, 1, 2], [0, 3, 2], [0, 3, 4]]
    with pytest.raises(MeshError, match="boundary_loops: "):
        tp.boundary_loops(F)


def test_to_ragged_does_not_misread_two_triangles_as_offsets():
    a, b = np.array([1, 2, 3]), np.array([0, 2, 3])  # b looks like offsets of faces of sizes 2 and 1
    idx, off = tp.to_ragged((a, b))
    np.testing.assert_array_equal(idx, [1, 2, 3, 0, 2, 3])
    np.testing.assert_array_equal(off, [0, 3, 6])
    assert tp.face_sizes((a, b)).tolist() == [3, 3]


def test_topology_and_validate_do_not_import_each_other():
    import subprocess
    import sys

    code = "import sys, geomlib.topology; print('geomlib.validate' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
