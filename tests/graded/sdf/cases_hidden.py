"""Hidden graded cases of the lab "sdf": other shapes, meshes, points and parameters than the public ones."""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks

from .cases import (
    KERNEL_TIMEOUT,
    _ao_inputs,
    _bricks_sample,
    _bvh_inputs,
    _grid_sample,
    _mesh_points,
    _pick,
    _pts,
    _rays,
    _sign_inputs,
    _surface_points,
    _with,
)
from .support import (
    box_mesh,
    close_outputs,
    close_with_inf,
    scene,
    sphere_grid,
    torus_small,
    wedge,
)


def _tri_cloud(n, m, seed):
    def make():
        rng = np.random.default_rng(seed)
        return {"P": rng.uniform(-1.5, 1.5, size=(n, 3)), "T": rng.uniform(-1, 1, size=(m, 3, 3))}

    return make


def _budget_rays():
    """Rays that run out of a 6-step budget, and 20 that fall straight onto the ground in two steps
    (far from the balls), so the step counts differ from ray to ray."""
    rays = _rays("balls", 200, 117)()
    x = np.random.default_rng(122).uniform(-3.0, -2.5, 20)
    down = np.c_[x, np.linspace(-1.0, 1.0, 20), np.full(20, 2.0)]
    rays["origins"] = np.r_[rays["origins"], down]
    rays["directions"] = np.r_[rays["directions"], np.tile([0.0, 0.0, -1.0], (20, 1))]
    return rays


H = "hidden"

CASES = [
    # Task 1
    Case(
        id="hidden-box-random",
        function="sd_box",
        inputs=_with(_pts(200, 101), center=np.array([0.3, -0.2, 0.1]), half_size=np.array([0.5, 1.2, 0.8])),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-capsule-torus-sphere",
        function="sd_capsule",
        inputs=_with(_pts(200, 102), a=np.array([0.2, 0.1, -0.7]), b=np.array([-0.3, 0.4, 0.9]), radius=0.45),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-torus",
        function="sd_torus",
        inputs=_with(_pts(200, 103), center=np.array([-0.2, 0.3, 0.0]), major=1.2, minor=0.5),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-union",
        function="op_union",
        inputs=lambda: {"a": np.linspace(-1, 1, 21), "b": np.linspace(1, -1.5, 21)},
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
        visibility=H,
    ),
    Case(
        id="hidden-intersection",
        function="op_intersection",
        inputs=lambda: {"a": np.linspace(-1, 1, 21), "b": np.linspace(1, -1.5, 21)},
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
        visibility=H,
    ),
    # Task 2
    Case(
        id="hidden-triangles-random",
        function="point_triangle_distance",
        inputs=_tri_cloud(80, 30, 104),
        outputs=("sq_dist", "closest", "region"),
        check=checks.All(checks.Equal("region"), checks.Allclose(("sq_dist", "closest"), atol=1e-10)),
        part="point-triangle distance",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-brute-force-wedge",
        function="brute_force_distance",
        inputs=_mesh_points(wedge, 150, 105),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist", "closest"), 1e-9)),
        part="point-triangle distance",
        points=2,
        visibility=H,
    ),
    # Task 3
    Case(
        id="hidden-bvh-closest-box",
        function="bvh_closest",
        timeout=KERNEL_TIMEOUT,
        inputs=_bvh_inputs(box_mesh, 300, 106),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist", "closest"), 1e-9)),
        part="BVH",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-bvh-band-wedge",
        function="bvh_closest",
        timeout=KERNEL_TIMEOUT,
        inputs=_with(_bvh_inputs(wedge, 300, 107), band=0.1),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist",), 1e-9)),
        part="BVH",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-band-grid-torus",
        function="grid_sdf_values",
        timeout=KERNEL_TIMEOUT,
        inputs=lambda: {
            "V": torus_small()[0],
            "F": torus_small()[1],
            "origin": np.array([-1.6, -1.6, -0.6]),
            "spacing": 0.16,
            "shape": (21, 21, 8),
            "band": 1.5,
        },
        outputs=("values",),
        check=checks.Allclose(atol=1e-9),
        tasks=(3, 4),  # the signs come from Task 4
        part="BVH",
        points=2,
        visibility=H,
    ),
    # Task 4
    Case(
        id="hidden-pseudonormals-torus",
        function="pseudonormals",
        inputs=lambda: dict(zip(("V", "F"), torus_small(), strict=True)),
        outputs=("face_n", "edge_n", "vertex_n"),
        check=checks.Allclose(atol=1e-10),
        part="sign",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-pseudonormal-sign-box",
        function="sign_pseudonormal",
        inputs=_sign_inputs(box_mesh, 400, 108, near=True),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-normal-sign-box",
        function="sign_normal",
        inputs=_pick(_sign_inputs(box_mesh, 400, 108, near=True), "V", "F", "P", "face", "closest"),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-vote-wedge",
        function="sign_vote",
        timeout=KERNEL_TIMEOUT,
        inputs=_pick(_mesh_points(wedge, 300, 109), "V", "F", "P"),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-winding-torus",
        function="winding_number",
        inputs=_pick(_mesh_points(torus_small, 150, 110), "V", "F", "P"),
        outputs=("w",),
        check=checks.Allclose(atol=1e-9),
        part="sign",
        points=1,
        visibility=H,
    ),
    # Task 5
    Case(
        id="hidden-bricks-sphere-30",
        function="encode_bricks",
        inputs=lambda: dict(zip(("values", "spacing"), sphere_grid(30, radius=0.55)[::2], strict=True)),
        params={"band_voxels": 3.0},
        outputs=("codes", "table"),
        check=checks.All(checks.Equal("table"), checks.Allclose("codes", atol=1.0)),
        part="bricks",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-bricks-sphere-15",
        function="encode_bricks",
        inputs=lambda: dict(zip(("values", "spacing"), sphere_grid(15, radius=0.8)[::2], strict=True)),
        params={"band_voxels": 1.5},
        outputs=("codes", "table"),
        check=checks.All(checks.Equal("table"), checks.Allclose("codes", atol=1.0)),
        part="bricks",
        points=1,
        visibility=H,
    ),
    # Task 6
    Case(
        id="hidden-trilinear-sphere-13",
        function="trilinear",
        inputs=_grid_sample(13, 500, 111),
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-bricks-lookup-3x2x2",
        function="brick_sample",
        inputs=_bricks_sample((3, 2, 2), 7, 112, m=600),
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-instances-three",
        function="instances_distance",
        inputs=lambda: {
            "sdf": scene("three"),
            "P": np.random.default_rng(113).uniform(-3, 3, size=(150, 3)),
            "translations": np.array([[1.0, 0.0, 0.5], [-1.0, 0.5, 0.0], [0.0, -2.0, 1.0]]),
            "scales": np.array([1.5, 0.5, 0.8]),
        },
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=1,
        visibility=H,
    ),
    # Task 7
    Case(
        id="hidden-gradient-6tap-three",
        function="gradient_central",
        inputs=lambda: {"sdf": scene("three"), "P": np.random.default_rng(114).uniform(-1, 1.5, size=(150, 3))},
        params={"h": 5e-3},
        outputs=("N",),
        check=checks.Allclose(atol=1e-9),
        part="gradients",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-gradient-4tap-three",
        function="gradient_tetra",
        inputs=lambda: {"sdf": scene("three"), "P": np.random.default_rng(115).uniform(-1, 1.5, size=(150, 3))},
        params={"h": 5e-3},
        outputs=("N",),
        check=checks.Allclose(atol=1e-9),
        part="gradients",
        points=2,
        visibility=H,
    ),
    # Task 8
    Case(
        id="hidden-trace-three",
        function="sphere_trace",
        inputs=_rays("three", 300, 116),
        params={"max_steps": 48, "eps": 1e-3, "t_max": 10.0},
        outputs=("t", "hit", "steps"),
        check=checks.All(
            checks.Equal("hit"), checks.Custom(close_with_inf("t", 1e-9)), checks.Allclose("steps", atol=1)
        ),
        part="sphere tracing",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-trace-budget",
        function="sphere_trace",
        inputs=_budget_rays,
        params={"max_steps": 6, "eps": 1e-4},
        outputs=("t", "hit", "steps"),
        check=checks.All(
            checks.Equal("hit"), checks.Custom(close_with_inf("t", 1e-9)), checks.Allclose("steps", atol=1)
        ),
        part="sphere tracing",
        points=1,
        visibility=H,
    ),
    # Task 9
    Case(
        id="hidden-soft-shadow-three",
        function="soft_shadow",
        inputs=_with(_surface_points("three", 250, 118), light_center=np.array([1.5, 1.0, 3.5]), light_radius=0.5),
        params={"max_steps": 48},
        outputs=("V",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=2,
        visibility=H,
    ),
    Case(
        id="hidden-soft-shadow-improved-three",
        function="soft_shadow",
        inputs=_with(_surface_points("three", 250, 119), light_center=np.array([-0.5, 1.0, 2.5]), light_radius=0.3),
        params={"improved": True},
        outputs=("V",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-ao-three",
        function="ambient_occlusion",
        inputs=_ao_inputs(200, 120, "three"),
        params={"taps": 4, "delta": 0.08},
        outputs=("AO",),
        check=checks.Allclose(atol=1e-10),
        part="soft shadows",
        points=1,
        visibility=H,
    ),
    Case(
        id="hidden-push-out-three",
        function="push_out",
        inputs=lambda: {"sdf": scene("three"), "P": np.random.default_rng(121).uniform(-1, 1, size=(120, 3))},
        params={"radius": 0.1, "iterations": 6},
        outputs=("P_out",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=1,
        visibility=H,
    ),
]
