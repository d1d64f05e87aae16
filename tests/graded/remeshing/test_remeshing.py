"""Graded tests of the remeshing lab.

``test_references`` compares with stored references and quality thresholds (``cases.py``); the
tests below apply one local operation to tiny meshes written out by hand, check the half-edge
structure's invariants after it (``check_halfedges``) and the answer worked out in the docstring,
and check bad input. Expected values never come from running a solution at test time.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, topology
from geomlib.grading import expect_close, expect_raises, graded, reference_tests
from geomlib.grading.errors import Mismatch

from ..common import expect_true
from .cases import CASES
from .support import OCTA_F, OCTA_V, SQUARE_F, SQUARE_V, TET_F, TET_V, edge_index, expect_refused, halfedges

test_references = reference_tests(CASES)


def expect_valid(label: str, V, H) -> np.ndarray:
    try:
        topology.check_halfedges(H)
    except Exception as exc:  # noqa: BLE001 - the message is the feedback
        raise Mismatch(f"{label}: the half-edge structure is broken: {exc}") from None
    expect_true(
        label, np.asarray(V).shape == (H.n_vertices, 3), f"V has shape {np.shape(V)}, H {H.n_vertices} vertices"
    )
    return np.sort(np.sort(H.idx.reshape(-1, 3), axis=1), axis=0)


def rebuilt(H):
    """A fresh structure of the returned faces (the returned one may be a plain record of its arrays)."""
    return topology.halfedge_mesh(np.asarray(H.idx).reshape(-1, 3), int(H.n_vertices))


def applied(operation, V, F, edge: tuple[int, int], label: str):
    """``operation(V, H, e)`` (split, flip or collapse) on the edge ``e`` between the vertices ``edge``;
    the returned structure must be valid. Returns the new positions and structure."""
    H = halfedges(V, F)
    V2, H2 = operation(V, H, edge_index(H, *edge))
    expect_valid(label, V2, H2)
    return np.asarray(V2), H2


def expect_faces(label: str, H, expected: list) -> None:
    """The faces of ``H`` as sorted vertex triples equal ``expected`` (sorted)."""
    got = sorted(tuple(sorted(f)) for f in H.idx.reshape(-1, 3).tolist())
    expect_true(label, got == expected, f"faces {got}, expected {expected}")


def expect_counts(label: str, H, expected: dict) -> None:
    """Counts of the rebuilt structure (``faces``, ``vertices``, ``boundary edges``) equal ``expected``."""
    R = rebuilt(H)
    counts = {"faces": R.n_faces, "vertices": R.n_vertices, "boundary edges": int(R.boundary_edge.sum())}
    got = {k: int(counts[k]) for k in expected}
    expect_true(
        label,
        got == expected,
        ", ".join(f"{v} {k}" for k, v in got.items())
        + ", expected "
        + ", ".join(f"{v} {k}" for k, v in expected.items()),
    )


# --------------------------------------------------------------------------------------------
# Task 1: split


@graded(points=1, part="local operations")
def test_split_the_diagonal_of_a_square(lab):
    """square (0,0),(1,0),(1,1),(0,1) split on diagonal 0-2: vertex 4 = (0.5, 0.5), four triangles around it"""
    V, H2 = applied(lab.split_edge, SQUARE_V, SQUARE_F, (0, 2), "split_edge on the square")
    expect_close("split_edge: the new vertex", V[4], [0.5, 0.5, 0.0], name="V[4]", mesh=(SQUARE_V, SQUARE_F))
    expect_faces("split_edge on the square", H2, [(0, 1, 4), (0, 3, 4), (1, 2, 4), (2, 3, 4)])


@graded(points=1, part="local operations")
def test_split_a_boundary_edge(lab):
    """square split on boundary edge 0-1: vertex 4 = (0.5, 0), three triangles, boundary still one loop of 5"""
    V, H2 = applied(lab.split_edge, SQUARE_V, SQUARE_F, (0, 1), "split_edge on a boundary edge")
    expect_close("split_edge: the new vertex", V[4], [0.5, 0.0, 0.0], name="V[4]", mesh=(SQUARE_V, SQUARE_F))
    expect_counts("split_edge on a boundary edge", H2, {"faces": 3, "boundary edges": 5})


# --------------------------------------------------------------------------------------------
# Task 3: flip


@graded(points=1, part="local operations")
def test_flip_the_diagonal_of_a_square(lab):
    """square with diagonal 0-2 flipped: diagonal 1-3, faces {0,1,3} and {1,2,3}, both still facing +z"""
    _, H2 = applied(lab.flip_edge, SQUARE_V, SQUARE_F, (0, 2), "flip_edge on the square")
    expect_faces("flip_edge on the square", H2, [(0, 1, 3), (1, 2, 3)])
    F = H2.idx.reshape(-1, 3)
    n = np.cross(SQUARE_V[F[:, 1]] - SQUARE_V[F[:, 0]], SQUARE_V[F[:, 2]] - SQUARE_V[F[:, 0]])
    expect_true("flip_edge on the square", (n[:, 2] > 0).all(), "a new face is turned over (orientation lost)")


@graded(points=1, part="local operations")
def test_flip_refuses_boundary_and_tetrahedron_edges(lab):
    """a boundary edge has one face; a tetrahedron's flip would duplicate an edge (valence 3)"""
    expect_refused(lab.flip_edge, SQUARE_V, SQUARE_F, (0, 1), match="cannot be flipped")
    expect_refused(lab.flip_edge, TET_V, TET_F, 0, match="cannot be flipped")


# --------------------------------------------------------------------------------------------
# Task 2: collapse


@graded(points=1, part="local operations")
def test_collapse_on_an_octahedron(lab):
    """octahedron edge (0, 2) of +x and +y: 5 vertices, 6 faces, merged vertex at (0.5, 0.5, 0)"""
    V, H2 = applied(lab.collapse_edge, OCTA_V, OCTA_F, (0, 2), "collapse_edge on the octahedron")
    expect_counts("collapse_edge on the octahedron", H2, {"vertices": 5, "faces": 6})
    expect_true(
        "collapse_edge on the octahedron",
        np.isclose(V, [0.5, 0.5, 0]).all(axis=1).any(),
        "no vertex at the midpoint (0.5, 0.5, 0)",
    )


@graded(points=1, part="local operations")
def test_collapse_refuses_the_link_condition(lab):
    """octahedron with face (0, 2, 4) split at a new vertex 6: ends 0 and 2 share neighbour 4, which is
    not opposite edge (0, 2) (6 and 5 are); a tetrahedron's collapse would leave valence-2 vertices"""
    V0 = np.r_[OCTA_V, [[0.5, 0.5, 0.5]]]
    F0 = np.r_[[[0, 2, 6], [2, 4, 6], [4, 0, 6]], OCTA_F[1:]]  # face 0 = (0, 2, 4) split at vertex 6
    expect_refused(lab.collapse_edge, V0, F0, (0, 2), match="link condition")
    expect_refused(lab.collapse_edge, TET_V, TET_F, 0, match="cannot be collapsed")


@graded(points=1, part="local operations")
def test_collapse_refuses_long_edges_and_flips(lab):
    """grid 4x4: the collapse of a short interior edge is allowed; with high smaller than the new edges, refused"""
    V0, F0 = datasets.grid_patch(4)
    H = halfedges(V0, F0)
    inner = np.flatnonzero(~H.boundary_vertex[H.E].any(axis=1))
    e = int(inner[0])
    V, H2 = lab.collapse_edge(V0, H, e)
    expect_valid("collapse_edge on the grid", V, H2)
    expect_raises(lambda: lab.collapse_edge(V0, H, e, high=0.26), "MeshError", match="longer than")
    # fold the grid: moving a vertex across its neighbours would turn faces over
    Vf = V0.copy()
    a, b = H.E[e]
    Vf[b] = Vf[a] + 3.0 * (Vf[b] - Vf[a])  # b far beyond a: the midpoint is outside a's fan
    expect_raises(lambda: lab.collapse_edge(Vf, H, e), "MeshError", match="turn over")


# --------------------------------------------------------------------------------------------
# bad input (given validation: no points)


@graded(points=0, part="bad input")
def test_rejects_bad_input(lab):
    """a negative target length, an edge index past the end and a non-manifold mesh give MeshErrors"""
    expect_raises(lambda: lab.isotropic_remesh(SQUARE_V, SQUARE_F, -1.0), "MeshError", match="target_length")
    H = halfedges(SQUARE_V, SQUARE_F)
    expect_raises(lambda: lab.split_edge(SQUARE_V, H, 99), "MeshError", match="does not exist")
    Fnm = np.array([[0, 1, 2], [0, 2, 3], [0, 2, 4]])
    Vnm = np.r_[SQUARE_V, [[0.5, 0.5, 1.0]]]
    expect_raises(lambda: lab.isotropic_remesh(Vnm, Fnm, 0.3), "MeshError", match="edge")
    expect_raises(lambda: lab.isotropic_remesh(SQUARE_V, SQUARE_F, 0.3, iterations=-1), "MeshError", match="iterations")


@graded(points=0, part="bad input")
def test_adaptive_rejects_bad_input(lab):
    """adaptive lengths: min above max, a negative error; per-vertex targets of the wrong shape or <= 0"""
    V, F = datasets.icosphere(1)
    expect_raises(
        lambda: lab.adaptive_target_length(V, F, 0.3, min_length=0.5, max_length=0.2), "MeshError", match="min_length"
    )
    expect_raises(lambda: lab.adaptive_target_length(V, F, 0.3, error=-1.0), "MeshError", match="error")
    expect_raises(lambda: lab.isotropic_remesh(V, F, np.full(3, 0.3)), "MeshError", match="one length per vertex")
    bad = np.full(len(V), 0.3)
    bad[5] = 0.0
    expect_raises(lambda: lab.isotropic_remesh(V, F, bad), "MeshError", match="vertex 5")
    expect_raises(
        lambda: lab.isotropic_remesh(V, F, np.full(len(V), 0.3), adaptive=True), "MeshError", match="adaptive"
    )
