"""Kernel zygotes: the course's own code starts every worker with its compiled kernels loaded.

A worker of a numba lab used to load its kernels from numba's disk cache at every call (0.03-0.1 s
of CPU each, dozens of calls per grading run). For trusted snapshots only (the course's
``solutions/`` and ``labs/``, :mod:`geomlib.grading.kernelcache`), a fork of the zygote imports the
lab and loads its kernels once and forks that snapshot's workers (:mod:`geomlib.grading.kernelzygote`).

One grading process (:data:`GRADE`) makes the calls in order and reports, per call, what the worker
found when it started: whether ``driver`` (a given kernel, called from Python) was loaded already,
numba's cache misses and hits of it, and whether numba's threading layer had been started.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from geomlib.grading import worker
from geomlib.grading.course import course as the_course

from .course import NUMBA_TASK_AND_GIVEN_KERNEL

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="kernel zygotes are Linux-only")

STUB = (
    '"""A lab with a task kernel, a given kernel that calls it and a parallel kernel."""\n\n'
    "import numpy as np\nfrom numba import prange\n"
    + NUMBA_TASK_AND_GIVEN_KERNEL
    + '''

@njit(cache=True, parallel=True)
def spread(x):
    out = np.empty(4)
    for i in prange(4):
        out[i] = x + i
    return out


@njit(cache=True)
def through(x):
    return spread(x)[3]


def _started():
    """What this worker had when it started: driver's loaded signatures, numba's threads."""
    from numba.np.ufunc import parallel

    return [len(getattr(driver, "overloads", ())), len(getattr(through, "overloads", ())), float(parallel._is_initialized)]


def probe(x):
    """Given: driver(x), then [driver loaded, through loaded, threads] at the start, misses, hits."""
    started = _started()
    v = driver(x)
    stats = getattr(driver, "stats", None)
    misses = sum(stats.cache_misses.values()) if stats else -1
    hits = sum(stats.cache_hits.values()) if stats else -1
    return np.array([v, *started, misses, hits])


def parallel_probe(x):
    """Given: through(x) (a kernel that calls a parallel one), then what the worker started with."""
    started = _started()
    return np.array([through(x), *started])
'''
)

SOLUTION = STUB.replace('    raise NotImplementedError("Task 1 (scale)")', "    return 2.0 * x")

#: A module that prints when imported: each worker imports it (what a call prints is the call's).
NOISY = '''"""Not plain: its top level prints."""

print("noisy was imported")


def fails(x):
    """Given: raises."""
    raise ValueError(f"no {x}")
'''

#: One grading process: each argument ``function:folder`` is one call with x = 1.5; prints the replies
#: (an exception's message for a call that fails).
GRADE = """
import json, sys
from pathlib import Path
from geomlib.grading import sandbox
out = []
for arg in sys.argv[1:]:
    function, folder = arg.split(":", 1)
    try:
        out.append(getattr(sandbox.LabProxy("jitlab", Path(folder), timeout=300), function)(1.5).tolist())
    except Exception as e:
        out.append(str(e))
print(json.dumps(out))
"""


def grade(course: Path, *calls: str, script: str = GRADE, **env_extra: str) -> list[list[float]]:
    env = {
        **os.environ,
        "GEOMLIB_ROOT": str(course),
        "GEOMLIB_KERNEL_CACHE": str(course.parent / "cache"),
        "GEOMLIB_SANDBOX_USER": "",  # workers run as the grading user: the case that trusts the course's code
        **env_extra,
    }
    env.pop("NUMBA_CACHE_DIR", None)
    p = subprocess.run([sys.executable, "-c", script, *calls], env=env, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def course(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("kzygote") / "course"
    for folder, text in (("labs", STUB), ("solutions", SOLUTION)):
        (root / folder / "jitlab").mkdir(parents=True)
        (root / folder / "jitlab" / "kernels.py").write_text(text)
        (root / folder / "jitlab" / "noisy.py").write_text(NOISY)
    sub = root.parent / "submission" / "jitlab"  # the solution with another constant: untrusted
    sub.mkdir(parents=True)
    (sub / "kernels.py").write_text(SOLUTION.replace("2.0 * x", "3.0 * x"))
    return root


@pytest.fixture(scope="module")
def replies(course) -> list[list[float]]:
    """One cold grading process: solution twice, the submission twice, the solution, the parallel probe
    twice, the noisy module's function."""
    solution, sub = course / "solutions" / "jitlab", course.parent / "submission" / "jitlab"
    calls = [f"probe:{solution}", f"probe:{solution}", f"probe:{sub}", f"probe:{sub}", f"probe:{solution}"]
    return grade(course, *calls, f"parallel_probe:{solution}", f"parallel_probe:{solution}", f"fails:{solution}")


def test_a_trusted_snapshot_s_worker_starts_with_its_kernels_loaded(replies):
    first, second = replies[0], replies[1]
    assert first[0] == 4.0 and first[1] == 0 and first[4] == 1, f"the first call compiles: {first}"
    # The second worker of the solution: driver was loaded before the worker started (by the kernel
    # zygote, from what the first worker compiled), in the very module object the call used.
    assert second[0] == 4.0, second
    assert second[1] == 1, f"the worker found driver not loaded: it loads it from disk again ({second})"
    assert second[4] == 0, f"the worker compiled driver again: {second}"
    assert replies[4][:2] == [4.0, 1], f"the solution's kernels after a submission's calls: {replies[4]}"


def test_a_submission_graded_between_gets_none_of_the_course_s_kernels(replies):
    for sub in replies[2:4]:
        assert sub[0] == 5.5, f"a submission's call ran the course's kernel (2 x instead of 3 x): {sub}"
        assert sub[1] == 0, f"a submission's worker started with kernels loaded (a kernel zygote's?): {sub}"
    assert replies[2][4] == 1, f"the submission's kernel was not compiled for it: {replies[2]}"


def test_no_kernel_zygote_starts_numba_s_threads_before_it_forks(replies):
    """A kernel that calls a parallel one is left to the worker: loading it starts numba's threads."""
    for reply in replies[5:7]:
        value, driver_loaded, through_loaded, threads = reply
        assert value == 4.5, reply
        assert threads == 0.0, f"the worker started with numba's threading layer running: {reply}"
        assert through_loaded == 0, f"a kernel that starts threads was loaded before the fork: {reply}"


def test_with_the_jit_off_the_trusted_lab_still_grades(course):
    (reply,) = grade(course, f"probe:{course / 'solutions' / 'jitlab'}", NUMBA_DISABLE_JIT="1")
    assert reply[0] == 4.0 and reply[4:] == [-1, -1], reply


def test_what_a_module_prints_when_imported_stays_in_the_call_s_message(replies):
    """A module that does more than define things is not imported by the kernel zygote: each worker
    imports it, so its output is the call's, as for any submission."""
    assert "ValueError" in replies[7] and "noisy was imported" in replies[7], replies[7]


@pytest.mark.parametrize(
    ("source", "plain"),
    [
        ("import numpy as np\nfrom .kernels import x\nK = 3\nT = np.array([1.0, 2.0]) / np.sqrt(2.0)\n", True),
        ('"""doc"""\nuse_cache_folder(__name__, __file__)\n\n@njit(cache=True)\ndef f(x):\n    return x\n', True),
        ("class A:\n    x = 1\n\nif __name__ == '__main__':\n    print(A)\n", True),
        ("print('hello')\n", False),
        ("X = f(3)\n", False),
        ("V, F = load_mesh('bunny.obj')\n", False),
        ("for i in range(3):\n    pass\n", False),
        ("try:\n    import scipy\nexcept ImportError:\n    pass\n", False),
    ],
)
def test_a_kernel_zygote_imports_only_modules_that_define_things(source, plain):
    assert worker._plain_top_level(ast.parse(source)) is plain


def test_the_course_s_numba_labs_are_imported_by_their_kernel_zygote():
    """Every module of remeshing and sdf but figures is plain: a worker imports none of them itself."""
    for lab in ("remeshing", "sdf"):
        for folder in (the_course().lab(lab).solution, the_course().lab(lab).stubs):
            for path in sorted(folder.glob("*.py")):
                if path.stem not in ("__init__", "figures"):
                    tree = ast.parse(path.read_text())
                    assert worker._plain_top_level(tree), f"{path}: not plain, so every worker imports it again"


#: Planted in the zygote (before its ``main``): a kernel zygote that, given a call, forks a worker
#: that writes a forged result into the call's result pipe (and says so in ``{mark}``), then hangs.
#: The zygote's wait for it is cut from 20 s to 3 s (the same constant, in the planted process only).
PLANT = r"""
import os, struct, time
import numpy as np
from geomlib.grading import wire
from geomlib.grading import kernelzygote as kz
from geomlib.grading.zygote import recv_msg, send_msg
kz.KERNEL_ZYGOTE_WAIT_S = 3.0
def _planted(sock, req, parent):
    send_msg(sock, {{"ready": True}})
    req, blob, fds = recv_msg(sock, with_fds=True)
    pid = os.fork()
    if pid == 0:
        data = b"R" + wire.encode(np.full(6, -7.0))
        os.write(fds[0], struct.pack("<Q", len(data)) + data)
        open({mark!r}, "a").write("forged\n")
        os._exit(0)
    os.waitpid(pid, 0)
    time.sleep(600)
kz._kernel_main = _planted
"""

#: :data:`GRADE`, with the zygote it starts planted with :data:`PLANT` (formatted; ``argv[1]``).
GRADE_PLANTED = (
    """
import subprocess, sys
from geomlib.grading import sandbox
_plant, _real = sys.argv.pop(1), subprocess.Popen
def _popen(args, **kwargs):
    if "geomlib.grading.zygote" in args[-2]:
        args = [*args[:-2], _plant + args[-2], args[-1]]
    return _real(args, **kwargs)
sandbox.subprocess.Popen = _popen
"""
    + GRADE
)


def test_a_hung_kernel_zygote_s_worker_cannot_forge_the_result_of_the_call_served_in_its_place(course, tmp_path):
    # The zygote gives up on a kernel zygote that does not answer and serves the call itself. A
    # worker the kernel zygote forked had the call's result pipe and may have written into it before
    # it was killed: the call must be served with descriptors no such worker ever had.
    mark = tmp_path / "forged"
    solution = course / "solutions" / "jitlab"
    calls = [f"probe:{solution}"] * 3  # the first may compile (no kernel zygote before that)
    replies = grade(course, PLANT.format(mark=str(mark)), *calls, script=GRADE_PLANTED)
    assert mark.exists(), f"no kernel zygote was asked to serve a call: the plant did not run ({replies})"
    for reply in replies:
        assert reply[0] == 4.0, f"the grader read a result a hung kernel zygote's worker forged: {reply}"
