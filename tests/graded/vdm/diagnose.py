"""Task table of the vdm lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis")."""

from __future__ import annotations

TASKS = {
    "choose_diagonals": (8,),
    "sharp_features": (7,),
    "align_to_features": (7,),
    "vertex_importance": (4,),
    "importance_field": (5,),
    "boundary_to_square": (1,),
    "parameterize_square": (1,),
    "locate_uv": (2,),
    "sample_surface": (2,),
    "bfm_half_step": (6,),
    "transport_grid": (6,),
    "naive_vdm": (3,),
}
TITLES = {
    1: "boundary",
    2: "point location",
    3: "naive VDM",
    4: "importance",
    5: "field",
    6: "transport solver",
    7: "sharp features",
    8: "diagonals",
}
COMPOSITES = {
    "choose_diagonals": ("locate_uv", "sample_surface"),
    "area_density": ("locate_uv",),
    "parameterize_square": ("boundary_to_square",),
    "sample_surface": ("locate_uv",),
    "bfm_potentials": ("bfm_half_step",),
    "transport_grid": ("bfm_half_step",),
    "naive_vdm": ("locate_uv", "sample_surface"),
    "bake_vdm": (
        "boundary_to_square",
        "parameterize_square",
        "locate_uv",
        "sample_surface",
        "naive_vdm",
        "vertex_importance",
        "importance_field",
        "bfm_half_step",
        "transport_grid",
        "align_to_features",
        "sharp_features",
        "choose_diagonals",
    ),
}
