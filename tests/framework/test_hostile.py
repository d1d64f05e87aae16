"""Planted hostile submissions of the real subdivision lab, graded as users grade (issue 19, 13.4-13.6).

Each test grades one submission from :mod:`tests.framework.hostile` with ``geomlib grade`` on a
throw-away copy of the course, so an attack that got through could not damage this checkout.
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
from .hostile import grade_planted

pytestmark = [pytest.mark.slow, pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")]


def _grade(kind: str, tmp_path: Path, python: str | None = None, **env) -> dict:
    work = Path(tempfile.mkdtemp(prefix=f"geomlib-hostile-{kind}-"))
    work.chmod(0o755)
    course = Path(__file__).resolve().parents[2]
    try:
        r = grade_planted(kind, course, work, python=python or sys.executable, env=env, timeout=600)
    finally:
        # The course copy holds whatever the checkout holds beside the sources (up to 2.6 GB each
        # before): left behind, a few suite runs filled the disk and the next run failed everywhere.
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


def test_nan_outputs_earn_nothing(tmp_path):
    r = _grade("nan", tmp_path)
    refs = [t for t in r["results"]["tests"] if ' on "' in t["name"] and t["max_score"] > 0]
    assert refs and all(t["status"] == "failed" for t in refs)
    assert sum(t["score"] for t in r["results"]["tests"] if t["visibility"] == "hidden") == 0
    assert any("NaN or inf where the expected values are finite" in t["text"] for t in refs)
    assert r["score"] == 0


def test_looking_up_stored_outputs_earns_nothing(tmp_path):
    """The worker holds no case list and cannot open the cases or references (Landlock or the sandbox user)."""
    r = _grade("lookup", tmp_path)
    assert r["score"] == 0
    assert all("lookup found nothing" in t["text"] for t in r["results"]["tests"] if t["max_score"] > 0)


@pytest.mark.parametrize("landlock", ["1", "0"], ids=["with-landlock", "file-permissions-only"])
def test_as_the_sandbox_user_looking_up_stored_outputs_earns_nothing(tmp_path, landlock):
    """Gradescope's set-up: root drops to nobody; hidden cases and references are root-only."""
    found = sandbox_python("nobody")
    if found is None:
        pytest.skip(sandbox_user_problem("nobody"))
    python, extra = found
    env = {"GEOMLIB_SANDBOX_USER": "nobody", "GEOMLIB_LANDLOCK": landlock, **extra}
    r = _grade("lookup", tmp_path, python=python, **env)
    assert r["score"] == 0
    assert all("lookup found nothing" in t["text"] for t in r["results"]["tests"] if t["max_score"] > 0)


def test_a_lone_surrogate_in_a_message_costs_only_its_tests(tmp_path):
    r = _grade("surrogate", tmp_path)
    weight = _tests(r, "loop_weight([3, 4, 6]")
    assert r["score"] > 0
    assert any("bad \ufffd" in t["text"] for t in r["results"]["tests"])
    json.dumps(r["results"], ensure_ascii=False).encode("utf-8")  # no lone surrogate left: encodes cleanly
    assert weight == [] or all(t["status"] == "failed" for t in weight)


def test_a_half_written_message_header_cannot_hang_the_grader(tmp_path):
    r = _grade("partial_header", tmp_path, GEOMLIB_TIME_LIMIT="2")
    failed = [t for t in r["results"]["tests"] if "did not finish within 2 s" in t["text"]]
    assert failed and r["score"] > 0


def test_a_huge_exception_is_cut_in_the_grader(tmp_path):
    r = _grade("huge_message", tmp_path)
    assert r["results_bytes"] < 1_000_000
    assert r["score"] > 0


def test_a_forged_sparse_shape_is_refused_before_anything_is_allocated(tmp_path):
    r = _grade("sparse_bomb", tmp_path)
    odd = [t for t in r["results"]["tests"] if "loop_odd_matrix" in t["text"] and t["max_score"] > 0]
    assert odd and all(t["status"] == "failed" for t in odd)
    assert any("300000000" in t["text"] for t in odd)
    assert r["score"] > 0


def test_the_whole_run_stops_at_its_time_budget_and_still_writes_results(tmp_path):
    r = _grade("slow", tmp_path, GEOMLIB_TIME_LIMIT="2", GEOMLIB_TIME_BUDGET="12")
    texts = [t["text"] for t in r["results"]["tests"]]
    assert any("time budget of 12 s for the whole submission" in t for t in texts)
    # Within a 12 s budget at most 12 / 2 calls can each use up their 2 s (plus the one running when
    # the budget ran out); every later call fails at once. (Counted, not timed: a loaded machine is
    # slower but cannot fit more 2 s waits into 12 s; it may spend the budget before the first one.)
    waited = [t for t in texts if "did not finish within 2 s" in t]
    assert len(waited) <= 12 // 2 + 1, len(waited)
    assert r["seconds"] < 12 + 300  # a hang (the grader did not stop at its budget), not slowness


def test_detached_children_forged_lines_and_tampering_do_not_survive_the_call(tmp_path):
    r = _grade("leftovers", tmp_path)
    assert r["daemons"] == 0
    assert not r["tampered"]
    assert not r["forged"]
    assert not r["rewritten"]
    assert r["score"] == sum(t["max_score"] for t in r["results"]["tests"])


def test_rewriting_a_given_helper_gains_nothing(tmp_path):
    """catmull_clark is given: the course's version runs, calling the submission's (stub) tasks."""
    r = _grade("edit_given", tmp_path)
    cc = [t for t in r["results"]["tests"] if "catmull_clark" in t["name"] and t["max_score"] > 0]
    assert cc and all(t["status"] == "failed" for t in cc)
    assert r["score"] == 0


def test_a_broken_import_in_one_file_costs_only_that_files_functions(tmp_path):
    r = _grade("blame_import", tmp_path)
    loop = [t for t in r["results"]["tests"] if "loop_faces" in t["name"] or "loop_weight" in t["name"]]
    assert loop and all(t["status"] == "passed" for t in loop)
    cc = [t for t in r["results"]["tests"] if "cc_face_points on" in t["name"]]
    assert cc and all("no_such_module" in t["text"] and "catmullclark.py" in t["text"] for t in cc)
