"""The shadows lab's shaders (tasks 9-10: depth.vert, depth.frag, shadow.frag) keep the relief route's
guarantees (issue 27): a shader that does not compile names its file, line and task; NaN, reads outside
the map and a wrong stage fail the shader's own check with the pass and stage named; a broken shader
costs only its own task's tests; a hang is named with its task; the stubs are the solutions with
``#error`` directives."""

from __future__ import annotations

import re

import numpy as np
import pytest

from geomlib.grading.errors import GradingFailure, Mismatch
from tests.graded.shadows.support import ortho_light, small_scene

from .course import (
    assert_compile_error_names_its_line,
    assert_hang_names_its_task,
    failure_of,
    planted_lab,
    shader_edit,
    stub_error_lines,
)

TASK = {"depth.vert": 9, "depth.frag": 9, "shadow.frag": 10}


def _depth_inputs():
    V, F = small_scene()
    return {"V": V, "F": F, "M": ortho_light(), "size": 16, "cull": "front"}


def _shadow_inputs():
    P = np.array([[0.0, 0.0, 0.0], [1.0, -0.6, 1.0], [2.5, 2.5, 0.0]])
    N = np.tile([0.0, 0.0, 1.0], (3, 1))
    return {"P": P, "N": N, "D": np.ones((8, 8)), "M": ortho_light(), "pcf": 3}


@pytest.mark.parametrize(
    ("shader", "function", "inputs", "needle", "typo", "stage"),
    [
        ("depth.vert", "glsl_depth_map", _depth_inputs, "gl_Position = lightSpaceMatrix * vec4(position, 1.0);",
         "lightSpaceMatrix", " \\(vertex shader\\)"),
        ("depth.frag", "glsl_depth_map", _depth_inputs, "result = vec4(gl_FragCoord.z, 1.0, 0.0, 1.0);", "result", ""),
        ("shadow.frag", "glsl_shadow_visibility", _shadow_inputs, "vec4 c = lightSpaceMatrix * vec4(P, 1.0);",
         "lightSpaceMatrix", ""),
    ],
)  # fmt: skip
def test_a_compile_error_names_the_shader_its_line_and_task(shader, function, inputs, needle, typo, stage):
    head = rf"{function}: shaders/{re.escape(shader)} \(Task {TASK[shader]}: [^)]*\){stage}"
    run = lambda lab: lab.call(function, **inputs())  # noqa: E731
    assert_compile_error_names_its_line("shadows", shader, needle, typo, run, head, timeout=180)


def _fail_of(edit, check: str, *args) -> str:
    """The Mismatch message of the graded check ``check`` (test_shadows_glsl) on a planted copy."""
    from tests.graded.shadows import test_shadows_glsl

    return failure_of("shadows", edit, lambda lab: getattr(test_shadows_glsl, check)(lab, *args), Mismatch, timeout=180)


def test_nan_from_the_shadow_pass_is_named():
    old = "return lit / float(pcf * pcf);"
    msg = _fail_of(shader_edit("shadow.frag", old, old[:-1] + " + sqrt(-1.0 - dot(P, P));"), "check_glsl_shadow",
                   "glsl-eye-spot-pcf3")  # fmt: skip
    assert "shaders/shadow.frag, the shadow pass's fragment stage" in msg and "NaN" in msg, msg


def test_nan_from_the_depth_pass_is_named():
    old = "result = vec4(gl_FragCoord.z, 1.0, 0.0, 1.0);"
    new = "result = vec4(sqrt(-1.0 - gl_FragCoord.z), 1.0, 0.0, 1.0);"
    msg = _fail_of(shader_edit("depth.frag", old, new), "check_glsl_depth", "depth-ortho-64")
    assert "the depth pass from the light" in msg and "NaN" in msg and "depth.frag" in msg, msg


def test_reads_outside_the_map_fail_the_shader_s_own_check():
    # no clamp: texelFetch outside the map (undefined, 0 on llvmpipe)
    outside = shader_edit("shadow.frag", "    col = clamp(col, 0, size - 1);\n    row = clamp(row, 0, size - 1);\n", "")
    msg = _fail_of(outside, "check_glsl_shadow", "hidden-glsl-eye-partial-nofix")
    assert "shaders/shadow.frag, the shadow pass's fragment stage" in msg and "differ by more than 1e-06" in msg, msg


def test_a_wrong_vertex_stage_is_named():
    old = "gl_Position = lightSpaceMatrix * vec4(position, 1.0);"
    msg = _fail_of(shader_edit("depth.vert", old, "gl_Position = vec4(position, 1.0) * lightSpaceMatrix;"),
                   "check_glsl_depth", "depth-ortho-64")  # fmt: skip
    assert "the vertex stage (depth.vert" in msg and "covered in one map and empty" in msg, msg


def test_a_wrong_fragment_stage_is_named():
    old = "result = vec4(gl_FragCoord.z, 1.0, 0.0, 1.0);"
    msg = _fail_of(shader_edit("depth.frag", old, "result = vec4(2.0 * gl_FragCoord.z - 1.0, 1.0, 0.0, 1.0);"),
                   "check_glsl_depth", "depth-ortho-64")  # fmt: skip
    assert "the fragment stage (depth.frag) must write the window depth" in msg, msg


def test_missing_culling_is_caught():
    old = "if ((cull == 1 && gl_FrontFacing) || (cull == 2 && !gl_FrontFacing)) {"
    msg = _fail_of(shader_edit("depth.frag", old, "if (false) {"), "check_glsl_depth", "depth-front-culled")
    assert 'cull="front"' in msg and "depth.frag" in msg, msg


def test_a_broken_shadow_shader_costs_only_its_own_tests():
    """shadow.frag that does not compile: the light pass's check still passes on the same copy."""
    from tests.graded.shadows import test_shadows_glsl

    with planted_lab(
        "shadows", shader_edit("shadow.frag", "behind = c.w <= 0.0;", "behind = c.w <= 0.0"), timeout=180
    ) as lab:
        test_shadows_glsl.check_glsl_depth(lab, "depth-ortho-64")
        with pytest.raises(GradingFailure, match=r"shaders/shadow.frag \(Task 10"):
            test_shadows_glsl.check_glsl_shadow(lab, "glsl-eye-ortho-defaults")


@pytest.mark.parametrize("shader", ["depth.frag", "shadow.frag"])
def test_a_hanging_shader_is_named_with_its_task(shader):
    assert_hang_names_its_task("shadows", shader, f"Task {TASK[shader]} (")


@pytest.mark.parametrize("shader", ["depth.vert", "depth.frag", "shadow.frag"])
def test_the_stubs_are_the_solutions_with_error_directives(shader):
    stub_error_lines("shadows", shader, f"Task {TASK[shader]} (")
