"""pytest plugin for graded tests: ``--impl``, the ``lab`` fixture, clean failure messages, scores.

Loaded by ``tests/conftest.py``. A graded test lives in ``tests/graded/<lab>/`` and carries a
``graded`` marker (points, part, visibility). The plugin

- hands each test the lab under test as a sandboxed :class:`~geomlib.grading.sandbox.LabProxy`;
- tells :mod:`~geomlib.grading.feedback` where the running graded test's failure pictures go;
- replaces the traceback of an expected failure (:class:`~geomlib.grading.errors.GradingFailure`)
  by its one- or two-sentence message;
- records every graded outcome in the run's :class:`GradingRun` (``geomlib grade`` hands pytest its
  own instance and turns its records into ``results.json``; a plain ``pytest`` run gets one) and
  prints a per-lab, per-part score table. No records are kept in module globals.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from geomlib.grading import impl as _impl
from geomlib.grading import sandbox, tolerances
from geomlib.grading.course import course as _course
from geomlib.grading.errors import GraderError, GradingFailure, NotImplementedYet
from geomlib.grading.results import Record
from geomlib.grading.sandbox import LabProxy
from geomlib.grading.settings import GradingSettings, env_float

_RECORD_KEY = "geomlib_graded_record"


def pytest_addoption(parser):
    g = parser.getgroup("geomlib grading")
    g.addoption(
        "--impl",
        default=None,
        help="implementation to grade: 'solutions', 'labs' or a path to a submission (default: solutions if present)",
    )
    g.addoption(
        "--feedback-dir", default="feedback", help="where failing checks write feedback pictures (default: feedback/)"
    )
    g.addoption(
        "--time-budget",
        type=float,
        default=env_float("GEOMLIB_TIME_BUDGET"),
        help="seconds for the whole run; later tests fail at once with a message saying so "
        f"(default {tolerances.TIME_BUDGET_S:g} when --impl is given, else none; 0 = none; env GEOMLIB_TIME_BUDGET)",
    )
    g.addoption(
        "--time-limit",
        type=float,
        default=env_float("GEOMLIB_TIME_LIMIT"),
        help="seconds allowed per call into the implementation (default: each test's own, else 30; env GEOMLIB_TIME_LIMIT)",
    )


class GradingRun:
    """One grading run, as a pytest plugin instance: its settings and the records of its graded tests.

    ``geomlib grade`` builds one per run (``pytest.main(args, plugins=[GradingRun(settings)])``) and
    reads :attr:`records` afterwards; a run without one (``pytest tests``) gets its own.
    """

    def __init__(self, settings: GradingSettings | None = None):
        self.settings = settings or GradingSettings.build()
        self.records: list[Record] = []

    def pytest_runtest_logreport(self, report):
        """Keep the graded record a report carries (see :func:`pytest_runtest_makereport`)."""
        for key, value in report.user_properties:
            if key == _RECORD_KEY:
                self.records.append(Record(**value))

    def pytest_terminal_summary(self, terminalreporter, exitstatus, config):
        if self.records:
            terminalreporter.write_sep("=", "graded score")
            terminalreporter.write_line(score_table(self.records))


def grading_run(config) -> GradingRun:
    """The :class:`GradingRun` registered with this pytest session."""
    for _, p in config.pluginmanager.list_name_plugin():
        if isinstance(p, GradingRun):
            return p
    raise RuntimeError("no GradingRun plugin in this pytest session")


@pytest.hookimpl(tryfirst=True)
def pytest_configure(config):
    if not any(isinstance(p, GradingRun) for _, p in config.pluginmanager.list_name_plugin()):
        config.pluginmanager.register(GradingRun(), "geomlib-grading-run")
    # The whole-run budget protects grading runs (`geomlib grade`, the autograder: both name --impl);
    # a plain `pytest tests` (CI, students) has none unless asked for.
    budget = config.getoption("--time-budget", None)
    if budget is None and config.getoption("--impl", None) is not None:
        budget = tolerances.TIME_BUDGET_S
    sandbox.set_deadline(budget)
    config.addinivalue_line("markers", "graded(points, part, visibility, timeout, memory_mb): a graded test")


def lab_of(path: Path) -> str | None:
    """The lab whose graded tests hold the file ``path`` (``tests/graded/<lab>/...`` of any course
    copy; see :meth:`geomlib.grading.course.Course.lab_of`), else None."""
    return _course().lab_of(path)


@pytest.fixture
def feedback_dir(request) -> Path | None:
    d = request.config.getoption("--feedback-dir")
    return Path(d) if d else None


@pytest.fixture(autouse=True)
def _feedback_pictures_of_this_test(request):
    """Tell :mod:`geomlib.grading.feedback` where a graded test's failure pictures go, so
    ``expect_close`` and a lab's own comparisons draw them (``feedback/<lab>/<test>--<output>.png``)."""
    from geomlib.grading import feedback

    name = lab_of(request.path)
    folder = request.config.getoption("--feedback-dir", None)
    if name is None or not folder:
        yield
        return
    feedback.begin_test(Path(folder), name, picture_stem_of(request.node))
    try:
        yield
    finally:
        feedback.end_test()


def picture_stem_of(item) -> str:
    """How the feedback pictures of the graded test ``item`` are named: its case's id for a
    reference test, else its name (:func:`geomlib.grading.context.picture_name`)."""
    from geomlib.grading.context import picture_stem

    callspec = getattr(item, "callspec", None)
    case = callspec.params.get("case") if callspec is not None else None
    return picture_stem(item.name, getattr(case, "id", None))


@pytest.fixture
def lab(request) -> LabProxy:
    """The lab under test (from the test's folder ``tests/graded/<lab>/``), run in sandboxed workers."""
    name = lab_of(request.path)
    if name is None:
        raise RuntimeError("the `lab` fixture is for tests under tests/graded/<lab>/")
    root = _impl.resolve_impl(request.config.getoption("--impl") or grading_run(request.config).settings.impl)
    marker = request.node.get_closest_marker("graded")
    timeout = request.config.getoption("--time-limit") or (marker.kwargs.get("timeout") if marker else None)
    memory = marker.kwargs.get("memory_mb") if marker else None
    return LabProxy(name, root / name, timeout=timeout, memory_mb=memory)


def _display_name(item) -> str:
    fn = getattr(item, "function", None)
    doc = (fn.__doc__ or "").strip().splitlines()[0] if fn is not None and fn.__doc__ else ""
    base = doc or item.originalname.removeprefix("test_").replace("_", " ")
    callspec = getattr(item, "callspec", None)
    if callspec is not None and "case" in callspec.params:
        return callspec.params["case"].label
    if callspec is not None:
        return f"{base} [{callspec.id}]"
    return base


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    marker = item.get_closest_marker("graded")
    exc = call.excinfo.value if call.excinfo is not None else None
    if isinstance(exc, GradingFailure) and rep.failed:
        rep.longrepr = str(exc)
    if marker is None:
        return
    done = rep.when == "call" or (rep.when == "setup" and not rep.passed)
    if not done:
        return
    if rep.skipped:
        passed, message = (
            False,
            "skipped: " + (str(rep.longrepr[-1]) if isinstance(rep.longrepr, tuple) else str(rep.longrepr)),
        )
    elif rep.passed:
        passed, message = True, ""
    elif isinstance(exc, GradingFailure):
        passed, message = False, str(exc)
    else:
        # An assertion in a graded test or an error in the grader: show the short reason, not a traceback.
        passed = False
        message = f"{type(exc).__name__}: {exc}" if exc is not None else str(rep.longrepr)[-800:]
    # The record travels on the report: with pytest-xdist the report reaches the controlling process
    # (which prints the score table) from a worker, and only what the report carries comes along.
    rep.user_properties.append(
        (
            _RECORD_KEY,
            dataclasses.asdict(
                Record(
                    nodeid=item.nodeid,
                    lab=lab_of(item.path) or "?",
                    part=marker.kwargs.get("part", "other"),
                    name=_display_name(item),
                    points=float(marker.kwargs.get("points", 0)),
                    visibility=marker.kwargs.get("visibility", "visible"),
                    passed=passed,
                    message=sandbox.clean_text(message),
                    duration=getattr(rep, "duration", 0.0),
                    not_implemented=isinstance(exc, NotImplementedYet),
                    picture=getattr(exc, "feedback", None) if isinstance(exc, GradingFailure) else None,
                    error=exc is not None
                    and (isinstance(exc, GraderError) or not isinstance(exc, GradingFailure | AssertionError)),
                )
            ),
        )
    )


def score_table(records: list[Record]) -> str:
    """A per-lab, per-part score table."""
    from collections import OrderedDict

    parts: OrderedDict = OrderedDict()
    for r in records:
        key = (r.lab, r.part)
        s, m, n, ok = parts.get(key, (0.0, 0.0, 0, 0))
        parts[key] = (s + r.score, m + r.points, n + 1, ok + r.passed)
    lines = [f"{'lab':<16}{'part':<34}{'tests':>9}{'score':>14}"]
    lines.append("-" * len(lines[0]))
    total = maxtotal = 0.0
    for (lab, part), (s, m, n, ok) in parts.items():
        lines.append(f"{lab:<16}{part[:33]:<34}{f'{ok}/{n}':>9}{f'{s:g} / {m:g}':>14}")
        total += s
        maxtotal += m
    lines.append("-" * len(lines[0]))
    lines.append(f"{'total':<59}{f'{total:g} / {maxtotal:g}':>14}")
    return "\n".join(lines)
