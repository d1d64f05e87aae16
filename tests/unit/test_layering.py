"""The layering: library modules never import the course tooling (``geomlib.grading``) or pytest,
and the tooling a student needs to grade locally imports without pytest."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

import geomlib

ROOT = Path(__file__).resolve().parents[2]


def library_modules() -> list[str]:
    """Every module of the library: all of ``geomlib`` but the tooling package and the command line."""
    names = []
    for m in pkgutil.walk_packages(geomlib.__path__, "geomlib."):
        if m.name.startswith("geomlib.grading") or m.name == "geomlib.cli":
            continue
        names.append(m.name)
    return sorted(names)


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_the_library_modules_are_found():
    names = library_modules()
    for expected in ("geomlib.validate", "geomlib.halfedge", "geomlib.render.draw", "geomlib.mesh_io.obj"):
        assert expected in names
    assert not any(n.startswith("geomlib.grading") for n in names)


def test_importing_any_library_module_imports_neither_pytest_nor_the_tooling():
    code = (
        "import importlib, sys\n"
        f"for name in {library_modules()!r}:\n"
        "    importlib.import_module(name)\n"
        "bad = sorted(m for m in sys.modules if m == 'pytest' or m.startswith(('_pytest', 'geomlib.grading')))\n"
        "print(' '.join(bad))\n"
    )
    p = _run(code)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "", f"library modules pulled in: {p.stdout.strip()}"


def test_a_planted_import_of_the_tooling_is_caught(tmp_path):
    """The check above can fail: a module that imports the grader shows up in sys.modules."""
    (tmp_path / "planted_module.py").write_text("import geomlib.grading.impl\n")
    code = (
        "import sys\n"
        f"sys.path.insert(0, {str(tmp_path)!r})\n"
        "import planted_module\n"
        "print(any(m.startswith('geomlib.grading') for m in sys.modules))\n"
    )
    p = _run(code)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "True"


def test_the_grading_tooling_imports_without_pytest():
    """What a student's notebook and the grader's own modules need, with pytest made unimportable."""
    code = (
        "import sys\n"
        "sys.modules['pytest'] = None  # import pytest now raises ImportError\n"
        "import geomlib.grading as g\n"
        "from geomlib.grading import Case, checks, course_root, load_cases, Mismatch\n"
        "import geomlib.grading.sandbox, geomlib.grading.results, geomlib.grading.refs, geomlib.grading.stubs\n"
        "import geomlib.grading.release, geomlib.grading.figures\n"
        "print('ok', callable(g.check))\n"
    )
    p = _run(code)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "ok True"
