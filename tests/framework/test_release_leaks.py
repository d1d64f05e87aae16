"""The real course's student release: for every task, no shipped file contains its solution lines.

A solution line is a line inside a ``# BEGIN SOLUTION`` block that appears nowhere in the code that
ships anyway (the library and the stubs' given code): see ``geomlib.grading.release.secret_lines``.
"""

from __future__ import annotations

import shutil
import tempfile
import zipfile
from pathlib import Path

import pytest

from geomlib.grading import release as rel

from .course import user_cli

ROOT = Path(__file__).resolve().parents[2]
SECRETS = rel.secret_lines(ROOT) if (ROOT / "solutions").is_dir() else {}
LABS = sorted(p.name for p in (ROOT / "solutions").iterdir() if (p / "__init__.py").is_file())


@pytest.fixture(scope="module")
def bundle():
    out = Path(tempfile.mkdtemp(prefix="geomlib-course-leaks-"))
    user_cli(ROOT, "release", str(out), "--no-check")  # packaging only: the suite grades the solutions
    texts = {}
    for f in (out / "student").rglob("*"):
        if f.is_file() and f.suffix in (".py", ".md", ".ipynb", ".txt", ".toml", ".json"):
            texts[f.relative_to(out / "student").as_posix()] = {ln.strip() for ln in f.read_text().splitlines()}
    yield out, texts
    shutil.rmtree(out, ignore_errors=True)


def test_every_lab_has_tasks_with_secret_lines():
    labs = {task.split("/")[0] for task in SECRETS}
    assert labs == set(LABS), labs


@pytest.mark.parametrize("task", sorted(SECRETS))
def test_no_shipped_file_contains_the_solution_lines_of(bundle, task):
    _, texts = bundle
    found = [(f, ln) for f, lines in texts.items() for ln in SECRETS[task] & lines]
    assert not found, f"{task}: solution lines shipped to students: {found[:5]}"


def test_release_writes_one_autograder_per_lab_and_only_public_material(bundle):
    out, texts = bundle
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["student", "student.zip"] + [f"autograder-{lab}.zip" for lab in LABS]
    )
    assert not any("hidden" in f or f.startswith("solutions/") for f in texts)
    for lab in LABS:
        assert f"labs/{lab}/README.md" in texts and f"tests/graded/{lab}/cases.py" in texts
        with zipfile.ZipFile(out / f"autograder-{lab}.zip") as z:
            labs_in_zip = {n.split("/")[1] for n in z.namelist() if n.startswith("labs/")}
        assert labs_in_zip == {lab}


def test_a_lab_release_holds_that_lab_only(tmp_path):
    user_cli(ROOT, "release", str(tmp_path / "d"), "--lab", "maps", "--lab", "denoise", "--no-check")
    d = tmp_path / "d"
    assert sorted(p.name for p in d.iterdir()) == [
        "autograder-denoise.zip",
        "autograder-maps.zip",
        "student",
        "student.zip",
    ]
    assert sorted(p.name for p in (d / "student" / "labs").iterdir()) == ["denoise", "maps"]
    assert sorted(p.name for p in (d / "student" / "tests" / "graded").iterdir() if p.is_dir()) == [
        "denoise",
        "maps",
    ]
    assert sorted(p.name for p in (d / "student" / "notebooks").glob("*.ipynb")) == ["denoise.ipynb", "maps.ipynb"]


@pytest.mark.render
def test_the_student_bundle_draws_a_labs_figures_as_its_handout_says(bundle):
    """The relief handout says ``uv run geomlib figures --lab relief``: in a released student bundle
    (no solutions) that draws with the student's ``labs/relief/figures.py`` (stubs: the missing
    panels labelled), using the bundle's own geomlib. The bundle is the module's release of every
    lab (its texts were read before: the figures drawn into its build/ change no test above)."""
    out, _ = bundle
    student = out / "student"
    assert not (student / "solutions").exists()
    assert "geomlib figures --lab relief" in (student / "labs" / "relief" / "README.md").read_text()
    p = user_cli(student, "figures", "--lab", "relief", "--quick", "--out", "build/figures")
    drawn = sorted(f.name for f in (student / "build" / "figures" / "relief").glob("*.png"))
    assert len(drawn) >= 5, p.stdout
    assert (student / "build" / "figures" / "index.html").is_file()
