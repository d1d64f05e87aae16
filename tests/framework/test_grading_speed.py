"""Work a grading run repeats for every test or call, done once (issue 26, item 4: feedback speed of
``geomlib grade --task N`` and ``check()``): the course's root folder is resolved once per path, and a
hand-written test's helper is searched for lab calls once per function."""

from __future__ import annotations

from pathlib import Path

from geomlib.grading import course as _course
from geomlib.grading import tasks


def test_the_course_root_is_resolved_once(monkeypatch):
    """A --task 3 run of shadows asked for the course about 300 times, each resolving its root
    (symbolic links followed: a system call per path component)."""
    _course._resolved.cache_clear()
    resolved = []
    real = Path.resolve
    monkeypatch.setattr(Path, "resolve", lambda self, *a, **k: (resolved.append(self), real(self, *a, **k))[1])
    roots = {_course.course_root() for _ in range(50)}
    assert roots == {real(Path(_course.__file__)).parents[2]}
    assert len(resolved) == 1, len(resolved)


def _helper(lab):
    return lab.split_edge(1)


def _a_test(lab):
    return _helper(lab) + lab.flip_edge(2)


def test_a_helpers_lab_calls_are_read_once(monkeypatch):
    """``--task N`` reads every collected test's lab calls, helpers included (a notebook's check()
    again at every run): each function's source is walked once."""
    tasks._DIRECT.clear()
    assert tasks.lab_calls(_a_test) == ["flip_edge", "split_edge"]
    walked = []
    real = tasks.ast.walk
    monkeypatch.setattr(tasks.ast, "walk", lambda node: (walked.append(node), real(node))[1])
    assert tasks._direct_lab_calls(_helper) == ["split_edge"]
    assert tasks._direct_lab_calls(_a_test) == ["flip_edge"]
    assert not walked, "a function's lab calls were searched again"
