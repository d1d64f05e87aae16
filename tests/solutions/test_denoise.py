"""Cross-checks of the denoise reference solution against independent code, and its properties.

Independent references: libigl's adjacency matrix, trimesh's Laplacian operator and Laplacian
filter, a cotangent Laplacian written out from the formula here, matplotlib's linear triangle
interpolator (baking), scipy.ndimage's bilinear ``map_coordinates`` (map lookups), and the
seamless ``datasets.torus`` (welding ``datasets.uv_torus`` must give the same mesh). Thresholds on
the denoising result are the ones the lab's issue states.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial import cKDTree

from geomlib import datasets, geometry, topology
from geomlib.textures import rasterize_uv
from geomlib.validate import MeshError
from solutions.denoise import (
    bake_offset_map,
    denoise_vertices,
    denoise_with_map,
    error_stats,
    laplacian_offsets,
    make_noisy,
    normal_offsets,
    quantisation_step,
    seam_mean,
    weld_seams,
)

RNG = np.random.default_rng(7)


def noisy(make, sigma_rel=0.3, seed=0):
    out = make()
    V, F = out[0], out[1]
    Vn, N = make_noisy(V, F, sigma_rel, seed)
    return (V, F, Vn, N) + tuple(out[2:])


def ico4():
    return datasets.icosphere(4)


def nut():
    return datasets.pyvista_mesh("nut")


def copy_spread(X: np.ndarray, group: np.ndarray) -> float:
    """Largest distance of a vertex from the mean of its seam group (0 when copies coincide)."""
    k = int(group.max()) + 1
    c = np.stack([np.bincount(group, weights=X[:, i], minlength=k) for i in range(3)], 1)
    c /= np.bincount(group, minlength=k)[:, None]
    return float(np.linalg.norm(X - c[group], axis=1).max())


def uv_lipschitz(F: np.ndarray, UV: np.ndarray, s: np.ndarray) -> float:
    """Largest |gradient| over UV triangles of the piecewise-linear interpolant of s (a Lipschitz constant)."""
    A, B, C = UV[F[:, 0]], UV[F[:, 1]], UV[F[:, 2]]
    M = np.stack([B - A, C - A], axis=1)  # (m, 2, 2): rows are edge vectors
    ds = np.stack([s[F[:, 1]] - s[F[:, 0]], s[F[:, 2]] - s[F[:, 0]]], axis=1)
    ok = np.abs(np.linalg.det(M)) > 1e-15
    g = np.linalg.solve(M[ok], ds[ok][:, :, None])[:, :, 0]
    return float(np.linalg.norm(g, axis=1).max())


# --------------------------------------------------------------------------------------------
# Task 1: Laplacian offsets against libigl, trimesh and the written-out cotangent formula


@pytest.mark.parametrize(
    "make", [ico4, datasets.torus, nut, lambda: datasets.height_field(12)], ids=["ico4", "torus", "nut", "height_field"]
)
def test_uniform_offsets_match_igl_adjacency(make):
    V, F, Vn, _ = noisy(make)
    A = igl.adjacency_matrix(F).astype(np.float64)
    deg = np.asarray(A.sum(axis=1)).ravel()
    expected = Vn - (A @ Vn) / deg[:, None]
    np.testing.assert_allclose(laplacian_offsets(Vn, F, weld=False), expected, atol=1e-12)


@pytest.mark.parametrize("make", [ico4, datasets.torus, nut], ids=["ico4", "torus", "nut"])
def test_uniform_offsets_match_trimesh(make):
    import trimesh

    _, F, Vn, _ = noisy(make, seed=3)
    Lt = trimesh.smoothing.laplacian_calculation(trimesh.Trimesh(Vn, F, process=False), equal_weight=True)
    np.testing.assert_allclose(laplacian_offsets(Vn, F), Vn - Lt @ Vn, atol=1e-12)


def cotan_offsets_by_formula(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """delta_i = p_i - sum_j w_ij p_j / sum_j w_ij, w_ij = (cot alpha + cot beta) / 2, from the corner angles."""
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):  # the corner opposite edge (a, b)
        k, a, b = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, v = V[a] - V[k], V[b] - V[k]
        cot = np.einsum("ij,ij->i", u, v) / np.linalg.norm(np.cross(u, v), axis=1)
        rows += [a, b]
        cols += [b, a]
        vals += [cot / 2, cot / 2]
    W = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    wsum = np.asarray(W.sum(axis=1)).ravel()
    return V - (W @ V) / wsum[:, None]


@pytest.mark.parametrize(
    "make", [ico4, datasets.torus, nut, lambda: datasets.height_field(12)], ids=["ico4", "torus", "nut", "height_field"]
)
def test_cotan_offsets_match_the_formula(make):
    _, F, Vn, _ = noisy(make, seed=1)
    np.testing.assert_allclose(laplacian_offsets(Vn, F, "cotan"), cotan_offsets_by_formula(Vn, F), atol=1e-10)


def test_offsets_of_a_pyramid_apex_by_hand():
    V = np.array([[0.2, -0.1, 1.5], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0.0]])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    d = laplacian_offsets(V, F)
    np.testing.assert_allclose(d[0], [0.2, -0.1, 1.5], atol=1e-15)  # the base's mean is the origin
    # vertex 1 has neighbours 0, 2, 4: mean = (0.2, -0.1 + 1 - 1, 1.5) / 3
    np.testing.assert_allclose(d[1], np.array([1, 0, 0]) - np.array([0.2, -0.1, 1.5]) / 3, atol=1e-15)


def test_flat_meshes_have_zero_interior_offsets():
    # Regular grid: every interior neighbourhood is symmetric, so uniform offsets vanish there.
    V, F = datasets.grid_patch(8)
    interior = np.ones(len(V), bool)
    interior[topology.boundary_edges(F).ravel()] = False
    np.testing.assert_allclose(laplacian_offsets(V, F)[interior], 0.0, atol=1e-14)
    # Irregular flat mesh: cotan weights have linear precision (interior offsets 0), uniform ones do not.
    Vj = V.copy()
    Vj[interior, :2] += RNG.uniform(-0.02, 0.02, size=(interior.sum(), 2))
    assert np.abs(laplacian_offsets(Vj, F, "cotan")[interior]).max() < 1e-12
    assert np.abs(laplacian_offsets(Vj, F, "uniform")[interior]).max() > 1e-3


def test_offsets_are_translation_invariant_and_rotation_equivariant():
    _, F, Vn, _ = noisy(datasets.torus, seed=2)
    Q, _ = np.linalg.qr(RNG.normal(size=(3, 3)))
    for w in ("uniform", "cotan"):
        d = laplacian_offsets(Vn, F, w)
        np.testing.assert_allclose(laplacian_offsets(Vn @ Q.T + [3.0, -1.0, 2.0], F, w), d @ Q.T, atol=1e-12)


def test_clean_sphere_offsets_measure_curvature():
    V, F = datasets.icosphere(4)
    N = geometry.vertex_normals(V, F)
    h = geometry.mean_edge_length(V, F)
    tangential = {}
    for w in ("uniform", "cotan"):
        d = laplacian_offsets(V, F, w)
        s = normal_offsets(d, N)
        assert (s > 0).all()  # every vertex sticks out of its neighbourhood: curvature
        assert 0.3 * h**2 < np.median(s) < 0.7 * h**2  # about h^2 / (2 R) with R = 1
        tangential[w] = np.linalg.norm(d - s[:, None] * N, axis=1) / s
    # cotan offsets follow the normal (mean-curvature normal); uniform ones also slide along the surface
    assert tangential["cotan"].max() < 0.01
    assert np.median(tangential["uniform"]) > 0.1


def test_isolated_vertex_gets_zero_offset():
    V, F = datasets.icosphere(1)
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    for w in ("uniform", "cotan"):
        d = laplacian_offsets(V2, F, w)
        np.testing.assert_array_equal(d[-1], 0.0)
        np.testing.assert_allclose(d[:-1], laplacian_offsets(V, F, w), atol=1e-15)


# --------------------------------------------------------------------------------------------
# Tasks 2 and 3: projection and the direct route


def test_normal_offsets_by_hand_and_normalisation():
    s = normal_offsets([[1.0, 2.0, 3.0], [0.5, 0.0, -1.0]], [[0.0, 0.0, 2.0], [3.0, 0.0, 4.0]])
    np.testing.assert_allclose(s, [3.0, (1.5 - 4.0) / 5.0], atol=1e-15)


@pytest.mark.parametrize("lam", [0.3, 0.7, 1.0])
def test_one_pass_matches_trimesh_filter_projected_on_normals(lam):
    import trimesh

    _, F, Vn, N = noisy(datasets.torus, seed=4)
    tm = trimesh.Trimesh(Vn.copy(), F, process=False)
    trimesh.smoothing.filter_laplacian(tm, lamb=lam, iterations=1, volume_constraint=False)
    step = np.asarray(tm.vertices) - Vn  # = -lam * delta (uniform, Jacobi)
    expected = Vn + np.einsum("ij,ij->i", step, N)[:, None] * N
    np.testing.assert_allclose(denoise_vertices(Vn, F, N, lam), expected, atol=1e-12)


def test_vertices_move_along_normals_only_and_lambda_zero_is_identity():
    _, F, Vn, N = noisy(ico4, seed=5)
    np.testing.assert_array_equal(denoise_vertices(Vn, F, N, 0.0), Vn)
    D = denoise_vertices(Vn, F, N, 0.7, weights="cotan") - Vn
    np.testing.assert_allclose(np.cross(D, N), 0.0, atol=1e-14)


def test_iterations_repeat_the_pass():
    _, F, Vn, N = noisy(datasets.torus, seed=6)
    once = denoise_vertices(denoise_vertices(Vn, F, N, 0.3), F, N, 0.3)
    np.testing.assert_allclose(denoise_vertices(Vn, F, N, 0.3, iterations=2), once, atol=1e-14)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("make", [ico4, datasets.torus], ids=["icosphere4", "torus"])
def test_one_pass_at_lambda_07_cuts_the_mean_error_to_06(make, seed):
    V, F, Vn, N = noisy(make, 0.3, seed)
    before = error_stats(V, F, Vn)
    after = error_stats(V, F, denoise_vertices(Vn, F, N, 0.7))
    assert after["mean"] <= 0.6 * before["mean"], (after, before)
    assert after["max"] < before["max"]


def test_lambda_one_makes_a_curved_mesh_with_little_noise_worse():
    # The documented failure: curvature leaks into delta and the surface shrinks.
    V, F, Vn, N = noisy(ico4, 0.05, 0)
    before = error_stats(V, F, Vn)["mean"]
    assert error_stats(V, F, denoise_vertices(Vn, F, N, 1.0))["mean"] > 1.5 * before


# --------------------------------------------------------------------------------------------
# Task 6: seams


def test_welding_uv_torus_gives_the_seamless_torus():
    Vt, Ft = datasets.torus()
    Vu, Fu, _ = datasets.uv_torus()
    Vw, Fw, group = weld_seams(Vu, Fu)
    assert len(Vw) == len(Vt) and topology.is_closed(Fw) and topology.euler_characteristic(Fw) == 0
    np.testing.assert_array_equal(Vw[group], Vu)
    dist, idx = cKDTree(Vt).query(Vw)
    assert dist.max() == 0.0
    assert {tuple(f) for f in np.sort(idx[Fw], 1).tolist()} == {tuple(f) for f in np.sort(Ft, 1).tolist()}
    # so the welded offsets of the cut torus are the offsets of the seamless torus
    Vn, _ = make_noisy(Vt, Ft, 0.3, 0)
    Vnu = Vn[idx[group]]
    for w in ("uniform", "cotan"):
        np.testing.assert_allclose(laplacian_offsets(Vnu, Fu, w), laplacian_offsets(Vn, Ft, w)[idx[group]], atol=1e-12)
        cut = laplacian_offsets(Vnu, Fu, w, weld=False)
        assert np.abs(cut - laplacian_offsets(Vnu, Fu, w)).max() > 1e-2  # the seam vertices are wrong without it


def test_welding_uv_sphere_closes_it():
    V, F, _ = datasets.uv_sphere(16, 32)
    Vw, Fw, group = weld_seams(V, F)
    assert len(Vw) == 2 + 15 * 32  # two poles and 15 rings of 32
    assert topology.is_closed(Fw) and topology.euler_characteristic(Fw) == 2


def test_weld_is_the_identity_without_seams():
    V, F = datasets.icosphere(2)
    Vw, Fw, group = weld_seams(V, F)
    np.testing.assert_array_equal(Vw, V)
    np.testing.assert_array_equal(Fw, F)
    np.testing.assert_array_equal(group, np.arange(len(V)))


def test_seam_mean_by_hand():
    np.testing.assert_allclose(seam_mean([1.0, 2.0, 4.0, 8.0], [0, 1, 0, 1]), [2.5, 5.0])
    np.testing.assert_allclose(seam_mean([[1.0, 0], [3, 2]], [1, 1]), [[0.0, 0.0], [2.0, 1.0]])


@pytest.mark.parametrize("make", [datasets.uv_sphere, datasets.uv_torus], ids=["uv_sphere", "uv_torus"])
def test_seam_cracks_without_the_fix_and_not_with_it(make):
    V, F, Vn, N, UV = noisy(make, 0.3, 0)
    _, _, group = weld_seams(V, F)
    h = geometry.mean_edge_length(V, F)
    # direct route
    assert copy_spread(denoise_vertices(Vn, F, N, 0.7, weld=False), group) > 0.05 * h
    assert copy_spread(denoise_vertices(Vn, F, N, 0.7), group) < 1e-12
    # map route
    for weld in (False, True):
        s = normal_offsets(laplacian_offsets(Vn, F, weld=weld), N)
        img, bias, scale = bake_offset_map(Vn, F, UV, s, 256)
        X = denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7, weld=weld)
        assert (copy_spread(X, group) < 1e-12) if weld else (copy_spread(X, group) > 0.05 * h)
    # with correct offsets, the map lookup alone already opens the seam (the copies read different texels)
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    img, bias, scale = bake_offset_map(Vn, F, UV, s, 256)
    assert copy_spread(denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7, weld=False), group) > 1e-4 * h


# --------------------------------------------------------------------------------------------
# Task 4: baking, against matplotlib's linear triangle interpolation


@pytest.mark.parametrize("bits", [8, 16])
@pytest.mark.parametrize(
    "make", [lambda: datasets.uv_sphere(8, 16), lambda: datasets.uv_torus(12, 8)], ids=["uv_sphere", "uv_torus"]
)
def test_baked_texels_match_matplotlib_interpolation(make, bits):
    import matplotlib.tri as mtri

    _, F, Vn, N, UV = noisy(make)
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    size = 64
    img, bias, scale = bake_offset_map(Vn, F, UV, s, size, bits, padding=0)
    assert img.dtype == (np.uint8 if bits == 8 else np.uint16) and img.shape == (size, size)
    assert bias == s.min() and np.isclose(scale, s.max() - s.min())
    c = (np.arange(size) + 0.5) / size
    U, W = np.meshgrid(c, 1.0 - c)  # row 0 is v = 1
    exact = mtri.LinearTriInterpolator(mtri.Triangulation(UV[:, 0], UV[:, 1], F), s)(U, W)
    inside = ~np.ma.getmaskarray(exact)
    face_id, _ = rasterize_uv(F, UV, size)
    assert (inside == (face_id >= 0)).mean() > 0.995  # coverage agrees except exactly on chart borders
    both = inside & (face_id >= 0)
    decoded = bias + scale * img.astype(np.float64) / (2**bits - 1)
    # half a quantisation step, plus the rasterizer's 1/256-texel vertex snapping times the slope of s
    tol = quantisation_step(scale, bits) / 2 + uv_lipschitz(F, UV, s) * np.sqrt(2) * 0.5 / 256 / size + 1e-12
    assert np.abs(decoded[both] - np.asarray(exact)[both]).max() <= tol
    assert img[~(face_id >= 0)].max(initial=0) == 0  # padding=0 leaves the background at 0


def test_padding_fills_around_the_charts():
    _, F, Vn, N, UV = noisy(lambda: datasets.uv_sphere(8, 16))
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    face_id, _ = rasterize_uv(F, UV, 64)
    img0, _, _ = bake_offset_map(Vn, F, UV, s, 64, padding=0)
    img, _, _ = bake_offset_map(Vn, F, UV, s, 64, padding=None)
    covered = face_id >= 0
    assert (~covered).any()
    np.testing.assert_array_equal(img[covered], img0[covered])
    assert (img[~covered] > 0).all()  # every gap texel holds a chart value now


def test_constant_offsets_bake_to_zero_scale():
    V, F, UV = datasets.uv_grid(4)
    img, bias, scale = bake_offset_map(V, F, UV, np.full(len(V), 0.25), 16)
    assert (bias, scale) == (0.25, 0.0) and not img.any()


# --------------------------------------------------------------------------------------------
# Task 5: the map route, against scipy.ndimage's bilinear lookup and the direct route


def test_map_lookup_matches_scipy_map_coordinates():
    from scipy.ndimage import map_coordinates

    V, F, UV = datasets.uv_grid(10)
    N = np.tile([0.0, 0.0, 1.0], (len(V), 1))
    img = RNG.integers(0, 65536, size=(32, 32)).astype(np.uint16)
    X = denoise_with_map(V, F, UV, N, img, -0.1, 0.3, 0.5)
    s = (V - X)[:, 2] / 0.5
    # texel coordinates: x = u w - 1/2 (columns), y = (1 - v) h - 1/2 (rows); clamp-to-edge = mode "nearest"
    coords = np.stack([(1.0 - UV[:, 1]) * 32 - 0.5, UV[:, 0] * 32 - 0.5])
    expected = -0.1 + 0.3 * map_coordinates(img.astype(np.float64) / 65535, coords, order=1, mode="nearest")
    np.testing.assert_allclose(s, expected, atol=1e-12)


@pytest.mark.parametrize("bits", [8, 16])
@pytest.mark.parametrize("size", [256, 1024])
def test_map_route_matches_direct_route_within_quantisation_and_resampling(bits, size):
    V, F, Vn, N, UV = noisy(datasets.uv_torus, 0.3, 0)
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    img, bias, scale = bake_offset_map(Vn, F, UV, s, size, bits)
    lam = 0.7
    Xm = denoise_with_map(Vn, F, UV, N, img, bias, scale, lam)
    Xd = denoise_vertices(Vn, F, N, lam)
    # The four texels a bilinear lookup reads lie within a texel diagonal of the vertex (uv_torus
    # covers the whole square, so no padded texel is read); each holds s there up to the snapping.
    resample = uv_lipschitz(F, UV, s) * np.sqrt(2) * (1 + 0.5 / 256) / size
    bound = lam * (quantisation_step(scale, bits) / 2 + resample)
    diff = np.linalg.norm(Xm - Xd, axis=1)
    assert diff.max() <= bound
    # and the two routes denoise equally well
    e_m, e_d = error_stats(V, F, Xm)["mean"], error_stats(V, F, Xd)["mean"]
    assert abs(e_m - e_d) < 0.1 * e_d


def test_finer_maps_get_closer_to_the_direct_route():
    V, F, Vn, N, UV = noisy(datasets.uv_sphere, 0.3, 1)
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    Xd = denoise_vertices(Vn, F, N, 0.7)
    gaps = []
    for size in (128, 512):
        img, bias, scale = bake_offset_map(Vn, F, UV, s, size)
        gaps.append(np.abs(denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7) - Xd).max())
    assert gaps[1] < 0.5 * gaps[0]


def test_lookups_at_texel_centres_return_the_stored_texels():
    # A grid whose vertices sit exactly on the texel centres: the bilinear lookup reads one texel each,
    # so the map route reproduces the decoded texels exactly (the half-texel convention is right).
    V, F, UV = datasets.uv_grid(8)
    s = RNG.normal(size=len(V))
    Vg, Fg, UVg = datasets.uv_grid(63)
    UVg = (UVg * 63 + 0.5) / 64
    Ng = np.tile([0.0, 0.0, 1.0], (len(Vg), 1))
    col = np.floor(UVg[:, 0] * 64).astype(int)
    row = np.floor((1.0 - UVg[:, 1]) * 64).astype(int)
    for bits in (8, 16):
        img, bias, scale = bake_offset_map(V, F, UV, s, 64, bits)
        X = denoise_with_map(Vg, Fg, UVg, Ng, img, bias, scale, 1.0, weld=False)
        expected = bias + scale * img[row, col].astype(np.float64) / (2**bits - 1)
        np.testing.assert_allclose(Vg[:, 2] - X[:, 2], expected, atol=1e-12)


# --------------------------------------------------------------------------------------------
# bad input


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda V, F, N, UV: laplacian_offsets(V, F, "cot"), "weights must be one of"),
        (lambda V, F, N, UV: laplacian_offsets(V, F[:, :2]), r"triangles \(m, 3\)"),
        (lambda V, F, N, UV: laplacian_offsets(np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F), "row 3"),
        (lambda V, F, N, UV: laplacian_offsets(V, F, weld="yes"), "weld must be True or False"),
        (lambda V, F, N, UV: normal_offsets(V, N[:-1]), "N has .* rows but delta has"),
        (lambda V, F, N, UV: normal_offsets(V, np.zeros_like(N)), "row 0 is the zero vector"),
        (lambda V, F, N, UV: denoise_vertices(V, F, N, 1.5), "lam must be <= 1"),
        (lambda V, F, N, UV: denoise_vertices(V, F, N, -0.1), "lam must be >= 0"),
        (lambda V, F, N, UV: denoise_vertices(V, F, N, 0.5, iterations=0), "iterations must be >= 1"),
        (lambda V, F, N, UV: bake_offset_map(V, F, UV, np.zeros(len(V)), 64, bits=12), "bits must be 8 or 16"),
        (lambda V, F, N, UV: bake_offset_map(V, F, UV, np.zeros(len(V) - 1), 64), "s has .* values but V has"),
        (lambda V, F, N, UV: bake_offset_map(V, F, UV + 0.5, np.zeros(len(V)), 64), r"outside the texture square"),
        (lambda V, F, N, UV: bake_offset_map(V, F, UV, np.zeros(len(V)), 0), "size must be >= 2"),
        (lambda V, F, N, UV: bake_offset_map(V, F, None, np.zeros(len(V)), 64), "UV is missing"),
        (lambda V, F, N, UV: denoise_with_map(V, F, UV, N, np.zeros((8, 16)), 0, 1, 0.5), "square"),
        (lambda V, F, N, UV: denoise_with_map(V, F, UV, N, np.zeros((8, 8, 3)), 0, 1, 0.5), "single-channel"),
        (lambda V, F, N, UV: denoise_with_map(V, F, UV, N, np.full((8, 8), 2.0), 0, 1, 0.5), r"values span"),
        (lambda V, F, N, UV: denoise_with_map(V, F, UV, N, np.zeros((8, 8)), np.nan, 1, 0.5), "bias must be finite"),
        (lambda V, F, N, UV: seam_mean(np.zeros(3), [0, 1]), "group has 2 labels but values has 3"),
    ],
)
def test_bad_input_is_rejected_with_a_clear_message(call, match):
    V, F, UV = datasets.uv_grid(4)
    N = np.tile([0.0, 0.0, 1.0], (len(V), 1))
    with pytest.raises(MeshError, match=match):
        call(V, F, N, UV)


def test_cotan_rejects_zero_area_triangles():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])
    with pytest.raises(MeshError, match="face 0 .* has zero area"):
        laplacian_offsets(V, [[0, 1, 2], [0, 1, 3]], "cotan")
