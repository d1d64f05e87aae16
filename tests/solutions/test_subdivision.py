"""Cross-checks of the subdivision reference solution against libigl, trimesh and VTK, plus properties.

Independent references:

- ``igl.loop`` uses Warren's weights and the standard boundary rules: ``weights="warren"`` must
  agree to 1e-10 on closed and open meshes (vertex order may differ: compared order-independently);
- ``trimesh.remesh.subdivide_loop`` uses Loop's beta: ``weights="loop"`` agrees on closed meshes;
  on open meshes trimesh differs exactly at boundary vertices joined by an interior edge to
  another boundary vertex (it gives them 1/8 per boundary *vertex* neighbour, weights summing to 9/8);
- VTK (``pyvista.PolyData.subdivide(1, "loop")``) uses Loop's beta and the standard boundary
  rules, in float32;
- Catmull-Clark has no installed library: on a regular (valence-4) quad torus it must equal the
  tensor product of 1-D cubic B-spline refinement, boundaries must follow the 1-D B-spline curve
  rules, and extraordinary vertices must converge to the closed-form limit positions.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest
import scipy.sparse as sp
import trimesh
from scipy.spatial import cKDTree

from geomlib import topology
from geomlib.validate import MeshError, check_manifold
from solutions.subdivision import (
    catmull_clark,
    cc_quads,
    loop_even_matrix,
    loop_odd_matrix,
    loop_subdivide,
    loop_weight,
)
from tests.graded.subdivision.support import RULES

# --------------------------------------------------------------------------- meshes


def octahedron():
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return V, F


def tetrahedron():
    V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1.0]])
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    return V, F


def icosphere(level=2, bumpy=True):
    m = trimesh.creation.icosphere(subdivisions=level)
    V = np.asarray(m.vertices, float)
    if bumpy:  # irregular positions so that weight mistakes show
        V = V * (1 + 0.1 * np.sin(5 * V[:, :1]) * np.cos(3 * V[:, 1:2]))
    return V, np.asarray(m.faces, np.int64)


def tri_torus(nu=12, nv=8):
    """Closed triangulated torus with irregular valences (alternating diagonals)."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    u, v = 2 * np.pi * i / nu, 2 * np.pi * j / nv
    V = np.stack([(2 + np.cos(v)) * np.cos(u), (2 + np.cos(v)) * np.sin(u), np.sin(v)], -1).reshape(-1, 3)

    def vid(a, b):
        return (a % nu) * nv + (b % nv)

    F = []
    for a in range(nu):
        for b in range(nv):
            p, q, r, s = vid(a, b), vid(a + 1, b), vid(a + 1, b + 1), vid(a, b + 1)
            F += [[p, q, r], [p, r, s]] if (a + b) % 2 else [[p, q, s], [q, r, s]]
    return V, np.array(F)


def grid(n=5, seed=1):
    """Open triangulated (n x n)-vertex grid with random heights."""
    x, y = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    rng = np.random.default_rng(seed)
    V = np.c_[x.ravel(), y.ravel(), 0.3 * rng.normal(size=n * n)].astype(float)
    F = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            F += [[a, b, c], [a, c, d]]
    return V, np.array(F)


def quad_torus(nu=10, nv=6, R=2.0, r=0.7, wobble=0.0):
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    u, v = 2 * np.pi * i / nu, 2 * np.pi * j / nv
    rr = r * (1 + wobble * np.sin(3 * u) * np.cos(2 * v))
    P = np.stack([(R + rr * np.cos(v)) * np.cos(u), (R + rr * np.cos(v)) * np.sin(u), rr * np.sin(v)], -1)

    def vid(a, b):
        return (a % nu) * nv + (b % nv)

    Q = np.stack([vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)], -1).reshape(-1, 4)
    return P.reshape(-1, 3), Q, P


def cube():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]])
    Q = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
    return V, Q


def pentagonal_prism():
    """Closed mixed cage: two pentagons and five quads."""
    t = 2 * np.pi * np.arange(5) / 5
    ring = np.c_[np.cos(t), np.sin(t), np.zeros(5)]
    V = np.concatenate([ring, ring + [0, 0, 1.2]])
    faces = [[4, 3, 2, 1, 0], [5, 6, 7, 8, 9]] + [[k, (k + 1) % 5, 5 + (k + 1) % 5, 5 + k] for k in range(5)]
    return V, faces


# --------------------------------------------------------------------------- helpers


def assert_same_mesh(Va, Fa, Vb, Fb, atol=1e-10):
    """Equal vertex sets (within atol) and equal sets of oriented faces, in any order."""
    assert Va.shape == Vb.shape and Fa.shape == Fb.shape
    d, j = cKDTree(Vb).query(Va)
    assert d.max() <= atol, f"max vertex distance {d.max():.3g}"
    assert len(np.unique(j)) == len(j)

    def canon(F):
        s = np.argmin(F, axis=1)
        return {tuple(r) for r in np.take_along_axis(F, (s[:, None] + np.arange(F.shape[1])) % F.shape[1], 1).tolist()}

    assert canon(j[Fa]) == canon(np.asarray(Fb))


def bspline_closed(P, axis):
    """One step of periodic cubic B-spline refinement along ``axis``: even = (p- + 6p + p+)/8, odd = (p + p+)/2."""
    Pm, Pp = np.roll(P, 1, axis), np.roll(P, -1, axis)
    even, odd = (Pm + 6 * P + Pp) / 8, (P + Pp) / 2
    out = np.stack([even, odd], axis + 1)
    shape = list(P.shape)
    shape[axis] *= 2
    return out.reshape(shape)


def bspline_open(P):
    """One step of cubic B-spline refinement of an open polyline with fixed end points (boundary rule)."""
    even = P.copy()
    even[1:-1] = (P[:-2] + 6 * P[1:-1] + P[2:]) / 8
    odd = (P[:-1] + P[1:]) / 2
    out = np.empty((2 * len(P) - 1, P.shape[1]))
    out[0::2], out[1::2] = even, odd
    return out


# --------------------------------------------------------------------------- Loop vs libraries

CLOSED = {"octahedron": octahedron, "tetrahedron": tetrahedron, "icosphere": icosphere, "torus": tri_torus}


@pytest.mark.parametrize("name", sorted(CLOSED))
@pytest.mark.parametrize("levels", [1, 2])
def test_warren_matches_igl_loop(name, levels):
    V, F = CLOSED[name]()
    V1, F1 = loop_subdivide(V, F, levels, "warren")
    Vi, Fi = igl.loop(V, F, levels)
    assert_same_mesh(V1, F1, Vi, Fi)
    np.testing.assert_allclose(V1[: len(V)], Vi[: len(V)], atol=1e-12)  # both keep old vertices first


@pytest.mark.parametrize("name", sorted(CLOSED))
@pytest.mark.parametrize("levels", [1, 2])
def test_loop_weights_match_trimesh(name, levels):
    V, F = CLOSED[name]()
    V1, F1 = loop_subdivide(V, F, levels, "loop")
    Vt, Ft = trimesh.remesh.subdivide_loop(V, F, iterations=levels)
    assert_same_mesh(V1, F1, np.asarray(Vt), np.asarray(Ft))


def test_loop_weights_match_vtk_closed():
    pv = pytest.importorskip("pyvista")
    V, F = icosphere(2)
    out = pv.PolyData(V, np.c_[np.full(len(F), 3), F].ravel()).subdivide(1, "loop")
    V1, _ = loop_subdivide(V, F, 1, "loop")
    d, _ = cKDTree(V1).query(np.asarray(out.points, float))
    assert d.max() < 1e-6  # VTK works in float32
    assert out.n_points == len(V1) and out.n_cells == 4 * len(F)


def test_weight_rules_differ_only_away_from_valence_3_and_6():
    n = np.arange(3, 13)
    w, b = loop_weight(n, "warren"), loop_weight(n, "loop")
    np.testing.assert_allclose(w[[0, 3]], [3 / 16, 1 / 16], atol=1e-15)
    np.testing.assert_allclose(b[[0, 3]], [3 / 16, 1 / 16], atol=1e-15)
    assert np.all(np.abs(w - b)[np.isin(n, [3, 6], invert=True)] > 1e-4)
    # beta(n) by hand for n = 4: (5/8 - (3/8 + 0)^2) / 4 = 31/256
    assert loop_weight(4, "loop") == pytest.approx(31 / 256, abs=1e-15)


def test_octahedron_even_vertex_by_hand():
    # Every vertex has valence 4: u = 3/32 (Warren); v' = (1 - 4u) v + u * (4 neighbours).
    # Vertex (1,0,0) has neighbours (0,+-1,0), (0,0,+-1): sum 0 -> v' = (1 - 12/32) v = 5/8 v.
    V, F = octahedron()
    V1, _ = loop_subdivide(V, F)
    np.testing.assert_allclose(V1[0], [5 / 8, 0, 0], atol=1e-15)
    # Edge (0, 2): 3/8 (v0 + v2) + 1/8 (v4 + v5) = (3/8, 3/8, 0); it is unique edge 0.
    np.testing.assert_allclose(V1[6], [3 / 8, 3 / 8, 0], atol=1e-15)


# --------------------------------------------------------------------------- boundaries


def test_open_grid_matches_igl_loop():
    V, F = grid()
    V1, F1 = loop_subdivide(V, F, 2, "warren")
    Vi, Fi = igl.loop(V, F, 2)
    assert_same_mesh(V1, F1, Vi, Fi)


def test_open_grid_matches_vtk():
    pv = pytest.importorskip("pyvista")
    V, F = grid()
    out = pv.PolyData(V, np.c_[np.full(len(F), 3), F].ravel()).subdivide(1, "loop")
    V1, _ = loop_subdivide(V, F, 1, "loop")
    d, _ = cKDTree(V1).query(np.asarray(out.points, float))
    assert d.max() < 1e-6


def test_trimesh_boundary_differs_where_documented():
    V, F = grid()
    V1, _ = loop_subdivide(V, F, 1, "loop")
    Vt, _ = trimesh.remesh.subdivide_loop(V, F, iterations=1)
    Vt = np.asarray(Vt)
    n = len(V)
    bnd = np.zeros(n, bool)
    bnd[topology.boundary_edges(F).ravel()] = True
    A = topology.vertex_adjacency(F, n).tolil().rows
    differs = np.linalg.norm(Vt[:n] - V1[:n], axis=1) > 1e-12
    expected = np.array([bnd[v] and sum(bnd[w] for w in A[v]) > 2 for v in range(n)])
    assert expected.any()
    np.testing.assert_array_equal(differs, expected)
    for v in np.flatnonzero(expected):  # trimesh: 3/4 v + 1/8 * (every boundary neighbour)
        hyp = 0.75 * V[v] + 0.125 * V[[w for w in A[v] if bnd[w]]].sum(0)
        np.testing.assert_allclose(Vt[v], hyp, atol=1e-12)
    np.testing.assert_allclose(np.sort(Vt[n:], 0), np.sort(V1[n:], 0), atol=1e-12)  # odd vertices agree


def test_loop_boundary_curve_is_cubic_bspline():
    V, F = grid(6)
    V1, F1 = loop_subdivide(V, F, 1)
    loops0 = topology.boundary_loops(F)
    assert len(loops0) == 1
    # The refined boundary, walked from old vertex loop0[0], is the 1-D B-spline refinement of the old one.
    L0 = loops0[0]
    L1 = topology.boundary_loops(F1)[0]
    L1 = np.roll(L1, -int(np.flatnonzero(L1 == L0[0])[0]))
    expected = bspline_closed(V[L0], 0)
    np.testing.assert_allclose(V1[L1], expected, atol=1e-12)


def test_single_triangle():
    V = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0.0]])
    V1, F1 = loop_subdivide(V, [[0, 1, 2]])
    # Corners: 3/4 v + 1/8 (two neighbours); edges (0,1), (0,2), (1,2) in unique_edges order: midpoints.
    # v1 = 3/4 (4, 0, 0) + 1/8 ((0, 0, 0) + (0, 4, 0)) = (3, 0.5, 0).
    exp = np.array([[0.5, 0.5, 0], [3, 0.5, 0], [0.5, 3, 0], [2, 0, 0], [0, 2, 0], [2, 2, 0]])
    np.testing.assert_allclose(V1, exp, atol=1e-15)
    np.testing.assert_array_equal(F1, [[0, 3, 4], [1, 5, 3], [2, 4, 5], [3, 5, 4]])


# --------------------------------------------------------------------------- Loop properties


@pytest.mark.parametrize("make", [octahedron, icosphere, tri_torus, grid])
@pytest.mark.parametrize("weights", ["warren", "loop"])
def test_loop_counts_topology_and_matrix(make, weights):
    V, F = make()
    n, e, m = len(V), len(topology.unique_edges(F)), len(F)
    V1, F1, S = loop_subdivide(V, F, 1, weights, return_matrix=True)
    assert V1.shape == (n + e, 3) and F1.shape == (4 * m, 3)
    assert sp.issparse(S) and S.shape == (n + e, n)
    np.testing.assert_allclose(S @ V, V1, atol=1e-12)
    np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, atol=1e-12)  # affine combinations
    assert topology.euler_characteristic(F1) == topology.euler_characteristic(F)
    assert topology.is_closed(F1) == topology.is_closed(F)
    check_manifold(F1, len(V1))  # raises if not manifold / oriented
    np.testing.assert_array_equal(topology.valence(F1, len(V1))[:n], topology.valence(F, n))
    odd_valence = topology.valence(F1, len(V1))[n:]
    bnd_edge = {tuple(sorted(b)) for b in topology.boundary_edges(F).tolist()}
    E = topology.unique_edges(F)
    expected = np.array([4 if tuple(r) in bnd_edge else 6 for r in E.tolist()])
    np.testing.assert_array_equal(odd_valence, expected)


def test_loop_levels_compose_and_matrix_is_product():
    V, F = tri_torus()
    V2, F2, S2 = loop_subdivide(V, F, 2, return_matrix=True)
    V1, F1, S1 = loop_subdivide(V, F, 1, return_matrix=True)
    V11, F11, S11 = loop_subdivide(V1, F1, 1, return_matrix=True)
    np.testing.assert_allclose(V2, V11, atol=1e-12)
    np.testing.assert_array_equal(F2, F11)
    np.testing.assert_allclose((S2 - S11 @ S1).toarray(), 0, atol=1e-12)
    V0, F0 = loop_subdivide(V, F, 0)
    np.testing.assert_array_equal(V0, V)
    np.testing.assert_array_equal(F0, F)
    assert V0 is not V


def test_loop_is_affine_invariant():
    V, F = icosphere(1)
    rng = np.random.default_rng(3)
    A, t = rng.normal(size=(3, 3)), rng.normal(size=3)
    for w in ("warren", "loop"):
        V1, _ = loop_subdivide(V, F, 2, w)
        V2, _ = loop_subdivide(V @ A.T + t, F, 2, w)
        np.testing.assert_allclose(V2, V1 @ A.T + t, atol=1e-10)


def test_planar_mesh_stays_planar():
    V, F = grid(6)
    rng = np.random.default_rng(0)
    V[:, 2] = 0
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    Vr = V @ R.T + [1, 2, 3]
    normal = R[:, 2]
    for w in ("warren", "loop"):
        V2, _ = loop_subdivide(Vr, F, 3, w)
        assert np.abs((V2 - [1, 2, 3]) @ normal).max() < 1e-12


def test_even_and_odd_matrices_by_rows():
    V, F = octahedron()
    So, Se = loop_odd_matrix(V, F), loop_even_matrix(V, F, "loop")
    E = topology.unique_edges(F)
    assert So.shape == (len(E), 6) and Se.shape == (6, 6)
    # Row of edge (0, 2): 3/8 on 0 and 2, 1/8 on the opposite vertices 4 and 5.
    np.testing.assert_allclose(So.toarray()[0], [3 / 8, 0, 3 / 8, 0, 1 / 8, 1 / 8])
    u = loop_weight(4, "loop")
    np.testing.assert_allclose(Se.toarray()[0], [1 - 4 * u, 0, u, u, u, u])


def test_loop_limit_surface_convergence():
    # Displacement of the old vertices between levels shrinks geometrically (smooth limit).
    V, F = icosphere(0)
    moves = []
    for _ in range(5):
        V1, F1 = loop_subdivide(V, F, 1, "loop")
        moves.append(np.abs(V1[: len(V)] - V).max())
        V, F = V1, F1
    moves = np.array(moves)
    assert np.all(moves[1:] < 0.5 * moves[:-1])


# --------------------------------------------------------------------------- Catmull-Clark


def test_cc_regular_torus_is_tensor_bspline():
    V, Q, P = quad_torus(wobble=0.2)
    nu, nv = P.shape[:2]
    V1, Q1 = catmull_clark(V, Q)
    expected = bspline_closed(bspline_closed(P, 0), 1)  # (2nu, 2nv, 3)
    d, j = cKDTree(V1).query(expected.reshape(-1, 3))
    assert d.max() < 1e-12
    # and the refined grid connectivity is the regular 2nu x 2nv grid
    ids = j.reshape(2 * nu, 2 * nv)
    grid_quads = np.stack([ids, np.roll(ids, -1, 0), np.roll(np.roll(ids, -1, 0), -1, 1), np.roll(ids, -1, 1)], -1)
    canon = {tuple(np.roll(q, -int(np.argmin(q)))) for q in grid_quads.reshape(-1, 4).tolist()}
    assert canon == {tuple(np.roll(q, -int(np.argmin(q)))) for q in Q1.tolist()}


def test_cc_open_grid_interior_and_boundary_are_bspline():
    # Open (5 x 4)-vertex quad patch with heights: the refined boundary polylines are the 1-D cubic
    # B-spline refinement (end points = corners fixed by 3/4, 1/8, 1/8 around the corner? no: corners
    # are ordinary boundary vertices here), and interior vertices far from the boundary follow the
    # tensor-product rule.
    nx, ny = 7, 6
    x, y = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float), indexing="ij")
    rng = np.random.default_rng(4)
    P = np.stack([x, y, rng.normal(size=x.shape)], -1)
    vid = np.arange(nx * ny).reshape(nx, ny)
    Q = np.stack([vid[:-1, :-1], vid[1:, :-1], vid[1:, 1:], vid[:-1, 1:]], -1).reshape(-1, 4)
    V1, Q1 = catmull_clark(P.reshape(-1, 3), Q)
    L0 = topology.boundary_loops(Q)[0]
    L1 = topology.boundary_loops(Q1)[0]
    L1 = np.roll(L1, -int(np.flatnonzero(L1 == L0[0])[0]))
    np.testing.assert_allclose(V1[L1], bspline_closed(P.reshape(-1, 3)[L0], 0), atol=1e-12)
    # interior: tensor product of the 1-D rules (valid two rings away from the boundary)
    T = np.empty((2 * nx - 1, 2 * ny - 1, 3))
    A = np.stack([bspline_open(P[:, j]) for j in range(ny)], 1)  # refine along x
    T = np.stack([bspline_open(A[i]) for i in range(A.shape[0])], 0)  # then along y
    inner = T[2:-2, 2:-2].reshape(-1, 3)
    d, _ = cKDTree(V1).query(inner)
    assert d.max() < 1e-12


def test_cc_cube_by_hand_and_limit():
    V, Q = cube()
    V1, Q1 = catmull_clark(V, Q)
    # Corner (0,0,0), valence 3: Q = mean face centre = (1/3,1/3,1/3), R = mean edge midpoint = (1/6,1/6,1/6):
    # (Q + 2R + 0 P) / 3 = 2/9 (1,1,1).
    np.testing.assert_allclose(V1[0], [2 / 9] * 3, atol=1e-15)
    assert len(V1) == 8 + 12 + 6 and Q1.shape == (24, 4)
    # Limit position of an extraordinary vertex of valence n after one step (all quads):
    # (n^2 P + 4 sum(edge neighbours) + sum(diagonal neighbours)) / (n (n + 5)).
    Vk, Qk = V1, Q1
    n = 3
    corner = 0
    quads_at = Qk[(Qk == corner).any(1)]
    edge_nb, diag_nb = set(), set()
    for q in quads_at.tolist():
        i = q.index(corner)
        edge_nb |= {q[(i + 1) % 4], q[(i + 3) % 4]}
        diag_nb.add(q[(i + 2) % 4])
    limit = (n * n * Vk[corner] + 4 * Vk[list(edge_nb)].sum(0) + Vk[list(diag_nb)].sum(0)) / (n * (n + 5))
    dists = []
    for _ in range(6):
        Vk, Qk = catmull_clark(Vk, Qk)
        dists.append(np.linalg.norm(Vk[corner] - limit))
    dists = np.array(dists)
    assert dists[-1] < 1e-3 * dists[0]
    assert np.all(dists[1:] < 0.6 * dists[:-1])  # geometric convergence toward the limit point
    # and the whole surface converges: distance between successive levels shrinks geometrically
    moves = []
    Vk, Qk = V, Q
    for _ in range(5):
        Vn, Qn = catmull_clark(Vk, Qk)
        moves.append(np.abs(Vn[: len(Vk)] - Vk).max())
        Vk, Qk = Vn, Qn
    assert np.all(np.array(moves[1:]) < 0.5 * np.array(moves[:-1]))


@pytest.mark.parametrize("make", [cube, pentagonal_prism, tetrahedron])
def test_cc_counts_topology_extraordinary(make):
    V, faces = make()
    n, e, m = len(V), len(topology.unique_edges(faces)), len(faces)
    corners = sum(len(f) for f in faces)
    V1, Q1 = catmull_clark(V, faces)
    assert V1.shape == (n + e + m, 3) and Q1.shape == (corners, 4) and Q1.dtype == np.int64
    assert topology.euler_characteristic(Q1) == topology.euler_characteristic(faces)
    assert topology.is_closed(Q1)
    check_manifold(Q1, len(V1))
    np.testing.assert_array_equal(topology.valence(Q1, len(V1))[:n], topology.valence(faces, n))
    # face points have valence = face size: extraordinary where != 4
    np.testing.assert_array_equal(topology.valence(Q1, len(V1))[n + e :], [len(f) for f in faces])
    counts = []
    Vk, Qk = V1, Q1
    for _ in range(3):
        counts.append(int((topology.valence(Qk, len(Vk)) != 4).sum()))
        Vk, Qk = catmull_clark(Vk, Qk)
    assert counts[0] == counts[1] == counts[2]
    expected = int((topology.valence(faces, n) != 4).sum()) + sum(len(f) != 4 for f in faces)
    assert counts[0] == expected


def test_cc_levels_and_quads_of_mixed_faces():
    V, faces = pentagonal_prism()
    V2, Q2 = catmull_clark(V, faces, 2)
    V1, Q1 = catmull_clark(V, faces, 1)
    V11, Q11 = catmull_clark(V1, Q1, 1)
    np.testing.assert_allclose(V2, V11, atol=1e-12)
    np.testing.assert_array_equal(Q2, Q11)
    # list input and the equivalent padded input give the same result; array input for pure quads
    Vc, Qc = cube()
    a = catmull_clark(Vc, Qc)
    b = catmull_clark(Vc, [list(q) for q in Qc])
    np.testing.assert_allclose(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    V0, F0 = catmull_clark(V, faces, 0)
    assert isinstance(F0, list) and [list(f) for f in F0] == faces
    # quads follow face orientation: corner 0 of face 0 -> (v, e_out, face point, e_in)
    n, e = len(V), len(topology.unique_edges(faces))
    q = cc_quads(faces, n_vertices=n)
    assert q[0, 0] == faces[0][0] and q[0, 2] == n + e + 0


def test_cc_planar_and_affine():
    V, faces = pentagonal_prism()
    rng = np.random.default_rng(5)
    A, t = rng.normal(size=(3, 3)), rng.normal(size=3)
    V1, _ = catmull_clark(V, faces, 2)
    V2, _ = catmull_clark(V @ A.T + t, faces, 2)
    np.testing.assert_allclose(V2, V1 @ A.T + t, atol=1e-10)
    # a flat open patch stays flat
    Vg, Fg = grid(5)
    Vg[:, 2] = 0.0
    V3, _ = catmull_clark(Vg, Fg, 2)
    assert np.abs(V3[:, 2]).max() == 0.0


# --------------------------------------------------------------------------- bad input


def nonmanifold_edge():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1.0]])
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    return V, F


def bowtie():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0.0]])
    return V, np.array([[0, 1, 2], [0, 3, 4]])


def two_tetrahedra_sharing_a_vertex():
    V, F = tetrahedron()
    V2 = np.concatenate([V, V[1:] + [4, 0, 0]])
    F2 = np.where(F == 0, 0, F + 3)
    return V2, np.concatenate([F, F2])


@pytest.mark.parametrize(
    "make, match",
    [
        (nonmanifold_edge, r"edge \(0, 1\) is shared by 3 faces"),
        (bowtie, r"vertex 0 is non-manifold"),
        (two_tetrahedra_sharing_a_vertex, r"vertex 0 is non-manifold"),
    ],
)
def test_non_manifold_rejected(make, match):
    V, F = make()
    with pytest.raises(MeshError, match=match):
        loop_subdivide(V, F)
    with pytest.raises(MeshError, match=match):
        catmull_clark(V, F)


def test_bad_input_messages():
    V, F = octahedron()
    with pytest.raises(MeshError, match=r"needs triangles"):
        loop_subdivide(*cube())
    with pytest.raises(MeshError, match=r"levels must be >= 0"):
        loop_subdivide(V, F, -1)
    for bad in (1.5, "2", True, None):
        with pytest.raises(MeshError, match=r"levels must be an integer"):
            loop_subdivide(V, F, bad)
        with pytest.raises(MeshError, match=r"levels must be an integer"):
            catmull_clark(*cube(), bad)
    with pytest.raises(MeshError, match=r"weights must be one of 'warren', 'loop'"):
        loop_subdivide(V, F, 1, "butterfly")
    Vn = V.copy()
    Vn[2, 1] = np.nan
    with pytest.raises(MeshError, match=r"row 2 has a non-finite value"):
        loop_subdivide(Vn, F)
    with pytest.raises(MeshError, match=r"uses vertex 9"):
        loop_subdivide(V, np.where(F == 5, 9, F))
    flipped = F.copy()
    flipped[0] = flipped[0, ::-1]
    with pytest.raises(MeshError, match=r"not consistently oriented"):
        loop_subdivide(V, flipped)
    with pytest.raises(MeshError, match=r"not consistently oriented|duplicate"):
        loop_subdivide(V, np.concatenate([F, F[:1]]))
    with pytest.raises(MeshError, match=r"face 1 has 2 vertices"):
        catmull_clark(V, [[0, 2, 4], [1, 2]])
    with pytest.raises(MeshError, match=r"repeats a vertex"):
        catmull_clark(V, [[0, 2, 4, 2]])
    with pytest.raises(MeshError, match=r"weights must be one of"):
        loop_weight(4, "Loop")


def test_unused_vertices_stay_put():
    V, F = octahedron()
    V = np.concatenate([V, [[5.0, 5.0, 5.0]]])  # vertex 6 is used by no face
    V1, F1 = loop_subdivide(V, F)
    np.testing.assert_array_equal(V1[6], [5.0, 5.0, 5.0])
    assert F1.max() < len(V1) and len(V1) == 7 + 12
    Vc, Qc = cube()
    Vc = np.concatenate([Vc, [[9.0, 9.0, 9.0]]])
    V2, Q2 = catmull_clark(Vc, Qc)
    np.testing.assert_array_equal(V2[8], [9.0, 9.0, 9.0])
    assert len(V2) == 9 + 12 + 6


def test_order_matches_unique_edges_and_igl_keeps_old_vertices_first():
    # Our odd vertex i sits on topology.unique_edges(F)[i]; igl.loop numbers edges by first
    # appearance instead, so only its first n rows coincide with ours.
    V, F = icosphere(1)
    V1, _ = loop_subdivide(V, F, 1, "warren")
    E = topology.unique_edges(F)
    # opposite vertices by brute force over the faces (small mesh)
    opp = {tuple(e): [] for e in E.tolist()}
    for tri in F.tolist():
        for i in range(3):
            a, b, c = tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]
            opp[(min(a, b), max(a, b))].append(c)
    expected = np.array([3 / 8 * (V[a] + V[b]) + 1 / 8 * V[opp[(a, b)]].sum(0) for a, b in E.tolist()])
    np.testing.assert_allclose(V1[len(V) :], expected, atol=1e-14)


@pytest.mark.parametrize("rule", list(RULES))
def test_the_solution_follows_the_rule(rule):
    """Each rule of the handout, as the graded tests' one place states it (``support.RULES``): a
    deliberate change of a rule in the solution fails here, named, as well as in the graded tests."""
    from tests.graded.subdivision.support import SQUARE_F, SQUARE_V, TET_F, TET_V

    given = RULES[rule]
    if rule.startswith("odd interior"):  # tetrahedron: every edge interior, opposite = the other two
        S = sp.csr_matrix(loop_odd_matrix(TET_V, TET_F)).toarray()
        E = topology.unique_edges(TET_F)
        expected = np.full((len(E), 4), given[1])
        expected[np.arange(len(E))[:, None], E] = given[0]
    elif rule.startswith("odd boundary"):  # split square: the four boundary edges
        S = sp.csr_matrix(loop_odd_matrix(SQUARE_V, SQUARE_F)).toarray()
        E = topology.unique_edges(SQUARE_F)
        rows = [i for i, (a, b) in enumerate(E.tolist()) if (a, b) != (0, 2)]
        S, expected = S[rows], np.zeros((len(rows), 4))
        expected[np.arange(len(rows))[:, None], E[rows]] = given[0]
    elif rule.startswith("even boundary"):  # split square: 0's boundary neighbours are 1 and 3
        S = sp.csr_matrix(loop_even_matrix(SQUARE_V, SQUARE_F, "loop")).toarray()[:1]
        expected = np.array([[given[0], given[1], 0, given[1]]])
    else:
        weights, formula = given
        n = np.arange(3, 13)
        S, expected = np.asarray(loop_weight(n, weights)), formula(n)
    assert np.allclose(S, expected, atol=1e-14), f"the solution breaks the rule {rule}:\n{S}\nexpected\n{expected}"


def test_loop_corner_vertices_stay_fixed_and_nothing_else_changes():
    """Hoppe et al.'s corner rule, loop_matrix's given option: a corner's row of S is the identity."""
    from solutions.subdivision import loop_matrix

    V, F = grid()
    xy = V[:, :2]
    corners = [int(np.argmin(xy @ d)) for d in ((1, 1), (-1, 1), (1, -1), (-1, -1))]
    S, F1 = loop_matrix(V, F, "loop")
    Sc, Fc = loop_matrix(V, F, "loop", corners=corners)
    np.testing.assert_array_equal(Fc, F1)
    V1, Vc = S @ V, Sc @ V
    np.testing.assert_array_equal(Vc[corners], V[corners])  # fixed
    assert np.linalg.norm(V1[corners] - V[corners], axis=1).min() > 1e-3  # the curve rule rounds them off
    others = np.setdiff1d(np.arange(S.shape[0]), corners)
    assert abs(Sc[others] - S[others]).max() == 0  # every other row is the plain rule
    with pytest.raises(MeshError, match="corners must be boundary vertices"):
        loop_matrix(V, F, "loop", corners=[int(np.argmin(np.linalg.norm(xy - xy.mean(0), axis=1)))])
    with pytest.raises(MeshError, match="corners must be vertex indices"):
        loop_matrix(V, F, "loop", corners=[len(V)])
