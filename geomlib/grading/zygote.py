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

Kernel zygotes (:mod:`geomlib.grading.kernelzygote`): the course's own code of a numba lab is
served by a fork of the zygote that keeps the lab's compiled kernels loaded; it runs this module's
loop (:func:`serve_calls`), and this loop hands it the calls of its snapshot (``kernels``). The
zygote itself never imports a lab.
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
from pathlib import Path

from geomlib.grading import blacklist, landlock, seccomp
from geomlib.grading import worker as _worker

_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36

#: Imported once in the zygote so every forked worker starts with them loaded.
PRELOAD = (
    "numpy",
    "scipy.sparse",
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
    # vdm's parameterisation and transport (splu; simplification's optional refit imports it inside
    # its function, so at its call): 0.1 s of CPU at every start of a zygote for the other labs, and
    # for the ~90 zygotes of one run of the test suite (mostly the sample course's).
    "scipy.sparse.linalg": ("scipy.sparse.linalg",),
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


def serve(sock: socket.socket, kernels=None) -> None:
    """The zygote: set up, say it is ready, serve the grader's calls on ``sock`` until it closes.

    ``kernels``: what hands the calls of trusted snapshots to kernel zygotes
    (:mod:`geomlib.grading.kernelzygote`: its ``relayed`` and ``pids``), or None: every call is
    served here."""
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
    serve_calls(sock, kernels=kernels)
    kill_descendants()


def serve_calls(sock: socket.socket, *, kernels=None, before_fork=None) -> None:
    """Serve the calls that come on ``sock`` until it closes: fork a worker per call, wait for it,
    kill what it left. The zygote's loop, and a kernel zygote's.

    ``kernels``: the zygote's kernel zygotes (see :func:`serve`); ``kernels.relayed(sock, req, blob,
    fds)`` is True when one of them served the call, and their pids are kept when the leftovers of
    a call are killed. ``before_fork``: a kernel zygote's check before each fork (False: it refuses
    the call, and the zygote serves it itself)."""
    while True:
        try:
            req, blob, fds = recv_msg(sock, with_fds=True)
        except (EOFError, OSError, ValueError):
            break
        if req.get("op") == "exit" or len(fds) != 2:
            for fd in fds:
                os.close(fd)
            break
        if kernels is not None and kernels.relayed(sock, req, blob, fds):
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
        if before_fork is not None and not before_fork():
            os.close(result_fd)  # e.g. a thread would not survive the fork: the zygote serves the call itself
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
        leftovers = kill_descendants(keep=kernels.pids() if kernels is not None else ())
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


def main(kernels=None) -> None:
    """The zygote process (``python -c``, the socket's descriptor in ``argv[1]``); ``kernels``: see :func:`serve`."""
    fd = int(sys.argv[1])
    sock = socket.socket(fileno=fd)
    serve(sock, kernels)


if __name__ == "__main__":
    main()
