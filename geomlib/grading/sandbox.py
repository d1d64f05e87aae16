"""Run student code in worker processes with a time and memory limit.

Each call forks a fresh worker from the grader (which has NumPy, SciPy and geomlib imported
already), so a call costs a few milliseconds plus the student's own work, and nothing a call does
(global state, ``sys.exit``, a segfault, an infinite loop, printing garbage) survives it or
reaches the grader. Results come back through :mod:`geomlib.grading.wire` (no pickle).
Plain ``fork`` rather than a fork server or spawn: those re-import the ``__main__`` module (pytest,
a notebook, a user's script) in every worker. The grader loads a case's expected output only after
the student's call has returned, so a worker never holds it.

:class:`LabProxy` makes this look like a module: ``lab.loop_subdivide(V, F)`` runs the student's
``loop_subdivide`` in a worker and returns its result, or raises a
:class:`~geomlib.grading.errors.GradingFailure` whose message a student can act on.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import signal
import tempfile
from pathlib import Path

from geomlib.grading import tolerances, wire
from geomlib.grading.errors import (
    BadReturn,
    GradingFailure,
    NotImplementedYet,
    StudentCrash,
    StudentError,
    StudentTimeout,
)
from geomlib.grading.worker import run_call

__all__ = ["call", "LabProxy"]

# Imported once in the grader so that every forked worker starts with them loaded (a worker that
# imported SciPy or libigl itself would pay that on every call).
_PRELOAD = (
    "numpy",
    "scipy.sparse",
    "scipy.sparse.linalg",
    "scipy.spatial",
    "igl",
    "geomlib.validate",
    "geomlib.topology",
    "geomlib.geometry",
)
_preloaded = False


def _context():
    global _preloaded
    if not _preloaded:
        import importlib

        for name in _PRELOAD:
            try:
                importlib.import_module(name)
            except Exception:  # a missing optional module only makes workers slower
                pass
        _preloaded = True
    return mp.get_context("fork")


def _signal_name(code: int) -> str:
    try:
        return signal.Signals(-code).name
    except ValueError:
        return f"signal {-code}"


def _read_output(path: str) -> str:
    try:
        with open(path, errors="replace") as f:
            text = f.read(tolerances.OUTPUT_CHARS + 1)
    except OSError:
        return ""
    if len(text) > tolerances.OUTPUT_CHARS:
        text = text[: tolerances.OUTPUT_CHARS] + " …"
    return text.strip()


def _format_student_exception(function: str, info: dict) -> str:
    where = ""
    if info.get("frames"):
        f = info["frames"][-1]
        code = f" `{f['code'].strip()}`" if f.get("code") else ""
        where = f" at {f['file']}, line {f['line']} (in {f['function']}):{code}"
    return f"{function} raised {info['type']}{where}: {info['message']}"


def call(
    lab_dir: Path,
    lab: str,
    function: str,
    args: tuple = (),
    kwargs: dict | None = None,
    *,
    timeout: float | None = None,
    memory_mb: int | None = None,
):
    """Call ``function`` of the lab in ``lab_dir`` in a sandboxed worker and return its result.

    Raises
    ------
    NotImplementedYet, StudentError, StudentCrash, StudentTimeout, BadReturn
        With a message naming the function and what happened.
    """
    timeout = tolerances.TIME_LIMIT_S if timeout is None else timeout
    memory_mb = tolerances.MEMORY_LIMIT_MB if memory_mb is None else memory_mb
    ctx = _context()
    recv, send = ctx.Pipe(duplex=False)
    fd, out_path = tempfile.mkstemp(prefix="geomlib-out-", suffix=".txt")
    os.close(fd)
    proc = ctx.Process(
        target=run_call,
        args=(send, str(lab_dir), lab, function, tuple(args), dict(kwargs or {}), memory_mb, timeout, out_path),
        daemon=True,
    )
    try:
        proc.start()
        send.close()
        data = None
        if recv.poll(timeout):
            try:
                data = recv.recv_bytes()
            except (EOFError, OSError):
                data = None
        else:
            proc.kill()
            proc.join(5)
            raise StudentTimeout(
                f"{function} did not finish within {timeout:g} s (time limit); look for an infinite loop "
                f"or a Python loop over every vertex/pixel that should be vectorised"
            )
        proc.join(10)
        if proc.is_alive():
            proc.kill()
            proc.join(5)
        printed = _read_output(out_path)
    finally:
        recv.close()
        try:
            os.unlink(out_path)
        except OSError:
            pass
    tail = f" Your code printed: {printed!r}" if printed else ""
    if data is None:
        code = proc.exitcode
        if code is not None and code < 0:
            sig = _signal_name(code)
            why = {
                "SIGSEGV": "a segmentation fault",
                "SIGXCPU": "exceeding the CPU-time limit",
                "SIGKILL": "being killed (out of memory?)",
                "SIGABRT": "an abort",
            }.get(sig, sig)
            raise StudentCrash(f"{function} crashed the worker process with {why}.{tail}")
        raise StudentCrash(
            f"{function} ended the process (exit code {code}, e.g. os._exit) without returning a result.{tail}"
        )
    tag, body = data[:1], data[1:]
    if tag == b"R":
        try:
            return wire.decode(body)
        except Exception as e:  # malformed data from the worker
            raise BadReturn(f"{function} sent back data the grader could not read ({e})") from None
    info = json.loads(body.decode())
    kind = info.get("kind")
    if kind == "exception" and info["type"] == "NotImplementedError":
        task = f" ({info['message']})" if info["message"] else ""
        raise NotImplementedYet(f"{function}: not implemented yet{task}")
    if kind == "exception":
        raise StudentError(_format_student_exception(function, info) + tail, info["type"], info["mro"], info["message"])
    if kind == "memory":
        raise StudentCrash(f"{function} ran out of memory (limit {memory_mb} MiB).{tail}")
    if kind == "exit":
        raise StudentCrash(f"{function} {info['message']} instead of returning a result.{tail}")
    if kind == "missing":
        raise StudentError(info["message"], "LookupError", ["LookupError", "Exception"], info["message"])
    if kind == "bad_return":
        raise BadReturn(info["message"] + "." + tail)
    raise GradingFailure(f"internal grader problem while calling {function}: {info.get('message')}")


class LabProxy:
    """A lab module whose functions run in sandboxed workers.

    Parameters
    ----------
    lab : str
        Lab name (``"subdivision"``).
    lab_dir : Path
        Folder of the implementation under test (``labs/subdivision``, a submission's folder, ...).
    """

    def __init__(self, lab: str, lab_dir: Path, *, timeout: float | None = None, memory_mb: int | None = None):
        self.name = lab
        self.lab_dir = Path(lab_dir)
        self.timeout = timeout
        self.memory_mb = memory_mb

    def call(self, function: str, *args, **kwargs):
        if not self.lab_dir.is_dir():
            raise StudentError(
                f"lab folder {self.lab_dir} is missing from the submission",
                "FileNotFoundError",
                ["FileNotFoundError", "OSError", "Exception"],
                str(self.lab_dir),
            )
        return call(self.lab_dir, self.name, function, args, kwargs, timeout=self.timeout, memory_mb=self.memory_mb)

    def __getattr__(self, function: str):
        if function.startswith("_"):
            raise AttributeError(function)

        def run(*args, **kwargs):
            return self.call(function, *args, **kwargs)

        run.__name__ = function
        return run

    def __repr__(self) -> str:
        return f"<lab {self.name!r} from {self.lab_dir}, run sandboxed>"
