"""Graded cases of the lab "sdf" (public): inputs from geomlib, NumPy and libigl only, never from the solution.

Tolerances: closed-form fields, distances and lookups to 1e-10 (a few float operations; 1e-9 for
mesh distances, whose closest-point arithmetic differs between correct implementations by
round-off); signs, hit masks and brick tables exactly; uint8 codes within one code (rounding of an
exact .5); step counts within one step (a sample within round-off of eps).
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks

from .support import (
    box_mesh,
    close_outputs,
    close_with_inf,
    closest_with_regions,
    random_bricks,
    random_points,
    scene,
    simple_bvh,
    sphere_grid,
    sphere_small,
    thin_prism,
    torus_small,
    wedge,
)

#: Seconds allowed for calls that run the numba kernels: the first call of a fresh submission
#: compiles them (10-30 s on a slow or busy machine); later calls load them from the cache.
KERNEL_TIMEOUT = 180.0

# hand-checkable points around the box centred at the origin with half sizes (1, 2, 3):
# centre (-1), inside near the x face (-0.5), on a face (0), outside a face (+1), an edge (sqrt 2),
# a corner (sqrt 3)
BOX_POINTS = np.array(
    [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.5, 0.5], [2.0, 0.0, 0.0], [2.0, 3.0, 0.0], [2.0, 3.0, 4.0]]
)

# one triangle and a point in each of its seven Voronoi regions
TRI = np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]])
TRI_POINTS = np.array(
    [
        [0.5, 0.5, 1.0],  # interior
        [-1.0, -1.0, 0.5],  # vertex a
        [3.0, -0.5, -0.2],  # vertex b
        [-0.5, 3.0, 0.3],  # vertex c
        [1.0, -1.0, 0.0],  # edge ab
        [1.5, 1.5, 0.7],  # edge bc
        [-1.0, 1.0, -0.4],  # edge ca
    ]
)


def _pts(n, seed, lo=-2.0, hi=2.0):
    return lambda: {"P": np.random.default_rng(seed).uniform(lo, hi, size=(n, 3))}


def _with(make, **extra):
    return lambda: {**make(), **extra}


def _mesh_points(mesh, n, seed):
    def make():
        V, F = mesh()
        return {"V": V, "F": F, "P": random_points(V, n, seed)}

    return make


def _sign_inputs(mesh, n, seed, near=False):
    """Points with their closest face, point and region from libigl (so Task 4 does not need Task 3)."""

    def make():
        V, F = mesh()
        P = random_points(V, n, seed, margin=0.05 if near else 0.3)
        face, C, region = closest_with_regions(V, F, P)
        return {"V": V, "F": F, "P": P, "face": face, "closest": C, "region": region}

    return make


def _pick(make, *names):
    return lambda: {k: v for k, v in make().items() if k in names}


def _bvh_inputs(mesh, n, seed):
    def make():
        V, F = mesh()
        return {"bvh": simple_bvh(V, F), "V": V, "F": F, "P": random_points(V, n, seed)}

    return make


def _grid_sample(n, m, seed):
    def make():
        values, origin, h = sphere_grid(n)
        P = np.random.default_rng(seed).uniform(-1.3, 1.3, size=(m, 3))  # inside and outside the box
        return {"values": values, "origin": origin, "spacing": h, "P": P}

    return make


def _bricks_sample(table_shape, n_stored, seed, m=400):
    def make():
        codes, table = random_bricks(table_shape, n_stored, seed)
        shape = 7 * np.array(table_shape) + 1 - np.array([0, 3, 5])  # last bricks partly used
        origin = np.array([-0.4, 0.1, 0.2])
        h = 0.05
        upper = origin + h * (shape - 1)
        P = np.random.default_rng(seed).uniform(origin - 0.2, upper + 0.2, size=(m, 3))
        return {
            "codes": codes,
            "table": table,
            "origin": origin,
            "spacing": h,
            "band_voxels": 3.0,
            "shape": shape,
            "P": P,
        }

    return make


def _rays(kind, n, seed):
    def make():
        rng = np.random.default_rng(seed)
        O = np.c_[rng.uniform(-1.5, 1.5, n), np.full(n, -4.0), rng.uniform(0.2, 2.0, n)]
        target = np.c_[rng.uniform(-1.0, 1.5, n), rng.uniform(-0.5, 0.8, n), rng.uniform(-0.2, 1.0, n)]
        return {"sdf": scene(kind), "origins": O, "directions": target - O}

    return make


def _surface_points(kind, n, seed, lift=1e-3):
    """Points on the ground plane (z = lift) of a scene, away from the spheres' insides."""

    def make():
        rng = np.random.default_rng(seed)
        P = np.c_[rng.uniform(-2, 2, n), rng.uniform(-1.4, 1.4, n), np.full(n, lift)]
        S = scene(kind)["spheres"]
        keep = np.all(np.linalg.norm(P[:, None, :] - S[None, :, :3], axis=2) > S[None, :, 3] + 0.01, axis=1)
        return {"sdf": scene(kind), "P": P[keep]}

    return make


def _ao_inputs(n, seed, kind="balls"):
    def make():
        d = _surface_points(kind, n, seed)()
        return {**d, "N": np.tile([0.0, 0.0, 1.0], (len(d["P"]), 1))}

    return make


CASES = [
    # ---------------------------------------------------------------- Task 1: analytic SDFs and CSG
    Case(
        id="box-hand",
        function="sd_box",
        inputs=lambda: {"P": BOX_POINTS, "center": np.zeros(3), "half_size": np.array([1.0, 2.0, 3.0])},
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=1,
        hint="expected -1, -0.5, 0, 1, sqrt(2), sqrt(3): q = |p - c| - b; |max(q, 0)| + min(max(q), 0)",
    ),
    Case(
        id="sphere",
        function="sd_sphere",
        inputs=_with(_pts(50, 1), center=np.array([0.2, -0.1, 0.3]), radius=0.8),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
    ),
    Case(
        id="plane",
        function="sd_plane",
        inputs=_with(_pts(50, 2), normal=np.array([1.0, 2.0, 2.0]), offset=0.5),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
        hint="normalise the normal first",
    ),
    Case(
        id="capsule",
        function="sd_capsule",
        inputs=_with(_pts(50, 3), a=np.array([-0.5, 0.0, 0.0]), b=np.array([0.5, 0.5, 0.0]), radius=0.3),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
    ),
    Case(
        id="torus",
        function="sd_torus",
        inputs=_with(_pts(50, 4), center=np.array([0.1, 0.0, -0.2]), major=1.0, minor=0.3),
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
    ),
    Case(
        id="csg-difference",
        function="op_difference",
        inputs=lambda: {"a": np.array([-1.0, -0.5, 0.2, 0.3]), "b": np.array([-0.2, 0.4, -0.1, 0.5])},
        outputs=("d",),
        check=checks.Allclose(atol=1e-12),
        part="analytic SDFs",
        points=0.5,
        hint="a minus b = max(a, -b)",
    ),
    # ---------------------------------------------------------------- Task 2: point-triangle distance
    Case(
        id="triangle-seven-regions",
        function="point_triangle_distance",
        inputs=lambda: {"P": TRI_POINTS, "T": TRI},
        outputs=("sq_dist", "closest", "region"),
        check=checks.All(checks.Equal("region"), checks.Allclose(("sq_dist", "closest"), atol=1e-12)),
        part="point-triangle distance",
        points=1,
        hint="regions in order: interior 0, vertices a b c = 1 2 3, edges ab bc ca = 4 5 6",
    ),
    Case(
        id="brute-force-sphere",
        function="brute_force_distance",
        inputs=_mesh_points(sphere_small, 60, 5),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist", "closest"), 1e-9)),
        part="point-triangle distance",
        points=1,
        hint="argmin of point_triangle_distance over the triangles",
    ),
    # ---------------------------------------------------------------- Task 3: BVH queries and the band
    Case(
        id="bvh-closest-torus",
        function="bvh_closest",
        timeout=KERNEL_TIMEOUT,
        inputs=_bvh_inputs(torus_small, 200, 6),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist", "closest"), 1e-9)),
        part="BVH",
        points=1,
        hint="skip a node when its box is at least the best squared distance away",
    ),
    Case(
        id="bvh-band-torus",
        function="bvh_closest",
        timeout=KERNEL_TIMEOUT,
        inputs=_with(_bvh_inputs(torus_small, 200, 7), band=0.15),
        outputs=("sq_dist", "face", "closest", "region"),
        check=checks.Custom(close_outputs(("sq_dist",), 1e-9)),
        part="BVH",
        points=1,
        hint="start the search with best = band^2; points with nothing closer keep sq_dist = band^2",
    ),
    Case(
        id="band-grid-sphere",
        function="grid_sdf_values",
        timeout=KERNEL_TIMEOUT,
        inputs=lambda: {
            "V": sphere_small()[0],
            "F": sphere_small()[1],
            "origin": np.full(3, -1.3),
            "spacing": 2.6 / 15,
            "shape": (16, 16, 16),
            "band": 2.0,
        },
        outputs=("values",),
        check=checks.Allclose(atol=1e-9),
        tasks=(3, 4),  # the signs come from Task 4
        part="BVH",
        points=1,
        hint="exact distances within r = band * spacing, +r outside and -r inside beyond it (uses Task 4's sign)",
    ),
    # ---------------------------------------------------------------- Task 4: signs
    Case(
        id="pseudonormals-wedge",
        function="pseudonormals",
        inputs=lambda: dict(zip(("V", "F"), wedge(), strict=True)),
        outputs=("face_n", "edge_n", "vertex_n"),
        check=checks.Allclose(atol=1e-10),
        part="sign",
        points=1,
        hint="edge normal = sum of the unit normals of the faces on that edge; vertex = sum of angle * unit normal",
    ),
    Case(
        id="normal-sign-prism",
        function="sign_normal",
        inputs=_pick(_sign_inputs(thin_prism, 300, 8), "V", "F", "P", "face", "closest"),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=0.5,
    ),
    Case(
        id="pseudonormal-sign-prism",
        function="sign_pseudonormal",
        inputs=_sign_inputs(thin_prism, 300, 8),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=1,
    ),
    Case(
        id="vote-torus",
        function="sign_vote",
        timeout=KERNEL_TIMEOUT,
        inputs=_pick(_mesh_points(torus_small, 200, 9), "V", "F", "P"),
        outputs=("s",),
        check=checks.Equal("s"),
        part="sign",
        points=1,
        hint="odd crossing count = inside for one ray; majority over the rays",
    ),
    Case(
        id="winding-box",
        function="winding_number",
        inputs=_pick(_mesh_points(box_mesh, 100, 10), "V", "F", "P"),
        outputs=("w",),
        check=checks.Allclose(atol=1e-9),
        part="sign",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 5: bricks
    Case(
        id="bricks-sphere-22",
        function="encode_bricks",
        inputs=lambda: dict(zip(("values", "spacing"), sphere_grid(22)[::2], strict=True)),
        params={"band_voxels": 2.0},
        outputs=("codes", "table"),
        check=checks.All(checks.Equal("table"), checks.Allclose("codes", atol=1.0)),
        part="bricks",
        points=1,
        hint="22 samples = 3 bricks of 7 cells + 1 apron sample; codes = rint((clamp(d) + r) / 2r * 255)",
    ),
    # ---------------------------------------------------------------- Task 6: queries
    Case(
        id="trilinear-sphere-9",
        function="trilinear",
        inputs=_grid_sample(9, 300, 11),
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=1,
        hint="outside the box: outside_rule(P, clamp(P), value at the clamped point)",
    ),
    Case(
        id="bricks-lookup-2x2x3",
        function="brick_sample",
        inputs=_bricks_sample((2, 2, 3), 5, 12),
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=1,
        hint="brick = min(floor(u / 7), n - 1); cell inside it = min(floor(u - 7 brick), 6)",
    ),
    Case(
        id="instances-balls",
        function="instances_distance",
        inputs=lambda: {
            "sdf": {"spheres": np.array([[0.0, 0.0, 0.0, 0.5]]), "planes": np.zeros((0, 4))},
            "P": np.random.default_rng(13).uniform(-3, 3, size=(100, 3)),
            "translations": np.array([[1.0, 0.0, 0.0], [-1.0, 0.5, 0.0]]),
            "scales": np.array([2.0, 0.5]),
        },
        outputs=("d",),
        check=checks.Allclose(atol=1e-10),
        part="queries",
        points=1,
        hint="s * phi((p - t) / s), then the min over instances",
    ),
    # ---------------------------------------------------------------- Task 7: gradients
    Case(
        id="gradient-6tap",
        function="gradient_central",
        inputs=lambda: {"sdf": scene("balls"), "P": np.random.default_rng(14).uniform(-1, 1.5, size=(100, 3))},
        params={"h": 1e-3},
        outputs=("N",),
        check=checks.Allclose(atol=1e-9),
        part="gradients",
        points=1,
    ),
    Case(
        id="gradient-4tap",
        function="gradient_tetra",
        inputs=lambda: {"sdf": scene("balls"), "P": np.random.default_rng(15).uniform(-1, 1.5, size=(100, 3))},
        params={"h": 1e-3},
        outputs=("N",),
        check=checks.Allclose(atol=1e-9),
        part="gradients",
        points=1,
    ),
    # ---------------------------------------------------------------- Task 8: sphere tracing
    Case(
        id="trace-balls",
        function="sphere_trace",
        inputs=_rays("balls", 200, 16),
        params={"max_steps": 64, "eps": 1e-4, "t_max": 12.0},
        outputs=("t", "hit", "steps"),
        check=checks.All(
            checks.Equal("hit"), checks.Custom(close_with_inf("t", 1e-9)), checks.Allclose("steps", atol=1)
        ),
        part="sphere tracing",
        points=1,
        hint="t += max(d, eps) until d < eps (hit) or t > t_max (miss); misses get t = inf",
    ),
    # ---------------------------------------------------------------- Task 9: soft shadows, AO, push-out
    Case(
        id="soft-shadow-balls",
        function="soft_shadow",
        inputs=_with(_surface_points("balls", 200, 17), light_center=np.array([0.8, -0.4, 4.0]), light_radius=0.6),
        outputs=("V",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=1,
        hint="V = min over the march of d / (t tan(alpha)), tan(alpha) = R / sqrt(D^2 - R^2), clamped to [0, 1]",
    ),
    Case(
        id="soft-shadow-improved-balls",
        function="soft_shadow",
        inputs=_with(_surface_points("balls", 200, 18), light_center=np.array([-1.0, 0.5, 3.0]), light_radius=0.4),
        params={"improved": True},
        outputs=("V",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=1,
    ),
    Case(
        id="ao-balls",
        function="ambient_occlusion",
        inputs=_ao_inputs(150, 19),
        outputs=("AO",),
        check=checks.Allclose(atol=1e-10),
        part="soft shadows",
        points=0.5,
    ),
    Case(
        id="push-out-balls",
        function="push_out",
        inputs=lambda: {"sdf": scene("balls"), "P": np.random.default_rng(20).uniform(-0.6, 0.6, size=(80, 3))},
        params={"radius": 0.05, "iterations": 4},
        outputs=("P_out",),
        check=checks.Allclose(atol=1e-9),
        part="soft shadows",
        points=0.5,
    ),
]
