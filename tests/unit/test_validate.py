"""MeshError messages name the problem and the place."""

from __future__ import annotations

import numpy as np
import pytest

from geomlib import datasets
from geomlib.validate import (
    MeshError,
    as_faces,
    as_image,
    as_polygons,
    check_choice,
    check_float,
    check_int,
    check_mesh,
    check_polygon_mesh,
)

TRI = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


def test_mesh_error_is_a_value_error():
    assert issubclass(MeshError, ValueError)


@pytest.mark.parametrize(
    "V, F, message",
    [
        (
            np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0.0]]),
            [[0, 1, 2]],
            "f: V: row 0 has a non-finite value (0, 0, nan)",
        ),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, np.inf]]), [[0, 1, 2]], "f: V: row 2 has a non-finite value"),
        (TRI[:, :2], [[0, 1, 2]], "f: V has shape (3, 2), expected (n, 3)"),
        (TRI, [[0, 1, 3]], "f: F: face 0 uses vertex 3, but V has only 3 vertices (valid indices 0..2)"),
        (TRI, [[0, 1, 2], [0, -1, 2]], "f: F: face 1 (0, -1, 2) has a negative index"),
        (TRI, [[0, 1, 1]], "f: F: face 0 (0, 1, 1) is degenerate (repeats a vertex)"),
        (TRI, [[0, 1, 2], [1, 2, 0]], "f: F: faces 0 and 1 are duplicates (both use vertices (0, 1, 2))"),
        (TRI, [[0, 1, 2, 0]], "f: F has shape (1, 4): this function needs triangles (m, 3)"),
        (TRI, [[0, 1.5, 2]], "f: F holds a non-integer value 1.5"),
        (TRI, np.array([["a", "b", "c"]]), "f: F has dtype <U1, expected integers"),
        (TRI, None, "f: F is missing (got None)"),
        ([[0, 0], [1, 0, 0]], [[0, 1, 2]], "f: V is ragged (rows of different lengths)"),
    ],
)
def test_bad_meshes_name_the_problem_and_the_place(V, F, message):
    with pytest.raises(MeshError) as e:
        check_mesh(V, F, where="f")
    assert message in str(e.value)


def test_non_manifold_edge_names_the_edge_and_its_faces():
    V = np.random.default_rng(0).random((5, 3))
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is shared by 3 faces \(0, 1, 2\)"):
        check_mesh(V, [[0, 1, 2], [1, 0, 3], [0, 1, 4]], where="f", manifold=True)


def test_non_manifold_vertex_names_the_vertex():
    V = np.random.default_rng(0).random((5, 3))
    with pytest.raises(MeshError, match=r"vertex 0 is non-manifold \(its faces form 2 separate fans\)"):
        check_mesh(V, [[0, 1, 2], [0, 3, 4]], where="f", manifold=True)


def test_two_cones_touching_at_a_vertex_are_non_manifold():
    # Two closed tetrahedra sharing only vertex 0: every edge has 2 faces, but vertex 0 has 2 fans.
    V = np.random.default_rng(1).random((7, 3))
    a = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    b = [[0, 5, 4], [0, 4, 6], [0, 6, 5], [4, 5, 6]]
    with pytest.raises(MeshError, match="vertex 0 is non-manifold"):
        check_mesh(V, a + b, manifold=True)


def test_inconsistent_orientation_is_named():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    with pytest.raises(MeshError, match="faces 0 and 1 both traverse edge .* same direction"):
        check_mesh(V, [[0, 1, 2], [0, 2, 3][::-1]], manifold=True)


def test_closed_requirement_counts_boundary_edges():
    V, F = datasets.grid_patch(2)
    with pytest.raises(MeshError, match="mesh has 8 boundary edges"):
        check_mesh(V, F, closed=True)


def test_valid_meshes_pass_and_come_back_as_float64_int64():
    for V, F in (datasets.icosphere(1), datasets.torus(), datasets.grid_patch(3)):
        V2, F2 = check_mesh(V.astype(np.float32), F.astype(np.int32), manifold=True)
        assert V2.dtype == np.float64 and F2.dtype == np.int64


def test_polygons():
    idx, off = as_polygons([[0, 1, 2, 3], [3, 2, 4]], 5)
    assert idx.tolist() == [0, 1, 2, 3, 3, 2, 4] and off.tolist() == [0, 4, 7]
    with pytest.raises(MeshError, match="face 1 has 2 vertices, a polygon needs at least 3"):
        as_polygons([[0, 1, 2], [1, 2]], 3, where="f")
    with pytest.raises(MeshError, match="face 0 uses vertex 7, but V has only 5 vertices"):
        as_polygons([[0, 1, 7]], 5)
    with pytest.raises(MeshError, match=r"face 0 \(0, 1, 0, 2\) is degenerate"):
        as_polygons([[0, 1, 0, 2]], 5)
    V, Q = datasets.quad_cube()
    check_polygon_mesh(V, Q, manifold=True)
    with pytest.raises(MeshError, match=r"faces: edge \(0, 1\) is shared by 3 faces"):
        check_polygon_mesh(V, np.vstack([Q, Q[:1, ::-1]]), manifold=True)


def test_parameters():
    assert check_int(np.int64(3), "levels") == 3
    for bad, msg in (
        (-1, "levels must be >= 0, got -1"),
        (1.5, "levels must be an integer, got 1.5"),
        (True, "must be an integer"),
    ):
        with pytest.raises(MeshError, match=msg):
            check_int(bad, "levels", minimum=0)
    with pytest.raises(MeshError, match="lam must be <= 1"):
        check_float(2.0, "lam", maximum=1.0)
    with pytest.raises(MeshError, match="lam must be finite"):
        check_float(np.nan, "lam")
    assert check_float(0.5, "radius", positive=True) == 0.5
    for bad in (0, -1.0):
        with pytest.raises(MeshError, match=r"sd_sphere: radius must be > 0, got -?[01]\.0"):
            check_float(bad, "radius", positive=True, where="sd_sphere")
    with pytest.raises(MeshError, match="weights must be one of 'warren', 'loop'; got 'cotan'"):
        check_choice("cotan", "weights", ("warren", "loop"))


def test_images():
    with pytest.raises(MeshError, match="height is 8x6 pixels; expected a square image"):
        as_image(np.zeros((8, 6)), "height", square=True)
    with pytest.raises(MeshError, match="has 4 channel"):
        as_image(np.zeros((4, 4, 4)), "normal_map", channels=3)
    with pytest.raises(MeshError, match="is 4x4 pixels; expected 8x8"):
        as_image(np.zeros((4, 4)), size=(8, 8))
    with pytest.raises(MeshError, match=r"shape \(4,\); expected an image"):
        as_image(np.zeros(4))
    nan = np.zeros((3, 5))
    nan[1, 2] = np.nan
    with pytest.raises(MeshError, match=r"img has a non-finite value \(nan\) at pixel \(1, 2\); images must be finite"):
        as_image(nan, "img")
    with pytest.raises(MeshError, match=r"img has 7 channel\(s\) \(shape \(2, 2, 7\)\); expected 1 or 2 or 3 or 4"):
        as_image(np.zeros((2, 2, 7)), "img")
    assert as_image(np.zeros((2, 2, 7)), "features", channels=7).shape == (2, 2, 7)  # when asked for
    with pytest.raises(MeshError, match="img has dtype complex128; expected numbers"):
        as_image(np.zeros((2, 2), complex), "img")


@pytest.mark.parametrize("n_vertices", [6, 3_000_000], ids=["packed-keys", "lexsort-fallback"])
@pytest.mark.parametrize("k", [3, 4])
def test_duplicate_faces_are_found_with_either_sort(n_vertices, k):
    """Rows are packed into one int64 key when n^k fits; huge index ranges fall back to a lexsort."""
    F = np.array([[0, 1, 2, 3], [1, 2, 4, 5], [3, 4, 5, 0], [5, 2, 1, 4]])[:, :k]
    if k == 3:
        F[3] = [2, 1, 4]  # the corners of face 1 in another order
    with pytest.raises(MeshError, match="faces 1 and 3 are duplicates"):
        as_faces(F, n_vertices, k=k)
    as_faces(F[:3], n_vertices, k=k)  # without the copy: accepted


def test_uint64_index_past_int64_is_named_not_wrapped_to_negative():
    F = np.array([[0, 1, 2**63]], dtype=np.uint64)
    with pytest.raises(MeshError, match=r"f: F: face 0 uses vertex 9223372036854775808, but V has only 3"):
        check_mesh(TRI, F, where="f")
    with pytest.raises(MeshError, match=r"faces holds 9223372036854775808 at \(0, 2\), too large for an index"):
        as_polygons(F, 3)
    with pytest.raises(MeshError, match=r"F holds 10000000000000000000 at \(0, 2\), too large"):
        check_mesh(TRI, np.array([[0, 1, 1e19]]))
    V2, F2 = check_mesh(TRI, np.array([[0, 1, 2]], dtype=np.uint64))  # small unsigned indices are fine
    assert F2.dtype == np.int64 and F2.tolist() == [[0, 1, 2]]


def test_check_uv():
    from geomlib.validate import check_uv

    UV = np.array([[0.0, 0.5], [1, 1], [0.25, 0]])
    assert check_uv(UV, 3).dtype == np.float64
    with pytest.raises(MeshError, match="f: UV is missing; this function needs texture coordinates"):
        check_uv(None, 3, "f")
    with pytest.raises(MeshError, match="f: UV has 3 rows but V has 4; expected one"):
        check_uv(UV, 4, "f")
    check_uv(UV + 0.5, 3)  # outside the square is fine unless asked
    with pytest.raises(MeshError, match=r"f: UV_lo row 1 is \(1.5, 1.5\), outside the texture square .*\(1 rows"):
        check_uv(UV + 0.5, 3, "f", in_range=True, name="UV_lo")


def test_meshes_as_ragged_pairs_are_accepted():
    idx, off = as_polygons((np.array([0, 1, 2, 3, 3, 2, 4]), np.array([0, 4, 7])), 5)
    assert off.tolist() == [0, 4, 7]


def test_checked_meshes_are_not_validated_again_inside_the_block(monkeypatch):
    import geomlib.validate as gv

    V, F = check_mesh(*datasets.icosphere(0))
    calls = []
    real = gv.as_vertices
    monkeypatch.setattr(gv, "as_vertices", lambda *a, **k: calls.append(1) or real(*a, **k))
    with gv.checked(V, F):
        assert check_mesh(V, F, allow_degenerate=True)[0] is V  # weaker demands: passed through
        assert not calls
        check_mesh(V, F, manifold=True)  # more than was checked: validated
        check_mesh(V.copy(), F)  # other arrays: validated
        assert len(calls) == 2
    check_mesh(V, F)  # outside the block: validated again
    assert len(calls) == 3
    with gv.checked(V, F), pytest.raises(MeshError, match="at least 30"):
        check_mesh(V, F, min_faces=30)
