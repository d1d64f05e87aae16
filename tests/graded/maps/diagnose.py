"""Task table of the maps lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis")."""

from __future__ import annotations

TASKS = {
    "bake_normal_map": (6,),
    "displace": (5,),
    "encode_normal_map": (2,),
    "decode_normal_map": (2,),
    "height_to_normal_map": (3,),
    "shade": (4,),
    "tangent_frames": (1,),
    "glsl_tbn": (7,),
    "glsl_shade": (8,),
    "glsl_displace": (9,),
}
TITLES = {
    1: "face tangents",
    2: "encode",
    3: "height to normals",
    4: "normal",
    5: "displace",
    6: "low-mesh frames",
    7: "vertex TBN",
    8: "fragment normal mapping",
    9: "vertex displacement",
}
COMPOSITES = {"bake_normal_map": ("tangent_frames",)}
