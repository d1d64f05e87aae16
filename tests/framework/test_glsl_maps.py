"""The maps lab's shaders (tasks 7-9) keep the relief route's guarantees (issue 27): a shader that does
not compile, writes NaN or reads outside its textures fails with a message naming its file, line or
stage and task; a loop that does not end is named with its task; the untouched stubs compile once
their task is written and fail only their own tests."""

from __future__ import annotations

import re

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

CASE = {c.id: c for c in load_cases("maps")}
TASK = {"tbn.vert": 7, "normalmap.frag": 8, "displace.vert": 9}


def _shade_inputs():
    c = CASE["shade-quad-float-map"]
    return {**c.inputs(), **c.params}


def _displace_inputs():
    c = CASE["displace-sphere-bias-1-scale-2"]
    return {**c.inputs(), **c.params}


def _tbn_inputs():
    import numpy as np

    return {"N": np.array([[0.0, 0, 1], [0, 1, 0]]), "tangents": np.array([[1.0, 0, 0, 1], [1, 0, 0, -1]])}


@pytest.mark.parametrize(
    ("shader", "function", "inputs", "needle", "typo", "task"),
    [
        (
            "tbn.vert",
            "glsl_tbn",
            _tbn_inputs,
            "B = (t.w < 0.0 ? -1.0 : 1.0) * cross(N, T);",
            "cross",
            "Task 7: vertex TBN",
        ),
        ("normalmap.frag", "glsl_shade", _shade_inputs, "vec3 v = normalize(eye - P);", "eye", "Task 8: fragment "),
        ("displace.vert", "glsl_displace", _displace_inputs, "return P + lam * d * n;", "lam", "Task 9: vertex "),
    ],
)
def test_a_compile_error_names_the_shader_its_line_and_task(shader, function, inputs, needle, typo, task):
    head = rf"{function}: shaders/{re.escape(shader)} \({task}[^)]*\)( \(vertex shader\))?"
    assert_compile_error_names_its_line("maps", shader, needle, typo, lambda lab: lab.call(function, **inputs()), head)


def _fail_of(edit, check: str, case_id: str) -> str:
    """The Mismatch message of the graded check ``check`` (test_maps) on a planted copy."""
    from tests.graded.maps import test_maps

    return failure_of("maps", edit, lambda lab: getattr(test_maps, check)(lab, case_id), Mismatch)


def test_nan_from_the_vertex_stage_is_named():
    nan = shader_edit("displace.vert", "return P + lam * d * n;", "return P + lam * d * n * sqrt(d - 9.0);")
    msg = _fail_of(nan, "check_glsl_displace", "displace-grid-wave")
    assert "shaders/displace.vert, the vertex stage" in msg and "NaN" in msg, msg


def test_nan_from_the_fragment_stage_is_named():
    old = "return colour * (ambient + diffuse) + specular * spec;"
    nan = shader_edit("normalmap.frag", old, old[:-1] + " + sqrt(-1.0 - dot(P, P));")
    msg = _fail_of(nan, "check_glsl_shade", "shade-quad-plain")
    assert "shaders/normalmap.frag, the fragment stage" in msg and "NaN" in msg, msg


def test_reads_outside_the_texture_fail_the_shader_s_own_check():
    # no clamp: texelFetch outside the map (undefined, 0 on llvmpipe)
    outside = shader_edit("displace.vert", "        x = clamp(x, 0, size.x - 1);\n", "        x = x + size.x;\n")
    msg = _fail_of(outside, "check_glsl_displace", "displace-grid-wave")
    assert "shaders/displace.vert, the vertex stage" in msg and "differ by more than 1e-05" in msg, msg


def test_a_wrong_stage_is_named_by_its_shader():
    from tests.graded.maps import test_maps

    # the model matrix instead of its inverse transpose
    wrong_normal = shader_edit("tbn.vert", "N = normalize(transpose(inverse(m)) * n);", "N = normalize(m * n);")
    msg = failure_of("maps", wrong_normal, test_maps.test_glsl_tbn_by_hand, Mismatch)
    assert "shaders/tbn.vert, the vertex stage" in msg and ", N" in msg, msg


@pytest.mark.parametrize("shader", list(TASK))
def test_a_hanging_shader_is_named_with_its_task(shader):
    assert_hang_names_its_task("maps", shader, f"Task {TASK[shader]} (")


@pytest.mark.parametrize("shader", list(TASK))
def test_the_stubs_are_the_solutions_with_error_directives_and_compile_once_written(shader):
    """The stub differs from the solution only by ``#error`` lines where the solution blocks were; with
    the solution's lines put back it is the solution (which compiles: the graded tests run it)."""
    stub_error_lines("maps", shader, f"Task {TASK[shader]} (")
