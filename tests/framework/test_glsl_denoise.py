"""The denoise lab's shader (task 7, shaders/denoise.vert) keeps the relief route's guarantees (issue 27):
a compile error names the file, the line and the task; NaN and reads outside the map fail its own
check with the stage named; a hang is named with its task; the stub is the solution with #error."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from geomlib.grading import shader_watch
from geomlib.grading.cases import load_cases
from geomlib.grading.errors import GradingFailure, Mismatch
from geomlib.grading.stubs import make_stub

from .course import failure_of, misspelt, shader_edit, shader_line

COURSE = Path(__file__).resolve().parents[2]
SHADER = "denoise.vert"


def test_a_compile_error_names_the_shader_its_line_and_task():
    needle = "return p - lam * s * n;"
    case = next(c for c in load_cases("denoise") if c.id == "map-uv-sphere-8bit")
    msg = failure_of(
        "denoise",
        misspelt(SHADER, needle, "lam"),
        lambda lab: lab.call("glsl_denoise_with_map", **case.inputs(), **case.params),
        GradingFailure,
    )
    first, line = msg.splitlines()[0], shader_line("denoise", SHADER, needle)
    m = re.match(
        r"glsl_denoise_with_map: shaders/denoise\.vert \(Task 7: vertex denoising\) \(vertex shader\) "
        r"did not compile, line (\d+)",
        first,
    )
    assert m and int(m.group(1)) == line and "lam_misspelt" in first, (first, line)


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
    msg = shader_watch.timeout_message("glsl_denoise_with_map", 60, f"shaders/{SHADER}", [COURSE / "labs" / "denoise"])
    assert "shaders/denoise.vert (Task 7 (vertex denoising))" in msg and "a loop that does not end" in msg, msg


def test_the_stub_is_the_solution_with_error_directives():
    solution = (COURSE / "solutions" / "denoise" / "shaders" / SHADER).read_text()
    stub = (COURSE / "labs" / "denoise" / "shaders" / SHADER).read_text()
    assert stub == make_stub(solution, f"shaders/{SHADER}")
    errors = [ln.strip() for ln in stub.splitlines() if ln.strip().startswith("#error")]
    assert len(errors) == 2 and all(e.startswith("#error Task 7 (vertex denoising)") for e in errors), errors
