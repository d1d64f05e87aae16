"""The zygote parses and compiles the course's stubs once (``worker.prepare_stubs``) and every worker it
forks starts with them: the merged module runs those code objects, they stay "given" code for the
blacklist, and a stub edited on disk is read again (a notebook's zygote lives for the session)."""

from __future__ import annotations

import os
import sys
import textwrap

import pytest

from geomlib.grading import blacklist, worker
from geomlib.grading.sandbox import LabProxy

STUB = '''
SCALE = {scale}


def given_helper(x):
    """Given code: the course's version is used."""
    return SCALE * x


def task(x):
    """Task 1."""
    raise NotImplementedError("Task 1 (the task)")
'''

STUDENT = """
def given_helper(x):
    return -1


def task(x):
    return given_helper(x) + 1
"""


def _write(folder, text):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "ops.py").write_text(textwrap.dedent(text))


@pytest.fixture
def fresh_cache():
    caches = (
        worker._TREES,
        worker._STUB_STAT,
        worker._STUB_CODE,
        worker._STUB_NAMES,
        worker._STUB_DEFINES,
        worker._STUB_PREFIX,
        worker._MERGED,
    )
    saved = [dict(d) for d in caches]
    for d in caches:
        d.clear()
    yield
    for d, old in zip(caches, saved, strict=True):
        d.clear()
        d.update(old)


def test_the_merged_module_runs_the_stub_code_compiled_ahead(tmp_path, fresh_cache):
    stubs, student = tmp_path / "stubs" / "toy", tmp_path / "sub" / "toy"
    _write(stubs, STUB.format(scale=3))
    _write(student, STUDENT)
    worker.prepare_stubs(str(stubs))
    tree = worker._parsed(stubs / "ops.py", student=False)
    helper_stmt = next(s for s in tree.body if getattr(s, "name", "") == "given_helper")
    ahead = worker._STUB_CODE[id(helper_stmt)]
    try:
        fn = worker.find_function(student, "toy", "task", stubs)
        assert fn(2) == 7  # the course's helper (3 * 2), not the submission's (-1)
        helper = sys.modules[fn.__module__].given_helper
        assert helper.__code__ in ahead.co_consts  # the code compiled in the zygote, not compiled again
        assert id(helper.__code__) in blacklist._GIVEN  # and still given code for the blacklist
    finally:
        for name in [m for m in sys.modules if m.startswith("_graded_toy")]:
            del sys.modules[name]
        sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, worker._LabFinder)]


def test_a_stub_edited_on_disk_is_read_again(tmp_path, fresh_cache):
    stubs = tmp_path / "stubs" / "toy"
    _write(stubs, STUB.format(scale=3))
    worker.prepare_stubs(str(stubs))
    first = worker._parsed(stubs / "ops.py", student=False)
    _write(stubs, STUB.format(scale=30) + "\n# edited\n")
    os.utime(stubs / "ops.py", ns=(1, 1))
    worker.prepare_stubs(str(stubs))
    again = worker._parsed(stubs / "ops.py", student=False)
    assert again is not first
    assert "30" in worker.ast.unparse(again)


def test_a_sandboxed_call_sees_the_stub_as_it_is_now(tmp_path, monkeypatch):
    """Through the zygote: the same long-lived sandbox, the stub changed between two calls."""
    stubs_root, student = tmp_path / "stubs", tmp_path / "sub" / "toy"
    _write(stubs_root / "toy", STUB.format(scale=3))
    _write(student, STUDENT)
    monkeypatch.setenv("GEOMLIB_STUBS", str(stubs_root))
    lab = LabProxy("toy", student)
    assert lab.task(2) == 7
    _write(stubs_root / "toy", STUB.format(scale=5) + "\n# edited\n")
    assert lab.task(2) == 11


def test_a_stub_changed_with_its_size_and_mtime_kept_is_read_again(tmp_path, monkeypatch):
    """The zygote's stub trees and code are known by the stub's bytes, not by its size and mtime."""
    stubs_root, student = tmp_path / "stubs", tmp_path / "sub" / "toy"
    stub = stubs_root / "toy" / "ops.py"
    _write(stubs_root / "toy", STUB.format(scale=3))
    _write(student, STUDENT)
    monkeypatch.setenv("GEOMLIB_STUBS", str(stubs_root))
    lab = LabProxy("toy", student)
    assert lab.task(2) == 7
    st = stub.stat()
    _write(stubs_root / "toy", STUB.format(scale=5))
    os.utime(stub, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert (stub.stat().st_size, stub.stat().st_mtime_ns) == (st.st_size, st.st_mtime_ns)
    assert lab.task(2) == 11, "the zygote ran the stub's code as it was before the change"


VALIDATED_STUB = '''
def checked(x):
    """Given validation."""
    if x < 0:
        raise ValueError("task: x must be >= 0")
    return x


def task(x):
    """Task 1."""
    x = checked(x)
    raise NotImplementedError("Task 1 (the task)")
'''

NO_VALIDATION = """


def task(x):
    return 2 * x
"""


def test_the_stubs_validation_prefix_is_worked_out_in_the_zygote(tmp_path, fresh_cache, monkeypatch):
    """A worker merges every task of a module at every call; the stub's side of it (the validation
    prefix of each task and its ``ast.dump``) comes worked out from the zygote (prepare_stubs), so a
    worker does not walk the stub's functions again. The merge is the same: a submission that drops
    the validation still runs it, reported at its own ``def`` line."""
    stubs, student = tmp_path / "stubs" / "toy", tmp_path / "sub" / "toy"
    _write(stubs, VALIDATED_STUB)
    _write(student, NO_VALIDATION)
    worker.prepare_stubs(str(stubs))

    def walked(_fn):
        raise AssertionError("the worker walked the stub's function for its prefix again")

    monkeypatch.setattr(worker, "_task_prefix", walked)
    try:
        fn = worker.find_function(student, "toy", "task", stubs)
        assert fn(3) == 6
        with pytest.raises(ValueError, match="x must be >= 0") as e:
            fn(-1)
        assert e.traceback[-2].lineno + 1 == 4  # the check runs at the submission's `def task` line
    finally:
        for name in [m for m in sys.modules if m.startswith("_graded_toy")]:
            del sys.modules[name]
        sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, worker._LabFinder)]


def test_relocated_stub_code_is_the_deep_copy_moved_to_one_line():
    """worker._relocate (a plain recursive copy, cheaper than copy.deepcopy) gives the same tree, with
    the same positions, as a deep copy with every position moved, for every statement of every stub."""
    import ast
    import copy

    from geomlib.grading.course import course

    def deep(node, line):
        node = copy.deepcopy(node)
        for sub in ast.walk(node):
            if "lineno" in sub._attributes:
                sub.lineno = sub.end_lineno = line
                sub.col_offset = sub.end_col_offset = 0
        return node

    n = 0
    for lab in course().labs:
        for path in sorted(course().lab(lab).stubs.glob("*.py")):
            for fn in ast.parse(path.read_text()).body:
                if not isinstance(fn, ast.FunctionDef):
                    continue
                for node in [fn.args, *fn.decorator_list, *([fn.returns] if fn.returns else []), *fn.body]:
                    a, b = deep(node, 7), worker._relocate(node, 7)
                    assert ast.dump(a, include_attributes=True) == ast.dump(b, include_attributes=True), (path, fn.name)
                    assert b is not node
                    n += 1
    assert n > 1000


def test_a_stub_statement_and_a_submissions_are_the_same_code_as_ast_dump_says():
    """The merge keeps a task's validation prefix when the submission starts with the same statements;
    worker._same decides it without writing both trees out (ast.dump did, for every statement of every
    task at every call): the same answer as comparing dumps, on every stub prefix and task start
    against the solution's first statements."""
    import ast

    from geomlib.grading.course import course

    pairs = same = 0
    for lab in course().labs:
        paths = course().lab(lab)
        for stub_path in sorted(paths.stubs.glob("*.py")):
            solution = paths.solution / stub_path.name
            if not solution.is_file():
                continue
            theirs = {f.name: f for f in ast.parse(solution.read_text()).body if isinstance(f, ast.FunctionDef)}
            for fn in ast.parse(stub_path.read_text()).body:
                if not isinstance(fn, ast.FunctionDef) or fn.name not in theirs:
                    continue
                for a in worker._task_prefix(fn) + fn.body[:3]:
                    for b in theirs[fn.name].body[:6]:
                        assert worker._same(a, b) == (ast.dump(a) == ast.dump(b)), (stub_path, fn.name, ast.dump(a))
                        pairs += 1
                        same += worker._same(a, b)
    assert pairs > 5000 and 0 < same < pairs, (pairs, same)


def _unload(lab: str) -> None:
    for name in [m for m in sys.modules if m.startswith(f"_graded_{lab}")]:
        del sys.modules[name]
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, worker._LabFinder)]


def _next_worker() -> None:
    """What a new worker of the same zygote starts with: the zygote's caches, none of the last
    worker's trees of the submission."""
    for key in [k for k in worker._TREES if k[1]]:
        del worker._TREES[key]


def test_the_zygote_merges_a_snapshots_modules_once_for_all_its_workers(tmp_path, fresh_cache, monkeypatch):
    """The zygote merges and compiles the submission's module ahead (prepare_merged): a worker runs it
    without merging or compiling again, with the zygote's stub code as given code; the zygote keeps
    no tree of the submission where a worker would take it unchecked."""
    stubs, student = tmp_path / "stubs" / "toy", tmp_path / "sub" / "toy"
    _write(stubs, STUB.format(scale=3))
    _write(student, STUDENT)
    worker.prepare_stubs(str(stubs))
    worker.prepare_merged(str(stubs), str(student))
    assert str(student / "ops.py") in worker._MERGED
    assert not [k for k in worker._TREES if k[1]]

    def merged(*_):
        raise AssertionError("the worker merged and compiled the module again")

    monkeypatch.setattr(worker, "merge_module", merged)
    for _ in range(2):  # two workers of the same snapshot
        try:
            fn = worker.find_function(student, "toy", "task", stubs)
            assert fn(2) == 7  # the course's helper (3 * 2) + 1
            helper = sys.modules[fn.__module__].given_helper
            tree = worker._parsed(stubs / "ops.py", student=False)
            stmt = next(s for s in tree.body if getattr(s, "name", "") == "given_helper")
            assert helper.__code__ in worker._STUB_CODE[id(stmt)].co_consts
            assert id(helper.__code__) in blacklist._GIVEN
            assert id(fn.__code__) not in blacklist._GIVEN
        finally:
            _unload("toy")
        _next_worker()


def test_a_file_changed_since_the_zygote_merged_it_is_merged_by_the_worker(tmp_path, fresh_cache):
    """The worker compares the bytes it reads with those the zygote merged: a file changed since (its
    size and modification time put back) runs as it is now."""
    stubs, student = tmp_path / "stubs" / "toy", tmp_path / "sub" / "toy"
    _write(stubs, STUB.format(scale=3))
    _write(student, STUDENT)
    worker.prepare_stubs(str(stubs))
    worker.prepare_merged(str(stubs), str(student))
    st = (student / "ops.py").stat()
    _write(student, STUDENT.replace("+ 1", "+ 2"))
    os.utime(student / "ops.py", ns=(st.st_atime_ns, st.st_mtime_ns))
    try:
        assert worker.find_function(student, "toy", "task", stubs)(2) == 8, "the zygote's merge of the old bytes ran"
    finally:
        _unload("toy")
    _next_worker()
    _write(stubs, STUB.format(scale=5))  # and the stubs changed since: merged with the stubs as they are
    worker.prepare_stubs(str(stubs))
    try:
        assert worker.find_function(student, "toy", "task", stubs)(2) == 12
    finally:
        _unload("toy")


FORGER = """
import sys


def given_helper(x):
    return -1


def task(x):
    w = sys.modules["geomlib.grading.worker"]
    for path, ahead in list(w._MERGED.items()):  # put its own helper in place of the course's
        forged = compile("def given_helper(x):\\n    return -100\\n", path, "exec")
        w._MERGED[path] = type(ahead)(ahead.digest, ahead.tree, ahead.stub, ahead.stub_tree, (*ahead.code, (forged, True)))
    return given_helper(x) + (__file__ in w._MERGED)
"""


def test_a_worker_cannot_change_what_the_zygote_merged_for_the_next_calls(tmp_path, monkeypatch):
    """Through the zygote: the submission's module comes merged from the zygote (one entry for its
    file), and an entry a worker rewrites stays in that worker: the next call runs the course's helper."""
    stubs_root, student = tmp_path / "stubs", tmp_path / "sub" / "toy"
    _write(stubs_root / "toy", STUB.format(scale=3))
    _write(student, FORGER)
    monkeypatch.setenv("GEOMLIB_STUBS", str(stubs_root))
    lab = LabProxy("toy", student)
    assert lab.task(2) == 6 + 1  # the course's helper, and its file was merged ahead by the zygote
    assert lab.task(2) == 6 + 1, "a worker's forged entry ran in the next call"


OWN_USER = """
from .mine import offset


def given_helper(x):
    return -1


def task(x):
    return given_helper(x) + offset()
"""
OWN = '''"""The student's own module: no stub of that name."""


def offset():
    return {n}
'''


def _own_submission(tmp_path, n: int = 1):
    stubs, student = tmp_path / "stubs" / "toy", tmp_path / "sub" / "toy"
    _write(stubs, STUB.format(scale=3))
    _write(student, OWN_USER)
    (student / "mine.py").write_text(OWN.format(n=n))
    return stubs, student


def test_the_zygote_compiles_a_submissions_own_module_once_for_all_its_workers(tmp_path, fresh_cache, monkeypatch):
    """A module of the submission's own (no stub: imported whole) is compiled by the zygote
    (prepare_merged), not by each worker, which could not keep its bytecode (the snapshot is
    read-only to it) and compiled it at every call. Planted fault: prepare_merged skipping files
    without a stub (the old code) makes the worker compile mine.py and fails here."""
    import builtins

    stubs, student = _own_submission(tmp_path)
    worker.prepare_stubs(str(stubs))
    worker.prepare_merged(str(stubs), str(student))
    real_compile = builtins.compile

    def compile_here(source, filename, *args, **kwargs):
        if str(filename).endswith("mine.py"):
            raise AssertionError("the worker compiled the submission's own module again")
        return real_compile(source, filename, *args, **kwargs)

    monkeypatch.setattr(builtins, "compile", compile_here)
    for _ in range(2):  # two workers of the same snapshot
        try:
            fn = worker.find_function(student, "toy", "task", stubs)
            assert fn(2) == 6 + 1
            assert not list(student.glob("__pycache__/*")), "a worker wrote bytecode into the snapshot"
        finally:
            _unload("toy")
        _next_worker()


def test_an_own_module_changed_since_the_zygote_compiled_it_runs_as_it_is_now(tmp_path, fresh_cache):
    """The worker compares the bytes it reads with those the zygote compiled: a module of the
    submission's own changed since (size and modification time put back) runs as it is now.
    Planted fault: the loader taking the zygote's code without comparing the bytes returns 7."""
    stubs, student = _own_submission(tmp_path, n=1)
    worker.prepare_stubs(str(stubs))
    worker.prepare_merged(str(stubs), str(student))
    st = (student / "mine.py").stat()
    (student / "mine.py").write_text(OWN.format(n=5))
    os.utime(student / "mine.py", ns=(st.st_atime_ns, st.st_mtime_ns))
    try:
        assert worker.find_function(student, "toy", "task", stubs)(2) == 6 + 5, "the zygote's code of the old bytes ran"
    finally:
        _unload("toy")


def test_a_submissions_own_module_runs_in_the_sandbox(tmp_path, monkeypatch):
    """Through the zygote and its workers: the own module imported by the submission's task runs."""
    stubs_root = tmp_path / "stubs"
    _, student = _own_submission(tmp_path, n=4)
    monkeypatch.setenv("GEOMLIB_STUBS", str(stubs_root))
    lab = LabProxy("toy", student)
    assert lab.task(2) == 6 + 4
    assert lab.task(3) == 9 + 4
