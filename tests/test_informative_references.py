"""Every graded case's stored output is informative (issue 23, item 1).

A submission that computes nothing — zeros, one constant, or one of the case's own input arrays
handed back unchanged (a mesh returned as it came) — must fail every case that carries points. The
forged submissions go through the case's own screening and check (:mod:`geomlib.grading.informative`),
so an output within tolerance of a constant counts as constant. A case meant to be trivial says why
(``Case(trivial="why")``) and carries no points; an uninformative output of an otherwise informative
case says why in ``Case(trivial_outputs={name: "why"})``.

Checked for every lab's public and hidden references, loaded as the graded tests load them
(:func:`geomlib.grading.cases.load_cases`, :func:`~geomlib.grading.cases.load_reference`); the
probe-only cases of ``diagnose.py`` are never graded and are left out.
"""

from __future__ import annotations

import numpy as np
import pytest

from geomlib.grading import checks, impl, informative
from geomlib.grading.cases import Case, load_cases


@pytest.mark.parametrize("lab", impl.lab_names())
def test_graded_references_are_informative(lab):
    cases = load_cases(lab, hidden=True, probes=False)
    assert cases, f"{lab}: no graded cases found"
    found = [p for case in cases for p in informative.problems(lab, case)]
    assert not found, f"{lab}: {len(found)} uninformative graded case(s):\n  " + "\n  ".join(found)


def _case(**kw) -> Case:
    base = dict(id="c", function="f", inputs=lambda: {"x": np.arange(5.0)}, check=checks.Allclose(atol=1e-9), part="p")
    return Case(**{**base, **kw})


def test_forgeries_catch_zeros_constants_and_echoed_inputs():
    inputs = {"x": np.arange(5.0), "scene": {"planes": np.ones((1, 4))}}
    zeros = _case()
    assert informative.forged_case(zeros, {"result": np.zeros(5)}, inputs) == {"result": "zeros"}
    near_constant = _case(check=checks.Allclose(atol=0.1))
    assert informative.forged_case(near_constant, {"result": np.array([0.5, 0.6, 0.55, 0.5, 0.6])}, inputs) == {
        "result": "constant 0.55"
    }
    assert informative.forged_case(zeros, {"result": np.arange(5.0)}, inputs) == {"result": "input x"}
    assert informative.forged_case(zeros, {"result": np.array([0.0, 1.0, 0.0, 2.0, 0.5])}, inputs) is None
    # one echoed output among informative ones: the case still needs the others, the output is named
    two = _case(outputs=("a", "b"))
    expected = {"a": np.arange(5.0), "b": np.array([3.0, 1.0, 4.0, 1.0, 5.0])}
    assert informative.forged_case(two, expected, inputs) is None
    assert informative.uninformative_outputs(two, expected, inputs) == {"a": "input x"}


def test_a_trivial_case_carries_no_points():
    with pytest.raises(ValueError, match="carries no points"):
        _case(trivial="an empty mesh stays empty", points=1)
    assert _case(trivial="an empty mesh stays empty", points=0).trivial


def test_a_wrong_scalar_output_fails_with_a_message():
    """Found by the forgeries: a wrong 0-d output (vdm's grad_sq) crashed the comparison with IndexError."""
    from geomlib.grading.checks import Context, compare_arrays
    from geomlib.grading.errors import Mismatch

    with pytest.raises(Mismatch, match=r"grad_sq\[0\] expected 2, got 0"):
        compare_arrays("grad_sq", np.array(2.0), np.array(0.0), Context(label="f"), atol=1e-10)


def test_a_degenerate_submitted_mesh_fails_a_custom_check_with_a_message():
    """Found by the forgeries: a zero-area submitted mesh made a lab's own check raise MeshError (a grader error)."""
    from geomlib import geometry
    from geomlib.grading.checks import Context
    from geomlib.grading.errors import Mismatch

    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]])
    check = checks.Custom(lambda e, g, ctx: geometry.mesh_distance(e["V"], e["F"], g["V"], g["F"]) and None)
    with pytest.raises(Mismatch, match="not a valid mesh.*zero total area"):
        check({"V": V, "F": F}, {"V": np.zeros((3, 3)), "F": F}, Context(label="f"))
