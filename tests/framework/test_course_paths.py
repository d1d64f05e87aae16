"""Folder names of the course are spelled in one module (issue 25, item 1): the tooling asks
:mod:`geomlib.grading.course` for every folder (``course().lab(name).graded``, ``.solutions_dir``,
``.is_hidden(path)``), so a layout change is one edit and no module keeps its own idea of it."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GRADING = ROOT / "geomlib" / "grading"

#: Folder names of the course layout (tests/graded, tests/reference/<lab>/hidden/inputs, ...).
FOLDERS = {
    "tests",
    "graded",
    "reference",
    "solutions",
    "labs",
    "hidden",
    "inputs",
    "notebooks",
    "docs",
    "figures",
    "geomlib",
}
#: Calls whose string arguments are paths or path patterns.
PATH_CALLS = {"Path", "PurePath", "joinpath", "glob", "rglob", "_tree", "with_name", "relative_to"}


def _names_a_folder(node: ast.AST) -> bool:
    """A string constant that is a folder name, or a path/pattern with a folder-name segment."""
    if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
        return False
    return node.value in FOLDERS or ("/" in node.value and bool(FOLDERS & set(node.value.split("/"))))


def _strings(node: ast.AST) -> list[ast.AST]:
    """``node`` and, for a literal tuple/list/set, its elements."""
    return list(node.elts) if isinstance(node, (ast.Tuple, ast.List, ast.Set)) else [node]


def _branches(node: ast.AST) -> list[ast.AST]:
    """``node``, or both values of a conditional expression (``ref / ("hidden" if h else "")``)."""
    return [node.body, node.orelse] if isinstance(node, ast.IfExp) else [node]


def _is_path_part(node: ast.AST) -> bool:
    """``x.parts``, ``x.parts[i]``, ``x.name``, ``x.parent.name``, ``x.stem``, ``parts[i]``, ``part``:
    parts of a path."""
    if isinstance(node, ast.Subscript):
        node = node.value
    if isinstance(node, ast.Name):
        return node.id in ("parts", "part")
    return isinstance(node, ast.Attribute) and node.attr in ("parts", "name", "stem")


def folder_literals(source: str) -> list[tuple[int, str]]:
    """(line, literal) of every folder name used as a path in ``source``: an operand of ``/``, an
    argument of a path call, a value compared with a path's parts, or one of two or more folder
    names in a literal collection (``for impl in ("solutions", "labs")``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        hits: list[ast.AST] = []
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
            hits += [e for side in (node.left, node.right) for e in _branches(side)]
        elif isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""
            if name in PATH_CALLS:
                hits += node.args
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_is_path_part(s) for s in sides):
                hits += [e for s in sides for e in _strings(s)]
        elif isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            if sum(_names_a_folder(e) for e in node.elts) >= 2:
                hits += node.elts
        found += [(h.lineno, h.value) for h in hits if _names_a_folder(h)]
    return sorted(set(found))


def test_the_detector_finds_each_way_the_tooling_spelled_folders():
    """The rules catch every form the old modules used (release.py, impl.py, tasks.py, sandbox.py)."""
    old = """
base = root / "tests"
p = root / "solutions" / lab / "__init__.py"
if parts[1] not in ("graded", "reference"): pass
if rel.parts[1:2] == ("figures",) and parts[2] == "hidden": pass
for impl in ("solutions", "labs"): pass
out = _tree(root, "labs", keep)
hidden = list(tests.glob("*/hidden")) + list(g.glob("*/*_hidden*.py"))
folder = ref / lab / ("hidden" if hidden else "")
hidden = any("hidden" in part for part in rel.parts)
"""
    lines = {line for line, _ in folder_literals(old)}
    assert lines == set(range(2, 11)), lines
    fine = 'x = data["tests"]\nif visibility == "hidden": pass\nm = item.get_closest_marker("graded")\n'
    assert folder_literals(fine) == []


def test_only_the_course_module_spells_folder_names():
    bad = []
    for f in sorted(GRADING.rglob("*.py")):
        if f.name == "course.py" or "__pycache__" in f.parts:
            continue
        bad += [f"{f.relative_to(ROOT)}:{line}: {text!r}" for line, text in folder_literals(f.read_text())]
    assert not bad, "ask geomlib.grading.course for the folder instead of spelling it:\n" + "\n".join(bad)
