"""The sandbox on planted hostile submissions: each behaviour costs one call, with a clear message."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from geomlib.grading import wire
from geomlib.grading.errors import (
    BadReturn,
    GradingFailure,
    NotImplementedYet,
    StudentCrash,
    StudentError,
    StudentTimeout,
)
from geomlib.grading.sandbox import LabProxy

PLANTED = """
import ctypes, os, sys, time
import numpy as np

def good(x):
    return x * 2, {"a": np.arange(3)}, [1.5, None, "s"], np.float64(2.5)

def infinite_loop():
    while True:
        pass

def segfault():
    ctypes.string_at(0)

def calls_sys_exit():
    sys.exit(3)

def calls_os_exit():
    os._exit(0)

def huge_allocation():
    return np.ones(6 * 10**8)  # 4.8 GB, over the 1 GiB limit used here

def prints_garbage():
    print("garbage" * 1000)
    sys.stderr.write("more garbage")
    return 7

def stub():
    raise NotImplementedError("Task 1 (odd vertices): 3/8 (a + b) + 1/8 (c + d)")

def index_error(i):
    values = [1, 2]
    return values[i]

def returns_object():
    return object()

class Exploit:
    def __reduce__(self):
        return (os.system, ("touch /tmp/geomlib-pwned",))

def returns_exploit():
    return Exploit()

def returns_sparse():
    import scipy.sparse as sp
    return sp.eye(3, format="csr") * 2.0

def deep_recursion(n=0):
    return deep_recursion(n + 1)

def _result_pipes():
    import stat
    return [fd for fd in range(3, 64) if _is_fifo(fd)]

def _is_fifo(fd):
    import stat
    try:
        return stat.S_ISFIFO(os.fstat(fd).st_mode)
    except OSError:
        return False

def forged_length():
    import struct
    for fd in _result_pipes():
        os.write(fd, struct.pack("<Q", 2**40) + b"R")
    os._exit(0)

def forged_array():
    import json, struct
    meta = json.dumps({"__nd__": 0, "dtype": "f8", "shape": [10**9]}).encode()
    body = b"R" + b"GW1" + struct.pack("<Q", len(meta)) + meta + bytes(64)
    for fd in _result_pipes():
        os.write(fd, struct.pack("<Q", len(body)) + body)
    os._exit(0)

def forged_sparse():
    import json, struct
    nd = lambda i, n: {"__nd__": i, "dtype": "i8", "shape": [n]}
    meta = json.dumps({"__sparse__": [nd(0, 0), nd(1, 0), {"__nd__": 2, "dtype": "f8", "shape": [0]}], "shape": [300_000_000, 10**6]}).encode()
    body = b"R" + b"GW1" + struct.pack("<Q", len(meta)) + meta
    for fd in _result_pipes():
        os.write(fd, struct.pack("<Q", len(body)) + body)
    os._exit(0)

def returns_nan():
    return np.full(3, np.nan)

def gc_counts():
    import gc
    return gc.get_freeze_count(), len(gc.get_objects())

def mutates_global_state():
    np.set_printoptions(precision=1)
    sys.modules["numpy"].pi = 3
    return 1
"""


@pytest.fixture(scope="module")
def planted(tmp_path_factory) -> LabProxy:
    """The planted lab with 3 s per call: the legitimate calls need 0.02 s (deep_recursion 0.1 s)."""
    d = tmp_path_factory.mktemp("planted") / "bad"
    d.mkdir()
    (d / "__init__.py").write_text("from .ops import *\nfrom .broken import *\n")
    (d / "ops.py").write_text(textwrap.dedent(PLANTED))
    (d / "broken.py").write_text("def broken(:\n    pass\n")
    return LabProxy("bad", d, timeout=3, memory_mb=1024)


@pytest.fixture(scope="module")
def planted_hang(planted) -> LabProxy:
    """The same lab with 1 s per call, for infinite_loop only: nothing of a hang's call needs time,
    and its limit is spent spinning a CPU."""
    return LabProxy("bad", planted.lab_dir, timeout=1, memory_mb=1024)


def test_good_call_round_trips_values(planted):
    x, d, lst, f = planted.good(np.arange(4.0))
    np.testing.assert_array_equal(x, np.arange(4.0) * 2)
    np.testing.assert_array_equal(d["a"], np.arange(3))
    assert lst == [1.5, None, "s"] and f == 2.5


def test_sparse_results_come_back_as_sparse(planted):
    S = planted.returns_sparse()
    np.testing.assert_array_equal(S.toarray(), 2 * np.eye(3))


@pytest.mark.parametrize(
    "function, error, words",
    [
        ("infinite_loop", StudentTimeout, "did not finish within 1 s"),
        ("segfault", StudentCrash, "segmentation fault"),
        ("calls_sys_exit", StudentCrash, "called sys.exit(3)"),
        ("calls_os_exit", StudentCrash, "without returning a result"),
        ("huge_allocation", StudentCrash, "ran out of memory (limit 1024 MiB)"),
        ("stub", NotImplementedYet, "stub: not implemented yet (Task 1 (odd vertices)"),
        ("returns_object", BadReturn, "returned an object of type builtins.object"),
        ("returns_exploit", BadReturn, "which the grader cannot read"),
        ("deep_recursion", StudentError, "RecursionError"),
        ("broken", StudentError, "broken.py line 1: invalid syntax"),
        ("no_such_function", StudentError, "could not find a function named 'no_such_function'"),
        ("forged_length", BadReturn, "more than this call may return"),
        ("forged_array", BadReturn, "more data than this call may return"),
        ("forged_sparse", BadReturn, "far larger than this call's inputs allow"),
    ],
)
def test_hostile_behaviour_costs_one_call_with_a_clear_message(planted, planted_hang, function, error, words):
    with pytest.raises(error) as e:
        getattr(planted_hang if function == "infinite_loop" else planted, function)()
    assert words in str(e.value)
    assert not Path("/tmp/geomlib-pwned").exists()


def test_student_exception_names_their_file_line_and_code(planted):
    with pytest.raises(StudentError) as e:
        planted.index_error(5)
    msg = str(e.value)
    assert msg.startswith("index_error raised IndexError at bad/ops.py, line ")
    assert "`return values[i]`" in msg and "list index out of range" in msg
    assert e.value.exc_mro[:2] == ["IndexError", "LookupError"]


def test_printing_does_not_disturb_the_result_or_the_grader(planted, capfd):
    assert planted.prints_garbage() == 7
    out, err = capfd.readouterr()
    assert "garbage" not in out and "garbage" not in err


def test_a_call_cannot_change_the_graders_state(planted):
    assert planted.mutates_global_state() == 1
    assert np.pi != 3
    assert np.get_printoptions()["precision"] == 8


def test_a_worker_collects_only_its_own_garbage(planted):
    """The worker inherits the zygote's objects (NumPy, SciPy, the preloaded modules) frozen
    (``gc.freeze``): its garbage collections walk what it made itself, not the whole inherited heap,
    which they would write to page by page (a copy of each page per call)."""
    frozen, walked = planted.gc_counts()
    assert frozen > 10 * walked, (frozen, walked)


def test_the_lab_keeps_working_after_every_failure(planted, planted_hang):
    for f in ("segfault", "calls_os_exit", "infinite_loop"):
        with pytest.raises(GradingFailure):
            getattr(planted_hang if f == "infinite_loop" else planted, f)()
        assert planted.good(1)[0] == 2


def test_wire_refuses_what_it_cannot_represent_safely():
    with pytest.raises(wire.WireError, match="dtype object"):
        wire.encode(np.array([object()]))
    with pytest.raises(wire.WireError, match="non-string keys"):
        wire.encode({1: 2})
    data = wire.encode((np.inf, -np.nan if False else 1, {"k": np.zeros((2, 2), np.float32)}))
    a, b, c = wire.decode(data)
    assert a == np.inf and b == 1 and c["k"].dtype == np.float32


def test_checks_refuse_nan_inf_complex_and_strings_where_the_reference_is_finite(planted):
    from geomlib.grading import checks, expect_close
    from geomlib.grading.errors import GradingFailure

    got = planted.returns_nan()
    ctx = checks.Context(label="f on case")
    e = {"x": np.zeros(3)}
    for bad in (got, np.array([1, np.inf, 0]), np.zeros(3) + 0j, np.array(["0", "0", "0"])):
        for check in (checks.Allclose("x"), checks.Equal("x"), checks.Allclose("x", atol=np.inf)):
            with pytest.raises(GradingFailure, match="NaN or inf|complex|not an array of real numbers|numeric"):
                check(e, {"x": bad}, ctx)
        with pytest.raises(GradingFailure):
            expect_close("f", bad, np.zeros(3), atol=1e9)
    img = {"image": np.zeros((4, 4, 3), np.uint8)}
    with pytest.raises(GradingFailure, match="NaN or inf"):
        checks.ImageMatch()(img, {"image": np.full((4, 4, 3), np.nan)}, ctx)
    # NaN where the reference holds NaN too is not a problem of its own.
    checks.Allclose("x", atol=np.inf)({"x": np.array([np.nan, 0.0])}, {"x": np.array([np.nan, 0.0])}, ctx)


def test_read_error_says_what_the_probe_cannot_read(tmp_path):
    from geomlib.grading.zygote import _read_error

    (tmp_path / "file").write_bytes(b"x")
    assert _read_error(str(tmp_path / "file")) is None
    assert _read_error(str(tmp_path)) is None  # a folder counts as readable when it can be listed
    missing = _read_error(str(tmp_path / "missing"))
    assert isinstance(missing, FileNotFoundError) and missing.strerror


KERNELS = """
from numba import njit

from geomlib.jit import use_cache_folder

use_cache_folder(__name__, __file__)


@njit(cache=True)
def _double(x):
    return 2.0 * x


def double(x):
    y = _double(x)
    return y, sum(_double.stats.cache_hits.values()), sum(_double.stats.cache_misses.values())
"""


def test_compiled_kernels_are_compiled_by_the_first_worker_only(tmp_path):
    """Every call runs in a fresh worker that may not write its lab folder: the run's workers share one
    numba cache, so only the first call compiles and the next ones load the machine code."""
    d = tmp_path / "jitlab"
    d.mkdir()
    (d / "__init__.py").write_text("from .kernels import double\n")
    (d / "kernels.py").write_text(KERNELS)
    lab = LabProxy("jitlab", d, timeout=120)
    y, hits, misses = lab.double(1.5)
    assert y == 3.0 and (hits, misses) == (0, 1)
    for _ in range(2):
        y, hits, misses = lab.double(2.5)
        assert y == 5.0 and (hits, misses) == (1, 0), "a later worker compiled the kernel again"
