"""Gradescope's ``results.json``: building it from graded records, and its schema.

The fields follow Gradescope's autograder specification: top-level ``score``, ``execution_time``,
``output``, ``visibility``, ``stdout_visibility`` and ``tests``; each test has ``name``,
``number``, ``score``, ``max_score``, ``status`` (``passed``/``failed``), ``output`` and
``visibility`` (plus ``name_format``/``output_format``). Messages are Markdown (``output_format: md``);
the top-level ``output`` holds a per-part table of the *visible* tests only, so hidden and
after-due-date tests follow their own visibility. A failed test with a feedback picture is written
as HTML (``output_format: html``) with the picture inlined as a base64 data URI, because Gradescope
serves no files from the results folder (:func:`embedded_picture`).
"""

from __future__ import annotations

import html
import json
import re
from dataclasses import dataclass
from pathlib import Path

from geomlib.grading.errors import SEE_PICTURE
from geomlib.grading.sandbox import clean_text
from geomlib.taskref import task_at_start, tasks_label

__all__ = ["RESULTS_SCHEMA", "build_results", "write_results", "validate_results", "markdown_text", "plain_text"]

_VIS = ["visible", "hidden", "after_due_date", "after_published"]

RESULTS_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "Gradescope autograder results.json",
    "type": "object",
    "required": ["tests"],
    "properties": {
        "score": {"type": "number"},
        "execution_time": {"type": "number", "minimum": 0},
        "output": {"type": "string"},
        "output_format": {"enum": ["text", "html", "simple_format", "md", "ansi"]},
        "visibility": {"enum": _VIS},
        "stdout_visibility": {"enum": _VIS},
        "extra_data": {"type": "object"},
        "tests": {
            "type": "array",
            "items": {
                "type": "object",
                "required": ["name", "score", "max_score", "status"],
                "properties": {
                    "name": {"type": "string"},
                    "name_format": {"enum": ["text", "html", "simple_format", "md", "ansi"]},
                    "number": {"type": "string"},
                    "score": {"type": "number"},
                    "max_score": {"type": "number"},
                    "status": {"enum": ["passed", "failed"]},
                    "output": {"type": "string"},
                    "output_format": {"enum": ["text", "html", "simple_format", "md", "ansi"]},
                    "tags": {"type": "array", "items": {"type": "string"}},
                    "visibility": {"enum": _VIS},
                    "extra_data": {"type": "object"},
                },
                "additionalProperties": False,
            },
        },
    },
    "additionalProperties": False,
}


_MD_SPECIAL = str.maketrans({c: "\\" + c for c in "\\`*_[]<>#|~"})

#: Longest test output / top-level output kept in results.json (characters).
TEST_OUTPUT_CHARS = 6000
TOP_OUTPUT_CHARS = 20000


@dataclass
class Record:
    """The outcome of one graded test."""

    nodeid: str
    lab: str
    part: str
    name: str
    points: float
    visibility: str
    passed: bool
    message: str
    duration: float
    not_implemented: bool = False
    error: bool = False
    picture: str | None = None  # a feedback picture (path), when the failed check drew one

    @property
    def score(self) -> float:
        return self.points if self.passed else 0.0


def markdown_text(text: str, limit: int = TEST_OUTPUT_CHARS) -> str:
    """Text (from messages that may quote student code) as literal Markdown: sanitised, escaped, cut."""
    return clean_text(text, limit).translate(_MD_SPECIAL).replace("\n", "  \n")


def plain_text(markdown: str) -> str:
    """The text of a test output written by :func:`markdown_text` (escapes removed)."""
    return re.sub(r"\\(.)", r"\1", markdown.replace("  \n", "\n"))


def visible_summary(records: list[Record]) -> str:
    """A Markdown per-lab, per-part table of the tests a student may see now (visibility ``visible``).

    Tests that are hidden or shown only after the due date are left out of the counts (and their
    number is not given), so the table never reveals hidden results.
    """
    shown = [r for r in records if r.visibility == "visible"]
    if not shown:
        return "No graded results are shown before the due date."
    parts: dict[tuple[str, str], list[float]] = {}
    for r in shown:
        s = parts.setdefault((r.lab, r.part), [0.0, 0.0, 0, 0])
        s[0] += r.score
        s[1] += r.points
        s[2] += 1
        s[3] += r.passed
    lines = ["| lab | part | tests passed | score |", "|---|---|---:|---:|"]
    for (lab, part), (sc, mx, n, ok) in parts.items():
        lines.append(f"| {markdown_text(lab, 100)} | {markdown_text(part, 100)} | {ok}/{n} | {sc:g} / {mx:g} |")
    total = sum(v[0] for v in parts.values())
    maxtotal = sum(v[1] for v in parts.values())
    lines.append(f"| **total shown** | | | **{total:g} / {maxtotal:g}** |")
    if len(shown) < len(records):
        lines.append("")
        lines.append("Some tests are not shown yet; they count towards the final score.")
    return "\n".join(lines)


#: Largest feedback picture embedded in results.json (PNG bytes, after shrinking to PICTURE_WIDTH).
PICTURE_BYTES = 400_000
PICTURE_WIDTH = 900


def embedded_picture(path: str | Path) -> str | None:
    """A feedback picture as an ``<img>`` with a base64 data URI, or None if it is missing or too large.

    Gradescope shows a test's output as HTML when ``output_format`` is ``html`` and does not serve
    files from ``/autograder/results``: an image reaches the student only inlined in the output
    (Gradescope's autograder_samples discussion #108). Pictures are shrunk to PICTURE_WIDTH pixels
    and capped at PICTURE_BYTES so a results.json stays small.
    """
    import base64
    import io

    try:
        from PIL import Image

        with Image.open(path) as im:
            im = im.convert("RGB")
            if im.width > PICTURE_WIDTH:
                im = im.resize((PICTURE_WIDTH, max(1, round(im.height * PICTURE_WIDTH / im.width))), Image.LANCZOS)
            buf = io.BytesIO()
            # Not optimize=True: 2-3 times the CPU (40-65 ms a picture, at every grade) for 1 % fewer bytes.
            im.save(buf, format="PNG")
    except Exception:  # a picture is a help, never a requirement
        return None
    data = buf.getvalue()
    if len(data) > PICTURE_BYTES:
        return None
    return f'<img alt="feedback picture" style="max-width: 100%" src="data:image/png;base64,{base64.b64encode(data).decode()}">'


def _without_paths(message: str, embedded: str | None) -> str:
    """The message without "(see feedback/....png)": the student cannot open the grader's files.
    The embedded picture becomes "(picture below)"."""
    return SEE_PICTURE.sub(lambda m: " (picture below)" if embedded and m.group(1) == embedded else "", message)


#: A diagnosis saying which task's rows differ (geomlib.grading.diagnose): "... belong to Task 1 (odd vertices)".
_ROWS = re.compile(r"the rows that differ(?: at [^—]*?)? belong to ")


def failure_tasks(message: str, tasks, part: str) -> tuple[tuple, str]:
    """``(task numbers, part)`` a failed test's message is about: the test's own ``tasks`` and
    ``part``, unless the diagnosis says the differing rows belong to another task (then that task
    and its title). Used by the local report and by results.json alike."""
    rows = _ROWS.search(message)
    owner = task_at_start(message[rows.end() :]) if rows else None
    if owner and owner.title is not None:
        return (owner.number,), owner.title
    return tuple(tasks), part


def _test_output(r: Record, tasks=()) -> dict:
    """A test's ``output`` and ``output_format``: Markdown, or HTML with its feedback picture inlined.
    A failed test's message starts with the tasks it checks (``Task 4: ...``), as the local report's
    "What to fix" lines do: on Gradescope the test's name gives only the lab and the part. (Not on a
    stub's "not implemented yet", which names its task, a skip, or a grader problem.)"""
    img = embedded_picture(r.picture) if (r.picture and not r.passed) else None
    message = _without_paths(r.message, r.picture if img is not None else None)
    if tasks and not (r.passed or r.not_implemented or r.error or r.message.startswith("skipped")):
        message = f"{tasks_label(failure_tasks(' '.join(r.message.split()), tasks, r.part)[0])}: {message}"
    if img is None:
        return {"output": markdown_text(message), "output_format": "md"}
    text = html.escape(clean_text(message, TEST_OUTPUT_CHARS)).replace("\n", "<br>")
    return {"output": f"<p>{text}</p>\n{img}", "output_format": "html"}


def build_results(records: list[Record], execution_time: float, output: str = "", tasks=None) -> dict:
    """The ``results.json`` dict for graded records (test numbers are ``<lab>.<part>.<k>``).

    ``tasks``: ``{nodeid: task numbers}`` of the run's tests (the handout's tasks each checks).

    Everything that may come from student code is sanitised (lone surrogates, control characters),
    escaped for Markdown (``output_format: md``) and cut to a bounded length.
    """
    tests = []
    labs: dict[str, int] = {}
    parts: dict[tuple[str, str], int] = {}
    count: dict[tuple[str, str], int] = {}
    for r in records:
        li = labs.setdefault(r.lab, len(labs) + 1)
        pi = parts.setdefault((r.lab, r.part), sum(1 for k in parts if k[0] == r.lab) + 1)
        k = count[(r.lab, r.part)] = count.get((r.lab, r.part), 0) + 1
        tests.append(
            {
                "name": clean_text(f"{r.lab} › {r.part} › {r.name}", 300),
                "number": f"{li}.{pi}.{k}",
                "score": round(r.score, 6),
                "max_score": round(r.points, 6),
                "status": "passed" if r.passed else "failed",
                **_test_output(r, (tasks or {}).get(r.nodeid, ())),
                "visibility": r.visibility,
                "tags": [clean_text(r.lab, 100), clean_text(r.part, 100)],
            }
        )
    score = round(sum(r.score for r in records), 6)
    summary = visible_summary(records) if records else "No graded tests ran."
    note = markdown_text(output, 4000) + "\n\n" if output else ""
    return {
        "score": score,
        "execution_time": round(execution_time, 3),
        "output": clean_text(note + summary, TOP_OUTPUT_CHARS),
        "output_format": "md",
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "tests": tests,
    }


def validate_results(data: dict) -> None:
    """Raise ``jsonschema.ValidationError`` unless ``data`` follows :data:`RESULTS_SCHEMA`."""
    import jsonschema

    jsonschema.validate(data, RESULTS_SCHEMA)


def write_results(data: dict, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    # ensure_ascii: a lone surrogate that slipped through is written as an escape, never crashes.
    tmp.write_text(json.dumps(data, indent=1, ensure_ascii=True) + "\n")
    tmp.replace(path)
    return path
