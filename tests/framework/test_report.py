"""The student report of ``geomlib grade``: concise, no pytest noise, one line per failing test."""

from __future__ import annotations

from .course import run_geomlib


def _report(root, *args) -> list[str]:
    p = run_geomlib(root, "grade", *args)
    assert p.stderr.strip() == "", p.stderr
    return p.stdout.splitlines()


def test_stub_report_is_concise_and_quiet(sample_course):
    lines = _report(sample_course, "--impl", "labs")
    text = "\n".join(lines)
    for noise in ("Warning", "FAILED", "Traceback", "=====", "short test summary", "[100%]"):
        assert noise not in text, text
    body = [ln for ln in lines if ln.startswith("  ✗")]
    assert body and len(body) == len(set(body)), text
    assert text.index("total") < text.index("What to fix"), text
    assert all("not implemented yet" in ln for ln in body), text
    assert lines.count(lines[0]) == 1  # the score table is printed once


def test_one_task_only(sample_course):
    lines = _report(sample_course, "--impl", "labs", "--task", "1")
    text = "\n".join(lines)
    assert "Task 1" in text and "Task 2" not in text, text
    part = "\n".join(_report(sample_course, "--impl", "labs", "--part", "Midpoints"))
    assert "midpoints" in part and "scaling" not in part, part
    none = _report(sample_course, "--impl", "labs", "--task", "99")
    assert any("no graded test of task 99" in ln for ln in none), none


def test_check_in_a_notebook_returns_the_cli_lines(sample_course, monkeypatch):
    """``check("sample", task=1)`` in a Jupyter kernel gives the lines ``geomlib grade --task 1`` prints."""
    import nbformat
    from nbclient import NotebookClient

    cli = _report(sample_course, "--impl", "labs", "--lab", "sample", "--task", "1")
    monkeypatch.setenv("GEOMLIB_ROOT", str(sample_course))
    monkeypatch.setenv("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
    code = 'from geomlib.grading import check\nr = check("sample", task=1, impl="labs")\nprint(str(r))'
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(sample_course)}}
    ).execute()
    printed = "".join(o.get("text", "") for o in nb.cells[0].outputs if o.get("output_type") == "stream")
    assert printed.splitlines() == cli


def test_a_whole_lab_run_removes_pictures_of_tests_that_pass_now(sample_course, tmp_path):
    import os

    stale = tmp_path / "feedback" / "sample" / "tet-scale.png"
    stale.parent.mkdir(parents=True)
    stale.write_bytes(b"\x89PNG old picture")
    os.utime(stale, (1e9, 1e9))
    other = tmp_path / "feedback" / "sample" / "notes.txt"
    other.write_text("mine")
    _report(sample_course, "--impl", "solutions", "--feedback", str(tmp_path / "feedback"))
    assert not stale.exists() and other.exists()
