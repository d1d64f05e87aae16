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
``feedback/<lab>/<test>--<output>.png``; planted errors in four labs make such tests fail with a
picture that exists, is not blank and is named in the message. What stays without a picture: scalar
and short-list comparisons with no mesh or grid behind them (``loop_weight([3, 4, 6])``, a single
quadric, ``sd_box`` at six points, counts), and checks of topology or statistics with no wrong
place to mark (valences, Euler characteristic, "about half the faces").
"""

from __future__ import annotations

import importlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
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
def test_every_geometric_failure_has_a_picture(lab, tmp_path):
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
    rgb = np.asarray(Image.open(path).convert("RGB"))
    # distinct colours counted as one int per pixel (np.unique over float rows, axis=0, took seconds a picture)
    colours = np.unique((rgb[..., 0].astype(np.int32) << 16) | (rgb[..., 1].astype(np.int32) << 8) | rgb[..., 2])
    return min(rgb.shape[:2]) >= 100 and rgb.astype(float).std() > 10 and len(colours) > 20


@pytest.mark.render
def test_hand_written_graded_tests_draw_their_failures(tmp_path):
    """A planted error makes each lab's hand-written tests fail, each with a picture named in its
    message. The planted labs of :data:`HAND_WRITTEN` sit side by side in one submission folder and
    are graded by one pytest run (one interpreter, one zygote; a run per lab started four)."""
    impl = Path(tempfile.mkdtemp(prefix="geomlib-plant-hand-written-"))
    os.chmod(impl, 0o755)
    selected = []
    try:
        for lab, (plants, tests) in HAND_WRITTEN.items():
            folder = _plant(lab, *plants[0])
            for module, source in plants[1:]:
                with open(folder / f"{module}.py", "a") as f:
                    f.write("\n\n# planted error\n" + textwrap.dedent(source))
            shutil.move(folder, impl / lab)
            shutil.rmtree(folder.parent, ignore_errors=True)
            selected += [f"tests/graded/{lab}/test_{lab}.py::{test}" for test in tests]
        root = course_root()
        pictures = tmp_path / "feedback"
        env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_NO_FEEDBACK_PICTURES"}
        p = subprocess.run(
            [sys.executable, "-m", "pytest", *selected, f"--impl={impl}",
             f"--feedback-dir={pictures}", "-p", "no:cacheprovider", "-q"],
            cwd=root, capture_output=True, text=True, env=env, timeout=1200,
        )  # fmt: skip
    finally:
        shutil.rmtree(impl, ignore_errors=True)
    failures = _failures(p.stdout)
    expected = [test for _, tests in HAND_WRITTEN.values() for test in tests]
    assert sorted(failures) == sorted(expected), p.stdout[-3000:] + p.stderr[-2000:]
    for lab, (_, tests) in HAND_WRITTEN.items():
        for test in tests:
            message = failures[test]
            seen = re.search(r"\(see (\S+\.png)\)", message)
            assert seen, f"{lab}: {test} failed without a picture: {message}"
            picture = (root / seen.group(1)).resolve()
            assert picture.parent == (pictures / lab).resolve() and picture.name.startswith(f"{test}--"), picture
            assert picture.is_file() and _not_blank_png(picture), picture


def test_pictures_of_one_test_do_not_overwrite_each_other(tmp_path):
    feedback.begin_test(tmp_path, "subdivision", "test_x[warren/loop]")
    try:
        a, b, c = (feedback.picture_context("S @ V", name) for name in ("S_odd", "S_odd", "row sums"))
    finally:
        feedback.end_test()
    paths = [ctx.feedback_path() for ctx in (a, b, c)]
    assert [p.name for p in paths] == ["test_x_warren_loop--S_odd.png", "test_x_warren_loop--S_odd-2.png",
                                       "test_x_warren_loop--row_sums.png"]  # fmt: skip
    assert all(p.parent == tmp_path / "subdivision" for p in paths)
    assert feedback.picture_context("S @ V") is None  # outside a graded test: no picture, no error


def test_two_tests_that_draw_one_case_write_two_pictures_each_named_after_its_test(tmp_path):
    """A composite's test diagnosing with a building block's case draws that case too: its picture
    must not overwrite the case's own test's, and each name must say which test drew it, so a
    ``--task`` run removes exactly its own tests' stale pictures."""
    from geomlib.grading.context import Context, picture_owner

    def odd_ant():
        return Context(label="loop_odd_matrix", lab="subdivision", case_id="odd-ant", feedback_dir=tmp_path)

    names = []
    for test in ("odd-ant", "loop-ant-2-loop", "test_x[warren/loop]"):  # the case's reference test, two others
        feedback.begin_test(tmp_path, "subdivision", test)
        try:
            ctx = odd_ant()
        finally:
            feedback.end_test()
        names.append(ctx.feedback_path().name)
    assert names == ["odd-ant.png", "loop-ant-2-loop--odd-ant.png", "test_x_warren_loop--odd-ant.png"]
    assert [picture_owner(n) for n in names] == ["odd-ant", "loop-ant-2-loop", "test_x_warren_loop"]
    assert odd_ant().feedback_path().name == "odd-ant.png"  # outside a graded test: the case's id, as before
    # a case id, test name or output name with "--" or odd characters cannot make the owner ambiguous
    feedback.begin_test(tmp_path, "subdivision", "test_y[a--b]")
    try:
        odd = feedback.picture_context("x", "S--odd").feedback_path().name
    finally:
        feedback.end_test()
    assert odd == "test_y_a-b--S-odd.png" and picture_owner(odd) == "test_y_a-b"


def test_expect_close_outside_a_graded_test_still_fails_with_its_message():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(Mismatch) as e:
        expect_close("moved vertices", V + [0, 0, 0.5], V, name="V", mesh=(V, [[0, 1, 2]]))
    assert e.value.feedback is None and "V[0] expected (0, 0, 0), got (0, 0, 0.5)" in str(e.value)


# ------------------------------------------------------------------------------ every kind: expected | yours | difference


def _capture_panels(monkeypatch):
    """Record the panels each picture kind draws, in the drawing process (pictures are drawn inline)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.figure
    import matplotlib.pyplot as plt

    from geomlib import plot

    drawn = []
    monkeypatch.setattr(feedback, "_drawn_in_time", lambda path, draw: (draw(), str(path))[1])
    real_panels, real_save = plot.panels, matplotlib.figure.Figure.savefig

    def panels(images, captions=None, *a, **k):
        drawn.append(("images", [plot.to_rgb8(i) for i in images], list(captions or [])))
        return real_panels(images, captions, *a, **k)

    def savefig(fig, *a, **k):
        fig.canvas.draw()
        axes = [ax for ax in fig.axes if ax.get_title()]  # the three panels (colour bars have no title)
        crops = []
        for ax in axes:
            box = ax.get_window_extent()
            rgb = np.array(fig.canvas.buffer_rgba())[..., :3]  # a copy: saving draws again
            h = rgb.shape[0]
            crops.append(rgb[int(h - box.y1) : int(h - box.y0), int(box.x0) : int(box.x1)])
        drawn.append(("axes", crops, [ax.get_title() for ax in axes]))
        return real_save(fig, *a, **k)

    monkeypatch.setattr(plot, "panels", panels)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    return drawn, plt


OCTA_V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def _kinds():
    """One wrong output of each picture kind: (name, inputs, expected, got)."""
    rng = np.random.default_rng(1)
    E = np.array(sorted({tuple(sorted((f[i], f[(i + 1) % 3]))) for f in OCTA_F.tolist() for i in range(3)}))
    odd = (OCTA_V[E[:, 0]] + OCTA_V[E[:, 1]]) * 0.375  # points inside the octahedron (its odd vertices, 3/8)
    sphere_V = rng.normal(size=(60, 3))
    sphere_V /= np.linalg.norm(sphere_V, axis=1, keepdims=True)
    from scipy.spatial import ConvexHull

    sphere_F = ConvexHull(sphere_V).simplices
    values = np.linalg.norm(sphere_V - [1, 0, 0], axis=1)
    grid = rng.random((16, 16, 3))
    points = rng.random((40, 3))
    return [
        ("rows inside a solid", {"V": OCTA_V, "F": OCTA_F}, {"odd": odd}, {"odd": odd * 0.8}),
        ("few per-vertex values", {"V": OCTA_V, "F": OCTA_F}, {"w": np.arange(6.0)}, {"w": np.arange(6.0) + [0, 0, 2, 0, 0, 0]}),
        ("many per-vertex values", {"V": sphere_V, "F": sphere_F}, {"w": values}, {"w": values * 1.5}),
        ("a grid", {}, {"map": grid}, {"map": np.where(grid > 0.5, grid, 0.0)}),
        ("free points", {}, {"uvz": points}, {"uvz": points + [0.1, 0, 0]}),
    ]  # fmt: skip


@pytest.mark.render
@pytest.mark.parametrize("kind", [k[0] for k in _kinds()])
def test_every_picture_kind_shows_expected_yours_and_difference(kind, tmp_path, monkeypatch):
    """docs/students.md promises "expected / yours / difference": every kind of picture has those three
    panels, and the expected and yours panels differ where the data differ (markers inside a solid
    are drawn, not hidden by it)."""
    from geomlib.grading.checks import Context

    name, inputs, expected, got = next(k for k in _kinds() if k[0] == kind)
    drawn, _ = _capture_panels(monkeypatch)
    ctx = Context(label=kind, lab="kinds", case_id=_file(kind), feedback_dir=tmp_path)
    path = feedback.default_picture(ctx, inputs, expected, got)
    assert path and Path(path).is_file(), f"{kind}: no picture"
    (what, panels, captions), *_ = drawn
    assert len(panels) == 3, f"{kind}: {len(panels)} panels ({captions})"
    assert captions[0].startswith("expected") and captions[1].startswith("yours"), captions
    assert "difference" in captions[2] or "distance" in captions[2], captions
    a, b = panels[0], panels[1]
    h, w = min(a.shape[0], b.shape[0]), min(a.shape[1], b.shape[1])
    differ = np.abs(a[:h, :w].astype(int) - b[:h, :w].astype(int)).max(axis=2) > 40
    assert differ.sum() > 30, f"{kind}: the expected and yours panels look the same ({int(differ.sum())} pixels differ)"
    not_white = (a[:h, :w] < 200).any(axis=2)
    assert not_white.sum() > 20, f"{kind}: the expected panel is blank"


def test_points_and_rows_pictures_need_no_matplotlib_figure(tmp_path):
    """The first picture of shadows' --task 3 (wrong (u, v, z): free points) and of subdivision's
    --task 1 (wrong matrix rows on a mesh) are drawn with Pillow, not a matplotlib figure (importing
    matplotlib.figure, a 3D axes and a tight savefig cost 0.5-0.8 s of the 3 s a student waits for
    --task N). Three panels, as every kind (test above). Both are drawn in one fresh interpreter, one
    after the other, each followed by a look at what is imported by then."""
    kinds = ["free points", "rows inside a solid"]
    code = textwrap.dedent(
        f"""
        import sys
        from pathlib import Path
        sys.path.insert(0, {str(Path(__file__).resolve().parents[2])!r})
        from tests.framework.test_feedback_pictures import _kinds
        from geomlib.grading import feedback
        from geomlib.grading.checks import Context

        feedback._drawn_in_time = lambda path, draw: (draw(), str(path))[1]
        for kind in {kinds!r}:
            name, inputs, expected, got = next(k for k in _kinds() if k[0] == kind)
            ctx = Context(label=name, lab="kinds", case_id=kind.replace(" ", "_"), feedback_dir={str(tmp_path)!r})
            path = feedback.default_picture(ctx, inputs, expected, got)
            print(path, sorted(m for m in ("matplotlib.figure", "matplotlib.pyplot") if m in sys.modules))
        """
    )
    lines = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    lines = lines.strip().splitlines()
    assert len(lines) == len(kinds), lines
    for kind, line in zip(kinds, lines):
        out = line.split()
        assert Path(out[0]).is_file() and Path(out[0]).stat().st_size > 5000, (kind, out)
        assert out[1:] == ["[]"], f"the {kind} picture imported {out[1:]}"


def _file(text: str) -> str:
    return re.sub(r"\W+", "_", text)


@pytest.mark.render
def test_a_wrong_shader_picture_is_in_the_unit_of_its_message(tmp_path, monkeypatch):
    """relief's GLSL comparison says "differs by 6.4 texels": the picture's difference heat map is in
    texels too (it was in uv units, 1/s of the text's numbers)."""
    relief = importlib.import_module("graded.relief.test_relief")
    seen = {}
    real = feedback.image_picture

    def image_picture(ctx, expected, got, per_pixel, **k):
        seen.update(max=float(per_pixel.max()), **k)
        return real(ctx, expected, got, per_pixel, **k)

    monkeypatch.setattr(feedback, "image_picture", image_picture)
    monkeypatch.setattr(feedback, "_drawn_in_time", lambda path, draw: (draw(), str(path))[1])
    s = 64
    t = (np.arange(s) + 0.5) / s
    uv = np.stack(np.meshgrid(t, t), axis=-1)
    wrong = uv - 2 * (uv - 0.5) * 0.2  # a wrong-sign offset: 0.2 * 2 * |uv - 0.5| off, up to ~0.2 uv
    feedback.begin_test(tmp_path, "relief", "test_glsl_parallax")
    try:
        with pytest.raises(Mismatch) as e:
            relief.expect_glsl_matches("parallax", wrong, uv, atol=0.05, unit=" texels", scale_to=s)
    finally:
        feedback.end_test()
    said = float(re.search(r"differs from the NumPy reference by ([\d.]+) texels", str(e.value)).group(1))
    assert e.value.feedback and seen, "no picture"
    assert seen.get("unit") == "texels", seen
    worst = np.abs(wrong - uv).max() * s
    assert abs(seen["max"] - worst) < 1e-6 * s and said <= worst + 1e-3, (seen, said, worst)


# ------------------------------------------------------------------------------ which pictures a run draws, and when


def _image_ctx(tmp_path, case_id):
    from geomlib.grading.checks import Context

    return Context(label=case_id, lab="run", case_id=case_id, feedback_dir=tmp_path)


def test_a_run_draws_the_first_failures_picture_unless_asked_for_all(tmp_path, monkeypatch):
    """A student fixing one task gets one picture (a picture costs about a second): the first
    failure's; ``pictures="all"`` draws every one. Each run counts from zero (a notebook's kernel
    grades many times)."""
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.delenv("GEOMLIB_MAX_FEEDBACK_PICTURES", raising=False)
    a, b = np.zeros((8, 8)), np.eye(8)
    for mode, drawn in (("first", 1), ("first", 1), ("all", 3), ("none", 0)):
        out = tmp_path / mode
        with feedback.pictures_for_run(mode) as run:
            paths = [feedback.image_picture(_image_ctx(out, f"case{i}"), a, b, np.abs(a - b)) for i in range(3)]
        assert sum(p is not None for p in paths) == drawn, (mode, paths)
        assert all(Path(p).is_file() for p in paths if p), "a run ends when its pictures are drawn"
        assert run.held == 3 - drawn and not run.failed, (mode, run.held, run.failed)
    with pytest.raises(ValueError, match="pictures='some'"):
        feedback.pictures_for_run("some")


def test_a_marked_picture_past_the_runs_cap_prepares_nothing(tmp_path, monkeypatch):
    """shadows' ray-casting test marks the points where it disagrees; once the run's picture is drawn
    (the first failure's), the next marked picture is only counted as held back: its nearest
    vertices (a k-d tree, and scipy.spatial imported in the grader) are not looked up."""
    import scipy.spatial

    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.delenv("GEOMLIB_MAX_FEEDBACK_PICTURES", raising=False)
    looked_up = []
    real = scipy.spatial.cKDTree
    monkeypatch.setattr(scipy.spatial, "cKDTree", lambda *a, **k: (looked_up.append(1), real(*a, **k))[1])
    V, F = OCTA_V, OCTA_F
    feedback.begin_test(tmp_path, "shadows", "test_agrees_with_ray_casting")
    try:
        with feedback.pictures_for_run("none") as run:
            assert feedback.marked_picture("disagree", V, F, V[:2] * 0.5, "points where the two disagree") is None
    finally:
        feedback.end_test()
    assert run.held == 1 and not looked_up, (run.held, looked_up)


def test_a_picture_that_fails_while_the_tests_go_on_leaves_no_dangling_path(tmp_path, monkeypatch):
    """Pictures are drawn in a child while the next tests run; one that fails (or runs out of time) is
    taken out of the messages that named it."""
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    path = _image_ctx(tmp_path, "broken").feedback_path()

    def draw():
        raise RuntimeError("no OpenGL here")

    with feedback.pictures_for_run("all") as run:
        named = feedback._drawn_in_time(path, draw)
        assert named  # named at once: the child is still drawing
    assert run.failed == {named} and not path.exists()
    msg = f"S_odd row 0 differs (see {named})"
    assert feedback.without_pictures(msg, run.failed) == "S_odd row 0 differs"


@pytest.mark.render
def test_grade_task_draws_one_picture_and_says_how_to_get_the_others(tmp_path):
    """``geomlib grade --task 1`` with a wrong Task 1 (odd weight 3/8 -> 0.3): five failures, one
    picture (the first failure's, named in its message), and the report says ``--pictures all``."""
    from .course import planted_solution, run_geomlib

    def edit(dest):
        p = dest / "loop.py"
        text = p.read_text()
        p.write_text(text.replace("np.tile([3 / 8, 3 / 8, 1 / 8, 1 / 8]", "np.tile([0.3, 0.3, 1 / 8, 1 / 8]"))

    lab = planted_solution("subdivision", edit)
    try:
        env = {"GEOMLIB_NO_FEEDBACK_PICTURES": "", "GEOMLIB_MAX_FEEDBACK_PICTURES": ""}
        p = run_geomlib(course_root(), "grade", "--impl", str(lab.parent), "--lab", "subdivision", "--task", "1",
                        "--feedback", str(tmp_path), cwd=tmp_path, env=env)  # fmt: skip
    finally:
        shutil.rmtree(lab.parent, ignore_errors=True)
    out = p.stdout
    assert re.search(r"What to fix \([2-9] failing tests\)", out), out
    named = [ln.strip() for ln in out.splitlines() if ln.strip().endswith(".png")]
    assert "Feedback pictures (1)" in out and len(named) == 1 and (tmp_path / named[0]).is_file(), out
    assert sorted(x.name for x in (tmp_path / "subdivision").glob("*.png")) == [Path(named[0]).name]
    assert f"(see {named[0]})" in " ".join(out.split()), "the picture is named in its failure's message"
    assert "--pictures all" in out and 'pictures="all"' in out, out
