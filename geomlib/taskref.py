"""Reading "Task N" out of text: the one pattern for every place that parses a task reference.

A lab's solution marks each student part ``Task 2 (even vertices)``; a stub raises
``NotImplementedError("Task 2 (even vertices): ...")``; graded messages, shader sources and figure
captions repeat the reference. Everything that reads a task number or title back (the grader's task
table, the audit, the report, the shader watch, the "not implemented yet" figures) uses
:func:`find_task` / :func:`find_tasks` here (leaf module, library side: figures use it too).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["TASK", "TASK_RUN", "TaskRef", "find_task", "find_tasks", "task_at_start", "tasks_label"]

#: ``Task 3``, ``Task 3b``, ``Task 3 (title)``: groups number, part letter, title (or None).
TASK = re.compile(r"Task\s+(\d+)([a-z]?)(?![A-Za-z0-9])(?:\s*\(([^()\n]{0,80})\))?")

#: A run of task numbers as prose writes it: ``Task 3``, ``Tasks 2, 3 and 4``, ``Tasks 5-7``.
TASK_RUN = re.compile(r"Tasks?\s+\d+[a-z]?(?:(?:, | and |-)\d+[a-z]?)*")


@dataclass(frozen=True)
class TaskRef:
    """One task reference found in a text.

    Attributes
    ----------
    number : int
        The task number (``3`` for ``Task 3b``).
    part : str
        The part letter (``"b"``) or ``""``.
    title : str or None
        The title in parentheses right after the reference, or None.
    text : str
        The matched text, e.g. ``"Task 3b (title)"``.
    """

    number: int
    part: str
    title: str | None
    text: str

    @property
    def label(self) -> str:
        """Number and part letter, ``"3b"``."""
        return f"{self.number}{self.part}"


def _ref(m: re.Match) -> TaskRef:
    return TaskRef(int(m.group(1)), m.group(2), m.group(3), m.group(0))


def find_tasks(text: str) -> list[TaskRef]:
    """Every task reference in ``text``, in order."""
    return [_ref(m) for m in TASK.finditer(text)]


def task_at_start(text: str) -> TaskRef | None:
    """The task reference ``text`` starts with, or None."""
    m = TASK.match(text)
    return _ref(m) if m else None


def find_task(text: str, *, titled: bool = False) -> TaskRef | None:
    """The first task reference in ``text`` (with ``titled``: the first one that has a title), or None."""
    return next((r for r in find_tasks(text) if r.title is not None or not titled), None)


def tasks_label(numbers) -> str:
    """``Task 2``, ``Tasks 3, 5``, ``Tasks 1-8``: how a report names the tasks a test checks."""
    t = sorted(numbers)
    if len(t) == 1:
        return f"Task {t[0]}"
    if len(t) > 2 and t == list(range(t[0], t[-1] + 1)):
        return f"Tasks {t[0]}-{t[-1]}"
    return "Tasks " + ", ".join(map(str, t))
