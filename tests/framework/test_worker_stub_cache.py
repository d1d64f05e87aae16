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
    caches = (worker._TREES, worker._STUB_STAT, worker._STUB_CODE, worker._STUB_NAMES)
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
