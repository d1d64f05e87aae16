"""Graded cases of the lab "shadows" (public): inputs built from geomlib only, never from the solution.

Tolerances: light matrices, map coordinates and gradients to 1e-10 (a few matrix products);
depth maps exactly up to 1e-9 (everyone calls the same deterministic rasterizer); 0/1 shadow tests
and PCF fractions to 1e-12 (the points are random, so none sits within round-off of a texel border
or of its stored depth); rendered images by ``ImageMatch`` (at most 0.5% of pixels off by more than
2/255).
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input

from .support import (
    CAMERA,
    SCENE_BOUNDS,
    MapClose,
    NanClose,
    SameRows,
    ortho_light,
    small_scene,
    spot_light,
    surface_points,
)

LIGHT_DIR = np.array([0.4, 0.5, -0.75])
CUBE_POS = np.array([0.2, -0.3, 2.6])
#: The light of the public render case: steep, so the boxes' sides need more bias than the floor.
RENDER_DIR = np.array([2.5, 1.5, -6.5])


def _scene(**extra):
    def make():
        V, F = small_scene()
        return {"V": V, "F": F, **extra}

    return make


# ------------------------------------------------------------------------ stored inputs
# What a test needs from an earlier task (a depth map, light-space coordinates, receiver-plane
# gradients, cube-map matrices) is never computed here: `geomlib refs build` runs the solution
# once on the entries of STORED and the helpers read its outputs back with `stored_input`.


def _points(seed, n=400):
    V, F = small_scene()
    return surface_points(V, F, n, seed)


def stored(id: str) -> dict:
    return stored_input("shadows", id)


def depth_entry(id, M, size, cull="none", visibility="visible"):
    """A depth map of the small scene through M (Task 2's output), stored for later tasks."""
    return Case(id=id, function="depth_map", inputs=_scene(M=M, size=size), params={"cull": cull}, outputs=("D",),
                check=MapClose("D", atol=1e-9), part="stored input", points=0, visibility=visibility)  # fmt: skip


def uvz_entry(id, M, seed, n=400, visibility="visible"):
    """Light-space coordinates of random surface points (Task 3's light_uvz), stored for later tasks."""
    return Case(id=id, function="light_uvz", inputs=lambda: {"P": _points(seed, n)[0], "M": M}, outputs=("uvz",),
                check=NanClose("uvz", atol=1e-10), part="stored input", points=0, visibility=visibility)  # fmt: skip


def gradient_entry(id, M, size, seed, n=400, visibility="visible"):
    """Receiver-plane gradients of random surface points (Task 4), stored for the PCF cases."""

    def inputs():
        P, N = _points(seed, n)
        return {"P": P, "N": N, "M": M, "size": size}

    return Case(id=id, function="receiver_depth_gradient", inputs=inputs, outputs=("g",),
                check=checks.Allclose(atol=1e-10), part="stored input", points=0, visibility=visibility)  # fmt: skip


def map_entries(key, M, size, seed, visibility="visible"):
    return [
        depth_entry(f"depth-{key}", M, size, visibility=visibility),
        uvz_entry(f"uvz-{key}", M, seed, visibility=visibility),
    ]


def _map_inputs(key, M, seed, n=400, frustum=False):
    """A stored depth map of the small scene through M, random surface points and their stored map coordinates."""

    def make():
        P, N = _points(seed, n)
        D = stored(f"depth-{key}")["D"]
        uvz = stored(f"uvz-{key}")["uvz"]
        if not frustum:
            keep = np.all((uvz >= 0) & (uvz <= 1), axis=1)
            P, N, uvz = P[keep], N[keep], uvz[keep]
        return {"D": D, "P": P, "N": N, "uvz": uvz, "M": M}

    return make


def _pick(make, *names, **extra):
    def f():
        d = make()
        return {**{k: d[k] for k in names}, **extra}

    return f


def _grad(make, key):
    """Stored receiver-plane gradients of the map's points (so PCF does not need the student's Task 4)."""

    def f():
        d = make()
        uvz_all = stored(f"uvz-{key}")["uvz"]
        keep = np.all((uvz_all >= 0) & (uvz_all <= 1), axis=1)
        return {"D": d["D"], "uvz": d["uvz"], "gradient": stored(f"gradient-{key}")["g"][keep]}

    return f


M_ORTHO = ortho_light(LIGHT_DIR)
M_SPOT = spot_light()
M_PARTIAL = ortho_light(LIGHT_DIR, bounds=[[-1.5, -1.5, 0], [1.5, 1.5, 1.9]])  # covers part of the floor
MAP_ORTHO = _map_inputs("ortho-64", M_ORTHO, seed=1)
MAP_SPOT = _map_inputs("spot-64", M_SPOT, seed=2)
CUBE_SIZE = 64


def cube_entries(size, visibility="visible"):
    """The six faces' depth maps of a point light at CUBE_POS (Tasks 8 and 2), stored for the cube-map case."""
    prefix = "hidden-" if visibility == "hidden" else ""

    def face_inputs(i):
        def make():
            V, F = small_scene()
            return {"V": V, "F": F, "M": stored(f"{prefix}cube-matrices")["Ms"][i], "size": size}

        return make

    out = [
        Case(id=f"{prefix}cube-matrices", function="cube_light_matrices",
             inputs=lambda: {"position": CUBE_POS, "near": 0.2, "far": 12.0}, outputs=("Ms",),
             check=checks.Allclose(atol=1e-10), part="stored input", points=0, visibility=visibility)
    ]  # fmt: skip
    out += [
        Case(id=f"{prefix}cube-depth-{size}-{i}", function="depth_map", inputs=face_inputs(i), params={"cull": "front"},
             outputs=("D",), check=MapClose("D", atol=1e-9), part="stored input", points=0, visibility=visibility)
        for i in range(6)
    ]  # fmt: skip
    return out


STORED = [
    *map_entries("ortho-64", M_ORTHO, 64, seed=1),
    *map_entries("spot-64", M_SPOT, 64, seed=2),
    gradient_entry("gradient-spot-64", M_SPOT, 64, seed=2),
    uvz_entry("uvz-partial-32", M_PARTIAL, seed=5),
    depth_entry("depth-partial-64", M_PARTIAL, 64),
    *cube_entries(CUBE_SIZE),
]

CASES = [
    # ---------------------------------------------------------------- Task 1: light matrix
    Case(
        id="directional-scene",
        function="directional_light_matrix",
        inputs=lambda: {"direction": LIGHT_DIR, "bounds": SCENE_BOUNDS},
        outputs=("M",),
        check=checks.Allclose(atol=1e-10),
        part="light matrix",
        points=2,
        hint="look_at(c - R d, c, light_up_vector(d)), then a tight orthographic box from the 8 corners in eye space",
    ),
    Case(
        id="directional-straight-down",
        function="directional_light_matrix",
        inputs=lambda: {
            "direction": np.array([0.0, 0.0, -2.0]),
            "bounds": np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 1.0]]),
        },
        outputs=("M",),
        check=checks.Allclose(atol=1e-10),
        part="light matrix",
        points=1,
        hint="normalise the direction; near = -z_max and far = -z_min of the corners in eye space",
    ),
    Case(
        id="spot",
        function="spot_light_matrix",
        inputs=lambda: {
            "position": np.array([-3.0, -3.5, 5.0]),
            "target": np.array([0.0, 0.0, 0.0]),
            "fov_deg": 70.0,
            "near": 2.0,
            "far": 12.0,
        },
        outputs=("M",),
        check=checks.Allclose(atol=1e-10),
        part="light matrix",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 2: depth pass
    Case(
        id="depth-ortho-64",
        function="depth_map",
        inputs=_scene(M=M_ORTHO, size=64),
        params={"cull": "none"},
        outputs=("D",),
        check=MapClose("D", atol=1e-9),
        part="depth pass",
        points=2,
        hint="rasterize(V, F, M, size, size, depth_only=True).depth, empty texels = 1.0",
    ),
    Case(
        id="depth-spot-48",
        function="depth_map",
        inputs=_scene(M=M_SPOT, size=48),
        params={"cull": "none"},
        outputs=("D",),
        check=MapClose("D", atol=1e-9),
        part="depth pass",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 3: the comparison
    Case(
        id="uvz-ortho",
        function="light_uvz",
        inputs=lambda: {"P": _points(3)[0], "M": M_ORTHO},
        outputs=("uvz",),
        check=checks.Allclose(atol=1e-10),
        part="comparison",
        points=1,
        hint="(x, y, z, w) = M @ (P, 1); uvz = (xyz / w + 1) / 2",
    ),
    Case(
        id="uvz-spot",
        function="light_uvz",
        inputs=lambda: {
            "P": np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.5], [-3.0, -3.5, 5.0], [-6.0, -7.0, 10.0], [2.0, -1.0, 0.0]]),
            "M": M_SPOT,
        },
        outputs=("uvz",),
        check=NanClose("uvz", atol=1e-10),
        part="comparison",
        points=1,
        hint="rows where w <= 0 (level with or behind the light) must be NaN",
    ),
    Case(
        id="compare-ortho",
        function="compare_depth",
        inputs=_pick(MAP_ORTHO, "D", "uvz", bias=0.01),
        outputs=("lit",),
        check=checks.Allclose(atol=1e-12),
        part="comparison",
        points=2,
        hint="col = floor(u size), row = size - 1 - floor(v size) (row 0 is the top), lit where z - bias <= D[row, col]",
    ),
    Case(
        id="compare-spot-per-point-bias",
        function="compare_depth",
        inputs=lambda: {**_pick(MAP_SPOT, "D", "uvz")(), "bias": np.linspace(0.0, 0.02, len(MAP_SPOT()["uvz"]))},
        outputs=("lit",),
        check=checks.Allclose(atol=1e-12),
        part="comparison",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 4: bias
    Case(
        id="gradient-ortho",
        function="receiver_depth_gradient",
        inputs=_pick(MAP_ORTHO, "P", "N", "M", size=64),
        outputs=("g",),
        check=checks.Allclose(atol=1e-10),
        part="bias",
        points=2,
        hint="(a, b, c, d) = M^{-T} (N, -N.P); g = clip(-(a, b) / c, -max_slope, max_slope) / size",
    ),
    Case(
        id="gradient-spot",
        function="receiver_depth_gradient",
        inputs=_pick(MAP_SPOT, "P", "N", "M", size=64),
        params={"max_slope": 5.0},
        outputs=("g",),
        check=checks.Allclose(atol=1e-10),
        part="bias",
        points=1,
    ),
    Case(
        id="bias-formula",
        function="shadow_bias",
        inputs=lambda: {
            "gradient": np.array([[0.0, 0.0], [0.01, -0.02], [-0.5, 0.25]]),
            "bias": 0.001,
            "slope_bias": 1.5,
        },
        outputs=("b",),
        check=checks.Allclose(atol=1e-12),
        part="bias",
        points=1,
        hint="b = bias + slope_bias (|g_u| + |g_v|) / 2",
    ),
    # ---------------------------------------------------------------- Task 5: culling
    Case(
        id="cull-front-ortho",
        function="cull_faces",
        inputs=_scene(M=M_ORTHO),
        params={"cull": "front"},
        outputs=("F",),
        check=SameRows("F"),
        part="culling",
        points=1,
        hint="front-facing <=> det([x, y, w] of the three corners in clip space) > 0; cull='front' drops those",
    ),
    Case(
        id="cull-back-spot",
        function="cull_faces",
        inputs=_scene(M=M_SPOT),
        params={"cull": "back"},
        outputs=("F",),
        check=SameRows("F"),
        part="culling",
        points=1,
    ),
    Case(
        id="depth-front-culled",
        function="depth_map",
        inputs=_scene(M=M_ORTHO, size=64),
        params={"cull": "front"},
        outputs=("D",),
        check=MapClose("D", atol=1e-9),
        part="culling",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 6: frustum
    Case(
        id="outside-ortho",
        function="outside_frustum",
        inputs=lambda: {"uvz": stored("uvz-partial-32")["uvz"]},
        outputs=("outside",),
        check=checks.Equal("outside"),
        part="frustum handling",
        points=1,
        hint="outside: u or v outside [0, 1], or z > 1 (z < 0 is not outside)",
    ),
    # ---------------------------------------------------------------- Task 7: PCF
    Case(
        id="pcf3-ortho",
        function="pcf_visibility",
        inputs=_pick(MAP_ORTHO, "D", "uvz", bias=0.005),
        params={"pcf": 3},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="PCF",
        points=2,
        hint="mean over i, j in -(k-1)/2..(k-1)/2 of [z - bias <= D[clamp(row - j), clamp(col + i)]]: j counts texels UP",
    ),
    Case(
        id="pcf5-spot-gradient",
        function="pcf_visibility",
        inputs=lambda: {**_grad(MAP_SPOT, "spot-64")(), "bias": 0.002},
        params={"pcf": 5},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="PCF",
        points=1,
        hint="with a gradient, neighbour (i, j) compares z + g_u i + g_v j - bias",
    ),
    # ---------------------------------------------------------------- Task 8: cube map
    Case(
        id="cube-matrices",
        function="cube_light_matrices",
        inputs=lambda: {"position": CUBE_POS, "near": 0.2, "far": 12.0},
        outputs=("Ms",),
        check=checks.Allclose(atol=1e-10),
        part="cube map",
        points=1,
        hint="perspective(90, 1, near, far) @ look_at(position, position + CUBE_DIRECTIONS[i], CUBE_UPS[i])",
    ),
    Case(
        id="cube-faces",
        function="cube_face_index",
        inputs=lambda: {"directions": np.random.default_rng(7).normal(size=(200, 3))},
        outputs=("face",),
        check=checks.Equal("face"),
        part="cube map",
        points=1,
    ),
    Case(
        id="point-light-visibility",
        function="point_shadow_visibility",
        inputs=lambda: _point_inputs(64, seed=8),
        params={"bias": 0.002, "slope_bias": 0.0},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="cube map",
        points=2,
        hint="pick each point's face with cube_face_index(P - position) and use shadow_visibility with that face's map and matrix",
    ),
    # ---------------------------------------------------------------- everything together
    Case(
        id="visibility-ortho-defaults",
        function="shadow_visibility",
        # the map of M_PARTIAL covers the middle of the floor only: the points beside it must stay lit (Task 6)
        inputs=lambda: {**dict(zip(("P", "N"), _points(5))), "D": stored("depth-partial-64")["D"], "M": M_PARTIAL},
        params={"pcf": 3},
        outputs=("visibility",),
        check=checks.Allclose(atol=1e-12),
        part="all together",
        points=1,
    ),
    Case(
        id="render-small",
        function="render_with_shadows",
        # the scene as a (V, F) pair: one grey, flat-shaded mesh
        inputs=lambda: {
            "scene": small_scene(),
            "camera": CAMERA,
            "light": {"type": "directional", "direction": RENDER_DIR},
        },
        # The map's box covers the middle of the floor (the rest must be lit: Task 6), and the slope term alone
        # (bias 0, slope_bias 1) must fit each point's own plane: a steep light on the floor and the boxes' sides
        # (one gradient or one bias for every point shows as acne on the sides).
        params={
            "size": [96, 72],
            "map_size": 256,
            "bounds": [[-1.5, -1.5, 0.0], [1.5, 1.5, 1.9]],
            "bias": 0.0,
            "slope_bias": 1.0,
        },
        outputs=("image",),
        check=checks.ImageMatch(),
        part="all together",
        points=1,
    ),
]


def _point_inputs(size, seed, n=400, near=0.2, far=12.0, prefix=""):
    """Six stored depth maps of a point light (the solution's cube-map matrices and depth pass) and surface points."""
    maps = np.stack([stored(f"{prefix}cube-depth-{size}-{i}")["D"] for i in range(6)])
    P, N = _points(seed, n)
    return {"P": P, "N": N, "maps": maps, "position": CUBE_POS, "near": near, "far": far}


# The GLSL route's stored NumPy references (tasks 9-10): cases_glsl.py.
from .cases_glsl import STORED as _GLSL_STORED  # noqa: E402

STORED += _GLSL_STORED

# The point light's GLSL route (tasks 11-12): cases_cube_glsl.py.
from .cases_cube_glsl import STORED as _CUBE_GLSL_STORED  # noqa: E402

STORED += _CUBE_GLSL_STORED
