"""The software rasterizer: coverage (fill rule, watertightness), depth, culling, barycentrics, clipping, errors.

Expected pixel sets come from independent references written here: exact rational point-in-triangle
tests with the textbook top-left rule, or analytic ray casts through pixel centres.
"""

import doctest
from fractions import Fraction

import numpy as np
import pytest

from geomlib import raster
from geomlib.camera import look_at, orthographic, perspective, project
from geomlib.raster import GBuffer, rasterize, rasterize_clip
from geomlib.validate import MeshError


def pixel_camera(width, height):
    """Clip-from-world matrix under which world (x, y) ARE image coordinates (y down) and depth = (1 - z) / 2."""
    return orthographic(0, width, height, 0, -1, 1)


def coverage_counts(V, F, M, width, height, **kw):
    """How many triangles cover each pixel, each triangle rasterized on its own (test helper loop)."""
    counts = np.zeros((height, width), np.int64)
    for f in F:
        counts += rasterize(V, [f], M, width, height, **kw).mask
    return counts


def pixel_centres(width, height):
    c, r = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    return np.stack([c, r], -1)  # (h, w, 2) image coordinates


def signed_dist_to_polygon_edges(P, poly):
    """Smallest signed distance (> 0 inside) of points P (..., 2) to the edges of a convex CCW-or-CW polygon."""
    poly = np.asarray(poly, float)
    area = np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
    s = np.sign(area)
    d = np.full(P.shape[:-1], np.inf)
    for a, b in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        e = b - a
        n = s * np.array([-e[1], e[0]]) / np.linalg.norm(e)
        d = np.minimum(d, (P - a) @ n)
    return d


def rotate(P, angle_deg, centre):
    a = np.radians(angle_deg)
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return (P - centre) @ R.T + centre


# ---------------------------------------------------------------------------------------------- fill rule


def reference_coverage(tri, width, height):
    """Exact pixel-centre coverage with the top-left rule as textbooks state it (image y down).

    A centre on an edge is covered iff the edge is a *top* edge (horizontal, third vertex below it)
    or a *left* edge (not horizontal, third vertex to its right).
    """
    T = [(Fraction(x), Fraction(y)) for x, y in tri]
    out = np.zeros((height, width), bool)
    for r in range(height):
        for c in range(width):
            p = (Fraction(2 * c + 1, 2), Fraction(2 * r + 1, 2))
            ok = True
            for i in range(3):
                a, b, o = T[i], T[(i + 1) % 3], T[(i + 2) % 3]
                side = lambda q, a=a, b=b: (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0])
                sp, so = side(p), side(o)
                if sp * so > 0:
                    continue
                if sp != 0:
                    ok = False
                    break
                if a[1] == b[1]:
                    top = o[1] > a[1]
                    ok &= top
                else:
                    x_edge = a[0] + (b[0] - a[0]) * (o[1] - a[1]) / (b[1] - a[1])
                    ok &= o[0] > x_edge
            out[r, c] = ok
    return out


@pytest.mark.parametrize("seed", range(6))
def test_single_triangle_matches_exact_reference(seed):
    # Vertices on a quarter-pixel grid, so many pixel centres fall exactly on edges and vertices.
    rng = np.random.default_rng(seed)
    W = H = 16
    while True:
        tri = rng.integers(-8, 4 * W + 8, size=(3, 2)) / 4
        (ax, ay), (bx, by) = tri[1] - tri[0], tri[2] - tri[0]
        area = ax * by - ay * bx
        if abs(area) > 4:
            break
    V = np.c_[tri, np.zeros(3)]
    g = rasterize(V, [[0, 1, 2]], pixel_camera(W, H), W, H)
    np.testing.assert_array_equal(g.mask, reference_coverage(tri, W, H))
    g2 = rasterize(V, [[0, 2, 1]], pixel_camera(W, H), W, H)  # the other winding: same pixels
    np.testing.assert_array_equal(g2.mask, g.mask)


def test_axis_aligned_triangle_by_hand():
    # Right triangle with legs on pixel-centre lines x = 1.5 and y = 1.5: the left and top edges
    # contain centres and own them; the hypotenuse x + y = 7 passes through centres it does not own.
    V = np.array([[1.5, 1.5, 0], [5.5, 1.5, 0], [1.5, 5.5, 0]])
    g = rasterize(V, [[0, 1, 2]], pixel_camera(8, 8), 8, 8)
    expected = np.zeros((8, 8), bool)
    for r in range(8):
        for c in range(8):
            x, y = c + 0.5, r + 0.5
            expected[r, c] = x >= 1.5 and y >= 1.5 and x + y < 7
    np.testing.assert_array_equal(g.mask, expected)


# ---------------------------------------------------------------------------------------------- watertightness


def test_square_split_in_two_covers_each_pixel_once():
    W = H = 12
    V = np.array([[2.5, 2.5, 0], [10.5, 2.5, 0], [10.5, 10.5, 0], [2.5, 10.5, 0]])  # corners on pixel centres
    F = np.array([[0, 1, 2], [0, 2, 3]])
    counts = coverage_counts(V, F, pixel_camera(W, H), W, H)
    expected = np.zeros((H, W), np.int64)
    expected[2:10, 2:10] = 1  # top and left sides are owned, bottom and right are not
    np.testing.assert_array_equal(counts, expected)


@pytest.mark.parametrize("angle", [0.0, 17.3, 45.0, 90.0, 131.7, 250.9])
def test_rotated_square_no_cracks_no_overlap(angle):
    W = H = 24
    centre = np.array([12.0, 12.0])
    sq = rotate(np.array([[4.5, 4.5], [19.5, 4.5], [19.5, 19.5], [4.5, 19.5]]), angle, centre)
    V = np.c_[sq, np.zeros(4)]
    F = np.array([[0, 1, 2], [0, 2, 3]])
    M = pixel_camera(W, H)
    counts = coverage_counts(V, F, M, W, H)
    assert counts.max() <= 1
    d = signed_dist_to_polygon_edges(pixel_centres(W, H), sq)
    assert np.all(counts[d > 0.01] == 1) and np.all(counts[d < -0.01] == 0)
    g = rasterize(V, F, M, W, H)
    np.testing.assert_array_equal(g.mask, counts == 1)


@pytest.mark.parametrize("angle", [0.0, 7.7, 33.3])
@pytest.mark.parametrize("n", [5, 37])
def test_fan_around_a_pixel_centre(n, angle):
    W = H = 20
    c = np.array([10.5, 10.5])  # the shared vertex sits exactly on a pixel centre
    t = np.radians(angle) + 2 * np.pi * np.arange(n) / n
    ring = c + 7.3 * np.stack([np.cos(t), np.sin(t)], 1)
    V = np.c_[np.vstack([c, ring]), np.zeros(n + 1)]
    F = np.array([[0, 1 + i, 1 + (i + 1) % n] for i in range(n)])
    counts = coverage_counts(V, F, pixel_camera(W, H), W, H)
    assert counts.max() <= 1
    assert counts[10, 10] == 1
    d = signed_dist_to_polygon_edges(pixel_centres(W, H), ring)
    assert np.all(counts[d > 0.01] == 1) and np.all(counts[d < -0.01] == 0)


def jittered_grid(n, rng):
    """A triangulated n x n grid of the unit square with jittered interior points and random diagonals."""
    u = np.linspace(0, 1, n + 1)
    P = np.stack(np.meshgrid(u, u), -1).reshape(-1, 2)
    interior = (P > 0).all(1) & (P < 1).all(1)
    P[interior] += rng.uniform(-0.3, 0.3, (interior.sum(), 2)) / n
    F = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = i * (n + 1) + j, i * (n + 1) + j + 1, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1
            F += [[a, b, d], [a, d, c]] if rng.random() < 0.5 else [[a, b, c], [b, d, c]]
    return P, np.array(F)


@pytest.mark.parametrize("seed,angle", [(0, 0.0), (1, 13.7), (2, 61.1), (3, 199.9)])
def test_random_grid_no_cracks_no_overlap(seed, angle):
    rng = np.random.default_rng(seed)
    W = H = 32
    P, F = jittered_grid(6, rng)
    P = rotate(P * 20 + 6, angle, np.array([16.0, 16.0]))
    V = np.c_[P, np.zeros(len(P))]
    M = pixel_camera(W, H)
    counts = coverage_counts(V, F, M, W, H)
    assert counts.max() <= 1
    hull = rotate(np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]) * 20 + 6, angle, np.array([16.0, 16.0]))
    d = signed_dist_to_polygon_edges(pixel_centres(W, H), hull)
    assert np.all(counts[d > 0.01] == 1) and np.all(counts[d < -0.01] == 0)
    g = rasterize(V, F, M, W, H)  # all at the same depth: each pixel shows its only triangle
    np.testing.assert_array_equal(g.mask, counts == 1)
    for f in rng.choice(len(F), 5, replace=False):
        np.testing.assert_array_equal(g.face_id == f, rasterize(V, [F[f]], M, W, H).mask)


def test_grid_crossing_the_near_plane_stays_watertight():
    # A floor grid that extends behind the camera: the clipped triangles must still tile exactly.
    rng = np.random.default_rng(7)
    P, F = jittered_grid(5, rng)
    V = np.c_[P[:, 0] * 8 - 4, np.full(len(P), -1.0), P[:, 1] * 8 - 6]  # z from -6 to 2; camera at z = 0
    M = perspective(70, 1.0, 0.5, 20) @ look_at((0, 0, 0), (0, 0, -1))
    counts = coverage_counts(V, F, M, 32, 32)
    assert counts.max() <= 1
    g = rasterize(V, F, M, 32, 32)
    np.testing.assert_array_equal(g.mask, counts == 1)
    assert g.mask[-1].all()  # the bottom row sees the floor right in front of the near plane


# ---------------------------------------------------------------------------------------------- depth and culling


def test_nearer_triangle_wins_in_either_order():
    M = pixel_camera(16, 16)  # depth = (1 - z) / 2: larger z is nearer
    near = np.array([[0, 0, 0.5], [16, 0, 0.5], [0, 16, 0.5]])
    far = np.array([[16, 16, -0.2], [16, 0, -0.2], [0, 16, -0.2]]) + [-8, 0, 0]
    V = np.vstack([near, far])
    for F, near_id in [([[0, 1, 2], [3, 4, 5]], 0), ([[3, 4, 5], [0, 1, 2]], 1)]:
        g = rasterize(V, F, M, 16, 16)
        both = rasterize(V, [F[0]], M, 16, 16).mask & rasterize(V, [F[1]], M, 16, 16).mask
        assert both.sum() > 10
        assert np.all(g.face_id[both] == near_id)
        np.testing.assert_allclose(g.depth[both], 0.25)
    assert np.isinf(g.depth[~g.mask]).all() and np.all(g.face_id[~g.mask] == -1)


def test_depth_ties_go_to_the_lower_face_id():
    V = np.array([[1, 1, 0], [15, 2, 0], [3, 14, 0.0]])
    g = rasterize(V, [[0, 1, 2], [1, 2, 0], [0, 1, 2]], pixel_camera(16, 16), 16, 16)
    assert g.mask.sum() > 50 and np.all(g.face_id[g.mask] == 0)


def test_depth_is_window_depth_and_far_plane_clips():
    M = perspective(60, 1.0, 1.0, 10.0) @ look_at((0, 0, 0), (0, 0, -1))
    # A plane tilted away from the camera that crosses the far plane: beyond it nothing is drawn.
    V = np.array([[-20, -2, -2.0], [20, -2, -2.0], [0, 6, -30.0]])
    g = rasterize(V, [[0, 1, 2]], M, 32, 32, attributes={"position": V})
    P = g.attributes["position"][g.mask]
    xy, depth = project(P, M, 32, 32)
    np.testing.assert_allclose(g.depth[g.mask], depth, atol=1e-9)
    assert g.depth[g.mask].max() <= 1.0 and g.depth[g.mask].min() >= 0
    assert P[:, 2].min() >= -10 - 1e-6  # nothing beyond the far plane
    # Analytic: the pixel-centre ray hits the plane in front of the far plane <=> covered (away from the far line).
    n = np.cross(V[1] - V[0], V[2] - V[0])
    dirs = pixel_rays(M, 32, 32)
    t = (V[0] @ n) / (dirs @ n)
    z = t * dirs[..., 2]
    inside = (t > 0) & (z > -10 + 0.05)
    outside = (t < 0) | (z < -10 - 0.05)
    assert g.mask[inside].all() and not g.mask[outside].any()


def pixel_rays(M, width, height):
    """World directions through pixel centres for a camera at the origin (M = P @ V with V a pure rotation)."""
    xy = pixel_centres(width, height)
    ndc = np.stack(
        [2 * xy[..., 0] / width - 1, 1 - 2 * xy[..., 1] / height, np.zeros((height, width)), np.ones((height, width))],
        -1,
    )
    p = ndc @ np.linalg.inv(M).T
    return p[..., :3] / p[..., 3:]


@pytest.mark.parametrize(
    "cull,front_drawn,back_drawn", [("none", True, True), ("back", True, False), ("front", False, True)]
)
def test_culling(cull, front_drawn, back_drawn):
    M = perspective(60, 1.0, 0.1, 10) @ look_at((0, 0, 3), (0, 0, 0))
    V = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0.0]])  # counter-clockwise seen from +z: front-facing
    assert rasterize(V, [[0, 1, 2]], M, 16, 16, cull=cull).mask.any() == front_drawn
    assert rasterize(V, [[0, 2, 1]], M, 16, 16, cull=cull).mask.any() == back_drawn


def test_cull_back_on_a_closed_mesh_keeps_the_visible_side():
    # A cube seen from a corner: with or without back-face culling the picture is the same.
    V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    Q = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]  # outward quads
    F = np.array([t for a, b, c, d in Q for t in ((a, b, c), (a, c, d))])
    M = perspective(45, 1.0, 0.5, 20) @ look_at((3, 2.5, 4), (0, 0, 0))
    g, gb = rasterize(V, F, M, 48, 48), rasterize(V, F, M, 48, 48, cull="back")
    np.testing.assert_array_equal(g.face_id, gb.face_id)
    gf = rasterize(V, F, M, 48, 48, cull="front")  # the inside of the far walls
    np.testing.assert_array_equal(gf.mask, g.mask)
    assert np.all(gf.depth[g.mask] > g.depth[g.mask])


# ---------------------------------------------------------------------------------------------- barycentrics


def test_barycentrics_sum_to_one_and_reproduce_positions():
    rng = np.random.default_rng(3)
    V = rng.normal(size=(30, 3))
    F = rng.integers(0, 30, size=(40, 3))
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    M = perspective(50, 1.25, 0.5, 20) @ look_at((4, 3, 5), (0, 0, 0))
    g = rasterize(V, F, M, 40, 32, attributes={"position": V})
    b = g.bary[g.mask]
    assert g.mask.sum() > 200
    np.testing.assert_allclose(b.sum(1), 1, atol=1e-12)
    assert b.min() >= 0
    np.testing.assert_array_equal(g.bary[~g.mask], 0)
    P = g.attributes["position"]
    np.testing.assert_allclose(P[g.mask], np.einsum("pi,pij->pj", b, V[F[g.face_id[g.mask]]]))
    xy, depth = project(P[g.mask], M, 40, 32)
    # The interpolated position reprojects to the pixel centre (up to 1/256-pixel vertex snapping).
    np.testing.assert_allclose(xy, pixel_centres(40, 32)[g.mask], atol=0.01)
    np.testing.assert_allclose(depth, g.depth[g.mask], atol=1e-6)
    np.testing.assert_allclose(g.interpolate(V), P)
    np.testing.assert_allclose(g.interpolate(V[:, 1]), P[..., 1])


def test_perspective_correct_on_a_tilted_plane():
    # A large quad on the plane n.p = d, strongly tilted: affine (screen-space) interpolation would
    # miss the pixel centres by several pixels; perspective-correct interpolation must not.
    n = np.array([0.0, 0.8, 0.6])
    d = -0.5
    u = np.array([1.0, 0, 0])
    v = np.cross(n, u)
    o = n * d
    Q = np.array([o - 3 * u - 3 * v, o + 3 * u - 3 * v, o + 3 * u + 3 * v, o - 3 * u + 3 * v])
    M = perspective(60, 1.0, 0.1, 50) @ look_at((0.3, 1.5, 4), (0, 0, 0))
    g = rasterize(
        Q, [[0, 1, 2], [0, 2, 3]], M, 48, 48, attributes={"position": Q, "uv": [[0, 0], [1, 0], [1, 1], [0, 1]]}
    )
    P = g.attributes["position"][g.mask]
    assert len(P) > 500
    np.testing.assert_allclose(P @ n, d, atol=1e-9)
    xy, _ = project(P, M, 48, 48)
    np.testing.assert_allclose(xy, pixel_centres(48, 48)[g.mask], atol=0.01)
    # uv is affine in the plane's own coordinates: check it against the position.
    uv = g.attributes["uv"][g.mask]
    np.testing.assert_allclose(uv, np.stack([(P - Q[0]) @ u / 6, (P - Q[0]) @ v / 6], 1), atol=1e-9)
    # The test is sensitive: screen-space (affine) barycentrics would put points far off the pixel centres.
    F = np.array([[0, 1, 2], [0, 2, 3]])[g.face_id[g.mask]]
    qxy, _ = project(Q, M, 48, 48)
    T = np.concatenate([qxy[F], np.ones(F.shape + (1,))], axis=2)  # (p, 3, 3)
    lam = np.linalg.solve(T.transpose(0, 2, 1), np.c_[pixel_centres(48, 48)[g.mask], np.ones(len(P))][..., None])[
        ..., 0
    ]
    affine = np.einsum("pi,pij->pj", lam, Q[F])
    assert np.linalg.norm(affine - P, axis=1).max() > 0.2


def test_orthographic_barycentrics_are_affine():
    W = H = 16
    V = np.array([[1.0, 2.0, 0.3], [14.0, 3.5, -0.4], [4.0, 15.0, 0.9]])
    g = rasterize(V, [[0, 1, 2]], pixel_camera(W, H), W, H)
    xy = pixel_centres(W, H)[g.mask]
    T = np.c_[V[:, :2], np.ones(3)]
    expected = np.linalg.solve(T.T, np.c_[xy, np.ones(len(xy))].T).T
    np.testing.assert_allclose(g.bary[g.mask], expected, atol=2e-3)  # vertices snap to 1/256 pixel


# ---------------------------------------------------------------------------------------------- clipping


def test_triangle_crossing_the_near_plane():
    near = 0.5
    M = perspective(60, 1.0, near, 20) @ look_at((0, 0, 0), (0, 0, -1))
    # One vertex behind the camera, two in front (and the mirrored case with two behind).
    for V in (
        np.array([[-2, -1, -3.0], [2, -1, -3.0], [0, -1, 4.0]]),
        np.array([[-2, -1, 3.0], [2, -1, 3.0], [0, -1, -4.0]]),
    ):
        g = rasterize(V, [[0, 1, 2]], M, 32, 32, attributes={"position": V})
        assert g.mask.sum() > 20
        for a in (g.depth[g.mask], g.bary, g.attributes["position"]):
            assert np.isfinite(a).all()
        assert g.bary[g.mask].min() >= 0
        P = g.attributes["position"][g.mask]
        np.testing.assert_allclose(P[:, 1], -1, atol=1e-9)  # on the triangle's plane
        assert P[:, 2].max() <= -near + 1e-6  # only the part in front of the near plane
        xy, _ = project(P, M, 32, 32)
        np.testing.assert_allclose(xy, pixel_centres(32, 32)[g.mask], atol=0.01)
        # Analytic coverage: rays through pixel centres hit the triangle at or beyond the near plane.
        hit = ray_hits_triangle(pixel_rays(M, 32, 32), V, margin=1e-3, z_max=-near)
        miss = ~ray_hits_triangle(pixel_rays(M, 32, 32), V, margin=-1e-3, z_max=-near + 1e-3)
        assert g.mask[hit].all() and not g.mask[miss].any()


def ray_hits_triangle(D, T, margin, z_max):
    """Rays from the origin along D (..., 3) that hit triangle T at a point with z <= z_max, inside by margin."""
    n = np.cross(T[1] - T[0], T[2] - T[0])
    t = (T[0] @ n) / (D @ n)
    P = t[..., None] * D
    ok = (t > 0) & (P[..., 2] <= z_max)
    for i in range(3):
        a, b = T[i], T[(i + 1) % 3]
        e = np.cross(b - a, P - a) @ n / np.linalg.norm(n) / np.linalg.norm(b - a)
        ok &= e > margin
    return ok


def test_triangle_behind_the_camera_draws_nothing():
    M = perspective(60, 1.0, 0.5, 20) @ look_at((0, 0, 0), (0, 0, -1))
    V = np.array([[-5, -5, 2.0], [5, -5, 2.0], [0, 5, 2.0]])  # behind, and would project across the screen
    for F in ([[0, 1, 2]], [[0, 2, 1]]):
        g = rasterize(V, F, M, 16, 16)
        assert not g.mask.any() and np.isinf(g.depth).all()
    V2 = np.array([[-5, -5, -0.2], [5, -5, -0.2], [0, 5, -0.2]])  # in front of the eye but before the near plane
    assert not rasterize(V2, [[0, 1, 2]], M, 16, 16).mask.any()


def test_huge_triangle_covers_the_screen():
    M = perspective(60, 1.0, 0.5, 20) @ look_at((0, 0, 0), (0, 0, -1))
    V = np.array([[-1e7, -1e7, -5.0], [1e7, -1e7, -5.0], [0, 1e7, -5.0]])  # far beyond the guard band
    g = rasterize(V, [[0, 1, 2]], M, 24, 24, attributes={"position": V})
    assert g.mask.all()
    _, depth = project(np.array([[0, 0, -5.0]]), M, 24, 24)
    np.testing.assert_allclose(g.depth, depth[0], atol=1e-9)
    P = g.attributes["position"]
    np.testing.assert_allclose(P[..., 2], -5, atol=1e-6)
    xy, _ = project(P.reshape(-1, 3), M, 24, 24)
    np.testing.assert_allclose(xy.reshape(24, 24, 2), pixel_centres(24, 24), atol=0.01)


def test_huge_triangle_grazing_the_eye():
    # A floor triangle passing under the eye, extending far behind and far ahead: clipped by the near
    # plane and the guard band at once. Compare with the analytic floor.
    M = perspective(90, 1.0, 0.1, 100) @ look_at((0, 0, 0), (0, 0, -1))
    V = np.array([[-1e6, -1.0, 1e6], [1e6, -1.0, 1e6], [0, -1.0, -1e6]])
    g = rasterize(V, [[0, 1, 2]], M, 32, 32, attributes={"position": V})
    D = pixel_rays(M, 32, 32)
    t = -1.0 / D[..., 1]
    z = t * D[..., 2]
    covered = (t > 0) & (z > -100 + 0.5)
    empty = (t < 0) | (z < -100 - 0.5)
    assert g.mask[covered].all() and not g.mask[empty].any()
    np.testing.assert_allclose(g.attributes["position"][g.mask][:, 1], -1, atol=1e-6)


def test_shared_edge_cut_points_are_bitwise_identical():
    # Two triangles sharing an edge that crosses the near plane (traversed in opposite directions)
    # must produce the very same cut point, or snapping could open a crack along the edge.
    rng = np.random.default_rng(11)
    a = np.c_[rng.normal(size=(200, 2)), rng.uniform(-3, 3, 200), np.ones(200)]
    b = np.c_[rng.normal(size=(200, 2)), rng.uniform(-3, 3, 200), np.ones(200)]
    a[:, 2:] = np.c_[-np.abs(a[:, 2]) - 0.5, rng.uniform(0.1, 0.4, 200)]  # z + w < 0: behind the near plane
    b[:, 2:] = np.c_[np.abs(b[:, 2]), rng.uniform(0.1, 2, 200)]  # in front
    c1, c2 = rng.normal(size=(200, 4)) + [0, 0, 3, 5], rng.normal(size=(200, 4)) + [0, 0, 3, 5]
    T1 = np.stack([a, b, c1], 1)  # edge a -> b
    T2 = np.stack([b, a, c2], 1)  # edge b -> a
    P1, _, n1 = raster._clip_polygons(T1, 1e6, 1e6)
    P2, _, n2 = raster._clip_polygons(T2, 1e6, 1e6)
    assert (n1 == 4).all() and (n2 == 4).all()  # one vertex behind: a quad each
    for k in range(200):
        cuts1 = P1[k, :4][np.abs(P1[k, :4, 2] + P1[k, :4, 3]) < 1e-9]  # the two cut points of each polygon
        cuts2 = P2[k, :4][np.abs(P2[k, :4, 2] + P2[k, :4, 3]) < 1e-9]
        assert len(cuts1) == len(cuts2) == 2
        shared = [p for p in cuts1 if any(np.array_equal(p, q) for q in cuts2)]
        assert len(shared) == 1, k  # the cut on the shared edge ab, bit for bit


def test_results_do_not_depend_on_chunking(monkeypatch):
    rng = np.random.default_rng(2)
    V = rng.normal(size=(60, 3))
    F = np.array([[i, (i + 5) % 60, (i + 11) % 60] for i in range(60)])
    F = np.vstack([F, F[:10]])  # duplicates: exact depth ties across chunks
    M = perspective(50, 1.0, 0.5, 20) @ look_at((3, 2, 4), (0, 0, 0))
    g = rasterize(V, F, M, 40, 40)
    monkeypatch.setattr(raster, "_PAIR_BUDGET", 3)
    monkeypatch.setattr(raster, "_FRAG_BUDGET", 5)
    monkeypatch.setattr(raster, "_PIX_BLOCK", 7)
    gs = rasterize(V, F, M, 40, 40)
    np.testing.assert_array_equal(gs.face_id, g.face_id)
    np.testing.assert_array_equal(gs.depth, g.depth)
    np.testing.assert_array_equal(gs.bary, g.bary)
    assert g.face_id.max() < 60  # the duplicates never win a tie


def test_rasterize_clip_matches_rasterize():
    rng = np.random.default_rng(5)
    V = rng.normal(size=(20, 3))
    F = np.array([[i, (i + 3) % 20, (i + 7) % 20] for i in range(20)])
    M = perspective(50, 1.0, 0.5, 20) @ look_at((3, 2, 4), (0, 0, 0))
    g = rasterize(V, F, M, 24, 24)
    gc = rasterize_clip(np.c_[V, np.ones(20)] @ M.T, F, 24, 24)
    np.testing.assert_array_equal(g.face_id, gc.face_id)
    np.testing.assert_allclose(g.bary, gc.bary, atol=1e-12)
    gd = rasterize(V, F, M, 24, 24, depth_only=True)
    assert gd.bary is None
    np.testing.assert_array_equal(gd.face_id, g.face_id)
    np.testing.assert_array_equal(gd.depth, g.depth)


def test_empty_and_offscreen_inputs():
    M = pixel_camera(8, 4)
    g = rasterize(np.zeros((0, 3)), np.zeros((0, 3), int), M, 8, 4)
    assert isinstance(g, GBuffer) and g.depth.shape == (4, 8) and g.bary.shape == (4, 8, 3) and not g.mask.any()
    V = np.array([[20, 20, 0], [30, 20, 0], [20, 30, 0.0]])
    assert not rasterize(V, [[0, 1, 2]], M, 8, 4).mask.any()
    assert rasterize(V, [[0, 1, 1]], M, 8, 4).face_id.max() == -1  # degenerate faces draw nothing


def test_one_by_one_and_non_square_images():
    V = np.array([[-1, -1, 0], [3, -1, 0], [-1, 3, 0.0]])
    g = rasterize(V, [[0, 1, 2]], np.eye(4), 1, 1)
    assert g.mask.shape == (1, 1) and g.mask[0, 0]
    W, H = 7, 3
    g = rasterize(np.array([[0, 0, 0], [7, 0, 0], [0, 3, 0.0]]), [[0, 1, 2]], pixel_camera(W, H), W, H)
    assert g.mask.shape == (H, W)
    assert g.mask[0, 0] and not g.mask[H - 1, W - 1]  # row 0 is the top of the picture


# ---------------------------------------------------------------------------------------------- errors


V0 = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
F0 = np.array([[0, 1, 2]])


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(V=np.zeros((3, 2))), r"rasterize: V has shape \(3, 2\), expected \(n, 3\)"),
        (dict(V=np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]])), "rasterize: V: row 1 has a non-finite value"),
        (dict(F=[[0, 1, 3]]), "face 0 uses vertex 3, but V has only 3 vertices"),
        (dict(F=[[0, 1, 2, 0]]), r"F has shape \(1, 4\)"),
        (dict(M=np.eye(3)), r"M has shape \(3, 3\), expected \(4, 4\)"),
        (dict(M=np.full((4, 4), np.inf)), "M: row 0 has a non-finite value"),
        (dict(width=0), "width must be >= 1"),
        (dict(height=0), "height must be >= 1"),
        (dict(width=2.5), "width must be an integer"),
        (dict(width=10**6), "width must be <= 32768"),
        (dict(cull="sideways"), "cull must be one of 'none', 'back', 'front'; got 'sideways'"),
        (
            dict(attributes={"uv": np.zeros((2, 2))}),
            r"attributes\['uv'\] has shape \(2, 2\), expected \(3,\) or \(3, k\)",
        ),
        (dict(attributes={"n": np.full((3, 3), np.nan)}), r"attributes\['n'\]: row 0 has a non-finite value"),
        (dict(attributes=[1, 2]), "attributes must be a dict"),
        (dict(attributes={"uv": np.zeros((3, 2))}, depth_only=True), "cannot be combined with depth_only"),
    ],
)
def test_bad_input_raises_mesh_error(kwargs, match):
    args = dict(V=V0, F=F0, M=np.eye(4), width=4, height=4)
    args.update(kwargs)
    V, F, M, W, H = (args.pop(k) for k in ("V", "F", "M", "width", "height"))
    with pytest.raises(MeshError, match=match):
        rasterize(V, F, M, W, H, **args)


def test_bad_input_rasterize_clip_and_interpolate():
    with pytest.raises(MeshError, match=r"rasterize_clip: Vclip has shape \(3, 3\), expected \(n, 4\)"):
        rasterize_clip(V0, F0, 4, 4)
    g = rasterize(V0, F0, np.eye(4), 4, 4)
    with pytest.raises(MeshError, match=r"GBuffer.interpolate: values has shape \(4, 3\)"):
        g.interpolate(np.zeros((4, 3)))
    with pytest.raises(MeshError, match="depth_only=True"):
        rasterize(V0, F0, np.eye(4), 4, 4, depth_only=True).interpolate(V0)


# ---------------------------------------------------------------------------------------------- cross-checks


def test_docstring_examples():
    assert doctest.testmod(raster, raise_on_error=False).failed == 0


@pytest.mark.render
@pytest.mark.slow  # importing pyrender costs seconds (shared with the other render tests)
def test_matches_pyrender_pixel_for_pixel():
    # An independent rasterizer (Mesa through pyrender) with the same conventions: same covered pixels,
    # same depth up to its depth-buffer precision, also with the camera low over a floor that runs
    # behind it (near-plane clipping).
    from geomlib.render import import_pyrender

    pyrender = import_pyrender()
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=2)
    n = 12
    P, _ = jittered_grid(n, np.random.default_rng(0))
    Vg = np.c_[P[:, 0] * 10 - 5, np.full(len(P), -1.0), P[:, 1] * 10 - 5]
    _, Fg = jittered_grid(n, np.random.default_rng(0))
    Fg = Fg[:, ::-1]  # face up (counter-clockwise seen from +y)
    V = np.vstack([s.vertices, Vg])
    F = np.vstack([s.faces, Fg + len(s.vertices)])
    size, fov, near, far = 96, 60.0, 0.2, 12.0
    renderer = pyrender.OffscreenRenderer(size, size)
    try:
        for eye, target in [((2.5, 1.5, 3.0), (0, 0, 0)), ((0.3, -0.7, 2.2), (0, -0.5, 0))]:
            view = look_at(eye, target)
            scene = pyrender.Scene()
            scene.add(pyrender.Mesh.from_trimesh(trimesh.Trimesh(V, F, process=False), smooth=False))
            cam = pyrender.PerspectiveCamera(yfov=np.radians(fov), aspectRatio=1.0, znear=near, zfar=far)
            scene.add(cam, pose=np.linalg.inv(view))
            d_ref = renderer.render(scene, flags=pyrender.RenderFlags.DEPTH_ONLY)  # eye distance, 0 = background
            g = rasterize(V, F, perspective(fov, 1.0, near, far) @ view, size, size, cull="back")
            np.testing.assert_array_equal(g.mask, d_ref > 0)
            z_ndc = 2 * g.depth[g.mask] - 1
            dist = 2 * far * near / (far + near - z_ndc * (far - near))
            np.testing.assert_allclose(dist, d_ref[g.mask], rtol=5e-3)
    finally:
        renderer.delete()
