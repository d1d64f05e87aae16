"""Run student code in sandboxed worker processes with a time, memory and total-time limit.

The grader side of one protocol (about 630 lines): starting the zygote, sending calls, reading
replies under time and size limits, and turning every failure into a message; the worker side is
:mod:`geomlib.grading.worker`, the confinement :mod:`geomlib.grading.landlock`.

The grader starts a *zygote* (:mod:`geomlib.grading.zygote`): a fresh interpreter with NumPy, SciPy,
libigl and geomlib imported, which never sees a case, a reference or the grader's open files. For
each call the grader sends it the function's name and its inputs (pickled: grader → sandbox only);
the zygote forks a confined worker (own session, closed descriptors, resource limits, the sandbox
user when root, Landlock where the kernel has it), and the worker sends its result back through
:mod:`geomlib.grading.wire` (never pickle). The grader reads that reply under the call's time limit
and size limit, then waits until the zygote has killed every process the call started.

Protection levels (reported by :func:`status`):

- root with ``GEOMLIB_SANDBOX_USER`` (Gradescope): student code runs as that user; hidden cases and
  references are made readable by root only; with Landlock also nothing outside Python, geomlib,
  the stubs and its own lab is readable and nothing but a scratch folder and its snapshot's numba cache writable;
- any user with Landlock (``geomlib grade`` / ``grade-all`` by an instructor): the same file-system
  confinement, no TCP, no signals to the grader;
- neither: only the process isolation (fresh zygote, closed descriptors, limits, killed
  descendants); student code can read and write whatever the grading user can.

Before a student's code runs, its lab folder is copied (plain files only, never following links)
into a private read-only snapshot, and each module is merged with the course's stub so that given
code stays the course's (see :mod:`geomlib.grading.worker`). A snapshot is known by the bytes it
holds, checked at every call: a folder edited since (a notebook's ``check()`` run again, one process
grading many copies) gets a new snapshot and a new numba cache, never the old code. The course's
own ``solutions/`` and ``labs/`` (trusted code) are the exception when workers run as the grading
user: their snapshot and compiled kernels are kept between runs, by content, in a per-user cache
that only the grader writes (:mod:`geomlib.grading.kernelcache`), so each version is compiled once.

:class:`LabProxy` makes this look like a module: ``lab.loop_subdivide(V, F)`` runs the student's
``loop_subdivide`` in a worker and returns its result, or raises a
:class:`~geomlib.grading.errors.GradingFailure` whose message a student can act on.
"""

from __future__ import annotations

import atexit
import hashlib
import json
import os
import pickle
import select
import shutil
import signal
import socket
import stat
import struct
import subprocess
import sys
import sysconfig
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.grading import tolerances, wire
from geomlib.grading.errors import (
    BadReturn,
    BudgetSpent,
    GraderError,
    GradingFailure,
    NotImplementedYet,
    StudentCrash,
    StudentError,
    StudentTimeout,
)
from geomlib.grading.settings import env as setting

__all__ = ["call", "LabProxy", "status", "set_deadline", "remaining_time", "clean_text", "shutdown"]

_LOCK = threading.Lock()
_STATE: dict = {"deadline": None, "budget": None}


# ---------------------------------------------------------------------------------- text from students


def clean_text(text, limit: int = tolerances.MESSAGE_CHARS) -> str:
    """Text from student code made safe for messages and results.json.

    Lone surrogates and other unencodable characters become U+FFFD, control characters other than
    newline and tab are dropped, and the text is cut to ``limit`` characters.
    """
    if not isinstance(text, str):
        text = str(text)
    if len(text) > 4 * limit:
        text = text[: 4 * limit]
    text = text.encode("utf-8", errors="surrogatepass").decode("utf-8", errors="replace")
    text = "".join(c for c in text if c in "\n\t" or (c >= " " and c != "\x7f"))
    if len(text) > limit:
        text = text[:limit] + " …"
    return text


# ---------------------------------------------------------------------------------- time budget


def set_deadline(budget_s: float | None) -> None:
    """Start the whole-run time budget: calls after ``budget_s`` seconds from now fail at once."""
    _STATE["budget"] = budget_s
    _STATE["deadline"] = None if not budget_s else time.monotonic() + budget_s


def remaining_time() -> float | None:
    """Seconds left of the whole-run budget (None: no budget)."""
    d = _STATE["deadline"]
    return None if d is None else d - time.monotonic()


def _budget_message() -> str:
    return (
        f"not run: grading stopped after the time budget of {_STATE['budget']:g} s for the whole submission "
        f"was used up (by earlier slow or timed-out calls); make the slow functions faster"
    )


# ---------------------------------------------------------------------------------- the zygote


def _course_root() -> Path:
    from geomlib.grading import impl

    return impl.course_root()


def _geomlib_dir() -> Path:
    import geomlib

    return Path(geomlib.__file__).resolve().parent


def _hidden_paths() -> list[Path]:
    """Course files student code must never read (hidden cases and references)."""
    from geomlib.grading.course import course

    return course().hidden_paths()


def _forbidden() -> list[Path]:
    from geomlib.grading.course import course

    c = course()
    extra = [Path(p) for p in setting("GEOMLIB_SANDBOX_HIDE", "").split(os.pathsep) if p]
    return [c.tests_dir, c.solutions_dir, c.root / ".git", *extra]


#: :func:`_readable_paths` by what it depends on (it resolves dozens of paths: once, not per call).
_READABLE: dict = {}


def _readable_paths() -> list[str]:
    """What a Landlock-confined worker may read: Python, the libraries, geomlib, system folders."""
    key = (tuple(sys.path), setting("GEOMLIB_SANDBOX_HIDE") or "", str(_course_root()))
    if key not in _READABLE:
        _READABLE[key] = _find_readable_paths()
    return list(_READABLE[key])


def _find_readable_paths() -> list[str]:
    cands = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix}
    cands |= {p for k, p in sysconfig.get_paths().items() if k in ("stdlib", "platstdlib", "purelib", "platlib")}
    cands |= {p for p in sys.path if p and os.path.isdir(p)}
    cands |= {str(_geomlib_dir())}
    cands |= {"/usr", "/lib", "/lib64", "/lib32", "/bin", "/sbin", "/etc", "/proc", "/sys", "/dev", "/opt"}
    forbidden = [f.resolve() for f in _forbidden()]
    out = set()
    for c in cands:
        for p in {Path(c).absolute(), Path(c).resolve()}:
            if any(f == p or f.is_relative_to(p) or p.is_relative_to(f) for f in forbidden):
                continue
            if p == Path("/") or Path(tempfile.gettempdir()).resolve().is_relative_to(p):
                continue
            out.add(str(p))
    return sorted(out)


def _protect_hidden() -> None:
    """As root, make hidden cases and references readable by root only (a sandbox user cannot read them)."""
    for p in _hidden_paths():
        try:
            if p.is_dir():
                for q in [p, *p.rglob("*")]:
                    q.chmod(q.stat().st_mode & ~0o077)
            else:
                p.chmod(p.stat().st_mode & ~0o077)
        except OSError:
            pass


#: Lab folders larger than these are copied in part (the same rule for the digest and the copy).
_FILE_LIMIT = 64 << 20
_TOTAL_LIMIT = 512 << 20
_SKIP_DIRS = ("__pycache__", ".git", ".ipynb_checkpoints")


def _lab_files(lab_dir: Path):
    """``(relative path, full path, os.lstat)`` of what a snapshot of ``lab_dir`` holds, in a fixed
    order: each folder (``st`` None; the top one is ``"."``) then its plain files. Walked on strings
    (``Path`` objects cost the grader 5 ms per call: the digest is asked twice per call)."""
    top = str(lab_dir)
    total = 0
    for dirpath, dirnames, filenames in os.walk(top, followlinks=False):
        dirnames[:] = sorted(d for d in dirnames if d not in _SKIP_DIRS)
        rel = dirpath[len(top) + 1 :] if dirpath != top else "."
        yield rel, dirpath, None  # the folder itself (an empty folder is part of the snapshot too)
        for name in sorted(filenames):
            full = os.path.join(dirpath, name)
            try:
                st = os.lstat(full)
            except OSError:
                continue
            if not stat.S_ISREG(st.st_mode) or st.st_size > _FILE_LIMIT or total > _TOTAL_LIMIT:
                continue
            total += st.st_size
            yield (name if rel == "." else f"{rel}/{name}"), full, st


def _read_plain(path: Path) -> bytes:
    """A plain file's bytes, never following a link (nor waiting on a pipe put in its place)."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(f"{path} is not a plain file")
        return f.read()


#: ``path -> (stat key, sha256, when hashed in ns)``: a file is hashed again only when its stat key
#: (inode, size, modification and change times) differs, or it changed so close to its hashing that
#: a later write could keep the same times (file-system clocks tick every few milliseconds; the
#: change time cannot be set back, unlike the modification time: ``os.utime`` moves it forward).
_DIGESTS: dict[str, tuple[tuple, str, int]] = {}
_RACY_NS = 2_000_000_000


def _file_digest(path: str, st: os.stat_result) -> str:
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)
    known = _DIGESTS.get(path)
    if known is not None and known[0] == key and st.st_ctime_ns < known[2] - _RACY_NS:
        return known[1]
    now = time.time_ns()
    digest = hashlib.sha256(_read_plain(path)).hexdigest()
    _DIGESTS[path] = (key, digest, now)
    return digest


def _folder_digest(lab_dir: Path) -> str:
    """What a snapshot of ``lab_dir`` would hold (names and bytes), as one sha256 (:func:`_copy_lab`'s)."""
    h = hashlib.sha256()
    for rel, full, st in _lab_files(lab_dir):
        try:
            digest = _file_digest(full, st) if st is not None else "dir"
        except OSError:
            continue
        h.update(f"{rel}\0{digest}\n".encode("utf-8", "surrogateescape"))
    return h.hexdigest()


def _copy_lab(lab_dir: Path, dest: Path) -> str:
    """Copy ``lab_dir`` into ``dest`` (read-only); returns the digest of what was copied."""
    h = hashlib.sha256()
    for rel, full, st in _lab_files(lab_dir):
        if st is None:
            (dest / rel).mkdir(parents=True, exist_ok=True)
            digest = "dir"
        else:
            try:
                data = _read_plain(full)
            except OSError:
                continue
            (dest / rel).write_bytes(data)
            digest = hashlib.sha256(data).hexdigest()
        h.update(f"{rel}\0{digest}\n".encode("utf-8", "surrogateescape"))
    for dirpath, _dirnames, filenames in os.walk(dest.parent):
        os.chmod(dirpath, 0o555)
        for name in filenames:
            os.chmod(os.path.join(dirpath, name), 0o444)
    return h.hexdigest()


@dataclass
class _Snapshot:
    """A read-only copy of a lab folder, known by the digest of what it holds."""

    key: str
    dest: Path
    #: digest of the course's stubs (``""``: none) -> the numba cache folder of this code
    jit: dict[str, Path] = field(default_factory=dict)
    #: trusted code only: its entry in the persistent kernel cache (``dest`` is inside it, never
    #: removed by this process), and what :func:`kernelcache.seed` put into its ``jit`` folder
    shared: object | None = None
    seeded: dict = field(default_factory=dict)


class _Zygote:
    def __init__(self):
        parent, child = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self.log = tempfile.TemporaryFile(prefix="geomlib-zygote-")
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(_geomlib_dir().parent), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        env.setdefault("OPENBLAS_NUM_THREADS", "1")
        env.setdefault("OMP_NUM_THREADS", "1")
        env.setdefault("MKL_NUM_THREADS", "1")
        # the zygote, with its kernel zygotes for the course's own code of numba labs
        code = "import sys; from geomlib.grading import kernelzygote; from geomlib.grading.zygote import main; main(kernelzygote)"
        self.proc = subprocess.Popen(
            [sys.executable, "-s", "-c", code, str(child.fileno())],
            pass_fds=[child.fileno()],
            stdin=subprocess.DEVNULL,
            stdout=self.log,
            stderr=self.log,
            cwd="/",
            env=env,
            start_new_session=True,  # a kill of the grader's group reaches it as PDEATHSIG, so it cleans up
        )
        child.close()
        self.sock = parent
        self.sock.settimeout(120)
        try:
            from geomlib.grading.zygote import recv_msg

            ready, _, _ = recv_msg(self.sock)
        except (OSError, EOFError, ValueError) as e:
            raise GraderError(f"the sandbox could not start ({e}): {self.log_tail()}") from None
        # GEOMLIB_LANDLOCK=0 turns Landlock off (to test the protection of a kernel without it).
        self.landlock = 0 if setting("GEOMLIB_LANDLOCK") == "0" else int(ready.get("landlock", 0))
        # What a non-Linux system lacks (no prctl, no /proc, RLIMIT_AS ignored), one line each.
        self.notes = [n for n in ready.get("notes", []) if "Landlock" not in n]
        for note in self.notes:  # once per run, on stderr: the sandbox works, with less
            print(f"geomlib sandbox: {note}", file=sys.stderr)
        # GEOMLIB_SECCOMP=0 turns the network filter off (to test what it blocks).
        self.seccomp = bool(ready.get("seccomp")) and setting("GEOMLIB_SECCOMP") != "0"
        self.user = setting("GEOMLIB_SANDBOX_USER") or None
        self.is_root = os.geteuid() == 0
        if self.user and not self.is_root:
            self.user = None  # only root can switch users; say so in status()
        # Private to this run: only root and (when there is one) the sandbox user's group may enter,
        # so no other user's processes (another submission's workers under grade-all, each with its
        # own uid and gid) can reach this run's snapshots, scratch folders or numba cache.
        self.scratch_root = Path(tempfile.mkdtemp(prefix="geomlib-sandbox-"))
        self.scratch_root.chmod(0o700)
        # numba's caches (NUMBA_CACHE_DIR in the worker, see geomlib.jit), one per snapshot of a
        # submission and version of the stubs: the first call compiles a lab's kernels, later calls
        # of the same code load them (each call's own scratch folder would make every call compile
        # again, seconds per call). numba knows a source by path, mtime and size only, and a given
        # kernel of the stubs that calls a task kernel holds the submission's machine code: a
        # cache shared by two versions of a submission would run the first version's kernels.
        self.jit_cache = self.scratch_root / "numba-cache"
        self.jit_cache.mkdir(mode=0o700)
        #: resolved lab folder -> its current snapshot (most recently used last)
        self.snapshots: dict[str, _Snapshot] = {}
        self.problems: list[str] = []
        if self.user:
            from geomlib.grading.zygote import sandbox_ids

            try:
                uid, gid = sandbox_ids(self.user)
                os.chown(self.scratch_root, -1, gid)
                self.scratch_root.chmod(0o710)
                # The sandbox user may enter, not write: each snapshot's own cache is its (_jit_folder).
                os.chown(self.jit_cache, -1, gid)
                self.jit_cache.chmod(0o710)
            except KeyError:
                self.problems.append(f"the sandbox user {self.user!r} (GEOMLIB_SANDBOX_USER) does not exist")
            _protect_hidden()
        if not self.problems:
            self._probe()

    def log_tail(self) -> str:
        try:
            self.log.seek(0)
            return self.log.read()[-1500:].decode("utf-8", "replace").strip()
        except OSError:
            return ""

    def request(self, req: dict) -> dict:
        req = {
            **req,
            "user": self.user,
            "landlock": self.landlock > 0,
            "seccomp": self.seccomp,
            "read": _readable_paths() + req.get("read", []),
        }
        return req

    def _probe(self) -> None:
        import numpy

        must_read = [
            ("Python's standard library", os.path.dirname(os.__file__)),
            ("NumPy", os.path.dirname(numpy.__file__)),
            ("geomlib", str(_geomlib_dir())),
        ]
        must_hide = [str(p) for p in _hidden_paths()] if (self.user or self.landlock) else []
        try:
            reply = self.run(self.request({"op": "probe", "must_read": must_read, "must_hide": must_hide}), b"", 60)
        except GradingFailure as e:
            self.problems.append(str(e))
            return
        data = reply.get("data") or b""
        try:
            info = json.loads(data[1:].decode()) if data[:1] in (b"P", b"E") else {}
        except ValueError:
            info = {}
        if info.get("kind") != "probe":
            why = info.get("message") or reply.get("why")
            self.problems.append(f"sandbox self-test failed ({why}): {self.log_tail()}".rstrip(": "))
        else:
            self.problems += info.get("problems", [])

    def snapshot(self, lab_dir: Path, stubs: Path | None = None, *, trusted: bool = False) -> tuple[Path, Path]:
        """A private, read-only copy of a lab folder (plain files only, links never followed) and the
        numba cache folder of its workers.

        Known by its contents, checked at every call: a folder whose bytes changed since its snapshot
        was made (even with its files' size and modification time put back) gets a new snapshot in a
        new folder and a new numba cache, and the old ones are removed. The cache is also per
        version of the course's ``stubs`` (given kernels are compiled with the submission's).

        ``trusted``: the folder is the course's own (its ``solutions/`` or ``labs/``, graded with its
        own stubs). Then, when the workers run as the grading user, the snapshot is the persistent
        one of :mod:`geomlib.grading.kernelcache` (same bytes, same path in every process) and its
        numba cache is seeded with what earlier processes compiled; see :meth:`publish`.
        """
        path = lab_dir.resolve()
        key = _folder_digest(path)
        stubs_key = _folder_digest(stubs.resolve()) if stubs is not None else ""
        snap = self.snapshots.pop(str(path), None)
        if snap is not None and (snap.key != key or (snap.shared is not None and snap.shared.stubs_key != stubs_key)):
            self._drop(snap)
            snap = None
        if snap is None:
            self._evict()
            entry = self._shared_entry(path, key, stubs_key) if trusted else None
            if entry is not None:
                snap = _Snapshot(entry.lab_key, entry.src, shared=entry)
            else:
                dest = Path(tempfile.mkdtemp(prefix="lab-", dir=self.scratch_root)) / lab_dir.name
                snap = _Snapshot(_copy_lab(path, dest), dest)
        self.snapshots[str(path)] = snap
        if stubs_key not in snap.jit:
            snap.jit[stubs_key] = self._jit_folder()
            if snap.shared is not None:
                from geomlib.grading import kernelcache

                snap.seeded = kernelcache.seed(snap.shared, snap.jit[stubs_key])
        return snap.dest, snap.jit[stubs_key]

    def _shared_entry(self, path: Path, key: str, stubs_key: str):
        """The persistent kernel-cache entry of trusted code, or None (off, unusable, or the workers
        run as a sandbox user, who could not read the grading user's cache: each run compiles)."""
        from geomlib.grading import kernelcache
        from geomlib.grading.settings import kernel_cache_dir

        cache = kernel_cache_dir()
        if cache is None or self.user:
            return None
        return kernelcache.open_entry(cache, path, key, stubs_key, _copy_lab)

    def publish(self, lab_dir: Path) -> None:
        """Copy what the last call of the trusted ``lab_dir`` compiled into its persistent entry
        (:func:`kernelcache.publish`); nothing for other code."""
        snap = self.snapshots.get(str(Path(lab_dir).resolve()))
        if snap is None or snap.shared is None:
            return
        from geomlib.grading import kernelcache

        try:
            kernelcache.publish(snap.shared, snap.jit[snap.shared.stubs_key], snap.seeded)
        except OSError:
            pass  # the next process compiles what was not kept

    def shares_kernels(self, lab_dir: Path) -> bool:
        """Whether the current snapshot of ``lab_dir`` is trusted code's persistent one (:meth:`snapshot`)."""
        snap = self.snapshots.get(str(Path(lab_dir).resolve()))
        return snap is not None and snap.shared is not None

    def _jit_folder(self) -> Path:
        """A new numba cache folder that the workers (the sandbox user) can write."""
        folder = Path(tempfile.mkdtemp(prefix="jit-", dir=self.jit_cache))
        if self.user:
            from geomlib.grading.zygote import sandbox_ids

            try:
                os.chown(folder, *sandbox_ids(self.user))
            except KeyError:
                pass  # reported by self.problems
        return folder

    #: Snapshots kept for folders graded earlier in this process (an audit grades hundreds of copies).
    KEEP = 8

    def _evict(self) -> None:
        """Drop the snapshots of folders that are gone, and the oldest beyond :attr:`KEEP`."""
        for path in list(self.snapshots):
            if not os.path.isdir(path) or len(self.snapshots) >= self.KEEP:
                self._drop(self.snapshots.pop(path))
                for name in [n for n in _DIGESTS if n.startswith(path + os.sep)]:
                    del _DIGESTS[name]

    @staticmethod
    def _drop(snap: _Snapshot) -> None:
        from geomlib.grading.kernelcache import remove_tree

        if snap.shared is None:  # a persistent snapshot (trusted code) is kept for later runs
            remove_tree(snap.dest.parent)
        for folder in snap.jit.values():
            shutil.rmtree(folder, ignore_errors=True)

    def run(self, req: dict, blob: bytes, timeout: float, max_bytes: int | None = None, on_pid=None) -> dict:
        """Send one request; returns ``{"data": bytes|None, "why": ..., "status": ..., "printed": str}``.

        ``req["jit_cache"]``: the numba cache of the submission's snapshot (:meth:`snapshot`).
        """
        reply = self._attempt(req, blob, timeout, max_bytes)
        if reply is None:
            # A kernel zygote was given the call and failed (kernelzygote.relayed): once more, with a
            # new pipe, output file and scratch folder that none of its processes ever had.
            reply = self._attempt(req, blob, timeout, max_bytes)
        if reply is None:
            raise GraderError(f"the sandbox stopped working (it asked twice for the same call): {self.log_tail()}")
        return reply

    def _attempt(self, req: dict, blob: bytes, timeout: float, max_bytes: int | None) -> dict | None:
        """:meth:`run` with its own result pipe, output file and scratch folder; None when the zygote
        asks for the call to be sent again."""
        from geomlib.grading.zygote import recv_msg, send_msg

        r, w = os.pipe()
        out_fd, out_path = tempfile.mkstemp(prefix="geomlib-out-", dir=self.scratch_root)
        scratch = tempfile.mkdtemp(prefix="call-", dir=self.scratch_root)
        os.chmod(scratch, 0o700)
        jit = req.get("jit_cache")
        req = {**req, "scratch": scratch, "write": [scratch, *([jit] if jit else []), os.devnull]}
        pid = None
        try:
            try:
                send_msg(self.sock, req, blob, fds=[w, out_fd])
                os.close(w)
                w = -1
                self.sock.settimeout(60)
                head, _, _ = recv_msg(self.sock)
                if head.get("retry"):
                    return None
                pid = head["pid"]
            except (OSError, EOFError, ValueError, KeyError) as e:
                raise GraderError(f"the sandbox stopped working ({e}): {self.log_tail()}") from None
            data, why = _read_frame(r, time.monotonic() + timeout, max_bytes)
            if why == "timeout":
                for kill in (lambda: os.killpg(pid, signal.SIGKILL), lambda: os.kill(pid, signal.SIGKILL)):
                    try:
                        kill()
                    except (ProcessLookupError, PermissionError):
                        pass
            try:
                self.sock.settimeout(60)
                done, _, _ = recv_msg(self.sock)
            except (OSError, EOFError, ValueError) as e:
                raise GraderError(f"the sandbox stopped working ({e}): {self.log_tail()}") from None
            os.lseek(out_fd, 0, 0)
            printed = os.read(out_fd, 4 * tolerances.OUTPUT_CHARS).decode("utf-8", "replace")
            from geomlib.grading import shader_watch

            shader = shader_watch.read(scratch) if data is None else None  # the shader the call died in, if any
            return {"data": data, "why": why, "status": done.get("status", 0), "printed": printed, "shader": shader}
        finally:
            for fd in (r, w, out_fd):
                if fd >= 0:
                    try:
                        os.close(fd)
                    except OSError:
                        pass
            for p in (out_path,):
                try:
                    os.unlink(p)
                except OSError:
                    pass
            shutil.rmtree(scratch, ignore_errors=True)

    def close(self) -> None:
        try:
            from geomlib.grading.zygote import send_msg

            send_msg(self.sock, {"op": "exit"})
            self.sock.close()
            self.proc.wait(10)
        except Exception:  # noqa: BLE001
            self.proc.kill()
        from geomlib.grading.kernelcache import remove_tree

        remove_tree(self.scratch_root)  # the private snapshots; a persistent one is not in it: kept


def _read_frame(fd: int, deadline: float, max_bytes: int | None) -> tuple[bytes | None, str]:
    """Read one ``<Q``-length-prefixed message before ``deadline``: (data, "ok"), or (None, why)."""
    os.set_blocking(fd, False)
    buf = bytearray()
    need = 8
    length = None
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return None, "timeout"
        ready, _, _ = select.select([fd], [], [], min(left, 1.0))
        if not ready:
            continue
        try:
            chunk = os.read(fd, min(need - len(buf), 1 << 22))
        except BlockingIOError:
            continue
        if not chunk:
            return None, "eof"
        buf += chunk
        if len(buf) < need:
            continue
        if length is None:
            (length,) = struct.unpack("<Q", bytes(buf[:8]))
            limit = (max_bytes or 1 << 40) + (1 << 20)
            if length > limit:
                return None, "too_big"
            buf = bytearray()
            need = length
            if need == 0:
                return b"", "ok"
            continue
        return bytes(buf), "ok"


def _zygote() -> _Zygote:
    with _LOCK:
        z = _STATE.get("zygote")
        if z is None or z.proc.poll() is not None:
            z = _STATE["zygote"] = _Zygote()
        return z


def status() -> str:
    """One line saying how student code is confined in this run."""
    z = _zygote()
    if z.problems:
        return "sandbox NOT working: " + "; ".join(z.problems)
    parts = []
    if z.user:
        parts.append(f"runs as user {z.user}")
    if z.landlock:
        parts.append(f"Landlock file-system confinement (ABI {z.landlock})")
    net = " and no network sockets (seccomp)" if z.seccomp else ""
    if not parts:
        text = (
            f"student code is process-isolated only{net} (not root and no Landlock): it can read and write "
            "whatever this user can"
        )
    else:
        text = "student code " + " with ".join(parts) + net
    return text + "".join(f"; {n}" for n in z.notes)


def shutdown() -> None:
    """Stop the zygote and remove the snapshots (also done at exit)."""
    z = _STATE.pop("zygote", None)
    if z is not None:
        z.close()


atexit.register(shutdown)


# ---------------------------------------------------------------------------------- one call


def _signal_name(code: int) -> str:
    try:
        return signal.Signals(code).name
    except ValueError:
        return f"signal {code}"


def _format_student_exception(function: str, info: dict) -> str:
    if info.get("type") == "ShaderError":  # the message leads with the shader's file and line; the
        return f"{function}: {clean_text(info.get('message', ''))}"  # Python frame is the given code's
    where = ""
    frames = info.get("frames") if isinstance(info.get("frames"), list) else []
    if frames and isinstance(frames[-1], dict):
        f = frames[-1]
        code = f" `{clean_text(f.get('code', ''), 300).strip()}`" if f.get("code") else ""
        where = (
            f" at {clean_text(f.get('file', '?'), 200)}, line {clean_text(f.get('line', '?'), 20)} "
            f"(in {clean_text(f.get('function', '?'), 200)}):{code}"
        )
    return f"{function} raised {clean_text(info.get('type', '?'), 200)}{where}: {clean_text(info.get('message', ''))}"


def _resolved(path: str) -> Path:
    """A course folder (stubs, solutions) resolved once per run, as the course's root is
    (:func:`geomlib.grading.course._resolved`); a submission's folder is resolved at every call."""
    from geomlib.grading.course import _resolved as resolved

    return resolved(path)


def _stubs_dir(lab: str, lab_dir: Path) -> tuple[Path | None, bool]:
    """``(stubs, in_place)``: the course's stubs of ``lab`` (``GEOMLIB_STUBS``, else the course's
    ``labs/``) to merge with ``lab_dir``, None when there are none or ``lab_dir`` is those stubs
    themselves; ``in_place``: ``lab_dir`` is the course's stubs (a student's ``labs/<lab>``)."""
    base = setting("GEOMLIB_STUBS")
    from geomlib.grading.course import course

    stubs = Path(base) / lab if base else course().lab(lab).stubs
    in_place = _resolved(str(stubs)) == lab_dir.resolve()
    return (None if in_place or not stubs.is_dir() else stubs), in_place


def _trusted(lab: str, lab_dir: Path, stubs: Path | None) -> bool:
    """Whether ``lab_dir`` is the course's own code (its solutions or stubs of ``lab``, as the
    :class:`~geomlib.grading.course.Course` knows them) graded with the course's own stubs: the
    only code whose compiled kernels are kept between runs (:mod:`geomlib.grading.kernelcache`)."""
    from geomlib.grading.course import course

    paths = course().lab(lab)
    own = {_resolved(str(paths.solution)), _resolved(str(paths.stubs))}
    return lab_dir.resolve() in own and (stubs is None or _resolved(str(stubs)) == _resolved(str(paths.stubs)))


def _not_allowed(lab: str) -> dict[str, str]:
    """The lab's blacklist (:mod:`geomlib.grading.blacklist`), read once per run."""
    from geomlib.grading import blacklist, impl

    key = ("not_allowed", str(impl.tests_dir()), lab)
    if key not in _STATE:
        try:
            _STATE[key] = blacklist.declared(lab)
        except (OSError, SyntaxError, ValueError) as e:
            raise GraderError(f"grader problem (not your code): the lab's blacklist cannot be read ({e})") from None
    return _STATE[key]


def _input_bytes(args, kwargs) -> int:
    import numpy as np

    total = 0
    for v in [*args, *kwargs.values()]:
        if isinstance(v, np.ndarray):
            total += v.nbytes
        elif isinstance(v, tuple | list):
            total += sum(x.nbytes for x in v if isinstance(x, np.ndarray))
    return total


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
    BudgetSpent
        The whole run's time budget is used up (the call is not made).
    GraderError
        The sandbox itself failed: the grader's problem, never the student's.
    """
    timeout = tolerances.TIME_LIMIT_S if timeout is None else timeout
    memory_mb = tolerances.MEMORY_LIMIT_MB if memory_mb is None else memory_mb
    left = remaining_time()
    if left is not None:
        if left <= 0.5:
            raise BudgetSpent(_budget_message())
        timeout = min(timeout, left)
    kwargs = dict(kwargs or {})
    z = _zygote()
    if z.problems:
        raise GraderError("grader problem (not your code): " + "; ".join(z.problems) + "; please tell the course staff")
    try:
        blob = pickle.dumps((tuple(args), kwargs), protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as e:  # noqa: BLE001
        raise GraderError(f"grader problem (not your code): cannot pass the inputs of {function} ({e})") from None
    lab_dir = Path(lab_dir)
    stubs, in_place = _stubs_dir(lab, lab_dir)
    snap, jit = z.snapshot(lab_dir, stubs, trusted=_trusted(lab, lab_dir, stubs))
    max_bytes = max(tolerances.RESULT_MIN_MB << 20, tolerances.RESULT_INPUT_FACTOR * _input_bytes(args, kwargs))
    req = z.request(
        {
            "op": "call",
            "lab_dir": str(snap),
            "lab": lab,
            "function": function,
            "stubs_dir": str(stubs) if stubs else None,
            # The stubs graded in place (a student's labs/<lab>, `--impl labs`): the zygote preloads
            # what their own imports use (zygote._preload_for), not numba & co. for every lab.
            "preload_from": str(snap) if in_place else None,
            "memory_mb": memory_mb,
            "cpu_s": timeout,
            "cwd": str(snap),
            "read": [str(snap)] + ([str(stubs)] if stubs else []),
            "not_allowed": _not_allowed(lab),
            "jit_cache": str(jit),
            # the course's own code in its persistent snapshot: served by a kernel zygote (kernelzygote.py)
            "trusted_kernels": z.shares_kernels(lab_dir),
        }
    )
    reply = z.run(req, blob, timeout, max_bytes)
    z.publish(lab_dir)
    if reply.get("shader"):
        from geomlib.grading import shader_watch

        reply["shader"] = shader_watch.timeout_message(
            function, timeout, reply["shader"], [p for p in (stubs, snap) if p]
        )
    return _outcome(function, reply, timeout, memory_mb, max_bytes)


def _outcome(function: str, reply: dict, timeout: float, memory_mb: int, max_bytes: int):
    printed = clean_text(reply["printed"], tolerances.OUTPUT_CHARS).strip()
    tail = f" Your code printed: {printed!r}" if printed else ""
    data, why = reply["data"], reply["why"]
    if why == "timeout":
        left = remaining_time()
        if left is not None and left <= 0.5:
            raise StudentTimeout(
                f"{function} was stopped after {timeout:.3g} s when the time budget for the whole submission "
                f"({_STATE['budget']:g} s) ran out; make the slow functions faster"
            )
        if reply.get("shader"):
            raise StudentTimeout(reply["shader"])
        raise StudentTimeout(
            f"{function} did not finish within {timeout:g} s (time limit); look for an infinite loop "
            f"or a Python loop over every vertex/pixel that should be vectorised"
        )
    if why == "too_big":
        raise BadReturn(f"{function} sent back more than {max_bytes >> 20} MiB, more than this call may return")
    if data is None:
        st = reply["status"]
        if os.WIFSIGNALED(st):
            sig = _signal_name(os.WTERMSIG(st))
            what = {
                "SIGSEGV": "a segmentation fault",
                "SIGXCPU": "exceeding the CPU-time limit",
                "SIGXFSZ": "writing more output than allowed",
                "SIGKILL": "being killed (out of memory?)",
                "SIGABRT": "an abort",
            }.get(sig, sig)
            if sig == "SIGXCPU" and reply.get("shader"):  # llvmpipe's threads spent the CPU-time limit
                raise StudentTimeout(reply["shader"])
            raise StudentCrash(f"{function} crashed the worker process with {what}.{tail}")
        code = os.WEXITSTATUS(st) if os.WIFEXITED(st) else "?"
        raise StudentCrash(
            f"{function} ended the process (exit code {code}, e.g. os._exit) without returning a result.{tail}"
        )
    tag, body = data[:1], data[1:]
    if tag == b"R":
        try:
            return wire.decode(body, max_bytes=max_bytes, max_dense_elements=tolerances.SPARSE_MAX_DENSE)
        except wire.WireError as e:
            raise BadReturn(f"{function} sent back data the grader could not read ({clean_text(e, 300)})") from None
    if len(body) > 1 << 20:
        raise BadReturn(f"{function} sent back a message of {len(body)} bytes, more than the grader reads")
    try:
        info = json.loads(body.decode("utf-8", "replace"))
        if not isinstance(info, dict):
            raise ValueError
    except (ValueError, RecursionError):
        raise BadReturn(f"{function} sent back data the grader could not read (not a result message)") from None
    kind = info.get("kind")
    if tag == b"E" and kind == "internal":
        raise GraderError(
            f"grader problem (not your code) while calling {function}: {clean_text(info.get('message', ''), 500)}; "
            f"please tell the course staff"
        )
    message = clean_text(info.get("message", ""))
    if kind == "exception" and info.get("type") == "NotImplementedError":
        task = f" ({message})" if message else ""
        raise NotImplementedYet(f"{function}: not implemented yet{task}")
    if kind == "exception":
        mro = [clean_text(m, 200) for m in info.get("mro", [])[:20]] if isinstance(info.get("mro"), list) else []
        text = _format_student_exception(function, info)
        if tail and not text.endswith("."):  # "... is not defined. Your code printed: ..."
            text += "."
        raise StudentError(text + tail, clean_text(info.get("type", "?"), 200), mro, message)
    if kind == "memory":
        raise StudentCrash(f"{function} ran out of memory (limit {memory_mb} MiB).{tail}")
    if kind == "exit":
        raise StudentCrash(f"{function} {message} instead of returning a result.{tail}")
    if kind == "missing":
        raise StudentError(message, "LookupError", ["LookupError", "Exception"], message)
    if kind == "bad_return":
        raise BadReturn(message + "." + tail)
    raise BadReturn(f"{function} sent back a message the grader does not know ({clean_text(kind, 100)})")


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
