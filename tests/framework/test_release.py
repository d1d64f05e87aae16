"""`geomlib release`: the student bundle leaks nothing and grades its stubs to zero; the autograder zip works."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from geomlib.grading.results import validate_results

from .course import run_geomlib, sandbox_python


@pytest.fixture(scope="module")
def release(sample_course) -> Path:
    out = Path(tempfile.mkdtemp(prefix="geomlib-release-"))
    out.chmod(0o755)
    run_geomlib(sample_course, "release", str(out))
    return out


def test_student_bundle_has_no_solutions_and_no_hidden_material(release, sample_course):
    student = release / "student"
    files = [p.relative_to(student).as_posix() for p in student.rglob("*") if p.is_file()]
    assert "labs/sample/ops.py" in files and "tests/graded/sample/test_sample.py" in files
    assert "tests/reference/sample/tet-scale.npz" in files
    assert not any(f.startswith("solutions/") for f in files)
    assert not any("hidden" in f for f in files), [f for f in files if "hidden" in f]
    assert not any(f.startswith(("tests/framework", "tests/unit", "tests/solutions")) for f in files)
    # No line from inside a solution block appears anywhere in the bundle.
    secret = "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])"
    assert secret in (sample_course / "solutions" / "sample" / "ops.py").read_text()
    for p in student.rglob("*"):
        if p.is_file() and p.suffix in (".py", ".md", ".ipynb", ".txt", ".toml"):
            assert secret not in p.read_text(), p
    with zipfile.ZipFile(release / "student.zip") as z:
        assert not any("solutions/" in n or "hidden" in n for n in z.namelist())


def test_student_bundle_grades_its_stubs_to_zero_without_errors(release):
    student = release / "student"
    env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_ROOT"}
    env.update(PYTHONPATH=str(student), GEOMLIB_NO_FEEDBACK_PICTURES="1")
    p = subprocess.run(
        [sys.executable, "-m", "geomlib.cli", "grade", "--results", "r.json"],
        cwd=student,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    r = json.loads((student / "r.json").read_text())
    validate_results(r)
    assert r["score"] == 0 and r["tests"]
    assert all(
        t["status"] == "failed" and "not implemented yet" in t["output"] for t in r["tests"] if t["max_score"] > 0
    )
    assert "geomlib-sample" not in p.stdout  # it graded its own copy, not the instructors' course


def _autograder(release: Path, submission_labs: Path | None) -> dict:
    root = Path(tempfile.mkdtemp(prefix="geomlib-autograder-"))
    root.chmod(0o755)
    with zipfile.ZipFile(release / "autograder.zip") as z:
        z.extractall(root / "source")
        names = z.namelist()
    assert "setup.sh" in names and "run_autograder" in names
    assert any("hidden" in n for n in names)  # the autograder does get the hidden tests
    assert not any(n.startswith("solutions/") for n in names)
    (root / "submission").mkdir()
    if submission_labs is not None:
        import shutil

        shutil.copytree(submission_labs, root / "submission" / "labs" / submission_labs.name)
    hidden = root / "source" / "tests" / "reference" / "sample" / "hidden"
    hidden.chmod(0o700)  # as setup.sh does
    run = root / "source" / "run_autograder"
    run.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_ROOT"}
    env.update(GEOMLIB_AUTOGRADER_ROOT=str(root), GEOMLIB_PYTHON=sys.executable, PYTHONPATH=str(root / "source"))
    python = sandbox_python("nobody")
    if python is None:  # not root, or no Python `nobody` can read: grade without the user drop
        env["GEOMLIB_SANDBOX_USER"] = ""
    elif python[1]:  # the system's Python with this environment's packages (as on Gradescope)
        env.update(GEOMLIB_PYTHON=python[0], PYTHONPATH=os.pathsep.join([env["PYTHONPATH"], python[1]["PYTHONPATH"]]))
    p = subprocess.run(["bash", str(run)], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    return json.loads((root / "results" / "results.json").read_text())


def test_run_autograder_grades_a_correct_submission_with_hidden_tests(release, sample_course):
    r = _autograder(release, sample_course / "solutions" / "sample")
    validate_results(r)
    assert r["score"] == 7  # includes the hidden case
    assert any(t["visibility"] == "hidden" for t in r["tests"])


def test_run_autograder_on_an_empty_submission_scores_zero(release):
    r = _autograder(release, None)
    validate_results(r)
    assert r["score"] == 0 and r["tests"]
