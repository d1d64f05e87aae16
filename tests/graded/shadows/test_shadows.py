"""Graded tests of the lab "shadows": hand-checked cases, identities and properties, bad input.

Every expected value here is worked out by hand (in the comments) or measured against exact
ray-cast shadows (geomlib.geometry.ray_cast), never taken from the reference solution.
"""

from __future__ import annotations

import numpy as np

from geomlib import camera, datasets
from geomlib.geometry import ray_cast
from geomlib.grading import expect_close, graded, reference_tests
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import marked_picture
from geomlib.raster import rasterize

from ..common import expect_rejected
from .cases import CASES, LIGHT_DIR
from .support import CAMERA, SCENE_BOUNDS, ortho_light, scene_meshes, small_scene

test_references = reference_tests(CASES)

UNIT = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def square(z: float) -> np.ndarray:
    """The unit square at height z, counter-clockwise seen from +z (faces up)."""
    return np.array([[0.0, 0, z], [1, 0, z], [1, 1, z], [0, 1, z]])


def corners(B) -> np.ndarray:
    B = np.asarray(B, float)
    return np.array(np.meshgrid(*B.T, indexing="ij")).reshape(3, -1).T


def fail(msg: str, picture: str | None = None):
    raise Mismatch(msg, picture)


# ------------------------------------------------------------------------------------------ Task 1


@graded(points=1, part="light matrix")
def test_directional_fit_is_tight(lab):
    """the box's corners land inside the NDC cube and touch all six faces"""
    B = np.array([[-3.0, -2.0, 0.0], [3.0, 2.5, 2.0]])
    M = np.asarray(lab.directional_light_matrix((0.45, 0.55, -0.7), B))
    C = np.c_[corners(B), np.ones(8)] @ M.T
    ndc = C[:, :3] / C[:, 3:]
    expect_close("min over the 8 corners of (x, y, z)_ndc", ndc.min(axis=0), [-1, -1, -1], atol=1e-9,
                 hint="fit the orthographic box to the corners' eye-space extents: l, r, b, t and near = -z_max, far = -z_min")  # fmt: skip
    expect_close("max over the 8 corners of (x, y, z)_ndc", ndc.max(axis=0), [1, 1, 1], atol=1e-9)
    expect_close("clip w (orthographic: always 1)", C[:, 3], np.ones(8), atol=1e-12)


@graded(points=1, part="light matrix")
def test_straight_down_by_hand(lab):
    """light straight down on [0,1]^3: depth is 1 - z, the top face is at depth 0"""
    M = np.asarray(lab.directional_light_matrix((0, 0, -1), UNIT))
    P = np.array([[0.5, 0.5, 1.0], [0.5, 0.5, 0.0], [0.2, 0.7, 0.25]])
    C = np.c_[P, np.ones(3)] @ M.T
    depth = (C[:, 2] / C[:, 3] + 1) / 2
    expect_close("window depth of z = 1, 0, 0.25", depth, [0.0, 1.0, 0.75], atol=1e-9,
                 hint="the light looks along its direction; the nearest corner is at depth 0")  # fmt: skip


@graded(points=1, part="light matrix")
def test_spot_target_in_the_centre(lab):
    """a spot light sees its target in the middle of its map, and near/far at depths 0 and 1"""
    pos, tgt = np.array([1.0, -2.0, 4.0]), np.array([0.5, 0.5, 0.0])
    M = np.asarray(lab.spot_light_matrix(pos, tgt, 60.0, 1.0, 9.0))
    d = (tgt - pos) / np.linalg.norm(tgt - pos)
    P = np.array([tgt, pos + 1.0 * d, pos + 9.0 * d])
    C = np.c_[P, np.ones(3)] @ M.T
    uvz = (C[:, :3] / C[:, 3:] + 1) / 2
    expect_close("(u, v) of the target", uvz[0, :2], [0.5, 0.5], atol=1e-9)
    expect_close("depth at distance near and far along the axis", uvz[1:, 2], [0.0, 1.0], atol=1e-9)


# ------------------------------------------------------------------------------------------ Task 2


@graded(points=1, part="depth pass")
def test_depth_of_a_square_by_hand(lab):
    """a square at z = 0.25 under a light straight down fills the map with depth 0.75"""
    M = ortho_light((0, 0, -1), UNIT, up=np.array([0.0, 1.0, 0.0]))  # made here with geomlib.camera
    # This ortho box is the cube around the bounding sphere of [0,1]^3: radius R = sqrt(3)/2, depth range 2R
    # from z = 0.5 + R (depth 0) down to z = 0.5 - R (depth 1): depth(z) = (0.5 + R - z) / (2R).
    R = np.sqrt(3) / 2
    D = np.asarray(lab.depth_map(square(0.25), SQUARE_F, M, 16, cull="none"))
    if D.shape != (16, 16):
        fail(f"depth_map returned shape {D.shape}, expected (16, 16)")
    # The square covers the texels whose centres fall inside it: x, y in [0, 1] out of [0.5 - R, 0.5 + R].
    inside = D < 1.0
    expect_close("depth of the covered texels", D[inside], np.full(inside.sum(), (0.5 + R - 0.25) / (2 * R)), atol=1e-9)
    expect_close("number of covered texels (the square spans 1/(2R) of the map per side)", inside.sum(), 100, atol=0,
                 hint="empty texels must be 1.0, the far plane")  # fmt: skip


@graded(points=1, part="depth pass")
def test_empty_map_is_the_far_plane(lab):
    """texels that see nothing hold 1.0 (not inf)"""
    M = ortho_light((0, 0, -1), [[5, 5, 5], [6, 6, 6]], up=np.array([0.0, 1.0, 0.0]))
    D = np.asarray(lab.depth_map(square(0.25), SQUARE_F, M, 8, cull="none"))
    expect_close(
        "a map that sees nothing", D, np.ones((8, 8)), atol=0, hint="rasterize marks empty pixels with inf; store 1.0"
    )
    # Beside a covered area too: the square of test_depth_of_a_square_by_hand covers 100 of 256 texels
    # at depth (0.5 + R - 0.25) / (2R); the other 156 hold exactly 1.0.
    R = np.sqrt(3) / 2
    M = ortho_light((0, 0, -1), UNIT, up=np.array([0.0, 1.0, 0.0]))
    D = np.asarray(lab.depth_map(square(0.25), SQUARE_F, M, 16, cull="none"))
    expect_close("number of texels at 1.0 beside the square", (D == 1.0).sum(), 156, atol=0,
                 hint="texels no triangle covers hold 1.0; covered ones hold the triangle's depth")  # fmt: skip
    expect_close("the covered texels' depth", D[D < 1.0], np.full(100, (0.5 + R - 0.25) / (2 * R)), atol=1e-9)


# ------------------------------------------------------------------------------------------ Task 3


@graded(points=1, part="comparison")
def test_compare_on_a_2x2_map_by_hand(lab):
    """2x2 map: row 0 is the top (v > 0.5); lit when z - bias <= D"""
    D = np.array([[0.2, 0.9], [0.5, 0.7]])
    uvz = np.array([[0.25, 0.75, 0.2], [0.25, 0.75, 0.21], [0.75, 0.25, 0.7], [0.75, 0.25, 0.71], [0.25, 0.25, 0.4]])
    expect_close("compare_depth without bias", lab.compare_depth(D, uvz), [1, 0, 1, 0, 1], atol=0,
                 hint="col = floor(u size), row = size - 1 - floor(v size); a point exactly at the stored depth is lit")  # fmt: skip
    expect_close("compare_depth with bias 0.02", lab.compare_depth(D, uvz, 0.02), [1, 1, 1, 1, 1], atol=0)


@graded(points=1, part="comparison")
def test_compare_clamps_to_the_border(lab):
    """u = 1 and v = 0 read the last column and the bottom row; beyond the map reads the border"""
    D = np.array([[0.1, 0.2], [0.3, 0.4]])
    uvz = np.array([[1.0, 0.0, 0.45], [1.0, 0.0, 0.35], [-3.0, 5.0, 0.15], [-3.0, 5.0, 0.05]])
    expect_close("compare_depth at and beyond the border", lab.compare_depth(D, uvz), [0, 1, 0, 1], atol=0,
                 hint="clamp row and col to 0 .. size - 1")  # fmt: skip


@graded(points=1, part="comparison")
def test_uvz_behind_a_spot_light_is_nan(lab):
    """points behind a perspective light have no map coordinates (NaN)"""
    from .support import spot_light

    M = spot_light(position=(0, 0, 5), target=(0, 0, 0), fov=60, near=1, far=10)
    uvz = np.asarray(lab.light_uvz([[0.0, 0.0, 0.0], [0.0, 0.0, 8.0], [1.0, 0.0, 5.0]], M))
    # target at distance 5, near 1, far 10: z_ndc = (f + n) / (f - n) - 2 f n / ((f - n) 5) = 11/9 - 4/9 = 7/9,
    # window depth (7/9 + 1) / 2 = 8/9.
    expect_close("uvz of the target", uvz[0], [0.5, 0.5, 8 / 9], atol=1e-9)
    if not np.all(np.isnan(uvz[1:])):
        fail(f"light_uvz: points behind the light (w <= 0) should give NaN rows, got {uvz[1:].tolist()}")


# ------------------------------------------------------------------------------------------ Task 4


@graded(points=1, part="bias")
def test_gradient_of_a_tilted_plane_by_hand(lab):
    """plane z = 0.5 + 0.25 (x - 0.5) under a light straight down: depth falls 0.0025 per texel of u"""
    # With up = +y (given here) u runs along +x and v along +y. The ortho box is a cube of side 2R = sqrt(3),
    # so one texel of 100 is 2R/100 in x, where the plane rises 0.25 * 2R/100 in z; depth = (0.5 + R - z) / (2R)
    # then falls by 0.25/100 = 0.0025 per texel of u, and does not change along v.
    M = ortho_light((0, 0, -1), UNIT, up=np.array([0.0, 1.0, 0.0]))
    g = lab.receiver_depth_gradient([[0.5, 0.5, 0.5]], [[-0.25, 0.0, 1.0]], M, 100)
    expect_close("receiver_depth_gradient of the tilted plane", g, [[-0.0025, 0.0]], atol=1e-12,
                 hint="the plane (N, -N.P) maps to (a, b, c, d) = M^{-T} (N, -N.P); g = -(a, b) / (c size)")  # fmt: skip


@graded(points=1, part="bias")
def test_gradient_is_zero_facing_the_light(lab):
    """a plane facing the light head-on has no slope; an edge-on plane is clamped to max_slope / size"""
    M = ortho_light((0, 0, -1), UNIT, up=np.array([0.0, 1.0, 0.0]))
    g = lab.receiver_depth_gradient(
        [[0.3, 0.6, 0.2], [0.5, 0.5, 0.5]], [[0.0, 0.0, 2.0], [0.0, 1.0, 0.0]], M, 64, max_slope=4.0
    )
    expect_close(
        "gradient of a plane facing the light, and of an edge-on plane", np.abs(g), [[0, 0], [0, 4.0 / 64]], atol=1e-12
    )


@graded(points=1, part="bias")
def test_no_acne_with_default_bias(lab):
    """a tilted square lit at a slant does not shadow itself with the default bias (and does without)"""
    V = square(0.0) @ np.array([[1.0, 0, 0], [0, 1, 0], [0.3, 0.1, 1]]).T + np.array(
        [0, 0, 0.4]
    )  # z = 0.4 + 0.3 x + 0.1 y
    B = np.array([V.min(0) - 0.01, V.max(0) + 0.01])
    M = ortho_light((0.5, 0.2, -0.8), B)
    D = np.asarray(lab.depth_map(V, SQUARE_F, M, 64, cull="none"))
    rng = np.random.default_rng(0)
    b = rng.dirichlet(np.ones(3), 500)
    P = np.einsum("ki,kij->kj", b, V[SQUARE_F[rng.integers(0, 2, 500)]])
    N = np.tile(np.cross(V[1] - V[0], V[2] - V[0]), (500, 1))
    # frustum_fix=False: every point is inside the light's box, and Task 6 (outside_frustum) is not needed yet.
    vis = np.asarray(lab.shadow_visibility(P, N, D, M, bias=None, slope_bias=None, pcf=1, frustum_fix=False))
    raw = np.asarray(lab.shadow_visibility(P, N, D, M, bias=0.0, slope_bias=0.0, pcf=1, frustum_fix=False))
    if not (raw < 0.5).mean() > 0.2:
        fail("without bias about half of the slanted square should shadow itself (acne); check compare_depth")
    if (vis < 0.5).any():
        fail(f"with the default bias {int((vis < 0.5).sum())} of 500 points on a lit plane are shadowed (acne); "
             "the slope term must cover half a texel in u and in v: b = bias + slope_bias (|g_u| + |g_v|) / 2",
             marked_picture("shadow_visibility on a lit plane", V, SQUARE_F, P[vis < 0.5], "points shadowed (acne)"))  # fmt: skip
    # The slope term alone (bias = 0) covers every plane with its own gradient: a second square beside
    # the first, tilted the other way and much more steeply (z = 0.4 - 1.2 x), in the same map.
    # slope_bias = 1.5 is 1.5x the largest depth change within a texel, so no point may be shadowed.
    V2 = square(0.0) @ np.array([[1.0, 0, 0], [0, 1, 0], [-1.2, 0.0, 1]]).T + np.array([0.0, -2.0, 0.4])
    VV, FF = np.vstack([V, V2]), np.vstack([SQUARE_F, SQUARE_F + 4])
    B = np.array([VV.min(0) - 0.01, VV.max(0) + 0.01])
    M = ortho_light((0.5, 0.2, -0.8), B)
    D = np.asarray(lab.depth_map(VV, FF, M, 64, cull="none"))
    P = np.einsum("ki,kij->kj", rng.dirichlet(np.ones(3), 1000), VV[FF[rng.integers(0, 4, 1000)]])
    N = np.where((P[:, 1] > -0.5)[:, None], np.cross(V[1] - V[0], V[2] - V[0]), np.cross(V2[1] - V2[0], V2[2] - V2[0]))
    vis = np.asarray(lab.shadow_visibility(P, N, D, M, bias=0.0, slope_bias=None, pcf=1, frustum_fix=False))
    if (vis < 0.5).any():
        fail(f"with bias = 0 and the default slope_bias, {int((vis < 0.5).sum())} of 1000 points on two lit planes "
             "of different tilts are shadowed (acne): each point needs the gradient of its own plane "
             "(receiver_depth_gradient) and b = slope_bias (|g_u| + |g_v|) / 2",
             marked_picture("shadow_visibility, bias 0", VV, FF, P[vis < 0.5], "points shadowed (acne)"))  # fmt: skip


# ------------------------------------------------------------------------------------------ Task 5


@graded(points=1, part="culling")
def test_cull_one_triangle(lab):
    """a triangle facing the light is dropped by cull='front' and kept, unchanged, by cull='back'"""
    V = square(0.5)
    M = ortho_light((0, 0, -1), UNIT)
    front = np.asarray(lab.cull_faces(V, SQUARE_F[:1], M, "front")).reshape(-1, 3)
    back = np.asarray(lab.cull_faces(V, SQUARE_F[:1], M, "back")).reshape(-1, 3)
    if len(front) != 0 or len(back) != 1:
        fail(f"the square faces the light (counter-clockwise seen from it): cull='front' kept {len(front)} faces "
             f"(expected 0), cull='back' kept {len(back)} (expected 1). Front-facing <=> det([x, y, w] of the corners) > 0")  # fmt: skip
    if back.tolist() != np.asarray(SQUARE_F[:1]).tolist():
        fail(f"cull='back' kept the face {back.tolist()}, expected the input's own face {np.asarray(SQUARE_F[:1]).tolist()} "
             "(culling returns the rows of F it keeps, unchanged)")  # fmt: skip


@graded(points=1, part="culling")
def test_culling_splits_a_closed_mesh(lab):
    """on a sphere, front and back faces split the mesh in two halves, each face in exactly one"""
    V, F = datasets.icosphere(2)
    M = ortho_light((0.3, -0.4, -1.0), [V.min(0), V.max(0)])
    a = {tuple(f) for f in np.asarray(lab.cull_faces(V, F, M, "front")).tolist()}
    b = {tuple(f) for f in np.asarray(lab.cull_faces(V, F, M, "back")).tolist()}
    if a & b or len(a) + len(b) != len(F):
        fail(f"cull='front' kept {len(a)} and cull='back' kept {len(b)} of {len(F)} faces, {len(a & b)} in both; "
             "expected each face in exactly one (no face of this sphere is seen edge-on)")  # fmt: skip
    if not 0.4 < len(a) / len(F) < 0.6:
        fail(f"cull='front' kept {len(a)} of {len(F)} faces; about half should face away from the light")


# ------------------------------------------------------------------------------------------ Task 6


@graded(points=1, part="frustum handling")
def test_outside_by_hand(lab):
    """outside: u, v outside [0, 1] or z > 1; z < 0 and the border itself are inside"""
    uvz = [[0.5, 0.5, 0.5], [-0.01, 0.5, 0.5], [0.5, 1.01, 0.5], [0.5, 0.5, 1.01], [0.5, 0.5, -0.5], [1, 0, 1]]
    got = np.asarray(lab.outside_frustum(uvz))
    expect_close("outside_frustum", got.astype(float), [0, 1, 1, 1, 0, 0], atol=0)


@graded(points=1, part="frustum handling")
def test_outside_the_map_is_lit(lab):
    """with a map that covers only part of the floor, floor points beside it and beyond it are lit (uses Task 3 too)"""
    from .cases import M_PARTIAL as M
    from .cases import stored

    D = stored("depth-partial-64")["D"]  # the solution's depth pass (Task 2), stored by `geomlib refs build`
    P = np.array([[2.8, 2.8, 0.0], [-2.9, 2.5, 0.0], [2.9, -2.9, 0.0]])
    vis = np.asarray(lab.shadow_visibility(P, np.tile([0.0, 0, 1], (3, 1)), D, M, bias=0.01, slope_bias=0.0, pcf=1))
    expect_close("visibility of floor points outside the light's frustum", vis, [1, 1, 1], atol=0,
                 hint="outside_frustum must be True for them, and shadow_visibility then leaves them lit")  # fmt: skip
    # Inside the map nothing changes: floor points that ray casting finds in shadow stay dark.
    V, F = small_scene()
    g = np.linspace(-1.4, 1.4, 29)
    P = np.c_[np.array(np.meshgrid(g, g)).reshape(2, -1).T, np.zeros(29 * 29)]
    L = -LIGHT_DIR / np.linalg.norm(LIGHT_DIR)
    truth = _truth(V, F, P, np.tile(L, (len(P), 1)), None)
    vis = np.asarray(
        lab.shadow_visibility(P, np.tile([0.0, 0, 1], (len(P), 1)), D, M, bias=0.01, slope_bias=0.0, pcf=1)
    )
    dark = ~truth
    if dark.sum() < 20 or np.mean(vis[dark] < 0.5) < 0.9:
        fail(
            f"of {int(dark.sum())} floor points inside the map that ray casting finds in shadow, only "
            f"{int((vis[dark] < 0.5).sum())} are dark: outside_frustum must be False inside [0, 1]^2 with z <= 1"
        )


# ------------------------------------------------------------------------------------------ Task 7


@graded(points=1, part="PCF")
def test_pcf_by_hand(lab):
    """a 4x4 map with an occluder on its left half: 3x3 PCF gives 1/3, 2/3, 1 across the edge"""
    D = np.ones((4, 4))
    D[:, :2] = 0.3
    uvz = [[0.375, 0.5, 0.5], [0.625, 0.5, 0.5], [0.875, 0.5, 0.5]]
    expect_close("pcf_visibility, k = 3", lab.pcf_visibility(D, uvz, 0.0, 3), [1 / 3, 2 / 3, 1.0], atol=1e-12,
                 hint="average the 0/1 tests of the k x k texels around the point's own, clamping at the border")  # fmt: skip


@graded(points=1, part="PCF")
def test_pcf_up_is_up(lab):
    """offset j counts texels up the map (towards row 0), as v does"""
    D = np.ones((5, 5))
    D[0, :] = 0.2  # an occluder in the TOP row only
    uvz = [[0.5, 0.7, 0.5]]  # texel (row 1, col 2): its upper neighbours are row 0
    # and a second point at the bottom (row 4, col 2): its block (rows 3-5 clamped to 4) sees no occluder
    expect_close("pcf_visibility just below the occluded top row, and at the bottom row",
                 lab.pcf_visibility(D, [*uvz, [0.5, 0.1, 0.5]], 0.0, 3), [2 / 3, 1.0], atol=1e-12)  # fmt: skip
    # With a gradient, depth grows 0.1 per texel up: row 0 compares 0.6 <= 0.65 (lit), row 1 0.5 <= 0.55,
    # row 2 0.4 <= 0.55: all lit. The wrong sign or the wrong row direction darkens a row (2/3).
    D2 = np.full((5, 5), 0.55)
    D2[0, :] = 0.65
    expect_close("pcf_visibility with gradient (0, 0.1): neighbour j compares z + g_v j with the row j texels UP",
                 lab.pcf_visibility(D2, uvz, 0.0, 3, gradient=[[0.0, 0.1]]), [1.0], atol=1e-12)  # fmt: skip


@graded(points=1, part="PCF")
def test_pcf_1_is_the_plain_comparison(lab):
    """pcf = 1 gives exactly compare_depth"""
    rng = np.random.default_rng(4)
    D = rng.uniform(0, 1, (16, 16))
    uvz = rng.uniform(0, 1, (300, 3))
    a = np.asarray(lab.pcf_visibility(D, uvz, 0.01, 1))
    b = np.asarray(lab.compare_depth(D, uvz, 0.01))
    expect_close("pcf_visibility(k=1) against compare_depth", a, b, atol=0)


# ------------------------------------------------------------------------------------------ Task 8


@graded(points=1, part="cube map")
def test_cube_faces_look_along_the_axes(lab):
    """each face's camera sees its own axis direction in the middle of its map"""
    pos = np.array([0.3, -0.2, 1.0])
    Ms = np.asarray(lab.cube_light_matrices(pos, 0.1, 10.0))
    if Ms.shape != (6, 4, 4):
        fail(f"cube_light_matrices returned shape {Ms.shape}, expected (6, 4, 4)")
    axes = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    for i in range(6):
        C = Ms[i] @ np.r_[pos + 2 * axes[i], 1.0]
        expect_close(f"(u, v) of the direction {axes[i]} in face {i}", (C[:2] / C[3] + 1) / 2, [0.5, 0.5], atol=1e-9)


@graded(points=1, part="cube map")
def test_cube_face_index_by_hand(lab):
    """the face is the axis of the largest |component| and its sign: +x, -x, +y, -y, +z, -z"""
    d = [[2, 1, -1], [-3, 1, 2], [0.1, 0.5, 0.2], [0, -1, 0.5], [1, 1, 1.5], [0.2, -0.3, -0.9]]
    expect_close("cube_face_index", lab.cube_face_index(d), [0, 1, 2, 3, 4, 5], atol=0)
    # The docstring's rules for the edge cases: ties go to the first axis, the zero direction to face 0 (+x).
    ties = [[1, -1, 0], [0, -2, 2], [-1, 1, 1], [0, 0, 0]]
    expect_close("cube_face_index on ties and the zero direction", lab.cube_face_index(ties), [0, 3, 1, 0], atol=0,
                 hint="a = argmax |d_i| (the first axis on ties); face = 2 a + (d_a < 0), so 0 counts as +")  # fmt: skip


# ------------------------------------------------------------------------------------------ all together


def _truth(V, F, P, to_light, N):
    eps = 1e-6 * np.linalg.norm(V.max(0) - V.min(0))
    hit, _, _, _ = ray_cast(V, F, P, to_light, t_min=eps)
    return ~hit


@graded(points=2, part="all together")
def test_agrees_with_ray_casting(lab):
    """shadows of the small scene agree with exact ray casting on >= 99% of surface points, also with a map that
    covers only the objects (the floor outside it is lit)"""
    V, F = small_scene()
    d = np.array([0.4, 0.5, -0.75])
    M = np.asarray(lab.directional_light_matrix(d, [V.min(0), V.max(0)]))
    for cull in ("front", "none"):  # without culling, the default bias alone must keep the lit faces lit
        _agree_with_ray_casting(lab, V, F, d, M, np.asarray(lab.depth_map(V, F, M, 1024, cull=cull)), cull)
    # A map fitted to a box around the objects and their shadows only: the floor beside it and beyond its far
    # plane lies outside the map, where ray casting finds it lit (about 4% of a grid over the floor is beyond
    # the far plane), and shadow_visibility must leave it lit (Task 6).
    B = np.array([[-1.55, -1.15, 0.0], [2.1, 2.2, 1.95]])
    M = np.asarray(lab.directional_light_matrix(d, B))
    D = np.asarray(lab.depth_map(V, F, M, 1024, cull="none"))
    g = np.linspace(-2.9, 2.9, 41)
    P = np.c_[np.array(np.meshgrid(g, g)).reshape(2, -1).T, np.zeros(41 * 41)]
    N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
    truth = _truth(V, F, P, np.tile(-d / np.linalg.norm(d), (len(P), 1)), N)
    vis = np.asarray(lab.shadow_visibility(P, N, D, M))
    agree = np.mean((vis >= 0.5) == truth)
    if agree < 0.99:
        wrong = P[(vis >= 0.5) != truth]
        fail(f"with a map fitted to the box {B.tolist()} (the floor around it is outside the map), shadow_visibility "
             f"agrees with ray casting on {100 * agree:.2f}% of {len(P)} floor points (need >= 99%): points outside "
             "the light's frustum must count as lit (outside_frustum)",
             marked_picture("shadow_visibility vs ray casting, partial map", V, F, wrong, "points where the two disagree"))  # fmt: skip


def _agree_with_ray_casting(lab, V, F, d, M, D, cull):
    rng = np.random.default_rng(5)
    f = rng.integers(0, len(F), 4000)
    b = rng.dirichlet(np.ones(3), 4000)
    P = np.einsum("ki,kij->kj", b, V[F[f]])
    N = np.cross(V[F[f, 1]] - V[F[f, 0]], V[F[f, 2]] - V[F[f, 0]])
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    L = -d / np.linalg.norm(d)
    lit_side = N @ L > 0.05  # points turned away from the light are dark anyway
    P, N = P[lit_side], N[lit_side]
    truth = _truth(V, F, P, np.tile(L, (len(P), 1)), N)
    vis = np.asarray(lab.shadow_visibility(P, N, D, M))
    agree = np.mean((vis >= 0.5) == truth)
    acne = np.mean(vis[truth] < 0.5)
    if agree < 0.99 or acne > 0.005:
        wrong = P[(vis >= 0.5) != truth]
        fail(f"with a map made with cull={cull!r}, "
             f"shadow_visibility agrees with ray casting on {100 * agree:.2f}% of {len(P)} points (need >= 99%) "
             f"and shades {100 * acne:.2f}% of truly lit points dark (acne, allowed 0.5%)",
             marked_picture("shadow_visibility vs ray casting", V, F, wrong, "points where the two disagree"))  # fmt: skip


@graded(points=1, part="all together")
def test_render_is_an_image(lab):
    """render_with_shadows returns an (h, w, 3) image in [0, 1] with shadows on the floor, none where nothing
    stands between the light and the surface, and no acne on steep faces with the slope-scaled bias alone"""
    img, vis = lab.render_with_shadows(scene_meshes(), CAMERA, (0.4, 0.5, -0.75), size=(80, 60), map_size=256,
                                       return_visibility=True)  # fmt: skip
    img, vis = np.asarray(img), np.asarray(vis)
    if img.shape != (60, 80, 3) or not (0 <= img.min() and img.max() <= 1):
        fail(f"render_with_shadows returned shape {img.shape} with values in [{img.min():.3g}, {img.max():.3g}]")
    covered = np.isfinite(vis)
    if not 0.02 < np.mean(vis[covered] < 0.5) < 0.5:
        fail(f"{100 * np.mean(vis[covered] < 0.5):.1f}% of the scene is in shadow; expected a few percent to a third")
    # A scene where nothing casts a shadow on anything seen, built so that the bias and the frustum matter: a
    # low light grazes the floor (slope-scaled bias needed), a large panel facing the light beside it keeps
    # most pixels' slopes small (one bias for all is too small for the floor), its shadow falls beyond the
    # floor, and the map's box covers only the middle of the floor (the rest is outside the map: lit).
    d = np.array([-0.9, 0.3, -0.25])
    n = -d / np.linalg.norm(d)
    across = np.cross([0.0, 0.0, 1.0], n) / np.linalg.norm(np.cross([0.0, 0.0, 1.0], n))
    G, GF = datasets.grid_patch(4, 2.4)
    G = G - np.array([1.2, 1.2, 0.0])
    panel = np.array([-2.6, 0.0, 1.4]) + G[:, :1] * across + G[:, 1:2] * np.cross(n, across)
    V, F = datasets.grid_patch(4, 6.0)
    scene = [(V - np.array([3.0, 3.0, 0.0]), F, (0.8, 0.8, 0.8)), (panel, GF, (0.8, 0.5, 0.3))]
    _, vis = lab.render_with_shadows(scene, CAMERA, d, size=(80, 60), map_size=256, return_visibility=True,
                                     bounds=[[-1.5, -1.5, 0.0], [1.5, 1.5, 2.6]])  # fmt: skip
    vis = np.asarray(vis, float)
    dark = np.mean(vis[np.isfinite(vis)] < 0.999)
    if not dark <= 0.005:
        fail(f"render_with_shadows of a floor under a low light beside a panel, nothing in between: "
             f"{100 * dark:.1f}% of the visible points are not fully lit (allowed 0.5%); expected all lit: check the "
             "slope-scaled bias per point (receiver_depth_gradient, shadow_bias) and that points outside the map's "
             "box count as lit (outside_frustum)")  # fmt: skip
    # The small scene under a steep light with the slope term alone (bias 0): the boxes' sides are much steeper to
    # the light than the floor, so each point needs the bias of its own plane (one bias for all leaves acne on the
    # sides). The eye's pixels are rasterized here with geomlib and their shadows found by exact ray casting.
    d = np.array([2.5, 1.5, -6.5])
    _, vis = lab.render_with_shadows(scene_meshes(), CAMERA, d, size=(80, 60), map_size=256, bias=0.0,
                                     bounds=[[-1.5, -1.5, 0.0], [1.5, 1.5, 1.9]], return_visibility=True)  # fmt: skip
    vis = np.asarray(vis, float)
    V, F = small_scene()
    eye, target, up = CAMERA
    g = rasterize(V, F, camera.perspective_look_at(eye, target, up, 40.0, 80 / 60, 1.0, 20.0), 80, 60,
                  attributes={"position": V})  # fmt: skip
    seen = g.mask & np.isfinite(vis) if vis.shape == g.mask.shape else g.mask
    if vis.shape != g.mask.shape or seen.sum() < 0.9 * g.mask.sum():
        fail(f"render_with_shadows(..., return_visibility=True) gave visibility of shape {vis.shape} covering "
             f"{int(np.isfinite(vis).sum())} pixels; expected (60, 80) with about {int(g.mask.sum())} covered")  # fmt: skip
    P = g.attributes["position"][seen]
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N = (N / np.linalg.norm(N, axis=1, keepdims=True))[g.face_id[seen]]
    L = -d / np.linalg.norm(d)
    lit_side = N @ L > 0.05
    truth = _truth(V, F, P[lit_side], np.tile(L, (int(lit_side.sum()), 1)), N[lit_side])
    v = vis[seen][lit_side]
    acne = np.mean(v[truth] < 0.5)
    if acne > 0.005:
        fail(f"render_with_shadows of the small scene under a steep light with bias=0: {100 * acne:.2f}% of the "
             "visible points that ray casting finds lit are dark (acne, allowed 0.5%): each point needs the bias of "
             "its own plane, b = slope_bias (|g_u| + |g_v|) / 2 (receiver_depth_gradient, shadow_bias)")  # fmt: skip


# ------------------------------------------------------------------------------------------ bad input


@graded(points=0, part="bad input")
def test_rejects_zero_direction(lab):
    """a zero light direction is rejected"""
    expect_rejected(lab, "directional_light_matrix", (0, 0, 0), SCENE_BOUNDS, match="zero")


@graded(points=0, part="bad input")
def test_rejects_swapped_bounds(lab):
    """bounds given as [max, min] are rejected"""
    expect_rejected(lab, "directional_light_matrix", (0, 0, -1), SCENE_BOUNDS[::-1], match="min corner")


@graded(points=0, part="bad input")
def test_rejects_bad_spot(lab):
    """a spot light at its own target, or with near >= far, is rejected"""
    expect_rejected(lab, "spot_light_matrix", (0, 0, 1), (0, 0, 1), 60, 1, 5, match="coincide")
    expect_rejected(lab, "spot_light_matrix", (0, 0, 1), (0, 0, 0), 60, 5, 1, match="near")


@graded(points=0, part="bad input")
def test_rejects_bad_map_size_and_cull(lab):
    """a map size of 0 and an unknown cull mode are rejected"""
    V, F = small_scene()
    M = ortho_light()
    expect_rejected(lab, "depth_map", V, F, M, 0, match="size")
    expect_rejected(lab, "depth_map", V, F, M, 32, cull="up", match="cull")


@graded(points=0, part="bad input")
def test_rejects_bad_faces(lab):
    """faces that index past the vertices are rejected"""
    V, F = small_scene()
    expect_rejected(lab, "depth_map", V, F + len(V), ortho_light(), 32, match="vertex")


@graded(points=0, part="bad input")
def test_rejects_non_square_map_and_nan(lab):
    """a non-square shadow map and NaN map coordinates are rejected"""
    expect_rejected(lab, "compare_depth", np.ones((4, 5)), [[0.5, 0.5, 0.5]], match="square")
    expect_rejected(lab, "compare_depth", np.ones((4, 4)), [[0.5, np.nan, 0.5]], match="non-finite")


@graded(points=0, part="bad input")
def test_rejects_even_pcf(lab):
    """an even PCF size is rejected (the block must be centred)"""
    expect_rejected(lab, "pcf_visibility", np.ones((4, 4)), [[0.5, 0.5, 0.5]], 0.0, 4, match="odd")


@graded(points=0, part="bad input")
def test_rejects_mismatched_normals(lab):
    """P and N with different numbers of rows are rejected"""
    P = np.zeros((5, 3))
    expect_rejected(lab, "shadow_visibility", P, P[:3], np.ones((8, 8)), ortho_light(), match="one normal per point")


@graded(points=0, part="bad input")
def test_rejects_wrong_cube(lab):
    """a cube map without six faces is rejected"""
    P = np.zeros((5, 3))
    expect_rejected(lab, "point_shadow_visibility", P, P, np.ones((5, 8, 8)), (0, 0, 1), 0.1, 5.0, match="cube face")
