"""Graded cases declared once, and the helpers graded tests are written with.

See ``docs/adding-a-lab.md`` for how a lab uses them.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geomlib.grading import tolerances as tol
from geomlib.grading.checks import Context, compare_arrays, nonfinite_problem
from geomlib.grading.errors import BadReturn, Mismatch, StudentError
from geomlib.grading.registry import (  # re-exported: graded tests and the tooling import them from here
    hidden_cases,
    load_cases,
    load_reference,
    load_stored,
    reference_path,
    stored_input,
    stored_path,
)

__all__ = [
    "Case",
    "graded",
    "reference_tests",
    "run_case",
    "expect_close",
    "expect_raises",
    "load_cases",
    "hidden_cases",
    "reference_path",
    "load_reference",
    "inputs_digest",
    "stored_input",
    "stored_path",
    "load_stored",
]

VISIBILITIES = ("visible", "after_due_date", "hidden", "after_published")


@dataclass
class Case:
    """One graded call with a stored reference output.

    Attributes
    ----------
    id : str
        Unique within the lab; names the reference file.
    function : str
        Lab function, called as ``function(**inputs(), **params)``.
    inputs : callable
        Returns a dict of arguments (deterministic: seeded, built from ``geomlib.datasets``).
    params : dict
        JSON-able extra keyword arguments (recorded in the manifest).
    outputs : tuple of str
        Names of the returned values (one name: the function returns a single value); for a
        function that returns a dataclass, names of its fields.
    check : callable
        A comparison from :mod:`geomlib.grading.checks`.
    part : str
        Grading part this case counts towards.
    points : float
    visibility : str
        ``visible``, ``after_due_date`` or ``hidden`` (Gradescope's meanings).
    hint : str, optional
        Appended to the failure message.
    timeout : float, optional
        Seconds allowed for the call (default :data:`~geomlib.grading.tolerances.TIME_LIMIT_S`).
    trivial : str, optional
        Why this case is meant to be matched by a submission that computes nothing (zeros, a
        constant, an input returned unchanged); such a case carries no points. Every other case's
        reference must be informative (:mod:`geomlib.grading.informative`).
    trivial_outputs : dict, optional
        ``{output: why}`` for outputs that are uninformative in an otherwise informative case
        (e.g. a handedness that is +1 on a mesh without mirrored UVs).
    tasks : tuple of int, optional
        Every task the case needs, where its part and function do not say them all (a parameter
        that runs a later task: ``adaptive=True``); ``--task N`` selects it under the latest
        (:func:`geomlib.grading.tasks.test_tasks`).
    """

    id: str
    function: str
    inputs: Callable[[], dict]
    check: Callable
    part: str
    points: float = 1.0
    params: dict = field(default_factory=dict)
    outputs: tuple = ("result",)
    visibility: str = "visible"
    hint: str | None = None
    timeout: float | None = None
    trivial: str | None = None
    trivial_outputs: dict = field(default_factory=dict)
    tasks: tuple = ()

    def __post_init__(self):
        if self.visibility not in VISIBILITIES:
            raise ValueError(f"case {self.id}: visibility must be one of {VISIBILITIES}")
        if self.trivial is not None and self.points:
            raise ValueError(
                f"case {self.id}: a trivial case ({self.trivial}) carries no points, got points={self.points}"
            )
        if isinstance(self.outputs, str):
            self.outputs = (self.outputs,)
        if not re.fullmatch(r"[A-Za-z0-9_.\-]+", self.id):
            raise ValueError(f"case id {self.id!r}: use letters, digits, '-', '_' and '.' only")

    @property
    def hidden(self) -> bool:
        return self.visibility == "hidden"

    @property
    def label(self) -> str:
        return f'{self.function} on "{self.id}"'

    def name_outputs(self, result, label: str | None = None) -> dict:
        """Map a returned value to ``{output name: value}``, failing clearly on the wrong arity."""
        label = label or self.label
        if len(self.outputs) == 1:
            return {self.outputs[0]: result}
        names = ", ".join(self.outputs)
        fields = getattr(result, "__dict__", None)
        if not isinstance(result, tuple | list) and isinstance(fields, dict) and all(n in fields for n in self.outputs):
            # A returned dataclass (``ReturnedDataclass`` across the sandbox): the outputs name its fields.
            return {n: fields[n] for n in self.outputs}
        if not isinstance(result, tuple | list):
            raise BadReturn(
                f"{label}: should return {len(self.outputs)} values ({names}), got a single {type(result).__name__}"
            )
        if len(result) != len(self.outputs):
            raise BadReturn(f"{label}: should return {len(self.outputs)} values ({names}), got {len(result)}")
        return dict(zip(self.outputs, result, strict=True))


def graded(
    points: float,
    part: str,
    visibility: str = "visible",
    *,
    timeout: float | None = None,
    memory_mb: int | None = None,
    tasks: tuple = (),
):
    """Mark a test as graded: its points, its part and its Gradescope visibility; ``tasks``: every
    task it needs, where its part and the lab functions it calls do not say them all (as
    :attr:`Case.tasks`)."""
    if visibility not in VISIBILITIES:
        raise ValueError(f"visibility must be one of {VISIBILITIES}")
    import pytest  # graded tests run under pytest; importing this module does not need it

    return pytest.mark.graded(
        points=points, part=part, visibility=visibility, timeout=timeout, memory_mb=memory_mb, tasks=tuple(tasks)
    )


def inputs_digest(inputs: dict, params: dict) -> str:
    """A stable hash of a case's inputs, so `refs check` can tell changed inputs from changed outputs.

    Arrays are hashed by dtype, shape and bytes; lists, tuples and dicts recursively; anything else
    by ``repr`` (dataclasses of arrays included, field by field).
    """
    import dataclasses

    h = hashlib.sha256()

    def feed(v) -> None:
        if isinstance(v, np.ndarray | np.generic):
            a = np.ascontiguousarray(v)
            if a.dtype == object:
                for item in a.ravel():
                    feed(item)
                return
            h.update(f"nd:{a.dtype}:{a.shape}:".encode() + a.tobytes())
        elif isinstance(v, list | tuple):
            h.update(f"seq{len(v)}(".encode())
            for item in v:
                feed(item)
            h.update(b")")
        elif isinstance(v, dict):
            h.update(b"{")
            for k in sorted(v, key=str):
                h.update(repr(k).encode())
                feed(v[k])
            h.update(b"}")
        elif dataclasses.is_dataclass(v) and not isinstance(v, type):
            h.update(type(v).__name__.encode())
            feed({f.name: getattr(v, f.name) for f in dataclasses.fields(v)})
        else:
            h.update(repr(v).encode())

    feed(inputs)
    h.update(json.dumps(params, sort_keys=True, default=str).encode())
    return h.hexdigest()


def run_case(lab, case: Case, *, feedback_dir: Path | None = None, diagnose_composites: bool = True) -> None:
    """Call the case's function on the lab under test and compare with the stored reference.

    A mismatch gets the case's hint, or, for a composite function, the name of the first of the
    student's building blocks that is wrong (:mod:`geomlib.grading.diagnose`).
    """
    kwargs = {**case.inputs(), **case.params}
    result = lab.call(case.function, **kwargs)
    got = case.name_outputs(result)
    if diagnose_composites and not case.hidden:
        from geomlib.grading import diagnose

        diagnose.remember_outputs(lab, case, got)  # a composite's diagnosis may probe this case again
    expected = load_reference(lab.name, case)  # loaded only after the student's call has returned
    ctx = Context(label=case.label, lab=lab.name, case_id=case.id, feedback_dir=feedback_dir)
    try:
        _screen_outputs(expected, got, ctx)
        case.check(expected, got, ctx)
    except Mismatch as e:
        # The hint, or for a composite the building block that is wrong (geomlib.grading.diagnose).
        from geomlib.grading import diagnose

        if not diagnose_composites:
            raise type(e)(e.message + (f" — {case.hint}" if case.hint else ""), e.feedback) from None
        raise diagnose.enrich(e, lab, case, kwargs, expected, got, ctx) from None


def _screen_outputs(expected: dict, got: dict, ctx: Context) -> None:
    """Reject non-finite or non-real outputs, and outputs far larger than the reference, before any check.

    Runs for every case whatever its check, so a lab's own comparison (``checks.Custom``) cannot be
    fooled by NaN (``NaN > tol`` is False) or made to densify a forged (3e8, n) sparse matrix.
    """
    for name, e in expected.items():
        if name not in got:
            continue
        e = np.asarray(e)
        g = got[name]
        if hasattr(g, "toarray") and hasattr(g, "shape"):
            if int(np.prod(g.shape)) > 4 * e.size + 1000:
                raise BadReturn(f"{ctx.label}: {name} has shape {tuple(g.shape)}, expected {e.shape}")
            g = getattr(g, "data", np.zeros(0))
            problem = nonfinite_problem(name, np.zeros(1, e.dtype) if e.dtype.kind in "biuf" else e, g)
        else:
            if isinstance(g, np.ndarray) and g.size > 4 * e.size + 1000:
                raise BadReturn(f"{ctx.label}: {name} has shape {g.shape}, expected {e.shape}")
            problem = nonfinite_problem(name, e, g)
        if problem:
            ctx.fail(problem)


def reference_tests(cases: list[Case]):
    """One graded, parametrised pytest test per case. Assign it to a ``test_*`` name in a test module."""
    ids = [c.id for c in cases]
    if len(set(ids)) != len(ids):
        raise ValueError(f"duplicate case ids: {sorted({i for i in ids if ids.count(i) > 1})}")
    import pytest

    params = [pytest.param(c, id=c.id, marks=graded(c.points, c.part, c.visibility, timeout=c.timeout)) for c in cases]

    @pytest.mark.parametrize("case", params)
    def test_reference(lab, case, feedback_dir):
        run_case(lab, case, feedback_dir=feedback_dir)

    test_reference.__doc__ = "reference output"
    return test_reference


def expect_close(
    label: str,
    got,
    expected,
    *,
    atol: float = tol.EXACT,
    rtol: float = 0.0,
    name: str = "output",
    hint: str | None = None,
    mesh=None,
) -> None:
    """Fail with a student-readable message unless ``got`` matches ``expected`` (same shape, within tolerance).

    A failure in a graded test comes with a feedback picture
    (:func:`geomlib.grading.feedback.failure_picture`): with ``mesh=(V, F)``, the mesh with the wrong
    rows marked (one row per vertex, or points near the mesh; ``mesh=(V, F, rows)`` when the rows
    are those of the vertices ``rows`` only); without, grids as images and ``(n, 2)``/``(n, 3)``
    arrays as points.
    """
    ctx = Context(label=label, hint=hint)
    e = np.asarray(expected, dtype=np.float64)
    try:
        g = np.asarray(got)
        problem = nonfinite_problem(name, e, g) if g.dtype != object else None
        g = g if problem else g.astype(np.float64)
    except (TypeError, ValueError):
        raise BadReturn(f"{label}: {name} is not a numeric array (got {type(got).__name__})") from None
    try:
        if problem:
            raise Mismatch(f"{label}: {problem}" + (f" — {hint}" if hint else ""))
        compare_arrays(name, np.atleast_1d(e), np.atleast_1d(g), ctx, atol=atol, rtol=rtol)
    except Mismatch as err:
        from geomlib.grading import feedback

        picture = feedback.failure_picture(label, g, e, name=name, mesh=mesh, atol=atol, rtol=rtol)
        raise Mismatch(err.message, picture) from None


def expect_raises(
    call: Callable[[], object], exception: str = "ValueError", *, match: str | None = None, label: str = "the call"
) -> StudentError:
    """Fail unless ``call()`` raises ``exception`` (by class name, bases included) whose message matches ``match``.

    ``NotImplementedYet`` passes through, so a stub scores zero here too.
    """
    try:
        call()
    except StudentError as e:
        if exception not in e.exc_mro:
            raise Mismatch(f"{label} should raise {exception}, but raised {e.exc_type}: {e.exc_message}") from None
        if match and not re.search(match, e.exc_message, flags=re.IGNORECASE):
            raise Mismatch(
                f"{label} raised {e.exc_type} as expected, but its message {e.exc_message!r} does not say what is wrong "
                f"(expected it to mention {match!r})"
            ) from None
        return e
    raise Mismatch(f"{label} should raise {exception} for this input, but it returned normally")


# ------------------------------------------------------------------------------ stored inputs
# A test often needs, as its input, what an earlier task produces (a depth map for the shadow
# test, a mesh's sharp edges for the alignment). Test helpers never compute those with solution
# code: a lab's case module lists them in ``STORED`` (cases without points, of the solution's
# functions), ``geomlib refs build`` runs the solution once and stores their outputs under
# ``tests/reference/<lab>/inputs/`` (``hidden/inputs/`` for those of ``cases_hidden.py``), and
# the helpers read them with :func:`stored_input`.
