"""Where a comparison happens (:class:`Context`): a leaf module.

The checks (:mod:`geomlib.grading.checks`) word their messages with it and the feedback pictures
(:mod:`geomlib.grading.feedback`) are placed by it; both import it from here, so neither needs the
other to know what a context is. ``geomlib.grading.checks.Context`` is the same class.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from geomlib.grading.errors import Mismatch

__all__ = ["Context"]


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
    """

    label: str
    lab: str = ""
    case_id: str = ""
    hint: str | None = None
    feedback_dir: Path | None = None
    got_name: str = "submitted"
    got_owner: str = "the submission"

    def fail(self, what: str, feedback: str | None = None):
        msg = f"{self.label}: {what}"
        if self.hint:
            msg += f" — {self.hint}"
        raise Mismatch(msg, feedback)

    def feedback_path(self, suffix: str = "") -> Path | None:
        if self.feedback_dir is None:
            return None
        p = Path(self.feedback_dir) / self.lab / f"{self.case_id or 'case'}{suffix}.png"
        p.parent.mkdir(parents=True, exist_ok=True)
        return p
