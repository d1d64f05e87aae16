"""Gradescope's ``results.json``: building it from graded records, and its schema.

The fields follow Gradescope's autograder specification: top-level ``score``, ``execution_time``,
``output``, ``visibility``, ``stdout_visibility`` and ``tests``; each test has ``name``,
``number``, ``score``, ``max_score``, ``status`` (``passed``/``failed``), ``output`` and
``visibility`` (plus ``name_format``/``output_format``).
"""

from __future__ import annotations

import json
from pathlib import Path

from geomlib.grading.plugin import Record, score_table

__all__ = ["RESULTS_SCHEMA", "build_results", "write_results", "validate_results"]

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


def build_results(records: list[Record], execution_time: float, output: str = "") -> dict:
    """The ``results.json`` dict for graded records (test numbers are ``<lab>.<part>.<k>``)."""
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
                "name": f"{r.lab} › {r.part} › {r.name}",
                "number": f"{li}.{pi}.{k}",
                "score": round(r.score, 6),
                "max_score": round(r.points, 6),
                "status": "passed" if r.passed else "failed",
                "output": r.message,
                "visibility": r.visibility,
                "tags": [r.lab, r.part],
            }
        )
    score = round(sum(r.score for r in records), 6)
    summary = score_table(records) if records else "no graded tests ran"
    return {
        "score": score,
        "execution_time": round(execution_time, 3),
        "output": (output + "\n\n" if output else "") + summary,
        "output_format": "text",
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
    tmp.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n")
    tmp.replace(path)
    return path
