"""The point light's cube shaders (tasks 11-12: cube_depth.vert, cube_depth.frag, cube_shadow.frag) keep the
relief route's guarantees (issue 27): a shader that does not compile names its file, line and task; NaN and a
wrong stage fail the shader's own check with the pass and stage named; a broken shader costs only its own
task's tests; a hang is named with its task; the stubs are the solutions with ``#error`` directives."""

from __future__ import annotations

import re

import numpy as np
import pytest

from geomlib.grading.errors import GradingFailure, Mismatch
from tests.graded.shadows.support import small_scene

from .course import (
    assert_compile_error_names_its_line,
    assert_hang_names_its_task,
    failure_of,
    planted_lab,
    shader_edit,
    stub_error_lines,
)

TASK = {"cube_depth.vert": 11, "cube_depth.frag": 11, "cube_shadow.frag": 12}
LIGHT = {"position": np.array([0.2, -0.3, 2.6]), "near": 0.2, "far": 12.0}


def _depth_inputs():
    V, F = small_scene()
    return {"V": V, "F": F, **LIGHT, "size": 8, "cull": "front"}


def _shadow_inputs():
    P = np.array([[0.0, 0.0, 0.0], [1.0, -0.6, 1.0], [2.5, 2.5, 0.0]])
    return {"P": P, "N": np.tile([0.0, 0.0, 1.0], (3, 1)), "maps": np.ones((6, 8, 8)), **LIGHT, "pcf": 3}


@pytest.mark.parametrize(
    ("shader", "function", "inputs", "needle", "typo", "stage"),
    [
        ("cube_depth.vert", "glsl_cube_depth_maps", _depth_inputs, "gl_Position = lightSpaceMatrix * vec4(position, 1.0);",
         "lightSpaceMatrix", " \\(vertex shader\\)"),
        ("cube_depth.frag", "glsl_cube_depth_maps", _depth_inputs,
         "result = vec4(length(world - lightPos) / far, 1.0, 0.0, 1.0);", "lightPos", ""),
        ("cube_shadow.frag", "glsl_point_shadow_visibility", _shadow_inputs, "float depth = length(d) / far - bias;",
         "bias", ""),
    ],
)  # fmt: skip
def test_a_compile_error_names_the_shader_its_line_and_task(shader, function, inputs, needle, typo, stage):
    head = rf"{function}: shaders/{re.escape(shader)} \(Task {TASK[shader]}: [^)]*\){stage}"
    run = lambda lab: lab.call(function, **inputs())  # noqa: E731
    assert_compile_error_names_its_line("shadows", shader, needle, typo, run, head, timeout=180)


def _fail_of(edit, check: str, *args) -> str:
    """The Mismatch message of the graded check ``check`` (test_shadows_cube_glsl) on a planted copy."""
    from tests.graded.shadows import test_shadows_cube_glsl

    return failure_of(
        "shadows", edit, lambda lab: getattr(test_shadows_cube_glsl, check)(lab, *args), Mismatch, timeout=180
    )


def test_nan_from_the_cube_lookup_is_named():
    old = "return lit / float(pcf * pcf);"
    nan = shader_edit("cube_shadow.frag", old, old[:-1] + " + sqrt(-1.0 - dot(P, P));")
    msg = _fail_of(nan, "check_glsl_cube_shadow", "glsl-cube-eye-pcf3")
    assert "shaders/cube_shadow.frag, the cube lookup's fragment stage" in msg and "NaN" in msg, msg


def test_nan_from_the_cube_pass_is_named():
    old = "result = vec4(length(world - lightPos) / far, 1.0, 0.0, 1.0);"
    new = "result = vec4(sqrt(-1.0 - length(world)), 1.0, 0.0, 1.0);"
    msg = _fail_of(shader_edit("cube_depth.frag", old, new), "check_glsl_cube_depth", "glsl-cube-linear-a-64-front")
    assert "the cube pass from the light" in msg and "NaN" in msg and "cube_depth.frag" in msg, msg


def test_a_wrong_vertex_stage_is_named():
    old = "gl_Position = lightSpaceMatrix * vec4(position, 1.0);"
    msg = _fail_of(shader_edit("cube_depth.vert", old, "gl_Position = vec4(position, 1.0) * lightSpaceMatrix;"),
                   "check_glsl_cube_depth", "glsl-cube-linear-a-64-front")  # fmt: skip
    assert "the vertex stage (cube_depth.vert" in msg and "covered in one map and empty" in msg, msg


@pytest.mark.parametrize(
    "wrong",
    ["gl_FragCoord.z", "length(world - lightPos)", "length(world) / far"],
    ids=["window-depth", "not-over-far", "distance-to-origin"],
)
def test_a_wrong_fragment_stage_is_named(wrong):
    """Window depth instead of linear depth, the distance not divided by far, the distance to the origin."""
    old = "result = vec4(length(world - lightPos) / far, 1.0, 0.0, 1.0);"
    msg = _fail_of(shader_edit("cube_depth.frag", old, f"result = vec4({wrong}, 1.0, 0.0, 1.0);"),
                   "check_glsl_cube_depth", "glsl-cube-linear-a-64-front")  # fmt: skip
    assert "the fragment stage (cube_depth.frag) must write the linear depth" in msg, msg


def test_a_wrong_world_position_from_the_vertex_stage_is_caught():
    msg = _fail_of(shader_edit("cube_depth.vert", "world = position;", "world = gl_Position.xyz;"),
                   "check_glsl_cube_depth", "glsl-cube-linear-a-64-front")  # fmt: skip
    assert "cube_depth.frag) must write the linear depth" in msg and "`world`" in msg, msg


def test_missing_culling_is_caught():
    old = "if ((cull == 1 && gl_FrontFacing) || (cull == 2 && !gl_FrontFacing)) {"
    msg = _fail_of(
        shader_edit("cube_depth.frag", old, "if (false) {"), "check_glsl_cube_depth", "glsl-cube-linear-a-64-front"
    )
    assert 'cull="front"' in msg and "cube_depth.frag" in msg, msg


@pytest.mark.parametrize(
    ("old", "new", "case"),
    [
        ("sctc = vec2(-d.x, -d.y);", "sctc = vec2(d.x, -d.y);", "glsl-cube-eye-defaults"),  # -z face mirrored
        ("sctc = vec2(d.x, d.z);", "sctc = vec2(d.x, -d.z);", "glsl-cube-eye-pcf3"),  # +y face upside down
        ("int row = int(size) - 1 - int(floor(st.y * size));", "int row = int(floor(st.y * size));",
         "glsl-cube-eye-defaults"),  # no row flip
        ("return 2 * a + (d[a] < 0.0 ? 1 : 0);", "return 2 * a;", "glsl-cube-eye-defaults"),  # the axis' sign ignored
        ("if (ma > far) {", "if (false) {", "glsl-cube-eye-short-far"),  # beyond the far plane read as shadowed
    ],
    ids=["mirrored-face", "flipped-face", "no-row-flip", "no-sign", "no-far-fix"],
)  # fmt: skip
def test_a_wrong_lookup_is_caught(old, new, case):
    msg = _fail_of(shader_edit("cube_shadow.frag", old, new), "check_glsl_cube_shadow", case)
    assert "shaders/cube_shadow.frag, the cube lookup's fragment stage" in msg and "points differ" in msg, msg


#: Each face's (s, t) entry of cube_shadow.frag's table, and a wrong one: the face mirrored left-right (s negated).
FACE_ENTRIES = [
    ("sctc = vec2(-d.z, -d.y);", "sctc = vec2(d.z, -d.y);"),  # +x
    ("sctc = vec2(d.z, -d.y);", "sctc = vec2(-d.z, -d.y);"),  # -x
    ("sctc = vec2(d.x, d.z);", "sctc = vec2(-d.x, d.z);"),  # +y
    ("sctc = vec2(d.x, -d.z);", "sctc = vec2(-d.x, -d.z);"),  # -y
    ("sctc = vec2(d.x, -d.y);", "sctc = vec2(-d.x, -d.y);"),  # +z
    ("sctc = vec2(-d.x, -d.y);", "sctc = vec2(d.x, -d.y);"),  # -z
]


def _face_edit(face: int, new: str):
    """Replace the table entry of ``face`` only (the -x and +z entries read like other faces' right-hand sides)."""
    branch = "if (face == 0) {" if face == 0 else f"if (face == {face}) {{" if face < 5 else "} else {"
    old = FACE_ENTRIES[face][0]

    def edit(dest):
        path = dest / "shaders" / "cube_shadow.frag"
        text = path.read_text()
        head, tail = text.split(branch, 1)
        assert tail.lstrip().startswith(old), (face, tail[:80])
        path.write_text(head + branch + tail.replace(old, new, 1))

    return edit


@pytest.mark.parametrize(
    ("face", "wrong"),
    [(f, w) for f, (_, mirrored) in enumerate(FACE_ENTRIES) for w in (mirrored, "swap")],
    ids=[f"{face}-{kind}" for face in ("+x", "-x", "+y", "-y", "+z", "-z") for kind in ("mirrored", "transposed")],
)
def test_a_wrong_face_entry_is_caught_by_the_public_room_case(face, wrong):
    """Every face's (s, t) table entry mirrored, or its s and t swapped, fails the public room case and names the
    face (the eye view has no +z point and light "a" no shadow on +x: the room case is what catches those)."""
    if wrong == "swap":
        s, t = FACE_ENTRIES[face][0].removeprefix("sctc = vec2(").removesuffix(");").split(", ")
        wrong = f"sctc = vec2({t}, {s});"
    msg = _fail_of(_face_edit(face, wrong), "check_glsl_cube_shadow", "glsl-cube-room-defaults")
    name = ("+x", "-x", "+y", "-y", "+z", "-z")[face]
    assert "shaders/cube_shadow.frag, the cube lookup's fragment stage" in msg, msg
    assert re.search(rf"by the light's cube face: {re.escape(name)}: \d+$", msg.splitlines()[0]), msg


@pytest.mark.parametrize("old", ["if (ad.y > ad[a]) {", "if (ad.z > ad[a]) {"], ids=["x-y-tie-to-y", "z-tie-to-z"])
def test_the_later_axis_on_a_face_tie_is_caught(old):
    """`>` turned `>=` in cube_face (the audit's mutants): points exactly on a cube edge read the later axis's face."""
    msg = _fail_of(shader_edit("cube_shadow.frag", old, old.replace(">", ">=")), "check_glsl_cube_shadow",
                   "glsl-cube-ties-defaults")  # fmt: skip
    assert "exactly between two faces" in msg and "points differ" in msg, msg


@pytest.mark.parametrize("code", ["4", "0"], ids=["back-never-culled", "back-culled-under-none"])
def test_wrong_back_culling_is_caught_inside_the_room(code):
    """The audit's survivors `cull == 2` -> `cull == 4` / `cull == 0`: back culling dropped (the small scene's
    closed meshes show the same nearest faces either way); from inside the room the walls are back faces."""
    old = "(cull == 2 && !gl_FrontFacing)"
    msg = _fail_of(shader_edit("cube_depth.frag", old, old.replace("2", code)), "check_glsl_cube_depth",
                   "glsl-cube-linear-room-48-back")  # fmt: skip
    assert 'cull="back"' in msg and "cube_depth.frag culls the wrong faces" in msg, msg


def test_a_broken_cube_lookup_costs_only_its_own_tests():
    """cube_shadow.frag that does not compile: the cube pass's check, and Task 10's, still pass on the same copy."""
    from tests.graded.shadows import test_shadows_cube_glsl, test_shadows_glsl

    with planted_lab("shadows", shader_edit("cube_shadow.frag", "ma = ad[a];", "ma = ad[a]"), timeout=180) as lab:
        test_shadows_cube_glsl.check_glsl_cube_depth(lab, "glsl-cube-linear-b-48-none")
        test_shadows_glsl.check_glsl_shadow(lab, "glsl-eye-ortho-defaults")
        with pytest.raises(GradingFailure, match=r"shaders/cube_shadow.frag \(Task 12"):
            test_shadows_cube_glsl.check_glsl_cube_shadow(lab, "glsl-cube-eye-defaults")


@pytest.mark.parametrize("shader", ["cube_depth.frag", "cube_shadow.frag"])
def test_a_hanging_shader_is_named_with_its_task(shader):
    assert_hang_names_its_task("shadows", shader, f"Task {TASK[shader]} (")


@pytest.mark.parametrize("shader", list(TASK))
def test_the_stubs_are_the_solutions_with_error_directives(shader):
    stub_error_lines("shadows", shader, f"Task {TASK[shader]} (")
