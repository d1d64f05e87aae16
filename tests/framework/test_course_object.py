"""The course as a unit (issue 25, item 1): one declared, ordered lab list and every path of a lab,
asked of :mod:`geomlib.grading.course`; a lab added the way docs/adding-a-lab.md says appears
everywhere with no other edit."""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from pathlib import Path

from geomlib.grading import figures, impl
from geomlib.grading.course import course

from .course import SAMPLE, run_geomlib

ROOT = Path(__file__).resolve().parents[2]


def test_the_real_course_declares_every_lab_once_in_order():
    c = course(ROOT)
    with_solution = {p.parent.name for p in (ROOT / "solutions").glob("*/__init__.py")}
    assert set(c.declared) == with_solution == set(c.labs), "declare each lab in pyproject.toml [tool.geomlib] labs"
    assert impl.lab_names() == list(c.declared) == c.labs
    assert figures.lab_figure_modules() == [n for n in c.declared if (ROOT / "solutions" / n / "figures.py").is_file()]
    paths = c.lab("subdivision")
    assert paths.cases.is_file() and paths.references.is_dir() and paths.notebook.is_file() and paths.figures.is_file()


def test_no_module_keeps_its_own_list_of_lab_names():
    """The order lives in pyproject.toml only (impl.py and figures.py each had a hand-kept copy)."""
    two = re.compile(r"[\"']subdivision[\"'],\s*[\"']simplification[\"']")
    bad = [str(f.relative_to(ROOT)) for f in (ROOT / "geomlib").rglob("*.py") if two.search(f.read_text())]
    assert not bad, f"ask geomlib.grading.course for the labs, do not list them: {bad}"


def _add_lab(root: Path, new: str) -> None:
    """Add lab ``new`` to the course at ``root`` by the steps of docs/adding-a-lab.md (a copy of the
    sample lab under a new name): solution package, graded tests, the name in ``[tool.geomlib] labs``."""
    shutil.copytree(root / "solutions" / "sample", root / "solutions" / new)
    graded = root / "tests" / "graded" / new
    shutil.copytree(root / "tests" / "graded" / "sample", graded, ignore=shutil.ignore_patterns("__pycache__"))
    for f in list(graded.iterdir()):
        f.write_text(f.read_text().replace("sample", new))
        if "sample" in f.name:
            f.rename(graded / f.name.replace("sample", new))
    (root / "pyproject.toml").write_text(f'[tool.geomlib]\nlabs = ["{new}", "sample"]\n')


def test_a_lab_added_by_the_documented_steps_is_built_graded_and_checked():
    base = Path(tempfile.mkdtemp(prefix="geomlib-addlab-"))
    try:
        base.chmod(0o755)
        root = base / "course"
        shutil.copytree(SAMPLE, root, ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(ROOT / "geomlib", root / "geomlib", ignore=shutil.ignore_patterns("__pycache__", "READY"))
        _add_lab(root, "extra")
        assert course(root).labs == ["extra", "sample"]  # declared order, not name order
        run_geomlib(root, "refs", "build")
        run_geomlib(root, "stubs", "build")
        assert (root / "labs" / "extra" / "ops.py").is_file()
        assert list((root / "tests" / "reference" / "extra").glob("*.npz"))
        run_geomlib(root, "refs", "check")
        out = root / "results.json"
        run_geomlib(root, "grade", "--impl", "solutions", "--results", str(out))
        r = json.loads(out.read_text())
        labs = [t["name"].split(" › ")[0] for t in r["tests"]]
        assert labs[0] == "extra" and "sample" in labs, labs
        assert r["score"] == sum(t["max_score"] for t in r["tests"]) == 14
    finally:
        shutil.rmtree(base, ignore_errors=True)
