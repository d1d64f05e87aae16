"""Hidden graded cases of the subdivision lab (not shipped to students): other meshes, same rules."""

from __future__ import annotations

from geomlib import datasets
from geomlib.grading import Case, checks

from .cases import BOUNDARY_HINT, CC_HINT, EVEN_HINT, FACES_HINT, LEVELS_HINT, ODD_HINT, no_vertices, plane
from .support import faces_check, matrix_check, quad_grid


def nut():
    V, F = datasets.pyvista_mesh("nut")
    return {"V": V, "F": F}


def tetra_faces():
    V, F = datasets.icosphere(0)
    return {"V": datasets.add_noise(V, 0.1, seed=7), "faces": F}


def open_quads():
    V, Q = quad_grid(5, 7, seed=4)
    return {"V": V, "faces": Q}


def quad_torus():
    V, Q = datasets.quad_torus(n_major=12, n_minor=8)
    return {"V": datasets.add_noise(V, 0.02, seed=5), "faces": Q}


H = "hidden"
CASES = [
    Case(id="h-odd-nut", function="loop_odd_matrix", inputs=nut, outputs=("S_odd",),
         check=matrix_check("S_odd", what_row="row (edge)"), part="odd vertices", points=11, visibility=H, hint=ODD_HINT),
    Case(id="h-even-nut-warren", function="loop_even_matrix", inputs=nut, params={"weights": "warren"},
         outputs=("S_even",), check=matrix_check("S_even", what_row="row (vertex)"), part="even vertices", points=15,
         visibility=H, hint=EVEN_HINT),
    Case(id="h-faces-nut", function="loop_faces", inputs=no_vertices(nut), outputs=("F",), check=faces_check("F"),
         part="connectivity", points=9, visibility=H, hint=FACES_HINT),
    Case(id="h-odd-airplane", function="loop_odd_matrix", inputs=plane, outputs=("S_odd",),
         check=matrix_check("S_odd", what_row="row (edge)"), part="boundary rules", points=4, visibility=H,
         hint=BOUNDARY_HINT),
    Case(id="h-even-airplane-loop", function="loop_even_matrix", inputs=plane, params={"weights": "loop"},
         outputs=("S_even",), check=matrix_check("S_even", what_row="row (vertex)"), part="boundary rules", points=4,
         visibility=H, hint=BOUNDARY_HINT),
    Case(id="h-cc-open-grid-2", function="catmull_clark", inputs=open_quads, params={"levels": 2}, outputs=("V", "Q"),
         check=checks.MeshMatch(faces="Q"), part="boundary rules", points=4, visibility=H, hint=BOUNDARY_HINT,
         tasks=(4, 6, 7, 8, 9)),  # Catmull-Clark's boundary branches need Tasks 6-9
    Case(id="h-loop-nut-2-warren", function="loop_subdivide", inputs=nut, params={"levels": 2, "weights": "warren"},
         outputs=("V", "F"), check=checks.MeshMatch(), part="several levels", points=15, visibility=H, hint=LEVELS_HINT),
    Case(id="h-cc-quad-torus-2", function="catmull_clark", inputs=quad_torus, params={"levels": 2},
         outputs=("V", "Q"), check=checks.MeshMatch(faces="Q"), part="catmull-clark points", points=15, visibility=H,
         hint=CC_HINT),
    Case(id="h-cc-icosahedron-2", function="catmull_clark", inputs=tetra_faces, params={"levels": 2},
         outputs=("V", "Q"), check=checks.MeshMatch(faces="Q"), part="non-quad input", points=14, visibility=H,
         hint=CC_HINT + " (all faces are triangles here)"),
]  # fmt: skip
