"""Graded tests of the lab "sdf" (public): stored references, hand-checked values and bad input."""

from __future__ import annotations

import numpy as np

from geomlib.grading import expect_close, graded, reference_tests
from geomlib.grading.errors import Mismatch

from ..common import expect_rejected
from .cases import BOX_POINTS, CASES, KERNEL_TIMEOUT, TRI, TRI_POINTS
from .support import check_bvh, scene, torus_small, wedge

test_references = reference_tests(CASES)


@graded(points=1, part="analytic SDFs")
def test_box_by_hand(lab):
    """sd_box: centre, inside, on a face, outside a face, at an edge and a corner (by hand)"""
    d = lab.sd_box(BOX_POINTS, np.zeros(3), np.array([1.0, 2.0, 3.0]))
    expect_close("sd_box", d, [-1.0, -0.5, 0.0, 1.0, np.sqrt(2), np.sqrt(3)], atol=1e-12)


@graded(points=0.5, part="point-triangle distance")
def test_seven_regions_by_hand(lab):
    """point_triangle_distance: one point in each of the seven Voronoi regions (by hand)"""
    sq, C, region = lab.point_triangle_distance(TRI_POINTS, TRI)
    expect_close("region", np.asarray(region).ravel(), [0, 1, 2, 3, 4, 5, 6], atol=0, name="region")
    expect_close(
        "closest",
        np.asarray(C).reshape(7, 3),
        [[0.5, 0.5, 0], [0, 0, 0], [2, 0, 0], [0, 2, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        atol=1e-12,
        name="closest",
        mesh=(TRI[0], [[0, 1, 2]]),
    )


def _bvh_test(lab, mesh, leaf):
    V, F = mesh()
    B = lab.build_bvh(V, F, leaf_size=leaf)
    msg = check_bvh(B, V, F, leaf)
    if msg:
        raise Mismatch(f"build_bvh(leaf_size={leaf}): {msg}")


@graded(points=1, part="BVH", timeout=KERNEL_TIMEOUT)
def test_bvh_is_valid_torus(lab):
    """build_bvh on a torus: boxes hold their triangles, children split their parent, leaves cover every triangle once"""
    _bvh_test(lab, torus_small, 4)


@graded(points=1, part="sign", timeout=KERNEL_TIMEOUT)
def test_vote_on_an_open_mesh(lab):
    """sign_vote still answers on a mesh with a hole: far-inside points stay inside; the closed wedge's thin arm is inside"""
    V, F = wedge()
    F = F[1:]  # drop one side triangle: a hole
    P = np.array([[0.15, 0.15, 0.4], [1.8, 0.15, 0.4], [0.15, 1.3, 0.4], [3.0, 3.0, 3.0], [-1.0, 0.5, 0.4]])
    s = lab.sign_vote(V, F, P)
    expect_close("sign_vote on a wedge with a hole", s, [-1, -1, -1, 1, 1], atol=0, name="s")
    # The closed wedge is the L-shaped prism 0 < z < 0.8 over [0, 2] x [0, 0.3] and [0, 0.3] x [0, 1.5]: points in
    # its long thin arm are inside, points beside the arm (x > 0.3) or above it (z > 0.8) are outside.
    V, F = wedge()
    P = np.array(
        [[0.1, 1.2, 0.15], [0.1, 1.1, 0.3], [0.08, 1.3, 0.4], [0.1, 1.0, 0.12], [0.5, 1.0, 0.3], [0.1, 1.2, 0.9]]
    )
    s = lab.sign_vote(V, F, P)
    expect_close("sign_vote in and beside the arm of the closed wedge", s, [-1, -1, -1, -1, 1, 1], atol=0, name="s")


@graded(points=1, part="sphere tracing")
def test_trace_straight_at_a_sphere(lab):
    """sphere_trace: a ray straight at a sphere stops at the distance to its surface (by hand)"""
    sdf = {"spheres": np.array([[0.0, 0.0, 0.0, 1.0]]), "planes": np.zeros((0, 4))}
    t, hit, steps = lab.sphere_trace(
        sdf, np.array([[0.0, 0.0, 5.0], [3.0, 0.0, 5.0]]), np.array([[0, 0, -2.0], [0, 0, -1.0]])
    )
    expect_close("hit", np.asarray(hit, float), [1.0, 0.0], atol=0, name="hit")
    expect_close("t of the hit", np.asarray(t)[:1], [4.0], atol=1e-4, name="t")


@graded(points=1, part="soft shadows")
def test_unoccluded_point_is_lit(lab):
    """soft_shadow: a point with nothing between it and the light sees it fully (V = 1); one whose line to the light
    runs through a ball sees none of it (V = 0)"""
    v = lab.soft_shadow(scene("balls"), np.array([[-2.5, 1.5, 0.001]]), np.array([-2.5, 1.5, 3.0]), 0.3)
    expect_close("soft_shadow", v, [1.0], atol=1e-9, name="V")
    # With the light at (0, 0, 3): (0.3, 0, 0.001) is in full shadow (at height 0.5 its line to the light is at
    # x = 0.25, inside the ball of radius 0.5 centred at (0, 0, 0.5), so the march meets d < eps); (-2.5, 1.5, 0.001)
    # is lit (its line passes 1.74 from that ball's centre, about 7 penumbra widths t tan(a) away).
    P = np.array([[0.3, 0.0, 0.001], [-2.5, 1.5, 0.001]])
    v = lab.soft_shadow(scene("balls"), P, np.array([0.0, 0.0, 3.0]), 0.3)
    expect_close("soft_shadow of a point behind a ball and a lit one", v, [0.0, 1.0], atol=1e-9, name="V")


# ------------------------------------------------------------------------------ bad input
# Validation is given code (it stays in the stubs), so these are worth 0 points.


@graded(points=0, part="bad input")
def test_rejects_zero_extent_grid(lab):
    """sdf_grid rejects a mesh whose vertices all coincide (a grid with zero extent)"""
    V = np.zeros((3, 3))
    expect_rejected(lab, "sdf_grid", V, np.array([[0, 1, 2]]), 8, match="extent")


@graded(points=0, part="bad input")
def test_rejects_nonpositive_band(lab):
    """encode_bricks rejects a band radius r <= 0"""
    expect_rejected(lab, "encode_bricks", np.zeros((8, 8, 8)), 0.1, 0.0, match="band")


@graded(points=0, part="bad input")
def test_rejects_unknown_sign_method(lab):
    """signed_distance names the accepted sign methods"""
    V, F = wedge()
    expect_rejected(lab, "signed_distance", V, F, np.zeros((1, 3)), sign="guess", match="pseudonormal")


@graded(points=0, part="bad input")
def test_rejects_degenerate_faces(lab):
    """signed_distance rejects faces that repeat a vertex"""
    V, F = wedge()
    F = np.vstack([F, [[0, 0, 1]]])
    expect_rejected(lab, "signed_distance", V, F, np.zeros((1, 3)))


@graded(points=0, part="bad input")
def test_rejects_nan_points(lab):
    """trilinear rejects NaN query points"""
    P = np.array([[0.0, 0.0, np.nan]])
    expect_rejected(lab, "trilinear", np.zeros((4, 4, 4)), np.zeros(3), 0.1, P, match="NaN")


@graded(points=0, part="bad input")
def test_rejects_zero_spacing(lab):
    """trilinear rejects a grid with zero spacing"""
    expect_rejected(lab, "trilinear", np.zeros((4, 4, 4)), np.zeros(3), 0.0, np.zeros((1, 3)), match="spacing")


@graded(points=0, part="bad input")
def test_rejects_light_around_the_point(lab):
    """soft_shadow rejects points inside the light"""
    expect_rejected(lab, "soft_shadow", scene("balls"), np.zeros((1, 3)), np.zeros(3), 0.5, match="inside the light")
