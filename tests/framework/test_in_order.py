"""``geomlib audit --in-order``: a student who did Tasks 1..N gets full marks from ``--task N``.

The check grades, for every task N, a copy of the solution with the later tasks' blocks stubbed as
``geomlib stubs build`` stubs them (:func:`geomlib.grading.audit.in_order_copy`). Here: the copies are
exactly the stubs (N = 0) and the solution (N = last), on every lab; and the command itself on
denoise, where it failed before 2026-11-28 (Task 5's map-route seam test ran ``denoise_with_map``'s
default ``weld=True``, Task 6: "not implemented yet (Task 6 ...)"; the test now declares Tasks 5
and 6). About 10 CPU-s (seven task runs, one audit worker).
"""

from __future__ import annotations

import json

from geomlib.grading import audit, stubs, tasks
from geomlib.grading import impl as _impl
from geomlib.grading.course import course

from .course import run_geomlib


def _files(d):
    return {
        str(f.relative_to(d)): f.read_text()
        for f in sorted(d.rglob("*"))
        if f.suffix in stubs.STUB_SUFFIXES and "__pycache__" not in f.parts
    }


def test_in_order_copies_are_the_stubs_and_the_solution_at_the_ends_and_denoise_passes_in_order(tmp_path):
    for lab in _impl.lab_names():
        last = max(tasks.derive(course().lab(lab).solution).titles)
        audit.in_order_copy(lab, 0, tmp_path / f"{lab}-0")
        audit.in_order_copy(lab, last, tmp_path / f"{lab}-last")
        solution, copy0 = _files(course().lab(lab).solution), _files(tmp_path / f"{lab}-0")
        assert copy0 == {k: (course().lab(lab).stubs / k).read_text() for k in copy0}, f"{lab}: Tasks 1..0 != stubs"
        assert set(copy0) == set(solution)
        assert _files(tmp_path / f"{lab}-last") == solution, f"{lab}: every task done != the solution"
    assert audit.later_tasks_named("f: not implemented yet (Task 6 (seam fix, weld): ...)", 5) == [6]
    assert audit.later_tasks_named("f: not implemented yet (Task 6 (seam fix, weld): ...)", 6) == []

    p = run_geomlib(_impl.course_root(), "audit", "--in-order", "--lab", "denoise", "--out", str(tmp_path / "out"),
                    check=False, timeout=600)  # fmt: skip
    report = json.loads((tmp_path / "out" / "in-order.json").read_text())
    rows = report["labs"]["denoise"]
    bad = [
        f"Task {r['task']}: {r['status']} {r['score']:g}/{r['max']:g} {r['failures'][:2]}"
        for r in rows
        if r["status"] != "ok"
    ]
    assert not bad, "\n".join(bad)
    assert [r["task"] for r in rows] == sorted(tasks.derive(course().lab("denoise").solution).titles)
    assert all(r["max"] > 0 for r in rows), rows
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
