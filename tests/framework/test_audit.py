"""`geomlib audit`: mutants of the solutions, graded through the sandbox, and what the report says.

The end-to-end test runs `geomlib audit --quick` on a copy of the sample course with a second lab,
``weak``: the same solution with the midpoint tests planted weak (the midpoints ``M`` are never
compared). Its does-nothing mutant of Task 2 must survive, while the same mutant of the intact lab
is killed: the audit measures the tests' power, not the solution's.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from geomlib.grading import audit, stubs
from geomlib.grading import impl as _impl

from .course import run_geomlib

LABS = sorted(p.name for p in (_impl.course_root() / "solutions").iterdir() if (p / "__init__.py").is_file())


def _changed_span(original: str, mutant: str) -> tuple[int, int]:
    """The lines that differ between two texts (trailing newlines aside): the 1-based number of the
    first line that differs, and how many lines the two share at their ends."""
    a, b = original.rstrip("\n").split("\n"), mutant.rstrip("\n").split("\n")
    head = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
    tail = 0
    while tail < min(len(a), len(b)) - head and a[-1 - tail] == b[-1 - tail]:
        tail += 1
    return head + 1, tail


@functools.cache
def _generated(lab: str) -> tuple:
    """``audit.generate(lab)`` of the course's solution (GLSL compiling: test_audit_glsl.py), made once
    for the tests below that read it (shadows': 1 s of CPU)."""
    mutants, notes = audit.generate(lab, check_glsl=False)
    return tuple(mutants), notes


@pytest.mark.parametrize("lab", LABS)
def test_every_mutant_changes_one_block_only_and_compiles(lab):
    """Mutants differ from the solution only inside their own solution block (between its BEGIN and
    END lines, so their stubs are the solution's), every Python block has mutants, ids are unique and
    every mutant compiles.

    The block is checked on the lines that differ (the first, and the lines both texts end with):
    making each mutant's stub and comparing it with the solution's (what this did before) parsed the
    whole file per mutant, 1.9 s of CPU for remeshing's 1,226 mutants, and let a mutant edit
    another block too."""
    root = _impl.course_root() / "solutions" / lab
    mutants, notes = _generated(lab)
    assert mutants, f"{lab}: no mutants"
    assert len({m.id for m in mutants}) == len(mutants), f"{lab}: duplicate mutant ids"
    blocks, _ = audit._blocks(root)
    covered = {(m.file, b.start) for m in mutants for b in blocks if b.file == m.file and b.start <= m.line < b.end}
    missing = [f"{b.file}:{b.start}" for b in blocks if (b.file, b.start) not in covered]
    assert not missing, f"{lab}: blocks without a mutant: {missing}"
    originals = {}
    for m in mutants:
        if m.file not in originals:
            originals[m.file] = ((root / m.file).read_text(), len((root / m.file).read_text().rstrip("\n").split("\n")))
        original, n_lines = originals[m.file]
        glsl = not m.file.endswith(".py")
        if not glsl and m.kind != "operator":  # generate() compiles every operator mutant, and drops those that do not
            compile(m.source, m.file, "exec", dont_inherit=True)
        src = m.source
        if m.kind == "nothing" and not glsl:
            assert audit._HELPER_SOURCE in src, m.id
            src = src.replace(audit._HELPER_SOURCE, "").rstrip("\n") + "\n"
        own = [b for b in blocks if b.file == m.file and b.start <= m.line < b.end]
        assert len(own) == 1, f"{m.id}: line {m.line} is in no solution block"
        first, shared_tail = _changed_span(original, src)
        assert own[0].start < first and shared_tail >= n_lines - own[0].end + 1, (
            f"{m.id} changes code outside its solution block (lines {own[0].start}-{own[0].end}): "
            f"from line {first}, {shared_tail} lines the same at the end"
        )
        assert m.source != original and m.diff.startswith("- "), m.id
    kinds = {m.kind for m in mutants}
    assert "operator" in kinds and "nothing" in kinds, f"{lab}: mutant kinds {kinds}"


def test_operator_mutants_that_do_not_compile_are_dropped(tmp_path, monkeypatch):
    """The guard that lets the test above compile only the does-nothing mutants: generate() compiles
    each operator mutant and keeps only those that compile."""
    src = "def f(a, b):\n    # BEGIN SOLUTION: Task 1 (all): everything\n    return a + b\n    # END SOLUTION\n"
    (tmp_path / "f.py").write_text(src)
    plus = src.index("+")

    def edits(text, tree, b):  # one edit that compiles, one that does not
        yield plus, plus + 1, "-", "+ → -", 3, 13
        yield plus, plus + 1, "+ +)", "+ → broken", 3, 13

    monkeypatch.setattr(audit, "_operator_edits", edits)
    mutants, _ = audit.generate("f", tmp_path)
    assert [m.op for m in mutants if m.kind == "operator"] == ["+ → -"]


def test_operator_mutants_cover_every_listed_operator():
    src = (
        "import numpy as np\n\n\ndef f(a, b, i, ok=True):\n"
        "    # BEGIN SOLUTION: Task 1 (all): everything\n"
        "    x = a + b - 2 * a / 3.0\n"
        "    x += 1\n"
        "    y = a[i] if (a < b and b >= a) else np.maximum(a, b) + np.subtract(a, b)\n"
        "    return x, y, True\n"
        "    # END SOLUTION\n"
    )
    blocks, _ = stubs._scan(src, "f.py")
    b = audit._Block("f.py", blocks[0].start, blocks[0].end, 1, "all")
    import ast

    labels = {e[3] for e in audit._operator_edits(src, ast.parse(src), b)}
    for want in ["+ → -", "- → +", "* → /", "/ → *", "+= → -=", "< → <=", ">= → >", "True → False",
                 "2 → 0", "2 → 4", "2 → 1", "2 → 3", "3.0 → 6.0", "3.0 → 1.5", "[i] → [i + 1]",
                 "np.subtract(a, b) → np.subtract(b, a)"]:  # fmt: skip
        assert want in labels, f"{want!r} not among {sorted(labels)}"
    assert "np.maximum(a, b) → np.maximum(b, a)" not in labels, "swapping commuting arguments is equivalent"


@pytest.fixture
def two_lab_course(sample_course, tmp_path) -> Path:
    """The sample course plus ``weak``: the same lab whose midpoint tests never look at ``M``."""
    base = tmp_path / "audit"
    root = base / "course"
    shutil.copytree(sample_course, root, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(root / "solutions" / "sample", root / "solutions" / "weak")
    shutil.copytree(root / "tests" / "graded" / "sample", root / "tests" / "graded" / "weak")
    cases = root / "tests" / "graded" / "weak" / "cases.py"
    text = cases.read_text()
    assert 'checks.All(checks.Equal("E"), checks.Allclose("M"))' in text
    cases.write_text(text.replace('checks.All(checks.Equal("E"), checks.Allclose("M"))', 'checks.Equal("E")'))
    test = root / "tests" / "graded" / "weak" / "test_sample.py"
    text = test.read_text()
    start = text.index('@graded(points=1, part="midpoints")')
    end = text.index("@graded", start + 1)
    test.write_text(text[:start] + text[end:])
    # A declaration the audit must refuse: the intact lab's does-nothing mutant of Task 1 is killed.
    (root / "tests" / "graded" / "sample" / "equivalent_mutants.toml").write_text(
        '[[equivalent]]\nid = "ops.py:22:nothing-zeros"\nreason = "planted: wrongly declared"\n\n'
        '[[equivalent]]\nid = "ops.py:99:0:gone"\nreason = "planted: names no mutant"\n'
    )
    # The sample lab is built already; the weak lab's stubs are the sample's (the same solution).
    shutil.copytree(root / "labs" / "sample", root / "labs" / "weak")
    run_geomlib(root, "refs", "build", "--lab", "weak")
    for dirpath, _dirs, files in os.walk(base):
        os.chmod(dirpath, 0o755)
        for f in files:
            os.chmod(os.path.join(dirpath, f), 0o644)
    return root


@pytest.mark.slow
def test_audit_quick_reports_a_planted_weak_test(two_lab_course, tmp_path):
    out = tmp_path / "report"
    p = run_geomlib(two_lab_course, "audit", "--quick", "--jobs", "2", "--out", str(out), check=False, timeout=600)
    assert p.returncode == 1, f"a wrong equivalent declaration must fail the audit:\n{p.stdout}\n{p.stderr}"
    assert "mutants" in p.stderr and "survived" in p.stderr, "no progress bar on stderr"
    data = json.loads((out / "audit.json").read_text())
    md = (out / "audit.md").read_text()
    assert md == p.stdout.split("wrote ")[0], "audit.md differs from the table printed"
    assert set(data["labs"]) == {"sample", "weak"}
    for lab, lr in data["labs"].items():
        assert set(lr["tasks"]) == {"1", "2"}, lab
        assert lr["baseline"] == {}, f"{lab}: --quick grades no baseline (the suite checks the solutions)"
        for r in lr["mutants"]:
            assert {"id", "task", "kind", "op", "diff", "status", "score", "max"} <= set(r), r
        assert sum(t["mutants"] for t in lr["tasks"].values()) == len(lr["mutants"]) == audit.QUICK_PER_LAB
    by_id = {lab: {r["id"]: r for r in lr["mutants"]} for lab, lr in data["labs"].items()}
    # The planted weak test: the midpoints can be anything, so doing nothing survives...
    weak = by_id["weak"]["ops.py:41:nothing-zeros"]
    assert weak["status"] == "survived" and weak["score"] == weak["max"] > 0, weak
    # ...judged by the tests that run the block (found by its probe run), whose points it keeps.
    assert weak["own_tests"] >= 1 and weak["own_score"] == weak["own_max"] > 0, weak
    assert weak["kept_points"] and weak["task_status"] == "survived", weak
    assert "| weak | 2 (midpoints) |" in md and "ops.py:41:nothing-zeros" in md.split("## weak")[1]
    # ...while the intact tests kill the same mutant.
    intact = by_id["sample"]["ops.py:41:nothing-zeros"]
    assert intact["status"] == "killed" and intact["own_tests"] >= 1 and intact["own_score"] == 0, intact
    # A declared-equivalent mutant that a test kills, and a declaration naming no mutant, are errors.
    errors = "\n".join(data["labs"]["sample"]["errors"])
    assert "ops.py:22:nothing-zeros: ERROR: declared equivalent but killed" in errors, errors
    assert "'ops.py:99:0:gone', which is not a mutant" in errors, errors
    assert not data["labs"]["weak"]["errors"]
    # Deterministic sample: the same mutants every run.
    again = [m.id for m in audit.quick_sample(audit.generate("weak", two_lab_course / "solutions" / "weak")[0], "weak")]
    assert again == [r["id"] for r in data["labs"]["weak"]["mutants"]]


def test_does_nothing_is_judged_by_the_tests_that_run_the_block():
    """A does-nothing mutant's own tests are the ones its block's probe failed (not the whole
    task's); without a probe result, the tests that call the block's function or a composite of it."""
    src = "def f(x):\n    y = 1\n    # BEGIN SOLUTION: Task 1 (t): x\n    return x\n    # END SOLUTION\n"
    probe = audit._probe_source(src, 3)
    assert probe.split("\n")[3] == '    raise RuntimeError("geomlib audit: probe (this block runs)")'
    compile(probe, "f.py", "exec")
    res = {"tests": [
        {"name": "a", "score": 0, "max": 2, "calls": ["f"]},
        {"name": "b", "score": 1, "max": 1, "calls": ["g"]},  # another function of the task: not f's test
        {"name": "c", "score": 1, "max": 1, "calls": ["whole"]},  # a composite that runs f
        {"name": "d", "score": 0, "max": 0, "calls": ["f"]},  # no points: cannot tell
    ]}  # fmt: skip
    runs = {"whole": {"whole", "f"}}
    assert [t["name"] for t in audit._own_tests(res, "f", runs)] == ["a", "c"]
    assert [t["name"] for t in audit._own_tests(res, "f", runs, covered={"a", "d"})] == ["a"]
    assert audit._own_tests(res, "f", runs, covered=set()) == []


def test_a_survivor_is_graded_on_the_other_tasks_that_run_its_block(tmp_path, monkeypatch):
    """remeshing's ``split`` kernel (Task 1) is only observable through the passes and the loop
    (Tasks 4 and 10): an operator mutant its own task misses is graded there, killed when it loses
    points; a declared-equivalent one that loses points there is an error."""
    from geomlib.grading.tasks import TaskTable

    tab = TaskTable(
        tasks={"split": (1,), "split_pass": (4,), "remesh": (10,), "other": (2,)},
        composites={"split_pass": ("split",), "remesh": ("split", "split_pass"), "other": ()},
    )
    monkeypatch.setattr(audit, "_copy_lab", lambda src, dest: dest.mkdir(parents=True))
    m = audit.Mutant("k.py:1:1:+ → -", "lab", "k.py", 1, 1, "split", "operator", "+ → -", "- a\n+ b", "split", "x")
    rows = {0: {**{k: v for k, v in vars(m).items() if k != "source"}, "status": "survived", "why": ""}}
    rows[1] = {**rows[0], "id": "k.py:2:1:+ → -", "status": "equivalent"}
    report = {"labs": {"lab": {"baseline": {1: {"score": 5, "max": 5}}, "errors": []}}}
    graded = []

    class Pool:
        def run(self, requests, on_done):
            for i, r in enumerate(requests):
                r = r["prepare"]() if "prepare" in r else r
                graded.append((r.get("mutant"), r["task"]))
                lost = r.get("mutant") is not None and r["task"] == 10
                on_done(i, r, {"ok": True, "tests": [{"name": "t", "score": 0 if lost else 3, "max": 3,
                                                      "passed": not lost, "output": "min_angle = 0"}]})  # fmt: skip

    reqs = [{"mutant": m}, {"mutant": m}]
    audit._grade_elsewhere(Pool(), reqs, rows, report, {"lab": tab}, {"lab": {}}, tmp_path, False, False)
    assert sorted(t for mid, t in graded if mid is None) == [4, 10], "the solution is graded on Tasks 4 and 10 first"
    assert sorted(t for mid, t in graded if mid) == [4, 4, 10, 10]
    assert rows[0]["status"] == "killed" and rows[0]["killed_by"] == "Task 10", rows[0]
    assert rows[1]["status"].startswith("ERROR: declared equivalent but killed by Task 10"), rows[1]
    assert "killed only by the tests of another task" in audit.markdown(
        {"labs": {"lab": {"tasks": {}, "mutants": list(rows.values()), "errors": [], "notes": []}}}
    )


JIT_KERNELS = '''"""Planted lab: a given kernel that calls the task kernel (as remeshing's clean_pass calls flip)."""

from numba import njit

from geomlib.jit import use_cache_folder

use_cache_folder(__name__, __file__)


@njit(cache=True)
def scale(x):
    """Task 1: twice ``x``."""
    # BEGIN SOLUTION: Task 1 (scale): 2 x
    return 2.0 * x
    # END SOLUTION


@njit(cache=True)
def driver(x):
    return scale(x) + 1.0


def run(x):
    """Given: the given kernel, which calls the task kernel."""
    return float(driver(float(x)))
'''

JIT_TEST = '''from geomlib.grading import graded


@graded(points=1, part="scale")
def test_run_through_the_given_kernel(lab):
    """run(1.5) = 2 * 1.5 + 1 through the given kernel"""
    got = lab.run(1.5)
    assert got == 4.0, f"run(1.5) = {got!r}, expected 4.0"
'''


@pytest.mark.slow
def test_kernel_mutants_graded_in_one_zygote_each_run_their_own_kernel(sample_course, tmp_path):
    """The audit grades a numba lab's mutants one after another in one worker and one zygote (no
    new zygote per mutant: a fresh sandbox costs about 1.7 s of CPU per request). A given kernel that
    calls the task kernel links the task kernel's machine code into its own, and numba keys its
    cache on the given kernel's file only; each mutant's folder must still get its own cache, or the
    given kernel would run the solution's (graded first) or the previous mutant's task kernel and
    every mutant would survive. Each operator mutant of ``2.0 * x`` gives its own ``run(1.5)``."""
    root = tmp_path / "course"
    shutil.copytree(sample_course, root, ignore=shutil.ignore_patterns("__pycache__"))
    (root / "solutions" / "jitlab").mkdir()
    (root / "solutions" / "jitlab" / "__init__.py").write_text(
        '"""Planted numba lab."""\n\nfrom .kernels import run, scale\n\n__all__ = ["run", "scale"]\n'
    )
    (root / "solutions" / "jitlab" / "kernels.py").write_text(JIT_KERNELS)
    (root / "tests" / "graded" / "jitlab").mkdir()
    (root / "tests" / "graded" / "jitlab" / "__init__.py").write_text('"""Planted numba lab graded tests."""\n')
    (root / "tests" / "graded" / "jitlab" / "test_jitlab.py").write_text(JIT_TEST)
    run_geomlib(root, "stubs", "build", "--lab", "jitlab")
    for dirpath, _dirs, files in os.walk(tmp_path):
        os.chmod(dirpath, 0o755)
        for f in files:
            os.chmod(os.path.join(dirpath, f), 0o644)
    assert audit._jit_request(root / "solutions" / "jitlab") == {"time_limit": audit.COMPILED_CALL_LIMIT}
    out = tmp_path / "report"
    p = run_geomlib(root, "audit", "--lab", "jitlab", "--kind", "operator", "--jobs", "1", "--out", str(out),
                    check=False, timeout=600)  # fmt: skip
    data = json.loads((out / "audit.json").read_text())
    lr = data["labs"]["jitlab"]
    assert lr["baseline"]["1"]["score"] == lr["baseline"]["1"]["max"] == 1, (lr["baseline"], p.stderr[-2000:])
    got = {r["op"]: r for r in lr["mutants"]}
    # 2.0 -> 0.0, 4.0, 1.0, 3.0 and * -> /: run(1.5) = 1.0, 7.0, 2.5, 5.5, 2.333... (each its own compiled scale)
    expected = {
        "2.0 → 0.0": "1.0",
        "2.0 → 4.0": "7.0",
        "2.0 → 1.0": "2.5",
        "2.0 → 3.0": "5.5",
        "* → /": "2.333333333333333",
    }
    assert set(expected) <= set(got), sorted(got)
    for op, value in expected.items():
        r = got[op]
        assert r["status"] == "killed", f"{op}: {r['status']}, graded with another version's kernel? {r['why']}"
        assert f"run(1.5) = {value}," in r["why"], f"{op} ran another mutant's kernel: {r['why']}"
    assert p.returncode == 0, p.stdout + p.stderr[-2000:]


def test_does_nothing_restores_the_objects_the_block_changes(tmp_path):
    """A block that changes an object through one of the lab's functions (simplification's greedy loop
    calls ``contract_pair(state, ...)``) does nothing only if the object is left as the block found it."""
    lab = tmp_path / "toy"
    lab.mkdir()
    (lab / "__init__.py").write_text("")
    (lab / "work.py").write_text(
        "from dataclasses import dataclass\n\nimport numpy as np\n\n\n@dataclass\nclass State:\n    x: np.ndarray\n"
        "    n: int\n\n\ndef step(state, k):\n    state.x[k] += 1.0\n    state.n -= 1\n\n\n"
        "def loop(state, times):\n    # BEGIN SOLUTION: Task 1 (loop): step times\n    for k in range(times):\n"
        "        step(state, k)\n    return state.n\n    # END SOLUTION\n"
    )
    mutants, _ = audit.generate("toy", lab, check_glsl=False)
    nothing = {m.op: m for m in mutants if m.kind == "nothing" and m.function == "loop"}
    assert set(nothing) == set(audit.NOTHING_MODES)
    for mode, m in nothing.items():
        ns = {}
        exec(compile(m.source, "work.py", "exec"), ns)
        state = ns["State"](np.zeros(3), 5)
        out = ns["loop"](state, 3)
        assert state.x.tolist() == [0.0, 0.0, 0.0] and state.n == 5, (mode, state)
        assert out == {"zeros": 0, "input": 3, "constant": 1}[mode], (mode, out)


def test_task_and_file_filters_keep_exactly_their_mutants():
    """``geomlib audit --task 11 --file shaders/`` grades the cube light pass's shader mutants only."""
    muts, _ = _generated("shadows")
    kept = audit.select_mutants(muts, tasks=[11], files=["shaders/"])
    assert kept and {m.task for m in kept} == {11}, {m.task for m in kept}
    assert {m.file for m in kept} == {"shaders/cube_depth.vert", "shaders/cube_depth.frag"}, {m.file for m in kept}
    assert len(kept) == sum(m.task == 11 and m.file.startswith("shaders/") for m in muts)
    nothing = audit.select_mutants(muts, kind="nothing", files=["lookup.py"])
    assert nothing and all(m.kind == "nothing" and "lookup.py" in m.file for m in nothing)
