"""A case that mixes the rows of two tasks names the task of the rows that differ.

``odd-height-field`` is a boundary-rules case (Task 4) of ``loop_odd_matrix``, but most of its rows
are interior edges (Task 1). A Task 1 bug (the odd weights 3/8 and 1/8 swapped) must be reported as
Task 1 with the odd-vertex hint, not as "Task 4 · boundary rules" with the boundary hint.
"""

from __future__ import annotations

import shutil

import pytest

from geomlib.grading.cases import load_cases, run_case
from geomlib.grading.errors import Mismatch
from geomlib.grading.grade import report_lines
from geomlib.grading.results import Record
from geomlib.grading.sandbox import LabProxy

from .course import appended, planted_solution

SWAPPED_ODD_WEIGHTS = """
_true_loop_odd_matrix = loop_odd_matrix

def loop_odd_matrix(V, F, *, topo=None):
    S = _true_loop_odd_matrix(V, F, topo=topo).tocsr(copy=True)
    d = S.data.copy()
    S.data = np.where(np.isclose(d, 3 / 8), 1 / 8, np.where(np.isclose(d, 1 / 8), 3 / 8, d))
    return S
"""

HALVED_BOUNDARY_ODD_WEIGHTS = """
_true_loop_odd_matrix = loop_odd_matrix

def loop_odd_matrix(V, F, *, topo=None):
    S = _true_loop_odd_matrix(V, F, topo=topo).tocsr(copy=True)
    S.data = np.where(np.isclose(S.data, 1 / 2), 1 / 4, S.data)
    return S
"""


def _message(source: str, case_id: str) -> str:
    dest = planted_solution("subdivision", appended("loop", source, "tests/framework/test_rows_task.py"))
    base = dest.parent
    case = next(c for c in load_cases("subdivision") if c.id == case_id)
    try:
        with pytest.raises(Mismatch) as e:
            run_case(LabProxy("subdivision", dest), case, feedback_dir=None)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return str(e.value)


def _line(msg: str) -> str:
    r = Record("n", "subdivision", "boundary rules", "t", 1, "visible", False, msg, 0.0)
    return next(ln for ln in report_lines([r], feedback_dir=None, tasks={"n": (4,)}) if "✗" in ln)


def test_interior_rows_of_a_boundary_case_name_task_1_and_its_hint():
    from graded.subdivision.cases import BOUNDARY_HINT, ODD_HINT

    msg = _message(SWAPPED_ODD_WEIGHTS, "odd-height-field")
    assert "belong to Task 1 (odd vertices)" in msg and "interior edges" in msg, msg
    assert ODD_HINT in msg and BOUNDARY_HINT not in msg, msg
    line = _line(msg)
    assert line.startswith("  ✗ Task 1 · odd vertices: "), line
    assert "Task 4" not in line.split(":")[0], line


def test_boundary_rows_of_a_boundary_case_keep_task_4():
    from graded.subdivision.cases import BOUNDARY_HINT

    msg = _message(HALVED_BOUNDARY_ODD_WEIGHTS, "odd-height-field")
    assert "belong to Task" not in msg and BOUNDARY_HINT in msg, msg
    assert _line(msg).startswith("  ✗ Task 4 · boundary rules: ")
