"""How a lab's points are split between parts, public tests and hidden cases (collected, not declared twice).

Hidden cases run on inputs students never see; they carry most of each part's points so that a
submission which only reproduces the public stored outputs cannot pass (``docs/adding-a-lab.md``).
The handouts' grading tables (``labs/<lab>/README.md``) are checked against :func:`points_by_part`.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
from collections import OrderedDict

from geomlib.grading import impl as _impl
from geomlib.grading.course import course
from geomlib.grading.registry import graded_package_modules

__all__ = ["points_by_part", "graded_items"]


class _Collector:
    def __init__(self):
        self.items: list[tuple[str, str, str, float, str]] = []

    def pytest_collection_modifyitems(self, items):
        from geomlib.grading.plugin import lab_of

        for it in items:
            m = it.get_closest_marker("graded")
            if m is None:
                continue
            self.items.append(
                (
                    lab_of(it.path) or "?",
                    m.kwargs.get("part", "other"),
                    m.kwargs.get("visibility", "visible"),
                    float(m.kwargs.get("points", 0)),
                    it.nodeid,
                )
            )


def graded_items(labs: list[str] | None = None) -> list[tuple[str, str, str, float, str]]:
    """``(lab, part, visibility, points, nodeid)`` of every graded test of ``labs``, in collection order."""
    import pytest

    names = labs or _impl.lab_names()
    c = _Collector()
    args = [str(course().lab(n).graded) for n in names]
    args += ["--collect-only", "-qq", "-p", "no:cacheprovider", f"--rootdir={_impl.course_root()}"]
    # Another course's `graded` package (a test session may hold one) would shadow this one's.
    saved = {k: sys.modules.pop(k) for k in graded_package_modules()}
    # Collecting loads the course's conftest.py, whose pytest_configure sets the test suite's limits
    # (GEOMLIB_TIME_LIMIT=300 for hangs) in os.environ and adds an import guard: left behind, every
    # submission `grade-all` started after counting the points got 300 s per call instead of 30 s.
    environ, meta_path = dict(os.environ), list(sys.meta_path)
    try:
        with contextlib.redirect_stdout(io.StringIO()) as out:
            code = pytest.main(args, plugins=[c])
    finally:
        for k in graded_package_modules():
            del sys.modules[k]
        sys.modules.update(saved)
        for k in set(os.environ) - set(environ):
            del os.environ[k]
        os.environ.update({k: v for k, v in environ.items() if os.environ.get(k) != v})
        sys.meta_path[:] = meta_path
    if code not in (0, 5):
        raise RuntimeError(f"collecting the graded tests of {', '.join(names)} failed:\n{out.getvalue()[-2000:]}")
    return c.items


def points_by_part(labs: list[str] | None = None) -> dict[str, OrderedDict[str, tuple[float, float]]]:
    """``{lab: {part: (public points, hidden points)}}`` in the order the tests declare the parts."""
    out: dict[str, OrderedDict[str, tuple[float, float]]] = {}
    for lab, part, vis, pts, _ in graded_items(labs):
        parts = out.setdefault(lab, OrderedDict())
        pub, hid = parts.get(part, (0.0, 0.0))
        parts[part] = (pub, hid + pts) if vis == "hidden" else (pub + pts, hid)
    return out
