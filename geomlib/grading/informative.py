"""Which stored outputs of a graded case a submission could match without computing anything.

A case earns its points only if its reference output is *informative*: a submission that returns
zeros, a constant, or one of the case's own input arrays unchanged (a mesh handed back as it came)
must fail the case's check. This module forges such submissions and runs them through the same
screening and comparison as a graded call (:func:`geomlib.grading.cases.run_case`), so a tolerance
counts: an output within ``atol`` of a constant is as uninformative as an exactly constant one.

``tests/framework/test_informative_references.py`` runs it over every lab's references. A case meant
to be trivial says why (``Case(trivial="...")``) and carries no points; an output that is
uninformative in an otherwise informative case says why in ``Case(trivial_outputs={name: "..."})``.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np

from geomlib.grading.cases import Case, _screen_outputs, load_reference
from geomlib.grading.checks import Context
from geomlib.grading.errors import GradingFailure

__all__ = ["Forgery", "input_arrays", "forgeries", "uninformative_outputs", "forged_case", "problems"]

#: Joint forgeries tried per case at most (the product of the per-output candidates).
MAX_JOINT = 256


@dataclass
class Forgery:
    """A stand-in for one output: what it is (``"zeros"``, ``"constant 0.5"``, ``"input V"``) and its value."""

    what: str
    value: np.ndarray


def input_arrays(value, name: str = "") -> list[tuple[str, np.ndarray]]:
    """Every numeric array in a case's inputs (dicts, lists, tuples and dataclasses walked), with its path."""
    out: list[tuple[str, np.ndarray]] = []

    def walk(v, path):
        if isinstance(v, np.ndarray | np.generic):
            a = np.asarray(v)
            if a.dtype.kind in "biuf":
                out.append((path, a))
        elif isinstance(v, dict):
            for k, x in v.items():
                walk(x, f"{path}.{k}" if path else str(k))
        elif isinstance(v, list | tuple):
            if v and all(isinstance(x, bool | int | float | np.number) for x in v):
                out.append((path, np.asarray(v)))
            else:
                for i, x in enumerate(v):
                    walk(x, f"{path}[{i}]")
        elif dataclasses.is_dataclass(v) and not isinstance(v, type):
            for f in dataclasses.fields(v):
                walk(getattr(v, f.name), f"{path}.{f.name}")
        elif hasattr(v, "toarray") and hasattr(v, "shape"):
            out.append((path, np.asarray(v.toarray())))

    walk(value, name)
    return out


def forgeries(expected: np.ndarray, inputs: list[tuple[str, np.ndarray]]) -> list[Forgery]:
    """Outputs a submission can return without computing: zeros, the best constant, an input of that shape."""
    e = np.asarray(expected)
    out = [Forgery("zeros", np.zeros(e.shape, e.dtype))]
    if e.size > 1 and e.dtype.kind == "b":
        out.append(Forgery("all True", np.ones(e.shape, bool)))
    elif e.size > 1 and e.dtype.kind in "iuf":
        finite = e[np.isfinite(e)] if e.dtype.kind == "f" else e
        if finite.size:
            # the constant closest to every entry in the max norm, so a tolerance check accepts it if any does
            mid = (float(finite.min()) + float(finite.max())) / 2
            values = {mid} if e.dtype.kind == "f" else {np.floor(mid), np.ceil(mid)}
            out += [Forgery(f"constant {v:.6g}", np.full(e.shape, v, e.dtype)) for v in sorted(values) if v != 0]
    out += [Forgery(f"input {name}", a) for name, a in inputs if a.shape == e.shape]
    return out


def _passes(case: Case, expected: dict, got: dict) -> bool:
    ctx = Context(label=case.label, case_id=case.id)
    try:
        _screen_outputs(expected, got, ctx)
        case.check(expected, got, ctx)
    except GradingFailure:
        return False
    return True


def compared(case: Case, expected: dict, name: str) -> bool:
    """Whether the case's check looks at output ``name`` at all (a grossly wrong value fails it).

    Some checks compare a subset on purpose (the face index of a closest point is not compared,
    since ties may pick either face): such an output is not graded, so it cannot be uninformative.
    """
    e = np.asarray(expected[name])
    if e.dtype.kind == "b":
        wrong = ~e
    elif e.dtype.kind in "iu":
        wrong = (e.astype(np.int64) + 101).astype(e.dtype)  # wraps for uint8, still differs everywhere
    else:
        wrong = e + 1000.0
    return not _passes(case, expected, {**expected, name: wrong})


def uninformative_outputs(case: Case, expected: dict, inputs: dict) -> dict[str, str]:
    """``{output: forgery}`` for each compared output that a forgery matches while the other outputs are right."""
    arrays = input_arrays(inputs)
    found = {}
    for name, e in expected.items():
        if not compared(case, expected, name):
            continue
        for f in forgeries(e, arrays):
            if _passes(case, expected, {**expected, name: f.value}):
                found[name] = f.what
                break
    return found


def forged_case(case: Case, expected: dict, inputs: dict) -> dict[str, str] | None:
    """A forgery of *every* output at once that passes the case's check (``{output: forgery}``), or None.

    Such a case gives its points to a submission that computes nothing.
    """
    arrays = input_arrays(inputs)
    options = [[(name, f) for f in forgeries(e, arrays)] for name, e in expected.items()]
    for combo in itertools.islice(itertools.product(*options), MAX_JOINT):
        if _passes(case, expected, {name: f.value for name, f in combo}):
            return {name: f.what for name, f in combo}
    return None


def problems(lab: str, case: Case) -> list[str]:
    """What is wrong with ``case``'s declaration given its stored reference (empty: nothing).

    * every output is forged at once and the case does not say ``trivial="why"``, or it does and
      carries points;
    * one output is forged (the others right) and ``trivial_outputs`` does not name it with a reason;
    * ``trivial`` or ``trivial_outputs`` is declared where nothing is forged (a stale declaration).
    """
    expected = load_reference(lab, case)
    inputs = {**case.inputs(), **case.params}
    out = []
    whole = forged_case(case, expected, inputs)
    if whole is not None and not case.trivial:
        forged = ", ".join(f"{k} = {v}" for k, v in whole.items())
        out.append(
            f"{lab}/{case.id} ({case.points:g} points): a submission returning {forged} passes it; "
            f"change its inputs so the answer says something, or declare trivial='why' with points=0"
        )
        return out
    if case.trivial and case.points:
        out.append(f"{lab}/{case.id}: declared trivial ({case.trivial}) but carries {case.points:g} points")
    if case.trivial and whole is None:
        out.append(f"{lab}/{case.id}: declared trivial ({case.trivial}) but no forgery passes it: drop trivial=")
    if case.trivial:
        return out
    single = uninformative_outputs(case, expected, inputs)
    for name, what in single.items():
        if name not in case.trivial_outputs:
            out.append(
                f"{lab}/{case.id}: output {name} passes as {what}; make it informative or say why in "
                f"trivial_outputs={{{name!r}: 'why'}}"
            )
    for name in case.trivial_outputs:
        if name not in single:
            out.append(f"{lab}/{case.id}: trivial_outputs names {name!r}, which is informative: drop the declaration")
    return out
