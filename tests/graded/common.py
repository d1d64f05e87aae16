"""Assertion helpers shared by the labs' graded tests (shipped with every lab's tests)."""

from __future__ import annotations

from geomlib.grading import expect_raises


def expect_rejected(lab, function: str, *args, match: str | None = None, label: str | None = None, **kwargs) -> None:
    """``lab.<function>(*args, **kwargs)`` must raise a ``MeshError`` whose message matches ``match``.

    The failure message names ``label`` (default: ``function``); a stub's ``NotImplementedError``
    passes through (see :func:`geomlib.grading.expect_raises`).
    """
    expect_raises(lambda: getattr(lab, function)(*args, **kwargs), "MeshError", match=match, label=label or function)
