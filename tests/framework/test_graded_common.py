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
