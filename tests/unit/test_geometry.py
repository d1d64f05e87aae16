"""Tests for geomlib.geometry.

Expected values come from geometry worked out by hand (a sphere's area and normals, a cube's
right angles, the analytic ray/sphere intersection, the gap between concentric spheres) or from
an independent implementation: libigl's normals and Hausdorff distance, and a brute-force
Möller-Trumbore ray caster written out in this file.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest

from geomlib import datasets, geometry, topology
from geomlib.validate import MeshError

TRI_V = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
TRI_F = np.array([[0, 1, 2]])


@pytest.fixture(scope="module")
def sphere4():
    return datasets.icosphere(4)


# --------------------------------------------------------------------------------------------
# per-element measures


def test_single_triangle_by_hand():
    np.testing.assert_allclose(geometry.face_normals(TRI_V, TRI_F), [[0, 0, 1]])
    np.testing.assert_allclose(geometry.face_areas(TRI_V, TRI_F), [1.0])  # legs 2 and 1
    for w in ("area", "angle", "uniform"):
        np.testing.assert_allclose(geometry.vertex_normals(TRI_V, TRI_F, w), np.tile([0, 0, 1.0], (3, 1)))
    assert geometry.bbox_diagonal(TRI_V) == pytest.approx(np.sqrt(5))
    assert geometry.mean_edge_length(TRI_V, TRI_F) == pytest.approx((2 + 1 + np.sqrt(5)) / 3)
    E, ang = geometry.dihedral_angles(TRI_V, TRI_F)
    assert E.shape == (0, 2) and ang.shape == (0,)  # no interior edge


def test_face_normals_of_sphere_are_unit_and_outward(sphere4):
    V, F = sphere4
    N = geometry.face_normals(V, F)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0)
    assert (np.einsum("ij,ij->i", N, V[F].mean(axis=1)) > 0).all()


@pytest.mark.parametrize("weighting", ["area", "angle", "uniform"])
def test_vertex_normals_of_sphere_are_radial(weighting):
    V, F = datasets.icosphere(3)
    N = geometry.vertex_normals(V, F, weighting)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", N, V), -1, 1)))
    assert angle.max() < 1.0  # level 3 (642 vertices): measured at most 0.7 degrees


@pytest.mark.parametrize(
    "weighting, igl_type",
    [
        ("area", igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA),
        ("angle", igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_ANGLE),
        ("uniform", igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_UNIFORM),
    ],
)
def test_vertex_normals_match_libigl(weighting, igl_type):
    V, F = datasets.rock_on_plinth(16)
    np.testing.assert_allclose(
        geometry.vertex_normals(V, F, weighting), igl.per_vertex_normals(V, F, igl_type), atol=1e-12
    )


def test_isolated_and_degenerate_give_zero_not_nan():
    V = np.vstack([TRI_V, [[5.0, 5.0, 5.0]], [[1.0, 0.0, 0.0]]])  # vertex 3 unused; 4 on edge 0-1
    F = np.array([[0, 1, 2], [0, 4, 1]])  # second face has zero area
    np.testing.assert_array_equal(geometry.face_normals(V, F)[1], [0, 0, 0])
    for w in ("area", "angle", "uniform"):
        N = geometry.vertex_normals(V, F, w)
        assert np.isfinite(N).all()
        np.testing.assert_array_equal(N[3], [0, 0, 0])
        np.testing.assert_allclose(N[0], [0, 0, 1])


def test_sphere_area_converges_to_4_pi_r2():
    err = [abs(geometry.face_areas(*datasets.icosphere(k, radius=2.0)).sum() - 16 * np.pi) for k in range(6)]
    assert all(a > b for a, b in zip(err, err[1:]))  # inscribed polyhedra: monotone from below
    assert err[-1] / (16 * np.pi) < 1e-3


def test_dihedral_angles_of_box_are_right_angles():
    n = 3
    V, F = datasets.sharp_box((1.0, 2.0, 0.5), n)
    E, ang = geometry.dihedral_angles(V, F, signed=True)
    sharp = np.abs(ang - np.pi / 2) < 1e-12
    flat = np.abs(ang) < 1e-12
    assert (sharp | flat).all()  # convex edges are positive
    assert sharp.sum() == 12 * n  # the 12 box edges, each cut into n segments
    # every sharp edge lies on two coordinate bounds at once
    P = V[E[sharp]].reshape(-1, 3)
    on_bound = np.isclose(np.abs(P), [0.5, 1.0, 0.25]).sum(axis=1)
    assert (on_bound >= 2).all()


def test_dihedral_angle_sign_and_boundary_nan():
    # a "V" fold: two triangles sharing edge 0-1 (the x axis), one tilted up, one tilted down
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0.0], [0.5, -1, 1.0]])
    F = np.array([[0, 1, 2], [1, 0, 3]])
    E, ang = geometry.dihedral_angles(V, F, include_boundary=True)
    assert len(E) == 5 and np.isnan(ang).sum() == 4
    i = np.flatnonzero((E == [0, 1]).all(axis=1))[0]
    assert ang[i] == pytest.approx(np.pi / 4)  # normals (0, 0, 1) and (0, 1, 1) / sqrt(2)
    _, s = geometry.dihedral_angles(V, F, signed=True)
    # vertex 3 is lifted to the side the normals point to: the surface folds up, a valley
    assert s[0] == pytest.approx(-np.pi / 4)
    _, s2 = geometry.dihedral_angles(V, F[:, ::-1], signed=True)
    assert s2[0] == pytest.approx(np.pi / 4)  # flipped normals: the same fold is a ridge
    _, s3 = geometry.dihedral_angles(V * [1, 1, -1], F[:, ::-1], signed=True)
    assert s3[0] == pytest.approx(-np.pi / 4)  # a mirror image (orientation carried along) stays a valley


# --------------------------------------------------------------------------------------------
# closest points


def test_closest_points_on_surface_are_zero(sphere4):
    V, F = sphere4
    P, fid = geometry.random_points_on_mesh(V, F, 500, seed=1)
    d, face, C = geometry.closest_points(V, F, P)
    assert d.max() < 1e-20
    np.testing.assert_allclose(C, P, atol=1e-10)
    assert face.dtype == np.int64 and face.shape == (500,)


def test_closest_point_outside_convex_mesh_is_the_vertex(sphere4):
    V, F = sphere4
    d, _, C = geometry.closest_points(V, F, 2 * V[:50])
    np.testing.assert_allclose(d, 1.0)  # |2v - v| = 1, and the mesh lies inside the unit ball
    np.testing.assert_allclose(C, V[:50], atol=1e-12)


# --------------------------------------------------------------------------------------------
# ray casting


def brute_force_rays(V, F, O, D):
    """Independent reference: Möller-Trumbore against every triangle, nearest t > 0."""
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    e1, e2 = B - A, C - A
    p = np.cross(D[:, None, :], e2[None])
    det = np.einsum("ijk,jk->ij", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = O[:, None, :] - A[None]
        u = np.einsum("ijk,ijk->ij", s, p) / det
        q = np.cross(s, e1[None])
        v = np.einsum("ik,ijk->ij", D, q) / det
        t = np.einsum("ijk,jk->ij", q, e2) / det
    ok = (np.abs(det) > 1e-14) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    t = np.where(ok, t, np.inf)
    return np.isfinite(t.min(axis=1)), t.min(axis=1), t.argmin(axis=1)


def test_ray_cast_matches_brute_force():
    V, F = datasets.rock_on_plinth(16, seed=3)
    rng = np.random.default_rng(0)
    O = np.c_[rng.uniform(-0.2, 1.2, (300, 2)), np.full(300, 1.0)]
    D = np.c_[rng.normal(0, 0.3, (300, 2)), -np.ones(300)]
    hit, t, face, bary = geometry.ray_cast(V, F, O, D)
    bh, bt, bf = brute_force_rays(V, F, O, D)
    np.testing.assert_array_equal(hit, bh)
    np.testing.assert_allclose(t[hit], bt[hit], rtol=1e-12)
    np.testing.assert_array_equal(face[hit], bf[hit])
    np.testing.assert_allclose(
        np.einsum("ij,ijk->ik", bary[hit], V[F[face[hit]]]), O[hit] + t[hit, None] * D[hit], atol=1e-14
    )
    assert (t[~hit] == np.inf).all() and (face[~hit] == -1).all() and (bary[~hit] == 0).all()


def test_ray_cast_rays_beside_the_mesh_and_grazing_its_box_match_brute_force():
    """Most rays miss the mesh's box (ray_cast drops them before the traversal); the others start
    inside it, run in a box face's plane, graze its corners or stop before it: all as brute force."""
    V, F = datasets.icosphere(2)
    rng = np.random.default_rng(1)
    lo, hi = V.min(axis=0), V.max(axis=0)
    O = rng.uniform(-3, 3, (600, 3))
    D = rng.normal(size=(600, 3))
    O[:100] = rng.uniform(lo, hi, (100, 3))  # inside the box
    D[100:200, 2] = 0.0  # parallel to the z slabs
    O[100:200, 2] = np.where(rng.random(100) < 0.5, lo[2], hi[2])  # in a box face's plane
    O[200:300] = hi + rng.uniform(0.1, 1, (100, 3))
    D[200:300] = hi - O[200:300]  # aimed at the box's corner (just beside the sphere)
    a, r = rng.uniform(0, 2 * np.pi, 100), rng.uniform(0.9, 1.0, 100)
    O[300:400] = np.c_[r * np.cos(a), r * np.sin(a), np.full(100, 3.0)]
    D[300:400] = [0.0, 0.0, -1.0]  # down past the sphere's rim, near the box's sides
    for t_max in (np.inf, 2.0):
        hit, t, face, _ = geometry.ray_cast(V, F, O, D, t_max=t_max)
        with np.errstate(invalid="ignore"):  # rays parallel to a triangle: inf + inf in the reference
            bh, bt, bf = brute_force_rays(V, F, O, D)
        bh &= bt <= t_max
        np.testing.assert_array_equal(hit, bh)
        np.testing.assert_allclose(t[hit], bt[hit], rtol=1e-12)
        np.testing.assert_array_equal(face[hit], bf[hit])
        assert (t[~hit] == np.inf).all() and (face[~hit] == -1).all()
        assert 0 < hit.sum() < 0.5 * len(hit)


def test_ray_cast_against_analytic_sphere(sphere4):
    V, F = sphere4
    rng = np.random.default_rng(2)
    O = rng.normal(size=(400, 3))
    O = 3 * O / np.linalg.norm(O, axis=1, keepdims=True)
    D = -O + rng.normal(0, 0.4, size=O.shape)
    hit, t, face, bary = geometry.ray_cast(V, F, O, D)
    # |O + tD|^2 = 1:  t = (-b - sqrt(b^2 - ac)) / a  with a = D.D, b = O.D, c = O.O - 1
    a, b, c = (D * D).sum(1), (O * D).sum(1), (O * O).sum(1) - 1
    disc = b * b - a * c
    inside = disc > 0.05 * a  # stay clear of the silhouette, where the mesh and sphere differ
    t_sphere = (-b - np.sqrt(np.where(disc > 0, disc, 0))) / a
    assert hit[inside].all()
    P = O + t[:, None] * D
    # the mesh is inscribed: hits lie just inside the sphere (level 4: sag < 0.2%)
    r = np.linalg.norm(P[inside], axis=1)
    assert (r <= 1 + 1e-12).all() and (r > 0.998).all()
    assert np.abs(t - t_sphere)[inside].max() * np.sqrt(a[inside]).max() < 0.01
    assert (bary[hit] >= 0).all()
    np.testing.assert_allclose(bary[hit].sum(1), 1.0)


def test_ray_cast_is_watertight_at_vertices_and_edges():
    # Rays from the centre of a closed mesh through its vertices and edge midpoints must all hit.
    V, F = datasets.icosphere(3)
    E = topology.unique_edges(F)
    D = np.vstack([V, 0.5 * (V[E[:, 0]] + V[E[:, 1]])])
    hit, t, _, _ = geometry.ray_cast(V, F, np.zeros_like(D), D)
    assert hit.all()
    np.testing.assert_allclose(t[: len(V)], 1.0, rtol=1e-12)
    # Axis-aligned rays straight down onto a box's grid vertices and edges.
    n = 4
    Vb, Fb = datasets.sharp_box(n=n)
    g = np.arange(n + 1) / n - 0.5
    X, Y = np.meshgrid(np.r_[g, g[:-1] + 0.5 / n], np.r_[g, g[:-1] + 0.5 / n])
    O = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 2.0)]
    hit, t, _, _ = geometry.ray_cast(Vb, Fb, O, np.tile([0, 0, -1.0], (len(O), 1)))
    assert hit.all()
    np.testing.assert_allclose(t, 1.5)


def test_ray_cast_t_range_for_shadow_rays(sphere4):
    V, F = sphere4
    # rays leaving the surface outward: only the surface itself at t = 0, skipped with t_min
    hit, *_ = geometry.ray_cast(V, F, V[:200], V[:200], t_min=1e-9)
    assert not hit.any()
    # rays leaving inward hit the far side at t = 2 |v| ... but not if t_max is shorter
    hit, t, _, _ = geometry.ray_cast(V, F, V[:200], -V[:200], t_min=1e-9)
    assert hit.all() and np.allclose(t, 2.0, atol=1e-3)
    hit, *_ = geometry.ray_cast(V, F, V[:200], -V[:200], t_min=1e-9, t_max=1.9)
    assert not hit.any()


def test_ray_cast_does_not_trust_a_wrong_bound(monkeypatch):
    # libigl only supplies an upper bound on t. Feed a bogus one (a "hit" at t = 0.5 on a
    # triangle the ray misses): the exact search finds nothing before it and must retrace the
    # ray without the bound, finding the real hit at t = 2.
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-5, -5, -1], [5, -5, -1], [0, 5, -1.0]])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    real = geometry._accelerators

    class Liar:
        def intersect_ray_first(self, V, F, O, D, t_max):
            return np.zeros(len(O), np.int64), np.full(len(O), 0.5), np.zeros((len(O), 2))

    monkeypatch.setattr(geometry, "_accelerators", lambda V, F, need: (Liar(), real(V, F, need)[1]))
    hit, t, face, _ = geometry.ray_cast(V, F, [[-0.5, 0.5, 1.0]], [[0, 0, -1.0]])
    assert hit[0] and t[0] == pytest.approx(2.0) and face[0] == 1


def rays_at_the_origin(n: int, seed: int):
    """``n`` seeded rays from around radius 3, aimed near the origin (origins ``O``, directions ``D``)."""
    rng = np.random.default_rng(seed)
    O = rng.normal(size=(n, 3)) * 3
    return O, -O + rng.normal(size=O.shape)


def test_ray_cast_igl_method_agrees_on_generic_rays(sphere4):
    V, F = sphere4
    O, D = rays_at_the_origin(300, seed=5)
    exact = geometry.ray_cast(V, F, O, D)
    fast = geometry.ray_cast(V, F, O, D, method="igl")
    np.testing.assert_array_equal(exact[0], fast[0])
    np.testing.assert_array_equal(exact[2], fast[2])
    np.testing.assert_allclose(exact[1][exact[0]], fast[1][fast[0]], rtol=1e-12)


def test_ray_cast_small_chunks_give_the_same_answer(sphere4):
    V, F = sphere4
    O, D = rays_at_the_origin(100, seed=6)
    a = geometry.ray_cast(V, F, O, D)
    b = geometry.ray_cast(V, F, O, D, chunk=7)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


# --------------------------------------------------------------------------------------------
# sampling and distances


def test_random_points_on_mesh_is_area_uniform_and_seeded():
    # two triangles of areas 1 and 3 (a 1x2 and a 3x2 right triangle)
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [10, 0, 0], [13, 0, 0], [10, 2, 0.0]])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    P, fid, B = geometry.random_points_on_mesh(V, F, 40000, seed=3, return_barycentric=True)
    assert abs((fid == 1).mean() - 0.75) < 0.01
    np.testing.assert_allclose(np.einsum("ij,ijk->ik", B, V[F[fid]]), P)
    assert (B >= 0).all()
    # uniform inside a triangle: the mean is the centroid
    np.testing.assert_allclose(P[fid == 0].mean(0), V[:3].mean(0), atol=0.01)
    P2, fid2 = geometry.random_points_on_mesh(V, F, 40000, seed=3)
    np.testing.assert_array_equal(P, P2)
    assert not np.array_equal(P, geometry.random_points_on_mesh(V, F, 40000, seed=4)[0])


def test_mesh_distance_to_itself_is_zero(sphere4):
    V, F = sphere4
    d = geometry.mesh_distance(V, F, V, F, n_samples=5000)
    assert d["hausdorff"] < 1e-12 and d["chamfer"] < 1e-12 and d["rms"] < 1e-12


def test_mesh_distance_to_scaled_copy_is_the_gap():
    # Mesh 2 = 1.1 * mesh 1, both convex and inscribed in spheres of radii 1 and 1.1. Every
    # point of one surface is between 0.1 h_min and 0.1 from the other, where h_min is the
    # smallest distance of a face plane from the centre: for p on mesh 1, the distance to the
    # boundary of the larger polytope is min over faces g of (1.1 h_g - n_g . p) >= 0.1 h_min,
    # and at most 0.1 h_f on p's own face f; symmetrically for points of mesh 2.
    V, F = datasets.icosphere(3)
    N = geometry.face_normals(V, F)
    h_min = np.einsum("ij,ij->i", N, V[F[:, 0]]).min()
    assert 0.99 < h_min < 1
    d = geometry.mesh_distance(V, F, 1.1 * V, F, n_samples=5000, relative=False)
    for key in ("hausdorff", "chamfer", "rms"):
        assert 0.1 * h_min - 1e-12 <= d[key] <= 0.1 + 1e-12, key
    assert d["hausdorff"] > 0.1 * (1 - 1e-6)  # reached at the vertices
    # relative = absolute / bbox diagonal of mesh 1; the convenience functions pick one entry
    kw = dict(n_samples=2000, seed=3)
    absolute = geometry.mesh_distance(V, F, 1.1 * V, F, relative=False, **kw)
    rel = geometry.mesh_distance(V, F, 1.1 * V, F, **kw)
    assert rel["diagonal"] == pytest.approx(geometry.bbox_diagonal(V))
    for key in ("hausdorff", "chamfer", "rms"):
        assert rel[key] == pytest.approx(absolute[key] / rel["diagonal"])
    assert geometry.hausdorff_distance(V, F, 1.1 * V, F, **kw) == rel["hausdorff"]
    assert geometry.chamfer_distance(V, F, 1.1 * V, F, **kw) == rel["chamfer"]
    assert geometry.rms_distance(V, F, 1.1 * V, F, **kw) == rel["rms"]


def test_mesh_distance_is_deterministic_and_not_below_libigl():
    V1, F1 = datasets.height_field(12, seed=1)
    V2, F2 = datasets.height_field(20, seed=2)
    a = geometry.mesh_distance(V1, F1, V2, F2, n_samples=3000, seed=7)
    assert a == geometry.mesh_distance(V1, F1, V2, F2, n_samples=3000, seed=7)
    # libigl's Hausdorff distance looks at vertices only; ours includes them, so it is never smaller
    h = geometry.hausdorff_distance(V1, F1, V2, F2, n_samples=3000, relative=False)
    assert h >= igl.hausdorff(V1, F1, V2, F2) - 1e-12


def test_hausdorff_sees_what_vertex_based_hausdorff_misses():
    # A non-planar quad split along its two different diagonals: the meshes share all four
    # vertices (libigl's vertex-based distance is 0), but A's diagonal 0-2 lies at z = 0 and B's
    # diagonal 1-3 at z = h. The centre of A, (1/2, 1/2, 0), is at distance h / sqrt(2 h^2 + 1)
    # from B's plane h x + h y + z = 2h (and from B's other face, by symmetry), and so is the
    # centre of B from A.
    h = 0.5
    V = np.array([[0, 0, 0], [1, 0, h], [1, 1, 0], [0, 1, h]])
    FA, FB = np.array([[0, 1, 2], [0, 2, 3]]), np.array([[0, 1, 3], [1, 2, 3]])
    assert igl.hausdorff(V, FA, V, FB) < 1e-12
    d = geometry.mesh_distance(V, FA, V, FB, n_samples=20000, relative=False)
    exact = h / np.sqrt(2 * h * h + 1)
    # Samples measure exact point-to-surface distances, so the maximum can only fall short: by
    # O(sample spacing) at this kink-shaped maximum (about 0.7% with 20,000 samples).
    assert 0.98 * exact < d["hausdorff_12"] <= exact + 1e-12
    assert 0.98 * exact < d["hausdorff_21"] <= exact + 1e-12


# --------------------------------------------------------------------------------------------
# bad input


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda: geometry.face_normals([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], TRI_F),
            r"^face_normals: V: row 0 has a non-finite",
        ),
        (lambda: geometry.face_areas(TRI_V, [[0, 1, 3]]), r"^face_areas: F: face 0 uses vertex 3, but V has only 3"),
        (lambda: geometry.face_areas(TRI_V, [[0, 1, -1]]), r"^face_areas: F: face 0 .* has a negative index"),
        (
            lambda: geometry.vertex_normals(TRI_V[:, :2], TRI_F),
            r"^vertex_normals: V has shape \(3, 2\), expected \(n, 3\)",
        ),
        (lambda: geometry.vertex_normals(TRI_V, TRI_F, "cotan"), r"^vertex_normals: weighting must be one of"),
        (lambda: geometry.dihedral_angles(TRI_V, [[0, 1, 2, 0]]), r"^dihedral_angles: F has shape \(1, 4\).*triangles"),
        (lambda: geometry.mean_edge_length(TRI_V, [[0, 1], [1, 2]]), r"^mean_edge_length: F has shape \(2, 2\)"),
        (lambda: geometry.mean_edge_length(TRI_V, [[0, 1, 2], [1, 2]]), r"^mean_edge_length: F must be an \(m, 3\)"),
        (lambda: geometry.bbox_diagonal(np.zeros((0, 3))), r"^bbox_diagonal: V is empty"),
        (lambda: geometry.face_areas(TRI_V, [[0, 1, 2.5]]), r"^face_areas: F holds a non-integer value 2.5"),
        (lambda: geometry.closest_points(TRI_V, TRI_F, [1.0, 2.0, 3.0]), r"^closest_points: P has shape \(3,\)"),
        (
            lambda: geometry.ray_cast(TRI_V, TRI_F, [[0, 0, 1.0]], [[0, 0, 0.0]]),
            r"^ray_cast: directions: row 0 is the zero",
        ),
        (lambda: geometry.ray_cast(TRI_V, TRI_F, [[0, 0, 1.0]] * 2, [[0, 0, 1.0]]), r"^ray_cast: origins has 2 rows"),
        (lambda: geometry.ray_cast(TRI_V, TRI_F, [[0, 0, np.inf]], [[0, 0, 1.0]]), r"^ray_cast: origins: row 0"),
        (lambda: geometry.ray_cast(TRI_V, TRI_F, [[0, 0, 1]], [[0, 0, 1]], t_max=-1), r"^ray_cast: t_max must be >="),
        (lambda: geometry.ray_cast(TRI_V, TRI_F, [[0, 0, 1]], [[0, 0, 1]], method="embree"), r"^ray_cast: method must"),
        (lambda: geometry.random_points_on_mesh(TRI_V, TRI_F, -1), r"^random_points_on_mesh: n must be >= 0"),
        (
            lambda: geometry.random_points_on_mesh(TRI_V * 0, TRI_F, 5),
            r"^random_points_on_mesh: the mesh has zero total area",
        ),
        (lambda: geometry.mesh_distance(TRI_V, TRI_F, TRI_V, [[0, 1, 5]]), r"^mesh_distance: F2: face 0 uses vertex 5"),
        (lambda: geometry.hausdorff_distance(TRI_V, TRI_F, None, TRI_F), r"^hausdorff_distance: V2 is missing"),
        (
            lambda: geometry.chamfer_distance(TRI_V, TRI_F, TRI_V, TRI_F, n_samples=0),
            r"^chamfer_distance: n_samples must",
        ),
        (lambda: geometry.rms_distance(TRI_V, np.zeros((0, 3)), TRI_V, TRI_F), r"^rms_distance: F1 has 0 faces"),
    ],
)
def test_bad_input_raises_mesh_error(call, message):
    with pytest.raises(MeshError, match=message):
        call()


def test_degenerate_and_duplicate_faces_are_accepted_as_a_soup():
    F = np.array([[0, 1, 2], [0, 1, 2], [0, 0, 1]])
    np.testing.assert_allclose(geometry.face_areas(TRI_V, F), [1, 1, 0])
    hit, t, face, _ = geometry.ray_cast(TRI_V, F, [[0.2, 0.2, 1.0]], [[0, 0, -1.0]])
    assert hit[0] and t[0] == pytest.approx(1.0) and face[0] == 0  # lowest index on the tie


def test_sample_counts_that_cannot_fit_in_memory_are_refused_clearly():
    with pytest.raises(MeshError, match=r"^random_points_on_mesh: n = 1,000,000,000,000 samples would need about"):
        geometry.random_points_on_mesh(TRI_V, TRI_F, 10**12)
    with pytest.raises(MeshError, match=r"^mesh_distance: n_samples = .* would need about .* GiB of memory"):
        geometry.mesh_distance(TRI_V, TRI_F, TRI_V, TRI_F, n_samples=10**12)


def test_corner_angles_match_libigl_and_sum_to_pi():
    V, F = datasets.icosphere(2)
    V = datasets.add_noise(V, 0.05, seed=3)
    A = geometry.corner_angles(V, F)
    np.testing.assert_allclose(A, igl.internal_angles(V, F), atol=1e-12)
    np.testing.assert_allclose(A.sum(axis=1), np.pi, atol=1e-12)


def test_triangle_quality_against_independent_counts():
    V, F = datasets.height_field(12)  # an open grid: its boundary vertices do not count for valence 6
    V = V + np.random.default_rng(0).normal(scale=1e-3, size=V.shape)
    q = geometry.triangle_quality(V, F)
    angles = np.degrees(igl.internal_angles(V, F))
    E = igl.edges(F)
    lengths = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    valence = np.bincount(E.ravel(), minlength=len(V))
    inner = np.ones(len(V), bool)
    inner[np.unique(igl.boundary_loop(F))] = False
    assert q["faces"] == len(F)
    assert q["min_angle"] == pytest.approx(angles.min(), abs=1e-9)
    assert q["below_30"] == pytest.approx(np.mean(angles < 30))
    assert q["mean_edge"] == pytest.approx(lengths.mean())
    assert q["edge_cv"] == pytest.approx(lengths.std() / lengths.mean())
    assert q["valence6"] == pytest.approx(np.mean(valence[inner] == 6))
    with pytest.raises(MeshError):
        geometry.triangle_quality(V, np.vstack([F, F[:2, [0, 2, 1]]]))  # edges shared by three faces
