"""Stored NumPy references for the GLSL route of the lab "shadows" (tasks 9-10), public and hidden.

``shaders/shadow.frag`` (Task 10) is graded per pixel of an eye view: the surface point and face
normal of every covered pixel of the small scene seen from ``CAMERA`` (rasterized here with
:func:`geomlib.raster.rasterize`, not with the lab). What it must give there is the NumPy route's
:func:`shadow_visibility` on the same points, map and options: ``geomlib refs build`` stores it once
(the ``STORED`` entries below, added to ``cases.py``'s and ``cases_hidden.py``'s lists); the depth maps
are the stored depth-pass inputs of those modules. ``depth.vert``/``depth.frag`` (Task 9) are graded
against the references of the NumPy depth-pass cases themselves.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from geomlib import camera
from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input
from geomlib.raster import rasterize

from .support import CAMERA, MapClose, ortho_light, small_scene, spot_light

#: Size of the eye view whose pixels shadow.frag shades.
EYE_SIZE = (96, 72)
LIGHT_DIR = np.array([0.4, 0.5, -0.75])
#: A spot light whose far plane (6) cuts the floor: the floor's far corner has z > 1 in its map.
M_SPOT_SHORT = spot_light(far=6.0)


@cache
def eye_points(width: int = EYE_SIZE[0], height: int = EYE_SIZE[1]):
    """``(mask, P, N)``: the covered pixels of the eye view, their world points and unit face normals."""
    V, F = small_scene()
    eye, target, up = CAMERA
    Mc = camera.perspective_look_at(eye, target, up, 40.0, width / height, 1.0, 20.0)
    g = rasterize(V, F, Mc, width, height, attributes={"position": V})
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return g.mask, g.attributes["position"][g.mask], n[g.face_id[g.mask]]


def eye_inputs(depth_id: str, M):
    """The eye view's points and normals with a stored depth map ``depth_id`` taken through ``M``."""

    def make():
        _, P, N = eye_points()
        return {"P": P, "N": N, "D": stored_input("shadows", depth_id)["D"], "M": M}

    return make


def visibility_entry(id: str, depth_id: str, M, visibility: str = "visible", **params) -> Case:
    """The NumPy route's shadow_visibility per eye pixel, stored for the shadow.frag tests."""
    return Case(id=id, function="shadow_visibility", inputs=eye_inputs(depth_id, M), params=params,
                outputs=("visibility",), check=checks.Allclose(atol=1e-12), part="stored input", points=0,
                visibility=visibility)  # fmt: skip


def _spot_short_depth(visibility="visible"):
    def make():
        V, F = small_scene()
        return {"V": V, "F": F, "M": M_SPOT_SHORT, "size": 64}

    prefix = "hidden-" if visibility == "hidden" else ""
    return Case(id=f"{prefix}depth-spot-short-64", function="depth_map", inputs=make, params={"cull": "front"},
                outputs=("D",), check=MapClose("D", atol=1e-9), part="stored input", points=0,
                visibility=visibility)  # fmt: skip


def _depth(id: str, M, size: int, visibility="visible"):
    """A depth map of the small scene through M (cull "none"), stored for the shadow.frag cases."""

    def make():
        V, F = small_scene()
        return {"V": V, "F": F, "M": M, "size": size}

    return Case(id=id, function="depth_map", inputs=make, params={"cull": "none"}, outputs=("D",),
                check=MapClose("D", atol=1e-9), part="stored input", points=0, visibility=visibility)  # fmt: skip


M_ORTHO = ortho_light(LIGHT_DIR)
M_SPOT = spot_light()
M_PARTIAL = ortho_light(LIGHT_DIR, bounds=[[-1.5, -1.5, 0], [1.5, 1.5, 1.9]])
M2 = ortho_light(np.array([-0.6, 0.2, -0.7]))
S2 = spot_light(position=(3.0, 2.0, 4.0), target=(0.5, 0.0, 0.3), fov=55.0, near=1.0, far=10.0)
# Every shadow.frag test has a case where part of the view lies outside the light's frustum, so a shader that
# never finds a point outside it (outside_frustum) fails each of them, not only the frustum tests:
#: the spot light with its far plane at 8: the floor's far part (z > 1, 13% of the view) must stay lit;
M_SPOT_8 = spot_light(far=8.0)
#: the hidden light M2's map over the middle of the floor only;
M2_PARTIAL = ortho_light(np.array([-0.6, 0.2, -0.7]), bounds=[[-1.5, -1.5, 0], [1.5, 1.5, 1.9]])
#: the hidden spot light S2 with its far plane at 6.
S2_SHORT = spot_light(position=(3.0, 2.0, 4.0), target=(0.5, 0.0, 0.3), fov=55.0, near=1.0, far=6.0)

#: Public: constant bias, slope-scaled bias (the defaults, a map over the middle of the floor), 3 x 3 PCF (a spot whose
#: far plane cuts the floor), Poisson, z > 1 with and without the fix.
STORED = [
    _spot_short_depth(),
    visibility_entry("glsl-eye-ortho-constant-bias", "depth-ortho-64", M_ORTHO, bias=0.01, slope_bias=0.0),
    _depth("depth-spot-far8-64", M_SPOT_8, 64),
    visibility_entry("glsl-eye-ortho-defaults", "depth-partial-64", M_PARTIAL),
    visibility_entry("glsl-eye-spot-pcf3", "depth-spot-far8-64", M_SPOT_8, bias=0.002, slope_bias=1.5, pcf=3),
    visibility_entry("glsl-eye-spot-poisson", "depth-spot-64", M_SPOT, pcf=3, pcf_sampling="poisson"),
    visibility_entry("glsl-eye-spot-short-far", "depth-spot-short-64", M_SPOT_SHORT),
    visibility_entry("glsl-eye-spot-short-far-nofix", "depth-spot-short-64", M_SPOT_SHORT, frustum_fix=False),
]
H = "hidden"
#: Hidden: other lights and maps, 5 x 5 PCF with a large slope factor, 32 Poisson samples, a map beside the view.
STORED_HIDDEN = [
    _depth("hidden-depth-m2-partial-80", M2_PARTIAL, 80, H),
    _depth("hidden-depth-s2-short-72", S2_SHORT, 72, H),
    visibility_entry(
        "hidden-glsl-eye-m2-pcf5", "hidden-depth-m2-partial-80", M2_PARTIAL, H, bias=0.001, slope_bias=2.0, pcf=5
    ),
    visibility_entry("hidden-glsl-eye-m2-defaults", "depth-hidden-m2-80", M2, H),
    visibility_entry(
        "hidden-glsl-eye-s2-poisson32", "depth-hidden-s2-72", S2, H, pcf=5, pcf_sampling="poisson", pcf_samples=32
    ),
    visibility_entry("hidden-glsl-eye-s2-max-slope", "hidden-depth-s2-short-72", S2_SHORT, H, pcf=3, max_slope=2.0),
    visibility_entry("hidden-glsl-eye-partial", "depth-partial-64", M_PARTIAL, H, pcf=3),
    visibility_entry("hidden-glsl-eye-partial-nofix", "depth-partial-64", M_PARTIAL, H, frustum_fix=False),
]
