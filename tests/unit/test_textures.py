"""Tests for geomlib.textures: lookups against scipy.ndimage, coverage against areas, padding by hand."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from geomlib import datasets
from geomlib.textures import dilate, rasterize_uv, sample_bilinear, triangle_atlas, weld_by_position
from geomlib.validate import MeshError


def texel_centres(h: int, w: int) -> np.ndarray:
    """(h, w, 2) UV of every texel centre, by the convention of the module docstring."""
    r, c = np.mgrid[0:h, 0:w]
    return np.stack([(c + 0.5) / w, 1.0 - (r + 0.5) / h], axis=-1)


# --------------------------------------------------------------------------------------------
# sample_bilinear


def test_texel_centres_return_texel_values():
    rng = np.random.default_rng(0)
    img = rng.random((5, 7, 3))
    got = sample_bilinear(img, texel_centres(5, 7))
    np.testing.assert_allclose(got, img, atol=1e-12)


def test_v_points_up_row_zero_is_the_top():
    img = np.array([[10.0, 20.0], [30.0, 40.0]])
    # Upper-left quarter of UV space (u small, v large) is row 0, column 0.
    assert sample_bilinear(img, [0.25, 0.75]) == pytest.approx(10.0)
    assert sample_bilinear(img, [0.75, 0.25]) == pytest.approx(40.0)


def test_matches_scipy_map_coordinates_clamp_and_repeat():
    rng = np.random.default_rng(1)
    img = rng.random((9, 13))
    uv = rng.uniform(-0.3, 1.3, size=(500, 2))
    x = uv[:, 0] * 13 - 0.5
    y = (1 - uv[:, 1]) * 9 - 0.5
    ref_clamp = ndimage.map_coordinates(img, [y, x], order=1, mode="nearest")
    np.testing.assert_allclose(sample_bilinear(img, uv, wrap="clamp"), ref_clamp, atol=1e-12)
    ref_wrap = ndimage.map_coordinates(img, [y, x], order=1, mode="grid-wrap")
    np.testing.assert_allclose(sample_bilinear(img, uv, wrap="repeat"), ref_wrap, atol=1e-12)


def test_bilinear_reproduces_a_linear_ramp_inside():
    h, w = 6, 8
    C = texel_centres(h, w)
    img = 2.0 * C[..., 0] - 3.0 * C[..., 1] + 0.5  # linear in (u, v)
    rng = np.random.default_rng(2)
    uv = rng.uniform([0.5 / w, 0.5 / h], [1 - 0.5 / w, 1 - 0.5 / h], size=(200, 2))
    np.testing.assert_allclose(sample_bilinear(img, uv), 2.0 * uv[:, 0] - 3.0 * uv[:, 1] + 0.5, atol=1e-12)


def test_repeat_has_period_one():
    rng = np.random.default_rng(3)
    img = rng.random((4, 4, 2))
    uv = rng.random((50, 2))
    np.testing.assert_allclose(
        sample_bilinear(img, uv + [1.0, -2.0], wrap="repeat"), sample_bilinear(img, uv, wrap="repeat"), atol=1e-12
    )


def test_output_shape_follows_uv_and_channels():
    img = np.zeros((4, 4, 3), np.uint8)
    assert sample_bilinear(img, np.zeros((2, 5, 2))).shape == (2, 5, 3)
    assert sample_bilinear(img[..., 0], np.zeros((7, 2))).shape == (7,)


@pytest.mark.parametrize(
    ("image", "uv", "wrap", "match"),
    [
        (np.zeros(4), [0.5, 0.5], "clamp", "expected an image"),
        (np.zeros((4, 4)), [0.5, 0.5, 0.5], "clamp", r"expected \(\.\.\., 2\)"),
        (np.zeros((4, 4)), [np.nan, 0.5], "clamp", "non-finite|finite"),
        (np.zeros((4, 4)), [0.5, 0.5], "mirror", "wrap must be one of"),
    ],
)
def test_sample_bilinear_bad_input(image, uv, wrap, match):
    with pytest.raises(MeshError, match=match):
        sample_bilinear(image, uv, wrap=wrap)


# --------------------------------------------------------------------------------------------
# rasterize_uv


def test_two_triangles_cover_the_square_once():
    F = np.array([[0, 1, 2], [0, 2, 3]])
    UV = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    fid, bary = rasterize_uv(F, UV, 16)
    assert (fid >= 0).all()
    C = texel_centres(16, 16)
    # Texels strictly below the diagonal u = v belong to face 0, strictly above to face 1.
    assert (fid[C[..., 1] < C[..., 0] - 1e-9] == 0).all()
    assert (fid[C[..., 1] > C[..., 0] + 1e-9] == 1).all()
    # Barycentrics reproduce the texel centre.
    rec = np.einsum("hwi,hwij->hwj", bary, UV[F[fid]])
    np.testing.assert_allclose(rec, C, atol=1e-9)
    np.testing.assert_allclose(bary.sum(axis=2), 1.0, atol=1e-12)


def test_coverage_matches_uv_area():
    V, F, UV = datasets.uv_torus(12, 6)
    fid, _ = rasterize_uv(F, UV, 128)
    # The torus charts tile the unit square exactly: every texel is covered.
    assert (fid >= 0).all()
    tri = np.array([[0, 1, 2]])
    UVt = np.array([[0.1, 0.1], [0.9, 0.2], [0.3, 0.8]])
    fid, _ = rasterize_uv(tri, UVt, 256)
    area = 0.5 * abs((0.8 * 0.7) - (0.2 * 0.1))  # |(b - a) x (c - a)| / 2 by hand = 0.27
    assert (fid == 0).mean() == pytest.approx(area, rel=0.01)


def test_uncovered_texels_and_non_square_size():
    fid, bary = rasterize_uv([[0, 1, 2]], [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]], (4, 8))
    assert fid.shape == (4, 8) and bary.shape == (4, 8, 3)
    assert fid[0, 7] == -1 and (bary[0, 7] == 0).all()
    assert fid[3, 0] == 0


@pytest.mark.parametrize(
    ("F", "UV", "size", "match"),
    [
        ([[0, 1, 3]], [[0, 0], [1, 0], [0, 1]], 8, "uses vertex 3"),
        ([[0, 1, 2]], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], 8, r"UV has shape \(3, 3\)"),
        ([[0, 1, 2]], [[0, 0], [1, 0], [0, 1]], 0, "size must be >= 1"),
        ([[0, 1, 2]], [[0, 0], [1, 0], [0, 1]], "big", "size must be an int"),
    ],
)
def test_rasterize_uv_bad_input(F, UV, size, match):
    with pytest.raises(MeshError, match=match):
        rasterize_uv(F, UV, size)


# --------------------------------------------------------------------------------------------
# dilate


def test_dilate_grows_like_binary_dilation_and_averages():
    rng = np.random.default_rng(4)
    img = rng.random((20, 20, 2))
    mask = np.zeros((20, 20), bool)
    mask[5:8, 6:9] = True
    mask[14, 3] = True
    out, grown = dilate(img, mask, 2, return_mask=True)
    ref = ndimage.binary_dilation(mask, structure=np.ones((3, 3)), iterations=2)
    np.testing.assert_array_equal(grown, ref)
    np.testing.assert_array_equal(out[mask], img[mask])  # covered texels untouched
    # Texel (14, 4) touches only (14, 3) among covered texels after one step: same value.
    np.testing.assert_allclose(out[14, 4], img[14, 3])
    # Texel (4, 7) touches (5, 6), (5, 7), (5, 8): their mean.
    np.testing.assert_allclose(out[4, 7], img[5, 6:9].mean(axis=0))
    far = ~ref
    np.testing.assert_array_equal(out[far], img[far])


def test_dilate_none_fills_everything_and_zero_iterations_is_identity():
    img = np.zeros((5, 6))
    img[2, 3] = 7.0
    mask = img > 0
    assert (dilate(img, mask) == 7.0).all()
    np.testing.assert_array_equal(dilate(img, mask, 0), img)
    empty = np.zeros((3, 3), bool)
    np.testing.assert_array_equal(dilate(np.ones((3, 3)), empty), np.ones((3, 3)))


@pytest.mark.parametrize(
    ("mask", "iterations", "match"),
    [
        (np.zeros((4, 5), bool), 1, r"mask has shape \(4, 5\)"),
        (np.zeros((4, 4), int), 1, "expected bool"),
        (np.zeros((4, 4), bool), -1, "iterations must be >= 0"),
    ],
)
def test_dilate_bad_input(mask, iterations, match):
    with pytest.raises(MeshError, match=match):
        dilate(np.zeros((4, 4)), mask, iterations)


# --------------------------------------------------------------------------------------------
# weld_by_position and triangle_atlas


def test_weld_groups_the_seam_copies_of_a_uv_sphere():
    V, F, UV = datasets.uv_sphere(8, 12)
    g, k = weld_by_position(V)
    # Distinct positions: 2 poles + 7 rings of 12 (the seam column repeats column 0).
    assert k == 2 + 7 * 12
    assert g[0] == g[11]  # all north-pole copies together
    assert len(np.unique(np.round(V[g == g[12 + 0]], 12), axis=0)) == 1
    assert g.min() == 0 and g.max() == k - 1


def test_triangle_atlas_keeps_shapes_and_stays_in_the_unit_square():
    V, F = datasets.icosphere(1)
    Vs, Fs, UV, src = triangle_atlas(V, F, gutter=0.05)
    np.testing.assert_array_equal(Vs, V[src])
    assert UV.min() >= 0 and UV.max() <= 1
    # One similarity for all charts: UV edge lengths / 3-D edge lengths is a single constant.
    e3 = np.linalg.norm(Vs[Fs[:, [1, 2, 0]]] - Vs[Fs], axis=2)
    e2 = np.linalg.norm(UV[Fs[:, [1, 2, 0]]] - UV[Fs], axis=2)
    ratio = e2 / e3
    np.testing.assert_allclose(ratio, ratio.mean(), rtol=1e-9)
    # Counter-clockwise in UV (positive signed area) for every face.
    a, b, c = UV[Fs[:, 0]], UV[Fs[:, 1]], UV[Fs[:, 2]]
    signed2 = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert (signed2 > 0).all()
    # Charts do not overlap: texel coverage equals the summed chart areas.
    fid, _ = rasterize_uv(Fs, UV, 512)
    assert (fid >= 0).mean() == pytest.approx(0.5 * signed2.sum(), rel=0.02)


def test_triangle_atlas_fill_mode_gives_every_triangle_half_a_cell():
    V, F = datasets.rock_on_plinth(16)
    _, Fs, UV, _ = triangle_atlas(V, F, gutter=0.0, mode="fill")
    k = int(np.ceil(np.sqrt(len(F))))
    rows = int(np.ceil(len(F) / k))
    a, b, c = UV[Fs[:, 0]], UV[Fs[:, 1]], UV[Fs[:, 2]]
    signed2 = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    # Corners (0, 0), (1, 0), (x, 1) in cell units of a k x rows grid: area 1/2 cell, counter-clockwise.
    np.testing.assert_allclose(signed2, 1.0 / (k * rows), rtol=1e-9)
    assert UV.min() >= 0 and UV.max() <= 1
    with pytest.raises(MeshError, match="mode must be one of"):
        triangle_atlas(V, F, mode="pack")
