"""The handouts and docs point at things that exist: files, links and ``geomlib.…`` names.

A renamed module or a moved figure otherwise leaves a handout that sends students to nothing.
Checked in every Markdown page a user reads (README.md, DEVELOPERS.md, docs/, each lab's handout):

- Markdown links and images ``[text](path)`` that are not web addresses: relative to the page;
- file names in backticks (``lookup.py``, ``tests/test_course.py``): a path with a folder is
  relative to the course root or the page; a bare name must be a file of the page's lab (its
  folder, its shaders, its graded tests) or, for pages outside a lab, some file of the course;
- dotted names in backticks (``geomlib.topology.unique_edges``): the module imports and has the name.
"""

from __future__ import annotations

import functools
import importlib
import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted(
    [ROOT / "README.md", ROOT / "DEVELOPERS.md", *ROOT.glob("docs/*.md"), *ROOT.glob("labs/*/README.md")],
)
PAGES = [p for p in PAGES if p.is_file()]

#: Names of files a command writes (results, Gradescope's export, what `geomlib release` makes).
OUTPUTS = {"results.json", "submission_metadata.yml", "student.zip", "setup.sh", "run_autograder"}

_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
_FILE = re.compile(r"`([A-Za-z0-9_./-]+\.(?:py|md|glsl|frag|vert|sh|toml|ipynb|png|npz|yml|lock))`")
_DOTTED = re.compile(r"`((?:geomlib|solutions)(?:\.[A-Za-z_][A-Za-z0-9_]*)+)(?:\(|`)")


@functools.cache
def _course_files() -> frozenset[str]:
    """The names of every file of the course (not of its environment or git)."""
    names = set()
    for _, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d not in ("__pycache__", "node_modules")]
        names.update(files)
    return frozenset(names)


def _lab_of(page: Path) -> str | None:
    rel = page.relative_to(ROOT).parts
    return rel[1] if rel[0] == "labs" else None


def _file_exists(name: str, page: Path, every_name: set[str]) -> bool:
    if name in OUTPUTS:
        return True
    lab = _lab_of(page)
    if "/" in name:
        return (ROOT / name).exists() or (page.parent / name).exists()
    if lab is not None:
        where = [ROOT / "labs" / lab, ROOT / "labs" / lab / "shaders", ROOT / "tests" / "graded" / lab, ROOT]
        return any((d / name).exists() for d in where)
    return name in every_name


def _name_exists(dotted: str) -> bool:
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ModuleNotFoundError:
            continue
        for attr in parts[k:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_file_link_and_name_a_page_cites_exists(page):
    text = page.read_text(encoding="utf-8")
    every_name = _course_files()
    missing = []
    for target in _LINK.findall(text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # a web address or an anchor on the page
        if not (page.parent / target.split("#")[0]).exists():
            missing.append(f"link {target}")
    missing += [f"file `{n}`" for n in _FILE.findall(text) if not _file_exists(n, page, every_name)]
    missing += [f"name `{n}`" for n in sorted(set(_DOTTED.findall(text))) if not _name_exists(n)]
    assert not missing, f"{page.relative_to(ROOT)} cites what does not exist: " + "; ".join(missing)


def test_a_missing_file_is_caught(tmp_path):
    page = ROOT / "labs" / "subdivision" / "README.md"
    assert not _file_exists("no_such_module.py", page, _course_files())
    assert _file_exists("catmullclark.py", page, _course_files())
    assert not _name_exists("geomlib.topology.no_such_function")
    assert _name_exists("geomlib.topology.unique_edges")
