"""Where numba keeps the compiled kernels, so that only the first process on a machine compiles (given code).

``@njit(cache=True)`` writes the machine code of a kernel to disk the first time it is compiled
and loads it in every later process (tens of milliseconds instead of seconds). numba's default
place is the ``__pycache__`` folder next to the source file, else ``~/.cache/numba``; when neither
is writable — the autograder runs student code as the user ``nobody``, who owns neither the lab
folder nor a home directory — numba refuses to decorate the function at all. This module, imported
before the kernels are defined, keeps the default when it works and otherwise points numba at a
private folder of the current user under the system's temporary directory
(``$TMPDIR/geomlib-numba-cache-<uid>``): the first worker compiles and writes there, later
workers load from there.

The cache holds pickled data that numba loads, so the folder must belong to the current user and
be writable by nobody else; a folder that someone else created under that name is not used (a
fresh private folder is made instead, at the cost of compiling again). ``NUMBA_CACHE_DIR`` set by
the user always wins.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["njit", "choose_cache_dir"]


def _writable(folder: Path) -> bool:
    """Whether files can be created in ``folder`` (created if missing), as numba's own check does."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError:
        return False
    return True


def _private(folder: Path) -> bool:
    """A real folder (not a link) owned by the current user that no one else can write to."""
    try:
        info = folder.lstat()
    except OSError:
        return False
    return stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o022


def choose_cache_dir(package_dir: Path, temp_root: Path | None = None) -> str | None:
    """The folder numba should cache in, or None when its default (``package_dir/__pycache__``) works.

    Parameters
    ----------
    package_dir : Path
        The folder of the kernels' source files.
    temp_root : Path, optional
        Where to make the per-user folder; default ``tempfile.gettempdir()``.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    if _writable(Path(package_dir) / "__pycache__"):
        return None
    root = Path(temp_root or tempfile.gettempdir())
    folder = root / f"geomlib-numba-cache-{os.getuid()}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        pass
    if not (_private(folder) and _writable(folder)):
        folder = Path(tempfile.mkdtemp(prefix="geomlib-numba-cache-", dir=root))
    return str(folder)


_cache_dir = choose_cache_dir(Path(__file__).resolve().parent)
if _cache_dir is not None:
    os.environ["NUMBA_CACHE_DIR"] = _cache_dir  # read by numba when it is imported (below) ...

import numba  # noqa: E402

if _cache_dir is not None:
    numba.core.config.CACHE_DIR = _cache_dir  # ... and here in case it was imported already

njit = numba.njit
