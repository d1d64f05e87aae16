"""Planted hostile submissions of the subdivision lab (issue 19, issue 13.4-13.6).

Each is the reference solution of the lab (or its stubs) with an attack added, written to a folder
by :func:`plant`. ``tests/framework/test_hostile.py`` grades them; the closing note of issue 19
records what each scored before and after the grader was hardened.
"""

from __future__ import annotations

import shutil
import textwrap
from pathlib import Path

COURSE = Path(__file__).resolve().parents[3]

LOOP_TASKS = ["loop_weight", "loop_odd_matrix", "loop_even_matrix", "loop_faces", "loop_subdivide"]
CC_TASKS = ["cc_face_points", "cc_edge_points", "cc_vertex_points", "cc_quads"]

#: Every task returns NaN (floats), zeros (integers) or NaN weights (sparse) of the right shape.
NAN = """
import numpy as _np
import scipy.sparse as _sp


def _nan_like(x):
    if isinstance(x, tuple):
        return tuple(_nan_like(v) for v in x)
    if _sp.issparse(x):
        y = x.astype(float).tocsr(copy=True)
        y.data[:] = _np.nan
        return y
    a = _np.asarray(x)
    if a.dtype.kind == "f":
        return _np.full(a.shape, _np.nan)
    if a.dtype.kind in "iu":
        return _np.zeros(a.shape, a.dtype)
    return x


def _hollow(f):
    def hollow(*args, **kwargs):
        return _nan_like(f(*args, **kwargs))

    return hollow


for _name in TASKS:
    globals()[_name] = _hollow(globals()[_name])
"""

#: Every task looks its inputs up among the grader's cases (in memory, else from the course files)
#: and returns the stored reference output.
LOOKUP = """
def _lookup(fname, args, kwargs):
    import sys

    import numpy as np

    cands = []
    for m in list(sys.modules.values()):
        cs = getattr(m, "CASES", None)
        if isinstance(cs, list):
            cands += cs
    if not cands:
        try:
            from geomlib.grading.cases import load_cases

            cands = load_cases("subdivision")
        except Exception:
            pass
    for c in cands:
        if getattr(c, "function", None) != fname:
            continue
        try:
            inp = {**c.inputs(), **c.params}
            if set(inp) != set(kwargs) or not all(np.array_equal(np.asarray(inp[k]), np.asarray(kwargs[k])) for k in inp):
                continue
            from geomlib.grading.cases import load_reference

            ref = load_reference("subdivision", c)
        except Exception:
            continue
        vals = [ref[n] for n in c.outputs]
        return vals[0] if len(vals) == 1 else tuple(vals)
    raise NotImplementedError("lookup found nothing")


def _looker(name):
    def look(*args, **kwargs):
        return _lookup(name, args, kwargs)

    return look


for _name in TASKS:
    globals()[_name] = _looker(_name)
"""

#: loop_weight raises an exception whose message holds a lone surrogate.
SURROGATE = """
def loop_weight(n, weights="warren"):
    raise ValueError("bad \\\\udc80 value".encode().decode("unicode_escape"))
"""

#: loop_weight writes half a message header into every pipe it holds, then sleeps: in the run's
#: first call only (it leaves a mark in the folder the run's workers share), so that one call, not
#: each of the twenty that reach loop_weight, waits out the time limit; later calls answer. Where no
#: mark can be left, every call hangs (slower, the same outcome).
PARTIAL_HEADER = """
_loop_weight_real = loop_weight


def loop_weight(n, weights="warren"):
    import os
    import stat
    import time

    try:
        os.close(os.open(os.path.join(os.environ["NUMBA_CACHE_DIR"], "hostile-hung-once"), os.O_CREAT | os.O_EXCL))
    except (KeyError, OSError) as e:
        if isinstance(e, FileExistsError):
            return _loop_weight_real(n, weights)
    for fd in range(3, 256):
        try:
            if stat.S_ISFIFO(os.fstat(fd).st_mode):
                os.write(fd, b"\\x05\\x00")
        except OSError:
            pass
    time.sleep(3600)
"""

#: loop_weight raises an exception whose class name is 5 MB long.
HUGE_MESSAGE = """
def loop_weight(n, weights="warren"):
    raise type("E" * 5_000_000, (Exception,), {})("x" * 5_000_000)
"""

#: loop_odd_matrix returns an empty sparse matrix of shape (4e7, n) to the grader (rows x cols 3.6 to
#: 1,600 times tolerances.SPARSE_MAX_DENSE for this lab's cases, n from 3 to 1340; 3e8 rows cost the
#: worker 2.4 GB and about 1 s of CPU a call to build and send, for the same refusal); called by the
#: lab's own loop_subdivide it answers correctly (building on the forged matrix there only costs
#: the worker seconds of work, which is not what this attack is about).
SPARSE_BOMB = """
_loop_odd_matrix_real = loop_odd_matrix


def loop_odd_matrix(V, F, *, topo=None):
    import sys

    import scipy.sparse as sp

    if sys._getframe(1).f_globals.get("__name__") == __name__:
        return _loop_odd_matrix_real(V, F, topo=topo)
    return sp.csr_matrix((40_000_000, len(V)))
"""

#: Every task sleeps for an hour.
SLOW = """
def _sleeper(name):
    def sleep(*args, **kwargs):
        import time

        time.sleep(3600)

    return sleep


for _name in TASKS:
    globals()[_name] = _sleeper(_name)
"""

#: loop_weight starts a detached daemon that burns CPU until the grader has exited, then rewrites
#: results.json with 999 points; it also forges lines in every file descriptor it inherited and
#: rewrites the grader's checks, then answers correctly. (Waiting for the grader's exit, not a fixed
#: time, puts the rewrite after the grader's own write however fast the run is, and lets the test wait
#: only a moment after the grader ends.)
LEFTOVERS = """
def _daemon():
    import ctypes
    import json
    import os
    import time

    if os.fork():
        return
    os.setsid()
    if os.fork():
        os._exit(0)
    ctypes.CDLL(None).prctl(15, b"hostile-daemon", 0, 0, 0)
    try:
        grader, results = None, None
        for p in os.listdir("/proc"):
            if p.isdigit():
                try:
                    args = open(f"/proc/{p}/cmdline", "rb").read().split(b"\\0")
                except OSError:
                    continue
                if b"--results" in args:
                    grader, results = p, args[args.index(b"--results") + 1].decode()
        t0 = time.time()
        while grader and os.path.exists(f"/proc/{grader}") and time.time() - t0 < 600:
            pass  # burn CPU while the grader runs
        if results:
            open(results, "w").write(json.dumps({"score": 999, "tests": []}))
        time.sleep(60)
    finally:
        os._exit(0)


def _forge_and_tamper():
    import os
    import stat

    for fd in range(3, 256):
        try:
            st = os.fstat(fd)
            if stat.S_ISREG(st.st_mode):
                os.write(fd, b"\\nFORGED LINE: 69/69\\n")
        except OSError:
            pass
    try:
        import geomlib.grading.checks as c

        with open(c.__file__, "a") as f:
            f.write("\\n# TAMPERED BY A SUBMISSION\\n")
    except OSError:
        pass


_loop_weight_real = loop_weight


_STARTED = []


def loop_weight(n, weights="warren"):
    if not _STARTED:  # once per process: loop_subdivide calls loop_weight at every level
        _STARTED.append(True)
        _daemon()
        _forge_and_tamper()
    return _loop_weight_real(n, weights)
"""

#: A given helper (catmull_clark) rewritten to answer by itself; every task is left as the stub.
EDIT_GIVEN_CC = """
import igl as _igl


def catmull_clark(V, F, levels=1):
    from . import _my_answers

    return _my_answers.catmull_clark(V, F, levels)
"""

#: catmullclark.py re-exports two loop functions and has a missing import: loop's functions must not pay.
BLAME_IMPORT = """
from .loop import loop_faces, loop_weight  # noqa: F401
from .no_such_module import helper  # noqa: F401
"""

ATTACKS = {
    "nan": (
        "solutions",
        {"loop.py": NAN.replace("TASKS", repr(LOOP_TASKS)), "catmullclark.py": NAN.replace("TASKS", repr(CC_TASKS))},
    ),
    "lookup": (
        "solutions",
        {
            "loop.py": LOOKUP.replace("TASKS", repr(LOOP_TASKS)),
            "catmullclark.py": LOOKUP.replace("TASKS", repr(CC_TASKS)),
        },
    ),
    "surrogate": ("solutions", {"loop.py": SURROGATE}),
    "partial_header": ("solutions", {"loop.py": PARTIAL_HEADER}),
    "huge_message": ("solutions", {"loop.py": HUGE_MESSAGE}),
    "sparse_bomb": ("solutions", {"loop.py": SPARSE_BOMB}),
    "slow": (
        "solutions",
        {"loop.py": SLOW.replace("TASKS", repr(LOOP_TASKS)), "catmullclark.py": SLOW.replace("TASKS", repr(CC_TASKS))},
    ),
    "leftovers": ("solutions", {"loop.py": LEFTOVERS}),
    "edit_given": ("labs", {"catmullclark.py": EDIT_GIVEN_CC}),
    "blame_import": ("solutions", {"catmullclark.py": BLAME_IMPORT}),
}


def plant(kind: str, dest: Path, course: Path = COURSE) -> Path:
    """Write the planted submission ``kind`` as ``dest/subdivision`` and return ``dest``."""
    base, additions = ATTACKS[kind]
    lab = dest / "subdivision"
    shutil.copytree(course / base / "subdivision", lab, ignore=shutil.ignore_patterns("__pycache__", "README.md"))
    for name, code in additions.items():
        with open(lab / name, "a") as f:
            f.write("\n\n" + textwrap.dedent(code))
    if kind == "edit_given":
        # The answer comes from a copy of the reference Catmull-Clark inside the submission.
        src = (course / "solutions" / "subdivision" / "catmullclark.py").read_text()
        (lab / "_my_answers.py").write_text(src)
    for p in [dest, *dest.rglob("*")]:
        p.chmod(0o755 if p.is_dir() else 0o644)
    return dest


def course_copy(dest: Path, course: Path = COURSE) -> Path:
    """A throw-away copy of the course (geomlib included), so attacks on it cannot touch the real one."""
    top = {"build", "out", "notebooks", "bench", "docs"}

    def skip(folder: str, names: list[str]) -> set[str]:
        # At the top, every hidden entry too: .venv, and the 1.4 GB .venv-sandbox that `grade-all` as
        # root makes in the checkout (test_batch.py), which every copy took along (30-50 s and 1.4 GB
        # of /tmp per hostile test).
        at_top = Path(folder) == course
        return {n for n in names if n in ("__pycache__", "results", "feedback") or at_top and (n[0] == "." or n in top)}

    shutil.copytree(course, dest, ignore=skip)
    for p in [dest, *dest.rglob("*")]:
        p.chmod(0o755 if p.is_dir() else 0o644)
    return dest


def grade_planted(
    kind: str,
    course: Path,
    work: Path,
    *,
    python: str,
    env: dict | None = None,
    timeout: float = 900,
    root: Path | None = None,
    part: str | None = None,
) -> dict:
    """Grade planted submission ``kind`` on a copy of ``course`` with ``python``; what happened.

    The copy is ``root`` when given (a :func:`course_copy` that several grades share), else made in ``work``.
    With ``part``, only that part of the lab is graded (``--part``: a grade costs about 2 s of CPU to
    start and 0.07 s per test).

    Returns ``score``, ``seconds``, ``results`` (the parsed results.json or None), ``hung`` (killed
    after ``timeout``), ``daemons`` (leftover hostile processes), ``tampered`` (the course's checks.py
    was changed), ``forged`` (the grader's output holds forged lines) and ``rewritten`` (results.json
    changed after the grader finished).
    """
    import json
    import os
    import subprocess
    import time

    if root is None:
        root = course_copy(work / "course", course)
    sub = plant(kind, work / "submission")
    results = work / "results.json"
    e = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    e.update({"GEOMLIB_ROOT": str(root), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **(env or {})})
    cmd = [python, "-m", "geomlib.cli", "grade", "--impl", str(sub), "--lab", "subdivision", "--results", str(results)]
    if part is not None:
        cmd += ["--part", part]
    t0 = time.monotonic()
    hung = False
    log = work / "grader-output.txt"
    with open(log, "wb") as out:
        p = subprocess.Popen(cmd, cwd=root, env=e, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            p.wait(timeout)
        except subprocess.TimeoutExpired:
            hung = True
            os.killpg(p.pid, 9)
            p.wait()
    seconds = time.monotonic() - t0
    data = None
    if results.is_file():
        try:
            data = json.loads(results.read_text())
        except ValueError:
            data = None
    before = results.read_bytes() if results.is_file() else b""
    if kind == "leftovers":
        time.sleep(1)  # a surviving daemon rewrites results.json once the grader has exited (~50 ms)
    daemons = 0
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                if open(f"/proc/{d}/comm").read().strip() == "hostile-daemon":
                    daemons += 1
                    os.kill(int(d), 9)
            except OSError:
                pass
    return {
        "score": None if data is None else data.get("score"),
        "seconds": round(seconds, 1),
        "results": data,
        "results_bytes": len(before),
        "hung": hung,
        "daemons": daemons,
        "tampered": "TAMPERED" in (root / "geomlib" / "grading" / "checks.py").read_text(),
        "forged": b"FORGED LINE" in log.read_bytes(),
        "rewritten": results.is_file() and results.read_bytes() != before,
        "log": log.read_text(errors="replace")[-3000:],
    }
