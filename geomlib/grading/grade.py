"""``geomlib grade``: run the graded tests against an implementation and report the score.

Student code only ever runs inside sandboxed worker processes; this process runs the checks,
computes the scores and writes ``results.json`` itself after the workers have returned.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from geomlib.grading import impl as _impl
from geomlib.grading import plugin
from geomlib.grading.results import build_results, write_results

__all__ = ["grade"]


def grade(
    impl: str | None = None,
    labs: list[str] | None = None,
    *,
    results: str | Path | None = None,
    feedback_dir: str | Path = "feedback",
    verbose: bool = False,
    extra_args: list[str] | None = None,
) -> dict:
    """Grade ``impl`` (``solutions``, ``labs`` or a submission path) on ``labs`` (default: all).

    Returns the ``results.json`` dict (also written to ``results`` when given).
    """
    import pytest

    impl = impl or _impl.default_impl()
    _impl.resolve_impl(impl)  # fail early, with the path, if it does not exist
    graded_dir = _impl.tests_dir() / "graded"
    names = labs or _impl.lab_names()
    unknown = [n for n in names if not (graded_dir / n).is_dir()]
    if unknown:
        raise SystemExit(f"unknown lab(s): {', '.join(unknown)}; known: {', '.join(_impl.lab_names())}")
    targets = [str(graded_dir / n) for n in names]
    args = [
        *targets,
        f"--impl={impl}",
        f"--feedback-dir={feedback_dir}",
        "-p",
        "no:cacheprovider",
        f"--rootdir={_impl.course_root()}",
        "-q" if not verbose else "-v",
        "--tb=line",
        "-o",
        "console_output_style=classic",
    ]
    args += extra_args or []
    os.environ.setdefault("GEOMLIB_IMPL", str(impl))
    t0 = time.time()
    code = pytest.main(args)
    elapsed = time.time() - t0
    records = list(plugin.RECORDS)
    note = ""
    if code not in (0, 1):  # 0: all passed, 1: some failed; anything else is a grader problem
        note = f"warning: the test run ended with pytest exit code {int(code)}; some tests may not have run"
    data = build_results(records, elapsed, note)
    if results:
        write_results(data, results)
    return data
