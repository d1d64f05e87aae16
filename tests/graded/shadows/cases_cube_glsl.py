"""Stored NumPy references for the point light's GLSL route (tasks 11-12), public and hidden.

``shaders/cube_depth.vert`` + ``cube_depth.frag`` (Task 11) are graded against the lab's given NumPy
linear cube pass :func:`cube_distance_maps` (Task 8's window-depth maps turned into distance / far),
drawn through face matrices stored from Task 8's :func:`cube_light_matrices`; ``shaders/cube_shadow.frag``
(Task 12) per pixel of the eye view of ``cases_glsl.py`` against :func:`linear_point_shadow_visibility`
on a stored linear cube map. ``geomlib refs build`` stores every output once (the ``STORED`` entries,
added to ``cases.py``'s and ``cases_hidden.py``'s lists); nothing is computed here.

The lights stand off the planes of the scene's faces: a receiver plane through the light puts its
points exactly on a texel border of its face, where the NumPy route's matrix product and the shader's
cube-map table may round to different texels (the handout's section 1.9).
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input

from .cases_glsl import eye_points
from .support import MapClose, small_scene

CUBE_POS = np.array([0.2, -0.3, 2.6])  # the NumPy cube-map cases' light (cases.py)
#: key -> (position, near, far): the point lights of the GLSL cube cases.
LIGHTS = {
    "a": (CUBE_POS, 0.2, 12.0),
    "b": (np.array([-1.1, 0.7, 1.3]), 0.1, 8.0),
    "b-short": (np.array([-1.1, 0.7, 1.3]), 0.1, 3.0),  # its far plane cuts the floor and the boxes
    "c": (np.array([1.3, 1.7, 3.1]), 0.25, 10.0),
    "d": (np.array([-0.3, -1.9, 0.9]), 0.15, 9.0),
}


def _prefix(visibility: str) -> str:
    return "hidden-" if visibility == "hidden" else ""


def matrices_entry(key: str, visibility: str = "visible") -> Case:
    """Task 8's face matrices of light ``key``, stored so Task 11's tests do not need Task 8."""
    pos, near, far = LIGHTS[key]
    return Case(id=f"{_prefix(visibility)}glsl-cube-matrices-{key}", function="cube_light_matrices",
                inputs=lambda: {"position": pos, "near": near, "far": far}, outputs=("Ms",),
                check=checks.Allclose(atol=1e-10), part="stored input", points=0, visibility=visibility)  # fmt: skip


def linear_maps_entry(key: str, size: int, cull: str, visibility: str = "visible") -> Case:
    """The NumPy linear cube pass (cube_distance_maps) of the small scene for light ``key``."""
    pos, near, far = LIGHTS[key]

    def make():
        V, F = small_scene()
        return {"V": V, "F": F, "position": pos, "size": size, "near": near, "far": far}

    return Case(id=f"{_prefix(visibility)}glsl-cube-linear-{key}-{size}-{cull}", function="cube_distance_maps",
                inputs=make, params={"cull": cull}, outputs=("maps",), check=MapClose("maps", atol=1e-9),
                part="stored input", points=0, visibility=visibility)  # fmt: skip


def cube_visibility_entry(id: str, maps_id: str, key: str, visibility: str = "visible", **params) -> Case:
    """The NumPy linear lookup per eye pixel on the stored linear maps ``maps_id``, for the cube_shadow.frag tests."""
    pos, near, far = LIGHTS[key]

    def make():
        _, P, N = eye_points()
        return {"P": P, "N": N, "maps": stored_input("shadows", maps_id)["maps"], "position": pos, "near": near,
                "far": far}  # fmt: skip

    return Case(id=f"{_prefix(visibility)}{id}", function="linear_point_shadow_visibility", inputs=make,
                params=params, outputs=("visibility",), check=checks.Allclose(atol=1e-12), part="stored input",
                points=0, visibility=visibility)  # fmt: skip


H = "hidden"
#: Public: two lights, culling front and none, a far plane that cuts the scene; default and small bias, PCF 3.
STORED = [
    matrices_entry("a"),
    matrices_entry("b"),
    matrices_entry("b-short"),
    linear_maps_entry("a", 64, "front"),
    linear_maps_entry("b", 48, "none"),
    linear_maps_entry("b-short", 48, "front"),
    cube_visibility_entry("glsl-cube-eye-defaults", "glsl-cube-linear-a-64-front", "a"),
    cube_visibility_entry("glsl-cube-eye-small-bias", "glsl-cube-linear-a-64-front", "a", bias=0.004),
    cube_visibility_entry("glsl-cube-eye-pcf3", "glsl-cube-linear-b-48-none", "b", bias=0.02, pcf=3),
    cube_visibility_entry("glsl-cube-eye-short-far", "glsl-cube-linear-b-short-48-front", "b-short"),
]
#: Hidden: two other lights, sizes and culling modes; PCF 5, the default bias, PCF 3 on a back-culled map.
STORED_HIDDEN = [
    matrices_entry("c", H),
    matrices_entry("d", H),
    linear_maps_entry("c", 80, "front", H),
    linear_maps_entry("d", 56, "back", H),
    cube_visibility_entry("glsl-cube-eye-pcf5", "hidden-glsl-cube-linear-c-80-front", "c", H, bias=0.01, pcf=5),
    cube_visibility_entry("glsl-cube-eye-defaults", "hidden-glsl-cube-linear-d-56-back", "d", H),
    cube_visibility_entry("glsl-cube-eye-pcf3", "hidden-glsl-cube-linear-d-56-back", "d", H, pcf=3),
]
