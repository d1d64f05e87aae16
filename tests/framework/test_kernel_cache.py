"""The course's own kernels are compiled once per content across grading processes (issue #25, item 5).

Every grading process (``geomlib grade``, a notebook's ``check()``, an xdist worker) used to copy
the lab into a fresh snapshot with a fresh numba cache and compile its kernels again. Trusted code
(the course's ``solutions/`` and ``labs/``) now keeps its snapshot and compiled kernels in a
per-user cache keyed by content (:mod:`geomlib.grading.kernelcache`); submissions keep a private one.

Each check runs a fresh grading process on a small course with one task kernel (``scale``: changing
its constant leaves its bytecode, which numba's key holds, alone) and one given kernel of the stubs
that calls it (``driver``). The lab's given ``probe`` returns ``driver``'s value and numba's own
count of cache misses (a compile) and hits (a load) in that worker.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from .course import NUMBA_TASK_AND_GIVEN_KERNEL

STUB = (
    '"""A lab with one task kernel and one given kernel that calls it."""\n\nimport numpy as np\n'
    + NUMBA_TASK_AND_GIVEN_KERNEL
    + '''

def probe(x):
    """Given: driver(x), then numba's cache misses and hits of the given kernel in this worker."""
    v = driver(x)
    return np.array([v, sum(driver.stats.cache_misses.values()), sum(driver.stats.cache_hits.values())])
'''
)

SOLUTION = STUB.replace('    raise NotImplementedError("Task 1 (scale)")', "    return 2.0 * x")

#: One grading process: ``probe(1.5)`` of the lab folder argv[1], then what it wants to know.
GRADE = """
import json, sys
from pathlib import Path
from geomlib.grading import sandbox
lab = sandbox.LabProxy("jitlab", Path(sys.argv[1]), timeout=300)
value, misses, hits = lab.probe(1.5).tolist()
out = {"value": value, "misses": misses, "hits": hits, "landlock": sandbox._zygote().landlock}
if len(sys.argv) > 2:
    out["wrote"] = lab.attack(sys.argv[2]).tolist()
print(json.dumps(out))
"""

#: A submission's own module: try to plant a file in every folder under ``cache``.
ATTACK = '''import numpy as np


def attack(cache):
    """Not a task: returns how many folders of the shared cache it could write a file into."""
    import os

    n = 0
    for dirpath, _, _ in os.walk(cache):
        try:
            with open(os.path.join(dirpath, "planted.nbi"), "wb") as f:
                f.write(b"x")
            n += 1
        except OSError:
            pass
    return np.array([n])
'''


def _new_course(base: Path) -> Path:
    root = base / "course"
    (root / "labs" / "jitlab").mkdir(parents=True)
    (root / "solutions" / "jitlab").mkdir(parents=True)
    (root / "labs" / "jitlab" / "kernels.py").write_text(STUB)
    (root / "solutions" / "jitlab" / "kernels.py").write_text(SOLUTION)
    # A module of the submission's in test_a_submission_is_neither_served_from_nor_written_into...:
    # in the course's solution from the start, so that submission is the solution byte for byte.
    (root / "solutions" / "jitlab" / "attack.py").write_text(ATTACK)
    return root


@pytest.fixture(scope="module")
def filled(tmp_path_factory) -> dict:
    """The course, its shared cache filled by two grading processes of the solution started at once.

    Each of the three scenarios below starts from a cache the solution has filled: one filling (two
    processes, two compiles) serves them all, and each checks what it is about from there (a grading
    process with a numba compile costs about 2.5 s of CPU; each scenario filled its own before).
    ``course``; ``first``: the two processes' answers; ``entries``, ``tmp`` and ``files``: the cache
    right after (its entry folders, its half-written files, :func:`cache_files`)."""
    course = _new_course(tmp_path_factory.mktemp("kcache"))
    env = {
        **os.environ,
        "GEOMLIB_ROOT": str(course),
        "GEOMLIB_KERNEL_CACHE": str(course.parent / "cache"),
        "GEOMLIB_SANDBOX_USER": "",
    }
    env.pop("NUMBA_CACHE_DIR", None)
    solution = course / "solutions" / "jitlab"
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", GRADE, str(solution)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
        )
        for _ in range(2)
    ]
    first = []
    for p in procs:
        out, err = p.communicate(timeout=600)
        assert p.returncode == 0, err.decode()[-3000:]
        first.append(json.loads(out.decode().strip().splitlines()[-1]))
    cache = course.parent / "cache"
    return {
        "course": course,
        "first": first,
        "entries": [p for p in cache.iterdir() if p.is_dir()],
        "tmp": list(cache.rglob("*.tmp")),
        "files": cache_files(course),
    }


def grade(course: Path, lab_dir: Path, *extra: str) -> dict:
    env = {
        **os.environ,
        "GEOMLIB_ROOT": str(course),
        "GEOMLIB_KERNEL_CACHE": str(course.parent / "cache"),
        "GEOMLIB_SANDBOX_USER": "",  # workers run as the grading user: the case that shares
    }
    env.pop("NUMBA_CACHE_DIR", None)
    p = subprocess.run(
        [sys.executable, "-c", GRADE, str(lab_dir), *extra], env=env, capture_output=True, text=True, timeout=600
    )
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def cache_files(course: Path) -> dict[str, tuple]:
    """Every file of the shared cache (its lock files aside) with its inode, size and modification time."""
    out = {}
    for p in (course.parent / "cache").rglob("*"):
        if p.is_file() and p.name != ".lock":
            st = p.stat()
            out[str(p)] = (st.st_ino, st.st_size, st.st_mtime_ns)
    return out


def test_a_changed_constant_gets_its_own_compile_and_result_and_the_old_code_its_own_kernels(filled):
    course = filled["course"]
    solution = course / "solutions" / "jitlab" / "kernels.py"
    assert [f["value"] for f in filled["first"]] == [4.0, 4.0]  # the first version, compiled and kept
    text = solution.read_text()
    st = solution.stat()
    solution.write_text(text.replace("2.0 * x", "3.0 * x"))  # same size, same bytecode (co_code)
    os.utime(solution, ns=(st.st_atime_ns, st.st_mtime_ns))
    try:
        changed = grade(course, solution.parent)
    finally:  # the other scenarios grade this solution
        solution.write_text(text)
        os.utime(solution, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert changed["value"] == 5.5, f"the kernel compiled for 2.0 * x ran: {changed}"
    assert changed["misses"] == 1, changed
    back = grade(course, solution.parent)
    assert (back["value"], back["misses"], back["hits"]) == (4.0, 0, 1), f"the first version was not kept: {back}"


def test_a_submission_is_neither_served_from_nor_written_into_the_shared_cache(filled):
    course = filled["course"]
    solution = course / "solutions" / "jitlab"  # its kernels are in the shared cache (the fixture)
    kept = cache_files(course)
    # The course's solution byte for byte (attack.py included), but not the course's folder: untrusted.
    sub = course.parent / "submission" / "jitlab"
    shutil.rmtree(sub.parent, ignore_errors=True)
    shutil.copytree(solution, sub)
    cache = course.parent / "cache"
    out = grade(course, sub, str(cache))
    assert out["value"] == 4.0 and out["misses"] == 1, f"a submission was served the course's kernels: {out}"
    if not out["landlock"]:  # then student code can write whatever the grading user can (status() says so)
        pytest.skip("no Landlock here: the worker's writes are not confined")
    assert out["wrote"] == [0], "a submission's worker could write into the shared kernel cache"
    assert cache_files(course) == kept, "grading a submission changed the shared kernel cache"
    again = grade(course, solution)
    assert (again["value"], again["misses"], again["hits"]) == (4.0, 0, 1), again


def test_two_processes_fill_the_cache_at_once_and_a_third_compiles_nothing(filled):
    """numba writes each file by ``os.replace`` but extends an index by load-modify-save, unlocked:
    the grader publishes under a lock, first index wins. A later process loads, compiles nothing and
    writes nothing. The two processes at once are the fixture's."""
    course = filled["course"]
    for first in filled["first"]:
        assert (first["value"], first["misses"]) == (4.0, 1), first
    assert len(filled["entries"]) == 1, f"one content, one entry: {filled['entries']}"
    assert not filled["tmp"], "a half-written file was left"
    assert any(p.endswith(".nbc") for p in filled["files"]), f"nothing compiled was kept: {sorted(filled['files'])}"
    kept = cache_files(course)
    third = grade(course, course / "solutions" / "jitlab")
    assert (third["value"], third["misses"], third["hits"]) == (4.0, 0, 1), f"a later process compiled again: {third}"
    assert cache_files(course) == kept, "a process that compiled nothing wrote into the cache"


def test_as_root_with_a_sandbox_user_nothing_is_shared_and_grading_works():
    """The autograder and grade-all run student code as ``nobody``, who can read neither the grading
    user's cache nor (rightly) write into what the course's code later loads: each run compiles in its
    private per-snapshot cache, as before, and the persistent cache is not even made."""
    import tempfile

    from .course import sandbox_python, sandbox_user_problem

    if (why := sandbox_user_problem("nobody")) is not None:
        pytest.skip(why)
    python, extra = sandbox_python("nobody")
    base = Path(tempfile.mkdtemp(prefix="geomlib-kcache-"))
    try:
        base.chmod(0o755)  # the sandbox user must read the course
        root = base / "course"
        for folder, text in (("labs", STUB), ("solutions", SOLUTION)):
            (root / folder / "jitlab").mkdir(parents=True)
            (root / folder / "jitlab" / "kernels.py").write_text(text)
        env = {**os.environ, "GEOMLIB_ROOT": str(root), "GEOMLIB_KERNEL_CACHE": str(base / "cache")}
        env.update(GEOMLIB_SANDBOX_USER="nobody", **extra)
        env.pop("NUMBA_CACHE_DIR", None)
        p = subprocess.run(
            [python, "-c", GRADE, str(root / "solutions" / "jitlab")],
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-3000:]
        out = json.loads(p.stdout.strip().splitlines()[-1])
        assert (out["value"], out["misses"]) == (4.0, 1), out
        assert not (base / "cache").exists(), "a cache the sandbox user's workers would feed was made"
    finally:
        shutil.rmtree(base, ignore_errors=True)
