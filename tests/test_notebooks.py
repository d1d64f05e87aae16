"""Every notebook executes headless, top to bottom (small inputs, quick figures), on the solutions
and on the stubs; on the stubs its ``check()`` cells show that every lab's stubs score zero.

Each thing is graded once in the suite: ``tests/graded/<lab>`` grades every graded test against the
solutions, and the stubs run here grades every graded test against the stubs (the notebook's
``check(lab, task=N)`` cells, one per task; ``tests/framework/test_task_selection.py`` checks that
together they select every graded test, and the stubs run here checks that no task's tests name a
later task). So the run on the solutions executes every cell but the
``check()`` cells, which would grade the solutions a second time (and start a grading sandbox in the
kernel for it: seconds of CPU per lab); only in one notebook (:data:`PASSING_REPORT_IN`) it keeps
the first one (task 1, it also imports ``check``), which shows a passing report in a kernel: the
path from ``check()`` to the report is the same for every lab, and the stubs run takes it in every
notebook.

On the stubs, the figures cell's pictures are checked as ``tests/test_lab_contracts.py`` checks the
stubs' figures (each names a task not implemented yet), and every panel it lays out is the solutions
run's panel or says what is missing: the suite draws them once, here.

One kernel runs a notebook twice: on the stubs first, as in a student's fresh kernel, then, after a
``%reset`` that drops every name the first run defined (:data:`_SWITCH`), on the solutions. The two
runs share the kernel's start and the imports of the set-up and figures cells (about 2 s of CPU a
notebook), and in :data:`PASSING_REPORT_IN` the grading sandbox. A kernel runs its ``check()`` cells
in one process: each is one pytest session, and they share one grading sandbox (the zygote, started
by the first, with what it preloaded for the lab) and the kernels compiled earlier
(:mod:`geomlib.grading.kernelcache`), as in a student's notebook.
"""

from __future__ import annotations

import base64
import io
import json
import pickle
import re
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from jupyter_client.manager import KernelManager

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
#: Seconds a cell may run, for hangs only: a check() cell needs seconds, but one took 363 s on a
#: 2-core machine shared with 20 busy processes (the old 300 s made the test depend on the load).
CELL_TIMEOUT = 3600

#: The notebook whose run on the solutions keeps its first check() cell (see the module docstring):
#: the lab that is quickest to grade.
PASSING_REPORT_IN = "subdivision"

#: A cell run after the notebook's own: the reports of its check() cells (IPython keeps every cell's
#: value in ``Out``), by execution count.
_REPORTS = """\
import json as _json
from geomlib.grading.grade import Report as _Report
print("@@reports" + _json.dumps({k: v.results for k, v in Out.items() if isinstance(v, _Report)}))
"""


_NO_DEBUGGER = (
    "import sys; sys.modules['debugpy'] = None; from ipykernel import kernelapp; kernelapp.launch_new_instance()"
)


class _Kernel(KernelManager):
    """The kernel Jupyter starts (``python -m ipykernel_launcher -f ...``), without its debugger:
    ipykernel imports debugpy at start for JupyterLab's debugger panel, which no cell uses (0.12 s
    of CPU of the 0.6 s a kernel costs, 18 kernels)."""

    def format_kernel_cmd(self, extra_arguments=None):
        cmd = super().format_kernel_cmd(extra_arguments)
        for i in range(len(cmd) - 1):
            if cmd[i : i + 2] == ["-m", "ipykernel_launcher"]:
                return [*cmd[:i], "-c", _NO_DEBUGGER, *cmd[i + 2 :]]
        return cmd


def _figures(cells) -> list[tuple[str, str, np.ndarray]]:
    """``(file name, caption, RGB pixels)`` of the figures the figures cell showed: a Markdown line
    ``**name.png** — caption``, then the picture."""
    from PIL import Image

    out, caption = [], None
    for c in cells:
        for o in c.get("outputs", []) if c.cell_type == "code" else []:
            data = o.get("data", {})
            m = re.match(r"\*\*(\S+\.png)\*\* — (.*)", data.get("text/markdown", ""), re.S)
            if m:
                caption = m.groups()
            elif "image/png" in data and caption is not None:
                img = Image.open(io.BytesIO(base64.b64decode(data["image/png"]))).convert("RGB")
                out.append((*caption, np.asarray(img)))
                caption = None
    return out


def _check_task(lab: str, source: str) -> int | None:
    """N for a cell that runs ``check(lab, task=N)``, else None."""
    m = re.search(rf'^check\("{lab}", task=(\d+)\)', source, re.M)
    return int(m.group(1)) if m else None


#: The cell between the two runs of one kernel (:func:`_execute`): the state a student's fresh kernel
#: would not have goes (every name the notebook defined or imported, ``Out``), and the second run
#: grades and loads the other implementation (``open_lab`` and ``check()`` read ``GEOMLIB_IMPL``).
_SWITCH = """\
get_ipython().run_line_magic("reset", "-f")
__import__("os").environ["GEOMLIB_IMPL"] = {impl!r}
"""

#: The two runs of every notebook, in the order one kernel runs them: the stubs (a student's fresh
#: kernel), then the solutions.
RUNS = ("labs", "solutions")

#: Cells around the figures cell of a run: every ``panels`` call it makes, as
#: ``tests/test_lab_contracts.py`` records them (:func:`tests.test_lab_contracts.panels_spy`), into
#: a pickle for the test. The figures module the cell imports is imported first, so that its
#: ``panels`` is spied on too.
_SPY_ON = """\
__import__("importlib").import_module("{impl}.{lab}.figures")
from tests.test_lab_contracts import panels_spy as _panels_spy
_spy = _panels_spy()
_panels = _spy.__enter__()
"""
_SPY_OFF = """\
_spy.__exit__(None, None, None)
with open({path!r}, "wb") as _f:
    __import__("pickle").dump(_panels, _f)
"""


def _cells(cells: list, lab: str, impl: str) -> list:
    """The notebook's cells for a run on ``impl``: on the solutions, the check() cells are left out
    but for the first one in the notebook of :data:`PASSING_REPORT_IN`."""
    if impl == "solutions":
        checks = [c for c in cells if c.cell_type == "code" and _check_task(lab, c.source) is not None]
        keep = checks[:1] if lab == PASSING_REPORT_IN else []
        cells = [c for c in cells if c not in checks or c in keep]
    return cells


_RUNS: dict[str, dict[str, tuple[str, dict[int, dict], list]]] = {}


def _execute(path: Path, impl: str) -> tuple[str, dict[int, dict], list]:
    """The notebook's run on ``impl`` (``"labs"`` or ``"solutions"``): its cells' printed text,
    ``{task: results}`` of its check() cells and the figures it showed (:func:`_figures`).

    Both runs of a notebook share one kernel, started once (a kernel and the notebook's imports:
    about 2 s of CPU; the grading sandbox too, where both runs grade): the stubs run first, as in a
    student's fresh kernel, then :data:`_SWITCH` and the run on the solutions (:func:`_cells`).
    A cell that fails in either run fails both tests of the notebook (nbclient's error names the
    cell)."""
    if path.stem not in _RUNS:
        _RUNS[path.stem] = _execute_both(path)
    runs = _RUNS[path.stem]
    got = runs.pop(impl)
    if not runs:
        del _RUNS[path.stem]
    return got


def _execute_both(path: Path) -> dict[str, tuple[str, dict[int, dict], list]]:
    import copy
    import os

    import nbformat
    from nbclient import NotebookClient

    lab = path.stem
    nb = nbformat.read(path, as_version=4)
    assert not any(c.get("outputs") for c in nb.cells if c.cell_type == "code"), f"{path.name} is stored with outputs"
    parts = {}
    cells = []
    spied = tempfile.TemporaryDirectory(prefix="panels-")
    for impl in RUNS:
        switch = [nbformat.v4.new_code_cell(_SWITCH.format(impl=impl))] if cells else []
        run = [copy.deepcopy(c) for c in _cells(nb.cells, lab, impl)]
        at = [i for i, c in enumerate(run) if c.cell_type == "code" and "make_figures(" in c.source]
        assert len(at) == 1, f"{path.name}: {len(at)} cells call make_figures"
        run[at[0] : at[0] + 1] = [
            nbformat.v4.new_code_cell(_SPY_ON.format(impl=impl, lab=lab)),
            run[at[0]],
            nbformat.v4.new_code_cell(_SPY_OFF.format(path=str(Path(spied.name, impl)))),
        ]
        reports = nbformat.v4.new_code_cell(_REPORTS)
        parts[impl] = (run, reports)
        cells += [*switch, *run, reports]
    nb.cells = cells
    scratch = Path(tempfile.gettempdir())
    before = set(scratch.glob(f"{lab}_*"))
    saved = {k: os.environ.get(k) for k in ("GEOMLIB_IMPL", "GEOMLIB_NO_FEEDBACK_PICTURES")}
    os.environ["GEOMLIB_IMPL"] = RUNS[0]
    os.environ["GEOMLIB_NO_FEEDBACK_PICTURES"] = "1"  # none expected; none left in notebooks/
    try:
        NotebookClient(
            nb,
            timeout=CELL_TIMEOUT,
            kernel_name="python3",
            kernel_manager_class=_Kernel,
            resources={"metadata": {"path": str(ROOT / "notebooks")}},
        ).execute()
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    # A folder the kernel's last cells still wrote into goes when the kernel process exits (the
    # TemporaryDirectory's finaliser), which nbclient does not wait for: wait for that, for hangs only.
    deadline = time.monotonic() + 60
    while (left := sorted(set(scratch.glob(f"{lab}_*")) - before)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not left, f"{path.name} leaves {[str(p) for p in left]} behind (a student runs it again and again)"
    out = {}
    for impl in RUNS:
        run, reports_cell = parts[impl]
        last = "".join(o.get("text", "") for o in reports_cell.outputs)
        by_count = json.loads(last.split("@@reports", 1)[1])
        reports = {}
        for c in run:
            task = _check_task(lab, c.source) if c.cell_type == "code" else None
            if task is not None:
                assert str(c.execution_count) in by_count, f"{path.name}: check(task={task}) returned no report"
                reports[task] = by_count[str(c.execution_count)]
        text = "".join(o.get("text", "") for c in run if c.cell_type == "code" for o in c.get("outputs", []))
        out[impl] = (text, reports, _figures(run))
    with spied:
        panels = {impl: pickle.loads(Path(spied.name, impl).read_bytes()) for impl in RUNS}
    # the stubs' panels with the solutions' (tests.test_lab_contracts.stub_panel_problems)
    out["labs"] = (*out["labs"], panels)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path):
    """On the solutions: every cell but the check() cells runs; in one notebook the first check()
    cell runs too and reports full marks."""
    _, reports, figures = _execute(path, "solutions")
    assert figures, f"{path.name}: the figures cell showed no figure"
    missing = [f"{name}: {caption[:200]}" for name, caption, _ in figures if "not implemented yet" in caption]
    assert not missing, f"{path.name}: figures of the solutions with a missing task:\n" + "\n".join(missing)
    if path.stem != PASSING_REPORT_IN:
        assert not reports, f"{path.name}: check() cells run {sorted(reports)}"
        return
    assert len(reports) == 1, f"{path.name}: check() cells run {sorted(reports)}"
    ((task, r),) = reports.items()
    assert r["tests"], f"check({path.stem!r}, task={task}) graded nothing"
    failed = [f"{t['name']}: {t['output'][:300]}" for t in r["tests"] if t["score"] < t["max_score"]]
    assert not failed, f"the solutions lose points in check({path.stem!r}, task={task}):\n" + "\n".join(failed)


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_on_the_stubs(path):
    """As in the student bundle before any work: every cell runs, the missing tasks are named (in
    the figures too: :func:`tests.test_lab_contracts.untouched_stub_figure_problems`; every panel
    the solution's or saying what is missing: :func:`tests.test_lab_contracts.stub_panel_problems`), and
    every task's check() scores 0 with no failure other than "not implemented yet" (a stub that
    fails for another reason, an error in the grader or in a given helper, shows here), and names
    no later task than its own (:func:`_later_tasks_named`)."""
    from geomlib.grading import tasks
    from geomlib.grading.results import validate_results

    lab = path.stem
    from tests.test_lab_contracts import (
        notebook_draws_the_quick_figures,
        stub_panel_problems,
        untouched_stub_figure_problems,
    )

    text, reports, figures, panels = _execute(path, "labs")
    assert "not implemented yet" in text
    problems = untouched_stub_figure_problems(lab, figures)
    if notebook_draws_the_quick_figures(lab):  # else test_lab_contracts draws them itself
        problems += stub_panel_problems(lab, panels["labs"], lambda: panels["solutions"])
    assert not problems, f"{path.name}, figures cell:\n" + "\n".join(problems)
    assert set(reports) == set(tasks.table(lab).titles), f"{path.name}: check() reports for tasks {sorted(reports)}"
    pointed = {}
    for task, r in sorted(reports.items()):
        validate_results(r)
        assert r["score"] == 0, (task, [t["name"] for t in r["tests"] if t["score"]])
        pointed.update({t["name"]: t for t in r["tests"] if t["max_score"] > 0})
    assert pointed, f"{lab}: no graded test with points"
    bad = [t for t in pointed.values() if "not implemented yet" not in t["output"]]
    assert not bad, "stub tests that fail for another reason than 'not implemented yet':\n" + "\n".join(
        f"{t['name']}: {t['output'][:300]}" for t in bad
    )
    later = _later_tasks_named(lab, reports)
    assert not later, "\n".join(later)


def _later_tasks_named(lab: str, reports: dict[int, dict]) -> list[str]:
    """The tests of ``check(lab, task=N)`` on the untouched stubs whose message names a later task
    than N (a student working in order has not reached it): ``--task N`` runs the tests whose latest
    task is N (:func:`geomlib.grading.tasks.selects`). Remeshing's split-bumpy-sphere runs Task 1's
    split through Task 4's split_long_edges and said "Task 4" under ``--task 1``. A task with no
    test of its own runs the tests of the functions that run it, and says so: those are later
    tasks' tests, and are left out. This is the suite's one grading of every lab's stubs task by
    task (``tests/framework/test_task_selection.py`` checks which tests each task selects)."""
    from geomlib.grading.results import plain_text
    from geomlib.taskref import find_task

    problems = []
    for task, r in sorted(reports.items()):
        if "has no test of its own" in plain_text(r["output"]):
            continue
        for t in r["tests"]:
            msg = plain_text(t["output"])
            m = find_task(msg)
            if m is not None and m.number > task:
                problems.append(f"{lab}: check(task={task}) runs {t['name']}, which says: {msg[:150]}")
    return problems


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_setup_is_one_call_and_every_task_has_a_check_cell(path):
    """The first code cell opens the lab with one call (no copy of the set-up code in nine notebooks),
    and each task of the handout's table has a cell that runs ``check(lab, task=N)``."""
    from geomlib.grading import tasks

    lab = path.stem
    cells = ["".join(c["source"]) for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code"]
    setup = cells[0]
    assert re.search(rf'^\w+, tasks_done = open_lab\("{lab}"\)$', setup, re.M), setup
    assert "def tasks_done" not in setup and "sys.path" not in setup and "load_lab" not in setup, setup
    checked = {int(n) for c in cells for n in re.findall(rf'^check\("{lab}", task=(\d+)\)', c, re.M)}
    assert checked == set(tasks.table(lab).titles), f"{path.name}: check() cells for tasks {sorted(checked)}"
