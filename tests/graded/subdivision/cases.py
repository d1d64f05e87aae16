"""Public graded cases of the subdivision lab: realistic meshes compared with stored references.

Each case calls one lab function on a deterministic input; ``geomlib refs build --lab subdivision``
stored the reference solution's output. Functions that return a subdivision matrix are compared
row by row (the rows follow the edge order of the given ``mesh_topology``, so the order is part of
the task); whole meshes are compared order-independently (``checks.MeshMatch``), so a correct
implementation that numbers new vertices differently still passes.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input

from .support import airplane, faces_check, matrix_check, quad_grid

# --------------------------------------------------------------------------------------------
# inputs (functions: built when the case runs, identical every time)


def ico(level):
    return lambda: dict(zip(("V", "F"), datasets.icosphere(level), strict=True))


def ant():
    V, F = datasets.pyvista_mesh("ant")  # closed, valences 3..9: the two weight rules differ a lot
    return {"V": V, "F": F}


def torus():
    return dict(zip(("V", "F"), datasets.torus(n_major=12, n_minor=8), strict=True))


def height_field():
    return dict(zip(("V", "F"), datasets.height_field(n=6, seed=1), strict=True))


def plane():
    return dict(zip(("V", "F"), airplane(), strict=True))


def bumpy_quad_torus():
    V, Q = datasets.quad_torus(n_major=10, n_minor=6)
    return {"V": datasets.add_noise(V, 0.03, seed=2), "faces": Q}


def bumpy_cube():
    V, Q = datasets.quad_cube()
    return {"V": datasets.add_noise(V, 0.05, seed=3), "faces": Q}


def cage():
    V, faces = datasets.polygon_cage()
    return {"V": V, "faces": faces}


def face_points_entry(name: str, make) -> Case:
    """The face points of a mesh (Task 6's output), stored by `geomlib refs build` for the edge/vertex-point cases."""
    return Case(id=f"face-points-{name}", function="cc_face_points", inputs=make, outputs=("FP",),
                check=checks.Allclose(), part="stored input", points=0)  # fmt: skip


def with_face_points(make, name: str):
    """The mesh and its stored face points (the solution's, see STORED: these cases do not need Task 6)."""

    def inputs():
        d = make()
        d["face_points"] = stored_input("subdivision", f"face-points-{name}")["FP"]
        return d

    return inputs


def open_quads():
    V, Q = quad_grid(6, 5, seed=0)
    return {"V": V, "faces": Q}


def no_vertices(make):
    def inputs():
        d = make()
        del d["V"]
        return d

    return inputs


def with_unused_vertex(make):
    """The mesh plus one vertex no face uses (its row of S_even keeps it where it is: weight 1 on itself)."""

    def inputs():
        d = make()
        d["V"] = np.vstack([d["V"], [[0.3, 0.2, 0.1]]])
        return d

    return inputs


ODD_HINT = (
    "row i is the new vertex on edge topo.E[i] = (a, b): 3/8 on a and b, 1/8 on the two opposite "
    "vertices (opposite_vertices gives them)"
)
EVEN_HINT = (
    "row v: (1 - k u) on v itself and u on each of its k neighbours; u comes from loop_weight(k, weights); "
    "a vertex no face uses (k = 0): 1 on itself"
)
FACES_HINT = (
    "face f = (v0, v1, v2) with edge vertices m01, m12, m20 becomes (v0, m01, m20), (v1, m12, m01), "
    "(v2, m20, m12), (m01, m12, m20); m01 = n + topo.he_edge[3f]"
)
BOUNDARY_HINT = "boundary edge -> midpoint; boundary vertex -> 3/4 itself + 1/8 each of its two boundary neighbours"
LEVELS_HINT = "apply one step `levels` times, feeding each result into the next step"
CC_HINT = "face point = centroid; edge point = (a + b + two face points) / 4; vertex point = (Q + 2R + (k - 3) P) / k"

# What a case needs from an earlier task is stored by `geomlib refs build` from the solution and
# read back with `stored_input`, never computed here.
STORED = [
    face_points_entry("open-grid", open_quads),
    face_points_entry("quad-torus", bumpy_quad_torus),
    face_points_entry("cube", bumpy_cube),
    face_points_entry("cage", cage),
]

CASES = [
    # ---------------------------------------------------------------- Task 1: odd vertices
    Case(
        id="odd-icosphere-1",
        function="loop_odd_matrix",
        inputs=ico(1),
        outputs=("S_odd",),
        check=matrix_check("S_odd", what_row="row (edge)"),
        part="odd vertices",
        points=2,
        hint=ODD_HINT,
    ),
    Case(
        id="odd-ant",
        function="loop_odd_matrix",
        inputs=ant,
        outputs=("S_odd",),
        check=matrix_check("S_odd", what_row="row (edge)"),
        part="odd vertices",
        points=2,
        hint=ODD_HINT,
    ),
    # ---------------------------------------------------------------- Task 2: even vertices
    Case(
        id="weights-warren",
        function="loop_weight",
        inputs=lambda: {"n": list(range(3, 13))},
        params={"weights": "warren"},
        outputs=("u",),
        check=checks.Allclose(),
        part="even vertices",
        points=1,
        hint="warren: u = 3/16 for n = 3, else 3 / (8 n)",
    ),
    Case(
        id="weights-loop",
        function="loop_weight",
        inputs=lambda: {"n": list(range(3, 13))},
        params={"weights": "loop"},
        outputs=("u",),
        check=checks.Allclose(),
        part="even vertices",
        points=1,
        hint="loop: u = (1/n) (5/8 - (3/8 + cos(2 pi / n) / 4)^2)",
    ),
    Case(
        id="even-icosphere-1-warren",
        function="loop_even_matrix",
        inputs=ico(1),
        params={"weights": "warren"},
        outputs=("S_even",),
        check=matrix_check("S_even", what_row="row (vertex)"),
        part="even vertices",
        points=1,
        hint=EVEN_HINT,
    ),
    Case(
        id="even-icosphere-1-loop",
        function="loop_even_matrix",
        inputs=with_unused_vertex(ico(1)),
        params={"weights": "loop"},
        outputs=("S_even",),
        check=matrix_check("S_even", what_row="row (vertex)"),
        part="even vertices",
        points=1,
        hint=EVEN_HINT,
    ),
    Case(
        id="even-ant-loop",
        function="loop_even_matrix",
        inputs=ant,
        params={"weights": "loop"},
        outputs=("S_even",),
        check=matrix_check("S_even", what_row="row (vertex)"),
        part="even vertices",
        points=2,
        hint=EVEN_HINT,
    ),
    # ---------------------------------------------------------------- Task 3: connectivity
    Case(
        id="faces-icosphere-1",
        function="loop_faces",
        inputs=no_vertices(ico(1)),
        outputs=("F",),
        check=faces_check("F"),
        part="connectivity",
        points=2,
        hint=FACES_HINT,
    ),
    Case(
        id="faces-torus",
        function="loop_faces",
        inputs=no_vertices(torus),
        outputs=("F",),
        check=faces_check("F"),
        part="connectivity",
        points=1,
        hint=FACES_HINT,
    ),
    # ---------------------------------------------------------------- Task 4: boundary rules
    Case(
        id="odd-height-field",
        function="loop_odd_matrix",
        inputs=height_field,
        outputs=("S_odd",),
        check=matrix_check("S_odd", what_row="row (edge)"),
        part="boundary rules",
        points=1,
        hint=BOUNDARY_HINT,
    ),
    Case(
        id="even-height-field-warren",
        function="loop_even_matrix",
        inputs=height_field,
        params={"weights": "warren"},
        outputs=("S_even",),
        check=matrix_check("S_even", what_row="row (vertex)"),
        part="boundary rules",
        points=1,
        hint=BOUNDARY_HINT + " (not 1/8 to every neighbour that happens to lie on the boundary)",
    ),
    Case(
        id="cc-edges-open-grid",
        function="cc_edge_points",
        inputs=with_face_points(open_quads, "open-grid"),
        outputs=("EP",),
        check=checks.Allclose(),
        part="boundary rules",
        tasks=(4, 7),  # the boundary branch of Task 7's function
        points=1,
        hint="Catmull-Clark boundary edge -> its midpoint (the face points are given)",
    ),
    Case(
        id="cc-vertices-open-grid",
        function="cc_vertex_points",
        inputs=with_face_points(open_quads, "open-grid"),
        outputs=("VP",),
        check=checks.Allclose(),
        part="boundary rules",
        tasks=(4, 8),  # the boundary branch of Task 8's function
        points=1,
        hint="Catmull-Clark boundary vertex -> 3/4 P + 1/8 (its two boundary neighbours)",
    ),
    # ---------------------------------------------------------------- Task 5: several levels
    Case(
        id="loop-icosahedron-3-warren",
        function="loop_subdivide",
        inputs=ico(0),
        params={"levels": 3, "weights": "warren"},
        outputs=("V", "F"),
        check=checks.MeshMatch(),
        part="several levels",
        points=2,
        hint=LEVELS_HINT,
    ),
    Case(
        id="loop-torus-2-loop",
        function="loop_subdivide",
        inputs=torus,
        params={"levels": 2, "weights": "loop"},
        outputs=("V", "F"),
        check=checks.MeshMatch(),
        part="several levels",
        points=1,
        hint=LEVELS_HINT,
    ),
    Case(
        id="loop-airplane-1-warren",
        function="loop_subdivide",
        inputs=plane,
        params={"levels": 1, "weights": "warren"},
        outputs=("V", "F"),
        check=checks.MeshMatch(),
        part="several levels",
        points=1,
        hint="an open mesh with 10 boundary loops: every rule, including the boundary ones, is used",
    ),
    Case(
        id="loop-height-field-2-loop",
        function="loop_subdivide",
        inputs=height_field,
        params={"levels": 2, "weights": "loop"},
        outputs=("V", "F"),
        check=checks.MeshMatch(),
        part="several levels",
        points=1,
        hint=LEVELS_HINT,
    ),
    # ---------------------------------------------------------------- Tasks 6-8: Catmull-Clark points
    Case(
        id="cc-faces-quad-torus",
        function="cc_face_points",
        inputs=bumpy_quad_torus,
        outputs=("FP",),
        check=checks.Allclose(),
        part="catmull-clark points",
        points=1,
        hint="face point = mean of the face's corners",
    ),
    Case(
        id="cc-edges-quad-torus",
        function="cc_edge_points",
        inputs=with_face_points(bumpy_quad_torus, "quad-torus"),
        outputs=("EP",),
        check=checks.Allclose(),
        part="catmull-clark points",
        points=1,
        hint="edge point = (a + b + FP[f0] + FP[f1]) / 4, rows in topo.E order (the face points are given)",
    ),
    Case(
        id="cc-vertices-quad-torus",
        function="cc_vertex_points",
        inputs=with_face_points(bumpy_quad_torus, "quad-torus"),
        outputs=("VP",),
        check=checks.Allclose(),
        part="catmull-clark points",
        points=1,
        hint="vertex point = (Q + 2R + (k - 3) P) / k; Q, R are means over the k faces / k edges at P",
    ),
    Case(
        id="cc-vertices-cube",
        function="cc_vertex_points",
        inputs=with_face_points(bumpy_cube, "cube"),
        outputs=("VP",),
        check=checks.Allclose(),
        part="catmull-clark points",
        points=1,
        hint="valence 3: (Q + 2R + 0 P) / 3",
    ),
    Case(
        id="cc-cube-2",
        function="catmull_clark",
        inputs=bumpy_cube,
        params={"levels": 2},
        outputs=("V", "Q"),
        check=checks.MeshMatch(faces="Q"),
        part="catmull-clark points",
        points=2,
        hint=CC_HINT,
    ),
    # ---------------------------------------------------------------- Task 9 and mixed polygons
    Case(
        id="cc-faces-cage",
        function="cc_face_points",
        inputs=cage,
        outputs=("FP",),
        check=checks.Allclose(),
        part="non-quad input",
        points=1,
        hint="faces have 3, 4 and 5 corners: average over each face's own corners (np.add.reduceat on off)",
    ),
    Case(
        id="cc-vertices-cage",
        function="cc_vertex_points",
        inputs=with_face_points(cage, "cage"),
        outputs=("VP",),
        check=checks.Allclose(),
        part="non-quad input",
        points=1,
        hint="k counts the edges (= faces) at a vertex, whatever their sizes; the apex has k = 5",
    ),
    Case(
        id="cc-quads-cage",
        function="cc_quads",
        inputs=no_vertices(cage),
        outputs=("Q",),
        check=faces_check("Q"),
        part="non-quad input",
        points=2,
        hint=(
            "one quad per corner j: (idx[j], n + he_edge[j], n + e + he_face[j], n + he_edge[prv[j]]) — "
            "a k-gon gives k quads"
        ),
    ),
    Case(
        id="cc-cage-1",
        function="catmull_clark",
        inputs=cage,
        params={"levels": 1},
        outputs=("V", "Q"),
        check=checks.MeshMatch(faces="Q"),
        part="non-quad input",
        points=1,
        hint=CC_HINT,
    ),
    Case(
        id="cc-cage-3",
        function="catmull_clark",
        inputs=cage,
        params={"levels": 3},
        outputs=("V", "Q"),
        check=checks.MeshMatch(faces="Q"),
        part="non-quad input",
        points=1,
        hint=CC_HINT + "; after level 1 every face is a quad",
    ),
]
