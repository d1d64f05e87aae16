"""Cross-checks of the signed-distance solution against independent libraries, and its properties.

* mesh distances against ``igl.signed_distance`` (pseudonormal) and ``igl.point_mesh_squared_distance``;
* every sign method against libigl's winding number;
* the box formula against libigl's distance to a box mesh;
* trilinear lookups against ``scipy.ndimage.map_coordinates(order=1)``;
* bricks: error at most half a quantisation step in the band, memory;
* sphere-traced hit masks and depths against geomlib's rasterizer on the same mesh and camera;
* soft shadows against the sphere-occluder truth and a Monte-Carlo area light (how far they are);
* the compiled kernels with ``NUMBA_DISABLE_JIT=1`` (plain Python) on a small case.

Grids are small (<= 32^3) to keep the suite quick; the 128^3 comparisons are in ``bench/sdf.py``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import igl
import numpy as np
import pytest
from scipy.ndimage import map_coordinates

from geomlib import camera, datasets, raster
from geomlib.geometry import bbox_diagonal
from geomlib.validate import MeshError
from solutions.sdf import (
    brute_force_distance,
    compress_bricks,
    gradient_central,
    gradient_tetra,
    instances_distance,
    make_scene,
    mesh_visibility,
    push_out,
    render_sdf,
    sd_box,
    sdf_grid,
    signed_distance,
    soft_shadow,
    sphere_occluder_visibility,
    sphere_trace,
    winding_number,
)
from solutions.sdf.bricks import BRICK
from solutions.sdf.field import outside_rule
from solutions.sdf.trace import camera_rays
from tests.solutions.fresh import run_python

ROOT = Path(__file__).resolve().parents[2]
FANDISK = Path("/work/shared/data/meshes/fandisk.obj")


def _igl_pseudo(V, F, P):
    return np.asarray(igl.signed_distance(P, V, F, sign_type=igl.SIGNED_DISTANCE_TYPE_PSEUDONORMAL)[0])


def _points(V, n, seed, margin=0.3):
    rng = np.random.default_rng(seed)
    lo, hi = V.min(0) - margin, V.max(0) + margin
    return lo + rng.random((n, 3)) * (hi - lo)


MESHES = {
    "torus": lambda: datasets.torus(),
    "icosphere": lambda: datasets.icosphere(3),
    "sharp_box": lambda: datasets.sharp_box((1.0, 0.6, 0.4), n=3),
}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_pseudonormal_distance_matches_igl(name):
    V, F = MESHES[name]()
    P = _points(V, 3000, 1)
    d = signed_distance(V, F, P)
    np.testing.assert_allclose(d, _igl_pseudo(V, F, P), atol=1e-12 * bbox_diagonal(V))


@pytest.mark.skipif(not FANDISK.is_file(), reason="real meshes in ../shared are not available")
def test_pseudonormal_distance_matches_igl_on_the_fandisk():
    from geomlib import mesh_io as io

    V, F = io.read_mesh(FANDISK)[:2]
    P = _points(V, 4000, 2, margin=0.05 * bbox_diagonal(V))
    np.testing.assert_allclose(signed_distance(V, F, P), _igl_pseudo(V, F, P), atol=1e-12 * bbox_diagonal(V))


def test_brute_force_matches_igl():
    V, F = datasets.torus(1.0, 0.35, 24, 12)
    P = _points(V, 400, 3)
    sq, face, C, _ = brute_force_distance(V, F, P)
    sq_i, _, C_i = igl.point_mesh_squared_distance(P, V, F)
    np.testing.assert_allclose(sq, sq_i, atol=1e-12)
    np.testing.assert_allclose(C, C_i, atol=1e-9)


@pytest.mark.parametrize("sign", ["pseudonormal", "vote", "winding"])
def test_signs_match_igl_winding_number(sign):
    V, F = datasets.torus(1.0, 0.35, 32, 16)
    P = _points(V, 1500, 4)
    inside_igl = np.asarray(igl.winding_number(V, F, P)) > 0.5
    d = signed_distance(V, F, P, sign=sign)
    assert np.array_equal(d < 0, inside_igl)


def test_winding_number_matches_igl():
    V, F = datasets.icosphere(2)
    P = _points(V, 300, 5, margin=0.5)
    np.testing.assert_allclose(winding_number(V, F, P), np.asarray(igl.winding_number(V, F, P)), atol=1e-10)


@pytest.mark.parametrize("shape", ["wedge", "thin_prism"])
def test_normal_sign_fails_at_sharp_edges(shape):
    """The cheap sign is wrong near the 20-degree edge of a sliver prism; the pseudonormal and the vote never are."""
    sys.path.insert(0, str(ROOT / "tests"))
    from graded.sdf import support

    V, F = getattr(support, shape)()
    P = _points(V, 4000, 6, margin=0.1)
    truth = np.asarray(igl.winding_number(V, F, P)) > 0.5
    for s in ("pseudonormal", "vote"):
        assert np.array_equal(signed_distance(V, F, P, sign=s) < 0, truth)
    wrong = np.count_nonzero((signed_distance(V, F, P, sign="normal") < 0) != truth)
    if shape == "thin_prism":
        assert wrong > 0  # the sharp edge fools the face normal


def test_box_formula_matches_the_box_mesh():
    V, F = datasets.sharp_box((2.0, 1.2, 0.8), n=2)
    P = _points(V, 2000, 7, margin=0.6)
    np.testing.assert_allclose(sd_box(P, V.mean(0), np.array([1.0, 0.6, 0.4])), _igl_pseudo(V, F, P), atol=1e-12)


def test_grid_and_trilinear_match_map_coordinates():
    V, F = datasets.torus(1.0, 0.35, 32, 16)
    g = sdf_grid(V, F, 24)
    P = _points(V, 2000, 8, margin=0.1)
    u = ((P - g.origin) / g.spacing).T
    np.testing.assert_allclose(g.sample(P), map_coordinates(g.values, u, order=1), atol=1e-12)
    np.testing.assert_allclose(g.values.ravel(), _igl_pseudo(V, F, g.points()), atol=1e-12)


def test_band_equals_clamped_full_grid():
    V, F = datasets.torus(1.0, 0.35, 32, 16)
    full = sdf_grid(V, F, 28)
    r = 3 * full.spacing
    for sign in ("pseudonormal", "vote"):
        band = sdf_grid(V, F, 28, band=3, sign=sign)
        np.testing.assert_allclose(band.values, np.clip(full.values, -r, r), atol=1e-12)


def test_bricks_error_and_memory():
    V, F = datasets.torus(1.0, 0.35, 48, 24)
    g = sdf_grid(V, F, 50)  # 49 cells = 7 bricks per axis, no padding
    B = compress_bricks(g, band_voxels=4)
    assert B.table.shape == (7, 7, 7)
    X = g.points()
    in_band = np.abs(g.values.ravel()) < B.r
    err = np.abs(B.sample(X) - g.values.ravel())[in_band] / B.step
    assert err.max() <= 0.5 + 1e-9
    assert B.nbytes == B.codes.nbytes + B.table.nbytes == len(B.codes) * BRICK**3 + 4 * 7**3
    assert B.nbytes < g.values.astype(np.float32).nbytes / 3
    # the tightest correct rule: a brick is kept iff one of its 8^3 stored samples is in the band
    inband = np.abs(g.values) < B.r
    needed = [
        [[inband[7 * i : 7 * i + 8, 7 * j : 7 * j + 8, 7 * k : 7 * k + 8].any() for k in range(7)] for j in range(7)]
        for i in range(7)
    ]
    np.testing.assert_array_equal(B.table >= 0, needed)
    # between samples the bricked field follows the dense one's trilinear interpolation
    P = _points(V, 3000, 9, margin=0.0)
    near = np.abs(g.sample(P)) < 0.5 * B.r
    assert np.max(np.abs(B.sample(P) - g.sample(P))[near]) <= 0.5 * B.step + 1e-12


def test_bricks_pad_a_grid_that_is_not_7k_plus_1():
    V, F = datasets.icosphere(2)
    g = sdf_grid(V, F, 20)  # 19 cells: padded to 3 bricks of 7
    B = compress_bricks(g, band_voxels=2)
    assert B.table.shape == (3, 3, 3)
    X = g.points()
    in_band = np.abs(g.values.ravel()) < B.r
    assert np.max(np.abs(B.sample(X) - g.values.ravel())[in_band]) <= 0.5 * B.step + 1e-12
    with pytest.raises(MeshError, match="band_voxels"):
        compress_bricks(g, band_voxels=-1)


def test_outside_the_box_is_a_lower_bound():
    V, F = datasets.icosphere(3)
    g = sdf_grid(V, F, 20)
    P = np.random.default_rng(10).normal(size=(500, 3)) * 4
    d = g.sample(P)
    true = np.linalg.norm(P, axis=1) - 1
    far = np.any((P < g.origin) | (P > g.upper), axis=1)
    assert np.all(d[far] <= true[far] + 2e-2)
    # the lookup applies the outside rule to the value at the clamped point, and inside the box the
    # rule changes nothing (the lookup skips it there): exactly, not just to round-off
    Q = np.clip(P, g.origin, g.upper)
    np.testing.assert_array_equal(d, outside_rule(P, Q, g.sample(Q)))
    np.testing.assert_array_equal(d[~far], outside_rule(P[~far], P[~far], d[~far]))


def test_instancing_scales_distances():
    sc = make_scene(spheres=[[0, 0, 0, 1.0]])
    P = np.random.default_rng(11).uniform(-4, 4, size=(300, 3))
    d = instances_distance(sc, P, np.array([[1.0, 2.0, 0.0]]), np.array([1.5]))
    np.testing.assert_allclose(d, np.linalg.norm(P - [1, 2, 0], axis=1) - 1.5, atol=1e-12)


def test_gradients_match_the_true_normal_at_hits():
    V, F = datasets.icosphere(4)
    g = sdf_grid(V, F, 32)
    M = camera.perspective(40, 1, 0.1, 10) @ camera.look_at([0.3, -3.0, 1.2], [0, 0, 0], [0, 0, 1])
    R = render_sdf(g, M, 48, 48)
    X = R["points"][R["hit"]]
    true = X / np.linalg.norm(X, axis=1, keepdims=True)
    for grad in (gradient_central, gradient_tetra):
        N = grad(g, X, 0.5 * g.spacing)
        assert np.degrees(np.arccos(np.clip(np.sum(N * true, axis=1), -1, 1))).mean() < 2.0


def test_sphere_tracing_matches_the_rasterizer():
    V, F = datasets.torus()
    g = sdf_grid(V, F, 48)
    M = camera.perspective(40, 1.0, 0.1, 10.0) @ camera.look_at([0.0, -3.0, 2.0], [0, 0, 0], [0, 0, 1])
    R = render_sdf(g, M, 96, 96)
    gb = raster.rasterize(V, F, M, 96, 96)
    assert np.mean(R["hit"] != gb.mask) < 0.01  # silhouettes only
    both = R["hit"] & gb.mask
    # the rasterizer's window depth -> distance along the ray from the near plane
    from solutions.sdf import camera_rays

    O, D = camera_rays(M, 96, 96)
    ys, xs = np.nonzero(both)
    ndc = np.stack([(xs + 0.5) / 96 * 2 - 1, 1 - (ys + 0.5) / 96 * 2, gb.depth[both] * 2 - 1, np.ones(len(xs))], 1)
    W = ndc @ np.linalg.inv(M).T
    W = W[:, :3] / W[:, 3:]
    t_ras = np.linalg.norm(W - O.reshape(96, 96, 3)[both], axis=1)
    err = np.abs(R["depth"][both] - t_ras)
    assert np.median(err) < 0.5 * g.spacing and np.percentile(err, 95) < 2 * g.spacing


def test_soft_shadow_of_a_sphere_against_the_truth():
    """The course formula is an estimate: it agrees with the truth where fully lit or in umbra, not in between."""
    sc = make_scene(spheres=[[0, 0, 1, 0.5]], planes=[[0, 0, 1, 0]])
    xs = np.linspace(-2.5, 2.5, 101)
    P = np.c_[xs, np.zeros_like(xs), np.full_like(xs, 1e-3)]
    lc = np.array([0.5, 0.0, 4.0])
    v = soft_shadow(sc, P, lc, 0.5, max_steps=64)
    truth = sphere_occluder_visibility(P, lc, 0.5, [0, 0, 1], 0.5, n=4096)
    lit, umbra = truth > 0.999, truth < 1e-3
    assert np.all(v[lit] > 0.99) and np.all(v[umbra] < 0.02)
    assert np.mean(np.abs(v - truth)) < 0.1
    vi = soft_shadow(sc, P, lc, 0.5, max_steps=64, improved=True)
    assert np.mean(np.abs(vi - truth)) < 0.1


def test_soft_shadow_of_a_mesh_against_monte_carlo():
    V, F = datasets.icosphere(3, radius=0.5)
    V = V + [0, 0, 1.0]
    g = sdf_grid(V, F, 32, padding=1.0)
    P = np.c_[np.linspace(-1.5, 1.5, 31), np.zeros(31), np.full(31, 0.02)]
    truth = mesh_visibility(V, F, P, [0.5, 0, 4.0], 0.5, n=256)
    est = soft_shadow(g, P, [0.5, 0, 4.0], 0.5, max_steps=64)
    assert np.mean(np.abs(est - truth)) < 0.15
    assert np.all(est[truth > 0.999] > 0.95)


def test_mesh_visibility_casts_every_ray_that_could_hit():
    """``mesh_visibility`` casts only the rays of points whose cone meets the mesh's bounding sphere:
    the same numbers, bit for bit, as casting every ray with ``geomlib.geometry.ray_cast``, on a grid
    whose points lie in the light, in the penumbra, in the umbra and just beside the cone's edge."""
    from geomlib.geometry import ray_cast
    from solutions.sdf.truth import cone_directions

    V, F = datasets.icosphere(2, radius=0.5)
    V = V + [0, 0, 0.9]
    xs = np.linspace(-2.0, 2.0, 41)
    X, Y = np.meshgrid(xs, xs)
    P = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 1e-3)]
    light, R, n = np.array([0.8, -0.5, 3.2]), 0.5, 16
    got = mesh_visibility(V, F, P, light, R, n=n)
    L = light - P
    D = np.linalg.norm(L, axis=1)
    Dir = cone_directions(L, np.arcsin(R / D), n, 0).reshape(-1, 3)
    _, t, face, _ = ray_cast(V, F, np.repeat(P, n, axis=0), Dir, t_min=1e-6 * bbox_diagonal(V))
    every = 1.0 - ((face >= 0) & (t < np.repeat(D - R, n))).reshape(len(P), n).mean(axis=1)
    assert 0.2 < np.mean(every == 1.0) < 0.95 and (every == 0).any(), "the grid must hold lit, penumbra and umbra"
    assert got.tobytes() == every.tobytes(), np.flatnonzero(got != every)[:10]


def test_push_out_leaves_points_outside():
    sc = make_scene(spheres=[[0, 0, 0, 1.0]])
    P = np.random.default_rng(12).uniform(-0.7, 0.7, size=(200, 3))
    Q = push_out(sc, P, radius=0.1, iterations=3)
    r = np.linalg.norm(Q, axis=1)
    r0 = np.linalg.norm(P, axis=1)
    assert np.all(r >= 1.1 - 1e-6)
    np.testing.assert_array_equal(Q[r0 >= 1.1], P[r0 >= 1.1])  # points already clear do not move
    # the others land on phi = radius; near the centre a finite-difference normal is poor
    moved = (r0 < 1.1) & (r0 > 0.05)
    np.testing.assert_allclose(r[moved], 1.1, atol=1e-6)


def test_sphere_trace_misses_are_inf_and_budget_holds():
    sc = make_scene(spheres=[[0, 0, 0, 1.0]])
    t, hit, steps = sphere_trace(
        sc, np.array([[0, 0, 5.0], [5, 5, 5.0]]), np.array([[0, 0, -1.0], [0, 0, -1.0]]), max_steps=20
    )
    assert hit.tolist() == [True, False] and np.isinf(t[1]) and steps.max() <= 20


def _plain_sphere_trace(phi, O, D, max_steps, eps, t_max):
    """The march written plainly: every ray evaluated at every step, finished ones masked out."""
    D = D / np.linalg.norm(D, axis=1, keepdims=True)  # as sphere_trace does
    t, hit, steps = np.zeros(len(O)), np.zeros(len(O), bool), np.zeros(len(O), np.int64)
    live = np.ones(len(O), bool)
    for _ in range(max_steps):
        d = phi(O + t[:, None] * D)
        steps[live] += 1
        hit |= live & (d < eps)
        live &= d >= eps
        t[live] += np.maximum(d[live], eps)
        live &= t <= t_max
    return np.where(hit, t, np.inf), hit, steps


def test_sphere_trace_equals_the_plain_march_exactly():
    """Active-ray compaction is only bookkeeping: t, hits and step counts equal the plain march bit for bit."""
    V, F = datasets.torus(1.0, 0.35, 32, 16)
    g = sdf_grid(V, F, 24)
    M = camera.perspective(40, 1.0, 0.1, 20) @ camera.look_at([0.5, -3.5, 2.0], [0, 0, 0], [0, 0, 1])
    O, D = camera_rays(M, 40, 40)
    for max_steps, t_max in ((64, 8.0), (10, 8.0), (64, 4.0)):
        got = sphere_trace(g, O, D, max_steps=max_steps, eps=1e-4, t_max=t_max)
        want = _plain_sphere_trace(g.sample, O, D, max_steps, 1e-4, t_max)
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a, b)
        t, hit, steps = got
        assert hit.any() and (~hit).any()
        if max_steps == 10:  # some rays run out of budget
            assert np.any(~hit & (steps == 10))
        if t_max == 4.0:  # some rays stop beyond t_max
            assert np.any(~hit & (steps < max_steps))


def test_kernels_run_without_jit():
    """Every compiled kernel also runs as plain Python (NUMBA_DISABLE_JIT=1) and gives the same answer."""
    code = (
        "import json, numpy as np\n"
        "from geomlib import datasets\n"
        "from solutions.sdf import signed_distance\n"
        "V, F = datasets.icosphere(1)\n"
        "P = np.random.default_rng(0).uniform(-1.5, 1.5, size=(6, 3))\n"
        "print(json.dumps({s: signed_distance(V, F, P, sign=s).tolist() for s in ('pseudonormal', 'vote')}))\n"
    )
    got = json.loads(run_python(code, NUMBA_DISABLE_JIT="1"))
    V, F = datasets.icosphere(1)
    P = np.random.default_rng(0).uniform(-1.5, 1.5, size=(6, 3))
    for s, d in got.items():
        np.testing.assert_allclose(d, _igl_pseudo(V, F, P), atol=1e-12, err_msg=s)


def test_bad_input():
    V, F = datasets.icosphere(1)
    with pytest.raises(MeshError, match="sign"):
        signed_distance(V, F, np.zeros((1, 3)), sign="majority")
    with pytest.raises(MeshError, match="res"):
        sdf_grid(V, F, 1)
    with pytest.raises(MeshError, match="band"):
        sdf_grid(V, F, 8, band=0)
    with pytest.raises(MeshError, match="extent"):
        sdf_grid(np.zeros((3, 3)), [[0, 1, 2]], 8)
    with pytest.raises(MeshError):
        signed_distance(V, np.array([[0, 0, 1]]), np.zeros((1, 3)))


def test_zero_area_triangles_give_finite_distances():
    """A sliver with three distinct but collinear corners: distances stay exact (edge regions), the vote still signs."""
    V, F = datasets.icosphere(1)
    V = np.vstack([V, [[2.0, 0, 0], [2.5, 0, 0], [3.0, 0, 0]]])
    F = np.vstack([F, [[len(V) - 3, len(V) - 2, len(V) - 1]]])
    P = _points(V, 300, 13)
    sq, _, _, _ = brute_force_distance(V, F, P)
    sq_i, _, _ = igl.point_mesh_squared_distance(P, V, F)
    np.testing.assert_allclose(sq, sq_i, atol=1e-12)
    d = signed_distance(V, F, P, sign="vote")
    assert np.all(np.isfinite(d))
    np.testing.assert_allclose(np.abs(d), np.sqrt(sq_i), atol=1e-12)
