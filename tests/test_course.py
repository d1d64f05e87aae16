"""Course-wide invariants: stubs are fresh, references reproduce, lint is clean.

That every lab's stubs score zero with no error but "not implemented yet" is checked where the
stubs are graded once: the notebooks' check() cells on the stubs (tests/test_notebooks.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from geomlib.grading import impl, stubs
from geomlib.grading.course import course

ROOT = Path(__file__).resolve().parents[1]
LABS = course(ROOT).solution_labs


def _cli(*args: str, timeout: float = 600, env: dict | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **(env or {})}
    env.pop("GEOMLIB_ROOT", None)
    return subprocess.run(
        [sys.executable, "-m", "geomlib.cli", *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout
    )


def test_labs_are_generated_from_solutions():
    problems = stubs.check()
    assert not problems, "labs/ is stale, run `geomlib stubs build`:\n" + "\n".join(problems)


@pytest.mark.slow
def test_solutions_reproduce_the_stored_references():
    # The suite grades the solutions itself: tests/graded runs every case, public and hidden, and
    # compares its output with the stored reference by the case's own check. So this run neither
    # grades (--no-grade) nor re-runs the cases (--no-rerun); it checks what the graded tests do
    # not: each case's inputs and parameters are those the references were built from, the stored
    # inputs are reproduced, and no reference file is missing or stale.
    p = _cli("refs", "check", "--no-grade", "--no-rerun")
    assert p.returncode == 0, p.stdout[-4000:] + p.stderr[-2000:]


def test_every_lab_is_complete():
    for lab in LABS:
        for rel in (
            f"labs/{lab}/__init__.py",
            f"labs/{lab}/README.md",
            f"solutions/{lab}/figures.py",
            f"tests/graded/{lab}/__init__.py",
            f"tests/graded/{lab}/cases.py",
            f"tests/solutions/test_{lab}.py",
            f"notebooks/{lab}.ipynb",
            f"bench/{lab}.py",
        ):
            assert (ROOT / rel).is_file(), f"lab {lab!r} lacks {rel}"


def test_reference_data_is_small():
    total = sum(p.stat().st_size for p in impl.reference_dir().rglob("*") if p.is_file())
    assert total <= 25 * 2**20, f"tests/reference holds {total / 2**20:.1f} MiB (limit 25 MiB)"


def test_ruff_lint_and_format():
    for args in (["check", "."], ["format", "--check", "."]):
        p = subprocess.run([sys.executable, "-m", "ruff", *args], cwd=ROOT, capture_output=True, text=True)
        assert p.returncode == 0, f"ruff {' '.join(args)}:\n{p.stdout[-3000:]}{p.stderr[-1000:]}"
