"""Diagnosis table of the maps lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (the stubs'
"Task N" markers vanish as students fill them in; ``tests/framework/test_diagnose.py`` checks this
table against the solutions). When a composite case fails, the grader runs the student's building
blocks on this lab's graded cases of them, in task order, and names the first that is wrong.
"""

from __future__ import annotations

TASKS = {
    "bake_normal_map": (6,),
    "displace": (5,),
    "encode_normal_map": (2,),
    "decode_normal_map": (2,),
    "height_to_normal_map": (3,),
    "shade": (4,),
    "tangent_frames": (1,),
}
TITLES = {1: "face tangents", 2: "encode", 3: "height to normals", 4: "normal", 5: "displace", 6: "low-mesh frames"}
COMPOSITES = {"bake_normal_map": ("tangent_frames",)}
