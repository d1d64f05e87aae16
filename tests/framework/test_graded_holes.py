"""Implementations that do nothing score nothing (issue 24's holes in the remeshing tests).

The graded remeshing tests are run here in-process on stand-in labs that change nothing: a local
operation returning its input (the hidden chains of split, flip and collapse checked only the
invariants an unchanged mesh keeps: 10 of the part's 17 points), and an ``isotropic_remesh``
returning its input (the adaptive checks never compared edge lengths with the target).
"""

from __future__ import annotations

import importlib
import sys
import types

import pytest

from geomlib.grading import impl
from geomlib.grading.cases import load_cases
from geomlib.grading.checks import Context
from geomlib.grading.errors import GradingFailure, Mismatch

if str(impl.tests_dir()) not in sys.path:
    sys.path.insert(0, str(impl.tests_dir()))
hidden = importlib.import_module("graded.remeshing.test_remeshing_hidden")


def _unchanged(V, H, edge, **_):
    return V, H


@pytest.mark.parametrize(
    "op, test",
    [
        ("split_edge", hidden.test_hidden_split_chain),
        ("flip_edge", hidden.test_hidden_flip_chain),
        ("collapse_edge", hidden.test_hidden_collapse_chain),
    ],
)
def test_a_local_operation_that_does_nothing_fails_its_hidden_chain(op, test):
    with pytest.raises(Mismatch) as e:
        test(types.SimpleNamespace(**{op: _unchanged}))
    assert f"{op} on " in str(e.value) and "operation 1:" in str(e.value), str(e.value)


REMESH_CASES = [c for c in load_cases("remeshing") if c.function == "isotropic_remesh"]


@pytest.mark.parametrize("case", REMESH_CASES, ids=[c.id for c in REMESH_CASES])
def test_isotropic_remesh_returning_its_input_fails_every_case(case):
    d = case.inputs()
    with pytest.raises(GradingFailure) as e:
        case.check({}, {"V": d["V"], "F": d["F"]}, Context(label=case.id, lab="remeshing", case_id=case.id))
    assert "length" in str(e.value), str(e.value)
