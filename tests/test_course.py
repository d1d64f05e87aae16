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


#: Functions whose float64 results depend on the CPU: numpy runs its own AVX-512 code for the
#: transcendental ufuncs where the CPU has it and glibc's libm (FMA and non-FMA variants) elsewhere,
#: and ``math`` calls the same libm; the products call OpenBLAS (kernels per CPU) or may fuse
#: multiply-adds (einsum). ``geomlib.portable`` has CPU-independent versions.
CPU_DEPENDENT_NUMPY = (
    "sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "sinh", "cosh", "tanh", "arcsinh",
    "arccosh", "arctanh", "exp", "exp2", "expm1", "log", "log2", "log10", "log1p", "power",
    "float_power", "cbrt", "hypot", "dot", "vdot", "inner", "matmul", "tensordot", "einsum",
)  # fmt: skip
CPU_DEPENDENT_MATH = (
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
    "exp", "exp2", "expm1", "log", "log2", "log10", "log1p", "pow", "cbrt",
)  # fmt: skip


def test_case_inputs_call_nothing_whose_bits_depend_on_the_cpu(monkeypatch):
    # tests/solutions/test_deterministic.py compares every case's inputs with an emulated other CPU,
    # but no machine can play one with AVX-512 (numpy's own float64 exp, sin, cos, arctan2, power:
    # how 27 cases' references, built on such a CPU, broke on an AVX2 one). So here the course's
    # own code that builds the inputs of every case of every lab may not call those functions at
    # all. (``@`` and ``x ** 3`` cannot be intercepted: the emulated run catches what BLAS changes.)
    import math

    import numpy as np

    from geomlib.grading.cases import load_cases, load_stored
    from geomlib.grading.registry import graded_package_modules

    for name in graded_package_modules():  # imported afresh: some inputs are built when a case module loads
        monkeypatch.delitem(sys.modules, name)

    course_code = tuple(str(ROOT / d) + os.sep for d in ("geomlib", "tests", "solutions", "labs"))
    calls: dict[str, set[str]] = {}
    case = [""]

    def watch(module, name, label, blas_unless_axis=False):
        f = getattr(module, name)

        def watched(*args, **kwargs):
            frame = sys._getframe(1)
            if frame.f_code.co_filename.startswith(course_code) and not (
                blas_unless_axis and kwargs.get("axis", args[2] if len(args) > 2 else None) is not None
            ):
                where = f"{label} at {Path(frame.f_code.co_filename).relative_to(ROOT)}:{frame.f_lineno}"
                calls.setdefault(where, set()).add(case[0])
            return f(*args, **kwargs)

        monkeypatch.setattr(module, name, watched)

    for name in CPU_DEPENDENT_NUMPY:
        watch(np, name, f"np.{name}")
    for name in CPU_DEPENDENT_MATH:
        watch(math, name, f"math.{name}")
    watch(np.linalg, "norm", "np.linalg.norm without axis (a BLAS dot)", blas_unless_axis=True)
    for lab in LABS:
        for c in load_stored(lab) + load_cases(lab):
            case[0] = f"{lab}/{c.id}"
            c.inputs()
    found = [f"{where} (in {len(ids)} cases, e.g. {sorted(ids)[0]})" for where, ids in sorted(calls.items())]
    assert not found, "case inputs depend on the CPU: use geomlib.portable instead of\n" + "\n".join(found)


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
