"""Diagnosis table of the simplification lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (the stubs'
"Task N" markers vanish as students fill them in; ``tests/framework/test_diagnose.py`` checks this
table against the solutions). When a composite case fails, the grader runs the student's building
blocks on this lab's graded cases of them, in task order, and names the first that is wrong.
"""

from __future__ import annotations

TASKS = {
    "link_condition": (3,),
    "flips_normal": (3,),
    "contract_pair": (3,),
    "greedy_collapse": (4,),
    "optimal_contraction": (2,),
    "face_quadrics": (1,),
    "boundary_quadrics": (1,),
    "vertex_quadrics": (1,),
}
TITLES = {1: "quadrics", 2: "placement", 3: "contraction", 4: "greedy loop"}
COMPOSITES = {
    "check_contractions": ("flips_normal", "link_condition"),
    "contract_pairs": ("contract_pair",),
    "pair_costs": ("optimal_contraction",),
    "greedy_collapse": ("optimal_contraction", "contract_pair", "flips_normal", "link_condition"),
    "vertex_quadrics": ("boundary_quadrics", "face_quadrics"),
    "qem_simplify": (
        "boundary_quadrics",
        "face_quadrics",
        "vertex_quadrics",
        "optimal_contraction",
        "contract_pair",
        "flips_normal",
        "link_condition",
        "greedy_collapse",
    ),
}
