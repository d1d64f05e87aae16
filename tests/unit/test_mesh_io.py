"""Tests for geomlib.mesh_io: mesh files (OBJ, OFF, PLY).

Expected values are either written out by hand next to the hand-made file they describe, or
come from an independent reader (libigl) on files our writers produced.
"""

from __future__ import annotations

import os
import re
import struct

import numpy as np
import pytest

from geomlib import image_io
from geomlib import mesh_io as io
from geomlib.validate import MeshError

# A unit square split into two triangles, and the same square as one quad.
SQUARE_V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
SQUARE_T = np.array([[0, 1, 2], [0, 2, 3]])


def random_mesh(seed=0, n=30, m=40):
    """Vertices with awkward floats (many digits, tiny and huge magnitudes) and random triangles."""
    rng = np.random.default_rng(seed)
    V = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-8, 8, size=(n, 1))
    F = np.array([rng.choice(n, 3, replace=False) for _ in range(m)])
    return V, F


def write(tmp_path, name, content):
    p = tmp_path / name
    p.write_bytes(content.encode() if isinstance(content, str) else content)
    return p


def canonical_rotation(F):
    """Rotate each triangle so its smallest index comes first (same triangle, same orientation)."""
    F = np.asarray(F)
    r = np.argmin(F, axis=1)
    return np.stack([F[np.arange(len(F)), (r + j) % 3] for j in range(3)], axis=1)


# --------------------------------------------------------------------------------------------
# Round trips through every mesh format
# --------------------------------------------------------------------------------------------

PLY_FORMATS = ["ascii", "binary_little_endian", "binary_big_endian"]


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_triangle_round_trip_is_exact(tmp_path, ext):
    V, F = random_mesh()
    path = tmp_path / f"m.{ext}"
    io.write_mesh(path, V, F)
    V2, F2 = io.read_mesh(path)
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    np.testing.assert_array_equal(V2, V)  # shortest round-trip text / doubles: bit-exact
    np.testing.assert_array_equal(F2, F)


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_quads_come_back_as_quads_and_triangulate_as_fans(tmp_path, ext):
    path = tmp_path / f"q.{ext}"
    io.write_mesh(path, SQUARE_V, [[0, 1, 2, 3]])
    V, F = io.read_mesh(path)
    assert isinstance(F, np.ndarray) and F.tolist() == [[0, 1, 2, 3]]
    _, T = io.read_mesh(path, triangulate=True)
    assert T.tolist() == [[0, 1, 2], [0, 2, 3]]


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_mixed_polygons_come_back_as_a_list(tmp_path, ext):
    V = np.arange(27, dtype=float).reshape(9, 3)
    polys = [[0, 1, 2], [0, 2, 3, 4], [4, 5, 6, 7, 8]]
    path = tmp_path / f"p.{ext}"
    io.write_mesh(path, V, polys)
    V2, F2 = io.read_mesh(path)
    assert isinstance(F2, list)
    assert [f.tolist() for f in F2] == polys
    assert all(f.dtype == np.int64 for f in F2)
    _, T = io.read_mesh(path, triangulate=True)
    assert T.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4], [4, 5, 6], [4, 6, 7], [4, 7, 8]]


@pytest.mark.parametrize("fmt", PLY_FORMATS)
def test_ply_round_trip_with_attributes(tmp_path, fmt):
    V, F = random_mesh(1)
    rng = np.random.default_rng(1)
    N = rng.normal(size=V.shape)
    UV = rng.random((len(V), 2))
    C = rng.integers(0, 256, size=(len(V), 4))
    path = tmp_path / "a.ply"
    io.write_ply(path, V, F, N=N, UV=UV, colors=C, format=fmt)
    assert path.read_bytes().startswith(f"ply\nformat {fmt} 1.0\n".encode())
    d = io.read_ply(path)
    np.testing.assert_array_equal(d.V, V)
    np.testing.assert_array_equal(d.faces, F)
    np.testing.assert_array_equal(d.N, N)
    np.testing.assert_array_equal(d.UV, UV)
    np.testing.assert_array_equal(d.colors, C)
    assert d.colors.dtype == np.uint8


@pytest.mark.parametrize("fmt", PLY_FORMATS)
def test_ply_float_vertices_and_point_clouds(tmp_path, fmt):
    V, _ = random_mesh(2)
    path = tmp_path / "pc.ply"
    io.write_ply(path, V, format=fmt, vertex_type="float")
    d = io.read_ply(path)
    np.testing.assert_array_equal(d.V, V.astype(np.float32))
    assert d.faces.shape == (0, 3)


@pytest.mark.parametrize("fmt", PLY_FORMATS)
def test_ply_polygons_with_more_than_255_corners(tmp_path, fmt):
    V = np.c_[np.cos(np.arange(300)), np.sin(np.arange(300)), np.zeros(300)]
    faces = [list(range(300)), [0, 1, 2]]
    path = tmp_path / "big.ply"
    io.write_ply(path, V, faces, format=fmt)
    F = io.read_ply(path).faces
    assert [f.tolist() for f in F] == faces


def test_files_we_write_read_the_same_in_libigl(tmp_path):
    igl = pytest.importorskip("igl")
    V, F = random_mesh(3)
    for name in ["m.obj", "m.off", "m.ply"]:
        io.write_mesh(tmp_path / name, V, F)
        Vi, Fi = igl.read_triangle_mesh(str(tmp_path / name))[:2]
        np.testing.assert_allclose(Vi, V, rtol=1e-15, atol=0)
        np.testing.assert_array_equal(Fi, F)


def test_precision_option_limits_digits(tmp_path):
    V = np.array([[1 / 3, 2 / 3, 1.0]])
    io.write_obj(tmp_path / "p.obj", V, np.zeros((0, 3), int), precision=4)
    assert "v 0.3333 0.6667 1\n" in (tmp_path / "p.obj").read_text()


# --------------------------------------------------------------------------------------------
# OBJ specifics
# --------------------------------------------------------------------------------------------


def test_obj_hand_written_file_with_every_corner_format(tmp_path):
    text = (
        "# a comment line\n"
        "mtllib scene.mtl\n"
        "o thing\n"
        "v 0 0 0\n"
        "v 1 0 0 0.5 0.25 1.0\n"  # vertex colour: ignored (not every vertex has one)
        "  v 1 1 0   # indented, trailing comment\n"
        "v\t0\t1\t0\r\n"  # tabs and a Windows line ending
        "vt 0 0\n"
        "vt 1 0\n"
        "vt 1 1\n"
        "vn 0 0 1\n"
        "g group\n"
        "s 1\n"
        "usemtl red\n"
        "f 1/1/1 2/2/1 3/3/1\n"  # v/vt/vn
        "f 1//1 3//1 4//1\n"  # v//vn
        "f 1/1 2/2 3/3 4/1\n"  # v/vt
        "f -4 -3 -1\n"  # relative: 4 vertices so far -> 1 2 4
        "l 1 2\n"
    )
    d = io.read_obj(write(tmp_path, "hand.obj", text))
    np.testing.assert_array_equal(d.V, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert [f.tolist() for f in d.faces] == [[0, 1, 2], [0, 2, 3], [0, 1, 2, 3], [0, 1, 3]]
    np.testing.assert_array_equal(d.UV, [[0, 0], [1, 0], [1, 1]])
    np.testing.assert_array_equal(d.N, [[0, 0, 1]])
    assert [f.tolist() for f in d.face_uv] == [[0, 1, 2], [-1, -1, -1], [0, 1, 2, 0], [-1, -1, -1]]
    assert [f.tolist() for f in d.face_normal] == [[0, 0, 0], [0, 0, 0], [-1, -1, -1, -1], [-1, -1, -1]]
    assert d.colors is None


def test_obj_relative_indices_use_the_vertices_defined_so_far(tmp_path):
    # Two triangles, each written right after its own vertices with relative indices.
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf -3 -2 -1\nf -6 -5 1\n"
    V, F = io.read_mesh(write(tmp_path, "rel.obj", text))
    assert F.tolist() == [[0, 1, 2], [3, 4, 5], [0, 1, 0]]
    d = io.read_obj(write(tmp_path, "rel_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 1\nf 1/-1 2/-2 3/-1\n"))
    assert d.face_uv.tolist() == [[1, 0, 1]]


def test_obj_vertex_colours_and_w_coordinate(tmp_path):
    d = io.read_obj(write(tmp_path, "c.obj", "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n"))
    np.testing.assert_array_equal(d.colors, np.eye(3))
    np.testing.assert_array_equal(d.V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    d = io.read_obj(write(tmp_path, "w.obj", "v 1 2 3 1\nv 4 5 6 1\nv 7 8 9 1\nf 1 2 3\n"))
    np.testing.assert_array_equal(d.V, [[1, 2, 3], [4, 5, 6], [7, 8, 9]])
    assert d.colors is None


def test_obj_colours_round_trip(tmp_path):
    V, F = random_mesh(4)
    C = np.random.default_rng(4).random(V.shape)
    io.write_obj(tmp_path / "c.obj", V, F, colors=C)
    np.testing.assert_array_equal(io.read_obj(tmp_path / "c.obj").colors, C)


@pytest.mark.parametrize("with_uv,with_n", [(True, True), (True, False), (False, True)])
def test_obj_uv_and_normal_round_trip(tmp_path, with_uv, with_n):
    rng = np.random.default_rng(5)
    V = rng.random((6, 3))
    F = [[0, 1, 2, 3], [3, 2, 4], [4, 2, 5]]
    UV = rng.random((8, 2)) if with_uv else None
    face_uv = [[0, 1, 2, 3], [7, 6, 5], [4, 6, 0]] if with_uv else None
    N = rng.normal(size=(3, 3)) if with_n else None
    face_normal = [[0, 0, 0, 0], [1, 1, 1], [2, 1, 0]] if with_n else None
    path = tmp_path / "uvn.obj"
    io.write_obj(path, V, F, UV=UV, N=N, face_uv=face_uv, face_normal=face_normal)
    token = {(True, True): "1/1/1", (True, False): "1/1", (False, True): "1//1"}[(with_uv, with_n)]
    assert f"f {token} " in path.read_text()
    d = io.read_obj(path)
    np.testing.assert_array_equal(d.V, V)
    assert [f.tolist() for f in d.faces] == F
    if with_uv:
        np.testing.assert_array_equal(d.UV, UV)
        assert [f.tolist() for f in d.face_uv] == face_uv
    else:
        assert d.UV is None and d.face_uv is None
    if with_n:
        np.testing.assert_array_equal(d.N, N)
        assert [f.tolist() for f in d.face_normal] == face_normal
    else:
        assert d.N is None and d.face_normal is None


def test_obj_per_vertex_uv_needs_no_face_uv(tmp_path):
    UV = SQUARE_V[:, :2] * 0.5
    io.write_obj(tmp_path / "pv.obj", SQUARE_V, SQUARE_T, UV=UV)
    d = io.read_obj(tmp_path / "pv.obj")
    np.testing.assert_array_equal(d.face_uv, SQUARE_T)
    np.testing.assert_array_equal(d.UV[d.face_uv], UV[SQUARE_T])


def test_obj_triangulate_keeps_uv_corners_aligned(tmp_path):
    io.write_obj(tmp_path / "t.obj", SQUARE_V, [[0, 1, 2, 3]], UV=np.eye(4)[:, :2], face_uv=[[3, 2, 1, 0]])
    d = io.read_obj(tmp_path / "t.obj", triangulate=True)
    assert d.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert d.face_uv.tolist() == [[3, 2, 1], [3, 1, 0]]


def test_obj_read_larger_regular_grid(tmp_path):
    # A 40x40 quad grid written by hand (not by write_obj): checks the vectorised fast paths.
    n = 40
    lines = [f"v {i} {j} {i * j}" for j in range(n) for i in range(n)]
    quads = [
        (j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i) for j in range(n - 1) for i in range(n - 1)
    ]
    lines += ["f " + " ".join(f"{a + 1}/{a + 1}" for a in q) for q in quads]
    lines += [f"vt {i} {j}" for j in range(n) for i in range(n)]
    d = io.read_obj(write(tmp_path, "grid.obj", "\n".join(lines)))
    assert d.V.shape == (n * n, 3) and d.V[n + 2].tolist() == [2.0, 1.0, 2.0]
    np.testing.assert_array_equal(d.faces, quads)
    np.testing.assert_array_equal(d.face_uv, quads)


# --------------------------------------------------------------------------------------------
# OFF specifics
# --------------------------------------------------------------------------------------------


def test_off_hand_written_with_comments_colours_and_inline_counts(tmp_path):
    text = (
        "OFF 4 2 0  # counts on the header line\n"
        "\n"
        "# vertices\n"
        "0 0 0\n"
        "1 0 0\n"
        "1 1 0\n"
        "0 1 0\n"
        "3 0 1 2 255 0 0\n"  # face colour after the indices
        "4 0 1 2 3 0.5 0.5 0.5 1.0\n"
    )
    V, F = io.read_off(write(tmp_path, "h.off", text))
    np.testing.assert_array_equal(V, SQUARE_V)
    assert [f.tolist() for f in F] == [[0, 1, 2], [0, 1, 2, 3]]


def test_coff_and_noff_extra_vertex_values_are_ignored(tmp_path):
    coff = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n"
    noff = "NOFF\n3 1 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 2 1 0\n"
    V, F = io.read_mesh(write(tmp_path, "c.off", coff))
    np.testing.assert_array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert F.tolist() == [[0, 1, 2]]
    V, F = io.read_mesh(write(tmp_path, "n.off", noff))
    assert F.tolist() == [[2, 1, 0]]


# --------------------------------------------------------------------------------------------
# PLY specifics: hand-built files
# --------------------------------------------------------------------------------------------


def ply_header(fmt, *element_lines):
    return ("ply\nformat " + fmt + " 1.0\ncomment hand made\n" + "".join(element_lines) + "end_header\n").encode()


def test_ply_big_endian_hand_built_bytes(tmp_path):
    head = ply_header(
        "binary_big_endian",
        "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar flag\n",
        "element face 2\nproperty list uchar uint vertex_index\nproperty int tag\n",
    )
    body = b"".join(struct.pack(">fffB", *v, 7) for v in SQUARE_V)
    body += struct.pack(">BIIIi", 3, 0, 1, 2, -5) + struct.pack(">BIIIi", 3, 0, 2, 3, 9)
    d = io.read_ply(write(tmp_path, "be.ply", head + body))
    np.testing.assert_array_equal(d.V, SQUARE_V)
    np.testing.assert_array_equal(d.faces, SQUARE_T)
    assert d.vertex_properties["flag"].tolist() == [7, 7, 7, 7]


def test_ply_little_endian_variable_face_sizes_and_extra_elements(tmp_path):
    head = ply_header(
        "binary_little_endian",
        "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n",
        "element face 2\nproperty list int short vertex_indices\n",
        "element edge 1\nproperty int a\nproperty int b\n",
    )
    body = SQUARE_V.astype("<f8").tobytes()
    body += struct.pack("<ihhh", 3, 0, 1, 2) + struct.pack("<ihhhh", 4, 0, 1, 2, 3) + struct.pack("<ii", 0, 1)
    V, F = io.read_mesh(write(tmp_path, "le.ply", head + body))
    np.testing.assert_array_equal(V, SQUARE_V)
    assert [f.tolist() for f in F] == [[0, 1, 2], [0, 1, 2, 3]]


def test_ply_ascii_hand_written_with_texture_names(tmp_path):
    head = ply_header(
        "ascii",
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n",
        "property float s\nproperty float t\n",
        "element face 1\nproperty list uchar int vertex_indices\nproperty uchar red\n",
    )
    body = b"0 0 0 0.25 0.5\n1 0 0 1 0\n\n0 1 0 0 1\n3 0 1 2 255\n"
    d = io.read_ply(write(tmp_path, "a.ply", head + body))
    np.testing.assert_array_equal(d.UV, [[0.25, 0.5], [1, 0], [0, 1]])
    assert d.faces.tolist() == [[0, 1, 2]]


# Strip A = 0 1 2 3 4 gives (0,1,2), (2,1,3) [odd: swapped], (2,3,4); strip B = 5 6 7 7 8 gives
# (5,6,7) and two degenerate triangles (7,6,7), (7,7,8) that are dropped.
STRIPS = [0, 1, 2, 3, 4, -1, 5, 6, 7, 7, 8]
STRIP_TRIANGLES = [[0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 6, 7]]


@pytest.mark.parametrize("fmt", PLY_FORMATS)
def test_ply_tristrips_decode(tmp_path, fmt):
    V = np.arange(27, dtype=float).reshape(9, 3)
    head = ply_header(
        fmt,
        "element vertex 9\nproperty float x\nproperty float y\nproperty float z\n",
        "element tristrips 1\nproperty list int int vertex_indices\n",
    )
    if fmt == "ascii":
        body = "".join(f"{a:g} {b:g} {c:g}\n" for a, b, c in V) + f"{len(STRIPS)} " + " ".join(map(str, STRIPS)) + "\n"
        body = body.encode()
    else:
        o = "<" if fmt == "binary_little_endian" else ">"
        body = V.astype(o + "f4").tobytes() + struct.pack(f"{o}i{len(STRIPS)}i", len(STRIPS), *STRIPS)
    path = write(tmp_path, "strips.ply", head + body)
    V2, F = io.read_mesh(path)
    np.testing.assert_array_equal(V2, V)
    assert F.tolist() == STRIP_TRIANGLES
    if fmt == "binary_little_endian":
        # libigl writes odd triangles as (s[k], s[k+2], s[k+1]) -- the same oriented triangle --
        # and keeps degenerate ones, which we drop.
        Fi = pytest.importorskip("igl").read_triangle_mesh(str(path))[1]
        Fi = Fi[(Fi[:, 0] != Fi[:, 1]) & (Fi[:, 1] != Fi[:, 2]) & (Fi[:, 0] != Fi[:, 2])]
        np.testing.assert_array_equal(canonical_rotation(Fi), canonical_rotation(F))


def test_ply_several_tristrip_records_and_faces_together(tmp_path):
    V = np.arange(27, dtype=float).reshape(9, 3)
    head = ply_header(
        "ascii",
        "element vertex 9\nproperty float x\nproperty float y\nproperty float z\n",
        "element face 1\nproperty list uchar int vertex_indices\n",
        "element tristrips 2\nproperty list int int vertex_indices\n",
    )
    body = "".join(f"{a:g} {b:g} {c:g}\n" for a, b, c in V) + "3 8 7 6\n5 0 1 2 3 4\n3 5 6 7\n"
    _, F = io.read_mesh(write(tmp_path, "mix.ply", head + body.encode()))
    assert F.tolist() == [[8, 7, 6], [0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 6, 7]]


# --------------------------------------------------------------------------------------------
# Malformed input: clear MeshError naming the file, the line and the problem
# --------------------------------------------------------------------------------------------

OBJ_ERRORS = [
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 40\n", "line 4: face index 40 out of range (file has 3 vertices)"),
    ("v 0 0 0\nv 1 0\nv 0 1 0\n", "line 2: expected 3 coordinates after 'v', got 2"),
    ("v 0 0 0\nv 1 0 zero\n", "line 2: cannot read number 'zero'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2\n", "line 5: face has 2 vertices, a face needs at least 3"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: face index 0 is invalid (OBJ indices start at 1)"),
    ("v 0 0 0\nf -2 -1 -1\nv 1 0 0\n", "line 2: face index -2 out of range (only 1 vertices defined before this line)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2/1 3/1\n", "line 4: cannot read face vertex '1/x'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "line 4: cannot read face vertex '1/1/1/1'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1.5 2 3\n", "line 4: cannot read face vertex '1.5'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", "line 4: face uses a texture coordinate, but the file has no 'vt'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", "line 5: texture coordinate index 2 out of range"),
    ("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", "line 3: vertex has a non-finite value"),
    ("# nothing here\n", "no vertices"),
]


@pytest.mark.parametrize("text,message", OBJ_ERRORS)
def test_obj_errors_name_the_line_and_the_problem(tmp_path, text, message):
    path = write(tmp_path, "bad.obj", text)
    with pytest.raises(MeshError) as e:
        io.read_mesh(path)
    assert message in str(e.value)
    assert str(e.value).startswith(f"read_mesh: {path}")


OFF_ERRORS = [
    ("PLY\n3 1 0\n", "line 1: expected the header 'OFF', got 'PLY'"),
    ("OFF\n3 one 0\n", "line 2: expected counts 'n_vertices n_faces n_edges', got '3 one 0'"),
    ("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "line 4: expected 3 coordinates on a vertex line, got 2"),
    ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: face index 3 out of range (file has 3 vertices"),
    ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "line 6: face says 4 vertices but lists 3 indices"),
    ("OFF\n3 2 0\n0 0 0\n\n1 0 0\n0 1 0\n3 0 1 2\n", "line 7: file ends after 1 of 2 faces"),
    ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n", "line 6: face index 2.5 is not an integer"),
]


@pytest.mark.parametrize("text,message", OFF_ERRORS)
def test_off_errors_name_the_line_and_the_problem(tmp_path, text, message):
    with pytest.raises(MeshError, match="read_off: .*bad.off") as e:
        io.read_off(write(tmp_path, "bad.off", text))
    assert message in str(e.value)


def test_ply_header_and_ascii_errors(tmp_path):
    vert = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    face = "element face 1\nproperty list uchar int vertex_indices\n"
    cases = [
        (b"PLY?\n", "not a PLY file"),
        (ply_header("binary_middle_endian", vert), "line 2: unknown format"),
        (ply_header("ascii", vert, "property quaternion q\n"), "line 8: cannot read property 'property quaternion q'"),
        (ply_header("ascii", vert) + b"0 0 0\n1 0\n0 1 0\n", "line 10: expected 3 values for 'vertex' (x y z), got 2"),
        (ply_header("ascii", vert, face) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "line 14: face index 7 out of range"),
        (ply_header("ascii", vert, face) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "line 14: 'vertex_indices' says 3 entries"),
        (ply_header("ascii", vert, face) + b"0 0 0\n1 0 0\n", "file ends after 2 of 3 'vertex' records"),
        (ply_header("ascii", face) + b"3 0 1 2\n", "the file has no 'vertex' element"),
        (ply_header("ascii", face), "line 6: file ends after 0 of 1 'face' records"),
        (b"ply\nformat ascii 1.0\nelement vertex 1\n", "no 'end_header'"),
        (
            ply_header("ascii", vert, "element face 1\nproperty uchar n\n") + b"0 0 0\n1 0 0\n0 1 0\n3\n",
            "the 'face' element has no list property 'vertex_indices' (or 'vertex_index')",
        ),
        (
            ply_header("ascii", vert, "element tristrips 1\nproperty list int int corners\n")
            + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            "the 'tristrips' element has no list property 'vertex_indices' (or 'vertex_index')",
        ),
    ]
    for content, message in cases:
        with pytest.raises(MeshError) as e:
            io.read_ply(write(tmp_path, "bad.ply", content))
        assert message in str(e.value), (message, str(e.value))


@pytest.mark.parametrize("fmt", ["binary_little_endian", "binary_big_endian"])
def test_truncated_binary_ply(tmp_path, fmt):
    io.write_ply(tmp_path / "ok.ply", SQUARE_V, [[0, 1, 2], [0, 2, 3, 1]], format=fmt)
    full = (tmp_path / "ok.ply").read_bytes()
    # Body: 4 vertices x 24 bytes, then faces of 1 + 3 * 4 and 1 + 4 * 4 bytes (126 bytes in all).
    for cut, where in [(40, "'vertex' record 4 of 4"), (55, "'vertex' record 3 of 4"), (10, "'face' record 2 of 2")]:
        with pytest.raises(MeshError, match="file is truncated") as e:
            io.read_ply(write(tmp_path, "cut.ply", full[:-cut]))
        assert where in str(e.value)


def test_binary_ply_bad_index_names_the_face(tmp_path):
    io.write_ply(tmp_path / "ok.ply", SQUARE_V, SQUARE_T)
    data = bytearray((tmp_path / "ok.ply").read_bytes())
    data[-4:] = struct.pack("<i", 9)  # last index of face 1
    with pytest.raises(MeshError, match=r"face 1: face index 9 out of range \(file has 4 vertices"):
        io.read_ply(write(tmp_path, "bad.ply", bytes(data)))


def test_missing_file_and_unknown_extension(tmp_path):
    for reader in (io.read_mesh, io.read_obj, io.read_off, io.read_ply, image_io.read_image):
        missing = tmp_path / "nope" / "x.obj"
        with pytest.raises(FileNotFoundError, match="nope"):
            reader(missing)
    with pytest.raises(MeshError, match=r"unsupported extension '\.stl'"):
        io.read_mesh(write(tmp_path, "m.stl", "solid"))
    with pytest.raises(MeshError, match=r"unsupported extension '\.stl'"):
        io.write_mesh(tmp_path / "m.stl", SQUARE_V, SQUARE_T)


def test_writers_reject_bad_input(tmp_path):
    p = tmp_path / "w.obj"
    with pytest.raises(MeshError, match=r"write_obj: V has shape \(4, 2\), expected \(n, 3\)"):
        io.write_obj(p, SQUARE_V[:, :2], SQUARE_T)
    with pytest.raises(MeshError, match="write_off: F: face 1 uses vertex 4, but V has only 4 vertices"):
        io.write_off(tmp_path / "w.off", SQUARE_V, [[0, 1, 2], [0, 2, 4]])
    with pytest.raises(MeshError, match="write_ply: F: face 0 has 2 vertices; a face needs at least 3"):
        io.write_ply(tmp_path / "w.ply", SQUARE_V, [[0, 1], [1, 2]])
    with pytest.raises(MeshError, match="write_obj: V: row 2 has a non-finite value"):
        io.write_obj(p, np.where(np.arange(12).reshape(4, 3) == 7, np.nan, SQUARE_V), SQUARE_T)
    with pytest.raises(MeshError, match="UV has 3 rows but V has 4; pass face_uv"):
        io.write_obj(p, SQUARE_V, SQUARE_T, UV=np.zeros((3, 2)))
    with pytest.raises(MeshError, match="face 1 has 3 corners in F but 4 in face_uv"):
        io.write_obj(p, SQUARE_V, [[0, 1, 2], [0, 2, 3]], UV=np.zeros((5, 2)), face_uv=[[0, 1, 2], [0, 1, 2, 3]])
    with pytest.raises(
        MeshError, match=r"face_normal: face 0 uses N row 1, but N has only 1 rows \(valid indices 0\.\.0\)"
    ):
        io.write_obj(p, SQUARE_V, SQUARE_T, N=[[0, 0, 1]], face_normal=[[0, 0, 1], [0, 0, 0]])
    with pytest.raises(MeshError, match="write_ply: N has 2 rows but V has 4"):
        io.write_ply(tmp_path / "w.ply", SQUARE_V, SQUARE_T, N=np.zeros((2, 3)))
    with pytest.raises(MeshError, match=r"colors must be integers in 0\.\.255"):
        io.write_ply(tmp_path / "w.ply", SQUARE_V, SQUARE_T, colors=np.full((4, 3), 256))
    with pytest.raises(MeshError, match="format must be one of"):
        io.write_ply(tmp_path / "w.ply", SQUARE_V, SQUARE_T, format="binary")


# --------------------------------------------------------------------------------------------
# One parser per format: layouts the old fast paths sent to a slower twin
# --------------------------------------------------------------------------------------------


def test_obj_corner_formats_may_mix_within_a_face(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 1\nvn 0 0 1\nf 1/1 2 3//1 4/2/1\n"
    d = io.read_obj(write(tmp_path, "mix.obj", text))
    assert d.faces.tolist() == [[0, 1, 2, 3]]
    assert d.face_uv.tolist() == [[0, -1, -1, 1]] and d.face_normal.tolist() == [[-1, -1, 0, 0]]


@pytest.mark.parametrize("corner", ["1/", "/1", "1//", "1/1/", "+", "1_0", "--1"])
def test_obj_bad_corner_tokens_are_named(tmp_path, corner):
    path = write(tmp_path, "bad.obj", f"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1 2 3\nf 1 2 {corner}\n")
    with pytest.raises(MeshError, match=rf"line 7: cannot read face vertex '{re.escape(corner)}'"):
        io.read_obj(path)


def test_ply_ascii_element_with_two_lists_and_scalars_between(tmp_path):
    head = ply_header(
        "ascii",
        "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n",
        "element face 2\nproperty list uchar int vertex_indices\nproperty uchar tag\n",
        "property list uchar float texcoord\n",
    )
    body = b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 7 6 0 0 1 0 1 1\n4 0 1 2 3 9 0\n"
    d = io.read_ply(write(tmp_path, "two.ply", head + body))
    assert [f.tolist() for f in d.faces] == [[0, 1, 2], [0, 1, 2, 3]]
    bad = b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 7 6 0 0 1 0 1\n4 0 1 2 3 9 0\n"
    with pytest.raises(MeshError, match=r"line 17: 'texcoord' says 6 entries, but the line has 5"):
        io.read_ply(write(tmp_path, "bad.ply", head + bad))


@pytest.mark.parametrize("count", [2**31 - 1, 2**32 - 1])
def test_binary_ply_huge_list_count_is_a_clear_error(tmp_path, count):
    head = ply_header(
        "binary_little_endian",
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n",
        "element face 1\nproperty list uint int vertex_indices\n",
    )
    body = np.zeros((3, 3), "<f4").tobytes() + struct.pack("<Iiii", count, 0, 1, 2)
    with pytest.raises(MeshError, match=rf"'face' record 1 of 1 .*says {count} entries .* list length is corrupt"):
        io.read_ply(write(tmp_path, "huge.ply", head + body))


# --------------------------------------------------------------------------------------------
# Not a file: folders and FIFOs get a clear error instead of IsADirectoryError or a hang
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("reader", ["read_mesh", "read_obj", "read_off", "read_ply", "read_image"])
def test_folders_and_fifos_are_refused(tmp_path, reader):
    fn = getattr(image_io if reader == "read_image" else io, reader)
    folder = tmp_path / "mesh.obj"
    folder.mkdir()
    with pytest.raises(MeshError, match=rf"{reader}: .*mesh.obj is a folder"):
        fn(folder)
    if not hasattr(os, "mkfifo"):
        return
    fifo = tmp_path / "pipe.ply"
    os.mkfifo(fifo)
    with pytest.raises(MeshError, match=rf"{reader}: .*pipe.ply is a FIFO"):
        fn(fifo)  # would block forever in open() if the FIFO were opened


# --------------------------------------------------------------------------------------------
# Why the readers are our own: what the well-kept libraries keep of the same small file
# --------------------------------------------------------------------------------------------

SEAM_OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
SEAM_OBJ += "f 1/1 2/2 3/3 4/4\nf 2/5 5/2 3/1\n"  # a quad and a triangle; vertices 2 and 3 sit on a UV seam


def test_why_not_a_library(tmp_path):
    """We keep polygons, vertex identity and per-corner UVs; trimesh, libigl and pyvista do not.

    If this test starts failing because a library now keeps all three, switch read_obj to it.
    """
    path = write(tmp_path, "seam.obj", SEAM_OBJ)
    d = io.read_obj(path)
    assert len(d.V) == 5 and [f.tolist() for f in d.faces] == [[0, 1, 2, 3], [1, 4, 2]]
    assert [f.tolist() for f in d.face_uv] == [[0, 1, 2, 3], [4, 1, 0]]

    trimesh = pytest.importorskip("trimesh")
    t = trimesh.load(str(path), process=False, force="mesh")
    assert t.faces.shape == (3, 3) and len(t.vertices) == 7  # triangulated, seam vertices split
    igl = pytest.importorskip("igl")
    assert igl.read_triangle_mesh(str(path))[1].shape == (3, 3)  # triangulated
    pv = pytest.importorskip("pyvista")
    m = pv.read(str(path))
    assert m.n_points == 7  # polygons kept, but seam vertices split (per-point UVs)
