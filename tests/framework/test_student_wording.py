"""Student-facing text speaks to students: no "the issue's meshes" (issues are the developers' tracker)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_handouts_stubs_and_notebooks_do_not_refer_to_our_issues():
    files = [*ROOT.glob("labs/*/*.py"), *ROOT.glob("labs/*/README.md"), *ROOT.glob("notebooks/*.ipynb")]
    files.append(ROOT / "docs" / "students.md")
    assert len(files) > 20
    bad = []
    for f in files:
        for n, line in enumerate(f.read_text().splitlines(), 1):
            if re.search(r"\b(the|an|this) issue('s)?\b|\bissue \d+", line, re.I):
                bad.append(f"{f.relative_to(ROOT)}:{n}: {line.strip()[:120]}")
    assert not bad, "\n".join(bad)


def test_the_first_grade_students_md_quotes_has_the_courses_points():
    """docs/students.md quotes the first grade of the untouched stubs ("0 / 60 — nothing implemented
    yet; start with Task 1 ..."): its total is subdivision's public points as the Course counts them."""
    from geomlib.grading.points import points_by_part

    public = sum(p for p, _ in points_by_part(["subdivision"])["subdivision"].values())
    quoted = re.findall(
        r"(\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) — nothing implemented yet", (ROOT / "docs" / "students.md").read_text()
    )
    assert quoted and all(got == "0" and float(total) == public for got, total in quoted), (quoted, public)
