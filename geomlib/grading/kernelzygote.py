"""Kernel zygotes: forks of the zygote that keep the compiled kernels of the course's own code loaded.

The course's own code (``solutions/<lab>``, ``labs/<lab>``: the snapshots that
:mod:`geomlib.grading.kernelcache` trusts, graded with workers running as the grading user) of a
numba lab is served by a fork of the zygote that has imported the lab's modules and loaded their
compiled kernels once (:func:`_kernel_main`); it forks that snapshot's workers with the zygote's own
loop (:func:`geomlib.grading.zygote.serve_calls`), and they then start with the kernels loaded
instead of loading them from disk at every call (0.03-0.1 s of CPU each). The zygote itself never
imports a lab, so the workers of any other code (a submission, another snapshot) start as before:
nothing of the course's solution in their memory, no machine code of it in their JIT. At most
:data:`KERNEL_ZYGOTES` at a time, for the last trusted snapshots called; a kernel zygote starts no
thread (parallel kernels are left to the workers) and imports only modules that define things and
use no library the zygote has not loaded (:func:`worker.preload_lab`), so what a call prints or
raises is the same.

The zygote runs in one process with this module: :func:`relayed` and :func:`pids` are what its loop
asks (``geomlib.grading.zygote.main(kernels=this module)``, started so by the sandbox); the state
below is that process's.
"""

from __future__ import annotations

import importlib
import os
import resource
import signal
import socket
import sys
import warnings
from pathlib import Path

from geomlib.grading import kernelcache, zygote
from geomlib.grading import worker as _worker
from geomlib.grading.zygote import kill_descendants, recv_msg, send_msg

__all__ = ["relayed", "pids", "KERNEL_ZYGOTES", "KERNEL_ZYGOTE_WAIT_S"]


def _threads() -> int:
    """This process's threads (1 where /proc cannot say: Linux is the only system with kernel zygotes)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return 1


class _KernelZygote:
    """The zygote's side of a kernel zygote: its pid, the socket to it and the snapshot it serves."""

    def __init__(self, key: tuple, pid: int, sock: socket.socket):
        self.key, self.pid, self.sock = key, pid, sock

    def close(self) -> None:
        self.sock.close()
        try:
            os.kill(self.pid, signal.SIGKILL)
            os.waitpid(self.pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass


#: The kernel zygotes of the last trusted snapshots called, most recent last (at most
#: :data:`KERNEL_ZYGOTES`: a process that grades the solutions and the stubs of a lab in turn keeps
#: both); the snapshots that may have one (True) and those that cannot (False: no numba, or it failed).
_KERNELS: dict[tuple, _KernelZygote] = {}
KERNEL_ZYGOTES = 2
_KERNEL_USE: dict = {}
#: How long the zygote waits for a kernel zygote (to import its lab, to fork a worker) before it
#: kills it and serves the snapshot itself (the grader waits 60 s for a worker's pid; twice, when
#: the call is sent again).
KERNEL_ZYGOTE_WAIT_S = 20.0


def pids() -> tuple[int, ...]:
    """The kernel zygotes' pids: the zygote's children that outlive a call."""
    return tuple(k.pid for k in _KERNELS.values())


def _uses_numba(folder: str) -> bool:
    """Whether a module of the lab folder imports numba (or :mod:`geomlib.jit`) at its top level."""
    return any(n.split(".")[0] == "numba" or n == "geomlib.jit" for n in zygote._top_imports(folder))


def _kernel_key(req: dict) -> tuple | None:
    """The snapshot a kernel zygote would serve this call of, or None: only calls the grader marks
    ``trusted_kernels`` (the course's own code, :mod:`geomlib.grading.kernelcache`) of a lab that
    uses numba, with the JIT on, on Linux. A trusted snapshot's folder is named by its content."""
    if req.get("op") != "call" or not req.get("trusted_kernels") or not req.get("jit_cache") or sys.platform != "linux":
        return None
    key = (req["lab"], req["lab_dir"], req.get("stubs_dir"), req["jit_cache"])
    if key not in _KERNEL_USE:
        _KERNEL_USE[key] = _uses_numba(req.get("stubs_dir") or req["lab_dir"])
    if not _KERNEL_USE[key]:
        return None
    # Not before something was compiled for it (in an earlier run, or by an earlier call): a kernel
    # zygote with nothing to load costs its start (simplification's graded calls use no kernel).
    return key if key in _KERNELS or any(Path(req["jit_cache"]).rglob("*.nbi")) else None


def _drop_kernel_zygote(key: tuple, *, for_good: bool) -> None:
    """Kill the kernel zygote of ``key`` and any worker it left (they come back to the zygote); with
    ``for_good``, that snapshot's calls are served by the zygote from now on."""
    k = _KERNELS.pop(key, None)
    if k is not None:
        k.close()
        kill_descendants(keep=pids())
    if for_good:
        _KERNEL_USE[key] = False


def relayed(sock: socket.socket, req: dict, blob: bytes, fds: list[int]) -> bool:
    """Have the kernel zygote of the call's trusted snapshot serve it (started when there is none):
    True when the grader got its replies (the call's, or ``retry``: send it again), False when the
    zygote must serve the call itself (no kernel zygote was given the call)."""
    key = _kernel_key(req)
    if key is None:
        return False
    if key not in _KERNELS:
        for old in list(_KERNELS)[: max(0, len(_KERNELS) - KERNEL_ZYGOTES + 1)]:
            _drop_kernel_zygote(old, for_good=False)
        zygote._prepare(req)
        if "numba" not in sys.modules:  # built here once, for every later kernel zygote
            importlib.import_module("numba")
            zygote._warm_numba()
        import numba

        if numba.config.DISABLE_JIT or _threads() != 1:
            _KERNEL_USE[key] = False
            return False
        k = _start_kernel_zygote(key, req, sock)
        if k is None:
            _KERNEL_USE[key] = False
            return False
        _KERNELS[key] = k
    k = _KERNELS[key] = _KERNELS.pop(key)  # the most recent last
    try:
        k.sock.settimeout(KERNEL_ZYGOTE_WAIT_S)
        send_msg(k.sock, req, blob, fds=fds)
        head, _, _ = recv_msg(k.sock)
        k.sock.settimeout(None)
    except (OSError, EOFError, ValueError):
        head = {}
    for fd in fds:
        os.close(fd)
    if "pid" not in head:
        # It refused (a thread), hung or died after it was given the call's descriptors: a worker it
        # forked may have written into the result pipe or the output file before it was killed, and
        # the grader would read that as the call's result. So the call is not served here with these
        # descriptors: the kernel zygote and everything it forked are killed and reaped, and the
        # grader sends the call again with a new pipe, output file and scratch folder
        # (``sandbox._Zygote.run``), which no process of the kernel zygote ever had. The zygote
        # serves this snapshot itself from now on.
        _drop_kernel_zygote(key, for_good=True)
        send_msg(sock, {"retry": True})
        return True
    send_msg(sock, head)
    try:
        done, _, _ = recv_msg(k.sock)
    except (OSError, EOFError, ValueError):  # it died during the call: its worker came back to us
        _drop_kernel_zygote(key, for_good=True)
        done = {"done": True, "status": 0, "leftovers": 0, "seconds": 0.0}
    send_msg(sock, done)
    return True


def _start_kernel_zygote(key: tuple, req: dict, grader: socket.socket) -> _KernelZygote | None:
    """Fork a kernel zygote for ``req``'s snapshot and wait until it is ready; None when it is not."""
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:
        try:
            ours.close()
            grader.close()
            for other in _KERNELS.values():  # its siblings are the zygote's
                other.sock.close()
            _KERNELS.clear()
            _kernel_main(theirs, req, parent)
        finally:
            os._exit(0)
    theirs.close()
    k = _KernelZygote(key, pid, ours)
    ours.settimeout(KERNEL_ZYGOTE_WAIT_S)
    try:
        ready, _, _ = recv_msg(ours)
    except (OSError, EOFError, ValueError):
        ready = {}
    if not ready.get("ready"):
        k.close()
        return None
    return k


#: A kernel zygote's snapshot (``req``), its modules' number, kernels and the index files it read.
_KERNEL_STATE: dict = {}


def _kernel_main(sock: socket.socket, req: dict, parent: int) -> None:
    """A kernel zygote: import the trusted snapshot's modules, load their compiled kernels, serve."""
    zygote._prctl(zygote._PR_SET_CHILD_SUBREAPER, 1)  # its workers' orphans come back to it
    zygote._prctl(zygote._PR_SET_PDEATHSIG, int(signal.SIGTERM))
    if os.getppid() != parent:
        return
    os.environ["NUMBA_CACHE_DIR"] = req["jit_cache"]  # the workers' own folder: the decorators read it
    try:
        importlib.import_module("geomlib.jit")
        _KERNEL_STATE.update(req=req, modules=-1, kernels=[], seen={})
        ready = _refresh_kernels()
    except Exception:  # noqa: BLE001 - then it is not ready, and the zygote serves the calls
        ready = False
    send_msg(sock, {"ready": ready})
    if ready:
        zygote.serve_calls(sock, before_fork=_ready_to_fork)
        kill_descendants()


def _ready_to_fork() -> bool:
    """A kernel zygote's check before it forks a worker (False: it refuses the call): one thread,
    and its lab's kernels refreshed without a warning."""
    return _threads() == 1 and _refresh_kernels()


def _refresh_kernels() -> bool:
    """In a kernel zygote, before each fork: import the lab's modules that became importable (a call
    imported a library they use) and load what was compiled for its kernels since it last looked.
    False when a thread is running (then no worker may be forked from here), or when that issued a
    warning (a ``SyntaxWarning`` of a lab file, say): a worker would have printed it, in the call's
    output; then the zygote serves the snapshot itself."""
    with warnings.catch_warnings(record=True) as issued:
        _load_lab()
    return _threads() == 1 and not issued


def _load_lab() -> None:
    """:func:`_refresh_kernels`' imports and loads."""
    st = _KERNEL_STATE
    if st and st["modules"] != len(sys.modules):
        req = st["req"]
        stubs = req.get("stubs_dir")
        # the call's memory limit, as a worker's (soft: the workers set their own), while it imports
        old = resource.getrlimit(resource.RLIMIT_AS)
        if req.get("memory_mb"):
            zygote._set_limit("AS", _worker.vm_size_bytes() + int(req["memory_mb"]) * 2**20, old[1])
        try:
            modules = _worker.preload_lab(Path(req["lab_dir"]), req["lab"], Path(stubs) if stubs else None)
        finally:
            zygote._set_limit("AS", *old)
        st["kernels"] = kernelcache.kernels_in(modules)
        st["modules"] = len(sys.modules)
    if st:
        kernelcache.load_cached(st["kernels"], st["seen"])
