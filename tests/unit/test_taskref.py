"""geomlib.taskref: the one pattern that reads "Task N" back out of text (issue 25, item 4)."""

import re
from pathlib import Path

from geomlib.taskref import find_task, find_tasks, task_at_start

ROOT = Path(__file__).resolve().parents[2]


def test_number_part_and_title():
    r = find_task("loop_odd_matrix: Task 2b (even vertices): not implemented")
    assert (r.number, r.part, r.label, r.title, r.text) == (2, "b", "2b", "even vertices", "Task 2b (even vertices)")
    assert find_task("see Task 12 first").label == "12" and find_task("see Task 12 first").title is None
    assert find_task("no task here") is None
    assert find_task("Task 2abc") is None  # not a task reference, a word


def test_titled_skips_untitled_references():
    text = "as in Task 3, then Task 1 (odd vertices): ..."
    assert find_task(text).number == 3
    assert find_task(text, titled=True).text == "Task 1 (odd vertices)"
    assert [r.number for r in find_tasks(text)] == [3, 1]
    assert task_at_start("Task 4 (x), not Task 5").number == 4 and task_at_start(" Task 4") is None


def test_no_other_module_spells_a_task_pattern():
    """Every "Task N" parser goes through geomlib.taskref: no regular expression elsewhere names "Task"."""
    pattern = re.compile(r"re\.(?:compile|search|match|fullmatch|findall|finditer|sub)\(\s*r?[\"'][^\"']*Task")
    files = [*ROOT.joinpath("geomlib").rglob("*.py"), *ROOT.joinpath("solutions").rglob("*.py")]
    bad = [
        f"{f.relative_to(ROOT)}:{i}"
        for f in files
        if f.name != "taskref.py"
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not bad, f"parse 'Task N' with geomlib.taskref.find_task, not a regular expression of its own: {bad}"
