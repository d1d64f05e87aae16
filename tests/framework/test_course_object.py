"""The course as a unit (issue 25, item 1): one declared, ordered lab list and every path of a lab,
asked of :mod:`geomlib.grading.course`; a lab added the way docs/adding-a-lab.md says appears
everywhere with no other edit."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from geomlib.grading import figures, impl, readme
from geomlib.grading.course import course

from .course import SAMPLE, run_autograder, run_geomlib

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


#: The new lab's figures (docs/adding-a-lab.md, "figures"): one builder drawing with the lab's own
#: functions and the interactive view, made by ``lab_figure_makers``.
_FIGURES = """\"\"\"Figures of the {lab} lab, drawn with the lab's own functions.\"\"\"

import numpy as np

from geomlib.labfigures import Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import panels

__all__ = ["make_figures", "make_view"]

LAB = "{lab}"
TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def _dots(*point_sets):
    img = np.full((120, 160, 3), 255, np.uint8)
    for k, P in enumerate(point_sets):
        xy = np.clip((20 + 30 * np.asarray(P)[:, :2]).astype(int), 0, 119)
        img[xy[:, 1], xy[:, 0]] = (200 * k, 0, 200 - 200 * k)
    return img


@figure_name("scaled")
def fig_scaled(out, L, quick):
    V2 = L.scale_about_centroid(TET_V, TET_F, 2.0)
    E, M = L.edge_midpoints(TET_V, TET_F)
    img = panels([_dots(TET_V, V2), _dots(TET_V, M)], ["scaled twice", "edge midpoints"])
    return Drawn.claimed(img, "A tetrahedron scaled about its centroid; its {{n}} edge midpoints.", n=len(M))


@figure_name("{lab}_3d")
def fig_view(L, quick):
    V2 = L.scale_about_centroid(TET_V, TET_F, 2.0)
    return MeshView(V2, TET_F, caption="The tetrahedron scaled twice about its centroid.")


make_figures, make_view = lab_figure_makers(LAB, __name__, (fig_scaled,), fig_view, quick="nothing")
"""

#: The new lab's handout (written by hand): its task list and its grading table, as the tests declare.
_HANDOUT = """# Lab: {lab}

## Tasks

1. **Scaling** (`scale_about_centroid`): v' = c + s (v - c).
2. **Midpoints** (`edge_midpoints`): one point per unique edge.

## Grading

| part | points (public + hidden) |
|---|---|
| scaling | 3 + 1 |
| midpoints | 3 + 0 |
| bad input | 0 |
| **total** | 6 + 1 = 7 |

## Notes

Nothing else.
"""


def _notebook(lab: str) -> str:
    cells = [
        {"cell_type": "markdown", "id": "intro", "metadata": {}, "source": [f"# The {lab} lab"]},
        {
            "cell_type": "code",
            "execution_count": None,
            "id": "figures",
            "metadata": {},
            "outputs": [],
            "source": [f"from labs.{lab} import figures\n", "figures.make_figures('figures')"],
        },
    ]
    meta = {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}}
    return json.dumps({"cells": cells, "metadata": meta, "nbformat": 4, "nbformat_minor": 5}, indent=1) + "\n"


def _add_lab(root: Path, new: str) -> None:
    """Add lab ``new`` to the course at ``root`` by the steps of docs/adding-a-lab.md (the sample lab's
    solution and graded tests under a new name, plus what the sample lab lacks): declaration and
    README row, solution package with ``figures.py``, handout, graded tests, notebook."""
    shutil.copytree(root / "solutions" / "sample", root / "solutions" / new)
    (root / "solutions" / new / "figures.py").write_text(_FIGURES.format(lab=new))
    (root / "labs" / new).mkdir(parents=True)
    (root / "labs" / new / "README.md").write_text(_HANDOUT.format(lab=new))
    graded = root / "tests" / "graded" / new
    shutil.copytree(root / "tests" / "graded" / "sample", graded, ignore=shutil.ignore_patterns("__pycache__"))
    for f in list(graded.iterdir()):
        f.write_text(f.read_text().replace("sample", new))
        if "sample" in f.name:
            f.rename(graded / f.name.replace("sample", new))
    (root / "notebooks").mkdir(exist_ok=True)
    (root / "notebooks" / f"{new}.ipynb").write_text(_notebook(new))
    (root / "pyproject.toml").write_text(
        f'[tool.geomlib]\nlabs = ["{new}", "sample"]\n\n[tool.geomlib.readme]\n'
        f'{new} = {{ topic = "scaling and midpoints", tasks = "the scale, the midpoints" }}\n'
    )


def _course_tests(root: Path, selected: dict[str, tuple[str, int]]) -> None:
    """Run some of the real course's own test files (copied unchanged) on the course at ``root``, in
    one pytest (one start, 1.5 s of CPU, for them all): ``selected`` maps a file to the ``-k``
    expression that picks its tests in it and how many; each file's picked tests all pass."""
    for test_file in selected:
        target = root / test_file
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / test_file, target)
    env = {**os.environ, "GEOMLIB_ROOT": str(root), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    # A -k expression also matches the module's name: each file's expression is limited to its file.
    select = " or ".join(f"({Path(f).stem} and ({k}))" for f, (k, _) in selected.items())
    cmd = [sys.executable, "-m", "pytest", *selected, "-q", "-rA", "-p", "no:cacheprovider", "-k", select]
    p = subprocess.run(cmd, cwd=root, env=env, capture_output=True, text=True, timeout=600)
    log = p.stdout[-4000:] + p.stderr[-2000:]
    assert p.returncode == 0, log
    for test_file, (_, passed) in selected.items():
        assert len(re.findall(rf"^PASSED {re.escape(test_file)}::", p.stdout, re.M)) == passed, (test_file, log)


def test_a_lab_added_by_the_documented_steps_appears_everywhere():
    """figures, grade, refs, stubs, release (student bundle and the lab's autograder), points, the
    README table and the lab contracts: each finds the lab added by docs/adding-a-lab.md's steps."""
    base = Path(tempfile.mkdtemp(prefix="geomlib-addlab-"))
    try:
        base.chmod(0o755)
        root = base / "course"
        shutil.copytree(SAMPLE, root, ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(ROOT / "geomlib", root / "geomlib", ignore=shutil.ignore_patterns("__pycache__", "READY"))
        (root / "README.md").write_text(f"# Sample course\n\n{readme.BEGIN}\n{readme.END}\n")
        _add_lab(root, "extra")
        assert course(root).labs == ["extra", "sample"]  # declared order, not name order
        # refs and stubs
        run_geomlib(root, "refs", "build")
        run_geomlib(root, "stubs", "build")
        assert (root / "labs" / "extra" / "ops.py").is_file() and (root / "labs" / "extra" / "figures.py").is_file()
        assert list((root / "tests" / "reference" / "extra").glob("*.npz"))
        assert list((root / "tests" / "reference" / "extra" / "hidden").glob("*.npz"))
        # --no-grade: the grade below grades the solutions on every graded test (refs check would
        # do it a second time); the references are still re-run and compared.
        run_geomlib(root, "refs", "check", "--no-grade")
        # grade
        out = root / "results.json"
        run_geomlib(root, "grade", "--impl", "solutions", "--results", str(out))
        r = json.loads(out.read_text())
        labs = [t["name"].split(" › ")[0] for t in r["tests"]]
        assert labs[0] == "extra" and "sample" in labs, labs
        assert r["score"] == sum(t["max_score"] for t in r["tests"]) == 14
        # figures: the handout's figures (docs/figures/<lab>/), drawn by the solution
        run_geomlib(root, "figures", "--lab", "extra", "--out", str(root / "docs" / "figures"))
        drawn = {p.name for p in (root / "docs" / "figures" / "extra").iterdir()}
        assert {"scaled.png", "extra_3d.html"} <= drawn, drawn
        # points and the README table
        run_geomlib(root, "readme", "build")
        assert (
            "| [extra](labs/extra/README.md) | scaling and midpoints | the scale, the midpoints | 7 (6 + 1) |"
            in (root / "README.md").read_text()
        )
        # with the contracts (figures' signatures, __all__, the handout's tasks, the stubs' figures)
        _course_tests(
            root,
            {
                "tests/framework/test_points.py": ("test_handout_grading_table_matches_the_tests and extra", 1),
                "tests/test_lab_contracts.py": ("extra", 5),
            },
        )
        # release: the student bundle and the lab's own autograder
        dist = base / "dist"
        run_geomlib(root, "release", str(dist), "--no-check")
        student = {p.relative_to(dist / "student").as_posix() for p in (dist / "student").rglob("*") if p.is_file()}
        for f in ("labs/extra/ops.py", "labs/extra/README.md", "tests/graded/extra/test_extra.py",
                  "tests/reference/extra/tet-scale.npz", "notebooks/extra.ipynb", "docs/figures/extra/scaled.png"):  # fmt: skip
            assert f in student, f
        assert not any("hidden" in f or f.startswith("solutions/") for f in student)
        graded = run_autograder(dist, "extra", root / "solutions" / "extra")
        assert graded["score"] == 7 and any(t["visibility"] == "hidden" for t in graded["tests"])
    finally:
        shutil.rmtree(base, ignore_errors=True)
