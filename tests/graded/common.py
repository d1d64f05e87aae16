"""Assertions and checks shared by the labs' graded tests and cases (shipped with every lab's tests)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.grading import expect_raises
from geomlib.grading.checks import Context, as_output_array, format_vec
from geomlib.grading.errors import Mismatch


def expect_rejected(lab, function: str, *args, match: str | None = None, label: str | None = None, **kwargs) -> None:
    """``lab.<function>(*args, **kwargs)`` must raise a ``MeshError`` whose message matches ``match``.

    The failure message names ``label`` (default: ``function``); a stub's ``NotImplementedError``
    passes through (see :func:`geomlib.grading.expect_raises`).
    """
    expect_raises(lambda: getattr(lab, function)(*args, **kwargs), "MeshError", match=match, label=label or function)


@dataclass
class SameRows:
    """A check: output ``output`` holds the same set of rows as expected, in any order (faces,
    corners, edges as vertex pairs: ``sort_within`` compares each row as an unordered set), with
    the shape ``(k, c)`` or ``(k,)`` of the reference; the message counts and shows a missing and
    an extra row, in the words ``missing`` and ``extra``."""

    output: str
    sort_within: bool = False
    missing: str = "expected entries missing"
    extra: str = "unexpected entries"

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output])
        g = as_output_array(got.get(self.output), self.output, ctx)
        if g.ndim != e.ndim or g.shape[1:] != e.shape[1:]:
            ctx.fail(f"{self.output} has shape {g.shape}, expected (k{''.join(f', {n}' for n in e.shape[1:])})")
        if e.ndim == 2 and self.sort_within:
            e, g = np.sort(e, axis=1), np.sort(g, axis=1)
        E = {tuple(np.atleast_1d(r).tolist()) for r in e}
        G = {tuple(np.atleast_1d(r).tolist()) for r in g}
        if E != G:
            missing, extra = sorted(E - G), sorted(G - E)
            examples = ((missing, self.missing), (extra, self.extra))
            what = [f"{len(rows)} {words} (e.g. {format_vec(np.array(rows[0]))})" for rows, words in examples if rows]
            ctx.fail(f"{self.output}: {len(G)} distinct rows, expected {len(E)}; " + "; ".join(what))


def expect_true(label: str, condition: bool, message: str) -> None:
    """Fail with ``"<label>: <message>"`` unless ``condition`` holds."""
    if not condition:
        raise Mismatch(f"{label}: {message}")
