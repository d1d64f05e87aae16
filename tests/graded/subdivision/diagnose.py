"""Diagnosis table of the subdivision lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (the stubs'
"Task N" markers vanish as students fill them in; ``tests/framework`` checks this table against
the solutions). ``CASES`` are probe-only cases: the building blocks on the inputs of the composite
cases, with references stored by ``geomlib refs build``, run only to explain a wrong composite.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from geomlib import topology
from geomlib.grading import Case

from .cases import (
    BOUNDARY_HINT,
    EVEN_HINT,
    bumpy_cube,
    cage,
    height_field,
    ico,
    no_vertices,
    torus,
    with_face_points,
)
from .cases import CASES as GRADED_CASES
from .support import matrix_picture, wrong_rows

TASKS = {
    "loop_odd_matrix": (1, 4),
    "loop_weight": (2,),
    "loop_even_matrix": (2, 4),
    "loop_faces": (3,),
    "loop_subdivide": (5,),
    "cc_face_points": (6,),
    "cc_edge_points": (7, 4),
    "cc_vertex_points": (8, 4),
    "cc_quads": (9,),
}
TITLES = {
    1: "odd vertices",
    2: "even vertices",
    3: "connectivity",
    4: "boundary rules",
    5: "several levels",
    6: "face points",
    7: "edge points",
    8: "vertex points",
    9: "quads",
}
_LOOP = ("loop_odd_matrix", "loop_even_matrix", "loop_weight", "loop_faces")
_CC = ("cc_face_points", "cc_edge_points", "cc_vertex_points", "cc_quads")
COMPOSITES = {
    "loop_even_matrix": ("loop_weight",),
    "loop_matrix": _LOOP,
    "loop_subdivide": _LOOP,
    "cc_edge_points": ("cc_face_points",),
    "cc_vertex_points": ("cc_face_points",),
    "catmull_clark_step": _CC,
    "catmull_clark": _CC,
}


_GRADED = {case.id: case for case in GRADED_CASES}


def _probe(graded_id: str, id: str, inputs, **changes) -> Case:
    """Graded case ``graded_id``'s call, outputs and check on another input: zero points, never graded."""
    return replace(_GRADED[graded_id], id=id, inputs=inputs, part="diagnosis", points=0, **changes)


EDGE_POINT_HINT = "edge point = (a + b + FP[f0] + FP[f1]) / 4"

CASES = [
    _probe("odd-icosphere-1", "probe-odd-icosahedron", ico(0)),
    _probe("even-icosphere-1-warren", "probe-even-icosahedron-warren", ico(0)),
    _probe("faces-icosphere-1", "probe-faces-icosahedron", no_vertices(ico(0))),
    _probe("odd-icosphere-1", "probe-odd-torus", torus),
    _probe("even-icosphere-1-loop", "probe-even-torus-loop", torus),
    _probe("even-icosphere-1-loop", "probe-even-height-field-loop", height_field, hint=f"{EVEN_HINT}; {BOUNDARY_HINT}"),
    _probe("faces-icosphere-1", "probe-faces-height-field", no_vertices(height_field)),
    _probe("cc-faces-quad-torus", "probe-cc-faces-cube", bumpy_cube, hint="face point = mean of the corners"),
    _probe("cc-edges-quad-torus", "probe-cc-edges-cube", with_face_points(bumpy_cube, "cube"), hint=EDGE_POINT_HINT),
    _probe(
        "cc-quads-cage",
        "probe-cc-quads-cube",
        no_vertices(bumpy_cube),
        hint="one quad per corner j: (idx[j], n + he_edge[j], n + e + he_face[j], n + he_edge[prv[j]])",
    ),
    _probe("cc-edges-quad-torus", "probe-cc-edges-cage", with_face_points(cage, "cage"), hint=EDGE_POINT_HINT),
]

#: Probes on the composite case's own input, tried first.
PROBES = {
    "loop-icosahedron-3-warren": [
        "probe-odd-icosahedron",
        "probe-even-icosahedron-warren",
        "weights-warren",
        "probe-faces-icosahedron",
    ],
    "loop-torus-2-loop": ["probe-odd-torus", "probe-even-torus-loop", "weights-loop", "faces-torus"],
    "loop-height-field-2-loop": [
        "odd-height-field",
        "probe-even-height-field-loop",
        "weights-loop",
        "probe-faces-height-field",
    ],
    "cc-cube-2": ["probe-cc-faces-cube", "probe-cc-edges-cube", "cc-vertices-cube", "probe-cc-quads-cube"],
    "cc-cage-1": ["cc-faces-cage", "probe-cc-edges-cage", "cc-vertices-cage", "cc-quads-cage"],
    "cc-cage-3": ["cc-faces-cage", "probe-cc-edges-cage", "cc-vertices-cage", "cc-quads-cage"],
}


def _kinds(labels) -> str:
    kinds = sorted(set(labels), key=lambda s: (not s.startswith("valence"), s))
    if len(kinds) > 3:
        return ""
    return " at " + " and ".join(kinds)


def _where_even(inputs, expected, got) -> str:
    rows = wrong_rows(expected["S_even"], got["S_even"], "S_even")
    if rows is None or not len(rows):
        return ""
    F = np.asarray(inputs["F"])
    val = topology.valence(F, len(inputs["V"]))
    on_boundary = np.zeros(len(inputs["V"]), bool)
    on_boundary[topology.boundary_edges(F).ravel()] = True
    labels = ["boundary vertices" if on_boundary[r] else f"valence-{int(val[r])} vertices" for r in rows]
    return _kinds(labels)


def _where_odd(inputs, expected, got) -> str:
    rows = wrong_rows(expected["S_odd"], got["S_odd"], "S_odd")
    if rows is None or not len(rows):
        return ""
    F = np.asarray(inputs["F"])
    E = topology.unique_edges(F)
    B = {tuple(e) for e in np.sort(topology.boundary_edges(F), axis=1).tolist()}
    labels = ["boundary edges" if tuple(E[r]) in B else "interior edges" for r in rows if r < len(E)]
    return _kinds(labels)


WHERE = {"loop_even_matrix": _where_even, "loop_odd_matrix": _where_odd}


def _rows_task(name: str, interior_task: int, boundary_rows):
    """The task of the rows of ``name`` that differ: ``interior_task`` when none is a boundary row,
    Task 4 (boundary rules) when all are, else None."""

    def task(inputs, expected, got):
        rows = wrong_rows(expected[name], got[name], name)
        if rows is None or not len(rows):
            return None
        on_boundary = boundary_rows(inputs)[np.asarray(rows)]
        if not on_boundary.any():
            return interior_task
        return 4 if on_boundary.all() else None

    return task


def _boundary_edge_rows(inputs):
    F = np.asarray(inputs["F"])
    E = topology.unique_edges(F)
    B = {tuple(e) for e in np.sort(topology.boundary_edges(F), axis=1).tolist()}
    return np.array([tuple(e) in B for e in E.tolist()], bool)


def _boundary_vertex_rows(inputs):
    out = np.zeros(len(inputs["V"]), bool)
    out[topology.boundary_edges(np.asarray(inputs["F"])).ravel()] = True
    return out


#: A boundary-rules case has interior rows too: when only those differ, the message names Task 1
#: or 2 (and its hint), not the case's Task 4.
ROWS_TASK = {
    "loop_odd_matrix": _rows_task("S_odd", 1, _boundary_edge_rows),
    "loop_even_matrix": _rows_task("S_even", 2, _boundary_vertex_rows),
}


def _picture(name):
    def picture(ctx, inputs, expected, got):
        return matrix_picture(ctx, inputs["V"], inputs["F"], expected[name], got[name], name)

    return picture


PICTURES = {"loop_even_matrix": _picture("S_even"), "loop_odd_matrix": _picture("S_odd")}
