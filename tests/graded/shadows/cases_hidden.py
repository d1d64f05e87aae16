"""Hidden graded cases of the lab "shadows": other lights, sizes and points than the public ones."""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks

from .cases import (
    _grad,
    _map_inputs,
    _pick,
    _point_inputs,
    _scene,
    cube_entries,
    gradient_entry,
    map_entries,
    stored,
    uvz_entry,
)
from .support import CAMERA, MapClose, SameRows, ortho_light, small_scene, spot_light

DIR2 = np.array([-0.6, 0.2, -0.7])
M2 = ortho_light(DIR2)
S2 = spot_light(position=(3.0, 2.0, 4.0), target=(0.5, 0.0, 0.3), fov=55.0, near=1.0, far=10.0)
H = "hidden"
MAP2 = _map_inputs("hidden-m2-80", M2, seed=11)
MAP_S2 = _map_inputs("hidden-s2-72", S2, seed=12)
STORED = [
    *map_entries("hidden-m2-80", M2, 80, seed=11, visibility=H),
    *map_entries("hidden-s2-72", S2, 72, seed=12, visibility=H),
    gradient_entry("gradient-hidden-m2-80", M2, 80, seed=11, visibility=H),
    uvz_entry("uvz-hidden-s2-13", S2, seed=13, visibility=H),
    *cube_entries(48, visibility=H),
]

CASES = [
    Case(
        id="hidden-directional-oblique",
        function="directional_light_matrix",
        inputs=lambda: {
            "direction": np.array([1.0, -2.0, 0.3]),
            "bounds": np.array([[-1.0, 0.0, 2.0], [4.0, 1.5, 3.0]]),
        },
        outputs=("M",),
        check=checks.Allclose(atol=1e-10),
        part="light matrix",
        points=6,
        visibility="hidden",
    ),
    Case(
        id="hidden-spot-narrow",
        function="spot_light_matrix",
        inputs=lambda: {
            "position": np.array([3.0, 2.0, 4.0]),
            "target": np.array([0.5, 0.0, 0.3]),
            "fov_deg": 25.0,
            "near": 0.5,
            "far": 30.0,
        },
        outputs=("M",),
        check=checks.Allclose(atol=1e-10),
        part="light matrix",
        points=5,
        visibility="hidden",
    ),
    Case(
        id="hidden-depth-80",
        function="depth_map",
        inputs=_scene(M=M2, size=80),
        params={"cull": "none"},
        outputs=("D",),
        check=MapClose("D", atol=1e-9),
        part="depth pass",
        points=8,
        visibility="hidden",
    ),
    Case(
        id="hidden-compare-spot",
        function="compare_depth",
        inputs=_pick(MAP_S2, "D", "uvz", bias=0.003),
        outputs=("lit",),
        check=checks.Allclose(atol=1e-12),
        part="comparison",
        points=12,
        visibility="hidden",
    ),
    Case(
        id="hidden-gradient",
        function="receiver_depth_gradient",
        inputs=_pick(MAP_S2, "P", "N", "M", size=72),
        outputs=("g",),
        check=checks.Allclose(atol=1e-10),
        part="bias",
        points=11,
        visibility="hidden",
    ),
    Case(
        id="hidden-cull-front-spot",
        function="cull_faces",
        inputs=_scene(M=S2),
        params={"cull": "front"},
        outputs=("F",),
        check=SameRows("F"),
        part="culling",
        points=8,
        visibility="hidden",
    ),
    Case(
        id="hidden-outside-spot",
        function="outside_frustum",
        inputs=lambda: {"uvz": np.nan_to_num(stored("uvz-hidden-s2-13")["uvz"], nan=2.0)},
        outputs=("outside",),
        check=checks.Equal("outside"),
        part="frustum handling",
        points=5,
        visibility="hidden",
    ),
    Case(
        id="hidden-pcf3-gradient",
        function="pcf_visibility",
        inputs=lambda: {**_grad(MAP2, "hidden-m2-80")(), "bias": 0.001},
        params={"pcf": 3},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="PCF",
        points=9,
        visibility="hidden",
    ),
    Case(
        id="hidden-point-light",
        function="point_shadow_visibility",
        inputs=lambda: _point_inputs(48, seed=14, prefix="hidden-"),
        params={"bias": 0.004, "slope_bias": 0.0},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="cube map",
        points=9,
        visibility="hidden",
    ),
    Case(
        id="hidden-render-spot",
        function="render_with_shadows",
        inputs=lambda: {
            "scene": small_scene(),  # a (V, F) pair: one grey, flat-shaded mesh
            "camera": CAMERA,
            "light": {"type": "spot", "position": np.array([-2.0, -2.5, 6.0]), "target": np.zeros(3), "fov_deg": 70.0},
        },
        # A high spot: the boxes' sides are steep to it, the floor is not, so the slope term alone (bias 0,
        # slope_bias 1) must fit each point's own plane. `bounds` sets the spot's near and far planes (light_setup):
        # its far plane cuts the floor's far corner, which lies in the cone and must stay lit (z > 1: Task 6).
        params={
            "size": [96, 72],
            "map_size": 256,
            "pcf": 1,
            "bounds": [[-2.0, -2.0, 0.0], [1.0, 1.0, 1.9]],
            "bias": 0.0,
            "slope_bias": 1.0,
        },
        outputs=("image",),
        check=checks.ImageMatch(),
        part="all together",
        points=8,
        visibility="hidden",
    ),
]


# The GLSL route's hidden stored NumPy references (tasks 9-10): cases_glsl.py.
from .cases_glsl import STORED_HIDDEN as _GLSL_STORED  # noqa: E402

STORED += _GLSL_STORED

# The point light's GLSL route, hidden (tasks 11-12): cases_cube_glsl.py.
from .cases_cube_glsl import STORED_HIDDEN as _CUBE_GLSL_STORED  # noqa: E402

STORED += _CUBE_GLSL_STORED
