"""``geomlib grade`` and ``check``: run the graded tests against an implementation and report.

Student code only ever runs inside sandboxed worker processes; this process runs the checks,
computes the scores and writes ``results.json`` itself after the workers have returned.

The report a student reads is short and always in the same order: the per-part score table, then
"What to fix" (one line per failing test, tasks not started yet summed up in one line each), then
where the feedback pictures are. pytest's own output (progress dots, tracebacks, warnings) is
kept out of it; ``verbose=True`` shows it.
"""

from __future__ import annotations

import contextlib
import io
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.grading import impl as _impl
from geomlib.grading import plugin
from geomlib.grading.course import course
from geomlib.grading.errors import SEE_PICTURE
from geomlib.grading.results import build_results, failure_tasks, write_results
from geomlib.grading.settings import GradingSettings, env
from geomlib.taskref import find_task, tasks_label

__all__ = ["grade", "check", "Report", "report_lines"]


@dataclass
class _Selection:
    """A pytest plugin (passed to ``pytest.main``): keeps the graded tests of one task or part,
    and remembers the task of every graded test.

    ``task``: the tests whose latest task it is (:func:`geomlib.grading.tasks.selects`), so a
    student doing the tasks in order sees no test that needs a later one; ``every_test``: every test
    that needs the task, whatever else it needs (the mutation audit: every test a bug can fail)."""

    task: int | None = None
    part: str | None = None
    every_test: bool = False
    tasks: dict = field(default_factory=dict)  # nodeid -> tuple of task numbers
    titles: dict = field(default_factory=dict)  # lab -> TaskTable
    deselected: int = 0
    #: the task has no test of its own; the tests that run it (through a composite) were kept
    through: str = ""

    def pytest_collection_modifyitems(self, session, config, items):
        from geomlib.grading import tasks as _tasks

        keep, drop = [], []
        runs = {}
        for item in items:
            marker = item.get_closest_marker("graded")
            lab = plugin.lab_of(item.path)
            if marker is None or lab is None:
                keep.append(item)
                continue
            if lab not in self.titles:
                try:
                    self.titles[lab] = _tasks.table(lab)
                except Exception:  # a broken table must not stop grading
                    self.titles[lab] = _tasks.TaskTable()
            part = marker.kwargs.get("part", "other")
            try:
                t = _tasks.test_tasks(item, self.titles[lab], part)
            except Exception:
                t = ()
            self.tasks[item.nodeid] = t
            ok = (self.task is None or _tasks.selects(t, self.task, self.every_test)) and (
                self.part is None or part.strip().lower() == self.part.strip().lower()
            )
            (keep if ok else drop).append(item)
        if self.task is not None and self.part is None and not [i for i in keep if i.nodeid in self.tasks]:
            for item in drop:  # the task has no test of its own: which tests run it (parsed only now)
                if item.nodeid in self.tasks:
                    try:
                        runs[item.nodeid] = self.task in self.tasks[item.nodeid] or self.task in _tasks.test_runs(
                            item, self.titles[plugin.lab_of(item.path)]
                        )
                    except Exception:
                        runs[item.nodeid] = False
        if self.task is not None and not [i for i in keep if i.nodeid in self.tasks] and any(runs.values()):
            keep += [i for i in drop if runs.get(i.nodeid)]
            drop = [i for i in drop if not runs.get(i.nodeid)]
            labs = sorted({plugin.lab_of(i.path) for i in keep if i.nodeid in runs})
            titles = [self.titles[lab].describe(self.task) for lab in labs if lab in self.titles]
            self.through = (
                f"{titles[0] if titles else f'Task {self.task}'} has no test of its own: "
                "these are the tests of the functions that run it"
            )
        if drop:
            config.hook.pytest_deselected(items=drop)
            items[:] = keep
            self.deselected = len(drop)


def grade(
    impl: str | None = None,
    labs: list[str] | None = None,
    *,
    results: str | Path | None = None,
    feedback_dir: str | Path = "feedback",
    verbose: bool = False,
    extra_args: list[str] | None = None,
    task: int | None = None,
    part: str | None = None,
    pictures: str | None = None,
    records_out: list | None = None,
    every_test: bool = False,
) -> dict:
    """Grade ``impl`` (``solutions``, ``labs`` or a submission path) on ``labs`` (default: all).

    Parameters
    ----------
    task : int, optional
        Only the graded tests of this task (``Task 2`` in the stubs): those whose latest task it is,
        so a student working in order meets no later task's test (a task without such a test: the
        tests that run it, and the report says so).
    every_test : bool
        With ``task``: every graded test that needs the task, also with later ones (the mutation
        audit's question: which tests can a bug of this task fail).
    part : str, optional
        Only the graded tests of this part (``"boundary rules"``), as in the score table.
    verbose : bool
        Show pytest's own output as well.
    pictures : {"first", "all", "none"}, optional
        Feedback pictures to draw: the first failure's (default; a picture costs about a second),
        every failure's, or none (see :class:`geomlib.grading.feedback.pictures_for_run`).
    records_out : list, optional
        Receives this run's :class:`~geomlib.grading.plugin.Record` objects, in the order of
        ``results["tests"]`` (the audit matches them to test node ids).

    Returns
    -------
    dict
        The ``results.json`` dict (also written to ``results`` when given), plus an entry
        ``"report"``: the lines of the student report (see :func:`report_lines`). The entry is not
        part of what is written to ``results``.
    """
    import pytest

    impl = impl or _impl.default_impl()
    root = _impl.resolve_impl(impl)  # fail early, with the path, if it does not exist
    c = course()
    names = labs or c.labs
    if names == [root.name] and not (root / root.name).is_dir() and c.impl_dir(str(impl)) is None:
        # `--impl path/to/subdivision --lab subdivision`: the lab folder itself, as a student uploads it
        # (it read "lab folder .../subdivision/subdivision is missing from the submission")
        impl = str(root.parent)
    unknown = [n for n in names if not c.lab(n).graded.is_dir()]
    if unknown:
        raise SystemExit(f"unknown lab(s): {', '.join(unknown)}; known: {', '.join(c.labs)}")
    targets = [str(c.lab(n).graded) for n in names]
    args = [
        *targets,
        f"--impl={impl}",
        f"--feedback-dir={feedback_dir}",
        "-p",
        "no:cacheprovider",
        # A student's segfault is reported by the sandbox; the fault handler would dump the
        # grader's own stack on top.
        "-p",
        "no:faulthandler",
        # pytest's collection of unraisable exceptions ends with two full garbage collections
        # (0.1 s); student code never runs in this process.
        "-p",
        "no:unraisableexception",
        "-W",
        "ignore::pytest.PytestAssertRewriteWarning",
        f"--rootdir={_impl.course_root()}",
        "-q" if not verbose else "-v",
        "--tb=line" if verbose else "--tb=no",
        "-o",
        "console_output_style=classic",
    ]
    args += extra_args or []
    run = plugin.GradingRun(GradingSettings.build(impl=impl, feedback_dir=feedback_dir))
    selection = _Selection(task=task, part=part, every_test=every_test)
    owners = _PictureOwners()
    _start_sandbox_early()
    t0 = time.time()
    captured = io.StringIO()
    from geomlib.grading import feedback

    with feedback.pictures_for_run(pictures) as drawn, _no_plugin_autoload():
        if verbose:
            code = pytest.main(args, plugins=[selection, run, owners])
        else:
            with contextlib.redirect_stdout(captured), contextlib.redirect_stderr(captured):
                code = pytest.main(args, plugins=[selection, run, owners])
    elapsed = time.time() - t0
    records = list(run.records)
    if records_out is not None:
        records_out.extend(records)
    for r in records if drawn.failed else ():  # pictures named in a message but not drawn after all
        r.message = feedback.without_pictures(r.message, drawn.failed)
        if r.picture and feedback._relpath(r.picture) in drawn.failed:
            r.picture = None
    _remove_stale_pictures(feedback_dir, records, before=t0, ran=None if owners.whole else owners.stems)
    note = ""
    if code == 5 or (code == 0 and not records):
        what = f"task {task}" if task is not None else f'part "{part}"' if part else "these labs"
        note = f"no graded test of {what} in {', '.join(names)}"
    elif code not in (0, 1):  # 0: all passed, 1: some failed; anything else is a grader problem
        note = f"warning: the test run ended with pytest exit code {int(code)}; some tests may not have run"
        tail = _problem_lines(captured.getvalue())
        if tail:
            note += ":\n" + "\n".join(tail)
    if selection.through and records:
        note = f"{selection.through}\n{note}" if note else selection.through
    data = build_results(records, elapsed, note, tasks=selection.tasks)
    if results:
        write_results(data, results)
    data["report"] = report_lines(
        records, feedback_dir=feedback_dir, note=note, tasks=selection.tasks, whole=task is None and part is None
    )
    if drawn.held and feedback_dir:
        data["report"] += [
            "Pictures of the other failures (about a second each): add --pictures all "
            '(in a notebook: check(..., pictures="all")).'
        ]
    return data


@contextlib.contextmanager
def _no_plugin_autoload():
    """The graded tests use no installed pytest plugin: not loading them (anyio, xdist, ...) saves a
    quarter of a second of every ``geomlib grade`` and ``check``. ``PYTEST_DISABLE_PLUGIN_AUTOLOAD``
    set by the user stays as it is."""
    import os

    if "PYTEST_DISABLE_PLUGIN_AUTOLOAD" in os.environ:
        yield
        return
    os.environ["PYTEST_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    try:
        yield
    finally:
        os.environ.pop("PYTEST_DISABLE_PLUGIN_AUTOLOAD", None)


def _start_sandbox_early() -> None:
    """Start the sandbox's zygote (an interpreter importing NumPy, SciPy, libigl: about a second) in
    the background, so that it starts while pytest starts and collects, not after: a student's
    ``--task N`` waits for the longer of the two, not their sum. Later runs in this process (a
    notebook's ``check``) reuse it."""
    import threading

    from geomlib.grading import sandbox

    if any(t.name == "geomlib-zygote-start" for t in threading.enumerate()):
        return  # started by an earlier run in this process (and restarted by the sandbox if it died)

    def start():
        try:
            sandbox._zygote()
        except Exception:  # noqa: BLE001 - the first test starts it again and reports the problem
            return
        # The zygote asks for SIGTERM when its parent *thread* ends (PR_SET_PDEATHSIG follows the
        # thread that started it), so this thread stays, parked, for the life of the process.
        threading.Event().wait()

    threading.Thread(target=start, name="geomlib-zygote-start", daemon=True).start()


class _PictureOwners:
    """A pytest plugin: the tests that run, each with the name its feedback pictures start with
    (:func:`geomlib.grading.context.picture_name`), and whether any test was left out."""

    def __init__(self):
        self.stems: dict[str, str] = {}  # nodeid -> picture stem
        self.whole = True

    def pytest_deselected(self, items):  # --task, --part, -k ...
        if items:
            self.whole = False

    def pytest_collection_finish(self, session):
        self.stems = {i.nodeid: plugin.picture_stem_of(i) for i in session.items}


def _remove_stale_pictures(feedback_dir, records, *, before: float, ran: dict | None = None) -> None:
    """Remove the pictures this run's tests did not draw or cite: their tests pass now (or no longer
    exist), so ``feedback/<lab>/`` shows only today's failures. ``ran`` (nodeid -> picture stem):
    only some tests ran (``--task``, ``--part``), and only their pictures go — a picture's name
    starts with its test's, so another task's pictures stay. None: whole labs ran, every stale
    picture goes."""
    if not feedback_dir:
        return
    from geomlib.grading.context import picture_owner

    cited, stems = set(), {}
    for r in records:
        for p in [r.picture or "", *SEE_PICTURE.findall(r.message or "")]:
            if p:
                cited.add((Path(p).parent.name, Path(p).name))
        if ran is not None and r.nodeid in ran:
            stems.setdefault(r.lab, set()).add(ran[r.nodeid])
    for lab in {r.lab for r in records}:
        for png in Path(feedback_dir, lab).glob("*.png"):
            if (lab, png.name) in cited or (ran is not None and picture_owner(png.name) not in stems.get(lab, ())):
                continue
            try:
                if png.stat().st_mtime < before:
                    png.unlink()
            except OSError:
                pass
    # A folder whose pictures all went says nothing: leave no empty feedback/<lab>/ or feedback/.
    for folder in [*(Path(feedback_dir, lab) for lab in {r.lab for r in records}), Path(feedback_dir)]:
        try:
            folder.rmdir()  # only when empty
        except OSError:
            pass


def _problem_lines(text: str, limit: int = 12) -> list[str]:
    """The lines of pytest's output that say why a run could not go ahead (collection errors)."""
    lines = [ln.rstrip() for ln in text.splitlines() if ln.strip()]
    keep = [ln for ln in lines if re.match(r"^(E |ERROR|[A-Za-z]*Error)", ln)]
    return (keep or lines)[-limit:]


#: geomlib.grading.diagnose.rows_task_note: the rows that differ are another task's than the case's
def report_lines(
    records: list,
    *,
    feedback_dir: str | Path | None = "feedback",
    note: str = "",
    tasks: dict | None = None,
    whole: bool = True,
) -> list[str]:
    """The student report: score table, "What to fix", feedback pictures.

    One line per failing test (at most :data:`LINE` characters, the details indented below it):
    wrong results of started tasks first, in task order, then the tasks not started yet, one line
    per function (their tests all say the same). ``whole``: the run graded whole labs (no
    ``--task`` or ``--part``): a first grade of untouched stubs starts with "0 / 60 — nothing
    implemented yet; start with Task 1 (...)", and a run without hidden cases says what the lab is
    out of with them.
    """
    tasks = tasks or {}
    lines: list[str] = []
    if note:
        lines += [note, ""]
    if not records:
        return lines or ["no graded tests ran"]
    first = _nothing_implemented(records) if whole else ""
    if first:
        lines += [first, ""]
    lines += plugin.score_table(records).splitlines()
    if whole:  # say what the public total is out of
        lines += _hidden_totals(records)
    failed = [r for r in records if not r.passed and not r.message.startswith("skipped")]
    skipped = [r for r in records if not r.passed and r.message.startswith("skipped")]
    if not failed and not skipped:
        lines += ["", f"All {len(records)} graded tests pass."]
        return lines
    labs = list(dict.fromkeys(r.lab for r in records))
    several = len(labs) > 1  # then every line says which lab it is about
    todo: dict[tuple, list] = {}
    fix: dict[str, list[tuple[int, str]]] = {lab: [] for lab in labs}
    pictures: list[str] = []
    seen: set[str] = set()
    for r in failed:
        msg = " ".join(r.message.split())  # one line, whatever the message
        for pic in SEE_PICTURE.findall(msg):
            if pic not in pictures:
                pictures.append(pic)
        if r.not_implemented:
            todo.setdefault((r.lab, msg), []).append(r)
            continue
        where = f"{r.lab} · " if several else ""
        t, part = failure_tasks(msg, tasks.get(r.nodeid, ()), r.part)
        line = f"✗ {where}{tasks_label(t)} · {part}: {msg}" if t else f"✗ {where}{part}: {msg}"
        if line in seen:
            continue
        seen.add(line)
        fix[r.lab].append((min(t) if t else 1_000, line))
    if failed:
        n_tests = len(failed)
        lines += ["", f"What to fix ({n_tests} failing test{'s' if n_tests != 1 else ''}):"]

        def task_no(msg):
            m = find_task(msg)
            return m.number if m else 1_000

        for lab in labs:  # per lab: wrong results of started tasks, then tasks not started, in task order
            for _, line in sorted(fix[lab], key=lambda tl: tl[0]):
                lines += _wrapped(line)
            for (_, msg), rs in sorted(
                ((k, v) for k, v in todo.items() if k[0] == lab), key=lambda kv: task_no(kv[0][1])
            ):
                n = len(rs)
                where = f"{lab} · " if several else ""
                lines += _wrapped(f"✗ {where}{msg}" + (f" — {n} tests" if n != 1 else ""))
    for r in skipped:
        lines.append(f"  - {r.part}: {r.name}: {r.message}")
    if pictures:
        folders = sorted({str(Path(p).parent) for p in pictures})
        lines += ["", f"Feedback pictures ({len(pictures)}) in {', '.join(f + '/' for f in folders)}:"]
        lines += [f"  {p}" for p in pictures]
    elif feedback_dir and any(not r.not_implemented for r in failed):
        lines += ["", "No feedback pictures for these failures."]
    return lines


#: Longest line of "What to fix"; the rest of a message follows on indented lines below it.
LINE = 160


def _wrapped(line: str) -> list[str]:
    """``  ✗ ...`` in lines of at most :data:`LINE` characters: the first says which task and
    check, the details follow below it, indented."""
    import textwrap

    return textwrap.wrap(
        line, LINE, initial_indent="  ", subsequent_indent="      ", break_long_words=True, break_on_hyphens=False
    )


def _nothing_implemented(records) -> str:
    """ "0 / 60 — nothing implemented yet; start with Task 1 (odd vertices): loop_odd_matrix" when
    no point-carrying test passes and every failure is a task not started; else ""."""
    pointed = [r for r in records if r.points > 0]
    if not pointed or any(r.passed or not r.not_implemented for r in pointed):
        return ""
    best = None
    for r in pointed:
        m = find_task(r.message, titled=True)
        if m and (best is None or m.number < best[0]):
            best = (m.number, m.text, r.message.split(":", 1)[0].strip())
    total = sum(r.points for r in pointed)
    start = f"; start with {best[1]}: {best[2]}" if best else ""
    return f"0 / {total:g} — nothing implemented yet{start}"


def _hidden_totals(records) -> list[str]:
    """When the run had no hidden cases (a student's copy): what each lab is out of with them,
    from the grading table of its handout ("| **total** | 60 + 91 = 151 |")."""
    if any(r.visibility == "hidden" for r in records):
        return []
    out = []
    for lab in dict.fromkeys(r.lab for r in records):
        try:
            text = course().lab(lab).handout.read_text()
        except OSError:
            continue
        m = re.search(r"^\| \*\*total\*\* \| ([0-9.]+) \+ ([0-9.]+) = ([0-9.]+) \|", text, re.M)
        if m and float(m.group(2)) > 0:
            out.append(
                f"These are the public tests only: with the hidden cases the autograder adds, {lab} is "
                f"out of {m.group(3)} ({m.group(1)} public + {m.group(2)} hidden)."
            )
    return out


class Report(list):
    """The lines of a grading report; shows as plain text in a notebook or at the prompt."""

    def __init__(self, lines, results: dict | None = None):
        super().__init__(lines)
        self.results = results or {}

    @property
    def score(self) -> float:
        return float(self.results.get("score", 0.0))

    def __str__(self) -> str:
        return "\n".join(self)

    __repr__ = __str__

    def _repr_pretty_(self, p, cycle):  # IPython
        p.text(str(self))


def check(
    lab: str,
    task: int | None = None,
    part: str | None = None,
    *,
    impl: str | None = None,
    feedback_dir: str | Path = "feedback",
    pictures: str | None = None,
) -> Report:
    """Grade one lab (optionally one task or part) and return the report's lines.

    The same check as ``geomlib grade --lab LAB [--task N] [--part NAME]``, for a notebook cell::

        from geomlib.grading import check
        check("subdivision", task=2)

    ``pictures="all"`` draws a feedback picture for every failure, not only the first. The
    implementation graded is ``impl``, else ``GEOMLIB_IMPL``, else the default: the one the
    notebook's ``open_lab`` loads, so a notebook grades what its cells run.

    Returns
    -------
    Report
        A list of the report's lines (it prints as the report); ``.score`` and ``.results`` hold
        the numbers.
    """
    impl = impl or env("GEOMLIB_IMPL")
    data = grade(impl, [lab], feedback_dir=feedback_dir, task=task, part=part, pictures=pictures)
    return Report(data.pop("report"), data)
