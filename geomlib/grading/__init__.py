"""The course tooling: graded cases, sandboxed student code, references, stubs, scores, release, figures.

The library (every other module of :mod:`geomlib`) never imports this package, and importing it
needs no pytest (``tests/unit/test_layering.py``).

What a graded test module imports::

    from geomlib.grading import Case, checks, graded, reference_tests, expect_close, expect_raises

See ``docs/adding-a-lab.md`` (instructors) and ``docs/autograder.md`` (running the autograder).
"""

import importlib

#: Public names, by the submodule that defines them. Imported on first use, so that importing the
#: grader (a notebook's ``check``, ``geomlib grade``) needs neither pytest nor the plugin until a
#: graded test module is collected.
_EXPORTS = {
    "cases": ("Case", "expect_close", "expect_raises", "graded", "load_cases", "reference_tests", "run_case"),
    "errors": (
        "BadReturn",
        "BudgetSpent",
        "GraderError",
        "GradingFailure",
        "Mismatch",
        "NotImplementedYet",
        "StudentCrash",
        "StudentError",
        "StudentTimeout",
    ),
    "impl": ("course_root", "lab_names", "load_lab", "resolve_impl"),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}
_SUBMODULES = ("checks", "tolerances")


def __getattr__(name: str):
    if name in _WHERE:
        value = getattr(importlib.import_module(f"geomlib.grading.{_WHERE[name]}"), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f"geomlib.grading.{name}")
    else:
        raise AttributeError(f"module 'geomlib.grading' has no attribute {name!r}")
    globals()[name] = value
    return value


def check(lab: str, task: int | None = None, part: str | None = None, **kwargs):
    """Grade one lab, or one task or part of it, and return the report's lines (for notebooks).

    ``check("subdivision", task=2)`` runs what ``geomlib grade --lab subdivision --task 2`` runs;
    see :func:`geomlib.grading.grade.check`.
    """
    # Imported here: the grade module loads the pytest plugin, which pytest must import itself.
    from geomlib.grading.grade import check as _check

    return _check(lab, task, part, **kwargs)


# The public names are the table above (one list to keep), plus check and the two submodules.
__all__ = ["check", *_SUBMODULES, *_WHERE]
