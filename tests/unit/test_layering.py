"""The layering: library modules never import the course tooling (``geomlib.grading``) or pytest,
the tooling a student needs to grade locally imports without pytest, and no package has an
import cycle."""

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


def _imports(path: Path, name: str, known: set[str]) -> set[str]:
    """The modules of ``known`` that module ``name`` (file ``path``) imports, anywhere: at the top,
    in ``try``/``if`` blocks and inside functions too (a function-level import that closes a cycle
    only hides it: the two modules still need each other), but not under ``if TYPE_CHECKING``."""
    import ast

    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()

    def visit(node):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for s in node.orelse:
                visit(s)
            return
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else []))
            for a in node.names:
                out.add(f"{base}.{a.name}" if f"{base}.{a.name}" in known else base)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8")))
    return {m for m in out if m in known and m != name}


def import_cycles(root: Path, top: str) -> list[list[str]]:
    """The import cycles among the modules of package ``top`` under ``root`` (strongly connected
    components of the import graph, function-level imports included, with more than one module)."""
    files = {}
    for p in sorted((root / top).rglob("*.py")):
        rel = p.relative_to(root).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        files[".".join(parts)] = p
    graph = {n: _imports(p, n, set(files)) for n, p in files.items()}
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def strong(v):  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            strong(v)
    return cycles


def test_no_import_cycles_in_the_library_the_tooling_or_the_labs():
    for top in ("geomlib", "solutions", "labs"):
        assert import_cycles(ROOT, top) == [], top


def test_a_planted_import_cycle_is_found(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from pkg import b\n")
    (pkg / "b.py").write_text("from .c import x\n")
    (pkg / "c.py").write_text("import pkg.a\nx = 1\n")
    (pkg / "d.py").write_text("def f():\n    from pkg import a  # a lazy import of a: no cycle by itself\n")
    (pkg / "e.py").write_text("def f():\n    from pkg import f  # lazy, but f imports e: a cycle all the same\n")
    (pkg / "f.py").write_text("from pkg import e\n")
    assert import_cycles(tmp_path, "pkg") == [["pkg.a", "pkg.b", "pkg.c"], ["pkg.e", "pkg.f"]]


#: A module may be longer than this when its docstring says why (issue: "no module over ~600 lines
#: without a reason stated in its docstring").
LONG_MODULE_LINES = 650


def long_modules_without_a_reason(root: Path, tops: tuple[str, ...]) -> list[str]:
    """Modules over :data:`LONG_MODULE_LINES` whose docstring does not give their length and a reason
    (a sentence with "lines" in it, e.g. "Longer than most modules (about 850 lines) on purpose: ...")."""
    import ast

    bad = []
    for top in tops:
        for p in sorted((root / top).rglob("*.py")):
            text = p.read_text(encoding="utf-8")
            n = text.count("\n")
            if n <= LONG_MODULE_LINES:
                continue
            doc = ast.get_docstring(ast.parse(text)) or ""
            if "lines" not in doc:
                bad.append(f"{p.relative_to(root)} ({n} lines)")
    return bad


def test_long_modules_say_why_in_their_docstring():
    assert long_modules_without_a_reason(ROOT, ("geomlib", "solutions", "bench")) == []


def test_a_long_module_without_a_reason_is_found(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "long.py").write_text('"""Short docstring."""\n' + "x = 1\n" * 700)
    (tmp_path / "pkg" / "said.py").write_text('"""Long (about 700 lines): one table."""\n' + "x = 1\n" * 700)
    assert long_modules_without_a_reason(tmp_path, ("pkg",)) == ["pkg/long.py (701 lines)"]
