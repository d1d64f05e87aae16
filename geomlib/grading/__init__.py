"""The grading framework: graded cases, sandboxed student code, references, stubs, scores, release.

What a graded test module imports::

    from geomlib.grading import Case, checks, graded, reference_tests, expect_close, expect_raises

See ``docs/adding-a-lab.md`` (instructors) and ``docs/autograder.md`` (running the autograder).
"""

from geomlib.grading import checks, tolerances
from geomlib.grading.cases import Case, expect_close, expect_raises, graded, load_cases, reference_tests, run_case
from geomlib.grading.errors import (
    BadReturn,
    BudgetSpent,
    GraderError,
    GradingFailure,
    Mismatch,
    NotImplementedYet,
    StudentCrash,
    StudentError,
    StudentTimeout,
)
from geomlib.grading.impl import course_root, lab_names, load_lab, resolve_impl


def check(lab: str, task: int | None = None, part: str | None = None, **kwargs):
    """Grade one lab, or one task or part of it, and return the report's lines (for notebooks).

    ``check("subdivision", task=2)`` runs what ``geomlib grade --lab subdivision --task 2`` runs;
    see :func:`geomlib.grading.grade.check`.
    """
    # Imported here: the grade module loads the pytest plugin, which pytest must import itself.
    from geomlib.grading.grade import check as _check

    return _check(lab, task, part, **kwargs)


__all__ = [
    "check",
    "Case",
    "checks",
    "tolerances",
    "graded",
    "reference_tests",
    "run_case",
    "expect_close",
    "expect_raises",
    "load_cases",
    "load_lab",
    "lab_names",
    "course_root",
    "resolve_impl",
    "GradingFailure",
    "Mismatch",
    "NotImplementedYet",
    "StudentError",
    "StudentCrash",
    "StudentTimeout",
    "BadReturn",
    "BudgetSpent",
    "GraderError",
]
