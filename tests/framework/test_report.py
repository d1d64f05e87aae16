"""The student report of ``geomlib grade``: concise, no pytest noise, one line per failing test.

The whole stubs' report and a whole-lab run's removal of stale pictures are tested in test_grading.py,
on the grading runs of the stubs and the solutions that its score tests read."""

from __future__ import annotations

from pathlib import Path

import pytest

from .course import run_geomlib


def _report(root, *args) -> list[str]:
    p = run_geomlib(root, "grade", *args)
    assert p.stderr.strip() == "", p.stderr
    return p.stdout.splitlines()


@pytest.fixture(scope="module")
def task_1_of_the_stubs(sample_course) -> list[str]:
    """The report of ``geomlib grade --impl labs --lab sample --task 1``: what ``--task`` selects
    (below) and what ``check("sample", task=1)`` must print (the notebook test), from one run."""
    return _report(sample_course, "--impl", "labs", "--lab", "sample", "--task", "1")


def test_one_task_only(sample_course, task_1_of_the_stubs):
    lines = task_1_of_the_stubs
    text = "\n".join(lines)
    assert "Task 1" in text and "Task 2" not in text, text
    # --part's report: test_a_task_run_after_a_fix_..., on the run of its --part Midpoints
    none = _report(sample_course, "--impl", "labs", "--task", "99")
    assert any("no graded test of task 99" in ln for ln in none), none


def test_check_in_a_notebook_returns_the_cli_lines(sample_course, task_1_of_the_stubs, monkeypatch):
    """``check("sample", task=1)`` in a Jupyter kernel gives the lines ``geomlib grade --task 1`` prints."""
    import nbformat
    from nbclient import NotebookClient

    cli = task_1_of_the_stubs
    monkeypatch.setenv("GEOMLIB_ROOT", str(sample_course))
    monkeypatch.setenv("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
    code = 'from geomlib.grading import check\nr = check("sample", task=1, impl="labs")\nprint(str(r))'
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(sample_course)}}
    ).execute()
    printed = "".join(o.get("text", "") for o in nb.cells[0].outputs if o.get("output_type") == "stream")
    assert printed.splitlines() == cli


def _planted_sample(sample_course, old: str, new: str) -> Path:
    """A world-readable copy of the sample lab's solution (the sandbox may run it as ``nobody``) with
    ``old`` replaced by ``new`` in ``ops.py``; returns the folder to pass as ``--impl``."""
    import os
    import shutil
    import tempfile

    base = Path(tempfile.mkdtemp(prefix="geomlib-stale-"))
    shutil.copytree(
        sample_course / "solutions" / "sample", base / "sample", ignore=shutil.ignore_patterns("__pycache__")
    )
    ops = base / "sample" / "ops.py"
    assert old in ops.read_text()
    ops.write_text(ops.read_text().replace(old, new))
    for p in [base, *base.rglob("*")]:
        os.chmod(p, 0o755 if p.is_dir() else 0o644)
    return base


def test_a_task_run_after_a_fix_removes_that_tasks_pictures_and_keeps_the_others(sample_course, tmp_path):
    """Issue #26 item 5: ``grade --task 1`` after fixing Task 1 removes the pictures of Task 1's
    tests (their names start with the test's) and keeps Task 2's, also a Task 2 test's picture of a
    Task 1 case; ``--part`` does the same for its tests (a whole-lab run removing every stale one,
    stray ones too: test_grading.py); ``--part``'s report names that part only."""
    import os
    import shutil

    from geomlib.grading.context import picture_owner

    task1 = ("return c + s * (V - c)", "return c + s * (V - c) + 0.25")
    task2 = ("M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "M = 0.4 * (V[E[:, 0]] + V[E[:, 1]])")
    both = _planted_sample(sample_course, *task1)
    ops = both / "sample" / "ops.py"
    ops.write_text(ops.read_text().replace(*task2))
    fixed1 = _planted_sample(sample_course, *task2)
    fb = tmp_path / "feedback"
    env = {"GEOMLIB_NO_FEEDBACK_PICTURES": "", "GEOMLIB_MAX_FEEDBACK_PICTURES": ""}
    try:
        run_geomlib(sample_course, "grade", "--impl", str(both), "--feedback", str(fb), "--pictures", "all", env=env)
        drawn = {p.name for p in (fb / "sample").glob("*.png")}
        # one Task 2 test's picture of a Task 1 case (a composite diagnosing with it), and a stray one
        for name in ("tet-mid--tet-scale.png", "an-old-test.png"):
            (fb / "sample" / name).write_bytes(b"\x89PNG old picture")
        for p in (fb / "sample").glob("*.png"):
            os.utime(p, (1e9, 1e9))
        ones = {
            n for n in drawn if picture_owner(n) in ("tet-scale", "tet-scale-half", "test_scale_by_one_is_identity")
        }
        twos = {n for n in drawn if picture_owner(n) in ("tet-mid", "test_one_triangle_midpoints")}
        assert "tet-scale.png" in ones and "tet-mid.png" in twos and ones | twos == drawn, drawn
        assert "test_scale_by_one_is_identity--output.png" in ones, drawn

        run_geomlib(sample_course, "grade", "--impl", str(fixed1), "--feedback", str(fb), "--task", "1", env=env)
        left = {p.name for p in (fb / "sample").glob("*.png")}
        assert left == twos | {"tet-mid--tet-scale.png", "an-old-test.png"}, (drawn, left)

        # the part's name in any case; the report holds that part only (the run costs 2 s of CPU: it
        # is also test_one_task_only's run of --part)
        part = run_geomlib(sample_course, "grade", "--impl", "solutions", "--feedback", str(fb), "--part", "Midpoints")
        assert "midpoints" in part.stdout and "scaling" not in part.stdout, part.stdout
        assert {p.name for p in (fb / "sample").glob("*.png")} == {"an-old-test.png"}
        # A whole-lab run then removes the stray one too: test_grading.py, test_a_whole_lab_run_removes_...
    finally:
        shutil.rmtree(both, ignore_errors=True)
        shutil.rmtree(fixed1, ignore_errors=True)


def test_a_picture_a_message_still_cites_stays_and_a_k_selection_removes_only_its_tests(tmp_path):
    """A diagnosis reused from an earlier run (``geomlib.grading.diagnose`` caches probe outcomes in a
    notebook's process) cites a picture drawn then: it stays while a message names it. A run that
    ran some tests only (any deselection: ``--task``, ``--part``, ``-k``) removes their pictures only."""
    import os

    from geomlib.grading.grade import _remove_stale_pictures
    from geomlib.grading.results import Record

    folder = tmp_path / "feedback" / "lab"
    folder.mkdir(parents=True)
    names = ["loop-a.png", "loop-a--odd-a.png", "loop-b--odd-b.png", "odd-a.png", "test_x--V.png"]
    for n in names:
        (folder / n).write_bytes(b"\x89PNG")
        os.utime(folder / n, (1e9, 1e9))

    def record(nodeid, passed, message=""):
        return Record(nodeid, "lab", "p", nodeid, 1.0, "visible", passed, message, 0.0)

    cites = "loop_subdivide is off because loop_odd_matrix differs (see feedback/lab/loop-b--odd-b.png)"
    records = [record("t.py::test_references[loop-a]", True), record("t.py::test_references[loop-b]", False, cites)]
    ran = {"t.py::test_references[loop-a]": "loop-a", "t.py::test_references[loop-b]": "loop-b"}
    _remove_stale_pictures(tmp_path / "feedback", records, before=2e9, ran=ran)
    assert sorted(p.name for p in folder.iterdir()) == ["loop-b--odd-b.png", "odd-a.png", "test_x--V.png"]
    _remove_stale_pictures(tmp_path / "feedback", records, before=2e9)  # whole labs ran
    assert sorted(p.name for p in folder.iterdir()) == ["loop-b--odd-b.png"]
    # everything passes now: no picture, and no empty feedback/lab/ or feedback/ left behind
    _remove_stale_pictures(tmp_path / "feedback", [record("t.py::test_references[loop-b]", True)], before=2e9)
    assert not (tmp_path / "feedback").exists(), list((tmp_path / "feedback").rglob("*"))
