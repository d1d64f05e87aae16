"""Task table of the remeshing lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis").

Declared (not derived at grading time) because the stubs' "Task N" markers vanish as students fill them
in, and the stubs alone do not show which building blocks a composite calls; ``tests/framework/
test_diagnose.py`` checks this table against the solutions.
"""

from __future__ import annotations

TASKS = {
    "max_curvature": (11,),
    "adaptive_target_length": (11,),
    "split": (1,),
    "collapse_check": (2,),
    "collapse": (2,),
    "flip_check": (3,),
    "flip": (3,),
    "split_pass": (4,),
    "collapse_pass": (5,),
    "flip_pass": (6,),
    "isotropic_remesh": (10,),
    "sharp_edges": (7,),
    "_relax": (8,),
    "project_to_surface": (9,),
}
TITLES = {
    1: "edge split",
    2: "collapse checks",
    3: "flip checks",
    4: "split long edges",
    5: "collapse short edges",
    6: "equalize valences",
    7: "features",
    8: "tangential relaxation",
    9: "projection",
    10: "the loop",
    11: "curvature",
}
COMPOSITES = {
    "adaptive_target_length": ("max_curvature",),
    "split_pass": ("split",),
    "collapse_pass": ("collapse", "collapse_check"),
    "flip_pass": ("flip", "flip_check"),
    "_target_field": ("adaptive_target_length", "max_curvature"),
    "isotropic_remesh": ("sharp_edges", "_relax", "adaptive_target_length", "max_curvature"),
    "tangential_relaxation": ("_relax",),
}
