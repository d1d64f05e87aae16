"""The checks shared by the labs' graded tests (``tests/graded/common.py``) fail when they should."""

from __future__ import annotations

import importlib
import sys

import numpy as np
import pytest

from geomlib.grading import impl
from geomlib.grading.checks import Context
from geomlib.grading.errors import Mismatch

if str(impl.tests_dir()) not in sys.path:
    sys.path.insert(0, str(impl.tests_dir()))
common = importlib.import_module("graded.common")


def _run(check, expected, got):
    check({check.output: np.asarray(expected)}, {check.output: got}, Context(label="case"))


def test_same_rows_takes_any_row_order():
    _run(common.SameRows("F"), [[0, 1, 2], [1, 2, 3]], [[1, 2, 3], [0, 1, 2]])
    _run(common.SameRows("corners"), [3, 5, 7], [7, 3, 5])


def test_same_rows_names_a_missing_and_an_extra_row_in_the_given_words():
    check = common.SameRows("F", missing="faces missing", extra="faces kept")
    with pytest.raises(Mismatch, match=r"1 faces missing \(e.g. \(1, 2, 3\)\); 1 faces kept \(e.g. \(2, 1, 3\)\)"):
        _run(check, [[0, 1, 2], [1, 2, 3]], [[0, 1, 2], [2, 1, 3]])


def test_same_rows_compares_unordered_rows_only_when_asked():
    _run(common.SameRows("edges", sort_within=True), [[0, 1], [1, 2]], [[2, 1], [1, 0]])
    with pytest.raises(Mismatch):
        _run(common.SameRows("edges"), [[0, 1], [1, 2]], [[2, 1], [1, 0]])


def test_same_rows_rejects_other_shapes_and_non_integer_rows():
    with pytest.raises(Mismatch, match=r"shape \(3,\), expected \(k, 3\)"):
        _run(common.SameRows("F"), [[0, 1, 2]], [0, 1, 2])
    with pytest.raises(Mismatch, match="1 unexpected entries"):
        _run(common.SameRows("edges", sort_within=True), [[0, 1], [1, 2]], [[0, 1], [1.5, 2]])


def test_expect_true_names_the_label():
    common.expect_true("split_edge", True, "never shown")
    with pytest.raises(Mismatch, match="split_edge: 3 faces"):
        common.expect_true("split_edge", False, "3 faces")


# ------------------------------------------------------------------ hidden cases, one loader
@pytest.fixture
def graded_package(tmp_path, monkeypatch):
    """Makes a graded package ``<name>.<lab>`` (any name, as pytest may import it) in ``tmp_path``,
    with ``cases_hidden.py`` holding ``hidden`` (none if None), imports it and returns its name;
    its modules are forgotten after the test."""
    made = []

    def make(name: str, lab: str, hidden: str | None) -> str:
        pkg = tmp_path / name / lab
        pkg.mkdir(parents=True)
        (tmp_path / name / "__init__.py").write_text("")
        (pkg / "__init__.py").write_text("")
        if hidden is not None:
            (pkg / "cases_hidden.py").write_text(hidden)
        monkeypatch.syspath_prepend(str(tmp_path))
        made.append(name)
        importlib.import_module(f"{name}.{lab}")
        return f"{name}.{lab}"

    yield make
    for m in [m for m in sys.modules if m.split(".")[0] in made]:
        del sys.modules[m]


def test_hidden_cases_load_from_the_test_modules_own_package_under_any_name(graded_package):
    """The grader's package name is not the course's ``graded``: the cases come from the package the
    test was imported under (planted fault: ignoring ``package`` and loading the course's
    ``graded.maps.cases_hidden`` gives the real course's cases, not these two)."""
    from geomlib.grading.registry import hidden_cases

    package = graded_package("graded_elsewhere", "maps", "CASES = ['h1', 'h2']\n")
    assert hidden_cases("maps", package=package) == ("h1", "h2")
    with pytest.raises(ValueError, match="not lab 'denoise'"):
        hidden_cases("denoise", package=package)


def test_no_hidden_file_means_no_hidden_cases(graded_package):
    """A student's bundle has no ``cases_hidden.py``: none, not an error (planted fault: importing
    without looking for the file raises ModuleNotFoundError)."""
    from geomlib.grading.registry import hidden_cases

    assert hidden_cases("maps", package=graded_package("graded_bundle", "maps", None)) == ()


def test_an_import_error_inside_the_hidden_cases_is_raised(graded_package):
    """A broken ``cases_hidden.py`` (it imports a module that does not exist) is the course's error and
    is raised, not read as "no hidden cases" (planted fault: catching every ModuleNotFoundError)."""
    from geomlib.grading.registry import hidden_cases

    broken = "import geomlib_no_such_module_for_this_test\nCASES = ['h1']\n"
    package = graded_package("graded_broken", "maps", broken)
    with pytest.raises(ModuleNotFoundError, match="geomlib_no_such_module_for_this_test"):
        hidden_cases("maps", package=package)
