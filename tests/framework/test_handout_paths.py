"""Handouts name files of the course repository that the student bundle does not hold.

A student reads ``labs/<lab>/README.md`` in the bundle made by ``geomlib release``, which ships
geomlib, the stubs, the public graded tests and references, the notebooks and the handout figures,
but no benchmarks, no solutions and no other tests. A handout that points at such a file (the walk
of issue 26 found ``tests/solutions/test_subdivision.py`` cited as if at hand) says in the same
paragraph that it lives in the course repository.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# what `geomlib release` leaves out of the student bundle (geomlib/grading/release.py)
COURSE_ONLY = re.compile(r"`((?:bench|solutions|tests/solutions|tests/framework|tests/unit)/[^`\s]*)`")


def _missing_notes(text: str) -> list[str]:
    out = []
    for para in (" ".join(p.split()) for p in re.split(r"\n\s*\n", text)):
        for m in COURSE_ONLY.finditer(para):
            if "course repository" not in para:
                out.append(f"{m.group(1)}: {para[:160]}")
    return out


def test_a_handout_says_where_the_course_only_files_it_cites_are():
    problems = {
        md.parent.name: found
        for md in sorted((ROOT / "labs").glob("*/README.md"))
        if (found := _missing_notes(md.read_text(encoding="utf-8")))
    }
    assert not problems, problems


def test_the_rule_catches_a_course_only_path_without_the_note():
    assert _missing_notes("Checked in `tests/solutions/test_x.py` against libigl.")
    assert not _missing_notes("Checked in `tests/solutions/test_x.py` (in the course repository).")
    assert not _missing_notes("Graded by `tests/graded/x/test_x.py`.")  # shipped to students
