"""The points of every lab: hidden cases carry most of each part, and the handouts' tables say so."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from geomlib.grading.course import course
from geomlib.grading.points import points_by_part

ROOT = Path(__file__).resolve().parents[2]
LABS = course(ROOT).labs


@pytest.fixture(scope="module")
def table():
    return points_by_part(LABS)


@pytest.mark.parametrize("lab", LABS)
def test_hidden_cases_carry_most_of_every_part(table, lab):
    """A submission that only reproduces the public outputs cannot pass a part (issue 13, item 5)."""
    weak = {part: (pub, hid) for part, (pub, hid) in table[lab].items() if pub + hid > 0 and hid <= pub}
    assert not weak, f"{lab}: parts whose hidden cases carry at most half of the points (public, hidden): {weak}"


@pytest.mark.parametrize("lab", LABS)
def test_handout_grading_table_matches_the_tests(table, lab):
    text = (ROOT / "labs" / lab / "README.md").read_text()
    rows = dict(re.findall(r"^\| ([^|]+?) \| ([0-9.]+(?: \+ [0-9.]+)?(?: = [0-9.]+)?) \|", text, flags=re.M))
    for part, (pub, hid) in table[lab].items():
        expected = "0" if pub + hid == 0 else f"{pub:g} + {hid:g}"
        assert rows.get(part) == expected, f"labs/{lab}/README.md: row {part!r} should say {expected}"
    pub = sum(p for p, _ in table[lab].values())
    hid = sum(h for _, h in table[lab].values())
    assert rows.get("**total**") == f"{pub:g} + {hid:g} = {pub + hid:g}", f"labs/{lab}/README.md: total row"


def test_readme_lab_table_is_the_one_geomlib_readme_build_writes(table):
    """README.md's lab table (issue 26, item 8): every lab of the course in course order, with "total
    (public + hidden)" as the grader counts them, exactly as `geomlib readme build` writes it."""
    from geomlib.grading import readme

    problems = readme.check(diff=True)
    assert not problems, problems[0] + "\nrun `geomlib readme build`"
    text = (ROOT / "README.md").read_text()
    rows = re.findall(r"^\| \[([a-z]+)\]\(labs/[a-z]+/README\.md\) \|.*\| ([^|]+) \|$", text, flags=re.M)
    assert [lab for lab, _ in rows] == LABS
    for lab, points in rows:
        pub = sum(p for p, _ in table[lab].values())
        hid = sum(h for _, h in table[lab].values())
        assert points.strip() == f"{pub + hid:g} ({pub:g} + {hid:g})", f"README.md: the points of {lab}"


def test_a_stale_readme_table_is_reported_with_its_diff(tmp_path, monkeypatch):
    """A hand edit of the table (remeshing's points said 42 while the grader gave 51) is found and shown."""
    from geomlib.grading import readme

    text = (ROOT / "README.md").read_text()
    stale = re.sub(r"(\[remeshing\].*\| )[^|]+( \|)$", r"\g<1>42 (15 + 27)\2", text, count=1, flags=re.M)
    assert stale != text
    (tmp_path / "README.md").write_text(stale)
    monkeypatch.setattr(readme, "_readme", lambda: tmp_path / "README.md")
    [problem] = readme.check(diff=True)
    assert "-| [remeshing]" in problem and "42 (15 + 27)" in problem
    readme.build(log=lambda *_: None)
    assert (tmp_path / "README.md").read_text() == text
    (tmp_path / "README.md").write_text(text.replace(readme.BEGIN, ""))
    assert "needs the lines" in readme.check()[0]


def test_counting_the_points_leaves_the_process_as_it_found_it(monkeypatch):
    """`grade-all` counts the points (collecting loads the course's conftest.py) before it starts a
    grading process per submission with its own environment: the suite's limits (GEOMLIB_TIME_LIMIT=300)
    left behind gave a hanging submission 300 s per call instead of 30 (fresh-clone walk, issue 26)."""
    import os
    import sys

    for name in ("GEOMLIB_TIME_LIMIT", "GEOMLIB_PICTURE_TIME_LIMIT"):
        monkeypatch.delenv(name, raising=False)
    before, finders = dict(os.environ), list(sys.meta_path)
    points_by_part(["subdivision"])
    assert dict(os.environ) == before
    assert sys.meta_path == finders
