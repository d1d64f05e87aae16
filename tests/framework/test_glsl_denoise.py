"""The denoise lab's shader (task 7, shaders/denoise.vert) keeps the relief route's guarantees (issue 27):
a compile error names the file, the line and the task; NaN and reads outside the map fail its own
check with the stage named; a hang is named with its task; the stub is the solution with #error."""

from __future__ import annotations

import pytest

from geomlib.grading.cases import load_cases
from geomlib.grading.errors import Mismatch

from .course import (
    assert_compile_error_names_its_line,
    assert_hang_names_its_task,
    failure_of,
    shader_edit,
    stub_error_lines,
)

SHADER = "denoise.vert"


def test_a_compile_error_names_the_shader_its_line_and_task():
    needle = "return p - lam * s * n;"
    case = next(c for c in load_cases("denoise") if c.id == "map-uv-sphere-8bit")
    run = lambda lab: lab.call("glsl_denoise_with_map", **case.inputs(), **case.params)  # noqa: E731
    head = r"glsl_denoise_with_map: shaders/denoise\.vert \(Task 7: vertex denoising\) \(vertex shader\)"
    assert_compile_error_names_its_line("denoise", SHADER, needle, "lam", run, head)


@pytest.mark.parametrize(
    ("old", "new", "needle"),
    [
        ("return p - lam * s * n;", "return p - lam * s * n * sqrt(-1.0 - s * s);", "NaN"),
        ("        x = clamp(x, 0, size.x - 1);\n", "        x = x + size.x;\n", "differ by more than 1e-05"),
    ],
    ids=["nan", "outside-the-map"],
)
def test_nan_and_reads_outside_the_map_fail_the_shader_s_own_check(old, new, needle):
    from tests.graded.denoise.test_denoise import check_glsl_denoise

    msg = failure_of(
        "denoise", shader_edit(SHADER, old, new), lambda lab: check_glsl_denoise(lab, "map-uv-sphere-8bit"), Mismatch
    )
    assert "shaders/denoise.vert, the vertex stage" in msg and needle in msg, msg


def test_a_hanging_shader_is_named_with_its_task():
    assert_hang_names_its_task("denoise", SHADER, "Task 7 (vertex denoising))")


def test_the_stub_is_the_solution_with_error_directives():
    assert len(stub_error_lines("denoise", SHADER, "Task 7 (vertex denoising)")) == 2
