"""Pictures for every geometric or image failure.

Reference cases: a planted wrong submission per lab is graded on the lab's reference cases, and
every failing case whose output is geometric gets a feedback picture. Geometric here: the case's
inputs hold a mesh (``V`` and ``F``/``faces``), or an output is a grid or image (``(h, w, c)``, or
``(h, w)`` with both sides at least 8, booleans included: vdm's diagonals), or points with no mesh
(``(n, 2)`` or ``(n, 3)``: shadows' light-space ``(u, v, z)``). Not geometric, and so allowed
without a picture: outputs on free-standing random vectors with no mesh or grid to draw them on
(denoise's ``normal_offsets`` on random ``delta``/``N``: a list of scalars).

Hand-written graded tests (``test_<lab>.py``): the grading plugin names each running graded test
for :mod:`geomlib.grading.feedback`, so ``expect_close(..., mesh=(V, F))`` and a lab's own
comparisons (subdivision's matrix rows, maps' texel maps) draw the failure as
``feedback/<lab>/<test>-<output>.png``; planted errors in four labs make such tests fail with a
picture that exists, is not blank and is named in the message. What stays without a picture: scalar
and short-list comparisons with no mesh or grid behind them (``loop_weight([3, 4, 6])``, a single
quadric, ``sd_box`` at six points, counts), and checks of topology or statistics with no wrong
place to mark (valences, Euler characteristic, "about half the faces").
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from geomlib.grading import feedback
from geomlib.grading.cases import expect_close, load_cases, load_reference, run_case
from geomlib.grading.errors import Mismatch
from geomlib.grading.impl import course_root
from geomlib.grading.sandbox import LabProxy

from .test_diagnose import _plant

# lab, module, planted source, at least this many failing cases, at least this many with pictures
PLANTS = {
    "vdm": (
        "sampling",
        """
        _true_sample_surface = sample_surface

        def sample_surface(V, F, UV, uv_points):
            return 1.01 * _true_sample_surface(V, F, UV, uv_points)
        """,
        8,
    ),
    "denoise": (
        "laplacian",
        """
        _true_normal_offsets = normal_offsets

        def normal_offsets(delta, N):
            return 0.8 * _true_normal_offsets(delta, N)
        """,
        3,
    ),
    "shadows": (
        "lookup",
        """
        _true_light_uvz = light_uvz

        def light_uvz(P, M):
            return np.asarray(_true_light_uvz(P, M)) + [0.05, 0.0, 0.0]
        """,
        3,
    ),
}


def _geometric(case, expected: dict) -> bool:
    inputs = case.inputs()
    if "V" in inputs and any(k in inputs for k in ("F", "faces", "Q")):
        return True
    for e in expected.values():
        e = np.asarray(e)
        if e.dtype.kind not in "fb":
            continue
        if e.ndim == 3 and min(e.shape[:2]) >= 2 and e.shape[2] <= 4:
            return True
        if e.ndim == 2 and min(e.shape) >= 8:
            return True
        if e.dtype.kind == "f" and e.ndim == 2 and e.shape[1] in (2, 3) and len(e) >= 2:
            return True  # free-standing points (light-space (u, v, z)): a scatter picture
    return False


@pytest.mark.parametrize("lab", list(PLANTS))
def test_every_geometric_failure_has_a_picture(lab, tmp_path, generous_pictures):
    module, source, at_least = PLANTS[lab]
    folder = _plant(lab, module, source)
    proxy = LabProxy(lab, folder)
    failing, missing = [], []
    try:
        for case in load_cases(lab, hidden=True, probes=False):
            try:
                run_case(proxy, case, feedback_dir=tmp_path)
            except Mismatch as e:
                failing.append(case.id)
                if _geometric(case, load_reference(lab, case)) and not (e.feedback and (tmp_path / lab).is_dir()):
                    missing.append(case.id)
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)
    assert len(failing) >= at_least, f"the plant should fail at least {at_least} cases, failed {failing}"
    assert not missing, f"failing geometric cases without a feedback picture: {missing}"
    drawn = list((tmp_path / lab).glob("*.png"))
    assert drawn and all(p.stat().st_size > 1000 for p in drawn), drawn


# ------------------------------------------------------------------------------ hand-written graded tests

# lab: ([(module, planted source), ...], hand-written tests that must fail with a picture)
HAND_WRITTEN = {
    "subdivision": (
        [
            (
                "loop",
                """
                _true_loop_odd_matrix = loop_odd_matrix

                def loop_odd_matrix(V, F, *, topo=None):
                    S = _true_loop_odd_matrix(V, F, topo=topo).tolil()
                    S[1, 0] += 0.1
                    return S.tocsr()
                """,
            )
        ],
        # matrix rows on the mesh (expect_matrix) and odd vertices as points (expect_close)
        [
            "test_tetrahedron_odd_rows",
            "test_octahedron_odd_positions",
            "test_square_interior_edge_between_boundary_vertices",
        ],
    ),
    "denoise": (
        [
            (
                "laplacian",
                """
                _true_laplacian_offsets = laplacian_offsets

                def laplacian_offsets(V, F, weights="uniform", *, weld=True):
                    d = np.array(_true_laplacian_offsets(V, F, weights, weld=weld), float)
                    d[len(d) // 2] += 0.05
                    return d
                """,
            )
        ],
        # per-vertex offsets, all vertices and the interior ones only (mesh=(V, F, interior))
        ["test_pyramid_uniform_offsets", "test_flat_meshes_have_zero_interior_offsets"],
    ),
    "maps": (
        [
            (
                "tangents",
                """
                _true_tangent_frames = tangent_frames

                def tangent_frames(V, F, UV, N=None, *, eps=1e-12):
                    T, B, N, w = (np.array(a, float) for a in _true_tangent_frames(V, F, UV, N, eps=eps))
                    T[0] = -T[0]
                    return T, B, N, w
                """,
            ),
            (
                "heightmap",
                """
                _true_height_to_normal_map = height_to_normal_map

                def height_to_normal_map(H, strength=1.0, border="clamp"):
                    n = np.array(_true_height_to_normal_map(H, strength, border), float)
                    n[: len(n) // 4] = [0.0, 0.0, 1.0]
                    return n
                """,
            ),
        ],
        # per-vertex frames on a triangle, and a texel map (the lab's own expect_map_close)
        ["test_one_triangle_by_hand", "test_matches_the_analytic_gradient"],
    ),
    "vdm": (
        [
            (
                "importance",
                """
                _true_vertex_importance = vertex_importance

                def vertex_importance(V, F):
                    return 0.9 * np.asarray(_true_vertex_importance(V, F), float)
                """,
            )
        ],
        ["test_importance_by_hand", "test_importance_of_the_box"],
    ),
}


def _failures(stdout: str) -> dict:
    """``{test name: its failure message}`` from pytest's FAILURES section (the plugin prints the message only)."""
    out, name = {}, None
    for line in stdout.splitlines():
        m = re.fullmatch(r"_{3,} (test_\S+) _{3,}", line.strip())
        if m:
            name = m.group(1)
            out[name] = ""
        elif re.match(r"={3,}", line):
            name = None
        elif name is not None:
            out[name] += line + "\n"
    return out


def _not_blank_png(path: Path) -> bool:
    from PIL import Image

    if path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        return False
    img = np.asarray(Image.open(path).convert("RGB"), float)
    return min(img.shape[:2]) >= 100 and img.std() > 10 and len(np.unique(img.reshape(-1, 3), axis=0)) > 20


@pytest.mark.render
@pytest.mark.parametrize("lab", list(HAND_WRITTEN))
def test_hand_written_graded_tests_draw_their_failures(lab, tmp_path):
    """A planted error makes the lab's hand-written tests fail, each with a picture named in its message."""
    plants, tests = HAND_WRITTEN[lab]
    folder = _plant(lab, *plants[0])
    for module, source in plants[1:]:
        with open(folder / f"{module}.py", "a") as f:
            f.write("\n\n# planted error\n" + textwrap.dedent(source))
    root = course_root()
    pictures = tmp_path / "feedback"
    env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_NO_FEEDBACK_PICTURES"}
    try:
        p = subprocess.run(
            [sys.executable, "-m", "pytest", f"tests/graded/{lab}/test_{lab}.py", f"--impl={folder.parent}",
             f"--feedback-dir={pictures}", "-p", "no:cacheprovider", "-p", "tests.framework.hang_limits",
             "-q", "-k", " or ".join(tests)],
            cwd=root, capture_output=True, text=True, env=env, timeout=600,
        )  # fmt: skip
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)
    failures = _failures(p.stdout)
    assert sorted(failures) == sorted(tests), p.stdout[-3000:] + p.stderr[-2000:]
    for test, message in failures.items():
        seen = re.search(r"\(see (\S+\.png)\)", message)
        assert seen, f"{test} failed without a picture: {message}"
        picture = (root / seen.group(1)).resolve()
        assert picture.parent == (pictures / lab).resolve() and picture.name.startswith(f"{test}-"), picture
        assert picture.is_file() and _not_blank_png(picture), picture


def test_pictures_of_one_test_do_not_overwrite_each_other(tmp_path):
    feedback.begin_test(tmp_path, "subdivision", "test_x[warren/loop]")
    try:
        a, b, c = (feedback.picture_context("S @ V", name) for name in ("S_odd", "S_odd", "row sums"))
    finally:
        feedback.end_test()
    paths = [ctx.feedback_path() for ctx in (a, b, c)]
    assert [p.name for p in paths] == ["test_x_warren_loop-S_odd.png", "test_x_warren_loop-S_odd-2.png",
                                       "test_x_warren_loop-row_sums.png"]  # fmt: skip
    assert all(p.parent == tmp_path / "subdivision" for p in paths)
    assert feedback.picture_context("S @ V") is None  # outside a graded test: no picture, no error


def test_expect_close_outside_a_graded_test_still_fails_with_its_message():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(Mismatch) as e:
        expect_close("moved vertices", V + [0, 0, 0.5], V, name="V", mesh=(V, [[0, 1, 2]]))
    assert e.value.feedback is None and "V[0] expected (0, 0, 0), got (0, 0, 0.5)" in str(e.value)
