"""A release never ships a broken solution (issue 24, part 2), on a copy of the real course.

The instructor's mistake of the issue: one constant of ``solutions/subdivision`` changed (the odd
rule's 3/8 on the edge's ends), then ``refs build``, ``stubs build`` and ``stubs check`` all
succeed — the rebuilt references follow the solution — yet the hand-written graded tests, which
take their weights from the handout's rule, fail. ``release`` grades the solutions (public and
hidden tests) and refuses, naming those tests; ``refs check`` names them too.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from .course import run_geomlib

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
LAB = "subdivision"
ODD_RULE = "np.tile([3 / 8, 3 / 8, 1 / 8, 1 / 8], len(inner))"


def _copy_of_the_course(lab: str) -> Path:
    """The real course's files that grade and release ``lab``, in a folder the sandbox user can read."""
    base = Path(tempfile.mkdtemp(prefix="geomlib-course-copy-"))
    root = base / "course"
    ignore = shutil.ignore_patterns("__pycache__", ".pytest_cache")
    for rel in ("geomlib", f"solutions/{lab}", f"labs/{lab}", f"tests/graded/{lab}", f"tests/reference/{lab}"):
        shutil.copytree(ROOT / rel, root / rel, ignore=ignore)
    for rel in ("pyproject.toml", "uv.lock", "tests/conftest.py", "docs/students.md", f"notebooks/{lab}.ipynb"):
        if (ROOT / rel).is_file():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, root / rel)
    for f in (ROOT / "tests" / "graded").glob("*.py"):  # the graded tests' shared helpers
        shutil.copy2(f, root / "tests" / "graded" / f.name)
    for p in [base, *base.rglob("*")]:
        if not p.is_symlink():
            os.chmod(p, 0o755 if p.is_dir() else 0o644)
    return root


@pytest.fixture(scope="module")
def broken_course():
    root = _copy_of_the_course(LAB)
    loop = root / "solutions" / LAB / "loop.py"
    text = loop.read_text()
    assert text.count(ODD_RULE) == 1, "the odd rule's line moved: update ODD_RULE"
    loop.write_text(text.replace(ODD_RULE, ODD_RULE.replace("[3 / 8, 3 / 8,", "[0.3, 0.45,")))
    # What the instructor ran, all successful: the references follow the changed solution.
    run_geomlib(root, "refs", "build", "--lab", LAB, timeout=900)
    run_geomlib(root, "stubs", "build")
    run_geomlib(root, "stubs", "check")
    yield root
    shutil.rmtree(root.parent, ignore_errors=True)


def test_release_refuses_a_solution_that_fails_its_own_tests(broken_course):
    out = broken_course.parent / "dist"
    p = run_geomlib(broken_course, "release", str(out), "--lab", LAB, check=False, timeout=900)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "a release would ship a broken solution" in p.stderr, p.stderr
    failing = [ln.strip() for ln in p.stderr.splitlines() if ln.startswith("    ")]
    # the hand-written tests of the odd rule (their weights are the handout's 3/8 and 1/8), by name
    assert failing and all("loop_odd_matrix" in ln and "3/8" in ln for ln in failing), p.stderr
    assert any(ln.startswith("odd vertices › tetrahedron") for ln in failing), p.stderr
    assert "Traceback" not in p.stderr
    assert not out.exists() or not any(out.glob("*.zip"))  # nothing released


def test_release_no_check_only_packages(broken_course):
    out = broken_course.parent / "dist-no-check"
    run_geomlib(broken_course, "release", str(out), "--lab", LAB, "--no-check", timeout=900)
    assert (out / f"autograder-{LAB}.zip").is_file()


def test_refs_check_names_the_tests_the_solution_fails(broken_course):
    # --no-rerun: the references were just rebuilt from this solution, so re-running its cases
    # reproduces them by construction; the grading of the solutions (what names the failing
    # tests) runs, and compares the solution with every reference, public and hidden.
    p = run_geomlib(broken_course, "refs", "check", "--lab", LAB, "--no-rerun", check=False, timeout=900)
    assert p.returncode == 1, p.stdout + p.stderr
    fails = [ln for ln in p.stdout.splitlines() if ln.startswith("FAIL ")]
    assert fails and all("loop_odd_matrix" in ln for ln in fails), p.stdout
    assert any(ln.startswith(f"FAIL {LAB}/odd vertices › tetrahedron") for ln in fails), p.stdout
    assert all("the solution fails this graded test" in ln for ln in fails), p.stdout
    assert f"{LAB}: the solutions score" in p.stdout
