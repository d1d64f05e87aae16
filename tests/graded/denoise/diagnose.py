"""Diagnosis table of the denoise lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (the stubs'
"Task N" markers vanish as students fill them in; ``tests/framework/test_diagnose.py`` checks this
table against the solutions). When a composite case fails, the grader runs the student's building
blocks on this lab's graded cases of them, in task order, and names the first that is wrong.
"""

from __future__ import annotations

TASKS = {
    "denoise_vertices": (3,),
    "laplacian_offsets": (1,),
    "normal_offsets": (2,),
    "bake_offset_map": (4,),
    "denoise_with_map": (5,),
    "weld_seams": (6,),
    "seam_mean": (6,),
}
TITLES = {
    1: "uniform offsets",
    2: "projection on normals",
    3: "direct denoising",
    4: "bake",
    5: "denoising through the map",
    6: "seam fix, weld",
}
COMPOSITES = {
    "denoise_vertices": ("laplacian_offsets", "normal_offsets", "seam_mean", "weld_seams"),
    "laplacian_offsets": ("weld_seams",),
    "denoise_with_map": ("seam_mean", "weld_seams"),
}
