"""Outcomes of a graded check that are expected failures, each with a message for the student.

They subclass ``AssertionError`` so pytest counts them as failures (not errors); the grading
plugin shows only their message, never a traceback of the grader.
"""

from __future__ import annotations

import re

#: Finds the reference :func:`see_picture` writes, its group the picture's path (with the space before it).
SEE_PICTURE = re.compile(r" ?\(see ([^()]+?\.png)\)")


def see_picture(path: str | None) -> str:
    """How a message points at its feedback picture: ``" (see PATH)"``, or ``""`` without one."""
    return f" (see {path})" if path else ""


class GradingFailure(AssertionError):
    """A graded test failed for a reason the message explains.

    Attributes
    ----------
    message : str
        One or two sentences: what was expected, what came, where.
    feedback : str or None
        Path of a feedback picture, relative to the working directory.
    """

    def __init__(self, message: str, feedback: str | None = None):
        super().__init__(message)
        self.message = message
        self.feedback = feedback

    def __str__(self) -> str:
        return self.message + see_picture(self.feedback)


class Mismatch(GradingFailure):
    """The student's output differs from the expected one."""


class NotImplementedYet(GradingFailure):
    """The student's function still raises ``NotImplementedError``."""


class StudentError(GradingFailure):
    """The student's code raised an exception.

    Attributes
    ----------
    exc_type : str
        Class name of the exception (``"MeshError"``).
    exc_mro : list of str
        Class names of the exception and its bases, to match ``ValueError`` for a ``MeshError``.
    exc_message : str
        ``str(exception)``.
    """

    def __init__(self, message: str, exc_type: str, exc_mro: list[str], exc_message: str):
        super().__init__(message)
        self.exc_type = exc_type
        self.exc_mro = exc_mro
        self.exc_message = exc_message


class StudentCrash(GradingFailure):
    """The worker process running student code died (segfault, ``os._exit``, killed)."""


class StudentTimeout(GradingFailure):
    """Student code exceeded the time limit."""


class BadReturn(GradingFailure):
    """Student code returned something of the wrong kind, shape or type."""


class BudgetSpent(GradingFailure):
    """The whole submission's time budget ran out before this test could call student code."""


class GraderError(GradingFailure):
    """The grader itself failed (the sandbox could not start, a set-up problem): never the student's fault.

    Its message starts with "grader problem (not your code)" and asks the student to tell the staff.
    """
