"""The zygote: a clean process that forks one sandboxed worker per call into student code.

The grader starts it as a fresh interpreter (``python -c ...``) before it loads any case or
reference, so nothing a worker inherits holds the case list, the expected outputs or the grader's
open files: a worker gets the call's *inputs* only, pickled by the grader (trusted → untrusted), and
sends its result back through :mod:`geomlib.grading.wire` (never pickle).

For each request the zygote forks a worker that

1. starts its own session (its own process group) and closes every descriptor but the result pipe
   and the file its prints go to;
2. limits its address space, CPU time, file size, core dumps and (as a user other than root) the
   number of processes;
3. as root with ``GEOMLIB_SANDBOX_USER`` set, becomes that user (``nobody``, or a private uid per
   submission under ``geomlib grade-all``);
4. where the kernel has Landlock, may read only Python, the libraries, geomlib, the course's stubs
   and its own lab, write only a private scratch folder (and its submission's numba cache), and neither open TCP connections nor signal
   processes outside its sandbox;
5. (Linux x86_64/aarch64) can open no network socket: a seccomp filter lets ``socket()`` create
   ``AF_UNIX`` sockets only (:mod:`geomlib.grading.seccomp`), so no UDP, TCP, IPv6 or raw packet
   leaves the worker, with or without Landlock.

The zygote is a child subreaper: anything the student's code started and detached is re-parented
to it, and after each call it kills and reaps every remaining descendant before it tells the grader
the call is over.

Kernel zygotes. The course's own code (``solutions/<lab>``, ``labs/<lab>``: the snapshots that
:mod:`geomlib.grading.kernelcache` trusts, graded with workers running as the grading user) of a
numba lab is served by a fork of the zygote that has imported the lab's modules and loaded their
compiled kernels once (:func:`_kernel_main`); it forks that snapshot's workers as the zygote does,
which then start with the kernels loaded instead of loading them from disk at every call (0.03-0.1 s
of CPU each). The zygote itself never imports a lab, so the workers of any other code (a
submission, another snapshot) start as before: nothing of the course's solution in their memory,
no machine code of it in their JIT. One kernel zygote at a time, for the last trusted snapshot;
it starts no thread (parallel kernels are left to the workers) and imports only modules that define
things and use no library the zygote has not loaded (:func:`worker.preload_lab`), so what a call
prints or raises is the same.

Longer than most modules (about 720 lines) on purpose: the zygote and the kernel zygotes run the
same loop (fork, wait, kill what is left) and relay the same framed messages; split, the relay
would need the loop's private state.
"""

from __future__ import annotations

import ast
import ctypes
import gc
import importlib
import json
import os
import pickle
import resource
import signal
import socket
import struct
import sys
import time
import warnings
from pathlib import Path

from geomlib.grading import blacklist, kernelcache, landlock, seccomp
from geomlib.grading import worker as _worker

_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36

#: Imported once in the zygote so every forked worker starts with them loaded.
PRELOAD = (
    "numpy",
    "scipy.sparse",
    "scipy.sparse.linalg",
    "igl",
    "geomlib.validate",
    "geomlib.topology",
    "geomlib.geometry",
    "geomlib.camera",
    "geomlib.raster",
    "geomlib.datasets",
    "geomlib.grading.shader_watch",  # every worker installs it (its dataclasses cost ~5 ms per call)
)

#: Imported by the zygote before the first call of a lab whose course stubs import them (or of a
#: lab without known stubs), not for the others: 0.4 s of CPU at every start of the grader
#: (``geomlib grade --task N``) and a larger process to fork. Module -> what in a stub's import
#: means the lab uses it.
PRELOAD_IF_USED = {
    # The compiled kernels of sdf, simplification and remeshing: importing numba costs a quarter
    # second of CPU, which every worker of those labs paid per call (their stubs too).
    "numba": ("numba", "geomlib.jit"),
    "scipy.fft": ("scipy.fft",),  # vdm's transport: 0.1 s per call otherwise
    # 0.08 and 0.05 s of CPU; geomlib.textures looks points up in a k-d tree (maps).
    "scipy.spatial": ("scipy.spatial", "geomlib.textures"),
    "scipy.ndimage": ("scipy.ndimage",),
}

#: Processes (threads) a worker may add to what its user already runs.
NPROC_EXTRA = 256
#: Largest file a worker may write (its printed output included), bytes.
FSIZE_LIMIT = 256 << 20


# ---------------------------------------------------------------------------------- framing


def send_msg(sock: socket.socket, obj: dict, blob: bytes = b"", fds: list[int] | None = None) -> None:
    head = json.dumps(obj).encode()
    data = struct.pack("<IQ", len(head), len(blob)) + head + blob
    if fds:
        socket.send_fds(sock, [data[:4096]], fds)
        sock.sendall(data[4096:])
    else:
        sock.sendall(data)


def _recv_exact(sock: socket.socket, n: int, fds: list[int] | None = None) -> bytes:
    parts, got = [], 0
    while got < n:
        if fds is not None and not fds and got == 0:
            chunk, new_fds, _, _ = socket.recv_fds(sock, min(n - got, 4096), 4)
            fds.extend(new_fds)
        else:
            chunk = sock.recv(min(n - got, 1 << 20))
        if not chunk:
            raise EOFError("connection closed")
        parts.append(chunk)
        got += len(chunk)
    return b"".join(parts)


def recv_msg(sock: socket.socket, with_fds: bool = False) -> tuple[dict, bytes, list[int]]:
    fds: list[int] = []
    hdr = _recv_exact(sock, 12, fds if with_fds else None)
    nh, nb = struct.unpack("<IQ", hdr)
    head = json.loads(_recv_exact(sock, nh).decode())
    blob = _recv_exact(sock, nb) if nb else b""
    return head, blob, fds


# ---------------------------------------------------------------------------------- processes


def _children() -> list[int]:
    me = os.getpid()
    try:
        with open(f"/proc/{me}/task/{me}/children") as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        pass
    kids = []
    try:
        names = os.listdir("/proc")
    except OSError:  # no /proc (macOS): the worker's process group is killed instead
        return kids
    for name in names:
        if name.isdigit():
            try:
                with open(f"/proc/{name}/stat", "rb") as f:
                    if int(f.read().rsplit(b")", 1)[1].split()[1]) == me:
                        kids.append(int(name))
            except (OSError, ValueError, IndexError):
                pass
    return kids


def kill_descendants(keep: tuple[int, ...] = ()) -> int:
    """SIGKILL and reap every descendant (orphans come back to us as subreaper) but the children
    ``keep`` (the kernel zygote); returns how many."""
    killed = 0
    for _ in range(1000):
        kids = [pid for pid in _children() if pid not in keep]
        if not kids:
            break
        for pid in kids:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for pid in kids:
            try:
                os.waitpid(pid, 0)
                killed += 1
            except ChildProcessError:
                pass
    return killed


# ------------------------------------------------------------------ Linux-only calls, with fallbacks
# prctl, /proc and some rlimits exist on Linux only (macOS has no prctl and no /proc and refuses or
# ignores RLIMIT_AS). Each helper below does without and says so in one line (platform_notes),
# instead of failing the grader: the sandbox is then weaker, and `status()` tells the user how.


def _prctl(option: int, arg: int) -> str | None:
    """``prctl(option, arg)``; None when it worked, else why not (one line)."""
    try:
        if ctypes.CDLL(None, use_errno=True).prctl(option, arg, 0, 0, 0) != 0:
            return f"prctl({option}) failed: {os.strerror(ctypes.get_errno())}"
    except (AttributeError, OSError) as e:
        return f"no prctl on this system ({type(e).__name__})"
    return None


def _set_limit(name: str, soft: int, hard: int) -> str | None:
    """``resource.setrlimit(RLIMIT_<name>, ...)``; None when it worked, else why not (one line)."""
    try:
        resource.setrlimit(getattr(resource, f"RLIMIT_{name}"), (soft, hard))
    except (AttributeError, ValueError, OSError) as e:
        return f"RLIMIT_{name} cannot be set here ({type(e).__name__}: {e})"
    return None


def _open_fds() -> list[int]:
    """This process's open descriptors (/proc on Linux, /dev/fd on macOS and BSD)."""
    for folder in ("/proc/self/fd", "/dev/fd"):
        try:
            return [int(n) for n in os.listdir(folder)]
        except (OSError, ValueError):
            continue
    return list(range(min(os.sysconf("SC_OPEN_MAX") if hasattr(os, "sysconf") else 1024, 65536)))


def platform_notes() -> list[str]:
    """One line per Linux-only protection this system lacks (empty on Linux)."""
    notes = []
    try:
        ctypes.CDLL(None).prctl  # noqa: B018 - only whether the symbol exists
    except (AttributeError, OSError):
        notes.append(
            "no prctl: processes that student code detaches are not re-parented to the grader, only its process group is killed"
        )
    if not os.path.isdir("/proc"):
        notes.append("no /proc: the per-user process limit (RLIMIT_NPROC) is not set")
    if not hasattr(resource, "RLIMIT_AS") or sys.platform == "darwin":
        notes.append("the memory limit (RLIMIT_AS) is not enforced on this system")
    if landlock.abi_version() == 0:
        notes.append("no Landlock: student code can read what the user running it can read")
    return notes


# ---------------------------------------------------------------------------------- the worker


def sandbox_ids(user: str) -> tuple[int, int]:
    """The uid and gid student code runs as for ``GEOMLIB_SANDBOX_USER=user``.

    A user name gives that user's ids (``nobody``); a number gives that uid with the gid of the same
    number, which need no passwd entry: ``geomlib grade-all`` gives every submission its own
    (see :mod:`geomlib.grading.batch`). Raises KeyError for an unknown name.
    """
    if user.isdigit():
        return int(user), int(user)
    import pwd

    pw = pwd.getpwnam(user)
    return pw.pw_uid, pw.pw_gid


def confine(req: dict, result_fd: int, out_fd: int) -> None:
    """Everything a worker does to itself before student code runs (see the module docstring)."""
    os.setsid()
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.dup2(out_fd, 1)
    os.dup2(out_fd, 2)
    keep = {0, 1, 2, result_fd}
    for fd in _open_fds():
        if fd not in keep:
            try:
                os.close(fd)
            except OSError:
                pass
    sys.stdin = open(0, closefd=False)  # noqa: SIM115
    sys.stdout = open(1, "w", closefd=False, errors="replace")  # noqa: SIM115
    sys.stderr = open(2, "w", closefd=False, errors="replace")  # noqa: SIM115
    apply_limits(memory_mb=req.get("memory_mb"), cpu_s=req.get("cpu_s"))
    scratch = req.get("scratch")
    user = req.get("user")
    uid = os.geteuid()
    if user and uid == 0:
        new_uid, new_gid = sandbox_ids(user)
        if scratch:
            os.chown(scratch, new_uid, new_gid)
        n = _worker.tasks_of_user(new_uid)
        if n is not None:
            _set_limit("NPROC", n + NPROC_EXTRA, n + NPROC_EXTRA)
        os.setgroups([])
        os.setgid(new_gid)
        os.setuid(new_uid)
        os.environ["HOME"] = scratch or "/nonexistent"
        os.environ["USER"] = os.environ["LOGNAME"] = user
    elif uid != 0 and (n := _worker.tasks_of_user(uid)) is not None:
        _set_limit("NPROC", n + NPROC_EXTRA, n + NPROC_EXTRA)
    if scratch:
        os.environ["TMPDIR"] = scratch
    if req.get("jit_cache"):
        os.environ["NUMBA_CACHE_DIR"] = req["jit_cache"]  # shared by the calls of one snapshot (geomlib.jit)
        # Mesa's compiled shaders too: llvmpipe compiles a shader at its first draw (about 0.3 s of
        # CPU, most of a GLSL call); with its disk cache in the same folder the calls of one snapshot
        # compile each shader once (its default, ~/.cache, is not writable under Landlock).
        os.environ["MESA_SHADER_CACHE_DIR"] = req["jit_cache"]
    if req.get("landlock"):
        landlock.restrict(req.get("read", []), req.get("write", []))
    if req.get("seccomp"):
        seccomp.deny_network()  # no socket but AF_UNIX: no UDP, raw or IPv6 either (Landlock blocks TCP only)
    os.chdir(req.get("cwd") or "/")


def apply_limits(*, memory_mb=None, cpu_s=None) -> list[str]:
    """The worker's resource limits; returns one line per limit this system does not support.

    Where a limit cannot be set (macOS refuses RLIMIT_AS) the worker runs without it: the time limit
    of the grader still stops a runaway call. Linux supports them all.
    """
    skipped = []
    if memory_mb:
        limit = _worker.vm_size_bytes() + int(memory_mb) * 2**20
        skipped.append(_set_limit("AS", limit, limit))
    if cpu_s:
        cpu = int(cpu_s) + 2
        skipped.append(_set_limit("CPU", cpu, cpu + 2))
    skipped.append(_set_limit("CORE", 0, 0))
    skipped.append(_set_limit("FSIZE", FSIZE_LIMIT, FSIZE_LIMIT))
    return [s for s in skipped if s]


def _read_error(path: str) -> OSError | None:
    """Why the current user cannot read ``path`` (list a folder, read a file's first byte), or None."""
    try:
        if os.path.isdir(path):
            os.listdir(path)
        else:
            with open(path, "rb") as f:
                f.read(1)
    except OSError as e:
        return e
    return None


def _probe(req: dict) -> dict:
    """What the sandboxed user can and cannot read (run inside a confined worker)."""
    problems = []
    for what, path in req.get("must_read", []):
        if (e := _read_error(path)) is not None:
            problems.append(f"the sandbox cannot read {what} ({path}: {e.strerror})")
    for path in req.get("must_hide", []):
        if _read_error(path) is None:
            problems.append(f"student code could read {path}, which must stay hidden")
    return {"kind": "probe", "problems": problems, "uid": os.getuid()}


def _worker_main(req: dict, blob: bytes, result_fd: int, out_fd: int) -> None:
    try:
        confine(req, result_fd, out_fd)
        if req.get("op") == "probe":
            _worker.send_json(result_fd, b"P", _probe(req))
            os._exit(0)
        args, kwargs = pickle.loads(blob)
    except BaseException as e:  # noqa: BLE001 - the sandbox itself failed: the grader's problem
        try:
            _worker.send_json(result_fd, b"E", {"kind": "internal", "message": f"sandbox set-up failed: {e!r}"[:2000]})
        finally:
            os._exit(0)
    extra = (req.get("stubs_dir"), req.get("not_allowed"))  # not_allowed: the lab's blacklist
    _worker.run_call(result_fd, req["lab_dir"], req["lab"], req["function"], args, kwargs, *extra)


def _stub_imports(stubs_dir: str) -> set[str]:
    """The absolute modules the course's stubs import at their top level (parsed by prepare_stubs)."""

    names = set()
    for path in Path(stubs_dir).glob("*.py"):
        names |= _imports_in(getattr(_worker._TREES.get((str(path), False)), "body", ()))
    return names


def _imports_in(body) -> set[str]:
    """The absolute modules (and ``module.name`` of ``from module import name``) the statements ``body`` import."""
    names = set()
    for node in body:
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{a.name}" for a in node.names)
    return names


def _top_imports(folder: str) -> set[str]:
    """The absolute modules the ``.py`` files of ``folder`` import at their top level (parsed here,
    never kept as the course's stubs: the folder is graded code)."""
    names = set()
    for path in Path(folder).glob("*.py"):
        try:
            names |= _imports_in(ast.parse(path.read_bytes()).body)
        except (OSError, SyntaxError, ValueError, RecursionError, MemoryError):
            continue
    return names


_PRELOADED_FOR: set = set()


def _preload_for(stubs_dir: str | None, function: str | None = None, own: str | None = None) -> None:
    """Import the modules of :data:`PRELOAD_IF_USED` the lab uses (all of them without stubs); with
    ``function``, only those the call may import (:func:`worker.may_import`): shadows' stubs import
    scipy.ndimage (0.25 s of CPU) for a ray-casting helper that no graded call runs. ``own``: the
    snapshot of stubs graded in place (no other stubs): the modules its files import (numba and its
    warm-up cost 1.5 s of CPU at every start of the grader of a lab without it)."""
    todo = [m for m in PRELOAD_IF_USED if m not in sys.modules]
    if not todo or (stubs_dir, function, own) in _PRELOADED_FOR:
        return
    _PRELOADED_FOR.add((stubs_dir, function, own))
    used = _stub_imports(stubs_dir) if stubs_dir else (_top_imports(own) if own else None)
    for module in todo:
        if used is None or (
            any(n == u or n.startswith(u + ".") for n in used for u in PRELOAD_IF_USED[module])
            and (function is None or not stubs_dir or _worker.may_import(stubs_dir, function, PRELOAD_IF_USED[module]))
        ):
            try:
                importlib.import_module(module)
                if module == "numba":
                    _warm_numba()
            except Exception:  # noqa: BLE001 - a missing optional module only makes workers slower
                pass


def _warm_numba() -> None:
    """Build numba's CPU typing and target contexts (its type registries, LLVM set-up) once, here:
    otherwise every worker builds them at its first compiled call, even one loaded from the cache
    (measured: 1.3 s of CPU per call of a numba lab, sdf's ``build_bvh`` on the stubs 1.5 s -> 0.5 s;
    1.5 s once in the zygote). No code is compiled and no thread started (the fork stays safe)."""
    from numba.core.registry import cpu_target

    cpu_target.typing_context.refresh()
    cpu_target.target_context.refresh()


# ---------------------------------------------------------------------------------- the server


def serve(sock: socket.socket) -> None:
    _prctl(_PR_SET_CHILD_SUBREAPER, 1)  # without prctl (macOS): platform_notes says what is lost
    _prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM))

    def on_term(signum, frame):
        kill_descendants()
        os._exit(0)

    signal.signal(signal.SIGTERM, on_term)
    for name in PRELOAD:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - a missing optional module only makes workers slower
            pass
    send_msg(
        sock,
        {
            "ready": True,
            "pid": os.getpid(),
            "landlock": landlock.abi_version(),
            "seccomp": seccomp.available(),
            "notes": platform_notes(),
        },
    )
    _loop(sock, kernel_zygotes=True)
    kill_descendants()


def _loop(sock: socket.socket, *, kernel_zygotes: bool) -> None:
    """Serve the calls that come on ``sock`` until it closes: the zygote's, and a kernel zygote's
    (``kernel_zygotes=False``: it relays nothing)."""
    while True:
        try:
            req, blob, fds = recv_msg(sock, with_fds=True)
        except (EOFError, OSError, ValueError):
            break
        if req.get("op") == "exit" or len(fds) != 2:
            for fd in fds:
                os.close(fd)
            break
        if kernel_zygotes and _relayed(sock, req, blob, fds):
            continue
        result_fd, out_fd = fds
        t0 = time.monotonic()
        _prepare(req)
        try:
            # PyOpenGL, once, for a lab with shaders, at its first call that may use them
            _worker.prepare_gl(req.get("stubs_dir"), req.get("lab_dir"), function=req.get("function"))
        except Exception:  # noqa: BLE001 - the worker imports it itself (and reports what fails)
            pass
        try:
            blacklist.prepare(req.get("not_allowed"))  # where the lab's forbidden functions are referenced
        except Exception:  # noqa: BLE001 - each worker searches every module itself
            pass
        if not kernel_zygotes and (_threads() != 1 or not _refresh_kernels()):
            os.close(result_fd)  # a thread would not survive the fork: the zygote serves the call itself
            os.close(out_fd)
            send_msg(sock, {"refused": True})
            continue
        # The worker inherits every object of this process frozen: its garbage collections walk only
        # what it made itself. Walking the inherited ones wrote to each of their pages, which the
        # kernel then copied (measured: 0.25 -> 0.12 s of CPU per call of shadows' stubs).
        gc.freeze()
        pid = os.fork()
        if pid == 0:
            sock.close()
            _worker_main(req, blob, result_fd, out_fd)
            os._exit(0)
        gc.unfreeze()  # here they stay collectable: this process lives for a whole grading run
        os.close(result_fd)
        os.close(out_fd)
        send_msg(sock, {"pid": pid})
        _, status = os.waitpid(pid, 0)
        try:
            os.killpg(pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        leftovers = kill_descendants(keep=tuple(k.pid for k in _KERNELS.values()))
        send_msg(sock, {"done": True, "status": status, "leftovers": leftovers, "seconds": time.monotonic() - t0})


def _prepare(req: dict) -> None:
    """What the zygote does for a call before it forks: parse the course's stubs, merge and compile
    the submission's modules with them, import numba and the other modules the call may use (and
    build numba's contexts)."""
    try:
        _worker.prepare_stubs(req.get("stubs_dir"))  # the course's stubs, parsed once for every worker
    except Exception:  # noqa: BLE001 - the worker parses them itself
        pass
    try:
        if req.get("op") == "call":  # the submission's modules merged and compiled once per snapshot
            _worker.prepare_merged(req.get("stubs_dir"), req.get("lab_dir"))
    except Exception:  # noqa: BLE001 - each worker merges them itself
        pass
    try:
        if req.get("op") == "call":
            # numba, scipy.fft: for the calls that use them
            _preload_for(req.get("stubs_dir"), req.get("function"), req.get("preload_from"))
    except Exception:  # noqa: BLE001 - the workers import them themselves
        pass


# ---------------------------------------------------------------------------------- kernel zygotes


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
#: kills it and serves the snapshot itself (the grader waits 60 s for a worker's pid).
KERNEL_ZYGOTE_WAIT_S = 20.0


def _uses_numba(folder: str) -> bool:
    """Whether a module of the lab folder imports numba (or :mod:`geomlib.jit`) at its top level."""
    return any(n.split(".")[0] == "numba" or n == "geomlib.jit" for n in _top_imports(folder))


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
        kill_descendants(keep=tuple(k.pid for k in _KERNELS.values()))
    if for_good:
        _KERNEL_USE[key] = False


def _relayed(sock: socket.socket, req: dict, blob: bytes, fds: list[int]) -> bool:
    """Have the kernel zygote of the call's trusted snapshot serve it (started when there is none):
    True when it did (the grader got its replies), False when the zygote must serve the call itself."""
    key = _kernel_key(req)
    if key is None:
        return False
    if key not in _KERNELS:
        for old in list(_KERNELS)[: max(0, len(_KERNELS) - KERNEL_ZYGOTES + 1)]:
            _drop_kernel_zygote(old, for_good=False)
        _prepare(req)
        if "numba" not in sys.modules:  # built here once, for every later kernel zygote
            importlib.import_module("numba")
            _warm_numba()
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
    if "pid" not in head:  # it refused (a thread), hung or died: the zygote serves this snapshot from now on
        _drop_kernel_zygote(key, for_good=True)
        return False
    for fd in fds:
        os.close(fd)
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
    _prctl(_PR_SET_CHILD_SUBREAPER, 1)  # its workers' orphans come back to it
    _prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM))
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
        _loop(sock, kernel_zygotes=False)
        kill_descendants()


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
            _set_limit("AS", _worker.vm_size_bytes() + int(req["memory_mb"]) * 2**20, old[1])
        try:
            modules = _worker.preload_lab(Path(req["lab_dir"]), req["lab"], Path(stubs) if stubs else None)
        finally:
            _set_limit("AS", *old)
        st["kernels"] = kernelcache.kernels_in(modules)
        st["modules"] = len(sys.modules)
    if st:
        kernelcache.load_cached(st["kernels"], st["seen"])


def main() -> None:
    fd = int(sys.argv[1])
    sock = socket.socket(fileno=fd)
    serve(sock)


if __name__ == "__main__":
    main()
