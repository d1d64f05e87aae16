"""A submission edited between two gradings in one process is graded on its new code (issue #24).

A notebook's zygote lives for the whole Python session, and ``check()`` / ``geomlib grade`` / the
audit grade many times in it. What a worker runs comes from a snapshot of the submission's folder,
from numba's cache of compiled kernels and from the zygote's parsed stubs: none of them may serve
the code of an earlier grading once a file changed, however it changed (its modification time put
back with ``os.utime``, its size kept, a constant changed so that the bytecode stays the same).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from geomlib.grading import impl as _impl
from geomlib.grading.sandbox import LabProxy

from .course import NUMBA_TASK_AND_GIVEN_KERNEL

ROOT = _impl.course_root()


def _edit(path: Path, old: str, new: str, *, keep_mtime: bool) -> None:
    """Replace ``old`` by ``new`` in ``path``; with ``keep_mtime`` the modification time is put back."""
    st = path.stat()
    text = path.read_text()
    assert old in text, f"{old!r} not in {path}"
    path.write_text(text.replace(old, new))
    if keep_mtime:
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
        assert path.stat().st_mtime_ns == st.st_mtime_ns


# ------------------------------------------------------------------------ plain Python, LabProxy


@pytest.mark.parametrize(
    "new, keep_mtime",
    [("x * 3 + 100", False), ("x * 3 + 100", True), ("x * 3", True)],
    ids=["edited", "mtime-restored", "same-size-and-mtime"],
)
def test_a_call_after_an_edit_runs_the_edited_file(tmp_path, new, keep_mtime):
    d = tmp_path / "editlab"
    d.mkdir()
    (d / "ops.py").write_text("def f(x):\n    return x * 2\n")
    lab = LabProxy("editlab", d, timeout=60)
    assert lab.f(5) == 10
    _edit(d / "ops.py", "x * 2", new, keep_mtime=keep_mtime)
    assert lab.f(5) == eval(new, {"x": 5}), "the second call ran the file as it was before the edit"
    _edit(d / "ops.py", new, "x * 2", keep_mtime=keep_mtime)
    assert lab.f(5) == 10, "the call after restoring the file did not run the restored file"


def test_a_new_file_and_a_removed_file_are_seen(tmp_path):
    d = tmp_path / "addlab"
    d.mkdir()
    (d / "ops.py").write_text("def f(x):\n    return x\n")
    lab = LabProxy("addlab", d, timeout=60)
    assert lab.f(1) == 1
    (d / "more.py").write_text("def g(x):\n    return -x\n")
    assert lab.g(2) == -2
    (d / "more.py").unlink()
    with pytest.raises(Exception, match="could not find a function named 'g'"):
        lab.g(2)


# ------------------------------------------------------------------------ check(), as a notebook calls it

_NOTEBOOK = r"""
import json, os, shutil, sys
from pathlib import Path
from geomlib.grading import check

sub = Path(sys.argv[1])
shutil.copytree(Path(sys.argv[2]) / "solutions" / "subdivision", sub / "subdivision")
loop = sub / "subdivision" / "loop.py"
text = loop.read_text()
st = loop.stat()
# One constant of Task 2 (even vertices), same length: the source keeps its size.
broken = text.replace("3.0 / 16.0", "3.0 / 17.0")
assert broken != text and len(broken) == len(text)

def score():
    return check("subdivision", task=2, impl=str(sub), feedback_dir="").score

scores = {"first": score()}
for how in ("edited", "mtime-restored"):
    loop.write_text(broken)
    if how == "mtime-restored":  # size and modification time as before: only the bytes differ
        os.utime(loop, ns=(st.st_atime_ns, st.st_mtime_ns))
    scores[how] = score()
    loop.write_text(text)
    if how == "mtime-restored":
        os.utime(loop, ns=(st.st_atime_ns, st.st_mtime_ns))
    scores[how + " then restored"] = score()
print(json.dumps(scores))
"""


def test_check_twice_in_one_session_grades_the_edited_lab(tmp_path):
    """The notebook's ``check("subdivision", task=2)``, run again in the same Python process after the
    student broke a constant of Task 2 (also with the file's size and modification time kept), loses
    the task's points, and gets them back when the file is restored."""
    p = subprocess.run(
        [sys.executable, "-c", _NOTEBOOK, str(tmp_path / "sub"), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=900,
        cwd=ROOT,
        env={**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1"},
    )
    assert p.returncode == 0, p.stderr[-3000:]
    scores = json.loads(p.stdout.strip().splitlines()[-1])
    full = scores["first"]
    assert full > 0
    for how in ("edited", "mtime-restored"):
        assert scores[how] < full, f"{how}: the broken Task 2 kept its points ({scores})"
        assert scores[how + " then restored"] == full, f"{how}: restoring the file did not restore the score ({scores})"


# ------------------------------------------------------------------------ numba kernels

KERNEL = """
from numba import njit

from geomlib.jit import use_cache_folder

use_cache_folder(__name__, __file__)


@njit(cache=True)
def scale(x):
    return 2.0 * x


def f(x):
    return scale(x)
"""


def test_a_kernel_changed_with_its_size_and_mtime_kept_is_compiled_again(tmp_path):
    """numba's cache knows a source by path, modification time and size, and its key holds the
    bytecode, which a changed constant leaves alone: none of them may let the grader run the old kernel."""
    d = tmp_path / "jitedit"
    d.mkdir()
    (d / "kernels.py").write_text(KERNEL)
    lab = LabProxy("jitedit", d, timeout=120)
    assert lab.f(1.5) == 3.0
    _edit(d / "kernels.py", "2.0 * x", "5.0 * x", keep_mtime=True)
    assert lab.f(1.5) == 7.5, "the grader ran the kernel compiled before the edit"
    _edit(d / "kernels.py", "5.0 * x", "2.0 * x", keep_mtime=True)
    assert lab.f(1.5) == 3.0


STUB_KERNELS = (
    "\n"
    + NUMBA_TASK_AND_GIVEN_KERNEL
    + '''

def run(x):
    """Given: calls the given kernel, which calls the student's."""
    return driver(x)
'''
)


STUDENT_KERNELS = """
from numba import njit


@njit(cache=True)
def scale(x):
    return {k} * x
"""


def test_given_kernels_that_call_a_submissions_kernel_are_compiled_per_submission(tmp_path, monkeypatch):
    """A given kernel (the course's stub) that calls a task kernel links the submission's machine
    code into its own; numba keys its cache on the stub's file only. Mutants graded one after another
    in one process (the audit), or one submission edited in place, must each run their own kernel."""
    stubs = tmp_path / "stubs"
    (stubs / "jitmerge").mkdir(parents=True)
    (stubs / "jitmerge" / "kernels.py").write_text(STUB_KERNELS)
    monkeypatch.setenv("GEOMLIB_STUBS", str(stubs))
    subs = []
    for k in ("2.0", "3.0"):  # same size, same bytecode: only a constant differs
        d = tmp_path / f"sub{k[0]}" / "jitmerge"
        d.mkdir(parents=True)
        (d / "kernels.py").write_text(STUDENT_KERNELS.format(k=k))
        subs.append(d)
    assert LabProxy("jitmerge", subs[0], timeout=120).run(1.5) == 4.0
    assert LabProxy("jitmerge", subs[1], timeout=120).run(1.5) == 5.5, "the given kernel ran another submission's"
    _edit(subs[0] / "kernels.py", "2.0 * x", "7.0 * x", keep_mtime=True)
    assert LabProxy("jitmerge", subs[0], timeout=120).run(1.5) == 11.5, "the given kernel ran the code before the edit"
