"""Diagnosis table of the shadows lab (see ``geomlib.grading.diagnose`` and ``geomlib.grading.tasks``).

``TASKS``, ``TITLES`` and ``COMPOSITES`` declare which task each function belongs to (the stubs'
"Task N" markers vanish as students fill them in; ``tests/framework/test_diagnose.py`` checks this
table against the solutions). When a composite case fails, the grader runs the student's building
blocks on this lab's graded cases of them, in task order, and names the first that is wrong.
"""

from __future__ import annotations

TASKS = {
    "cube_light_matrices": (8,),
    "cube_face_index": (8,),
    "point_shadow_visibility": (8,),
    "cull_faces": (5,),
    "depth_map": (2,),
    "directional_light_matrix": (1,),
    "spot_light_matrix": (1,),
    "light_uvz": (3,),
    "compare_depth": (3,),
    "receiver_depth_gradient": (4,),
    "shadow_bias": (4,),
    "outside_frustum": (6,),
    "pcf_visibility": (7,),
}
TITLES = {
    1: "light matrix",
    2: "depth pass",
    3: "the comparison",
    4: "bias",
    5: "culling",
    6: "frustum handling",
    7: "PCF",
    8: "cube map",
}
COMPOSITES = {
    "cube_depth_maps": ("depth_map", "cull_faces", "cube_light_matrices"),
    "point_shadow_visibility": (
        "compare_depth",
        "light_uvz",
        "receiver_depth_gradient",
        "shadow_bias",
        "outside_frustum",
        "pcf_visibility",
        "cube_face_index",
        "cube_light_matrices",
    ),
    "depth_map": ("cull_faces",),
    "shadow_visibility": (
        "compare_depth",
        "light_uvz",
        "receiver_depth_gradient",
        "shadow_bias",
        "outside_frustum",
        "pcf_visibility",
    ),
    "light_setup": ("directional_light_matrix", "spot_light_matrix", "cube_light_matrices"),
    "light_visibility": (
        "directional_light_matrix",
        "spot_light_matrix",
        "depth_map",
        "compare_depth",
        "light_uvz",
        "receiver_depth_gradient",
        "shadow_bias",
        "cull_faces",
        "outside_frustum",
        "pcf_visibility",
        "cube_face_index",
        "cube_light_matrices",
        "point_shadow_visibility",
    ),
    "render_with_shadows": (
        "directional_light_matrix",
        "spot_light_matrix",
        "depth_map",
        "compare_depth",
        "light_uvz",
        "receiver_depth_gradient",
        "shadow_bias",
        "cull_faces",
        "outside_frustum",
        "pcf_visibility",
        "cube_face_index",
        "cube_light_matrices",
        "point_shadow_visibility",
    ),
    "shadow_report": (
        "directional_light_matrix",
        "spot_light_matrix",
        "depth_map",
        "compare_depth",
        "light_uvz",
        "receiver_depth_gradient",
        "shadow_bias",
        "cull_faces",
        "outside_frustum",
        "pcf_visibility",
        "cube_face_index",
        "cube_light_matrices",
        "point_shadow_visibility",
    ),
}
