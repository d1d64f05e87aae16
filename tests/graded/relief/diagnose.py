"""Task table of the relief lab: the task of each function (docs/adding-a-lab.md, "Tasks and diagnosis").

Declared (not derived at grading time) because the stubs' "Task N" markers vanish as students fill them
in, and the stubs alone do not show which building blocks a composite calls; ``tests/framework/
test_diagnose.py`` checks this table against the solutions.
"""

from __future__ import annotations

TASKS = {
    "bump_offset": (1,),
    "bump_normal": (1,),
    "parallax_uv": (2,),
    "relief_uv": (3,),
    "relief_shadow": (4,),
    "inside_texture": (5,),
}
TITLES = {1: "bump offset", 2: "parallax", 3: "march", 4: "shadow", 5: "silhouette"}
COMPOSITES = {"bump_normal": ("bump_offset",)}
