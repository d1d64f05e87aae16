"""``geomlib info``: every defect named with its count, components counted through shared edges.

Expected counts are worked out by hand on small meshes built here (comments say why).
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib import mesh_io as io
from geomlib.cli import main
from geomlib.info import summary

# A unit square (faces 0, 1) plus one copy of face 0 with the other orientation (face 2), a face
# that repeats vertex 1 (face 3) and a zero-area face through the midpoint 6 of edge 0-1 (face 4).
# Vertex 4 sits exactly on vertex 0; vertices 4 and 5 are used by no face.
V = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0], [5, 5, 5], [0.5, 0, 0]],
    dtype=float,
)
F = np.array([[0, 1, 2], [0, 2, 3], [2, 1, 0], [1, 1, 3], [0, 6, 1]])


def test_every_defect_is_counted_with_examples():
    s = summary(V, F)
    assert (s["duplicate_faces"], s["duplicate_faces_examples"]) == (1, [2])
    assert (s["degenerate_faces"], s["degenerate_faces_examples"]) == (2, [3, 4])
    assert (s["degenerate_repeated"], s["degenerate_zero_area"]) == (1, 1)
    assert (s["duplicate_vertices"], s["duplicate_vertices_examples"]) == (1, [4])
    assert (s["unreferenced_vertices"], s["unreferenced_vertices_examples"]) == (2, [4, 5])
    # Edge 0-1 is used by faces 0, 2 and 4; edge 0-2 by faces 0, 1 and 2.
    assert (s["non_manifold_edges"], s["non_manifold_edges_examples"]) == (2, [[0, 1], [0, 2]])
    assert not s["edge_manifold"] and s["genus"] is None
    # Face 3 touches the rest only at vertex 1 and shares edge 1-3 with nothing: its own component.
    assert s["components"] == 2


def test_a_duplicated_face_stays_in_its_component():
    V, F = datasets.icosphere(1)
    s = summary(V, np.vstack([F, F[[7]]]))
    assert s["components"] == 1
    assert (s["duplicate_faces"], s["duplicate_faces_examples"]) == (1, [len(F)])
    assert s["non_manifold_edges"] == 3  # the three edges of the copied face
    clean = summary(V, F)
    assert clean["components"] == 1 and clean["genus"] == 0
    assert all(clean[k] == 0 for k in ("duplicate_faces", "degenerate_faces", "non_manifold_edges"))


def test_a_bow_tie_vertex_is_non_manifold():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], dtype=float)
    s = summary(V, np.array([[0, 1, 2], [0, 3, 4]]))
    assert s["edge_manifold"] and not s["vertex_manifold"]
    assert (s["non_manifold_vertices"], s["non_manifold_vertices_examples"]) == (1, [0])
    assert s["components"] == 2


def test_two_separate_cubes_are_two_components():
    V, Q = datasets.quad_cube()
    s = summary(np.vstack([V, V + 3]), np.vstack([Q, Q + len(V)]))
    assert s["components"] == 2 and s["euler_characteristic"] == 4 and s["genus"] is None


def test_the_command_names_each_defect_with_its_count(tmp_path, capsys):
    path = tmp_path / "broken.obj"
    io.write_obj(path, V, F)
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    for line in (
        "duplicate faces        1  (faces 2)",
        "degenerate faces       2  (faces 3, 4) [1 repeat a vertex, 1 have zero area]",
        "duplicate vertices     1  (vertices 4)",
        "unreferenced vertices  2  (vertices 4, 5)",
        "non-manifold edges     2  (edges (0, 1), (0, 2))",
        "components     2",
    ):
        assert line in out, f"missing {line!r} in:\n{out}"


def test_a_clean_mesh_says_so(tmp_path, capsys):
    path = tmp_path / "ico.off"
    io.write_off(path, *datasets.icosphere(2))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "components     1" in out and "genus 0" in out and "none: no duplicate" in out
