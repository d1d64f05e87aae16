"""Compiled kernels of the course's own code kept between grading runs: compiled once per content.

Every grading process copies the lab it grades into a private snapshot (:mod:`geomlib.grading.sandbox`)
and gives its workers a private numba cache; numba finds a cached kernel by the folder path of its
source file, so each process compiled a lab's kernels again (about 20 s of CPU for remeshing,
simplification or sdf). The test suite grades the course's own ``solutions/`` and ``labs/`` in
dozens of processes (``geomlib grade``, notebooks' ``check()``, xdist workers), each compiling.

For **trusted** code only — the course's own ``solutions/<lab>`` and ``labs/<lab>`` as the
:class:`~geomlib.grading.course.Course` knows them, graded with the course's own stubs — and only
when the workers run as the grading user itself (no sandbox user), a grading process uses an
*entry* of a per-user persistent cache instead (:func:`open_entry`):

- ``<cache>/<key>/src/<lab>/``: a read-only snapshot of the lab at a path that depends on its
  content only: ``<key>`` is a digest of the snapshot's bytes, the stubs' bytes, the lab's name and
  the Python, numba, llvmlite and NumPy versions and the machine type. Same bytes, same folder,
  so numba's own lookup (by source folder, then by the source file's digest) finds what an
  earlier process compiled; changed bytes (one constant) give another folder and another compile.
  numba keeps different CPUs apart inside its index (the key of an entry holds the target CPU's
  name and features), so one entry serves every CPU target. The entry is made in a private
  temporary folder and renamed into place: a reader never sees half of one.
- ``<cache>/<key>/numba/``: what workers compiled for that code. Workers never write there: each
  grading process still gives its workers a private cache folder (in its private scratch folder,
  as for any submission), *seeded* from the entry (hard links, else copies: numba replaces a file
  with ``os.replace``, it never writes into one) — :func:`seed`. After each call the grader
  *publishes* what the call compiled (:func:`publish`): per kernel, numba's index and the data
  files it names, data first, each by ``os.replace``, under a lock on the entry; a kernel whose
  index another process published since this one seeded is left as that process wrote it (numba
  extends an index it loaded, so the private one is a superset of what was seeded; two processes
  writing one index at once could otherwise lose entries or pair an index with another's data).

Why this is safe: the cache folder must be a real folder owned by the grading user that no one
else can write (else it is not used); nothing from a submission is ever published (a submission's
snapshot and numba cache stay private to its grading process, removed with it), so a submission
can neither plant machine code that the course's solutions or another submission later load, nor
be served another's. With Landlock a worker can write only its scratch folder and its private
numba cache, never the persistent cache; as root with a sandbox user (the autograder,
``grade-all``) nothing is shared at all (the workers would run as that user, who may not read the
grading user's cache). Without either protection student code can write whatever the grading user
can (its own ``~/.cache`` included): ``sandbox.status()`` says so, grade others' code as root or
under Landlock.

Loaded once per grading process (:func:`kernels_in`, :func:`load_cached`): a worker that loads its
kernels from the cache itself spends 0.03-0.1 s of CPU per call on it (reading numba's index,
unpickling, linking the machine code) and on importing the lab; the grading process makes dozens
of calls per lab. For the same trusted snapshots, the zygote forks a *kernel zygote*
(:mod:`geomlib.grading.kernelzygote`) that imports the lab and loads every kernel compiled for it from
the workers' private cache folder (only the grader and that snapshot's own workers can write it,
as for :func:`publish`) once, then forks that snapshot's workers: they start with the kernels loaded.

Where: ``GEOMLIB_KERNEL_CACHE``, else ``$XDG_CACHE_HOME/geomlib-kernels``, else
``~/.cache/geomlib-kernels`` (:func:`geomlib.grading.settings.kernel_cache_dir`); ``off`` turns
it off. Entries unused for :data:`MAX_AGE_S` are removed when a new one is made.
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import hashlib
import json
import os
import platform
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from geomlib.jit import is_private_folder

__all__ = ["Entry", "open_entry", "seed", "publish", "remove_tree", "kernels_in", "load_cached", "MAX_AGE_S"]

#: Entries not used for this long are removed when a new entry is made (none is ever in use that long).
MAX_AGE_S = 14 * 24 * 3600
#: A half-made entry (its maker was killed) older than this is removed.
_STALE_NEW_S = 3600
#: numba's files: an index per kernel (``<base>.nbi``) naming its data files (``<base>.<n>.nbc``).
_INDEX, _DATA = ".nbi", ".nbc"


@dataclass(frozen=True)
class Entry:
    """One content-addressed entry: ``root/src/<lab>`` (read-only snapshot) and ``root/numba``."""

    root: Path
    lab_name: str
    #: digest of the snapshot's bytes (``sandbox._folder_digest``) and of the stubs' (``""``: none)
    lab_key: str
    stubs_key: str

    @property
    def src(self) -> Path:
        return self.root / "src" / self.lab_name

    @property
    def numba(self) -> Path:
        return self.root / "numba"


@functools.lru_cache(maxsize=1)
def _versions() -> tuple[str, ...]:
    from importlib import metadata

    def version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "none"

    return (
        sys.version,
        sys.implementation.cache_tag,
        platform.machine(),
        *map(version, ("numba", "llvmlite", "numpy")),
    )


def entry_key(lab_name: str, lab_key: str, stubs_key: str) -> str:
    """The folder name of the entry for these bytes, this lab name and these library versions."""
    text = json.dumps([lab_name, lab_key, stubs_key, *_versions()])
    return hashlib.sha256(text.encode()).hexdigest()[:40]


@contextlib.contextmanager
def _locked(path: Path):
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def remove_tree(folder: Path) -> None:
    """Remove ``folder`` and everything in it, read-only folders included (snapshots are 0o555)."""
    for dirpath, _, _ in os.walk(folder):
        with contextlib.suppress(OSError):
            os.chmod(dirpath, 0o700)
    shutil.rmtree(folder, ignore_errors=True)


def _evict(cache: Path) -> None:
    now = time.time()
    with _locked(cache / ".lock"):
        for child in cache.iterdir():
            try:
                age = now - child.lstat().st_mtime
            except OSError:
                continue
            new = child.name.startswith(".new-")
            if child.is_dir() and age > (_STALE_NEW_S if new else MAX_AGE_S):
                remove_tree(child)


def open_entry(cache: Path, lab_dir: Path, lab_key: str, stubs_key: str, copy) -> Entry | None:
    """The entry of the trusted lab folder ``lab_dir`` (made if missing), or None when ``cache``
    cannot be used (not creatable, or not private to this user).

    ``copy(lab_dir, dest)`` copies the lab read-only into ``dest`` and returns the digest of what it
    copied (``sandbox._copy_lab``): the entry is named by the bytes it holds, even if the folder
    changed since ``lab_key`` was computed.
    """
    try:
        cache.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError:
        return None
    if not is_private_folder(cache):
        return None
    name = lab_dir.name
    root = cache / entry_key(name, lab_key, stubs_key)
    if not (root / "src" / name).is_dir():
        try:
            tmp = Path(tempfile.mkdtemp(prefix=".new-", dir=cache))
            copied = copy(lab_dir, tmp / "src" / name)
            (tmp / "numba").mkdir(mode=0o700)
        except OSError:
            return None
        lab_key = copied
        root = cache / entry_key(name, lab_key, stubs_key)
        try:
            os.rename(tmp, root)
        except OSError:  # another process made it first: the same bytes, use theirs
            remove_tree(tmp)
        with contextlib.suppress(OSError):
            _evict(cache)
    if not (root / "src" / name).is_dir() or not is_private_folder(root / "numba"):
        return None
    with contextlib.suppress(OSError):
        os.utime(root)  # its last use, for the eviction of old entries
    return Entry(root, name, lab_key, stubs_key)


def _stat_key(path: Path):
    try:
        st = os.stat(path, follow_symlinks=False)
    except OSError:
        return None
    return (st.st_ino, st.st_size, st.st_mtime_ns)


def _numba_files(folder: Path):
    """Relative paths of numba's index and data files under ``folder`` (nothing else: Mesa's shader
    cache shares the workers' folder)."""
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith((_INDEX, _DATA)):
                yield (Path(dirpath) / name).relative_to(folder)


def seed(entry: Entry, private: Path) -> dict:
    """Put the entry's compiled kernels into the workers' private cache folder ``private``.

    Returns the record :func:`publish` needs: ``relative path -> (stat of the entry's file, stat of
    the private file)`` as they were after seeding.
    """
    record = {}
    for rel in _numba_files(entry.numba):
        src, dst = entry.numba / rel, private / rel
        try:
            dst.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.link(src, dst)
            except OSError:  # another file system
                shutil.copy2(src, dst)
        except OSError:
            continue
        record[rel] = (_stat_key(src), _stat_key(dst))
    return record


def _replace_into(src: Path, dst: Path) -> None:
    dst.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=dst.name + ".", suffix=".tmp", dir=dst.parent)
    try:
        with os.fdopen(fd, "wb") as out, open(src, "rb") as f:
            shutil.copyfileobj(f, out)
        os.chmod(tmp, 0o444)
        os.replace(tmp, dst)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def publish(entry: Entry, private: Path, record: dict) -> int:
    """Copy what the workers compiled into ``private`` since :func:`seed` (or the last publish) into
    the entry; returns the number of kernel indexes published. ``record`` is updated."""
    changed = [
        rel
        for rel in _numba_files(private)
        if rel.suffix == _INDEX and _stat_key(private / rel) != record.get(rel, (None, None))[1]
    ]
    if not changed:
        return 0
    done = 0
    with _locked(entry.root / ".lock"):
        for rel in changed:
            if _stat_key(entry.numba / rel) != record.get(rel, (None, None))[0]:
                continue  # another process published this kernel since we seeded: keep theirs
            base = rel.name[: -len(_INDEX)] + "."
            data = [
                p.relative_to(private)
                for p in sorted((private / rel).parent.glob(base + "*" + _DATA))
                if _stat_key(p) != record.get(p.relative_to(private), (None, None))[1]
            ]
            try:
                for d in [*data, rel]:  # the data first: an index never names a file not there yet
                    _replace_into(private / d, entry.numba / d)
                    record[d] = (_stat_key(entry.numba / d), _stat_key(private / d))
            except OSError:
                continue
            done += 1
    return done


# ------------------------------------------------------------------ loading into a kernel zygote


class _NotCached(Exception):
    """Raised instead of compiling, or of starting numba's threads, while :func:`load_cached` loads."""


class _LoadOnly:
    """Stands in for a dispatcher's compiler while :func:`load_cached` loads: a signature whose data
    file went missing is left to the worker instead of compiled in the kernel zygote."""

    def compile(self, *args, **kwargs):
        raise _NotCached


def _names_used_by_python(modules) -> set[str]:
    """The global and attribute names that the plain Python functions (and methods) of ``modules`` use."""
    import types

    names: set[str] = set()
    todo = []
    for module in modules:
        for value in list(vars(module).values()):
            if getattr(value, "__module__", None) != module.__name__:
                continue
            if isinstance(value, type):
                todo += [f.__code__ for f in vars(value).values() if isinstance(f, types.FunctionType)]
            elif isinstance(value, types.FunctionType):
                todo.append(value.__code__)
    while todo:
        code = todo.pop()
        names.update(code.co_names)
        todo += [c for c in code.co_consts if isinstance(c, types.CodeType)]
    return names


def kernels_in(modules) -> list:
    """The numba kernels of ``modules`` that Python code calls (a kernel called only by kernels is
    compiled into them: loading it would be wasted) and that load from numba's disk cache
    (``cache=True``), but not the ``parallel=True`` ones: loading one starts numba's threads, which a
    process that forks must not have (a thread's locks stay taken in the child)."""
    if "numba" not in sys.modules:
        return []
    from numba.core.dispatcher import Dispatcher

    used = _names_used_by_python(modules)
    out, seen = [], set()
    for module in modules:
        for name, value in list(vars(module).items()):
            if (
                isinstance(value, Dispatcher)
                and name in used
                and id(value) not in seen
                and not value.targetoptions.get("parallel")
                and getattr(value._cache, "_cache_file", None) is not None
            ):
                seen.add(id(value))
                out.append(value)
    return out


@contextlib.contextmanager
def _no_threads():
    """numba starts its threading layer when it loads a kernel with parallel loops (``reload_init``),
    before loading it: refuse instead (a kernel that calls a parallel one has the same ``reload_init``)."""
    from numba.np.ufunc import parallel

    def refuse():
        raise _NotCached

    real, parallel._launch_threads = parallel._launch_threads, refuse
    try:
        yield
    finally:
        parallel._launch_threads = real


def load_cached(kernels: list, seen: dict) -> int:
    """Load into each of ``kernels`` every signature numba's cache holds for it, for this CPU and this
    bytecode; nothing is compiled and no thread is started. ``seen``: index file -> its stat when last
    read, updated (an index not changed since is not read again). Returns the number loaded."""
    n = 0
    with _no_threads():
        for disp in kernels:
            cache = disp._cache
            index = Path(cache._cache_file._index_path)
            stamp = _stat_key(index)
            if stamp is None or seen.get(index) == stamp:
                continue
            seen[index] = stamp
            try:
                keys = list(cache._cache_file._load_index())
            except Exception:  # noqa: BLE001 - an unreadable index: the worker reads it itself
                continue
            codegen = disp.targetctx.codegen()
            for key in keys:
                sig = key[0]
                if tuple(sig) in disp.overloads or cache._index_key(sig, codegen) != key:
                    continue  # loaded already, or compiled for another CPU or other bytecode
                compiler, disp._compiler = disp._compiler, _LoadOnly()
                try:
                    disp.compile(sig)
                    n += 1
                except Exception:  # noqa: BLE001 - _NotCached, or a broken entry: the worker's business
                    pass
                finally:
                    disp._compiler = compiler
    return n
