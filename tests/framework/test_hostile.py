"""Planted hostile submissions of the real subdivision lab, graded as users grade (issue 19, 13.4-13.6).

Each test grades one submission from :mod:`tests.framework.hostile` with ``geomlib grade`` (a
grading run of its own: combined in one submission, an attack on the grader's pipes or messages
would change what the others' tests see) on a throw-away copy of the course, so an attack that got
through could not damage this checkout. The copy is made once per module and shared: an attack that
changed it would fail its own test (``test_detached_children_forged_lines_and_tampering...`` checks
the copy's checks.py is untouched) and the ones graded after it.

A grade starts the grader and its zygote (about 2 s of CPU) and costs about 0.07 s per test: each
grades one part of the lab (``--part``), one that holds visible and hidden tests of the attacked
functions and, where a test needs some points to survive the attack, tests of functions left alone.
"""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

from geomlib.grading.results import plain_text, validate_results

from .course import sandbox_python, sandbox_user_problem
from .hostile import course_copy, grade_planted

pytestmark = [pytest.mark.slow, pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")]


COURSE = Path(__file__).resolve().parents[2]

#: Sparse (loop_odd_matrix, loop_even_matrix, whose interior rows call loop_weight), dense
#: (cc_edge_points, cc_vertex_points) and tuple (catmull_clark) outputs, three hidden cases, a test by
#: hand, and Catmull-Clark tests that a loop_weight or loop_odd_matrix attack leaves alone.
BOUNDARY = "boundary rules"
#: loop_odd_matrix's visible and hidden reference cases and two tests by hand; 5 tests.
ODD = "odd vertices"


@pytest.fixture(scope="module")
def course_root():
    """One world-readable throw-away copy of the course (10 MB) for every grade of this module."""
    base = Path(tempfile.mkdtemp(prefix="geomlib-hostile-course-"))
    base.chmod(0o755)
    try:
        yield course_copy(base / "course", COURSE)
    finally:
        # Left behind, copies of the course filled the disk and a later run failed everywhere.
        shutil.rmtree(base, ignore_errors=True)


def _grade(kind: str, root: Path, part: str | None, python: str | None = None, **env) -> dict:
    work = Path(tempfile.mkdtemp(prefix=f"geomlib-hostile-{kind}-"))
    work.chmod(0o755)
    try:
        r = grade_planted(
            kind, COURSE, work, python=python or sys.executable, env=env, timeout=600, root=root, part=part
        )
    finally:
        shutil.rmtree(work, ignore_errors=True)
    assert not r["hung"], r["log"]
    assert r["results"] is not None, r["log"]
    validate_results(r["results"])
    r["by_function"] = {}
    for t in r["results"]["tests"]:
        t["text"] = plain_text(t.get("output", ""))
    return r


def _tests(r: dict, words: str) -> list[dict]:
    return [t for t in r["results"]["tests"] if words in t["name"]]


def test_nan_outputs_earn_nothing(course_root):
    r = _grade("nan", course_root, BOUNDARY)
    refs = [t for t in r["results"]["tests"] if ' on "' in t["name"] and t["max_score"] > 0]
    assert refs and all(t["status"] == "failed" for t in refs)
    assert sum(t["score"] for t in r["results"]["tests"] if t["visibility"] == "hidden") == 0
    assert any("NaN or inf where the expected values are finite" in t["text"] for t in refs)
    assert r["score"] == 0


def test_looking_up_stored_outputs_earns_nothing(course_root):
    """The worker holds no case list and cannot open the cases or references (Landlock or the sandbox user)."""
    r = _grade("lookup", course_root, ODD)
    assert r["score"] == 0
    assert all("lookup found nothing" in t["text"] for t in r["results"]["tests"] if t["max_score"] > 0)


@pytest.mark.parametrize("landlock", ["1", "0"], ids=["with-landlock", "file-permissions-only"])
def test_as_the_sandbox_user_looking_up_stored_outputs_earns_nothing(course_root, landlock):
    """Gradescope's set-up: root drops to nobody; hidden cases and references are root-only."""
    found = sandbox_python("nobody")
    if found is None:
        pytest.skip(sandbox_user_problem("nobody"))
    python, extra = found
    env = {"GEOMLIB_SANDBOX_USER": "nobody", "GEOMLIB_LANDLOCK": landlock, **extra}
    r = _grade("lookup", course_root, ODD, python=python, **env)
    assert r["score"] == 0
    assert all("lookup found nothing" in t["text"] for t in r["results"]["tests"] if t["max_score"] > 0)


def test_a_lone_surrogate_in_a_message_costs_only_its_tests(course_root):
    r = _grade("surrogate", course_root, BOUNDARY)
    weight = _tests(r, "loop_weight([3, 4, 6]")
    assert r["score"] > 0
    assert any("bad \ufffd" in t["text"] for t in r["results"]["tests"])
    json.dumps(r["results"], ensure_ascii=False).encode("utf-8")  # no lone surrogate left: encodes cleanly
    assert weight == [] or all(t["status"] == "failed" for t in weight)


def test_a_half_written_message_header_cannot_hang_the_grader(course_root):
    r = _grade("partial_header", course_root, BOUNDARY, GEOMLIB_TIME_LIMIT="2")
    failed = [t for t in r["results"]["tests"] if "did not finish within 2 s" in t["text"]]
    assert failed and r["score"] > 0


def test_a_huge_exception_is_cut_in_the_grader(course_root):
    r = _grade("huge_message", course_root, BOUNDARY)
    assert r["results_bytes"] < 1_000_000
    assert r["score"] > 0


def test_a_forged_sparse_shape_is_refused_before_anything_is_allocated(course_root):
    r = _grade("sparse_bomb", course_root, BOUNDARY)
    odd = [t for t in r["results"]["tests"] if "loop_odd_matrix" in t["text"] and t["max_score"] > 0]
    assert odd and all(t["status"] == "failed" for t in odd)
    # Refused for its size, each one: without that refusal the checks densified the forged matrix
    # (13 GB and 40 s more for the former 3e8 rows) and this test still passed.
    assert all("far larger than this call's inputs allow" in t["text"] for t in odd), [t["text"] for t in odd]
    assert any("40000000" in t["text"] for t in odd)
    assert r["score"] > 0


def test_the_whole_run_stops_at_its_time_budget_and_still_writes_results(course_root):
    # Every call sleeps (no call of this run needs time of its own), so the limits are the smallest
    # that show the budget at work: 1 s calls in a 3 s budget, in a part of 10 tests.
    r = _grade("slow", course_root, BOUNDARY, GEOMLIB_TIME_LIMIT="1", GEOMLIB_TIME_BUDGET="3")
    texts = [t["text"] for t in r["results"]["tests"]]
    assert len(texts) == 10, len(texts)
    assert any("time budget of 3 s for the whole submission" in t for t in texts)
    # Within a 3 s budget at most 3 / 1 calls can each use up their 1 s (plus the one running when
    # the budget ran out); every later call fails at once. (Counted, not timed: a loaded machine is
    # slower but cannot fit more 1 s waits into 3 s; it may spend the budget before the first one.)
    waited = [t for t in texts if "did not finish within 1 s" in t]
    assert len(waited) <= 3 // 1 + 1, len(waited)
    assert r["seconds"] < 3 + 300  # a hang (the grader did not stop at its budget), not slowness


def test_detached_children_forged_lines_and_tampering_do_not_survive_the_call(course_root):
    r = _grade("leftovers", course_root, BOUNDARY)
    assert r["daemons"] == 0
    assert not r["tampered"]
    assert not r["forged"]
    assert not r["rewritten"]
    assert r["score"] == sum(t["max_score"] for t in r["results"]["tests"])


def test_rewriting_a_given_helper_gains_nothing(course_root):
    """catmull_clark is given: the course's version runs, calling the submission's (stub) tasks."""
    r = _grade("edit_given", course_root, "catmull-clark points")
    cc = [t for t in r["results"]["tests"] if "catmull_clark" in t["name"] and t["max_score"] > 0]
    assert cc and all(t["status"] == "failed" for t in cc)
    assert r["score"] == 0


def test_a_broken_import_in_one_file_costs_only_that_files_functions(course_root):
    # The whole lab: loop_faces and loop_weight (re-exported by the broken file) and cc_face_points
    # are tested in three different parts.
    r = _grade("blame_import", course_root, None)
    loop = [t for t in r["results"]["tests"] if "loop_faces" in t["name"] or "loop_weight" in t["name"]]
    assert loop and all(t["status"] == "passed" for t in loop)
    cc = [t for t in r["results"]["tests"] if "cc_face_points on" in t["name"]]
    assert cc and all("no_such_module" in t["text"] and "catmullclark.py" in t["text"] for t in cc)
