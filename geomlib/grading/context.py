"""Where a comparison happens (:class:`Context`): a leaf module.

The checks (:mod:`geomlib.grading.checks`) word their messages with it and the feedback pictures
(:mod:`geomlib.grading.feedback`) are placed by it; both import it from here, so neither needs the
other to know what a context is. ``geomlib.grading.checks.Context`` is the same class.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.grading.errors import Mismatch

__all__ = ["Context", "picture_name", "picture_owner", "picture_stem", "set_running_test"]

#: Between the parts of a picture's file name (``<test>--<case>.png``); a part never contains it,
#: so the test that drew a picture is read back from the name alone (:func:`picture_owner`).
SEP = "--"
#: The graded test now running (its picture stem), set by ``geomlib.grading.feedback.begin_test``.
_RUNNING: dict[str, str] = {}


def _part(text: str) -> str:
    """``text`` as one part of a file name: letters, digits, ``_ . -``, no ``--``."""
    return re.sub(r"-{2,}", "-", re.sub(r"[^A-Za-z0-9_.\-]+", "_", str(text))).strip("_-.")


def picture_name(test: str | None, case_id: str = "", suffix: str = "") -> str:
    """The file name (without ``.png``) of a feedback picture drawn by the graded test ``test``.

    A test's pictures all start with its name: a reference test's own picture is ``<case>.png``
    (its name is its case's id), a hand-written test's ``<test>--<output>.png``, and a picture of
    another case drawn while diagnosing it ``<case>--<probe case>.png``. So two tests that draw
    the same case never share a file, and a ``--task`` run can tell its own tests' stale pictures
    (:func:`picture_owner`). Outside a graded test (``test`` None) the name is the case id.
    """
    if not test:
        return f"{case_id or 'case'}{suffix}"
    test, case, extra = _part(test), _part(case_id), _part(suffix)
    return SEP.join(p for p in (test, "" if case == test else case, extra) if p) or "case"


def picture_owner(filename: str) -> str:
    """The name of the test that drew the picture ``filename`` (see :func:`picture_name`)."""
    return Path(filename).name.removesuffix(".png").split(SEP, 1)[0]


def set_running_test(stem: str | None) -> None:
    """Name the pictures of the contexts made from now on after the graded test ``stem`` (None: no test runs)."""
    _RUNNING.clear()
    if stem:
        _RUNNING["test"] = stem


def picture_stem(node_name: str, case_id: str | None = None) -> str:
    """How the pictures of the graded test ``node_name`` start: its case's id for a reference test
    (``test_references[odd-ant]`` draws ``odd-ant.png``), else the test's name made file-safe."""
    return _part(case_id or node_name) or "test"


@dataclass
class Context:
    """Where a comparison happens: used to word messages and to place feedback pictures.

    Attributes
    ----------
    label : str
        How the call is named in messages, e.g. ``loop_subdivide on "icosphere-1"``.
    lab, case_id : str
    hint : str or None
        Appended to failure messages ("check the even-vertex weights").
    feedback_dir : Path or None
        Where feedback pictures go (``feedback/<lab>/``); None disables pictures.
    got_name, got_owner : str
        How messages name the output under test: ``"submitted"`` vertex of ``"the submission"``
        (``geomlib refs check``: ``"recomputed"``, ``"the solution"``).
    test : str
        The graded test running when the context was made (its picture stem; "" outside one): its
        pictures' names start with it (:func:`picture_name`).
    """

    label: str
    lab: str = ""
    case_id: str = ""
    hint: str | None = None
    feedback_dir: Path | None = None
    got_name: str = "submitted"
    got_owner: str = "the submission"
    test: str = field(default_factory=lambda: _RUNNING.get("test", ""), repr=False)

    def fail(self, what: str, feedback: str | None = None):
        msg = f"{self.label}: {what}"
        if self.hint:
            msg += f" — {self.hint}"
        raise Mismatch(msg, feedback)

    def feedback_path(self, suffix: str = "") -> Path | None:
        if self.feedback_dir is None:
            return None
        name = picture_name(self.test, self.case_id, suffix)
        p = Path(self.feedback_dir) / self.lab / f"{name}.png"
        p.parent.mkdir(parents=True, exist_ok=True)
        return p
