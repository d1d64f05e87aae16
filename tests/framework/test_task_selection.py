"""``--task N`` and ``check(lab, task=N)`` on the real course: every task of a handout selects its tests.

The task numbers come from each handout's task table (``labs/<lab>/README.md``); which graded
tests a task selects is what the grader's own selection plugin keeps, collected in a subprocess
(the same code path as ``geomlib grade --task N`` and ``check``).

That a task's tests on the untouched stubs name no later task (``--task 1`` listed Task 4's
"not implemented" in remeshing) is checked on the one grading of every lab's stubs task by task:
the notebooks' ``check(lab, task=N)`` cells (``tests/test_notebooks.py``, ``_later_tasks_named``).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

from geomlib.grading import impl as _impl

from .course import run_geomlib, student_copy

ROOT = _impl.course_root()

_COLLECT = r"""
import contextlib, io, json, sys
import pytest
from geomlib.grading import grade as G, impl as I
sel = G._Selection()
points = {}
runs = {}
class Points:
    def pytest_collection_modifyitems(self, items):
        from geomlib.grading import plugin, tasks
        for it in items:
            m = it.get_closest_marker("graded")
            if m is not None:
                points[it.nodeid] = m.kwargs.get("points", 1)
                tab = tasks.table(plugin.lab_of(it.path))
                runs[it.nodeid] = list(tasks.test_runs(it, tab)) if hasattr(tasks, "test_runs") else []
args = [str(I.tests_dir() / "graded" / lab) for lab in sys.argv[1:]]
args += ["--impl=labs", "--collect-only", "-q", "-p", "no:cacheprovider", f"--rootdir={I.course_root()}"]
with contextlib.redirect_stdout(io.StringIO()):
    pytest.main(args, plugins=[sel, Points()])
print(json.dumps({k: [list(sel.tasks.get(k, ())), runs[k], p] for k, p in points.items()}))
"""


def handout_tasks(lab: str) -> set[int]:
    """Task numbers of the handout's task section: table rows ``| 2 |``, ``| 1a |``, ``| 2-4 in GLSL |``
    or list items ``3. **Connectivity**``."""
    text = (ROOT / "labs" / lab / "README.md").read_text()
    m = re.search(r"^##[^\n]*tasks[^\n]*\n(.*?)(?=^## )", text, re.S | re.M | re.I)
    assert m, f"labs/{lab}/README.md has no tasks section"
    out: set[int] = set()
    for line in m.group(1).splitlines():
        r = re.match(r"^\|\s*(\d+)[a-z]?(?:\s*-\s*(\d+))?\b", line) or re.match(r"^(\d+)\.\s+\*\*", line)
        if r:
            lo = int(r.group(1))
            hi = int(r.group(2)) if r.lastindex and r.lastindex >= 2 and r.group(2) else lo
            out |= set(range(lo, hi + 1))
    return out


@pytest.fixture(scope="module")
def selected() -> dict:
    """``{lab: {test id: (tasks, tasks it runs, points)}}`` for every lab, from the grader's
    selection plugin: ``--task N`` selects the tests of task N, else (a task graded only through
    a composite) the tests that run it."""
    labs = _impl.lab_names()
    p = subprocess.run([sys.executable, "-c", _COLLECT, *labs], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert p.returncode == 0, p.stderr[-3000:]
    data = json.loads(p.stdout.strip().splitlines()[-1])
    out: dict = {lab: {} for lab in labs}
    for nodeid, (tasks, runs, points) in data.items():
        lab = nodeid.split("/")[2]
        out[lab][nodeid.split("::", 1)[1]] = (tuple(tasks), tuple(runs), points)
    return out


@pytest.mark.parametrize("lab", _impl.lab_names())
def test_every_task_of_the_handout_selects_tests_and_every_test_has_a_task(lab, selected):
    from geomlib.grading import tasks as _tasks

    numbers = handout_tasks(lab)
    assert numbers == set(_tasks.table(lab).titles), f"{lab}: handout tasks {sorted(numbers)}"
    tests = selected[lab]
    assert tests, lab
    for n in sorted(numbers):
        own = [name for name, (t, _, _) in tests.items() if _tasks.selects(t, n)]
        assert own or any(n in t or n in r for t, r, _ in tests.values()), f"--task {n} selects no graded test of {lab}"
    orphans = sorted(name for name, (t, _, _) in tests.items() if not t)
    assert not orphans, f"{lab}: no --task selects {orphans}"


def test_remeshing_local_operations_and_relief_shaders_are_their_tasks(selected):
    """The handouts' tables: split (Task 1), collapse (2), flip (3); shaders/*.frag are Tasks 2-4 in GLSL."""
    mesh = selected["remeshing"]
    expected = {
        "test_split_the_diagonal_of_a_square": (1,),
        "test_split_a_boundary_edge": (1,),
        "test_collapse_on_an_octahedron": (2,),
        "test_collapse_refuses_the_link_condition": (2,),
        "test_flip_the_diagonal_of_a_square": (3,),
        "test_flip_refuses_boundary_and_tetrahedron_edges": (3,),
    }
    assert {k: mesh[k][0] for k in expected} == expected
    # split_long_edges runs Task 1's split through Task 4's pass: Task 4's test, not Task 1's
    from geomlib.grading.tasks import selects

    split = mesh["test_references[split-bumpy-sphere]"][0]
    assert 4 in split and selects(split, 4) and not selects(split, 1)
    # the collapse and flip passes are graded through the loop only: --task 5 and 6 run its tests
    loop = mesh["test_references[remesh-bumpy-sphere]"]
    assert loop[0] == (10,) and {5, 6} <= set(loop[1])
    relief = selected["relief"]
    assert {k: relief[k][0] for k in ("test_glsl_parallax", "test_glsl_relief", "test_glsl_shadow")} == {
        "test_glsl_parallax": (2,),
        "test_glsl_relief": (3,),
        "test_glsl_shadow": (4,),
    }


def test_remeshing_task_1_from_the_cli_and_from_check(tmp_path):
    """The notebook's own example, ``check("remeshing", task=1)``, and ``geomlib grade --task 1``
    on the stubs: the Task 1 tests run and say what to write."""
    cli = run_geomlib(ROOT, "grade", "--impl", "labs", "--lab", "remeshing", "--task", "1", cwd=tmp_path).stdout
    assert "no graded test" not in cli, cli
    assert "Task 1 (edge split)" in cli, cli
    # only Task 1's tests: not the split pass's (Task 4), which runs split too
    assert "split_long_edges" not in cli and "Task 4" not in cli, cli
    code = "from geomlib.grading import check\nprint(check('remeshing', task=1, impl='labs'))"
    env = {"GEOMLIB_ROOT": str(ROOT), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    p = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=600, env={**_env(), **env}
    )
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout.strip().splitlines() == cli.strip().splitlines()


def test_a_task_graded_through_the_loop_runs_the_loop_tests_and_says_so(tmp_path):
    """In the student's bundle, remeshing's Task 6 (equalize valences) has no public test of its own
    (its own checks are hidden): ``--task 6`` runs the loop's tests that call it, and says so."""
    root = student_copy("remeshing", tmp_path / "course")
    out = run_geomlib(root, "grade", "--impl", "labs", "--lab", "remeshing", "--task", "6", cwd=tmp_path).stdout
    assert out.startswith("Task 6: equalize valences has no test of its own"), out
    assert "Task 10 (the loop)" in out, out


def test_relief_glsl_tests_count_for_their_task(tmp_path):
    out = run_geomlib(ROOT, "grade", "--impl", "labs", "--lab", "relief", "--task", "2", cwd=tmp_path).stdout
    assert "shaders/parallax.frag" in out and "GLSL parallax" in out, out
    assert "relief.frag" not in out, out


def _env() -> dict:
    import os

    return dict(os.environ)


def test_public_graded_tests_do_not_import_the_hidden_cases():
    """A student's bundle has no ``cases_hidden.py``: a public test that looks a case up by id among
    public and hidden cases goes through ``registry.hidden_cases`` (shadows' and maps' GLSL tests and
    denoise's imported ``.cases_hidden`` and failed there with ModuleNotFoundError)."""
    graded = ROOT / "tests" / "graded"
    offenders = [
        str(p.relative_to(ROOT))
        for p in sorted(graded.glob("*/*.py"))
        if "hidden" not in p.name
        and re.search(r"^\s*(from\s+\.cases_hidden\s+import|import\s+.*cases_hidden)", p.read_text(), re.M)
    ]
    assert not offenders, f"public graded tests import the hidden cases: {offenders}"


def test_a_public_glsl_test_runs_in_the_students_bundle(tmp_path):
    """shadows' GLSL light pass (Task 9) graded in a student's bundle, on the solution: it passes."""
    root = student_copy("shadows", tmp_path / "course")
    out = run_geomlib(
        root, "grade", "--impl", str(ROOT / "solutions"), "--lab", "shadows", "--task", "9", cwd=tmp_path
    ).stdout
    assert "ModuleNotFoundError" not in out and "What to fix" not in out, out
