"""Hints that diagnose: when a composite result is wrong, find the building block that makes it so.

A *composite* is a lab function that calls other task functions (``loop_subdivide`` calls
``loop_odd_matrix``, ``loop_even_matrix`` and ``loop_faces``; see :mod:`geomlib.grading.tasks`).
When a graded case of a composite fails, :func:`enrich` runs the student's own building blocks on
*probe* cases, each compared with a reference stored by ``geomlib refs build``, in task order, and
names the first that is wrong::

    loop_subdivide on "loop-torus-2-loop": expected a vertex at ... — loop_subdivide is off because
    loop_even_matrix (Task 2 (even vertices)) differs at valence-6 vertices: ...

When every block agrees, the composite's own task is named instead. Probes are the lab's graded
cases of the building blocks plus the probe-only cases a lab declares in
``tests/graded/<lab>/diagnose.py`` (``CASES``: same inputs as the composite cases, zero points,
never graded themselves). That module may also declare

- ``PROBES``: ``{composite case id: [probe case ids to try first]}`` (the same input);
- ``WHERE``: ``{function: where(inputs, expected, got) -> " at valence-3 vertices" or ""}``;
- ``PICTURES``: ``{function: picture(ctx, inputs, expected, got) -> path or None}``, a feedback
  picture for outputs the generic checks cannot draw (a subdivision matrix: the mesh with the
  vertices whose rows are wrong highlighted);
- ``ROWS_TASK``: ``{function: task(inputs, expected, got) -> task number or None}``, the task of
  the rows that differ, for cases that mix the rows of two tasks (a boundary-rules case of
  ``loop_odd_matrix`` has interior edges too): when it is not the case's own task, the message
  says so and gives that task's hint instead of the case's (see :func:`rows_task_note`).

Everything here is a help: any problem while diagnosing leaves the original message as it was.
"""

from __future__ import annotations

import time
from pathlib import Path

from geomlib.grading import tasks as _tasks
from geomlib.grading.errors import GradingFailure, Mismatch, NotImplementedYet, see_picture

__all__ = ["enrich", "explain", "probes_for"]

#: Probe outcomes, keyed by (implementation folder, its files' modification times, probe id).
_CACHE: dict = {}
#: Seconds one explanation may spend on probes.
BUDGET_S = 60.0
#: Outputs of graded cases that a probe would ask for again (a block's reference case graded earlier
#: in the run: shadows' "uvz-ortho" explains render_with_shadows), keyed like :data:`_CACHE`; at most
#: :data:`KEEP_BYTES` of them. A probe takes its case's outputs from here instead of calling again.
_OUTPUTS: dict = {}
KEEP_BYTES = 32 << 20


def _nbytes(value) -> int:
    """Bytes of the arrays in a case's outputs (dicts, lists, arrays, sparse matrices)."""
    if isinstance(value, dict):
        return sum(_nbytes(v) for v in value.values())
    if isinstance(value, list | tuple):
        return sum(_nbytes(v) for v in value)
    if hasattr(value, "toarray") and hasattr(value, "nnz"):  # sparse: its stored entries and indices
        return 16 * int(value.nnz)
    return int(getattr(value, "nbytes", 0))


def remember_outputs(lab, case, got: dict) -> None:
    """Keep the outputs of a graded case whose function is a building block of one of the lab's
    composites (:func:`_run_probe` then does not call it again for the same case)."""
    try:
        if not any(case.function in blocks for blocks in _tasks.table(lab.name).composites.values()):
            return
        size = _nbytes(got)
        if size > KEEP_BYTES - sum(n for _, n in _OUTPUTS.values()):
            return
        _OUTPUTS[(str(lab.lab_dir), _stamp(lab.lab_dir), case.id)] = (got, size)
    except Exception:  # noqa: BLE001 - a help: the probe calls again
        return


def _stamp(folder: Path) -> tuple:
    try:
        return tuple(sorted((p.name, p.stat().st_mtime_ns) for p in Path(folder).glob("*.py")))
    except OSError:
        return ()


def _module(lab: str):
    try:
        return _tasks._declared(lab)
    except Exception:
        return None


def probes_for(lab: str, case) -> list:
    """Probe cases for a composite case, in the order they are tried (task, same input first)."""
    from geomlib.grading.registry import load_cases

    tab = _tasks.table(lab)
    blocks = tab.composites.get(case.function, ())
    if not blocks:
        return []
    mod = _module(lab)
    pool = {}
    for c in [*getattr(mod, "CASES", []), *load_cases(lab, hidden=False, probes=False)]:
        if c.function in blocks and not c.hidden:
            pool.setdefault(c.id, c)
    first = list(getattr(mod, "PROBES", {}).get(case.id, ()))

    def key(c):
        return (
            tab.tasks.get(c.function, (99,))[0],
            blocks.index(c.function),
            first.index(c.id) if c.id in first else len(first),
        )

    return sorted(pool.values(), key=key)


def _run_probe(lab, probe, mod, feedback_dir):
    """None when the student's block matches the probe's reference, else (what, message)."""
    from geomlib.grading.context import Context
    from geomlib.grading.registry import load_reference

    key = (str(lab.lab_dir), _stamp(lab.lab_dir), probe.id)
    if key in _CACHE:
        return _CACHE[key]
    out = None
    inputs = {**probe.inputs(), **probe.params}
    try:
        known = _OUTPUTS.pop(key, None)  # graded earlier in the run: the same call, not made again
        got = known[0] if known is not None else probe.name_outputs(lab.call(probe.function, **inputs))
        expected = load_reference(lab.name, probe)
        ctx = Context(label=probe.label, lab=lab.name, case_id=probe.id, feedback_dir=feedback_dir)
        try:
            probe.check(expected, got, ctx)
        except Mismatch as e:
            where = ""
            fn = getattr(mod, "WHERE", {}).get(probe.function)
            if fn is not None:
                try:
                    where = fn(inputs, expected, got) or ""
                except Exception:
                    where = ""
            pic = e.feedback or _picture(mod, probe.function, ctx, inputs, expected, got)
            msg = e.message + (f" — {probe.hint}" if probe.hint else "")
            out = (f"differs{where}", msg + see_picture(pic))
    except NotImplementedYet:
        out = ("is not implemented yet", "")
    except GradingFailure as e:
        out = ("fails", str(e))
    _CACHE[key] = out
    return out


def _picture(mod, function, ctx, inputs, expected, got):
    if ctx.feedback_dir is None:
        return None
    from geomlib.grading import feedback

    fn = getattr(mod, "PICTURES", {}).get(function, feedback.default_picture)
    try:
        return fn(ctx, inputs, expected, got)
    except Exception:
        return None


def explain(lab, case, *, feedback_dir=None) -> str | None:
    """Why the composite ``case`` fails on ``lab`` (a sandboxed lab proxy), or None if not a composite."""
    tab = _tasks.table(lab.name)
    probes = probes_for(lab.name, case)
    if not probes:
        return None
    mod = _module(lab.name)
    same_input = set(getattr(mod, "PROBES", {}).get(case.id, ()))
    t0 = time.time()
    # First the probes on this case's own input: a wrong block there explains the result. Then the
    # block's other cases: a multi-level composite meets inputs its first level does not show.
    for own_input in (True, False):
        for p in probes:
            if (p.id in same_input) != own_input or time.time() - t0 > BUDGET_S:
                continue
            res = _run_probe(lab, p, mod, feedback_dir)
            if res is None:
                continue
            what, detail = res
            task = tab.describe(tab.tasks[p.function][0]) if p.function in tab.tasks else "a building block"
            detail = f": {detail}" if detail else ""
            if own_input or not same_input:
                return f"{case.function} is off because {p.function} ({task}) {what}{detail}"
            return (
                f"{case.function} is off; its building blocks agree on this input, but {p.function} ({task}) "
                f"{what} on another mesh (later steps meet cases the input does not have){detail}"
            )
    blocks = ", ".join(tab.composites.get(case.function, ()))
    own = tab.tasks.get(case.function)
    if own:
        return (
            f"its building blocks ({blocks}) agree with the references, so look at {case.function} "
            f"itself ({tab.describe(own[0])})" + (f": {case.hint}" if case.hint else "")
        )
    return None


def enrich(error: Mismatch, lab, case, inputs: dict, expected: dict, got: dict, ctx) -> Mismatch:
    """``error`` with a picture if it has none, and the diagnosis (or the case's hint) appended."""
    try:
        mod = _module(lab.name)
        pic = error.feedback or _picture(mod, case.function, ctx, inputs, expected, got)
        why = explain(lab, case, feedback_dir=ctx.feedback_dir)
    except Exception:
        pic, why = error.feedback, None
    extra = why or rows_task_note(lab.name, case, inputs, expected, got) or case.hint
    return type(error)(error.message + (f" — {extra}" if extra else ""), pic)


def rows_task_note(lab: str, case, inputs: dict, expected: dict, got: dict) -> str | None:
    """ "the rows that differ at interior edges belong to Task 1 (odd vertices), not to Task 4: ...:
    <Task 1's hint>" when the lab's
    ``ROWS_TASK`` puts the differing rows of ``case`` in another task than the case's own."""
    try:
        fn = getattr(_module(lab), "ROWS_TASK", {}).get(case.function)
        if fn is None:
            return None
        n = fn(inputs, expected, got)
        tab = _tasks.table(lab)
        own = tab.of_part(case.part) or (tab.of_function(case.function) or (None,))[0]
        if n is None or n == own:
            return None
        from geomlib.grading.registry import load_cases

        hint = next(
            (
                c.hint
                for c in load_cases(lab, hidden=False, probes=False)
                if c.function == case.function and c.hint and tab.of_part(c.part) == n
            ),
            "",
        )
        where = ""
        w = getattr(_module(lab), "WHERE", {}).get(case.function)
        if w is not None:
            where = w(inputs, expected, got) or ""
        note = f"the rows that differ{where} belong to Task {n} ({tab.titles.get(n, '')}), not to {tab.describe(own)}"
        return note + (f": {hint}" if hint else "")
    except Exception:  # a help only
        return None
