"""Graded tests of the lab "vdm": stored references plus hand-checkable cases, identities, properties
and bad input.

Expected values here are worked out by hand (comments), are closed forms, or are properties any
correct implementation has; none comes from the solution. Every test first makes a valid call, so
an unfinished task scores zero here ("not implemented yet").
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.grading import expect_close, graded, reference_tests
from geomlib.grading.errors import Mismatch

from ..common import expect_rejected
from .cases import CASES, align_inputs, blob_field, open_box, rock_with_uv, texel_mismatch, uniform, warped

test_references = reference_tests(CASES)


def expect(condition: bool, message: str) -> None:
    if not condition:
        raise Mismatch(message)


def expect_texels_close(label: str, got, expected, atol: float, hint: str | None = None) -> None:
    """(h, w[, c]) arrays equal within atol; the message names the first texel [i, j] that differs."""
    try:
        g = np.asarray(got, dtype=np.float64)
    except (TypeError, ValueError):
        raise Mismatch(f"{label}: the result is not a numeric array (got {type(got).__name__})") from None
    message = texel_mismatch("result", g, np.asarray(expected, dtype=np.float64), atol)
    if message:
        raise Mismatch(f"{label}: {message}" + (f" — {hint}" if hint else ""))


def corner_areas(G):
    """Signed areas of the four corner triangles of every cell (all > 0: convex, unflipped)."""
    a, b, c, d = G[:-1, :-1], G[:-1, 1:], G[1:, 1:], G[1:, :-1]

    def tri(p, q, r):
        return 0.5 * (
            (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])
        )

    return np.stack([tri(d, a, b), tri(a, b, c), tri(b, c, d), tri(c, d, a)], axis=-1)


def usable_cells(G):
    """True where at least one diagonal split gives two positive triangles."""
    A = corner_areas(G) > 1e-12
    return (A[..., 1] & A[..., 3]) | (A[..., 0] & A[..., 2])


def expect_boundary_on_edges(label: str, G, G0=None):
    expect(
        np.all(G[:, 0, 0] == 0) and np.all(G[:, -1, 0] == 1),
        f"{label}: the left/right boundary columns must keep u = 0 / u = 1",
    )
    expect(
        np.all(G[0, :, 1] == 0) and np.all(G[-1, :, 1] == 1),
        f"{label}: the bottom/top boundary rows must keep v = 0 / v = 1",
    )
    corners = G[[0, 0, -1, -1], [0, -1, 0, -1]]
    expect(
        np.array_equal(corners, [[0, 0], [1, 0], [0, 1], [1, 1]]),
        f"{label}: the square's corners must not move, got {corners.tolist()}",
    )


# ------------------------------------------------------------------------------ parameterization


@graded(points=1, part="parameterization")
def test_boundary_to_square_by_hand(lab):
    """a 2 x 1 rectangle: long sides halve, short sides are whole edges"""
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [0, 1, 0.0]])
    # Corners at loop positions 0, 2, 3, 5: side 0 = (0,0,0)->(2,0,0) of length 2, its middle vertex at s/L = 1/2.
    # Corners need not start at loop position 0. Starting at position 3 = (2, 1, 0): side 0 runs 3 -> 4 -> 5 along
    # the top (length 2) to (0, 0) .. (1, 0); side 1 is 5 -> 0 down the left (length 1); side 2 is 0 -> 1 -> 2 along
    # the bottom to (1, 1) .. (0, 1); side 3 closes 2 -> 3.
    for corners, where, expected, hint in (
        (
            [0, 2, 3, 5],
            "on a 2 x 1 rectangle",
            [[0, 0], [0.5, 0], [1, 0], [1, 1], [0.5, 1], [0, 1]],
            "uv = c_k + (s / L) (c_{k+1} - c_k) with s measured from the side's first corner",
        ),
        (
            [3, 5, 0, 2],
            "starting at loop position 3",
            [[1, 1], [0.5, 1], [0, 1], [0, 0], [0.5, 0], [1, 0]],
            "side k starts at loop position corners[k] (it goes to the square corner k) and wraps past the loop's end",
        ),
    ):
        uv = lab.boundary_to_square(V, np.arange(6), np.array(corners))
        expect_close(f"boundary_to_square {where}", uv, expected, atol=1e-12, hint=hint)


@graded(points=1, part="parameterization")
def test_flat_square_maps_to_itself(lab):
    """a flat unit-square grid: u = x, v = y for every method"""
    V, F = datasets.grid_patch(6)
    for method in ("harmonic", "tutte"):
        UV = lab.parameterize_square(V, F, method=method)
        # The identity is harmonic for any weights and matches the arc-length boundary.
        expect_close(f"parameterize_square({method}) on a flat unit square", UV, V[:, :2], atol=1e-10, mesh=(V, F))


@graded(points=1, part="parameterization")
def test_parameterization_is_bijective(lab):
    """the box's uv triangles all keep their orientation; the boundary lies on the square"""
    V, F = open_box(6)
    UV = np.asarray(lab.parameterize_square(V, F))
    A = UV[F]
    area = (A[:, 1, 0] - A[:, 0, 0]) * (A[:, 2, 1] - A[:, 0, 1]) - (A[:, 1, 1] - A[:, 0, 1]) * (A[:, 2, 0] - A[:, 0, 0])
    expect(area.min() > 0, f"parameterize_square on the open box: {int((area <= 0).sum())} uv triangles are flipped")
    rim = np.isclose(V[:, 2], 0)
    on_square = np.isclose(UV[rim], 0, atol=1e-12) | np.isclose(UV[rim], 1, atol=1e-12)
    expect(
        on_square.any(axis=1).all(), "parameterize_square: every boundary (rim) vertex must lie on the square's edges"
    )
    expect(
        abs(area.sum() / 2 - 1) < 1e-9, f"the uv triangles must tile the unit square (total area {area.sum() / 2:.6g})"
    )


@graded(points=1, part="parameterization")
def test_parameterization_rejects_non_disks(lab):
    """closed meshes, holes and handles are not disks"""
    V, F = datasets.grid_patch(4)
    # A valid call first, and its answer: the identity (see the flat-square test).
    expect_close("parameterize_square on a flat unit square", lab.parameterize_square(V, F), V[:, :2], atol=1e-10)
    Vs, Fs = datasets.icosphere(1)
    expect_rejected(lab, "parameterize_square", Vs, Fs, match="closed", label="parameterize_square on a sphere")
    Vt, Ft = datasets.torus()
    expect_rejected(
        lab, "parameterize_square", Vt, Ft[1:], match="genus", label="parameterize_square on a torus with a hole"
    )
    expect_rejected(lab, "parameterize_square", V, F, method="spectral", match="method", label="an unknown method")


# ------------------------------------------------------------------------------ sampling


@graded(points=1, part="sampling")
def test_sampling_a_tilted_plane(lab):
    """on a plane z = 0.3 x - 0.2 y with uv = xy, every sample is (u, v, 0.3 u - 0.2 v), also among uneven triangles"""
    V, F = datasets.grid_patch(5)
    V = V.copy()
    V[:, 2] = 0.3 * V[:, 0] - 0.2 * V[:, 1]  # linear, so barycentric interpolation is exact
    X = np.random.default_rng(7).random((50, 2))
    P = lab.sample_surface(V, F, V[:, :2], X)
    expect_close(
        "sample_surface on a tilted plane",
        P,
        np.c_[X, 0.3 * X[:, 0] - 0.2 * X[:, 1]],
        atol=1e-12,
        hint="P = sum of barycentric weights times the 3-D corners of the uv triangle that contains the point",
        mesh=(V, F),
    )
    P = lab.sample_surface(V, F, V[:, :2], V[:, :2])
    expect_close(
        "sample_surface at the vertices' own uv",
        P,
        V,
        atol=1e-12,
        hint="a vertex's uv must give the vertex",
        mesh=(V, F),
    )
    # Point location must find the containing triangle however the triangles are spread: a large triangle
    # (0.5, 0), (1, 0), (1, 0.5), ten small ones just across its long side and one at the origin. The query
    # (0.8, 0.28) is inside the large one (0.28 < 0.8 - 0.5), though the small ones' centres are nearer to it.
    UV = [[0.5, 0], [1, 0], [1, 0.5], [0, 0], [0.01, 0], [0, 0.01]]
    for k in range(10):
        c = [0.74 + 0.02 * (k % 5), 0.33 + 0.03 * (k // 5)]
        UV += [c, [c[0] + 0.01, c[1]], [c[0], c[1] + 0.01]]
    UV = np.array(UV)
    Fs = np.arange(len(UV)).reshape(-1, 3)
    Vs = np.c_[UV, 0.3 * UV[:, 0] - 0.2 * UV[:, 1]]
    expect_close(
        "sample_surface at uv (0.8, 0.28), inside the large triangle (0.5, 0), (1, 0), (1, 0.5)",
        lab.sample_surface(Vs, Fs, UV, [[0.8, 0.28]]),
        [[0.8, 0.28, 0.3 * 0.8 - 0.2 * 0.28]],
        atol=1e-12,
        hint="a point inside a uv triangle must be found in that triangle, also when other triangles' centres are "
        "nearer (check that every triangle is listed in every grid cell its bounding box touches)",
    )


@graded(points=1, part="sampling")
def test_sampling_keeps_the_query_shape_and_checks_input(lab):
    """(res, res, 2) queries give (res, res, 3), (u, v, 0) on the flat square with uv = xy; a UV with the wrong row count is rejected"""
    V, F = datasets.grid_patch(3)
    P = np.asarray(lab.sample_surface(V, F, V[:, :2], uniform(4)))
    expect(P.shape == (4, 4, 3), f"sample_surface with a (4, 4, 2) query returned shape {P.shape}, expected (4, 4, 3)")
    # The grid is the flat unit square z = 0 with uv = xy, so the point at uv (u, v) is (u, v, 0).
    q = uniform(4)
    expect_close("sample_surface on the flat square with uv = xy", P, np.dstack([q, np.zeros((4, 4))]), atol=1e-12)
    expect_rejected(
        lab, "sample_surface", V, F, V[:3, :2], uniform(4), match="UV", label="UV with 3 rows for 16 vertices"
    )


# ------------------------------------------------------------------------------ naive VDM


@graded(points=2, part="naive VDM")
def test_naive_vdm_recovers_the_rock_exactly(lab):
    """the rock is the grid_patch(16) grid displaced: the 17 x 17 naive VDM is exactly V - grid"""
    d = rock_with_uv(16)
    Vg, _ = datasets.grid_patch(16)
    D = lab.naive_vdm(d["V"], d["F"], d["UV"], 17)
    # grid_patch vertex i + 17 j sits at (i, j) / 16: texel (row j, column i) samples exactly that vertex.
    expect_texels_close(
        "naive_vdm of the rock at res 17",
        D,
        (d["V"] - Vg).reshape(17, 17, 3),
        atol=1e-12,
        hint="texel [i, j] is at u = j / (res - 1), v = i / (res - 1); subtract p_o = (u, v, 0)",
    )


@graded(points=1, part="naive VDM")
def test_naive_vdm_of_a_flat_square_is_zero(lab):
    """a flat unit square with uv = xy needs no displacement at all; tilted to z = 0.3 x - 0.2 y, exactly that height"""
    V, F = datasets.grid_patch(3)
    D = lab.naive_vdm(V, F, V[:, :2], 5)
    expect_texels_close(
        "naive_vdm of the flat unit square",
        D,
        np.zeros((5, 5, 3)),
        atol=1e-12,
        hint="texel [i, j] samples u = j / (res - 1), v = i / (res - 1)",
    )
    # Tilt the square to z = 0.3 x - 0.2 y (uv still xy): now only the z component is displaced, by exactly that
    # height (linear, so barycentric interpolation is exact), at texel [i, j] = (u, v) = (j, i) / 4.
    Vt = V.copy()
    Vt[:, 2] = 0.3 * V[:, 0] - 0.2 * V[:, 1]
    t = np.linspace(0, 1, 5)
    expected = np.zeros((5, 5, 3))
    expected[..., 2] = 0.3 * t[None, :] - 0.2 * t[:, None]
    expect_texels_close(
        "naive_vdm of the square tilted to z = 0.3 x - 0.2 y",
        lab.naive_vdm(Vt, F, V[:, :2], 5),
        expected,
        atol=1e-12,
        hint="D = p(u, v) - (u, v, 0): the tilted square's height",
    )
    expect_rejected(lab, "naive_vdm", V, F, V[:, :2], 1, match="res", label="naive_vdm with res = 1")


# ------------------------------------------------------------------------------ importance


@graded(points=1, part="importance")
def test_importance_by_hand(lab):
    """a 90 degree fold gives 0.5 on the fold vertices, a 180 degree fold 1, flat 0"""
    V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]
    F = [[0, 1, 2], [1, 0, 3]]
    # faces (0,1,2) and (1,0,3): unit normals (0,0,1) and (0,1,0), n1.n2 = 0: 0.5 - 0.5 * 0 = 0.5.
    expect_close(
        "vertex_importance of a 90 degree fold", lab.vertex_importance(V, F), [0.5, 0.5, 0, 0], atol=1e-12, mesh=(V, F)
    )
    V2 = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 1, 0]]
    # (0,1,2) and (1,0,3) lie in one plane with opposite normals: 0.5 - 0.5 * (-1) = 1.
    expect_close(
        "vertex_importance of a folded-over pair", lab.vertex_importance(V2, F), [1, 1, 0, 0], atol=1e-12, mesh=(V2, F)
    )
    Vg, Fg = datasets.grid_patch(3)
    expect_close(
        "vertex_importance of a flat grid", lab.vertex_importance(Vg, Fg), np.zeros(len(Vg)), atol=1e-12, mesh=(Vg, Fg)
    )


@graded(points=1, part="importance")
def test_importance_of_the_box(lab):
    """box creases are 90 degrees: 0.5 on the creases (and the rim's crease feet), 0 on flat faces"""
    V, F = open_box(4)
    imp = np.asarray(lab.vertex_importance(V, F))
    at = np.isclose(V, 0) | np.isclose(V, 1)
    on_crease = (at[:, 0].astype(int) + at[:, 1] + np.isclose(V[:, 2], 0.5) >= 2) & ~np.isclose(V[:, 2], 0)
    foot = at[:, 0] & at[:, 1] & np.isclose(V[:, 2], 0)  # the rim corners: one interior (crease) edge
    expect_close(
        "vertex_importance on the box creases",
        imp[on_crease | foot],
        np.full((on_crease | foot).sum(), 0.5),
        atol=1e-12,
        mesh=(V, F, on_crease | foot),
    )
    expect_close(
        "vertex_importance on flat parts",
        imp[~(on_crease | foot)],
        np.zeros((~(on_crease | foot)).sum()),
        atol=1e-12,
        hint="boundary edges have only one face and do not count",
        mesh=(V, F, ~(on_crease | foot)),
    )


# ------------------------------------------------------------------------------ field


@graded(points=1, part="field")
def test_field_by_hand(lab):
    """one vertex on a pixel centre: background + 1 there, the Gaussian next to it, background beyond 3 sigma"""
    res, sigma = 8, 0.1
    uv = [[2.5 / res, 3.5 / res]]  # pixel (row 3, column 2)
    f = np.asarray(lab.importance_field(uv, [1.0], res, background=0.2, sigma=sigma))
    expect(f.shape == (res, res), f"importance_field returned shape {f.shape}, expected ({res}, {res})")
    expect_close("field at the vertex's pixel", f[3, 2], 1.2, atol=1e-12)
    # one pixel to the right: distance 1/8, exp(-(1/8)^2 / (2 * 0.01)) = exp(-0.78125)
    expect_close(
        "field one pixel right (column 3)",
        f[3, 3],
        0.2 + np.exp(-0.78125),
        atol=1e-12,
        hint="columns are u, rows are v",
    )
    expect_close("field one pixel up (row 4)", f[4, 2], 0.2 + np.exp(-0.78125), atol=1e-12)
    # 3 pixels right: distance 0.375 > 3 sigma = 0.3, cut off
    expect_close("field beyond 3 sigma", f[3, 5], 0.2, atol=1e-12, hint="the kernel is exactly 0 beyond 3 sigma")


@graded(points=1, part="field")
def test_field_takes_the_max_and_rejects_bad_input(lab):
    """two vertices on the same pixel: the larger importance wins (max, not sum)"""
    res = 4
    uv = [[0.625, 0.625], [0.625, 0.625]]
    f = np.asarray(lab.importance_field(uv, [0.3, 0.7], res, background=0.1, sigma=0.05))
    expect_close("field where two vertices meet", f[2, 2], 0.8, atol=1e-12, hint="take the maximum over vertices")
    expect_rejected(lab, "importance_field", uv, [0.3, -0.7], res, match="negative", label="a negative importance")
    expect_rejected(
        lab, "importance_field", uv, [0.3, 0.7], res, background=0, match="background", label="background 0"
    )


# ------------------------------------------------------------------------------ transport


@graded(points=1, part="transport grid")
def test_half_step_at_the_optimum(lab):
    """when the delivered density already equals the target, nothing moves and the residual is 0"""
    n = 8
    c = np.arange(0.5, n) / n  # pixel centres
    v, u = np.meshgrid(c, c, indexing="ij")
    phi = 0.5 * (u**2 + v**2)  # the identity potential is its own Legendre transform on the grid
    out = lab.bfm_half_step(phi, np.ones((n, n)), np.ones((n, n)), 1.0)
    expect(isinstance(out, tuple | list) and len(out) == 3, "bfm_half_step must return (phi, psi, grad_sq)")
    expect_close("bfm_half_step phi at the optimum", out[0], phi, atol=1e-12)
    expect_close("bfm_half_step psi at the optimum", out[1], phi, atol=1e-12)
    expect_close("bfm_half_step grad_sq at the optimum", out[2], 0.0, atol=1e-15)


@graded(points=1, part="transport grid")
def test_uniform_field_gives_the_uniform_grid(lab):
    """a constant field: the optimal map is the identity"""
    G = lab.transport_grid(np.full((16, 16), 0.7), 9)
    expect_close(
        "transport_grid of a constant field",
        G,
        uniform(9),
        atol=1e-9,
        hint="a uniform density must leave the grid uniform",
    )


@graded(points=2, part="transport grid")
def test_transport_grid_is_bijective_and_denser_where_important(lab):
    """a blob field: no folded cell, boundary on its edges, small cells in the blob, large cells away from it"""
    field = blob_field(32, centre=(0.65, 0.35), width=0.1)
    G = np.asarray(lab.transport_grid(field, 14))
    expect(G.shape == (14, 14, 2), f"transport_grid returned shape {G.shape}, expected (14, 14, 2)")
    A = corner_areas(G)
    expect(
        bool((A > 0).all()),
        f"transport_grid: {int((A <= 0).any(axis=-1).sum())} cells are folded, flipped or not convex",
    )
    expect_boundary_on_edges("transport_grid", G)
    centre = 0.25 * (G[:-1, :-1] + G[1:, 1:] + G[1:, :-1] + G[:-1, 1:])
    area = A[..., 1] + A[..., 3]
    near = np.linalg.norm(centre - [0.65, 0.35], axis=-1) < 0.1
    far = np.linalg.norm(centre - [0.65, 0.35], axis=-1) > 0.45
    expect(near.any() and far.any(), "transport_grid: expected cells both inside and far from the blob")
    ratio = area[far].mean() / area[near].mean()
    expect(
        ratio > 3, f"transport_grid: cells far from the blob are only {ratio:.2f}x larger than inside it (expected > 3)"
    )


@graded(points=1, part="transport grid")
def test_transport_rejects_bad_fields(lab):
    """fields must be square and strictly positive (after a valid call: a field 3x denser on the right pulls the grid right)"""
    field = np.ones((8, 8))
    field[:, 4:] = 3.0  # columns are u: the right half u > 1/2 is three times denser
    G = np.asarray(lab.transport_grid(field, 5))
    moved = G[1:-1, 1:-1, 0] - uniform(5)[1:-1, 1:-1, 0]
    expect(
        G.shape == (5, 5, 2) and bool((moved > 0.01).all()),
        "transport_grid of a field 3x denser on the right half: every interior grid point must move right "
        f"(u increases); moved by {np.round(moved, 3).tolist() if G.shape == (5, 5, 2) else G.shape}",
    )
    # The field does not change under v -> 1 - v, so neither does the grid: rows i and 4 - i mirror each other.
    mirror = np.abs(G[::-1, :, 1] - (1 - G[:, :, 1])).max()
    expect(
        mirror < 0.01,
        f"transport_grid of a field that only varies with u: rows i and 4 - i must mirror in v (v -> 1 - v), "
        f"off by {mirror:.3g}; the middle row has v = {np.round(G[2, :, 1], 3).tolist()}, expected 0.5",
    )
    expect_rejected(lab, "transport_grid", np.zeros((8, 8)), 4, match="positive", label="a zero field")
    expect_rejected(lab, "transport_grid", np.ones((8, 6)), 4, match="square", label="a non-square field")


# ------------------------------------------------------------------------------ alignment


@graded(points=1, part="alignment")
def test_sharp_features_of_a_closed_box(lab):
    """a box with one quad per side: 12 sharp edges, 8 corners; nothing is sharper than 91 degrees"""
    V, F = datasets.sharp_box(n=1)
    edges, corners = lab.sharp_features(V, F, 30.0)
    expect(
        len(np.asarray(edges)) == 12,
        f"sharp_features on a cube found {len(np.asarray(edges))} sharp edges, expected 12 (the quads' diagonals are flat)",
    )
    expect(
        sorted(np.asarray(corners).tolist()) == list(range(8)),
        f"sharp_features on a cube: corners {np.asarray(corners).tolist()}, expected all 8 vertices",
    )
    edges, corners = lab.sharp_features(V, F, 91.0)
    expect(
        len(np.asarray(edges)) == 0 and len(np.asarray(corners)) == 0,
        "sharp_features with angle 91: a cube's 90 degree edges are not sharper than that",
    )


@graded(points=2, part="alignment")
def test_alignment_puts_the_box_corners_on_the_grid(lab):
    """after alignment a 16 x 16 grid has a vertex exactly on each of the box's 8 corners"""
    d = align_inputs("box", uniform(16))
    G = np.asarray(lab.align_to_features(d["grid_uv"], d["V"], d["F"], d["UV"], d["edges"], d["corners"]))
    expect(bool(usable_cells(G).all()), f"align_to_features folded {int((~usable_cells(G)).sum())} cells")
    expect_boundary_on_edges("align_to_features", G)
    # Map the grid to 3-D with the mesh's own barycentric interpolation (numpy, no student code).
    from scipy.spatial import cKDTree

    corners3d = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 0.5)])
    vid = [int(np.argmin(np.linalg.norm(d["V"] - c, axis=1))) for c in corners3d]
    dist, _ = cKDTree(G.reshape(-1, 2)).query(d["UV"][vid])
    expect(
        dist.max() < 1e-6,
        f"align_to_features: the box corner {corners3d[int(np.argmax(dist))].tolist()} is {dist.max():.3g} (in uv) from the nearest grid vertex; snap the nearest grid vertex onto each sharp corner",
    )


@graded(points=1, part="alignment")
def test_alignment_moves_vertices_onto_sharp_edges_only(lab):
    """every moved grid vertex lies on a sharp edge in uv; untouched vertices stay put"""
    d = align_inputs("rock", warped(18))
    G0 = d["grid_uv"]
    G = np.asarray(lab.align_to_features(G0, d["V"], d["F"], d["UV"], d["edges"], d["corners"]))
    moved = (G != G0).any(axis=-1)
    expect(
        moved.sum() > 10, f"align_to_features moved only {int(moved.sum())} grid vertices on the rock; expected many"
    )
    A, B = d["UV"][d["edges"][:, 0]], d["UV"][d["edges"][:, 1]]
    P = G[moved]
    t = np.clip(np.einsum("pkd,kd->pk", P[:, None] - A[None], B - A) / np.sum((B - A) ** 2, 1), 0, 1)
    dist = np.linalg.norm(A[None] + t[..., None] * (B - A)[None] - P[:, None], axis=2).min(axis=1)
    expect(
        dist.max() < 1e-9,
        f"align_to_features: a moved vertex is {dist.max():.3g} from every sharp edge; moves go onto crossings or corners",
    )
    step = np.linalg.norm(G - G0, axis=-1)[moved].max()
    expect(
        step < 0.75 / 17,
        f"align_to_features moved a vertex by {step:.3g}, more than the nearer end of a grid edge can move",
    )
    expect(bool(usable_cells(G).all()), "align_to_features folded a cell")


@graded(points=1, part="alignment")
def test_alignment_rejects_bad_indices(lab):
    """edge indices must be mesh vertices"""
    d = align_inputs("box", uniform(6))
    lab.align_to_features(d["grid_uv"], d["V"], d["F"], d["UV"], d["edges"], d["corners"])  # valid first
    bad = d["edges"].copy()
    bad[0, 0] = len(d["V"])
    expect_rejected(
        lab,
        "align_to_features",
        d["grid_uv"],
        d["V"],
        d["F"],
        d["UV"],
        bad,
        d["corners"],
        match="edges",
        label="an edge with an out-of-range vertex",
    )


# ------------------------------------------------------------------------------ diagonals


def roof(n: int = 8):
    """A flat grid folded along u + v = 1, triangulated along the b-d diagonals (so the crease is made of edges)."""
    V, _ = datasets.grid_patch(n)
    q = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    F = np.r_[np.c_[a, b, d], np.c_[b, c, d]]
    V = V.copy()
    V[:, 2] = 0.3 * np.minimum(V[:, 0] + V[:, 1], 2 - V[:, 0] - V[:, 1])
    return V, F


@graded(points=2, part="diagonals")
def test_diagonals_follow_a_crease_on_the_anti_diagonal(lab):
    """a roof creased along u + v = 1 and a 9 x 9 grid: the crease cells take b-d (False), all others the default"""
    V, F = roof(8)
    E = np.array([[i * 9 + (8 - i), (i + 1) * 9 + (7 - i)] for i in range(8)])  # crease edges (i, 8-i)-(i+1, 7-i)
    E = np.sort(E, axis=1)
    diag = np.asarray(lab.choose_diagonals(uniform(9), V, F, V[:, :2], E))
    crease_cells = np.add.outer(np.arange(8), np.arange(8)) == 7  # cells whose b-d diagonal is on the crease
    expect(
        diag.shape == (8, 8) and diag.dtype == bool,
        f"choose_diagonals returned {diag.dtype} {diag.shape}, expected bool (8, 8)",
    )
    expect(
        not diag[crease_cells].any(),
        f"choose_diagonals: {int(diag[crease_cells].sum())} of the 8 crease cells keep the a-c split that cuts the crease",
    )
    expect(diag[~crease_cells].all(), "choose_diagonals: cells that no sharp edge crosses must keep the default (True)")


@graded(points=1, part="diagonals")
def test_diagonals_never_pick_a_flipped_split(lab):
    """a non-convex cell: only its a-c split has two positive triangles, whatever the default; and one where only b-d has"""
    G = uniform(3).copy()
    G[1, 1] = [0.2, 0.2]  # cell (0, 0) = (0,0), (.5,0), (.2,.2), (0,.5): triangle b, c, d is flipped
    V, F = roof(2)
    E = np.array([[2, 4], [4, 6]])
    for default in (True, False):
        diag = np.asarray(lab.choose_diagonals(G, V, F, V[:, :2], E, default=default))
        expect(
            bool(diag[0, 0]),
            f"choose_diagonals(default={default}) split the non-convex cell (0, 0) along b-d, which flips triangle bcd",
        )
    G[1, 1] = [0.8, 0.2]  # cell (0, 1) = (.5,0), (1,0), (1,.5), (.8,.2): triangle a, c, d is flipped
    for default in (True, False):
        diag = np.asarray(lab.choose_diagonals(G, V, F, V[:, :2], E, default=default))
        expect(
            not bool(diag[0, 1]),
            f"choose_diagonals(default={default}) split the non-convex cell (0, 1) along a-c, which flips triangle acd",
        )
