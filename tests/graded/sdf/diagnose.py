"""Diagnosis table of the sdf lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (derived from the
solutions' ``BEGIN SOLUTION: Task N (title)`` markers). When a composite case fails, the grader runs the
student's building blocks on this lab's graded cases of them, in task order, and names the first that is wrong.
"""

from __future__ import annotations

TASKS = {
    "op_difference": (1,),
    "op_intersection": (1,),
    "op_union": (1,),
    "sd_box": (1,),
    "sd_capsule": (1,),
    "sd_plane": (1,),
    "sd_sphere": (1,),
    "sd_torus": (1,),
    "brute_force_distance": (2,),
    "point_triangle_distance": (2,),
    "build_bvh_kernel": (3,),
    "closest_kernel": (3,),
    "closest_on_triangle": (3,),
    "grid_sdf_values": (3,),
    "crossings_kernel": (4,),
    "pseudonormals": (4,),
    "sign_normal": (4,),
    "sign_pseudonormal": (4,),
    "sign_vote": (4,),
    "winding_number": (4,),
    "encode_bricks": (5,),
    "brick_sample": (6,),
    "instances_distance": (6,),
    "trilinear": (6,),
    "gradient_central": (7,),
    "gradient_tetra": (7,),
    "sphere_trace": (8,),
    "ambient_occlusion": (9,),
    "push_out": (9,),
    "soft_shadow": (9,),
}
TITLES = {
    1: "analytic SDFs",
    2: "point-triangle distance",
    3: "BVH",
    4: "sign",
    5: "bricks",
    6: "queries",
    7: "gradients",
    8: "sphere tracing",
    9: "soft shadows",
}
COMPOSITES = {
    "compress_bricks": ("encode_bricks",),
    "closest_kernel": ("closest_on_triangle",),
    "_sign": ("pseudonormals", "sign_normal", "sign_pseudonormal", "sign_vote", "winding_number"),
    "signed_distance": ("pseudonormals", "sign_normal", "sign_pseudonormal", "sign_vote", "winding_number"),
    "grid_sdf_values": ("pseudonormals", "sign_normal", "sign_pseudonormal", "sign_vote", "winding_number"),
    "sdf_grid": ("grid_sdf_values", "pseudonormals", "sign_normal", "sign_pseudonormal", "sign_vote", "winding_number"),
    "push_out": ("gradient_tetra",),
    "sign_pseudonormal": ("pseudonormals",),
    "render_sdf": ("gradient_tetra", "sphere_trace"),
    "brute_force_distance": ("point_triangle_distance",),
}
