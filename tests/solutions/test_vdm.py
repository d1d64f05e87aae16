"""Cross-checks of the VDM reference solution against independent libraries and hand-checkable facts.

Independent references: libigl (``igl.lscm`` with the whole boundary pinned, ``igl.cotmatrix``),
POT (``ot.emd``: exact discrete optimal transport), trimesh (dihedral angles), matplotlib's
``LinearTriInterpolator`` (piecewise-linear interpolation on a given triangulation), and shapes whose
answer is known by construction (flat grids, the open box, the rock-on-plinth that
``geomlib.datasets`` builds as an exact displacement of a grid).
"""

from __future__ import annotations

import igl
import numpy as np
import pytest

from bench.anchors import pixel_centres, pot_transport_map
from geomlib import datasets
from geomlib.geometry import mesh_distance
from geomlib.image_io import read_image
from geomlib.validate import MeshError
from solutions.vdm import (
    VDM,
    align_to_features,
    bake_vdm,
    bfm_potentials,
    check_disk,
    choose_diagonals,
    convex_cells,
    crossed_cells,
    folded_cells,
    grid_faces,
    importance_field,
    legendre_transform,
    load_vdm,
    locate_uv,
    naive_vdm,
    open_box,
    parameterize_square,
    pushforward,
    sample_surface,
    save_vdm,
    sharp_features,
    transport_grid,
    uniform_grid,
    vdm_to_mesh,
    vertex_importance,
)
from solutions.vdm.transport import inverse_neg_laplacian

STAGES = [
    dict(optimize=False, align=False, diagonals=False),
    dict(optimize=True, align=False, diagonals=False),
    dict(optimize=True, align=True, diagonals=False),
    dict(optimize=True, align=True, diagonals=True),
]


def _signed_areas(UV, F):
    A = UV[F]
    return 0.5 * (
        (A[:, 1, 0] - A[:, 0, 0]) * (A[:, 2, 1] - A[:, 0, 1]) - (A[:, 1, 1] - A[:, 0, 1]) * (A[:, 2, 0] - A[:, 0, 0])
    )


def _box_corners(size=(1.0, 1.0, 0.5)):
    sx, sy, sz = size
    return np.array([[x, y, z] for x in (0, sx) for y in (0, sy) for z in (0, sz)])


@pytest.fixture(scope="module")
def rock():
    return datasets.rock_on_plinth()


@pytest.fixture(scope="module")
def box():
    return open_box(8)


# ------------------------------------------------------------------------------------------------
# Task 1: parameterization


@pytest.mark.parametrize("method", ["harmonic", "tutte", "lscm"])
def test_flat_grid_parameterizes_to_itself(method):
    # A flat unit-square grid: the square boundary by arc length plus any of the three interior
    # solves reproduces the identity map u = x, v = y.
    V, F = datasets.grid_patch(8)
    UV = parameterize_square(V, F, method)
    np.testing.assert_allclose(UV, V[:, :2], atol=1e-12)


@pytest.mark.parametrize("method", ["harmonic", "tutte", "lscm"])
@pytest.mark.parametrize("mesh", ["rock", "box", "height_field"])
def test_parameterization_is_bijective_with_boundary_on_square(method, mesh, rock, box):
    V, F = {"rock": rock, "box": box, "height_field": datasets.height_field(24)}[mesh]
    UV = parameterize_square(V, F, method)
    assert _signed_areas(UV, F).min() > 0, "flipped uv triangle"
    _, _, loop = check_disk(V, F)
    b = UV[loop]
    on_edge = np.isclose(b, 0, atol=1e-12) | np.isclose(b, 1, atol=1e-12)
    assert on_edge.any(axis=1).all(), "boundary vertex off the square"
    for corner in ([0, 0], [1, 0], [1, 1], [0, 1]):
        assert np.isclose(UV, corner, atol=1e-12).all(axis=1).sum() == 1
    assert UV.min() >= -1e-12 and UV.max() <= 1 + 1e-12


def test_harmonic_matches_igl_lscm_with_whole_boundary_pinned(box):
    # With every boundary vertex pinned, the LSCM energy differs from the Dirichlet energy by the
    # (fixed) uv area, so igl.lscm must return the harmonic map.
    V, F = box
    UV = parameterize_square(V, F, "harmonic")
    _, _, loop = check_disk(V, F)
    UV_lscm, _ = igl.lscm(V, F, loop, UV[loop])
    np.testing.assert_allclose(UV, UV_lscm, atol=1e-9)


def test_harmonic_interior_satisfies_cotangent_laplace(rock):
    V, F = rock
    UV = parameterize_square(V, F)
    L = igl.cotmatrix(V, F)
    _, _, loop = check_disk(V, F)
    interior = np.setdiff1d(np.arange(len(V)), loop)
    assert np.abs((L @ UV)[interior]).max() < 1e-10


def test_box_rim_corners_go_to_square_corners(box):
    V, F = box
    UV = parameterize_square(V, F)
    bottom = _box_corners()[[0, 2, 6, 4]]  # (0,0,0), (0,1,0), (1,1,0), (1,0,0)
    idx = [int(np.argmin(np.linalg.norm(V - c, axis=1))) for c in bottom]
    got = {tuple(np.round(UV[i], 12)) for i in idx}
    assert got == {(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)}
    # First corner = smallest x + y, so u follows x and v follows y.
    np.testing.assert_allclose(UV[idx[0]], [0, 0])
    np.testing.assert_allclose(UV[idx[3]], [1, 0])


def test_parameterization_rejects_non_disks():
    V, F = datasets.icosphere(1)
    with pytest.raises(MeshError, match="closed"):
        parameterize_square(V, F)
    Vg, Fg = datasets.grid_patch(6)
    centre = np.flatnonzero(np.isclose(Vg[:, :2], 0.5).all(axis=1))[0]
    holed = Fg[~(Fg == centre).any(axis=1)]
    keep = np.delete(np.arange(len(Vg)), centre)
    remap = np.full(len(Vg), -1)
    remap[keep] = np.arange(len(keep))
    with pytest.raises(MeshError, match="2 boundary loops"):
        parameterize_square(Vg[keep], remap[holed])
    with pytest.raises(MeshError, match="not used"):
        parameterize_square(Vg, holed)
    two = np.r_[Fg, Fg + len(Vg)]
    with pytest.raises(MeshError, match="2 connected components"):
        parameterize_square(np.r_[Vg, Vg + 2], two)
    # A torus with one face removed: one boundary loop but genus 1.
    Vt, Ft = datasets.torus()
    with pytest.raises(MeshError, match="genus 1"):
        parameterize_square(Vt, Ft[1:])
    with pytest.raises(MeshError, match="method"):
        parameterize_square(Vg, Fg, "conformal")
    with pytest.raises(MeshError, match="boundary"):
        parameterize_square(Vg, Fg, corners=[0, 1, 2, centre])


# ------------------------------------------------------------------------------------------------
# Task 2: sampling


def test_sampling_matches_matplotlib_linear_interpolation():
    mtri = pytest.importorskip("matplotlib.tri")
    V, F = datasets.height_field(12)
    UV = V[:, :2].copy()  # the grid's own xy is a valid parameterization
    rng = np.random.default_rng(1)
    X = rng.random((500, 2))
    P = sample_surface(V, F, UV, X)
    tri = mtri.Triangulation(UV[:, 0], UV[:, 1], F)
    z = mtri.LinearTriInterpolator(tri, V[:, 2])(X[:, 0], X[:, 1])
    np.testing.assert_allclose(P[:, 2], np.asarray(z), atol=1e-12)
    np.testing.assert_allclose(P[:, :2], X, atol=1e-12)


def test_sampling_at_vertices_returns_vertices_and_locates_against_brute_force(rock):
    V, F = rock
    UV = parameterize_square(V, F)
    np.testing.assert_allclose(sample_surface(V, F, UV, UV), V, atol=1e-12)
    X = np.random.default_rng(2).random((300, 2))
    face, bary = locate_uv(UV, F, X)
    # Brute force over every triangle: barycentric coordinates by solving the 2x2 system per pair.
    T = UV[F]  # (m, 3, 2)
    M = np.stack([T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]], axis=-1)  # (m, 2, 2)
    rhs = X[:, None, :] - T[None, :, 0]  # (k, m, 2)
    lb = np.linalg.solve(M[None], rhs[..., None])[..., 0]  # (k, m, 2)
    lam = np.concatenate([1 - lb.sum(-1, keepdims=True), lb], axis=-1)
    inside = (lam >= -1e-10).all(-1)
    assert inside.any(axis=1).all()
    assert inside[np.arange(len(X)), face].all()  # the returned triangle contains the point
    np.testing.assert_allclose(bary, lam[np.arange(len(X)), face], atol=1e-10)


def test_sampling_keeps_query_shape_and_clamps_outside_points():
    V, F = datasets.grid_patch(4)
    P = sample_surface(V, F, V[:, :2], uniform_grid(5))
    assert P.shape == (5, 5, 3)
    np.testing.assert_allclose(sample_surface(V, F, V[:, :2], [[-0.5, 0.5], [1.5, 2.0]]), [[0, 0.5, 0], [1, 1, 0]])
    with pytest.raises(MeshError, match="uv_points"):
        sample_surface(V, F, V[:, :2], np.zeros((3, 3)))
    with pytest.raises(MeshError, match="UV"):
        sample_surface(V, F, V[:5, :2], np.zeros((3, 2)))


# ------------------------------------------------------------------------------------------------
# Task 3: naive VDM


def test_naive_vdm_recovers_the_exact_displacement_of_the_rock():
    # rock_on_plinth(n) displaces the vertices of grid_patch(n): with the grid's xy as UV, the naive
    # (n+1)^2 VDM samples exactly the vertices, so D must be V - grid.
    n = 16
    V, F = datasets.rock_on_plinth(n)
    Vg, _ = datasets.grid_patch(n)
    D = naive_vdm(V, F, Vg[:, :2], n + 1)
    np.testing.assert_allclose(D.reshape(-1, 3), V - Vg, atol=1e-12)
    Vr, Fr = vdm_to_mesh(VDM(D, uniform_grid(n + 1), np.ones((n, n), bool)))
    np.testing.assert_allclose(Vr, V, atol=1e-12)


def test_vdm_to_mesh_faces_follow_the_diagonal_flags():
    F = grid_faces(3, [[True, False], [False, True]])
    assert F.tolist()[:4] == [[0, 1, 4], [0, 4, 3], [1, 2, 4], [2, 5, 4]]
    UV = uniform_grid(3).reshape(-1, 2)
    assert _signed_areas(UV, F).min() > 0


def test_save_and_load_vdm(tmp_path, box):
    vdm = bake_vdm(*box, 8, optimize=False)
    npz, png = save_vdm(tmp_path / "box", vdm)
    back = load_vdm(npz)
    np.testing.assert_array_equal(back.displacement, vdm.displacement)
    np.testing.assert_array_equal(back.diagonals, vdm.diagonals)
    img = read_image(png)
    assert img.dtype == np.uint16 and img.shape == (8, 8, 3)
    assert img.min() == 0 and img.max() == 65535
    # Row 0 of the preview is v = 1 (texture convention).
    D = vdm.displacement
    lo, hi = D.reshape(-1, 3).min(0), D.reshape(-1, 3).max(0)
    np.testing.assert_allclose(img[0] / 65535 * (hi - lo) + lo, D[-1], atol=(hi - lo).max() / 65535)


# ------------------------------------------------------------------------------------------------
# Tasks 4-5: importance


def test_importance_matches_trimesh_dihedral_angles(box, rock):
    trimesh = pytest.importorskip("trimesh")
    for V, F in (box, rock):
        m = trimesh.Trimesh(V, F, process=False)
        s = 0.5 - 0.5 * np.cos(m.face_adjacency_angles)
        expected = np.zeros(len(V))
        np.maximum.at(expected, m.face_adjacency_edges[:, 0], s)
        np.maximum.at(expected, m.face_adjacency_edges[:, 1], s)
        np.testing.assert_allclose(vertex_importance(V, F), expected, atol=1e-12)


def test_importance_hand_values(box):
    # Two triangles folded by 90 degrees: 0.5 - 0.5 cos 90 = 0.5 on the fold, 0 elsewhere.
    V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]
    np.testing.assert_allclose(vertex_importance(V, [[0, 1, 2], [1, 0, 3]]), [0.5, 0.5, 0, 0])
    V, F = box
    imp = vertex_importance(V, F)
    on_crease = np.isclose(V, 0).sum(1) + np.isclose(V, 1).sum(1) + np.isclose(V[:, 2:], 0.5).sum(1) >= 2
    on_crease &= V[:, 2] > 0  # the rim has no interior edge across it
    np.testing.assert_allclose(imp[on_crease], 0.5, atol=1e-12)
    np.testing.assert_allclose(imp[~on_crease & (V[:, 2] > 0)], 0, atol=1e-12)


def test_importance_field_hand_values():
    res, sigma = 8, 0.1
    uv = np.array([[2.5 / res, 3.5 / res], [6.5 / res, 6.5 / res]])  # pixel centres (row 3, col 2), (6, 6)
    f = importance_field(uv, [1.0, 0.25], res, background=0.1, sigma=sigma)
    assert f.shape == (res, res)
    assert f[3, 2] == pytest.approx(1.1)
    assert f[3, 3] == pytest.approx(0.1 + np.exp(-((1 / res) ** 2) / (2 * sigma**2)))
    # max, not sum: near the weak vertex the strong one's tail is smaller than 0.25
    assert f[6, 6] == pytest.approx(0.1 + max(0.25, np.exp(-((4 / res) ** 2 + (3 / res) ** 2) / (2 * sigma**2))))
    # Against the dense definition everywhere (within the 3 sigma cut-off).
    yy, xx = np.meshgrid((np.arange(res) + 0.5) / res, (np.arange(res) + 0.5) / res, indexing="ij")
    d2 = (xx[..., None] - uv[:, 0]) ** 2 + (yy[..., None] - uv[:, 1]) ** 2
    dense = 0.1 + (np.array([1.0, 0.25]) * np.exp(-d2 / (2 * sigma**2)) * (d2 <= (3 * sigma) ** 2)).max(-1)
    np.testing.assert_allclose(f, dense, atol=np.exp(-4.5) + 1e-12)
    with pytest.raises(MeshError, match="negative"):
        importance_field(uv, [1.0, -1.0], res)
    with pytest.raises(MeshError, match="background"):
        importance_field(uv, [1.0, 1.0], res, background=0.0)


# ------------------------------------------------------------------------------------------------
# Task 6: transport


def test_legendre_transform_and_poisson_solver():
    n = 16
    t = (np.arange(n) + 0.5) / n
    y, x = np.meshgrid(t, t, indexing="ij")
    f = 0.5 * (x**2 + y**2)
    np.testing.assert_allclose(legendre_transform(f), f, atol=1e-15)  # |x|^2/2 is self-dual on the grid
    g = np.random.default_rng(3).random((n, n))
    brute = (x.ravel()[:, None] * x.ravel()[None] + y.ravel()[:, None] * y.ravel()[None] - g.ravel()[None]).max(1)
    np.testing.assert_allclose(legendre_transform(g).ravel(), brute, atol=1e-14)
    r = np.random.default_rng(4).random((n, n))
    r -= r.mean()
    w = inverse_neg_laplacian(r)
    p = np.pad(w, 1, mode="edge")  # Neumann: mirrored ghost cells
    lap = (p[2:, 1:-1] + p[:-2, 1:-1] + p[1:-1, 2:] + p[1:-1, :-2] - 4 * w) * n * n
    np.testing.assert_allclose(-lap, r, atol=1e-10)


def _field(kind, n=32):
    t = (np.arange(n) + 0.5) / n
    y, x = np.meshgrid(t, t, indexing="ij")
    if kind == "blob":
        return 0.1 + np.exp(-((x - 0.3) ** 2 + (y - 0.6) ** 2) / (2 * 0.08**2))
    return 0.05 + 0.5 * np.exp(-((x + y - 1.2) ** 2 / 2) / (2 * 0.04**2))


@pytest.mark.parametrize("kind", ["blob", "line"])
def test_transport_matches_pot_exact_ot(kind):
    pytest.importorskip("ot")
    from solutions.vdm.transport import soft_legendre_map

    n = 32
    nu = _field(kind, n)
    phi, _, info = bfm_potentials(nu, 20)
    t = (np.arange(n) + 0.5) / n
    X = pixel_centres(n)
    T_pot, cost = pot_transport_map(nu)  # barycentric projection of the exact plan
    T = soft_legendre_map(phi, t, t, 1.0 / n**2).reshape(-1, 2)
    assert 2 * info["dual"] == pytest.approx(cost, rel=0.02)  # dual value = W2^2 / 2
    assert np.mean(np.sum((T - X) ** 2, axis=1)) == pytest.approx(cost, rel=0.06)
    err = np.linalg.norm(T - T_pot, axis=1) * n  # in pixels
    assert err.mean() < 0.5 and err.max() < 2.0


def test_transport_pushes_uniform_to_the_field():
    nu = _field("blob", 48)
    phi, psi, _ = bfm_potentials(nu, 20)
    rho = pushforward(psi, np.ones_like(nu))
    nu = nu * nu.size / nu.sum()
    assert np.abs(rho - nu).sum() / nu.sum() < 0.15
    # Grid cells shrink where the field is large: area x density is nearly constant.
    G = transport_grid(nu, 24)
    c = 0.25 * (G[:-1, :-1] + G[1:, 1:] + G[1:, :-1] + G[:-1, 1:])
    p, q = G[1:, 1:] - G[:-1, :-1], G[1:, :-1] - G[:-1, 1:]
    area = 0.5 * np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])
    i = np.clip((c[..., 1] * 48).astype(int), 0, 47)
    j = np.clip((c[..., 0] * 48).astype(int), 0, 47)
    mass = area * nu[i, j]
    assert np.std(mass) / np.mean(mass) < 0.35
    assert area.max() / area.min() > 4


@pytest.mark.parametrize("boundary", ["slide", "fixed"])
@pytest.mark.parametrize("kind", ["blob", "line", "rock", "box"])
def test_transport_grid_is_bijective_with_boundary_on_edges(kind, boundary, rock, box):
    if kind in ("rock", "box"):
        V, F = rock if kind == "rock" else box
        field = importance_field(parameterize_square(V, F), vertex_importance(V, F), 64)
    else:
        field = _field(kind, 64)
    for res in (8, 17, 32):
        G, info = transport_grid(field, res, boundary=boundary, return_info=True)
        assert info["blend"] == 1.0
        assert convex_cells(G).all() and not folded_cells(G).any()
        U0 = uniform_grid(res)
        np.testing.assert_array_equal(G[:, 0, 0], 0)
        np.testing.assert_array_equal(G[:, -1, 0], 1)
        np.testing.assert_array_equal(G[0, :, 1], 0)
        np.testing.assert_array_equal(G[-1, :, 1], 1)
        np.testing.assert_array_equal(G[[0, 0, -1, -1], [0, -1, 0, -1]], U0[[0, 0, -1, -1], [0, -1, 0, -1]])
        if boundary == "fixed":
            for edge in (np.s_[0, :], np.s_[-1, :], np.s_[:, 0], np.s_[:, -1]):
                np.testing.assert_allclose(G[edge], U0[edge], atol=1e-12)


def test_uniform_field_gives_uniform_grid():
    np.testing.assert_allclose(transport_grid(np.full((32, 32), 0.3), 17), uniform_grid(17), atol=1e-12)


def test_transport_rejects_bad_fields():
    with pytest.raises(MeshError, match="strictly positive"):
        transport_grid(np.zeros((8, 8)), 4)
    with pytest.raises(MeshError, match="square"):
        transport_grid(np.ones((8, 9)), 4)
    with pytest.raises(MeshError, match="row"):
        transport_grid(np.full((8, 8), np.nan), 4)
    with pytest.raises(MeshError, match="res"):
        transport_grid(np.ones((8, 8)), 1)


# ------------------------------------------------------------------------------------------------
# Task 7: features and alignment


def test_sharp_features_of_the_open_box_match_trimesh(box):
    trimesh = pytest.importorskip("trimesh")
    V, F = box
    edges, corners = sharp_features(V, F, 30)
    m = trimesh.Trimesh(V, F, process=False)
    sharp = np.sort(m.face_adjacency_edges[m.face_adjacency_angles > np.deg2rad(30)], axis=1)
    assert {tuple(e) for e in edges.tolist()} == {tuple(e) for e in sharp.tolist()}
    assert len(edges) == 8 * 8  # 4 top + 4 vertical creases, 8 segments each
    np.testing.assert_allclose(np.sort(V[corners], axis=0), np.sort(_box_corners()[1::2], axis=0))
    assert len(sharp_features(V, F, 91)[0]) == 0
    with pytest.raises(MeshError, match="angle"):
        sharp_features(V, F, 0)


@pytest.mark.parametrize("res", [16, 32])
def test_alignment_puts_box_corners_exactly_on_the_grid(res, box):
    V, F = box
    for stages in (dict(optimize=True, align=True, diagonals=False), dict(optimize=False, align=True, diagonals=True)):
        vdm = bake_vdm(V, F, res, **stages)
        Vr, _ = vdm_to_mesh(vdm)
        d = np.linalg.norm(Vr[None] - _box_corners()[:, None], axis=2).min(axis=1)
        assert d.max() < 1e-6, d
        assert not folded_cells(vdm.grid_uv).any()


def test_alignment_rules(rock):
    V, F = rock
    UV = parameterize_square(V, F)
    G = transport_grid(importance_field(UV, vertex_importance(V, F), 64), 32)
    edges, corners = sharp_features(V, F)
    G2, moved = align_to_features(G, V, F, UV, edges, corners, return_moved=True)
    changed = (G2 != G).any(axis=-1)
    assert changed.sum() > 20
    assert not (changed & ~moved).any()  # only vertices marked as moved changed
    assert not folded_cells(G2).any()
    # Boundary vertices stay on their edges, the square's corners stay put.
    np.testing.assert_array_equal(G2[:, 0, 0], 0)
    np.testing.assert_array_equal(G2[-1, :, 1], 1)
    np.testing.assert_array_equal(G2[[0, -1], [0, -1]], G[[0, -1], [0, -1]])
    # Moved vertices lie on a sharp edge (in uv) or on a sharp corner.
    P = G2[moved & changed]
    A, B = UV[edges[:, 0]], UV[edges[:, 1]]
    t = np.clip(np.einsum("pkd,kd->pk", P[:, None] - A[None], B - A) / np.sum((B - A) ** 2, 1), 0, 1)
    dist = np.linalg.norm(A[None] + t[..., None] * (B - A)[None] - P[:, None], axis=2).min(axis=1)
    assert dist.max() < 1e-9


# ------------------------------------------------------------------------------------------------
# Task 8: diagonals


def _roof(n=8, anti=True):
    """A flat grid folded into a roof along u + v = 1 (the cells' b-d diagonals)."""
    V, F = datasets.grid_patch(n)
    q = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    F = np.r_[np.c_[a, b, d], np.c_[b, c, d]] if anti else np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    V = V.copy()
    V[:, 2] = 0.3 * np.minimum(V[:, 0] + V[:, 1], 2 - V[:, 0] - V[:, 1])
    return V, F


def test_diagonals_follow_a_crease_along_the_anti_diagonal():
    V, F = _roof()
    UV = parameterize_square(V, F)
    np.testing.assert_allclose(UV, V[:, :2], atol=1e-12)
    edges, _ = sharp_features(V, F)
    res = 9  # grid vertices coincide with mesh vertices, the crease runs through them
    G = uniform_grid(res)
    diag = choose_diagonals(G, V, F, UV, edges)
    crossed = crossed_cells(G, UV[edges[:, 0]], UV[edges[:, 1]])
    on_crease = np.add.outer(np.arange(res - 1), np.arange(res - 1)) == res - 2  # cells whose b-d is the crease
    np.testing.assert_array_equal(crossed, on_crease)
    np.testing.assert_array_equal(diag, ~on_crease)  # b-d (False) on the crease, default elsewhere
    D = naive_vdm(V, F, UV, res)
    for flags, exact in ((diag, True), (np.ones_like(diag), False)):
        Vr, Fr = vdm_to_mesh(VDM(D, G, flags))
        h = mesh_distance(V, F, Vr, Fr, n_samples=5000)["hausdorff"]
        assert (h < 1e-12) == exact


def test_diagonals_never_pick_a_flipped_split():
    from solutions.vdm.grid import split_ok

    G = uniform_grid(3).copy()
    G[1, 1] = [0.2, 0.2]  # cell (0, 0) becomes non-convex: only its a-c split has two positive triangles
    V, F = _roof(2)
    ok = split_ok(G)
    assert ok[0, 0].tolist() == [True, False]
    for default in (True, False):
        diag = choose_diagonals(G, V, F, V[:, :2], sharp_features(V, F)[0], default=default)
        assert np.where(diag, ok[..., 0], ok[..., 1]).all()
        assert diag[0, 0]


# ------------------------------------------------------------------------------------------------
# The headline: every stage lowers the error on sharp shapes


def _errors(V, F, res, UV):
    out = []
    for st in STAGES:
        Vr, Fr = vdm_to_mesh(bake_vdm(V, F, res, UV=UV, **st))
        d = mesh_distance(V, F, Vr, Fr, n_samples=20000)
        out.append((d["hausdorff"], d["chamfer"]))
    return np.array(out)


@pytest.mark.parametrize("res", [16, 32])
def test_each_stage_lowers_the_error_on_the_box(res, box):
    V, F = box
    err = _errors(V, F, res, parameterize_square(V, F))
    assert (np.diff(err[:, 1]) < 0).all(), err  # chamfer: strictly lower at every stage
    assert (err[1:, 0] <= err[:-1, 0] * (1 + 1e-6)).all(), err  # hausdorff: never higher
    assert err[-1].max() < 1e-12  # creases land on grid edges: the box is reproduced exactly


def test_each_stage_lowers_the_error_on_the_rock(rock):
    V, F = rock
    err = _errors(V, F, 32, parameterize_square(V, F))
    assert (np.diff(err[:, 1]) < 0).all(), err  # chamfer: strictly lower at every stage
    assert (err[1:, 0] <= err[:-1, 0] * (1 + 1e-6)).all(), err  # hausdorff: never higher
    assert err[-1, 0] < 0.5 * err[0, 0] and err[-1, 1] < 0.4 * err[0, 1]


def test_area_weighting_helps_the_rock(rock):
    V, F = rock
    UV = parameterize_square(V, F)
    d = [
        mesh_distance(V, F, *vdm_to_mesh(bake_vdm(V, F, 32, UV=UV, area_weighted=w)), n_samples=20000)
        for w in (False, True)
    ]
    assert d[1]["chamfer"] < d[0]["chamfer"] and d[1]["hausdorff"] < d[0]["hausdorff"]


def test_smooth_height_field_gains_from_density_only():
    V, F = datasets.height_field(32)
    assert len(sharp_features(V, F)[0]) == 0  # all dihedral angles below 30 degrees
    err = _errors(V, F, 16, parameterize_square(V, F))
    assert err[1, 1] < err[0, 1]
    np.testing.assert_allclose(err[2:], err[[1, 1]], rtol=1e-9)  # no sharp features: stages 3 and 4 change nothing


def test_bake_rejects_bad_input(box):
    V, F = box
    with pytest.raises(MeshError, match="res"):
        bake_vdm(V, F, 1)
    with pytest.raises(MeshError, match="closed"):
        bake_vdm(*datasets.sharp_box(), 8)
    with pytest.raises(MeshError, match="triangles"):
        bake_vdm(V, F[:, :2], 8)
    with pytest.raises(MeshError, match="angle"):
        bake_vdm(V, F, 8, angle=200)


def test_grid_functions_reject_bad_shapes(box):
    V, F = box
    UV = parameterize_square(V, F)
    edges, corners = sharp_features(V, F)
    with pytest.raises(MeshError, match="grid_uv"):
        align_to_features(np.zeros((4, 5, 2)), V, F, UV, edges, corners)
    with pytest.raises(MeshError, match="grid_uv"):
        choose_diagonals(np.zeros((4, 4, 3)), V, F, UV, edges)
    with pytest.raises(MeshError, match=f"edges holds vertex index {int(edges.max()) + len(V)}"):
        choose_diagonals(uniform_grid(4), V, F, UV, edges + len(V))
    with pytest.raises(MeshError, match="corners holds vertex index -1"):
        align_to_features(uniform_grid(4), V, F, UV, edges, [-1])
    with pytest.raises(MeshError, match="diagonals"):
        vdm_to_mesh(VDM(np.zeros((4, 4, 3)), uniform_grid(4), np.ones((4, 4), bool)))
    with pytest.raises(MeshError, match="grid_uv"):
        naive_vdm(V, F, UV, 4, grid_uv=uniform_grid(5))


def test_boundary_to_square_rejects_bad_corners():
    from solutions.vdm import boundary_to_square

    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [0, 1, 0.0]])
    np.testing.assert_allclose(
        boundary_to_square(V, np.arange(6), [0, 2, 3, 5]), [[0, 0], [0.5, 0], [1, 0], [1, 1], [0.5, 1], [0, 1]]
    )
    with pytest.raises(MeshError, match="loop order"):
        boundary_to_square(V, np.arange(6), [0, 3, 2, 5])
    with pytest.raises(MeshError, match="loop"):
        boundary_to_square(V, [0, 1, 7, 3], [0, 1, 2, 3])


def test_bake_vdm_validates_its_mesh_once(monkeypatch):
    """Issue 15: a bake used to re-validate the same mesh ~15 times; now at the entry and once for the
    manifold check of the parameterization (which asks for more than the entry checked)."""
    import geomlib.validate as gv
    from solutions.vdm import bake_vdm

    V, F = datasets.rock_on_plinth(24)
    wheres = []
    real = gv.as_vertices
    monkeypatch.setattr(gv, "as_vertices", lambda *a, **k: wheres.append(k.get("where")) or real(*a, **k))
    bake_vdm(V, F, 16)
    # closest_points checks its query points (not the mesh) when features are aligned
    assert [w for w in wheres if w != "closest_points"] == ["bake_vdm", "parameterize_square"], wheres
