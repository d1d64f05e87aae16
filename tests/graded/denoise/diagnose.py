"""Task table of the denoise lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis")."""

from __future__ import annotations

TASKS = {
    "denoise_vertices": (3,),
    "laplacian_offsets": (1,),
    "normal_offsets": (2,),
    "bake_offset_map": (4,),
    "denoise_with_map": (5,),
    "weld_seams": (6,),
    "seam_mean": (6,),
    "glsl_denoise_with_map": (7,),
}
TITLES = {
    1: "uniform offsets",
    2: "projection on normals",
    3: "direct denoising",
    4: "bake",
    5: "denoising through the map",
    6: "seam fix, weld",
    7: "vertex denoising",
}
COMPOSITES = {
    "denoise_vertices": ("laplacian_offsets", "normal_offsets", "seam_mean", "weld_seams"),
    "laplacian_offsets": ("weld_seams",),
    "denoise_with_map": ("seam_mean", "weld_seams"),
    "glsl_denoise_with_map": ("seam_mean", "weld_seams"),
}
