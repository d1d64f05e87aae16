"""The student report's shape (issue 26, items 2 and 5): a first grade of untouched stubs, "What to
fix" in task order with real failures first and short lines, the total out of the hidden cases."""

from __future__ import annotations

from geomlib.grading.grade import LINE, report_lines
from geomlib.grading.results import Record

TODO1 = "loop_odd_matrix: not implemented yet (Task 1 (odd vertices): append the triplets of the interior edges)"
TODO3 = "loop_faces: not implemented yet (Task 3 (connectivity): four faces per face)"
WRONG = (
    'loop_even_matrix on "even-icosphere-1-warren": S_even row (vertex) 0: expected weights '
    + "{0: 0.625, 1: 0.075, 2: 0.075, 3: 0.075, 4: 0.075, 5: 0.075} (column = old vertex), got "
    + "{0: 0.6, 1: 0.08, 2: 0.08, 3: 0.08, 4: 0.08, 5: 0.08}; 12 of 12 rows differ — the diagonal is 1 - k u"
)


def _r(name, part, points, passed, msg, *, todo=False, visibility="visible"):
    return Record(name, "subdivision", part, name, points, visibility, passed, msg, 0.0, not_implemented=todo)


def test_untouched_stubs_start_with_what_to_do_first():
    records = [
        _r("a", "odd vertices", 2, False, TODO1, todo=True),
        _r("b", "connectivity", 3, False, TODO3, todo=True),
        _r("c", "bad input", 0, True, ""),
    ]
    lines = report_lines(records, feedback_dir=None)
    assert lines[0] == "0 / 5 — nothing implemented yet; start with Task 1 (odd vertices): loop_odd_matrix", lines


def test_failures_of_started_tasks_come_first_in_task_order_in_short_lines():
    records = [
        _r("a", "connectivity", 3, False, TODO3, todo=True),
        _r("b", "even vertices", 2, False, WRONG),
        _r("c", "odd vertices", 2, False, TODO1, todo=True),
        _r("d", "odd vertices", 2, True, ""),
    ]
    lines = report_lines(records, feedback_dir=None, tasks={"b": (2,), "a": (3,), "c": (1,), "d": (1,)})
    assert not lines[0].startswith("0 /"), lines  # something passes: no "nothing implemented"
    body = lines[lines.index(next(ln for ln in lines if ln.startswith("What to fix"))) + 1 :]
    heads = [ln for ln in body if ln.startswith("  ✗")]
    assert heads[0].startswith("  ✗ Task 2 · even vertices: "), heads
    assert "Task 1 (odd vertices)" in heads[1] and "Task 3 (connectivity)" in heads[2], heads
    assert all(len(ln) <= LINE for ln in lines), [ln for ln in lines if len(ln) > LINE]
    details = body[body.index(heads[0]) + 1]
    assert details.startswith("      ") and "the diagonal is 1 - k u" in " ".join(body), body


def test_a_run_without_hidden_cases_says_what_the_lab_is_out_of():
    records = [_r("a", "odd vertices", 2, True, ""), _r("b", "odd vertices", 2, False, WRONG)]
    text = "\n".join(report_lines(records, feedback_dir=None))
    assert "subdivision is out of 151 (60 public + 91 hidden)" in text, text
    hidden = [*records, _r("h", "odd vertices", 3, True, "", visibility="hidden")]
    assert "out of 151" not in "\n".join(report_lines(hidden, feedback_dir=None))


def test_results_json_messages_name_no_file_the_student_cannot_open(tmp_path):
    """On Gradescope the picture is inlined: "(picture below)", not "(see ../results/feedback/x.png)"."""
    from PIL import Image

    from geomlib.grading.results import build_results

    pic = tmp_path / "results" / "feedback" / "subdivision" / "odd-ant.png"
    pic.parent.mkdir(parents=True)
    Image.new("RGB", (8, 8), "red").save(pic)
    probe = tmp_path / "results" / "feedback" / "subdivision" / "probe-odd.png"
    msg = f"loop_subdivide is off (see {probe}) — S_odd row 0 differs (see {pic})"
    with_pic = Record("a", "subdivision", "odd vertices", "a", 1, "visible", False, msg, 0.0, picture=str(pic))
    without = Record("b", "subdivision", "odd vertices", "b", 1, "visible", False, msg, 0.0)
    out = {t["name"].split(" › ")[-1]: t["output"] for t in build_results([with_pic, without], 1.0)["tests"]}
    assert "(picture below)" in out["a"] and "<img" in out["a"], out["a"]
    for text in out.values():
        assert "feedback/" not in text and "(see" not in text, text
