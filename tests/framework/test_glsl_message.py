"""A GLSL compile error leads with the student's shader file, its line and its task, not with the
given code's Python frame (``relief/glsl.py, line 52``)."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from geomlib.grading import impl as _impl
from geomlib.grading.cases import load_cases
from geomlib.grading.errors import GradingFailure
from geomlib.grading.sandbox import LabProxy


def test_a_shader_syntax_error_leads_with_the_file_line_and_task():
    base = Path(tempfile.mkdtemp(prefix="geomlib-glsl-"))
    os.chmod(base, 0o755)  # the sandbox may run student code as `nobody`
    dest = base / "relief"
    shutil.copytree(_impl.course_root() / "solutions" / "relief", dest, ignore=shutil.ignore_patterns("__pycache__"))
    frag = dest / "shaders" / "parallax.frag"
    lines = frag.read_text().splitlines()
    n = next(i for i, ln in enumerate(lines) if ln.strip().endswith(";") and "uv" in ln and i > 30)
    lines[n] = lines[n].rstrip()[:-1]  # a missing ';'
    frag.write_text("\n".join(lines) + "\n")
    for p in base.rglob("*"):
        os.chmod(p, 0o755 if p.is_dir() else 0o644)
    case = next(c for c in load_cases("relief") if c.id == "parallax-bumps-45")
    try:
        with pytest.raises(GradingFailure) as e:
            LabProxy("relief", dest).call("glsl_parallax_uv", **case.inputs(), **case.params)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    first = str(e.value).splitlines()[0]
    assert first.startswith("glsl_parallax_uv: shaders/parallax.frag (Task 2: parallax) did not compile, line "), first
    assert "glsl.py" not in first and "error" in first, first
