"""Task table of the relief lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis").

Declared here because the markers it is read from (``geomlib.grading.tasks.derive``) leave the
stubs as a student fills them in; a framework test checks it against the solutions.
"""

from __future__ import annotations

TASKS = {
    "bump_offset": (1,),
    "bump_normal": (1,),
    "parallax_uv": (2,),
    "relief_uv": (3,),
    "relief_shadow": (4,),
    "inside_texture": (5,),
    "glsl_parallax_uv": (2,),
    "glsl_relief_uv": (3,),
    "glsl_relief_shadow": (4,),
}
TITLES = {
    1: "bump offset",
    2: "parallax",
    3: "march",
    4: "shadow",
    5: "silhouette",
}
COMPOSITES = {
    "bump_normal": ("bump_offset",),
}
