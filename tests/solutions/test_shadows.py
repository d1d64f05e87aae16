"""Cross-checks of the shadow-mapping solution against independent libraries, and its properties.

* light matrices against pyrender's own camera matrices (``OrthographicCamera``, ``PerspectiveCamera``);
* culling against trimesh's face normals;
* depth maps against pyrender's depth renders (OSMesa);
* shadows against an exact oracle: one ray per pixel towards the light with libigl's AABB tree;
* shadows against pyrender's own shadow mapping (``RenderFlags.SHADOWS_DIRECTIONAL``).

Maps are small (256-1024) to keep the suite cheap; the 2048^2 agreement is one slow test.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest
import trimesh

from geomlib import datasets
from geomlib.camera import look_at
from geomlib.render import import_pyrender, offscreen_renderer  # lazy: pyrender loads on first call
from geomlib.validate import MeshError
from solutions.shadows import (
    CLASSIC_CAMERA,
    CLASSIC_LIGHT,
    CUBE_DIRECTIONS,
    compare_depth,
    cube_face_index,
    cube_light_matrices,
    cull_faces,
    depth_map,
    directional_light_matrix,
    eye_gbuffer,
    light_uvz,
    light_visibility,
    make_scene,
    outside_frustum,
    pcf_visibility,
    point_shadow_visibility,
    poisson_disk,
    poisson_pcf_visibility,
    receiver_depth_gradient,
    render_with_shadows,
    shadow_bias,
    shadow_metrics,
    shadow_visibility,
    spot_light_matrix,
)
from solutions.shadows.scene import classic_scene, torus_scene

SIZE = (160, 120)
SPOT = {"type": "spot", "position": np.array([-3.0, -3.5, 5.0]), "target": np.array([0.0, 0.0, 0.0]), "fov_deg": 70.0}
POINT = {"type": "point", "position": np.array([0.2, -0.3, 2.6])}


@pytest.fixture(scope="module")
def scene():
    return classic_scene()


@pytest.fixture(scope="module")
def eye(scene):
    return eye_gbuffer(scene, CLASSIC_CAMERA, SIZE)


def _to_light(light, P):
    if light["type"] == "directional":
        d = -np.asarray(light["direction"], float)
        return np.tile(d / np.linalg.norm(d), (len(P), 1)), np.full(len(P), np.inf)
    v = light["position"] - P
    dist = np.linalg.norm(v, axis=1)
    return v / dist[:, None], dist


def igl_truth(scene, eb, light) -> dict:
    """The oracle, written independently of solutions.shadows.truth: libigl's AABB tree, first hit per ray."""
    L, dist = _to_light(light, eb.P)
    n = eb.N_face * np.sign(np.einsum("ij,ij->i", eb.N_face, eb.eye - eb.P))[:, None]
    reached = np.einsum("ij,ij->i", n, L) > 0
    if light["type"] == "spot":
        axis = light["target"] - light["position"]
        axis /= np.linalg.norm(axis)
        reached &= -L @ axis > np.cos(np.radians(0.5 * light["fov_deg"]))
    eps = 1e-6 * np.linalg.norm(scene.V.max(0) - scene.V.min(0))
    tree = igl.AABB()
    tree.init(scene.V, scene.F)
    face, t, _ = tree.intersect_ray_first(scene.V, scene.F, eb.P + eps * L, np.ascontiguousarray(L))
    hit = (np.asarray(face) >= 0) & (np.asarray(t) < dist - 2 * eps)
    face = np.asarray(face)
    return {
        "lit": ~hit,
        "dist": np.where(hit, t, np.inf),
        "other": hit & (scene.mesh_id[np.maximum(face, 0)] != scene.mesh_id[eb.face]),
        "reached": reached,
    }


@pytest.fixture(scope="module")
def truth(scene, eye):
    return igl_truth(scene, eye, CLASSIC_LIGHT)


# --------------------------------------------------------------------------------------------
# Task 1: light matrices against pyrender's cameras


@pytest.mark.parametrize("direction", [(0.45, 0.55, -0.7), (0.0, 0.0, -1.0), (1.0, -2.0, 0.3)])
def test_directional_matrix_matches_pyrender_orthographic_camera(direction):
    pyrender = import_pyrender()
    B = np.array([[-3.0, -2.0, 0.0], [3.0, 2.5, 2.0]])
    M = directional_light_matrix(direction, B)
    d = np.asarray(direction) / np.linalg.norm(direction)
    c, R = B.mean(0), 0.5 * np.linalg.norm(B[1] - B[0])
    View = look_at(c - R * d, c, np.eye(3)[np.argmin(np.abs(d))])
    corners = np.array(np.meshgrid(*B.T, indexing="ij")).reshape(3, -1).T
    E = corners @ View[:3, :3].T + View[:3, 3]
    # The box is symmetric about its centre, which the camera looks at: a symmetric ortho box.
    xmag, ymag = np.abs(E[:, 0]).max(), np.abs(E[:, 1]).max()
    cam = pyrender.OrthographicCamera(xmag=xmag, ymag=ymag, znear=-E[:, 2].max(), zfar=-E[:, 2].min())
    np.testing.assert_allclose(M, cam.get_projection_matrix() @ View, atol=1e-12)


def test_directional_matrix_is_tight_and_looks_along_the_light():
    B = np.array([[-3.0, -3.0, 0.0], [3.0, 3.0, 2.1]])
    d = np.array([0.45, 0.55, -0.7])
    M = directional_light_matrix(d, B)
    corners = np.array(np.meshgrid(*B.T, indexing="ij")).reshape(3, -1).T
    uvz = light_uvz(corners, M)
    np.testing.assert_allclose(uvz.min(0), 0.0, atol=1e-12)  # touches every face of the unit cube
    np.testing.assert_allclose(uvz.max(0), 1.0, atol=1e-12)
    # moving along the light direction keeps (u, v) and increases depth
    p = B.mean(0)
    a, b = light_uvz(np.array([p, p + 0.5 * d]), M)
    np.testing.assert_allclose(a[:2], b[:2], atol=1e-12)
    assert b[2] > a[2]


def test_spot_matrix_matches_pyrender_perspective_camera():
    pyrender = import_pyrender()
    pos, tgt = np.array([-3.0, -3.5, 5.0]), np.array([0.2, 0.1, 0.0])
    M = spot_light_matrix(pos, tgt, 70.0, 0.5, 20.0)
    cam = pyrender.PerspectiveCamera(yfov=np.radians(70.0), znear=0.5, zfar=20.0, aspectRatio=1.0)
    d = tgt - pos
    np.testing.assert_allclose(
        M, cam.get_projection_matrix() @ look_at(pos, tgt, np.eye(3)[np.argmin(np.abs(d))]), atol=1e-12
    )
    uvz = light_uvz(tgt[None], M)[0]
    np.testing.assert_allclose(uvz[:2], 0.5, atol=1e-12)


# --------------------------------------------------------------------------------------------
# Tasks 2 and 5: culling against trimesh, depth maps against pyrender


@pytest.mark.parametrize("light", ["directional", "spot"])
def test_cull_faces_agrees_with_trimesh_normals(light):
    V, F = datasets.icosphere(2)
    V = V + np.array([0.3, -0.2, 1.5])
    normals = trimesh.Trimesh(V, F, process=False).face_normals
    centroid = V[F].mean(axis=1)
    if light == "directional":
        d = np.array([0.3, 0.4, -1.0])
        M = directional_light_matrix(d, [V.min(0), V.max(0)])
        facing = normals @ -d
    else:
        pos = np.array([2.0, 3.0, 5.0])
        M = spot_light_matrix(pos, V.mean(0), 50.0, 1.0, 20.0)
        facing = np.einsum("ij,ij->i", normals, pos - centroid)
    front = cull_faces(V, F, M, "back")  # keeps the front faces
    back = cull_faces(V, F, M, "front")
    sure = np.abs(facing) > 1e-9
    expect_front = {tuple(f) for f in F[sure & (facing > 0)]}
    expect_back = {tuple(f) for f in F[sure & (facing < 0)]}
    got_front, got_back = {tuple(f) for f in front}, {tuple(f) for f in back}
    assert expect_front <= got_front and expect_back <= got_back
    assert not (expect_front & got_back) and not (expect_back & got_front)
    assert len(cull_faces(V, F, M, "none")) == len(F)


def test_culled_depth_map_equals_the_rasterizers_culling(scene):
    from geomlib.raster import rasterize

    M = directional_light_matrix(CLASSIC_LIGHT["direction"], scene.bounds)
    for cull in ("front", "back"):
        D = depth_map(scene.V, scene.F, M, 128, cull)
        g = rasterize(scene.V, scene.F, M, 128, 128, cull=cull, depth_only=True)
        np.testing.assert_array_equal(D, np.where(g.mask, g.depth, 1.0))


@pytest.mark.render
@pytest.mark.parametrize("kind", ["directional", "spot"])
def test_depth_map_matches_pyrender_depth(scene, kind):
    """Our depth pass and pyrender's depth buffer (OSMesa) see the same surfaces at the same depths."""
    pyrender = import_pyrender()
    size = 256
    if kind == "spot":
        near, far = 2.5, 11.0
        M = spot_light_matrix(SPOT["position"], SPOT["target"], SPOT["fov_deg"], near, far)
        d = SPOT["target"] - SPOT["position"]
        View = look_at(SPOT["position"], SPOT["target"], np.eye(3)[np.argmin(np.abs(d))])
        cam = pyrender.PerspectiveCamera(yfov=np.radians(SPOT["fov_deg"]), znear=near, zfar=far, aspectRatio=1.0)
    else:
        M = directional_light_matrix(CLASSIC_LIGHT["direction"], scene.bounds)
        d = CLASSIC_LIGHT["direction"] / np.linalg.norm(CLASSIC_LIGHT["direction"])
        B = scene.bounds
        c, R = B.mean(0), 0.5 * np.linalg.norm(B[1] - B[0])
        # The same clip-from-world matrix from a camera one unit further back (near plane away from 0,
        # where pyrender's depth read-back would lose all precision).
        View = look_at(c - (R + 1.0) * d, c, np.eye(3)[np.argmin(np.abs(d))])
        Pm = M @ np.linalg.inv(View)
        near, far = (Pm[2, 3] + 1) / Pm[2, 2], (Pm[2, 3] - 1) / Pm[2, 2]

        class Ortho(pyrender.OrthographicCamera):
            # pyrender stretches xmag to the viewport's aspect ratio when rendering; keep ours.
            def get_projection_matrix(self, width=None, height=None):
                return super().get_projection_matrix()

        cam = Ortho(xmag=1 / Pm[0, 0], ymag=1 / Pm[1, 1], znear=near, zfar=far)
    np.testing.assert_allclose(cam.get_projection_matrix() @ View, M, atol=1e-9)
    mat = pyrender.MetallicRoughnessMaterial(doubleSided=True)
    ps = pyrender.Scene()
    ps.add(pyrender.Mesh([pyrender.Primitive(positions=scene.V, indices=scene.F.astype(np.uint32), material=mat)]))
    ps.add(cam, pose=np.linalg.inv(View))
    lin = np.asarray(offscreen_renderer(size, size).render(ps, flags=pyrender.RenderFlags.DEPTH_ONLY), float)
    ref_cov = lin > 0
    # pyrender linearises the depth buffer with the perspective formula for every camera; undo it.
    ref = np.ones_like(lin)
    ref[ref_cov] = ((far + near - 2 * near * far / lin[ref_cov]) / (far - near) + 1) / 2
    D = depth_map(scene.V, scene.F, M, size, cull="none")
    ours_cov = D < 1.0
    assert np.mean(ours_cov == ref_cov) > 0.995
    both = ours_cov & ref_cov
    assert np.mean(np.abs(D[both] - ref[both]) < 1e-4) > 0.99  # float32 GPU depth; edges may pick the other surface


def test_depth_of_a_plane_seen_head_on_by_hand():
    """A unit square at z = 0.25 in bounds z in [0, 1], light straight down: depth 0.75 everywhere."""
    V = np.array([[0.0, 0, 0.25], [1, 0, 0.25], [1, 1, 0.25], [0, 1, 0.25]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    M = directional_light_matrix((0, 0, -1), [[0, 0, 0], [1, 1, 1]])
    D = depth_map(V, F, M, 8, cull="none")
    np.testing.assert_allclose(D, 0.75, atol=1e-12)
    # seen from below (light pointing up) the square faces away: front culling keeps it, back culling drops it
    M2 = directional_light_matrix((0, 0, 1), [[0, 0, 0], [1, 1, 1]])
    np.testing.assert_allclose(depth_map(V, F, M2, 8, cull="front"), 0.25, atol=1e-12)
    np.testing.assert_array_equal(depth_map(V, F, M2, 8, cull="back"), 1.0)


# --------------------------------------------------------------------------------------------
# Tasks 3, 4, 6, 7: the lookup, by hand and as properties


def test_compare_depth_by_hand():
    D = np.array([[0.2, 0.9], [0.5, 0.7]])  # row 0 = top = v in [0.5, 1]
    uvz = np.array([[0.25, 0.75, 0.2], [0.25, 0.75, 0.21], [0.75, 0.25, 0.7], [0.75, 0.25, 0.71], [1.0, 0.0, 0.7]])
    np.testing.assert_array_equal(compare_depth(D, uvz), [1, 0, 1, 0, 1])
    np.testing.assert_array_equal(compare_depth(D, uvz, 0.02), [1, 1, 1, 1, 1])
    # clamping: beside the map reads the border texel
    np.testing.assert_array_equal(compare_depth(D, [[-0.5, 2.0, 0.3]]), [0.0])


def test_pcf_by_hand_and_reduction_to_compare():
    D = np.ones((4, 4))
    D[:, :2] = 0.3  # left half occupied at depth 0.3
    uvz = np.array([[0.375, 0.5, 0.5], [0.625, 0.5, 0.5], [0.875, 0.5, 0.5]])  # cols 1, 2, 3
    np.testing.assert_allclose(pcf_visibility(D, uvz, 0.0, 3), [1 / 3, 2 / 3, 1.0])
    np.testing.assert_allclose(pcf_visibility(D, uvz, 0.0, 1), compare_depth(D, uvz))
    # a gradient tilts the plane the neighbours are compared with
    Df = np.full((5, 5), 0.5)
    g = np.array([[0.1, 0.0]])
    at = np.array([[0.5, 0.5, 0.5]])
    assert pcf_visibility(Df, at, 0.0, 3) == 1.0
    np.testing.assert_allclose(pcf_visibility(Df, at, 0.0, 3, gradient=g), 2 / 3)


def test_poisson_disk_is_deterministic_inside_the_disk_and_well_spread():
    d = poisson_disk(16)
    np.testing.assert_array_equal(d, poisson_disk(16))  # same seed, same disk
    assert not np.allclose(d, poisson_disk(16, seed=1))
    assert d.shape == (16, 2) and (np.hypot(d[:, 0], d[:, 1]) <= 1 + 1e-12).all()

    def min_gap(p):
        g = np.sqrt(((p[:, None] - p[None]) ** 2).sum(axis=2))
        np.fill_diagonal(g, np.inf)
        return g.min()

    # uniform random points in the disk, for comparison: their closest pair is much closer
    rng = np.random.default_rng(7)
    uniform = []
    for _ in range(50):
        r, t = np.sqrt(rng.random(16)), 2 * np.pi * rng.random(16)
        uniform.append(min_gap(np.stack([r * np.cos(t), r * np.sin(t)], axis=1)))
    assert min_gap(d) > 3 * np.mean(uniform)
    # and it covers the disk: every point of the disk is near a sample
    g = np.stack(np.meshgrid(np.linspace(-1, 1, 81), np.linspace(-1, 1, 81)), axis=-1).reshape(-1, 2)
    g = g[np.hypot(g[:, 0], g[:, 1]) <= 1]
    assert np.sqrt(((g[:, None] - d[None]) ** 2).sum(axis=2)).min(axis=1).max() < 0.45


def test_poisson_pcf_by_hand():
    size = 16
    D = np.ones((size, size))
    D[:, : size // 2] = 0.3  # left half occupied at depth 0.3: the edge is at u = 0.5
    disk = poisson_disk(16) * 2.0
    far_lit, far_dark = [[0.9, 0.5, 0.5]], [[0.1, 0.5, 0.5]]
    for rotate in (True, False):
        assert poisson_pcf_visibility(D, far_lit, 0.0, 2.0, 16, rotate=rotate) == 1.0
        assert poisson_pcf_visibility(D, far_dark, 0.0, 2.0, 16, rotate=rotate) == 0.0
    # on the edge, without rotation: the share of disk samples that land on the lit half
    at = np.array([[0.5 + 0.25 / size, 0.5 + 0.5 / size, 0.5]])  # a quarter texel right of the edge
    expected = np.mean(0.25 + disk[:, 0] >= 0)
    np.testing.assert_allclose(poisson_pcf_visibility(D, at, 0.0, 2.0, 16, rotate=False), expected)
    assert 0 < expected < 1
    # the same across a horizontal edge: rows 0..7 (the top half, v >= 0.5) occupied; dy points up
    Dh = np.ones((size, size))
    Dh[: size // 2] = 0.3
    above = np.array([[0.5 + 0.5 / size, 0.5 + 0.25 / size, 0.5]])  # a quarter texel into the top half
    np.testing.assert_allclose(
        poisson_pcf_visibility(Dh, above, 0.0, 2.0, 16, rotate=False), np.mean(0.25 + disk[:, 1] < 0)
    )
    # a depth gradient tilts the plane the samples are compared with (as in pcf_visibility)
    Df = np.full((size, size), 0.5)
    mid = np.array([[0.5 + 0.5 / size, 0.5 + 0.5 / size, 0.5]])
    v = poisson_pcf_visibility(Df, mid, 0.0, 2.0, 16, gradient=[[0.1, 0.0]], rotate=False)
    np.testing.assert_allclose(v, np.mean(disk[:, 0] <= 0))


def test_poisson_pcf_agrees_with_the_grid_and_the_truth(scene, eye, truth):
    grid, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=256, pcf=5)
    disk, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=256, pcf=5, pcf_sampling="poisson")
    assert abs(disk.mean() - grid.mean()) < 0.005
    partial = (disk > 0) & (disk < 1)
    assert 0 < partial.mean() < 0.2  # soft only along the shadow edges
    assert (partial & (grid == 1)).mean() < 0.01  # its soft pixels are where the grid's are
    wrong = [np.sum((v >= 0.5) != truth["lit"]) / truth["reached"].sum() for v in (grid, disk)]
    assert wrong[1] < wrong[0] + 0.005, wrong
    # point lights pass the option on to each cube face
    pg, _ = light_visibility(scene, eye, POINT, map_size=128, pcf=3)
    pd, _ = light_visibility(scene, eye, POINT, map_size=128, pcf=3, pcf_sampling="poisson")
    assert abs(pd.mean() - pg.mean()) < 0.01 and not np.array_equal(pd, pg)


def test_receiver_gradient_of_a_tilted_plane_by_hand():
    """Light straight down on bounds [0, 1]^3, map 100 texels: u runs along -y, v along +x (up = x axis),
    depth = 1 - z. The plane z = 0.5 + 0.25 (x - 0.5) rises 0.0025 per texel of v, so depth falls by that."""
    M = directional_light_matrix((0, 0, -1), [[0, 0, 0], [1, 1, 1]])
    np.testing.assert_allclose(light_uvz([[0.3, 0.2, 0.9]], M), [[0.8, 0.3, 0.1]], atol=1e-12)
    g = receiver_depth_gradient([[0.5, 0.5, 0.5]], [[-0.25, 0.0, 1.0]], M, 100)
    np.testing.assert_allclose(g, [[0.0, -0.0025]], atol=1e-15)
    np.testing.assert_allclose(shadow_bias(g, 0.001, 2.0), [0.001 + 2.0 * 0.5 * 0.0025])
    # an edge-on plane is clamped
    np.testing.assert_allclose(
        receiver_depth_gradient([[0.5, 0.5, 0.5]], [[1.0, 0, 0]], M, 100, max_slope=3.0), [[0, -0.03]]
    )


def test_receiver_gradient_matches_finite_differences_for_a_spot_light():
    rng = np.random.default_rng(3)
    M = spot_light_matrix(SPOT["position"], SPOT["target"], 70.0, 2.0, 12.0)
    P = rng.uniform(-1.0, 1.0, (8, 3)) + np.array([0.0, 0.0, 1.0])
    N = rng.normal(size=(8, 3))
    N[:, 2] = np.abs(N[:, 2]) + 0.5  # not edge-on
    size = 512
    g = receiver_depth_gradient(P, N, M, size, max_slope=1e9)
    uvz = light_uvz(P, M)
    h = 1e-5
    for i in range(len(P)):
        t1 = np.cross(N[i], [1.0, 0, 0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(N[i], t1) / np.linalg.norm(N[i])
        # (u, v, z) along the plane, differentiated numerically; then one texel step in u and in v
        J = np.stack([(light_uvz([P[i] + h * t], M)[0] - uvz[i]) / h for t in (t1, t2)], axis=1)
        for k in range(2):
            step = np.linalg.solve(J[:2], np.eye(2)[k] / size)
            np.testing.assert_allclose(g[i, k], J[2] @ step, rtol=1e-3, atol=1e-12)


def test_outside_frustum_by_hand():
    uvz = np.array(
        [[0.5, 0.5, 0.5], [-0.01, 0.5, 0.5], [0.5, 1.01, 0.5], [0.5, 0.5, 1.01], [0.5, 0.5, -0.5], [1, 0, 1]]
    )
    np.testing.assert_array_equal(outside_frustum(uvz), [False, True, True, True, False, False])


# --------------------------------------------------------------------------------------------
# Against the ray-cast oracle


def test_default_shadows_agree_with_ray_casting(scene, eye, truth):
    for cull in ("front", "back", "none"):
        vis, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=1024, cull=cull)
        m = shadow_metrics(vis, truth, eye.mask)
        assert m["agreement"] > 0.995, (cull, m)
        assert m["acne"] < 1e-3, (cull, m)


def test_no_bias_gives_acne_and_bias_removes_it(scene, eye, truth):
    vis0, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=512, bias=0.0, slope_bias=0.0, cull="none")
    m0 = shadow_metrics(vis0, truth, eye.mask)
    assert m0["acne"] > 0.2  # about half of every lit surface shadows itself
    const, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=512, bias=0.01, slope_bias=0.0, cull="none")
    assert shadow_metrics(const, truth, eye.mask)["acne"] < 0.01
    # front-face culling removes acne on closed objects without any bias
    front, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=512, bias=0.0, slope_bias=0.0, cull="front")
    assert shadow_metrics(front, truth, eye.mask)["acne"] < 1e-3


def test_too_much_bias_detaches_contact_shadows(scene):
    eb = eye_gbuffer(scene, CLASSIC_CAMERA, (320, 240))
    tr = igl_truth(scene, eb, CLASSIC_LIGHT)
    good = shadow_metrics(light_visibility(scene, eb, CLASSIC_LIGHT, map_size=1024, cull="none")[0], tr, eb.mask)
    big = light_visibility(scene, eb, CLASSIC_LIGHT, map_size=1024, bias=0.25, slope_bias=0.0, cull="none")[0]
    bad = shadow_metrics(big, tr, eb.mask)
    assert good["contact"] == bad["contact"] > 50
    assert good["peter_panning"] < 0.05 < 0.5 < bad["peter_panning"]


def test_frustum_fix(scene, eye, truth):
    """A map fitted to the middle of the floor: outside it, points must stay lit."""
    B = np.array([[-1.5, -1.5, 0.0], [1.5, 1.5, 2.1]])
    on, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=512, bounds=B, frustum_fix=True)
    off, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=512, bounds=B, frustum_fix=False)
    M = directional_light_matrix(CLASSIC_LIGHT["direction"], B)
    outside = outside_frustum(light_uvz(eye.P, M))
    assert outside.mean() > 0.3
    np.testing.assert_array_equal(on[outside], 1.0)
    assert (off[outside] < 0.5).mean() > 0.05  # clamped border texels and z > 1 darken them
    np.testing.assert_array_equal(on[~outside], off[~outside])


def test_resolution_and_pcf(scene, eye, truth):
    wrong = []
    for size in (128, 512, 2048):
        vis, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=size)
        wrong.append(np.sum((vis >= 0.5) != truth["lit"]) / truth["reached"].sum())
    assert wrong[0] > wrong[1] > wrong[2] or wrong[2] < 1e-3
    hard, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=256, pcf=1)
    soft, _ = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=256, pcf=5)
    assert set(np.unique(hard)) <= {0.0, 1.0}
    partial = (soft > 0) & (soft < 1)
    assert 0 < partial.mean() < 0.2  # soft only along the shadow edges
    assert abs(soft.mean() - hard.mean()) < 0.01


@pytest.mark.parametrize("light", [SPOT, POINT], ids=["spot", "point"])
def test_spot_and_point_lights_agree_with_ray_casting(scene, eye, light):
    tr = igl_truth(scene, eye, light)
    vis, _ = light_visibility(scene, eye, light, map_size=1024)
    m = shadow_metrics(vis, tr, eye.mask)
    assert m["agreement"] > 0.99 and m["acne"] < 1e-3, m


def test_cube_faces_tile_all_directions():
    rng = np.random.default_rng(0)
    pos = np.array([0.3, -0.2, 1.0])
    Ms = cube_light_matrices(pos, 0.1, 10.0)
    dirs = rng.normal(size=(2000, 3))
    P = pos + rng.uniform(0.2, 9.0, (2000, 1)) * dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    face = cube_face_index(P - pos)
    for f in range(6):
        uvz = light_uvz(P[face == f], Ms[f])
        assert np.all((uvz >= -1e-12) & (uvz <= 1 + 1e-12))
        c = light_uvz((pos + CUBE_DIRECTIONS[f])[None], Ms[f])[0]
        np.testing.assert_allclose(c[:2], 0.5, atol=1e-12)
    np.testing.assert_array_equal(cube_face_index(CUBE_DIRECTIONS), np.arange(6))


def test_point_light_matches_six_spot_lights(scene):
    """The cube map is six 90-degree spot lights: the same visibility through either route."""
    eb = eye_gbuffer(scene, CLASSIC_CAMERA, (96, 72))
    pos, near, far = POINT["position"], 0.2, 12.0
    Ms = cube_light_matrices(pos, near, far)
    maps = np.stack([depth_map(scene.V, scene.F, M, 256) for M in Ms])
    vis = point_shadow_visibility(eb.P, eb.N_face, maps, pos, near, far)
    face = cube_face_index(eb.P - pos)
    assert len(np.unique(face)) >= 4
    for f in np.unique(face):
        sel = face == f
        spot = spot_light_matrix(pos, pos + CUBE_DIRECTIONS[f], 90.0, near, far)
        # same frustum up to the up vector: only the rotation of the map differs
        ref = shadow_visibility(eb.P[sel], eb.N_face[sel], depth_map(scene.V, scene.F, spot, 256), spot)
        assert np.mean(ref == vis[sel]) > 0.98


# --------------------------------------------------------------------------------------------
# Against pyrender's shadow mapping


@pytest.mark.render
@pytest.mark.slow
def test_shadow_regions_agree_with_pyrender_and_have_less_acne():
    from solutions.shadows import pyrender_visibility

    T = torus_scene(125, 50)
    cam = (np.array([0.0, -5.5, 3.2]), np.array([0.0, 0.0, 1.2]))
    light = {"type": "directional", "direction": np.array([0.5, 0.3, -0.8])}
    size = (240, 180)
    eb = eye_gbuffer(T, cam, size)
    tr = igl_truth(T, eb, light)
    pv = pyrender_visibility(T, cam, light, size=size).ravel()[np.flatnonzero(eb.mask.ravel())]
    ours, _ = light_visibility(T, eb, light, map_size=2048, pcf=3)
    sel = tr["reached"]
    assert np.mean((np.nan_to_num(pv[sel]) >= 0.5) == (ours[sel] >= 0.5)) > 0.97
    m_py = shadow_metrics(np.nan_to_num(pv), tr, eb.mask)
    m_ours = shadow_metrics(ours, tr, eb.mask)
    assert m_ours["acne"] < m_py["acne"]


@pytest.mark.slow
def test_agreement_at_2048_is_at_least_99_percent(scene):
    eb = eye_gbuffer(scene, CLASSIC_CAMERA, (320, 240))
    tr = igl_truth(scene, eb, CLASSIC_LIGHT)
    vis, _ = light_visibility(scene, eb, CLASSIC_LIGHT, map_size=2048, pcf=1)
    assert shadow_metrics(vis, tr, eb.mask)["agreement"] >= 0.99


def test_render_with_shadows_darkens_exactly_the_shadowed_pixels(scene):
    img, vis = render_with_shadows(scene, CLASSIC_CAMERA, CLASSIC_LIGHT, size=SIZE, pcf=1, return_visibility=True)
    lit_only = render_with_shadows(scene, CLASSIC_CAMERA, CLASSIC_LIGHT, size=SIZE, pcf=1, bias=1.0)  # nothing shadowed
    assert img.shape == (SIZE[1], SIZE[0], 3) and 0 <= img.min() and img.max() <= 1
    shadowed = np.nan_to_num(vis, nan=1.0) < 1
    changed = np.abs(img - lit_only).max(axis=2) > 1e-12
    assert not (changed & ~shadowed).any()  # only shadowed pixels change ...
    assert np.all(img <= lit_only + 1e-12)  # ... and only get darker
    assert changed.sum() > 0.03 * np.isfinite(vis).sum()  # the floor shadows are visible


# --------------------------------------------------------------------------------------------
# Bad input


def test_bad_input_is_rejected_with_clear_messages():
    V, F = datasets.icosphere(1)
    M = directional_light_matrix((0, 0, -1), [V.min(0), V.max(0)])
    cases = [
        (lambda: directional_light_matrix((0, 0, 0), [V.min(0), V.max(0)]), "zero vector"),
        (lambda: directional_light_matrix((0, 0, -1), [V.max(0), V.min(0)]), "min corner"),
        (lambda: directional_light_matrix((0, 0, -1), [[0, 0, 0], [1, 1, 0]]), "flat"),
        (lambda: spot_light_matrix((0, 0, 1), (0, 0, 1), 60, 1, 2), "coincide"),
        (lambda: spot_light_matrix((0, 0, 1), (0, 0, 0), 180, 1, 2), "fov_deg"),
        (lambda: spot_light_matrix((0, 0, 1), (0, 0, 0), 60, 2, 1), "near < far"),
        (lambda: depth_map(V, F, M, 0), "size"),
        (lambda: depth_map(V, F, M, 64, cull="up"), "cull"),
        (lambda: depth_map(V, F + 100, M, 64), "vertex"),
        (lambda: depth_map(V, F, M[:3], 64), "shape"),
        (lambda: cull_faces(V, F, M, "sideways"), "cull"),
        (lambda: compare_depth(np.ones((4, 5)), [[0.5, 0.5, 0.5]]), "square"),
        (lambda: compare_depth(np.ones((4, 4)), [[0.5, np.nan, 0.5]]), "non-finite"),
        (lambda: compare_depth(np.ones((4, 4)), [[0.5, 0.5, 0.5]], [0.1, 0.2]), "bias"),
        (lambda: pcf_visibility(np.ones((4, 4)), [[0.5, 0.5, 0.5]], 0.0, 2), "odd"),
        (lambda: shadow_bias([[0.1, 0.1]], -1.0, 1.0), "bias"),
        (lambda: shadow_visibility(V, V[:3], np.ones((8, 8)), M), "one normal per point"),
        (lambda: shadow_visibility(V, V, np.ones((8, 8)), M, frustum_fix="yes"), "frustum_fix"),
        (lambda: shadow_visibility(V, V, np.ones((8, 8)), M, pcf=3, pcf_sampling="random"), "'grid', 'poisson'"),
        (lambda: shadow_visibility(V, V, np.ones((8, 8)), M, pcf=3, pcf_samples=0), "pcf_samples"),
        (lambda: poisson_pcf_visibility(np.ones((4, 4)), [[0.5, 0.5, 0.5]], 0.0, 0.0), "radius must be > 0"),
        (lambda: poisson_disk(0), "samples"),
        (lambda: receiver_depth_gradient(V, V, np.zeros((4, 4)), 8), "singular"),
        (lambda: cube_light_matrices((0, 0, 0), 0.0, 1.0), "near"),
        (lambda: point_shadow_visibility(V, V, np.ones((5, 8, 8)), (0, 0, 0), 0.1, 1), "cube face"),
        (lambda: make_scene([(V, F, (2.0, 0, 0))]), r"\[0, 1\]"),
        (lambda: render_with_shadows([(V, F)], CLASSIC_CAMERA, {"type": "sun"}), "type"),
    ]
    for call, match in cases:
        with pytest.raises(MeshError, match=match):
            call()
