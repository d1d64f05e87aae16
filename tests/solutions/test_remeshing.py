"""Cross-checks of the remeshing solution: libigl for projection, geomlib's dihedral angles for
sharp edges, the half-edge invariants after every kernel edit, and the kernels without numba."""

from __future__ import annotations

import igl
import numpy as np

from geomlib import datasets, topology
from geomlib.geometry import dihedral_angles
from solutions import remeshing as R
from solutions.remeshing import kernels as K
from solutions.remeshing import state as M
from tests.solutions.fresh import run_python


def test_projection_matches_igl():
    V, F = datasets.torus(n_major=16, n_minor=8)
    P = np.random.default_rng(0).normal(size=(100, 3))
    _, _, C = igl.point_mesh_squared_distance(P, V, F)
    np.testing.assert_allclose(R.project_to_surface(P, V, F), C, atol=1e-12)


def test_sharp_edges_match_dihedral_angles():
    V, F = datasets.sharp_box((1.0, 0.6, 0.4), n=5)
    E, theta = dihedral_angles(V, F)
    ours = R.sharp_edges(V, F, 30.0)
    ref = np.asarray(E)[np.degrees(theta) > 30.0]  # angle between the normals: pi/2 on a box edge
    assert len(ours) == 12 * 5  # 12 box edges of 5 segments
    assert {tuple(e) for e in ours} == {tuple(e) for e in ref}


def test_every_kernel_edit_keeps_the_state_consistent():
    """Random splits, flips and collapses on the corner table (compacted now and then): its twins,
    vertex half-edges and valences agree with the faces after each edit, and the rebuilt HalfEdgeMesh
    passes check_halfedges."""
    V, F = datasets.icosphere(2)
    S = M.make_state(V, F)
    rng = np.random.default_rng(1)
    hes, n1, n2 = (np.empty(K.RING, np.int64) for _ in range(3))
    edits = 0
    for _ in range(300):
        nf = int(S.cnt[1])
        h = int(rng.integers(0, 3 * nf))
        if not S.falive[h // 3]:
            continue
        kind = rng.integers(0, 3)
        a, b = K.org(S.F, h), K.dst(S.F, h)
        if kind == 0:
            if K.split(*S.args(), h, 0.5 * (S.V[a] + S.V[b])) == K.FULL:
                S.grow()
                continue
        elif kind == 1:
            if K.flip_check(S.V, S.F, S.T, S.VH, S.val, S.feat, h, hes, n1) != K.OK:
                continue
            K.flip(S.V, S.F, S.T, S.VH, S.val, S.feat, h)
        else:
            p = 0.5 * (S.V[a] + S.V[b])
            if K.collapse_check(*S.args()[:7], h, p, np.inf, hes, n1, n2) != K.OK:
                continue
            K.collapse(*S.args()[:8], h, p, hes)
        edits += 1
        if edits % 25 == 0:
            S.compact()  # drops dead rows: the same mesh, renumbered
            assert S.falive[: S.cnt[1]].all() and (S.VH[: S.cnt[0]] >= 0).all()
        Fl = S.faces()
        live = np.flatnonzero(np.repeat(S.falive[: S.cnt[1]], 3))
        t = S.T[live]
        assert (t >= 0).all() and (S.T[t] == live).all()
        used = np.unique(Fl)
        assert (S.F.ravel()[S.VH[used]] == used).all()
        assert np.array_equal(np.bincount(topology.unique_edges(Fl).ravel(), minlength=S.cnt[0])[used], S.val[used])
        W, G = M.state_mesh(S)
        topology.check_halfedges(topology.halfedge_mesh(G, len(W), manifold=True))
        assert topology.euler_characteristic(G) == 2
    assert edits > 100


def test_kernels_run_without_numba():
    """NUMBA_DISABLE_JIT=1: the kernels are plain Python and give the same small remesh."""
    code = (
        "import numpy as np; from geomlib import datasets; from solutions.remeshing import isotropic_remesh as r;"
        "V, F = datasets.icosphere(1); W, G = r(V, F, 0.5, iterations=2); print(len(W), len(G), float(np.abs(W).sum()))"
    )
    n, m, s = run_python(code, NUMBA_DISABLE_JIT="1").split()
    V, F = datasets.icosphere(1)
    W, G = R.isotropic_remesh(V, F, 0.5, iterations=2)
    assert (int(n), int(m)) == (len(W), len(G))
    assert abs(float(s) - np.abs(W).sum()) < 1e-9


def test_boundary_and_features_kept():
    V, F = datasets.sharp_box(n=6)
    W, G = R.isotropic_remesh(V, F, 0.1, feature_angle=45.0)
    # every box corner is still a vertex, every vertex on the box surface
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    assert all(np.isclose(W, c).all(axis=1).any() for c in corners)
    assert np.allclose(np.abs(W).max(axis=1), 0.5)
    V, F = datasets.height_field(16)
    W, G = R.isotropic_remesh(V, F, 0.04)
    b0, b = topology.boundary_loops(F), topology.boundary_loops(G)
    assert len(b) == len(b0) == 1
    lo, hi = V[:, :2].min(axis=0), V[:, :2].max(axis=0)
    xy = W[b[0], :2]
    assert (np.isclose(xy, lo) | np.isclose(xy, hi)).any(axis=1).all()  # boundary stays on the square's sides


def test_max_curvature_matches_igl_mean_and_gaussian_curvature():
    """κ = |H| + sqrt(max(H² − K, 0)) from libigl's cotangent Laplacian, barycentric mass matrix and
    angle defect (an independent implementation of the same formulas) agrees to round-off."""
    V, F = datasets.torus(n_major=32, n_minor=16)
    m = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    H = np.linalg.norm(igl.cotmatrix(V, F) @ V, axis=1) / m / 2
    K = igl.gaussian_curvature(V, F) / m
    np.testing.assert_allclose(R.max_curvature(V, F), H + np.sqrt(np.maximum(H * H - K, 0)), rtol=1e-9)


def test_max_curvature_of_a_torus_and_boundary():
    """On a torus the larger principal curvature is 1 / (minor radius) everywhere; boundary vertices get NaN."""
    V, F = datasets.torus(n_major=48, n_minor=24)
    r = 0.5 * (V[:, 2].max() - V[:, 2].min())
    assert abs(np.median(R.max_curvature(V, F)) * r - 1) < 0.01
    Vh, Fh = datasets.height_field(12)
    k = R.max_curvature(Vh, Fh)
    bnd = topology.halfedge_mesh(Fh, len(Vh)).boundary_vertex
    assert np.isnan(k[bnd]).all() and np.isfinite(k[~bnd]).all()


def test_adaptive_target_length_formula():
    """On a sphere of radius r (κ = 1/r everywhere) every length is sqrt(6 ε r − 3 ε²) for a given
    ε; with the default ε it is about L; clamping and the flat (boundary-only) fill behave."""
    V, F = datasets.icosphere(4)
    V = 2.0 * V
    kap = R.max_curvature(V, F)
    h = R.adaptive_target_length(V, F, 0.2, error=0.001, min_length=0.01, max_length=1.0, smoothing=0)
    np.testing.assert_allclose(h, np.sqrt(6 * 0.001 / kap - 3 * 0.001**2), rtol=1e-12)
    h = R.adaptive_target_length(V, F, 0.2)
    assert abs(np.median(h) / 0.2 - 1) < 0.01
    h = R.adaptive_target_length(V, F, 0.2, error=1e-9, min_length=0.05)
    assert np.allclose(h, 0.05)  # every length below the clamp
    Vh, Fh = datasets.height_field(12)
    assert np.isfinite(R.adaptive_target_length(Vh, Fh, 0.05)).all()


def test_adaptive_remesh_follows_curvature():
    """A stretched sphere remeshed adaptively has shorter edges at its tips than at its waist."""
    V, F = datasets.icosphere(3)
    V = V * np.array([1.5, 0.6, 0.6])

    def tips_over_waist(W, G):
        E = topology.unique_edges(G)
        e = np.linalg.norm(W[E[:, 0]] - W[E[:, 1]], axis=1)
        x = np.abs(W[E, 0].mean(axis=1))
        return e[x > 0.8 * x.max()].mean() / e[x < 0.2 * x.max()].mean()

    assert tips_over_waist(*R.isotropic_remesh(V, F, 0.1, adaptive=True)) < 0.85
    assert tips_over_waist(*R.isotropic_remesh(V, F, 0.1)) > 0.9
    field = R.adaptive_target_length(V, F, 0.1)
    W, G = R.isotropic_remesh(V, F, field)  # the same field given as an array
    assert tips_over_waist(W, G) < 0.85


def _count_builds(monkeypatch):
    """Count the half-edge structures built (``geomlib.topology.halfedge_mesh`` calls)."""
    calls = []
    build = topology.halfedge_mesh

    def counted(*args, **kwargs):
        calls.append(1)
        return build(*args, **kwargs)

    monkeypatch.setattr(topology, "halfedge_mesh", counted)
    return calls


def test_each_stage_builds_the_half_edge_structure_once(monkeypatch):
    """Issue #25 item 4: a public stage validates its mesh by building the structure, and the
    kernels' state is made from that one (it was built twice, and the valences counted a third time)."""
    V, F = datasets.icosphere(2)
    L = 0.2
    stages = {
        "split_long_edges": lambda: R.split_long_edges(V, F, 4 / 3 * L),
        "collapse_short_edges": lambda: R.collapse_short_edges(V, F, 4 / 5 * L, 4 / 3 * L),
        "equalize_valences": lambda: R.equalize_valences(V, F),
        "tangential_relaxation": lambda: R.tangential_relaxation(V, F),
        "sharp_edges": lambda: R.sharp_edges(V, F, 30.0),
        "isotropic_remesh": lambda: R.isotropic_remesh(V, F, L, iterations=2),
    }
    counts = {}
    for name, run in stages.items():
        calls = _count_builds(monkeypatch)
        run()
        counts[name] = len(calls)
    assert counts == dict.fromkeys(stages, 1), f"half-edge structures built per call: {counts}"


def test_sliver_clean_up_raises_the_smallest_angle():
    """The loop's last step (:func:`clean_slivers`) flips a cap (one angle near 180°) away and
    collapses a needle's short edge into an end; no vertex moves off its place (on the camel's head
    at 1.5x its mean edge the loop alone left a 10.6° corner, 22.3° after it; gpytoolbox: 25.7°)."""
    from geomlib.geometry import triangle_quality

    V, F = datasets.grid_patch(8)
    V = V.copy()
    H = topology.halfedge_mesh(F, len(V))
    inner = np.flatnonzero(~H.boundary_vertex)
    cap, needle = inner[10], inner[24]
    # the cap: an inner vertex pushed almost onto the far edge of one of its faces
    x, y = (v for v in F[(F == cap).any(axis=1)][0] if v != cap)
    V[cap] = 0.97 * 0.5 * (V[x] + V[y]) + 0.03 * V[cap]
    # the needle: an inner vertex moved next to one of its neighbours
    nb = H.E[(H.E == needle).any(axis=1)].ravel()
    nb = nb[nb != needle]
    V[needle] = 0.97 * V[nb[0]] + 0.03 * V[needle]
    before = triangle_quality(V, F)["min_angle"]
    S = M.make_state(V, F)
    S.high[:] = 1.0
    edits = R.stages.clean_slivers(S)
    U, G = M.state_mesh(S)
    topology.halfedge_mesh(G, len(U), manifold=True)
    after = triangle_quality(U, G)["min_angle"]
    assert edits >= 2 and after > 4 * before and after > 15.0, (edits, before, after)
    kept = (np.abs(U[:, None, :] - V[None, :, :]).sum(axis=2) == 0).any(axis=1)
    assert kept.all(), "the clean-up moved a vertex"


def test_a_wrong_valence_count_is_named_when_the_mesh_is_returned():
    """The kernels keep each vertex's valence by hand; a wrong count (an operation that forgot one
    edge) leaves a valid mesh, so state_mesh compares it with the faces and names the vertex."""
    import pytest

    from geomlib.errors import MeshError

    V, F = datasets.icosphere(1)
    S = M.make_state(V, F)
    M.state_mesh(S)  # the counts of a fresh state agree
    k = int(S.val[7])
    S.val[7] += 1
    with pytest.raises(
        MeshError, match=rf"val\[7\] is {k + 1}, but {k} edges meet at vertex 7: .*Task 2 edge collapse"
    ):
        M.state_mesh(S)
    S.val[9] -= 1
    with pytest.raises(MeshError, match=r"val\[7\] .*; 1 more vertex disagrees"):
        M.state_mesh(S)


def _points_around(V, n, seed):
    """Points on, near and far off the mesh (its vertices first)."""
    rng = np.random.default_rng(seed)
    scale = np.ptp(V, axis=0).max()
    near = V[rng.integers(0, len(V), n)] + rng.normal(0.0, 0.05 * scale, (n, 3))
    far = rng.uniform(V.min(axis=0) - 0.5 * scale, V.max(axis=0) + 0.5 * scale, (n, 3))
    return np.r_[V, near, far], scale


def test_grid_closest_agrees_with_igl_and_not_with_the_grid():
    """The projector's compiled query (``kernels.grid_closest`` through ``kernels.face_grid``) gives
    libigl's squared distances and closest points for points on, near and far off a mesh with sharp
    edges, and a mesh with a degenerate face (its sides); and the same bytes for any cell size (one
    cell, a fine grid, the default), the face of the lowest index among equally close ones, as
    measuring every face would: a mesh vertex names the first face around it."""
    cases = [datasets.rock_on_plinth(16)]
    # a strip with a degenerate face (three corners on a line) beside a proper one
    cases.append(
        (
            np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0], [1, -1, 0.5]], float),
            np.array([[0, 1, 2], [0, 3, 1], [1, 4, 2]]),
        )
    )
    for V, F in cases:
        F = F.astype(np.int64)
        X, scale = _points_around(V, 300, 5)
        d2, face, C = K.grid_closest(V, F, *K.face_grid(V, F, 0.0), X, 0.0)
        e2, _, EC = igl.point_mesh_squared_distance(X, V, F)
        np.testing.assert_allclose(d2, np.asarray(e2).ravel(), rtol=0, atol=1e-12 * scale**2)
        np.testing.assert_allclose(C, EC, rtol=0, atol=1e-9 * scale)
        assert ((face >= 0) & (face < len(F))).all()
        for cell in (1e-3 * scale, 0.1 * scale, 10.0 * scale):
            again = K.grid_closest(V, F, *K.face_grid(V, F, cell), X, 0.0)
            for a, b in zip(again, (d2, face, C)):
                assert a.tobytes() == b.tobytes(), f"cell {cell}: another answer"
        first = np.full(len(V), len(F))
        np.minimum.at(first, F.ravel(), np.repeat(np.arange(len(F)), 3))
        assert (d2[: len(V)] == 0).all() and (face[: len(V)] == first).all()


def test_grid_closest_stops_early_only_below_enough():
    """With ``enough``, a point closer than ``sqrt(enough)`` may stop at any such face (the tips'
    pass asks only whether an input vertex is covered); every other point gets the exact answer."""
    V, F = datasets.rock_on_plinth(16)
    F = F.astype(np.int64)
    X, scale = _points_around(V, 300, 6)
    grid = K.face_grid(V, F, 0.0)
    exact = K.grid_closest(V, F, *grid, X, 0.0)
    r2 = np.quantile(exact[0], 0.4)
    d2, face, C = K.grid_closest(V, F, *grid, X, r2)
    close = exact[0] < r2
    assert (d2[close] < r2).all()
    assert close.any() and (d2[close] != exact[0][close]).any(), "no point stopped early: the test shows nothing"
    for a, b in zip((d2, face, C), exact):
        assert a[~close].tobytes() == b[~close].tobytes()
