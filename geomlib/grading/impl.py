"""Where things are: the course root, the implementation under test, the labs.

An *implementation* is a folder laid out like ``labs/``: one sub-folder per lab. It is named on the
command line as ``solutions`` (the reference), ``labs`` (the stubs, or a student's work in their
checkout) or a path to a submission (either the folder of lab folders itself, or a folder that
contains ``labs/``).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

from geomlib.grading.course import course, course_root

__all__ = ["course_root", "resolve_impl", "default_impl", "lab_names", "load_lab", "tests_dir", "reference_dir"]


def tests_dir() -> Path:
    return course().tests_dir


def reference_dir() -> Path:
    return course().reference_dir


def default_impl() -> str:
    """``solutions`` where the reference solutions are present (instructors, CI), else ``labs``."""
    return course().default_impl


def resolve_impl(impl: str | os.PathLike | None) -> Path:
    """The folder of lab folders for ``impl`` (``solutions``, ``labs`` or a path).

    Raises
    ------
    FileNotFoundError
        With the path tried, when the folder does not exist.
    """
    c = course()
    impl = c.default_impl if impl is None else impl
    p = c.impl_dir(str(impl))
    if p is None:
        p = Path(impl).expanduser().resolve()
        if (p / c.stubs_dir.name).is_dir():
            p = p / c.stubs_dir.name
    if not p.is_dir():
        raise FileNotFoundError(f"implementation folder not found: {p}")
    return p


def lab_names(impl: str | os.PathLike | None = "solutions") -> list[str]:
    """Labs that have graded tests, in course order (``[tool.geomlib] labs``; see :mod:`geomlib.grading.course`)."""
    return course().labs


def load_lab(lab: str, impl: str | os.PathLike | None = None) -> ModuleType:
    """Import a lab package *in this process* (trusted code only: solutions, figures, notebooks).

    The autograder never uses this for student code; it runs student code through
    :mod:`geomlib.grading.sandbox`.

    Examples
    --------
    >>> sub = load_lab("subdivision", "solutions")          # doctest: +SKIP
    >>> V2, F2 = sub.loop_subdivide(V, F)                    # doctest: +SKIP
    """
    folder = resolve_impl(impl) / lab
    if not (folder / "__init__.py").is_file():
        raise FileNotFoundError(f"no lab {lab!r} in {folder.parent} (expected {folder}/__init__.py)")
    c = course()
    root = c.root
    if folder.parent in (c.solutions_dir, c.stubs_dir):
        if str(root) not in sys.path:
            sys.path.insert(0, str(root))
        return importlib.import_module(f"{folder.parent.name}.{lab}")
    name = f"_impl_{abs(hash(str(folder))):x}_{lab}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(
        name, folder / "__init__.py", submodule_search_locations=[str(folder)]
    )
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod
