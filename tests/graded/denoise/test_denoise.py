"""Graded tests of the denoise lab.

Two kinds: ``test_references`` compares with stored reference outputs on realistic meshes (see
``cases.py``); the tests below use tiny meshes whose answers are worked out by hand in the
docstrings and comments, identities any correct implementation satisfies, the denoising
threshold the lab promises, and bad input. Expected values never come from running a solution
at test time.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, topology
from geomlib.geometry import mean_edge_length, vertex_normals
from geomlib.grading import expect_close, graded, reference_tests
from geomlib.grading.cases import hidden_cases, stored_input
from geomlib.grading.checks import Context
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture
from geomlib.textures import rasterize_uv

from ..common import expect_rejected, expect_true
from .cases import CASES
from .support import (
    PYRAMID_F,
    PYRAMID_V,
    REG_TET_F,
    REG_TET_V,
    RIGHT_F,
    RIGHT_V,
    SPLIT_F,
    SPLIT_UV,
    SPLIT_V,
    copy_spread,
    noisy,
    random_map,
    seam_groups,
    surface_error,
    weld_check,
)

test_references = reference_tests(CASES)

UP = np.array([0.0, 0.0, 1.0])


def noisy_cut(V, F, seed: int):
    """A noisy UV-cut mesh ``Vn``, its normals computed on the cut (the copies of a seam vertex get
    different normals) and the seam group of every vertex."""
    Vn, _ = noisy(V, F, 0.3, seed)
    return Vn, vertex_normals(Vn, F), seam_groups(V)


def expect_closed_seams(label: str, X, group, advice: str) -> None:
    """The copies of every seam vertex stay together in ``X`` (within 1e-12)."""
    spread = copy_spread(X, group)
    expect_true(label, spread < 1e-12, f"seam copies are {spread:.3g} apart: {advice}")


# --------------------------------------------------------------------------------------------
# Task 1: Laplacian offsets


@graded(points=2, part="offsets")
def test_pyramid_uniform_offsets(lab):
    """pyramid: apex minus the mean of its 4 base neighbours; base corners minus the mean of 3 neighbours"""
    d = lab.laplacian_offsets(PYRAMID_V, PYRAMID_F, "uniform", weld=False)
    # apex (0,0,1): neighbours are the 4 base corners, mean (0,0,0) -> delta (0,0,1).
    # corner (1,0,0): neighbours apex (0,0,1), (0,1,0), (0,-1,0); mean (0,0,1/3) -> delta (1,0,-1/3).
    expected = [[0, 0, 1], [1, 0, -1 / 3], [0, 1, -1 / 3], [-1, 0, -1 / 3], [0, -1, -1 / 3]]
    expect_close(
        "laplacian_offsets on the pyramid", d, expected, atol=1e-12, name="delta",
        hint="each neighbour counts once, even when two triangles share the edge", mesh=(PYRAMID_V, PYRAMID_F),
    )  # fmt: skip


@graded(points=1, part="offsets")
def test_right_triangle_cotan_offsets(lab):
    """right triangle: cot 90 = 0 cuts the hypotenuse, so corner 1's weighted mean is corner 0"""
    d = lab.laplacian_offsets(RIGHT_V, RIGHT_F, "cotan", weld=False)
    # w_01 = cot(45)/2 = 1/2 (angle at 2), w_02 = 1/2 (angle at 1), w_12 = cot(90)/2 = 0 (angle at 0).
    # corner 0: (p1 + p2)/2 = (1/2, 1/2, 0) -> delta (-1/2, -1/2, 0); corner 1: mean p0 -> delta (1, 0, 0).
    expected = [[-0.5, -0.5, 0], [1, 0, 0], [0, 1, 0]]
    expect_close(
        "laplacian_offsets(weights='cotan') on a right triangle", d, expected, atol=1e-12, name="delta",
        hint="w_ij = (cot alpha + cot beta)/2 with the angles OPPOSITE the edge ij; one angle on a boundary edge",
        mesh=(RIGHT_V, RIGHT_F),
    )  # fmt: skip


@graded(points=1, part="offsets")
def test_regular_tetrahedron_cotan_equals_uniform(lab):
    """regular tetrahedron: all weights equal, delta_i = p_i - mean of the others = 4/3 p_i"""
    for w in ("uniform", "cotan"):
        d = lab.laplacian_offsets(REG_TET_V, REG_TET_F, w, weld=False)
        # the vertices sum to 0, so the mean of the other three is -p_i / 3
        label = f"laplacian_offsets(weights={w!r}) on a regular tetrahedron"
        expect_close(label, d, 4 / 3 * REG_TET_V, atol=1e-12, name="delta", mesh=(REG_TET_V, REG_TET_F))


@graded(points=1, part="offsets")
def test_flat_meshes_have_zero_interior_offsets(lab):
    """flat meshes: uniform offsets vanish on a regular grid, cotan offsets on any flat mesh (interior)"""
    V, F = datasets.grid_patch(6)
    interior = np.ones(len(V), bool)
    interior[topology.boundary_edges(F).ravel()] = False
    d = np.asarray(lab.laplacian_offsets(V, F, "uniform", weld=False))
    expect_close(
        "laplacian_offsets on a regular flat grid (interior vertices)",
        d[interior],
        0 * V[interior],
        atol=1e-12,
        mesh=(V, F, interior),
    )
    Vj = V.copy()
    Vj[interior, :2] += np.random.default_rng(3).uniform(-0.03, 0.03, size=(interior.sum(), 2))
    d = np.asarray(lab.laplacian_offsets(Vj, F, "cotan", weld=False))
    expect_close(
        "laplacian_offsets(weights='cotan') on a jittered flat grid (interior vertices)", d[interior], 0 * V[interior],
        atol=1e-10, hint="cotangent weights reproduce linear functions exactly: on a plane the weighted mean is the vertex",
        mesh=(Vj, F, interior),
    )  # fmt: skip
    # On the boundary the neighbours lie on one side: at a corner of the grid their mean is half an
    # edge away or more, with either weighting.
    corner = np.argmin(V[:, 0] + V[:, 1])
    h = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).min()
    for weights, W in (("uniform", V), ("cotan", Vj)):
        d = np.asarray(lab.laplacian_offsets(W, F, weights, weld=False))
        expect_true(
            f"laplacian_offsets(weights={weights!r}) at the grid's corner",
            np.linalg.norm(d[corner]) > 0.4 * h,
            f"the corner's offset is {np.linalg.norm(d[corner]):.3g}, expected at least half an edge ({0.5 * h:.3g}): "
            "delta = p - the weighted mean of its neighbours, which all lie on one side of a corner",
        )


# --------------------------------------------------------------------------------------------
# Task 2: projection on the normals


@graded(points=1, part="projection on normals")
def test_projection_by_hand(lab):
    """s_i = <delta_i, n_i>: (1,2,3).(0,0,1) = 3 and (0.5,0,-1).(0.6,0,0.8) = -0.5"""
    s = lab.normal_offsets([[1.0, 2.0, 3.0], [0.5, 0.0, -1.0]], [[0.0, 0.0, 2.0], [3.0, 0.0, 4.0]])
    expect_close(
        "normal_offsets", s, [3.0, -0.5], atol=1e-12, name="s", hint="one dot product per row; N arrives normalised"
    )


# --------------------------------------------------------------------------------------------
# Task 3: direct denoising


@graded(points=2, part="direct denoising")
def test_pyramid_denoise_by_hand(lab):
    """pyramid with normals (0,0,1), lambda = 1/2: the apex drops by 1/2, the base corners rise by 1/6"""
    N = np.tile(UP, (5, 1))
    X = lab.denoise_vertices(PYRAMID_V, PYRAMID_F, N, 0.5, weld=False)
    # s = (1, -1/3, -1/3, -1/3, -1/3) (z of the uniform offsets); p' = p - 0.5 s (0,0,1)
    expected = PYRAMID_V + np.outer([-0.5, 1 / 6, 1 / 6, 1 / 6, 1 / 6], UP)
    expect_close(
        "denoise_vertices on the pyramid, lam=0.5",
        X,
        expected,
        atol=1e-12,
        name="V'",
        hint="p' = p - lam s n",
        mesh=(PYRAMID_V, PYRAMID_F),
    )


@graded(points=1, part="direct denoising")
def test_lambda_zero_changes_nothing(lab):
    """lambda = 0 returns the input positions"""
    V, F = datasets.icosphere(2)
    Vn, N = noisy(V, F, 0.3, 1)
    X = lab.denoise_vertices(Vn, F, N, 0.0, weld=False)
    expect_close("denoise_vertices(lam=0)", X, Vn, atol=0.0, name="V'", mesh=(Vn, F))
    X = np.asarray(lab.denoise_vertices(Vn, F, N, 0.5, weld=False), float)
    expect_true("denoise_vertices(lam=0.5)", np.abs(X - Vn).max() > 1e-3,
                "with lam = 0.5 the noisy vertices should move (p' = p - lam s n)")  # fmt: skip


@graded(points=1, part="direct denoising")
def test_vertices_move_along_their_normals(lab):
    """every vertex moves along its own normal only (the tangential part of delta is dropped)"""
    V, F = datasets.icosphere(3)
    Vn, N = noisy(V, F, 0.3, 2)
    D = np.asarray(lab.denoise_vertices(Vn, F, N, 0.7, weights="cotan", weld=False)) - Vn
    expect_close(
        "cross(V' - V, N) after denoise_vertices", np.cross(D, N), 0 * D, atol=1e-12,
        hint="move by s_i n_i, not by delta_i", mesh=(Vn, F),
    )  # fmt: skip
    expect_true("denoise_vertices(lam=0.7)", np.abs(D).max() > 1e-3,
                "the noisy vertices should move (p' = p - lam s n); they stayed where they were")  # fmt: skip


@graded(points=1, part="direct denoising")
def test_iterations_repeat_the_pass(lab):
    """iterations=2 gives the same as two calls with iterations=1, and the second pass moves the vertices again"""
    V, F = datasets.torus(n_major=24, n_minor=12)
    Vn, N = noisy(V, F, 0.3, 3)
    once = np.asarray(lab.denoise_vertices(Vn, F, N, 0.3, weld=False), float)
    twice = lab.denoise_vertices(once, F, N, 0.3, weld=False)
    if np.shape(twice) != Vn.shape or not np.abs(np.asarray(twice, float) - once).max() > 1e-6:
        raise Mismatch(
            "denoise_vertices: a second pass on the once-denoised torus should move its vertices again "
            "(its offsets are not zero yet); it returned the same positions"
        )
    expect_close(
        "denoise_vertices(iterations=2)", lab.denoise_vertices(Vn, F, N, 0.3, iterations=2, weld=False), twice, atol=1e-12,
        hint="recompute delta from the moved vertices in every iteration, with the same normals", mesh=(Vn, F),
    )  # fmt: skip


@graded(points=2, part="direct denoising")
def test_one_pass_cuts_the_mean_error(lab):
    """one pass at lambda = 0.7 brings the mean error on a noisy sphere and torus down to at most 0.6x"""
    for name, (V, F) in (("icosphere(4)", datasets.icosphere(4)), ("torus()", datasets.torus())):
        Vn, N = noisy(V, F, 0.3, 0)
        before = surface_error(V, F, Vn).mean()
        after = surface_error(V, F, np.asarray(lab.denoise_vertices(Vn, F, N, 0.7, weld=False))).mean()
        expect_true(
            f"denoise_vertices on a noisy {name}", after <= 0.6 * before,
            f"the mean distance to the clean surface went from {before:.3g} to {after:.3g} ({after / before:.2f}x); "
            "a correct pass reaches about 0.5x",
        )  # fmt: skip


# --------------------------------------------------------------------------------------------
# Task 4: baking


def _uv_square():
    V, F, UV = datasets.uv_grid(1)  # the unit square, two triangles
    return V, F, UV


@graded(points=2, part="baking the map")
def test_bake_a_linear_function_by_hand(lab):
    """s = u + 2v on a square: texels hold (u + 2v)/3 at their centres, quantised; bias 0, scale 3"""
    V, F, UV = _uv_square()
    s = UV[:, 0] + 2 * UV[:, 1]
    c = (np.arange(4) + 0.5) / 4  # texel centres; row 0 is v = 7/8 (the top)
    h = (c[None, :] + 2 * c[::-1, None]) / 3  # linear inside every triangle, so exact at any centre
    for bits, dtype in ((16, np.uint16), (8, np.uint8)):
        image, bias, scale = lab.bake_offset_map(V, F, UV, s, 4, bits)
        label = f"bake_offset_map(size=4, bits={bits}) of s = u + 2v"
        expect_true(
            label,
            isinstance(image, np.ndarray) and image.dtype == dtype,
            f"image should be a {np.dtype(dtype).name} array, got {getattr(image, 'dtype', type(image).__name__)}",
        )
        expect_close(
            label,
            [bias, scale],
            [0.0, 3.0],
            atol=1e-12,
            name="(bias, scale)",
            hint="bias = min s, scale = max s - min s",
        )
        expect_close(
            label,
            image,
            np.round(h * np.iinfo(dtype).max),  # worked out above: h at the texel centres, in integer levels
            atol=1.0,
            name="image",
            hint="row 0 of the image is the TOP of UV space (v near 1)",
        )


@graded(points=1, part="baking the map")
def test_bake_pads_beyond_the_charts(lab):
    """two UV charts with empty space between them: padding fills the empty texels, padding=0 leaves them 0"""
    s = np.array([0.1, -0.2, 0.3, -0.2, 0.3, 0.05])
    face_id, _ = rasterize_uv(SPLIT_F, SPLIT_UV, 32)
    empty = face_id < 0
    img0, _, _ = lab.bake_offset_map(SPLIT_V, SPLIT_F, SPLIT_UV, s, 32, 16, padding=0)
    img, _, _ = lab.bake_offset_map(SPLIT_V, SPLIT_F, SPLIT_UV, s, 32, 16, padding=None)
    img0, img = np.asarray(img0), np.asarray(img)
    expect_true("bake_offset_map(padding=0)", not img0[empty].any(), "texels outside every UV triangle should stay 0")
    expect_close(
        "bake_offset_map(padding=None) on the covered texels", img[~empty], img0[~empty], atol=0.0, name="image"
    )
    zeros = int((img == 0).sum())
    expect_true(
        "bake_offset_map(padding=None)", zeros <= int((img0[~empty] == 0).sum()),
        f"{zeros} texels are still 0: pad with geomlib.textures.dilate(h, covered, padding) before quantising",
    )  # fmt: skip


@graded(points=1, part="baking the map")
def test_constant_offsets_give_zero_scale(lab):
    """all offsets equal: bias = that offset, scale = 0, and the image is all zeros"""
    V, F, UV = _uv_square()
    image, bias, scale = lab.bake_offset_map(V, F, UV, np.full(4, 0.25), 8, 16)
    expect_close("bake_offset_map with constant s", [bias, scale], [0.25, 0.0], atol=0.0, name="(bias, scale)")
    expect_true(
        "bake_offset_map with constant s",
        not np.asarray(image).any(),
        "h = 0 everywhere when scale = 0 (do not divide by 0)",
    )


# --------------------------------------------------------------------------------------------
# Task 5: the map route


def _five_points():
    """A flat fan: centre (1/2, 1/2) and the 4 texel centres of a 2 x 2 map; UV = xy."""
    UV = np.array([[0.5, 0.5], [0.25, 0.75], [0.25, 0.25], [0.75, 0.25], [0.75, 0.75]])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    return np.column_stack([UV, np.zeros(5)]), F, UV


@graded(points=2, part="denoising through the map")
def test_map_lookup_by_hand(lab):
    """2 x 2 map: texel centres read their texel, the middle reads the mean of all four"""
    V, F, UV = _five_points()
    image = np.array([[0.0, 1.0], [2.0, 3.0]]) / 3  # row 0 is the top (v = 3/4)
    X = lab.denoise_with_map(V, F, UV, np.tile(UP, (5, 1)), image, 0.0, 3.0, 1.0, weld=False)
    # s = 3 h: centre 1.5; (1/4, 3/4) -> texel [0, 0] = 0; (1/4, 1/4) -> [1, 0] = 2; (3/4, 1/4) -> 3; (3/4, 3/4) -> 1
    expect_close(
        "denoise_with_map on a 2x2 map (z of the result)", np.asarray(X)[:, 2], [-1.5, 0.0, -2.0, -3.0, -1.0], atol=1e-12,
        name="z", hint="bilinear lookup with geomlib.textures.sample_bilinear (row 0 = v near 1); p' = p - lam s n",
        mesh=(V, F),
    )  # fmt: skip


@graded(points=1, part="denoising through the map")
def test_integer_maps_are_decoded(lab):
    """uint8 code q reads as h = q/255 (255 as h = 1), uint16 32768 as h = 32768/65535"""
    V, F, UV = _five_points()
    N = np.tile(UP, (5, 1))
    X8 = lab.denoise_with_map(V, F, UV, N, np.full((4, 4), 255, np.uint8), 0.1, 0.2, 1.0, weld=False)
    expect_close(
        "denoise_with_map with a uint8 map of 255",
        np.asarray(X8)[:, 2],
        np.full(5, -0.3),
        atol=1e-12,
        name="z",
        mesh=(V, F),
    )
    # A 2 x 2 uint8 map of different codes, read at its texel centres and in the middle: h = [[0, 1], [0.4, 0.2]],
    # s = 0.1 + 0.2 h: centre 0.1 + 0.2 * 0.4 = 0.18; (1/4, 3/4) -> [0, 0]: 0.1; (1/4, 1/4) -> [1, 0]: 0.18;
    # (3/4, 1/4) -> [1, 1]: 0.14; (3/4, 3/4) -> [0, 1]: 0.3.
    codes = np.array([[0, 255], [102, 51]], np.uint8)
    X8 = lab.denoise_with_map(V, F, UV, N, codes, 0.1, 0.2, 1.0, weld=False)
    expect_close(
        "denoise_with_map with the uint8 map [[0, 255], [102, 51]]",
        np.asarray(X8)[:, 2],
        [-0.18, -0.1, -0.18, -0.14, -0.3],
        atol=1e-12,
        name="z",
        hint="each vertex reads its own h = q / 255 from the map (bilinear lookup); p' = p - lam (bias + scale h) n",
        mesh=(V, F),
    )
    X16 = lab.denoise_with_map(V, F, UV, N, np.full((4, 4), 32768, np.uint16), 0.0, 1.0, 0.5, weld=False)
    expect_close(
        "denoise_with_map with a uint16 map",
        np.asarray(X16)[:, 2],
        np.full(5, -0.5 * 32768 / 65535),
        atol=1e-12,
        name="z",
        mesh=(V, F),
    )


@graded(points=1, part="denoising through the map")
def test_linear_map_is_read_exactly_inside(lab):
    """a map that is linear in (u, v) is read exactly (up to its quantisation) away from the border"""
    # The map of s = 1/4 + u/2 + v/4 (uint16, 32 x 32), baked by the solution's bake_offset_map and
    # stored by `geomlib refs build` (see STORED in cases.py): reading it back must give s again.
    m = stored_input("denoise", "map-linear-32")
    image, bias, scale = m["image"], float(m["bias"]), float(m["scale"])
    V, F, UV = datasets.uv_grid(8)
    UV = 0.05 + 0.9 * UV  # stay inside the outermost texel centres
    X = lab.denoise_with_map(V, F, UV, np.tile(UP, (len(V), 1)), image, bias, scale, 1.0, weld=False)
    expected = -(0.25 + 0.5 * UV[:, 0] + 0.25 * UV[:, 1])
    expect_close(
        "denoise_with_map on a linear map", np.asarray(X)[:, 2], expected, atol=scale / 65535, name="z", mesh=(V, F)
    )


@graded(points=1, part="denoising through the map")
def test_map_route_matches_direct_route(lab):
    """bake s = <delta, n>, then denoise through the map: close to the direct route (needs Tasks 1-4 too)"""
    V, F, UV = datasets.uv_torus(32, 16)
    Vn, N = noisy(V, F, 0.3, 0)
    s = lab.normal_offsets(lab.laplacian_offsets(Vn, F, weld=False), N)
    image, bias, scale = lab.bake_offset_map(Vn, F, UV, s, 512, 16)
    Xm = np.asarray(lab.denoise_with_map(Vn, F, UV, N, image, bias, scale, 0.7, weld=False))
    Xd = np.asarray(lab.denoise_vertices(Vn, F, N, 0.7, weld=False))
    gap = float(np.linalg.norm(Xm - Xd, axis=1).max())
    # a texel holds s up to the slope of s times a texel diagonal; the reference solution reaches 0.028 scale here
    label = "denoise_with_map after bake_offset_map(size=512)"
    if not gap <= 0.7 * 0.05 * float(scale):
        raise Mismatch(
            f"{label}: the map route differs from denoise_vertices by up to {gap:.3g} (scale {float(scale):.3g}); check "
            "that the lookup undoes the bake (s = bias + scale h, with the bias and scale bake_offset_map returned) and that "
            "both use the same texel convention (row 0 = v near 1, texel centres at (col + 1/2) / size)",
            failure_picture(
                label, Xm, Xd, name="map route - direct route", mesh=(Vn, F), atol=0.7 * 0.05 * float(scale)
            ),
        )


# --------------------------------------------------------------------------------------------
# Task 6: the seam fix


@graded(points=1, part="seam fix")
def test_weld_by_hand(lab):
    """two triangles cut apart in UV: vertices 3 and 4 copy 1 and 2, so 4 groups remain (also with tol)"""
    out = lab.weld_seams(SPLIT_V, SPLIT_F)
    expected = {
        "Vw": SPLIT_V[[0, 1, 2, 5]],
        "Fw": np.array([[0, 1, 2], [1, 3, 2]]),
        "group": np.array([0, 1, 2, 1, 2, 3]),
    }
    if not isinstance(out, tuple | list) or len(out) != 3:
        raise Mismatch("weld_seams should return three values (Vw, Fw, group)")
    msg = weld_check().fn(expected, dict(zip(("Vw", "Fw", "group"), out, strict=True)), Context(label="weld_seams"))
    expect_true("weld_seams on two triangles cut along their shared edge", msg is None, str(msg))
    # With tol: copies that an exporter wrote 1e-4 apart are joined the same way (each group keeps the
    # position of its first member).
    Vt = SPLIT_V.astype(float)
    Vt[3] += [1e-4, 0.0, 0.0]
    Vt[4] += [0.0, -1e-4, 0.0]
    out = lab.weld_seams(Vt, SPLIT_F, tol=1e-3)
    if not isinstance(out, tuple | list) or len(out) != 3:
        raise Mismatch("weld_seams(tol=1e-3) should return three values (Vw, Fw, group)")
    expected["Vw"] = Vt[[0, 1, 2, 5]]
    msg = weld_check().fn(expected, dict(zip(("Vw", "Fw", "group"), out, strict=True)), Context(label="weld_seams"))
    expect_true("weld_seams(tol=1e-3) with copies 1e-4 apart", msg is None, str(msg))


@graded(points=1, part="seam fix")
def test_seam_mean_by_hand(lab):
    """means over groups: group 0 = {1, 4} -> 2.5, group 1 = {2, 8} -> 5"""
    expect_close("seam_mean", lab.seam_mean([1.0, 2.0, 4.0, 8.0], [0, 1, 0, 1]), [2.5, 5.0], atol=1e-12, name="mean")
    expect_close(
        "seam_mean of (n, 2) values",
        lab.seam_mean([[1.0, 0], [3, 2]], [1, 1]),
        [[0, 0], [2, 1]],
        atol=1e-12,
        name="mean",
    )


@graded(points=1, part="seam fix")
def test_welded_uv_sphere_is_closed(lab):
    """welding the UV sphere (16 x 32) leaves 2 poles + 15 rings of 32 vertices, a closed genus-0 mesh"""
    V, F, _ = datasets.uv_sphere(16, 32)
    Vw, Fw, group = lab.weld_seams(V, F)
    expect_true("weld_seams on uv_sphere(16, 32)", len(Vw) == 482, f"expected 482 vertices, got {len(Vw)}")
    Fw = np.asarray(Fw)
    expect_true(
        "weld_seams on uv_sphere(16, 32)", topology.is_closed(Fw) and topology.euler_characteristic(Fw) == 2,
        "the welded faces should close the sphere (every edge in two faces, V - E + F = 2); Fw = group[F]",
    )  # fmt: skip


@graded(points=1, part="seam fix", tasks=(1, 6))  # weld=True runs Task 6's weld_seams
def test_welded_offsets_match_the_seamless_torus(lab):
    """laplacian_offsets(weld=True) on the cut UV torus equals the offsets of the seamless torus (needs Task 1)"""
    Vu, Fu, _ = datasets.uv_torus(24, 12)
    Vt, Ft = datasets.torus(n_major=24, n_minor=12)
    Vn, _ = noisy(Vt, Ft, 0.3, 0)
    from scipy.spatial import cKDTree

    _, idx = cKDTree(Vt).query(Vu)  # uv_torus vertex -> torus vertex at the same position
    d_cut = lab.laplacian_offsets(Vn[idx], Fu, weld=True)
    d_ref = np.asarray(lab.laplacian_offsets(Vn, Ft, weld=False))[idx]
    # Offsets of a noisy torus vary from vertex to vertex and (uniform weights) stay within the longest
    # edge at the vertex: p minus a mean of neighbours.
    longest = np.linalg.norm(Vn[Ft] - Vn[np.roll(Ft, 1, axis=1)], axis=2).max()
    expect_true(
        "laplacian_offsets(weld=False) on the noisy torus",
        np.ptp(d_ref, axis=0).max() > 1e-3 and np.linalg.norm(d_ref, axis=1).max() <= longest,
        "the offsets should vary from vertex to vertex and each be at most one edge long (p minus the mean "
        f"of its neighbours); got a spread of {np.ptp(d_ref, axis=0).max():.3g} and a longest offset of "
        f"{np.linalg.norm(d_ref, axis=1).max():.3g} (longest edge {longest:.3g})",
    )
    expect_close(
        "laplacian_offsets(weld=True) on the cut torus", d_cut, d_ref, atol=1e-10, name="delta",
        hint="compute the offsets on the welded mesh (weld_seams) and give every copy its group's offset",
        mesh=(Vn[idx], Fu),
    )  # fmt: skip


@graded(points=1, part="seam fix", tasks=(3, 6))  # weld=True (the default) runs Task 6's seam fix
def test_direct_route_keeps_seams_closed(lab):
    """denoise_vertices(weld=True) moves the copies of every seam vertex identically (needs Task 3)"""
    V, F, _ = datasets.uv_sphere(12, 24)
    Vn, N, group = noisy_cut(V, F, 1)
    X = np.asarray(lab.denoise_vertices(Vn, F, N, 0.7), float)
    expect_closed_seams(
        "denoise_vertices(weld=True) on a UV sphere", X, group,
        "the seam cracks (weld for the offsets, and move every copy along the mean normal of its group)",
    )  # fmt: skip
    # ... and the vertices do move, each by less than the longest edge (lam |s| <= |delta| <= one edge).
    move = np.linalg.norm(X - Vn, axis=1)
    longest = np.linalg.norm(Vn[F] - Vn[np.roll(F, 1, axis=1)], axis=2).max()
    expect_true(
        "denoise_vertices(weld=True) on a UV sphere",
        move.max() > 1e-3 * longest and move.max() <= longest,
        f"the vertices moved by at most {move.max():.3g}; a denoising step moves the noisy vertices, each by "
        f"lam |s| <= one edge ({longest:.3g})",
    )


@graded(points=1, part="seam fix", tasks=(5, 6))  # weld=True (the default) runs Task 6's seam fix
def test_map_route_keeps_seams_closed(lab):
    """denoise_with_map(weld=True) moves the copies identically although they read different texels (needs Task 5)"""
    V, F, UV = datasets.uv_torus(24, 12)
    Vn, N, group = noisy_cut(V, F, 2)
    image = random_map(32, 3)
    h = mean_edge_length(V, F)
    cracked = copy_spread(lab.denoise_with_map(Vn, F, UV, N, image, -0.5 * h, h, 0.7, weld=False), group)
    expect_true(
        "denoise_with_map(weld=False)", cracked > 1e-3 * h, "with weld=False the copies should read different texels"
    )
    # ... and the vertices read the map's varying values: lam s = (Vn - X) . n spans much of [bias, bias + scale]
    # (the map spans all of [0, 1]), not one offset for every vertex.
    X = np.asarray(lab.denoise_with_map(Vn, F, UV, N, image, -0.5 * h, h, 0.7, weld=False), float)
    s = np.sum((Vn - X) * N, axis=1) / 0.7
    expect_true(
        "denoise_with_map(weld=False) on a UV torus",
        np.ptp(s) > 0.25 * h and s.min() >= -0.5 * h - 1e-9 and s.max() <= 0.5 * h + 1e-9,
        f"the offsets s = bias + scale h(uv) span [{s.min():.3g}, {s.max():.3g}]; the map's values span [0, 1], so "
        f"with bias {-0.5 * h:.3g} and scale {h:.3g} they should vary within [{-0.5 * h:.3g}, {0.5 * h:.3g}]",
    )
    expect_closed_seams(
        "denoise_with_map(weld=True) on a UV torus", lab.denoise_with_map(Vn, F, UV, N, image, -0.5 * h, h, 0.7), group,
        "give all copies the mean offset (seam_mean) and the mean normal (normalised)",
    )  # fmt: skip


# --------------------------------------------------------------------------------------------
# bad input (validation is given code, so these carry no points)


@graded(points=0, part="bad input")
def test_rejects_unknown_weights(lab):
    """an unknown weights option is rejected with the allowed values"""
    expect_rejected(
        lab, "laplacian_offsets", PYRAMID_V, PYRAMID_F, "cot", match="uniform", label="laplacian_offsets(weights='cot')"
    )


@graded(points=0, part="bad input")
def test_rejects_out_of_range_faces(lab):
    """a face index beyond the vertices is rejected with the face named"""
    expect_rejected(lab, "laplacian_offsets", PYRAMID_V, [[0, 1, 7]], match="face 0")


@graded(points=0, part="bad input")
def test_rejects_zero_normals(lab):
    """a zero normal is rejected with its row"""
    N = np.tile(UP, (5, 1))
    N[3] = 0
    expect_rejected(lab, "denoise_vertices", PYRAMID_V, PYRAMID_F, N, 0.5, match="row 3")


@graded(points=0, part="bad input")
def test_rejects_lambda_out_of_range(lab):
    """lambda outside [0, 1] is rejected"""
    N = np.tile(UP, (5, 1))
    expect_rejected(
        lab, "denoise_vertices", PYRAMID_V, PYRAMID_F, N, 1.5, match="lam", label="denoise_vertices(lam=1.5)"
    )


@graded(points=0, part="bad input")
def test_rejects_bad_bits_and_uvs(lab):
    """bits other than 8/16 and UVs outside the unit square are rejected"""
    V, F, UV = _uv_square()
    expect_rejected(
        lab, "bake_offset_map", V, F, UV, np.zeros(4), 8, 12, match="bits", label="bake_offset_map(bits=12)"
    )
    expect_rejected(lab, "bake_offset_map", V, F, UV + 1, np.zeros(4), 8, match="outside")


@graded(points=0, part="bad input")
def test_rejects_non_square_maps(lab):
    """an offset map that is not square and single-channel is rejected"""
    V, F, UV = _five_points()
    N = np.tile(UP, (5, 1))
    expect_rejected(lab, "denoise_with_map", V, F, UV, N, np.zeros((4, 8)), 0, 1, 0.5, match="square")
    expect_rejected(lab, "denoise_with_map", V, F, UV, N, np.zeros((4, 4, 3)), 0, 1, 0.5, match="single-channel")


# ------------------------------------------------------------------------------ the GLSL route (task 7)

#: shaders/denoise.vert against the stored NumPy references of the map route: measured (llvmpipe,
#: float32) p99 9.0e-8, p99.9 1.1e-7, max 1.1e-7 mesh units over the three map cases, welded or not;
#: the tolerance 1e-5 is 90x the max and far below a wrong sign or a missing lam (>= 1e-3 here).
GLSL_ATOL = 1e-5


def check_glsl_denoise(lab, case_id: str) -> None:
    """``glsl_denoise_with_map`` (shaders/denoise.vert, the vertex stage) on a map case: its stored reference."""
    from geomlib.grading.cases import load_reference

    case = {c.id: c for c in (*CASES, *hidden_cases("denoise", package=__package__))}[case_id]
    inp = case.inputs()
    got = np.asarray(lab.glsl_denoise_with_map(**inp, **case.params), float)
    expected = load_reference("denoise", case)["V"]
    label = f'glsl_denoise_with_map (shaders/denoise.vert, the vertex stage) on "{case_id}"'
    if got.shape != expected.shape:
        raise Mismatch(f"{label}: the shader's output has shape {got.shape}, expected {expected.shape}")
    per = np.abs(got - expected).max(axis=1)
    bad = ~(per <= GLSL_ATOL)  # NaN counts as wrong
    if bad.any():
        i = int(np.argmax(bad))
        nan = " (NaN: the shader wrote NaN)" if np.isnan(got[i]).any() else ""
        raise Mismatch(
            f"{label}: vertex {i} expected {expected[i].round(7).tolist()}, got {got[i].round(7).tolist()}{nan}; "
            f"{int(bad.sum())} of {len(per)} vertices differ by more than {GLSL_ATOL:g}",
            failure_picture(label, got, expected, name="V", mesh=(inp["V"], inp["F"]), atol=GLSL_ATOL),
        )


@graded(points=2, part="vertex denoising", timeout=60)
def test_glsl_denoise_with_map(lab):
    """shaders/denoise.vert against denoise_with_map's references (a 16-bit torus map, an 8-bit sphere map)"""
    check_glsl_denoise(lab, "map-uv-torus-16bit")
    check_glsl_denoise(lab, "map-uv-sphere-8bit")


@graded(points=1, part="vertex denoising", timeout=60)
def test_glsl_denoise_keeps_seams_closed(lab):
    """weld=True: the copies of every seam vertex of the UV torus end at one position (the CPU-side seam fix), the others where the reference puts them"""
    case = {c.id: c for c in CASES}["map-uv-torus-16bit"]
    inp = case.inputs()
    got = np.asarray(lab.glsl_denoise_with_map(**inp, **{**case.params, "weld": True}), float)
    V = np.asarray(inp["V"], float)
    _, first, group = np.unique(V.round(12), axis=0, return_index=True, return_inverse=True)
    gap = np.abs(got - got[first][group.ravel()]).max(axis=1)
    if not gap.max() <= 1e-6:
        i = int(np.argmax(gap))
        raise Mismatch(
            f"glsl_denoise_with_map(weld=True) (shaders/denoise.vert, the vertex stage, then the given seam fix): "
            f"vertex {i} is {gap[i]:.3g} away from its seam copy (the seam cracks open)"
        )
    # The seam fix touches only the copies of seam vertices: every other vertex ends where the case's
    # stored reference (weld=False) puts it, so a vertex stage that moves nothing cannot pass.
    from geomlib.grading.cases import load_reference

    expected = load_reference("denoise", case)["V"]
    single = np.bincount(group.ravel())[group.ravel()] == 1
    per = np.abs(got - expected)[single].max(axis=1)
    if not (per <= GLSL_ATOL).all():
        i = int(np.flatnonzero(single)[np.argmax(~(per <= GLSL_ATOL))])
        raise Mismatch(
            f"glsl_denoise_with_map(weld=True): vertex {i}, not on the seam, expected {expected[i].round(7).tolist()}, "
            f"got {got[i].round(7).tolist()}; {int((~(per <= GLSL_ATOL)).sum())} of {int(single.sum())} vertices off "
            f"the seam differ by more than {GLSL_ATOL:g} (the seam fix leaves them as shaders/denoise.vert moved them)"
        )
