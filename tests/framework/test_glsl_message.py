"""A GLSL compile error leads with the student's shader file, its line and its task, not with the
given code's Python frame (``relief/glsl.py, line 52``)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from geomlib.grading.cases import load_cases
from geomlib.grading.errors import GradingFailure
from geomlib.grading.sandbox import LabProxy

from .course import planted_solution


def test_a_shader_syntax_error_leads_with_the_file_line_and_task():
    def missing_semicolon(dest: Path) -> None:
        frag = dest / "shaders" / "parallax.frag"
        lines = frag.read_text().splitlines()
        n = next(i for i, ln in enumerate(lines) if ln.strip().endswith(";") and "uv" in ln and i > 30)
        lines[n] = lines[n].rstrip()[:-1]  # a missing ';'
        frag.write_text("\n".join(lines) + "\n")

    dest = planted_solution("relief", missing_semicolon)
    base = dest.parent
    case = next(c for c in load_cases("relief") if c.id == "parallax-bumps-45")
    try:
        with pytest.raises(GradingFailure) as e:
            LabProxy("relief", dest).call("glsl_parallax_uv", **case.inputs(), **case.params)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    first = str(e.value).splitlines()[0]
    assert first.startswith("glsl_parallax_uv: shaders/parallax.frag (Task 2: parallax) did not compile, line "), first
    assert "glsl.py" not in first and "error" in first, first
