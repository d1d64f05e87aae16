"""Task table of the simplification lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis")."""

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
