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


def test_a_tests_lab_calls_and_named_functions_are_read_once_per_session_of_a_process(monkeypatch):
    """Every check() cell of a notebook is a pytest session that collects the same graded tests
    again and asks each test's tasks: the second session walks no syntax tree (it walked each test's
    tree twice per session: 0.1 s of the 0.3 s a session costs in the kernel)."""
    table = tasks.TaskTable(tasks={"split_edge": (1,), "flip_edge": (3,)})
    for cache in (tasks._CALLS, tasks._STRINGS, tasks._DIRECT):
        cache.clear()
    first = (tasks.lab_calls(_a_test), tasks.named_functions(_names_one, table))
    walked = []
    real = tasks.ast.walk
    monkeypatch.setattr(tasks.ast, "walk", lambda node: (walked.append(node), real(node))[1])
    assert (tasks.lab_calls(_a_test), tasks.named_functions(_names_one, table)) == first
    assert first == (["flip_edge", "split_edge"], ["flip_edge"])
    assert not walked, "a test's syntax tree was walked again"


def _names_one(lab):
    return lab.call("x", "flip_edge", "not_a_task", "flip_edge")
