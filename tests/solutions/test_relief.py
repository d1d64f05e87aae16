"""Cross-checks of the reference solution of the lab "relief".

* the ground truth (:func:`exact_uv`: fine march + bisection) against the real displaced geometry
  (a grid displaced by the height field, drawn by geomlib's rasterizer);
* each method's uv error against the truth at 30/60/75 degrees, on smooth bumps and on bricks:
  secant refinement wins on the smooth map, binary search on the sharp steps;
* bump mapping against the maps lab's normal map of the same height field;
* identities of parallax, offset limiting, the layer count and the shadow march.
"""

from __future__ import annotations

import numpy as np
import pytest

import solutions.maps as maps
import solutions.relief as R
from geomlib import camera, datasets
from geomlib.raster import rasterize

S = 256  # height-map texels
SCALE = 0.08
P = 64  # pixels per side of the uv grid tested


def direction(deg: float, azimuth: float = 0.3) -> np.ndarray:
    t = np.radians(deg)
    return np.array([np.sin(t) * np.cos(azimuth), np.sin(t) * np.sin(azimuth), np.cos(t)])


def uv_grid(p: int = P) -> np.ndarray:
    r, c = np.mgrid[0:p, 0:p]
    return np.stack([(c + 0.5) / p, 1 - (r + 0.5) / p], axis=-1)


MAPS = {"bumps": R.bumps(S), "bricks": R.bricks(S)}


@pytest.fixture(scope="module")
def errors():
    """uv error in texels of each method against the truth: errors[map][angle][method] (p99), [method + " max"]."""
    out = {}
    for name, H in MAPS.items():
        uv = uv_grid(P if name == "bumps" else 2 * P)  # the bricks' sharp bevels cover few pixels
        for deg in (30, 60, 75):
            V = direction(deg)
            truth, _ = R.exact_uv(H, uv, V, scale=SCALE)
            res = {
                "parallax": R.parallax_uv(H, uv, V, scale=SCALE),
                "offset-limited": R.parallax_uv(H, uv, V, scale=SCALE, offset_limit=True),
            }
            for m in R.REFINEMENTS:
                res[m] = R.relief_uv(H, uv, V, scale=SCALE, refine=m)[0]
            e = {k: R.uv_error_texels(x, truth, S) for k, x in res.items()}
            out.setdefault(name, {})[deg] = {k: float(np.percentile(x, 99)) for k, x in e.items()}
            out[name][deg].update({f"{k} max": float(x.max()) for k, x in e.items()})
    return out


@pytest.mark.parametrize("deg", [30, 60, 75])
@pytest.mark.parametrize("name", ["bumps", "bricks"])
def test_truth_matches_the_displaced_geometry(name, deg):
    """Rasterize a grid displaced by the height field; each pixel's ray must hit where exact_uv says."""
    s = 64
    H = R.bumps(s, 2) if name == "bumps" else R.bricks(s)
    Vg, F = datasets.grid_patch(s - 1)
    V = Vg * (s - 1) / s + 0.5 / s  # vertices at the texel centres
    V[:, 2] = -SCALE * (1 - H[::-1].ravel())  # grid row j is texture row s - 1 - j
    d = direction(deg)
    centre = np.array([0.5, 0.5, 0.0])
    M = camera.orthographic(-0.75, 0.75, -0.75, 0.75, 0.1, 10) @ camera.look_at(centre + 4 * d, centre, (0, 0, 1))
    g = rasterize(V, F, M, 96, 96, attributes={"position": V})
    pos = g.attributes["position"][g.mask]
    uv0 = pos[:, :2] - pos[:, 2:3] * d[:2] / d[2]  # where the pixel's ray crosses the polygon z = 0
    inside = np.all((uv0 > 0.1) & (uv0 < 0.9) & (pos[:, :2] > 0.1) & (pos[:, :2] < 0.9), axis=1)
    assert inside.sum() > 400
    truth, depth = R.exact_uv(H, uv0[inside], d, scale=SCALE)
    err = R.uv_error_texels(truth, pos[inside, :2], s)
    # The mesh is piecewise linear, the truth bilinear: they differ by a small fraction of a texel.
    assert np.percentile(err, 99) < 0.1, np.percentile(err, [50, 99])
    assert np.percentile(np.abs(depth + pos[inside, 2]), 99) < 1e-2 * SCALE  # 1% of the relief depth


def test_secant_wins_on_smooth_bumps(errors):
    for deg, e in errors["bumps"].items():
        assert e["secant"] < 1e-6, (deg, e)
        assert e["secant"] < e["binary"] < e["none"] < e["parallax"], (deg, e)
        assert e["linear"] < e["none"], (deg, e)


def test_binary_wins_on_bricks(errors):
    """Bisection halves the bracket whatever the map; a secant step across a bevel's kink can land far off."""
    for deg, e in errors["bricks"].items():
        assert e["binary"] < 0.06, (deg, e)  # 5 bisections of a layer: about 1/64 of a layer
        assert e["binary"] < e["linear"] < e["none"] < e["parallax"], (deg, e)
    e30, e75 = errors["bricks"][30], errors["bricks"][75]
    assert e75["secant"] > 10 * e75["binary"], e75  # p99 at a grazing angle
    assert e30["secant max"] > 10 * e30["binary max"], e30  # the worst pixel at a steep angle


def test_error_grows_with_the_view_angle(errors):
    for name in MAPS:
        for method in ("parallax", "offset-limited", "none", "linear"):
            e = [errors[name][deg][method] for deg in (30, 60, 75)]
            assert e[0] < e[1] < e[2], (name, method, e)


def test_steep_parallax_is_within_one_layer():
    """Without refinement the hit is below the truth, by at most one layer (scale / n) almost everywhere."""
    H = MAPS["bumps"]
    uv = uv_grid(32)
    for deg in (30, 60, 75):
        V = direction(deg)
        n = int(R.layer_count(V[2], 8, 32))
        got, depth, steps = R.relief_uv(H, uv, V, scale=SCALE, refine="none")
        truth, tdepth = R.exact_uv(H, uv, V, scale=SCALE)
        assert np.all(depth >= tdepth - 1e-12)  # the march never stops above the first hit
        # ... and stops within one layer of it unless a thin crest fits between two layers (rare).
        assert np.mean(depth <= tdepth + SCALE / n + 1e-12) > 0.99
        assert np.all(steps <= n) and np.allclose(depth, SCALE * steps / n)


def test_layer_count_follows_the_angle():
    assert R.layer_count(1.0, 8, 32) == 8
    assert R.layer_count(0.0, 8, 32) == 32
    assert R.layer_count(0.5, 8, 32) == 20
    # A map of zeros is hit at the bottom layer: steps = n.
    for deg in (0, 45, 80):
        V = direction(deg)
        _, depth, steps = R.relief_uv(np.zeros((8, 8)), uv_grid(4), V, scale=0.1, refine="none")
        assert np.all(steps == R.layer_count(V[2], 8, 32)) and np.allclose(depth, 0.1)


def test_offset_limiting_caps_the_shift_but_is_not_more_accurate(errors):
    H = MAPS["bricks"]
    uv = uv_grid(16)
    for deg in (30, 60, 75, 85):
        V = direction(deg)
        lim = R.parallax_uv(H, uv, V, scale=SCALE, offset_limit=True)
        par = R.parallax_uv(H, uv, V, scale=SCALE)
        assert np.all(np.linalg.norm(lim - uv, axis=-1) <= SCALE * np.sin(np.radians(deg)) + 1e-12)
        assert np.allclose(par - uv, (lim - uv) / V[2])
    for name in MAPS:
        for deg in (60, 75):
            e = errors[name][deg]
            assert e["offset-limited"] > 0.8 * e["parallax"], (name, deg, e)


def test_bump_normal_is_the_maps_labs_normal_map_at_texel_centres():
    H = R.bricks(32)
    u, v = R.texel_uv(32)
    ours = R.bump_normal(H, np.stack([u, v], axis=-1), strength=0.05)
    theirs = maps.height_to_normal_map(H, 0.05, border="clamp")
    assert np.allclose(ours, theirs, atol=1e-12)
    D = R.bump_offset(H, np.stack([u, v], axis=-1), strength=0.05)
    assert np.allclose(
        ours,
        np.concatenate([-D, np.ones_like(D[..., :1])], -1)
        / np.linalg.norm(np.concatenate([-D, np.ones_like(D[..., :1])], -1), axis=-1, keepdims=True),
    )


def test_shadow_identities():
    H = MAPS["bumps"]
    uv = uv_grid(32)
    hit, depth, _ = R.relief_uv(H, uv, direction(45), scale=SCALE)
    # A light straight above: the ray rises through the air above the hit point.
    assert np.all(R.relief_shadow(H, hit, depth, (0, 0, 1), scale=SCALE) == 1)
    # Points at the polygon (depth 0) are always lit.
    assert np.all(R.relief_shadow(H, hit, np.zeros(depth.shape), direction(80), scale=SCALE) == 1)
    # A grazing light shadows a good part of the bumps, and more than a steep one.
    lit_steep = R.relief_shadow(H, hit, depth, direction(30), scale=SCALE).mean()
    lit_grazing = R.relief_shadow(H, hit, depth, direction(80), scale=SCALE).mean()
    assert lit_grazing < lit_steep and lit_grazing < 0.8


def test_shadow_of_a_wall_by_hand():
    """A wall (h = 1 for u < 1/2, else 0) lit from the -u side at 45 degrees shadows the floor up to scale beyond it."""
    s = 64
    H = np.zeros((s, s))
    H[:, : s // 2] = 1.0
    scale = 0.1
    u = np.array([0.52, 0.58, 0.62, 0.7, 0.9])
    uv = np.stack([u, np.full_like(u, 0.5)], axis=-1)
    light = np.array([-1.0, 0.0, 1.0])  # towards -u, 45 degrees up
    vis = R.relief_shadow(H, uv, np.full(len(u), scale), light, scale=scale, layers=64)
    # The floor point at u sees the light above the wall's top edge (u = 1/2, bilinear: 0.5 + 0.5/s) iff u - 0.5 > scale.
    assert vis.tolist() == [0.0, 0.0, 1.0, 1.0, 1.0]


def test_silhouette_mask():
    uv = np.array([[0.5, 0.5], [-0.01, 0.5], [0.5, 1.2], [1.0, 0.0]])
    assert R.inside_texture(uv).tolist() == [True, False, False, True]


@pytest.mark.parametrize("name", ["bumps", "bricks"])
def test_glsl_shaders_agree_with_numpy(name):
    """The same math in float32 on llvmpipe: 0.05 texel on 99.9% of the pixels, layer indices and shadows too."""
    H = MAPS[name]
    uv = uv_grid(96)
    light = np.array([-0.5, 0.3, 0.6])
    for deg in (30, 75):
        V = direction(deg)
        a, b = R.parallax_uv(H, uv, V, scale=SCALE), R.glsl_parallax_uv(H, uv, V, scale=SCALE)
        assert np.percentile(R.uv_error_texels(a, b, S), 99.9) < 0.05
        for refine in R.REFINEMENTS:
            n_uv, n_depth, n_steps = R.relief_uv(H, uv, V, scale=SCALE, refine=refine)
            g_uv, g_depth, g_steps = R.glsl_relief_uv(H, uv, V, scale=SCALE, refine=refine)
            assert np.percentile(R.uv_error_texels(n_uv, g_uv, S), 99.9) < 0.05, (deg, refine)
            assert np.mean(n_steps == g_steps) >= 0.999 and np.percentile(np.abs(n_depth - g_depth), 99.9) < 1e-4
        vis_n = R.relief_shadow(H, n_uv, n_depth, light, scale=SCALE)
        vis_g = R.glsl_relief_shadow(H, n_uv, n_depth, light, scale=SCALE)
        assert np.mean(vis_n == vis_g) >= 0.999 and 0 < vis_n.mean() < 1


def test_glsl_stub_shader_carries_an_error_directive_naming_its_task():
    """The generated stub shader has an #error line naming the task (glsl.py turns it into NotImplementedError)."""
    from geomlib.grading.stubs import make_stub

    stub = make_stub(R.shader_path("parallax").read_text(), "parallax.frag")
    assert "#error Task 2" in stub


def test_height_at_is_geomlibs_bilinear_clamp_lookup():
    from geomlib.textures import sample_bilinear
    from solutions.relief.inputs import height_at

    H = np.random.default_rng(0).random((16, 16))
    uv = np.random.default_rng(1).uniform(-0.3, 1.3, (500, 2))
    uv[:4] = [[0, 0], [1, 1], [0.5 / 16, 1 - 0.5 / 16], [1 - 0.5 / 16, 0.5]]
    assert np.allclose(height_at(H, uv[:, 0], uv[:, 1]), sample_bilinear(H, uv, "clamp"), atol=1e-15, rtol=0)


@pytest.mark.parametrize("deg", [0.5, 30, 75, 88])
def test_the_exact_march_starts_only_past_samples_above_the_surface(deg):
    """exact_uv starts each pixel's march where the map's highest texels under the ray allow: every
    sample it skips is above the surface (checked one by one), so the hit is the first sample at or below."""
    from solutions.relief.heights import bricks, bumps
    from solutions.relief.inputs import height_lookup
    from solutions.relief.truth import _first_sample

    rng = np.random.default_rng(int(deg))
    m = 512
    skipped = 0
    for H in (bumps(64), bricks(64), rng.random((32, 32)) * 0.7):
        uv = rng.random((300, 2)) * 1.2 - 0.1  # also outside [0, 1] (clamped reads)
        V = direction(deg, azimuth=rng.uniform(0, 2 * np.pi))
        du = np.full(300, -SCALE * V[0] / V[2])
        dv = np.full(300, -SCALE * V[1] / V[2])
        start = _first_sample(H, uv[:, 0], uv[:, 1], du, dv, m)
        h = height_lookup(H)
        j = np.arange(m + 1)
        d = j / m
        f = d - (1.0 - h(uv[:, :1] + d * du[:, None], uv[:, 1:] + d * dv[:, None]))
        first = np.argmax(f >= 0, axis=1)
        assert (start <= first).all(), f"the march would skip the hit at sample {first[start > first][0]}"
        skipped += int(start.sum())
    assert skipped > 0 or deg > 80, "no sample skipped: the start bound does nothing"
