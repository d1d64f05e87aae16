"""A lab's declared material, loaded: its case modules, stored references and stored inputs.

The one loader of ``tests/graded/<lab>/*.py`` (:func:`graded_module`): cases, hidden cases, the
diagnosis table and ``STORED`` entries are all imported through it. Below :mod:`~geomlib.grading.cases`
(which runs cases) and :mod:`~geomlib.grading.diagnose` (which probes building blocks), so data flows
one way: registry → diagnose → cases. ``geomlib.grading.cases`` re-exports the public names.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from geomlib.grading.course import course
from geomlib.grading.errors import Mismatch

if TYPE_CHECKING:
    from geomlib.grading.cases import Case

__all__ = [
    "graded_module",
    "hidden_cases",
    "load_cases",
    "reference_path",
    "load_reference",
    "stored_input",
    "stored_path",
    "load_stored",
    "graded_package_modules",
]


def graded_package_modules() -> list[str]:
    """Names in ``sys.modules`` of the imported graded-tests package (``graded``, the course's
    ``tests/graded`` folder) and its modules: what must be forgotten before another course's is imported."""
    package = course().graded_dir.name
    return [m for m in sys.modules if m == package or m.startswith(package + ".")]


def graded_module(lab: str, name: str, *, package: str | None = None):
    """The module ``tests/graded/<lab>/<name>.py`` of the course under grading, or None without that file.

    The course's ``tests`` folder goes first on ``sys.path`` (ahead of another course's tests folder
    imported in this process), and a ``graded`` package imported from another course (a fixture
    course in the same process) is forgotten first.

    ``package``: the lab's graded package as it is already imported (a graded test module's
    ``__package__``): the module is looked for in that package's folder and imported under its
    name, whichever course copy and package name pytest imported it from. Either way a missing
    file is None (a student's bundle has no ``cases_hidden.py``) and any error raised while
    importing an existing file is raised.
    """
    if package is not None:
        if package.rpartition(".")[2] != lab:
            raise ValueError(f"graded package {package!r} is not lab {lab!r}'s")
        folder = Path(next(iter(sys.modules[package].__path__)))
        return importlib.import_module(f"{package}.{name}") if (folder / f"{name}.py").is_file() else None
    c = course()
    folder = c.lab(lab).graded
    if not (folder / f"{name}.py").is_file():
        return None
    tests = str(c.tests_dir)
    if sys.path[:1] != [tests]:
        if tests in sys.path:
            sys.path.remove(tests)
        sys.path.insert(0, tests)
    loaded = sys.modules.get(c.graded_dir.name)
    if loaded is not None and str(folder.parent) not in [str(Path(p)) for p in getattr(loaded, "__path__", [])]:
        for mod in graded_package_modules():
            del sys.modules[mod]
    return importlib.import_module(f"{c.graded_dir.name}.{lab}.{name}")


def hidden_cases(lab: str, *, package: str | None = None) -> tuple[Case, ...]:
    """The hidden cases of ``lab`` (``cases_hidden.CASES``; ``package`` as for :func:`graded_module`),
    or none where the course copy has none: a student's bundle holds no hidden files, and a public
    test that looks its case up by id among public and hidden cases must still run there."""
    mod = graded_module(lab, "cases_hidden", package=package)
    return tuple(getattr(mod, "CASES", ())) if mod is not None else ()


def load_cases(lab: str, *, hidden: bool = True, probes: bool = True) -> list[Case]:
    """All cases a lab declares (``tests/graded/<lab>/cases.py`` and, if present and wanted,
    ``cases_hidden.py`` and the probe-only cases of ``diagnose.py``, which need references but are
    never graded)."""
    cases: list[Case] = []
    for mod_name, is_hidden in (("cases", False), ("cases_hidden", True), ("diagnose", False)):
        if (is_hidden and not hidden) or (mod_name == "diagnose" and not probes):
            continue
        mod = graded_module(lab, mod_name)
        if mod is not None:
            cases.extend(getattr(mod, "CASES", []))
    return cases


def reference_path(lab: str, case: Case) -> Path:
    paths = course().lab(lab)
    return (paths.hidden_references if case.hidden else paths.references) / f"{case.id}.npz"


def load_reference(lab: str, case: Case) -> dict:
    """The stored expected outputs of ``case`` (written by ``geomlib refs build``)."""
    path = reference_path(lab, case)
    if not path.is_file():
        raise Mismatch(
            f"reference output {path.relative_to(course().root)} is missing: run `geomlib refs build --lab {lab}`"
        )
    with np.load(path, allow_pickle=False) as z:
        return {name: z[name] for name in z.files}


# ------------------------------------------------------------------------------ stored inputs
def stored_path(lab: str, case: Case) -> Path:
    """Where ``geomlib refs build`` stores the outputs of a ``STORED`` entry."""
    paths = course().lab(lab)
    return (paths.hidden_stored_inputs if case.hidden else paths.stored_inputs) / f"{case.id}.npz"


def stored_input(lab: str, id: str) -> dict:
    """The stored outputs (``{name: array}``) of the ``STORED`` entry ``id`` of ``lab`` (public or hidden)."""
    paths = course().lab(lab)
    for folder in (paths.stored_inputs, paths.hidden_stored_inputs):
        path = folder / f"{id}.npz"
        if path.is_file():
            with np.load(path, allow_pickle=False) as z:
                return {name: z[name] for name in z.files}
    raise FileNotFoundError(
        f"stored input {lab}/inputs/{id}.npz is missing: run `geomlib refs build --lab {lab}` (instructors)"
    )


def load_stored(lab: str, *, hidden: bool = True) -> list[Case]:
    """The ``STORED`` entries of a lab's case modules (public first), in the order they are built."""
    out: list[Case] = []
    for mod_name, is_hidden in (("cases", False), ("cases_hidden", True)):
        mod = None if is_hidden and not hidden else graded_module(lab, mod_name)
        if mod is None:
            continue
        for c in getattr(mod, "STORED", []):
            if c.hidden != is_hidden:
                raise ValueError(f"{lab}: STORED entry {c.id} in {mod_name}.py has visibility {c.visibility!r}")
            out.append(c)
    return out
