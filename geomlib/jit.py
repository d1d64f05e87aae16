"""Where numba keeps the compiled kernels of a lab, so that only the first process on a machine compiles.

``@njit(cache=True)`` writes the machine code of a kernel to disk the first time it is compiled
and loads it in every later process (tens of milliseconds instead of seconds). Two things make
numba's default place (the ``__pycache__`` folder next to the source file) not enough for a course:

- numba's cache refers to the module by its import name, and one file is imported under several
  names (``labs.sdf.kernels`` in a notebook, another name in the grader's workers); a cache
  written under one name fails to load under another. So each import name gets its own folder.
- The autograder runs student code as the user ``nobody``, who owns neither the lab folder nor a
  home directory; where no cache folder is writable numba refuses to decorate the function at all.
  Then the cache goes to a private folder of the current user under the system's temporary
  directory (``$TMPDIR/geomlib-numba-cache-<uid>``): the first worker compiles and writes there,
  later workers load from there.

The cache holds pickled data that numba loads, so that temporary folder must belong to the current
user and be writable by nobody else; a folder that someone else created under that name is not
used (a fresh private folder is made instead, at the cost of compiling again). ``NUMBA_CACHE_DIR``
set by the user always wins (the per-name folders are made inside it).

Use, at the top of a module of compiled kernels, before the first ``@njit(cache=True)``::

    from geomlib.jit import use_cache_folder
    use_cache_folder(__name__, __file__)

numba reads the folder when a function is decorated, so the call must come before the kernels
are defined; it does not change ``NUMBA_CACHE_DIR`` for child processes.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["cache_folder", "use_cache_folder", "is_private_folder"]


def _writable(folder: Path) -> bool:
    """Whether files can be created in ``folder`` (created if missing), as numba's own check does."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError:
        return False
    return True


def is_private_folder(folder: Path) -> bool:
    """A real folder (not a link) owned by the current user that no one else can write to."""
    try:
        info = folder.lstat()
    except OSError:
        return False
    return stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o022


def _private_temp_root(root: Path) -> Path:
    """``root/geomlib-numba-cache-<uid>`` if it is (or can be made) private, else a fresh private folder."""
    folder = root / f"geomlib-numba-cache-{os.getuid()}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        pass
    if not (is_private_folder(folder) and _writable(folder)):
        folder = Path(tempfile.mkdtemp(prefix="geomlib-numba-cache-", dir=root))
    return folder


def cache_folder(module_name: str, source_dir: str | os.PathLike, temp_root: str | os.PathLike | None = None) -> Path:
    """The folder numba should cache the kernels of module ``module_name`` in.

    In this order: ``$NUMBA_CACHE_DIR/<name>`` when the variable is set; else
    ``source_dir/__pycache__/<name>`` when it is writable; else ``<name>`` inside the current user's
    private folder under ``temp_root`` (see the module docstring). ``<name>`` is
    ``numba-`` followed by the import name with dots turned into underscores.

    Parameters
    ----------
    module_name : str
        The import name of the module of kernels (its ``__name__``).
    source_dir : path-like
        The folder of the kernels' source file.
    temp_root : path-like, optional
        Where to make the per-user folder; default ``tempfile.gettempdir()``.

    Returns
    -------
    Path
        An existing folder in which the current user can create files (not checked for the
        ``NUMBA_CACHE_DIR`` choice, which is the user's).
    """
    name = "numba-" + module_name.replace(".", "_")
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"]) / name
    beside = Path(source_dir) / "__pycache__" / name
    if _writable(beside):
        return beside
    folder = _private_temp_root(Path(temp_root or tempfile.gettempdir())) / name
    folder.mkdir(mode=0o700, exist_ok=True)
    return folder


def use_cache_folder(module_name: str, source_file: str | os.PathLike) -> Path:
    """Point numba's cache at :func:`cache_folder` for the module ``module_name`` defined in ``source_file``.

    Call it before the module's ``@njit(cache=True)`` functions are defined.

    Returns
    -------
    Path
        The folder chosen.
    """
    import numba  # here, so that importing geomlib.jit stays cheap

    folder = cache_folder(module_name, Path(source_file).resolve().parent)
    numba.config.CACHE_DIR = str(folder)
    return folder
