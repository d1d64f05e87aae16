"""The grading framework: graded cases, sandboxed student code, references, stubs, scores, release.

What a graded test module imports::

    from geomlib.grading import Case, checks, graded, reference_tests, expect_close, expect_raises

See ``docs/adding-a-lab.md`` (instructors) and ``docs/autograder.md`` (running the autograder).
"""

from geomlib.grading import checks, tolerances
from geomlib.grading.cases import Case, expect_close, expect_raises, graded, load_cases, reference_tests, run_case
from geomlib.grading.errors import (
    BadReturn,
    GradingFailure,
    Mismatch,
    NotImplementedYet,
    StudentCrash,
    StudentError,
    StudentTimeout,
)
from geomlib.grading.impl import course_root, lab_names, load_lab, resolve_impl

__all__ = [
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
]
