"""The points of every lab: hidden cases carry most of each part, and the handouts' tables say so."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from geomlib.grading.points import points_by_part

ROOT = Path(__file__).resolve().parents[2]
LABS = sorted(p.name for p in (ROOT / "solutions").iterdir() if (p / "__init__.py").is_file())


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


def test_readme_lab_table_gives_the_points_the_grader_computes(table):
    """README.md's lab table: every lab, with "total (public + hidden)" as the grader counts them."""
    text = (ROOT / "README.md").read_text()
    rows = dict(re.findall(r"^\| \[([a-z]+)\]\(labs/[a-z]+/README\.md\) \|.*\| ([^|]+) \|$", text, flags=re.M))
    assert sorted(rows) == sorted(LABS), f"README.md's lab table lists {sorted(rows)}"
    for lab in LABS:
        pub = sum(p for p, _ in table[lab].values())
        hid = sum(h for _, h in table[lab].values())
        expected = f"{pub + hid:g} ({pub:g} + {hid:g})"
        assert rows[lab].strip() == expected, f"README.md: the points of {lab} should say {expected}"
