"""Task table of the shadows lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis")."""

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
    "glsl_depth_map": (9,),
    "glsl_shadow_visibility": (10,),
    "glsl_cube_depth_maps": (11,),
    "glsl_point_shadow_visibility": (12,),
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
    9: "light pass",
    10: "fragment shadow test",
    11: "cube light pass",
    12: "cube shadow lookup",
}
#: The shadow test of one receiver point, in task order.
_VISIBILITY = (
    "compare_depth",
    "light_uvz",
    "receiver_depth_gradient",
    "shadow_bias",
    "outside_frustum",
    "pcf_visibility",
)
#: Every building block of a full shadowed render, in task order.
_ALL = (
    "directional_light_matrix",
    "spot_light_matrix",
    "depth_map",
    *_VISIBILITY[:4],
    "cull_faces",
    *_VISIBILITY[4:],
    "cube_face_index",
    "cube_light_matrices",
    "point_shadow_visibility",
)
COMPOSITES = {
    "cube_depth_maps": ("depth_map", "cull_faces", "cube_light_matrices"),
    "point_shadow_visibility": (*_VISIBILITY, "cube_face_index", "cube_light_matrices"),
    "depth_map": ("cull_faces",),
    "shadow_visibility": _VISIBILITY,
    "light_setup": ("directional_light_matrix", "spot_light_matrix", "cube_light_matrices"),
    "light_visibility": _ALL,
    "render_with_shadows": _ALL,
    "shadow_report": _ALL,
    "cube_distance_maps": ("depth_map", "cull_faces", "cube_light_matrices"),
    "linear_point_shadow_visibility": (
        "compare_depth",
        "light_uvz",
        "pcf_visibility",
        "cube_face_index",
        "cube_light_matrices",
    ),
    "glsl_cube_depth_maps": ("cube_light_matrices",),
}
