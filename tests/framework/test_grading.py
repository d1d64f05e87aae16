"""The grading framework end to end on the sample course: scores, reports, messages, hostile submissions.

The stubs and the solutions are graded once each for the module (:func:`sample_stubs_graded`,
:func:`sample_solutions_graded`): the tests of their scores and of their reports read the same run
(in one file, so that pytest-xdist's ``--dist loadfile`` keeps them in one process)."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import textwrap
from pathlib import Path

import pytest

from geomlib.grading.results import plain_text, validate_results

from .course import grade, run_geomlib, sandbox_python, sandbox_user_problem

GOOD_OPS = (Path(__file__).parent / "sample_course" / "solutions" / "sample" / "ops.py").read_text()


def _by_name(results: dict) -> dict[str, dict]:
    """Tests by name, their Markdown output turned back into plain text."""
    return {t["name"]: {**t, "output": plain_text(t.get("output", ""))} for t in results["tests"]}


@pytest.fixture(scope="module")
def sample_stubs_graded(sample_course) -> tuple:
    """``(stdout, results)`` of one ``geomlib grade --impl labs --results R`` on the sample course:
    the report and the results of the stubs (tests below) come from one run (a
    grade costs about 2 s of CPU, most of it the start of the grader and its zygote)."""
    results = sample_course / "results" / "labs-shared.json"
    p = run_geomlib(sample_course, "grade", "--impl", "labs", "--results", str(results))
    assert p.stderr.strip() == "", p.stderr
    return p.stdout, json.loads(results.read_text())


@pytest.fixture(scope="module")
def sample_solutions_graded(sample_course, tmp_path_factory) -> tuple:
    """``(results, feedback folder)`` of one whole-lab ``geomlib grade --impl solutions --results R
    --feedback F`` on the sample course, ``F`` holding beforehand old pictures, of a test that now
    passes (``sample/tet-scale.png``) and a stray one (``an-old-test.png``), and a file of the
    student's (``sample/notes.txt``): the solutions' score and the stale pictures' removal (tests below)
    come from one run."""
    feedback = tmp_path_factory.mktemp("solutions-feedback") / "feedback"
    (feedback / "sample").mkdir(parents=True)
    for name in ("tet-scale.png", "an-old-test.png"):
        (feedback / "sample" / name).write_bytes(b"\x89PNG old picture")
        os.utime(feedback / "sample" / name, (1e9, 1e9))
    (feedback / "sample" / "notes.txt").write_text("mine")
    results = sample_course / "results" / "solutions-shared.json"
    p = run_geomlib(
        sample_course, "grade", "--impl", "solutions", "--results", str(results), "--feedback", str(feedback)
    )
    assert p.stderr.strip() == "", p.stderr
    return json.loads(results.read_text()), feedback


def test_solutions_score_full_marks_and_results_follow_the_schema(sample_solutions_graded):
    r, _ = sample_solutions_graded
    validate_results(r)
    assert r["score"] == sum(t["max_score"] for t in r["tests"]) == 7  # 6 public + 1 hidden point
    assert all(t["status"] == "passed" for t in r["tests"])
    vis = {t["name"]: t["visibility"] for t in r["tests"]}
    assert vis['sample › scaling › scale_about_centroid on "tet-scale-half"'] == "hidden"
    assert "total" in r["output"] and "scaling" in r["output"]


def test_stubs_score_zero_without_a_single_error(sample_stubs_graded):
    _, r = sample_stubs_graded
    validate_results(r)
    assert r["score"] == 0
    pointed = [t for t in r["tests"] if t["max_score"] > 0]
    assert pointed and all(t["status"] == "failed" for t in pointed)
    for t in pointed:
        assert "not implemented yet" in t["output"], t
        assert "Traceback" not in t["output"]
    assert "Task 1 (scaling)" in _by_name(r)['sample › scaling › scale_about_centroid on "tet-scale"']["output"]


def test_stub_report_is_concise_and_quiet(sample_stubs_graded):
    lines = sample_stubs_graded[0].splitlines()
    text = "\n".join(lines)
    for noise in ("Warning", "FAILED", "Traceback", "=====", "short test summary", "[100%]"):
        assert noise not in text, text
    body = [ln for ln in lines if ln.startswith("  ✗")]
    assert body and len(body) == len(set(body)), text
    assert text.index("total") < text.index("What to fix"), text
    assert all("not implemented yet" in ln for ln in body), text
    assert lines.count(lines[0]) == 1  # the score table is printed once


def test_a_whole_lab_run_removes_pictures_of_tests_that_pass_now(sample_solutions_graded):
    """The run (the fixture) had an old picture of a test that passes now (``tet-scale.png``), a stray
    old one that no test's name owns (``an-old-test.png``) and the student's ``notes.txt`` in its
    feedback folder: both pictures go, the student's file stays."""
    _, feedback = sample_solutions_graded
    assert not list((feedback / "sample").glob("*.png"))
    assert (feedback / "sample" / "notes.txt").read_text() == "mine"


#: Folders made by :func:`_submission`, removed after each test (:func:`_remove_submissions`).
_MADE: list[Path] = []


@pytest.fixture(autouse=True)
def _remove_submissions():
    yield
    while _MADE:
        shutil.rmtree(_MADE.pop(), ignore_errors=True)


def _submission(tmp_path: Path, ops_source: str, extra_files: dict[str, str] | None = None) -> Path:
    # A world-readable folder, so the sandbox may drop privileges to `nobody` and still read it
    # (pytest's tmp_path lies under a folder only its owner may enter); removed after the test.
    tmp_path = Path(tempfile.mkdtemp(prefix="geomlib-sub-"))
    _MADE.append(tmp_path)
    tmp_path.chmod(0o755)
    sub = tmp_path / "submission" / "sample"
    sub.mkdir(parents=True)
    (sub / "__init__.py").write_text("from .ops import *\n")
    (sub / "ops.py").write_text(textwrap.dedent(ops_source))
    for name, text in (extra_files or {}).items():
        (sub / name).write_text(textwrap.dedent(text))
    return tmp_path / "submission"


def test_wrong_values_get_a_message_naming_the_row_values_and_count(sample_course, tmp_path):
    wrong = GOOD_OPS.replace("return c + s * (V - c)", "return s * V  # forgot the centroid")
    r = grade(sample_course, str(_submission(tmp_path, wrong)))
    t = _by_name(r)['sample › scaling › scale_about_centroid on "tet-scale"']
    assert t["status"] == "failed" and t["score"] == 0
    assert t["output"].startswith('Task 1: scale_about_centroid on "tet-scale": V[0] expected (')
    assert "got (0, 0, 0)" in t["output"] and "of 4 rows off by more than" in t["output"]
    assert "scale about the centroid, not the origin" in t["output"]  # the case's hint
    # Partial credit: the midpoints part is untouched.
    assert _by_name(r)['sample › midpoints › edge_midpoints on "tet-mid"']["status"] == "passed"


def test_student_exception_shows_their_own_file_and_line(sample_course, tmp_path):
    broken = GOOD_OPS.replace("M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "M = 0.5 * (V[E[:, 0]] + V[E[:, 1] + 100])")
    r = grade(sample_course, str(_submission(tmp_path, broken)))
    t = _by_name(r)['sample › midpoints › edge_midpoints on "tet-mid"']
    assert "edge_midpoints raised IndexError at sample/ops.py, line" in t["output"]
    assert "V[E[:, 1] + 100]" in t["output"]
    assert "geomlib/grading" not in t["output"]


def test_a_crash_costs_only_the_affected_tests(sample_course, tmp_path):
    src = GOOD_OPS.replace("    c = V.mean(axis=0)\n", "    import ctypes; ctypes.string_at(0)\n")
    r = grade(sample_course, str(_submission(tmp_path, src)))
    validate_results(r)
    by = _by_name(r)
    assert "segmentation fault" in by['sample › scaling › scale_about_centroid on "tet-scale"']["output"]
    assert by['sample › midpoints › edge_midpoints on "tet-mid"']["status"] == "passed"
    assert r["score"] == 3  # the midpoints part (2 + 1) still scores


def test_syntax_error_in_one_file_costs_only_its_functions(sample_course, tmp_path):
    ops = GOOD_OPS.replace("def edge_midpoints(V, F):", "def edge_midpoints(V, F:")  # syntax error
    # scale_about_centroid moved to its own, valid file.
    start = GOOD_OPS.index("def scale_about_centroid")
    end = GOOD_OPS.index("def edge_midpoints")
    scale_src = GOOD_OPS[:end]
    ops = ops[:start] + ops[end:]
    sub = _submission(tmp_path, ops, {"scale.py": scale_src})
    r = grade(sample_course, str(sub))
    by = _by_name(r)
    assert by['sample › scaling › scale_about_centroid on "tet-scale"']["status"] == "passed"
    t = by['sample › midpoints › edge_midpoints on "tet-mid"']
    assert t["status"] == "failed" and "ops.py line" in t["output"] and "syntax" in t["output"].lower()


def test_missing_function_and_missing_lab(sample_course, tmp_path):
    ops = GOOD_OPS.replace("def edge_midpoints(V, F):", "def edge_midpoint(V, F):")
    r = grade(sample_course, str(_submission(tmp_path, ops)))
    t = _by_name(r)['sample › midpoints › edge_midpoints on "tet-mid"']
    assert "could not find a function named 'edge_midpoints'" in t["output"]
    empty = tmp_path / "empty"
    empty.mkdir()
    r = grade(sample_course, str(empty))
    assert r["score"] == 0 and all(
        "missing from the submission" in t["output"] for t in _by_name(r).values() if t["max_score"]
    )


def test_student_code_cannot_touch_the_results_or_read_hidden_references(sample_course, tmp_path):
    problem = sandbox_user_problem("nobody")
    if problem:
        pytest.skip(problem)
    results = sample_course / "results" / "submission.json"
    hidden = next((sample_course / "tests" / "reference" / "sample" / "hidden").glob("*.npz"))
    src = GOOD_OPS.replace(
        "    c = V.mean(axis=0)\n",
        f"""    import json, numpy as np
    try:
        open({str(results)!r}, "w").write(json.dumps({{"score": 999, "tests": []}}))
    except OSError:
        pass
    try:
        np.load({str(hidden)!r})
        raise RuntimeError("LEAK: read a hidden reference")
    except PermissionError:
        pass
    c = V.mean(axis=0)
""",
    )
    hidden.parent.chmod(0o700)
    try:
        python, extra = sandbox_python("nobody")
        r = grade(
            sample_course,
            str(_submission(tmp_path, src)),
            env={"GEOMLIB_SANDBOX_USER": "nobody", **extra},
            python=python,
        )
    finally:
        hidden.parent.chmod(0o755)
    assert r["score"] == 7
    assert json.loads(results.read_text())["score"] == 7


def _plain_pytest(sample_course: Path, sub: Path, *extra: str):
    """``pytest tests/graded/sample --impl=sub *extra`` in the sample course, in a subprocess."""
    import os
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-m", "pytest", "tests/graded/sample", f"--impl={sub}", "-p", "no:cacheprovider", *extra],
        cwd=sample_course,
        capture_output=True,
        text=True,
        env={**os.environ, "GEOMLIB_ROOT": str(sample_course), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"},
    )


@pytest.fixture(scope="module")
def wrong_scale_plain_run(sample_course):
    """One plain ``pytest`` run (no xdist) of a submission whose scaling ignores the centroid: its
    message (test below) and its score table (compared with xdist's) come from the same run."""
    sub = _submission(None, GOOD_OPS.replace("return c + s * (V - c)", "return s * V"))
    _MADE.remove(sub.parent)  # kept for the module's tests, removed below
    yield sub, _plain_pytest(sample_course, sub)
    shutil.rmtree(sub.parent, ignore_errors=True)


def test_plain_pytest_shows_the_message_not_a_traceback(wrong_scale_plain_run):
    _, p = wrong_scale_plain_run
    out = p.stdout
    assert p.returncode == 1
    assert 'scale_about_centroid on "tet-scale": V[0] expected' in out
    assert "sandbox.py" not in out and "Traceback" not in out
    assert "graded score" in out


def test_the_score_table_is_the_same_with_pytest_xdist(sample_course, wrong_scale_plain_run):
    """`./run tests` runs the whole suite on every core (pytest-xdist): the graded records travel on
    the reports from the workers, so the score table is printed there too, and is the same."""
    import importlib.util
    import re

    if importlib.util.find_spec("xdist") is None:
        pytest.skip("pytest-xdist is not installed (a dev dependency)")
    sub, plain = wrong_scale_plain_run
    tables = []
    for p in (plain, _plain_pytest(sample_course, sub, "-n", "2")):
        m = re.search(r"=+ graded score =+\n(.*?\ntotal[^\n]*)", p.stdout, re.S)
        assert m, p.stdout[-3000:]
        tables.append(m.group(1))
    assert tables[0] == tables[1]
    score, out_of = map(float, re.search(r"total\s+([\d.]+) / ([\d.]+)", tables[0]).groups())
    assert 0 < score < out_of  # the wrong submission passes some tests and fails others


def test_refs_check_detects_a_changed_solution(sample_course, tmp_path):
    copy = tmp_path / "course"
    shutil.copytree(sample_course, copy)
    assert run_geomlib(copy, "refs", "check").returncode == 0
    ops = copy / "solutions" / "sample" / "ops.py"
    ops.write_text(
        ops.read_text().replace("M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]]) + 1e-3")
    )
    p = run_geomlib(copy, "refs", "check", "--no-grade", check=False)
    assert p.returncode == 1 and "tet-mid" in p.stdout and "no longer reproduces" in p.stdout
    # --no-rerun leaves the outputs to the graded tests (the suite's run), but still checks each
    # case's inputs and parameters against the manifest.
    assert run_geomlib(copy, "refs", "check", "--no-grade", "--no-rerun").returncode == 0
    cases = copy / "tests" / "graded" / "sample" / "cases.py"
    cases.write_text(cases.read_text().replace('params={"s": 3.0}', 'params={"s": 2.0}'))
    p = run_geomlib(copy, "refs", "check", "--no-grade", "--no-rerun", check=False)
    assert p.returncode == 1 and "tet-scale" in p.stdout and "inputs or parameters changed" in p.stdout


def test_a_broken_sandbox_is_reported_as_the_graders_problem(sample_course, tmp_path):
    if __import__("os").geteuid() != 0:
        pytest.skip("switching to a sandbox user needs root")
    r = grade(sample_course, "solutions", env={"GEOMLIB_SANDBOX_USER": "no-such-user-here"})
    validate_results(r)
    pointed = [t for t in _by_name(r).values() if t["max_score"]]
    assert pointed and all(t["output"].startswith("grader problem (not your code)") for t in pointed)
    assert all("'no-such-user-here'" in t["output"] and "JSONDecodeError" not in t["output"] for t in pointed)


def test_student_code_cannot_open_hidden_cases_and_deleting_the_given_validation_gains_nothing(sample_course):
    """One submission, two attacks on scale_about_centroid that leave the grade whole (one grade: its
    start costs 2 s of CPU): it deletes the stub's given validation at the top of the task, and the
    course's still runs (NaN input is rejected with the course's message); and, under Landlock or as
    the sandbox user, it reads nothing of tests/ (hidden cases, references): a leak would raise, and
    show in the messages and the score."""
    from geomlib.grading import landlock

    src = GOOD_OPS.replace(
        '    V, F = check_mesh(V, F, where="scale_about_centroid")\n', "    V = __import__('numpy').asarray(V, float)\n"
    )
    sandboxed = bool(landlock.abi_version()) or not sandbox_user_problem("nobody")
    if sandboxed:  # else nothing keeps tests/ from the worker: the leak check cannot run here
        hidden = sample_course / "tests" / "graded" / "sample" / "cases_hidden.py"
        src = src.replace(
            "    c = V.mean(axis=0)\n",
            f"""    leaked = []
    for p in ({str(hidden)!r}, {str(sample_course / "tests" / "reference")!r}):
        try:
            leaked.append(open(p).read()[:50] if p.endswith(".py") else str(__import__("os").listdir(p)))
        except OSError:
            pass
    if leaked:
        raise RuntimeError("LEAK " + repr(leaked))
    c = V.mean(axis=0)
""",
        )
        assert "LEAK" in src
    assert "check_mesh" not in src.split("def scale_about_centroid")[1].split("def ")[0]
    r = grade(sample_course, str(_submission(None, src)))
    assert "LEAK" not in json.dumps(r)
    assert (
        _by_name(r)["sample › bad input › NaN coordinates are rejected with a message naming the row"]["status"]
        == "passed"
    )
    assert r["score"] == 7


def test_symbolic_links_in_a_submission_are_not_followed(sample_course, tmp_path):
    """A submission whose ops.py links to the course's solution gets nothing from it."""
    sub = _submission(tmp_path, "")
    (sub / "sample" / "ops.py").unlink()
    (sub / "sample" / "ops.py").symlink_to(sample_course / "solutions" / "sample" / "ops.py")
    r = grade(sample_course, str(sub))
    assert r["score"] == 0
