"""A failing geometry or image check writes a feedback picture (expected | submitted | difference)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geomlib import datasets, image_io
from geomlib.grading import checks
from geomlib.grading.errors import Mismatch


@pytest.mark.render
def test_mesh_mismatch_writes_a_three_panel_picture(tmp_path, monkeypatch):
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.chdir(tmp_path)
    V, F = datasets.icosphere(2)
    bent = V.copy()
    bent[V[:, 2] > 0.5] *= 1.1
    ctx = checks.Context(
        label='loop_subdivide on "ico"', lab="subdivision", case_id="ico", feedback_dir=Path("feedback")
    )
    with pytest.raises(Mismatch) as e:
        checks.MeshMatch()({"V": V, "F": F}, {"V": bent, "F": F}, ctx)
    assert e.value.feedback == "feedback/subdivision/ico.png"
    assert "(see feedback/subdivision/ico.png)" in str(e.value)
    img = image_io.read_image(tmp_path / e.value.feedback)
    assert img.shape[1] > 2.5 * img.shape[0] / 1.5 and img.std() > 10  # three panels side by side, not blank


_PICTURE_AFTER_FIGURES = """
import sys
from pathlib import Path
from geomlib import datasets, render
from geomlib.grading import checks
from geomlib.grading.errors import Mismatch

V, F = datasets.icosphere(2)
render.render(V, F, size=(64, 48))  # a figure first: this process now holds an OpenGL context
bent = V.copy()
bent[V[:, 2] > 0.5] *= 1.1
ctx = checks.Context(label="loop_subdivide", lab="subdivision", case_id="ico", feedback_dir=Path("feedback"))
try:
    checks.MeshMatch()({"V": V, "F": F}, {"V": bent, "F": F}, ctx)
except Mismatch as e:
    print(e.feedback)
"""


@pytest.mark.render
def test_a_picture_is_drawn_after_the_process_has_rendered(tmp_path):
    """A notebook draws its figures, then grades: the picture's forked child cannot use the parent's
    OpenGL (Mesa's threads stay behind) and draws through a fresh process instead of timing out."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_NO_FEEDBACK_PICTURES"}
    proc = subprocess.run(
        [sys.executable, "-c", _PICTURE_AFTER_FIGURES],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "feedback/subdivision/ico.png", (proc.stdout, proc.stderr[-2000:])
    img = image_io.read_image(tmp_path / "feedback/subdivision/ico.png")
    assert img.std() > 10


def test_image_mismatch_writes_a_difference_map(tmp_path):
    expected = np.zeros((32, 32, 3), np.uint8)
    got = expected.copy()
    got[8:16, 8:16] = 200
    ctx = checks.Context(label="shade", lab="maps", case_id="quad", feedback_dir=tmp_path)
    with pytest.raises(Mismatch) as e:
        checks.ImageMatch()({"image": expected}, {"image": got}, ctx)
    assert "6.25% of pixels differ" in str(e.value) and "row 8, column 8" in str(e.value)
    assert (tmp_path / "maps" / "quad.png").is_file()


def test_results_json_inlines_a_failed_tests_feedback_picture(tmp_path):
    """Gradescope serves no files from results/: the picture travels inside the test's HTML output."""
    import base64

    from PIL import Image

    from geomlib.grading.results import PICTURE_WIDTH, Record, build_results, validate_results

    pic = tmp_path / "wrong.png"
    Image.fromarray(np.full((300, 2000, 3), 200, np.uint8)).save(pic)

    def record(passed, picture, message='loop_subdivide on "cube": vertex 3 is off by 0.5 <script>'):
        return Record(
            nodeid="t", lab="subdivision", part="levels", name="cube", points=1.0, visibility="visible",
            passed=passed, message=message, duration=0.1, picture=picture,
        )  # fmt: skip

    data = build_results([record(False, str(pic)), record(False, None), record(True, str(pic), "")], 1.0)
    validate_results(data)
    with_picture, without, passed = data["tests"]
    assert with_picture["output_format"] == "html"
    assert "&lt;script&gt;" in with_picture["output"] and "<script>" not in with_picture["output"]
    b64 = with_picture["output"].split("base64,")[1].split('"')[0]
    from io import BytesIO

    shown = Image.open(BytesIO(base64.b64decode(b64)))
    assert shown.width == PICTURE_WIDTH  # shrunk to fit, aspect kept
    assert abs(shown.height - round(300 * PICTURE_WIDTH / 2000)) <= 1
    assert without["output_format"] == "md" and "data:image" not in without["output"]
    assert passed["output_format"] == "md" and "data:image" not in passed["output"]


def test_results_json_names_the_tasks_of_a_failed_test():
    """On Gradescope a test's name gives the lab and the part only; a failed test's output starts with
    the handout's tasks it checks, as the local "What to fix" lines do (a wrong Task 4 split point read
    "remeshing › stages › split_long_edges on ...: V has shape ..." with no task)."""
    from geomlib.grading.results import Record, build_results, validate_results

    def record(nodeid, passed, message="V has shape (1226, 3), expected (1225, 3)", not_implemented=False):
        return Record(
            nodeid=nodeid, lab="remeshing", part="stages", name="split", points=1.0, visibility="visible",
            passed=passed, message=message, duration=0.1, not_implemented=not_implemented,
        )  # fmt: skip

    records = [
        record("a", False),
        record("b", False),
        record("c", True, ""),
        record("d", False, "split_long_edges: not implemented yet (Task 4 (split long edges))", True),
        record("e", False),
        record("f", False, "grader problem (not your code): the sandbox user cannot run python"),
    ]
    records[-1].error = True
    data = build_results(records, 1.0, tasks={"a": (4,), "b": (1, 4), "c": (4,), "d": (4,), "f": (4,)})
    validate_results(data)
    out = [t["output"] for t in data["tests"]]
    assert out[0].startswith("Task 4: V has shape") and out[1].startswith("Tasks 1, 4: V has shape")
    assert "Task" not in out[2]  # passed: nothing to say
    assert out[3].count("Task 4") == 1  # a stub's message names its task already
    assert out[4].startswith("V has shape")  # a test without tasks (bad input): as before
    assert out[5].startswith("grader problem (not your code)")  # not the student's task
    assert build_results(records, 1.0)["tests"][0]["output"].startswith("V has shape")  # no task map given


def test_a_missing_or_huge_picture_is_not_embedded(tmp_path):
    from PIL import Image

    from geomlib.grading import results

    assert results.embedded_picture(tmp_path / "nope.png") is None
    noise = np.random.default_rng(0).integers(0, 256, (900, 900, 3), dtype=np.uint8)  # incompressible
    Image.fromarray(noise).save(tmp_path / "noise.png")
    assert results.embedded_picture(tmp_path / "noise.png") is None


def test_the_picture_cap_stops_drawing_after_n_pictures(tmp_path, monkeypatch):
    """The autograder caps pictures per run (GEOMLIB_MAX_FEEDBACK_PICTURES): the first failures get one, the
    rest keep their message without one; GEOMLIB_NO_FEEDBACK_PICTURES switches every kind off."""
    from geomlib.grading import feedback, picture_run

    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.setenv("GEOMLIB_MAX_FEEDBACK_PICTURES", "2")
    monkeypatch.setattr(picture_run, "_DRAWN", [0])
    expected = np.zeros((16, 16, 3))
    got = expected + 0.5

    def draw(i):
        ctx = checks.Context(label="shade", lab="maps", case_id=f"quad{i}", feedback_dir=tmp_path)
        return feedback.image_picture(ctx, expected, got, np.full((16, 16), 0.5))

    drawn = [draw(i) for i in range(3)]
    assert drawn[0] and drawn[1] and drawn[2] is None
    assert sorted(p.name for p in (tmp_path / "maps").glob("*.png")) == ["quad0.png", "quad1.png"]
    monkeypatch.delenv("GEOMLIB_MAX_FEEDBACK_PICTURES")
    assert draw(3) is not None
    monkeypatch.setenv("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
    assert draw(4) is None


def test_an_embedded_picture_is_not_run_through_the_png_optimiser(tmp_path, monkeypatch):
    """Every grade with a picture embeds it (results.json): Pillow's ``optimize=True`` spends 2-3 times
    the CPU (40-65 ms a picture) for 1 % fewer bytes. The embedded picture has the same pixels."""
    import base64
    from io import BytesIO

    from PIL import Image

    from geomlib.grading.results import embedded_picture

    pic = tmp_path / "p.png"
    pixels = np.random.default_rng(0).integers(0, 255, (120, 200, 3), dtype=np.uint8)
    Image.fromarray(pixels).save(pic)
    options = []
    real = Image.Image.save
    monkeypatch.setattr(Image.Image, "save", lambda self, fp, *a, **k: (options.append(k), real(self, fp, *a, **k))[1])
    html = embedded_picture(pic)
    assert options and not any(k.get("optimize") for k in options), options
    shown = np.asarray(Image.open(BytesIO(base64.b64decode(html.split("base64,")[1].split('"')[0]))).convert("RGB"))
    assert np.array_equal(shown, pixels)
