"""Graded tests of the point light's GLSL route (tasks 11-12): the student's cube shaders against the NumPy route.

Expected values are the NumPy route's outputs stored by ``geomlib refs build`` (``cases_cube_glsl.py``:
the linear cube pass ``cube_distance_maps`` and the lookup ``linear_point_shadow_visibility``); none is
computed here. The face matrices are stored too, so Task 11 does not need Task 8.

Tolerances, from the measured agreement of the solution's shaders with the NumPy route on llvmpipe
(the handout's section 1.9 gives the numbers):

* linear cube maps: 72 set-ups (4 lights x 2 far planes x sizes 48, 64, 256 x the 3 culling modes,
  10.4 M texels): 63 texels differ, 53 covered on one side only and 10 holding another surface, all
  texel centres on an edge where the two rasterizers' tie rules differ (at most 4 in one set-up, 0.02%
  of a 48² cube); the other depths (distance / far) differ by at most 4.2e-4 (p99.9 1.0e-4), the GPU's
  vertex snapping. So ``CUBE_DEPTH_ATOL = 1e-3`` (a sixteenth of the default bias of a 64² face) and at
  most ``CUBE_TEXELS_BAD = 0.1%`` of the texels may differ (other coverage, or depth beyond the tolerance);
* visibilities: 11 of 688,920 point lookups differed (4 lights x 3 sizes x 2 far planes x 2 point sets x
  5 option sets), all of them points on a plane through the light, which sit exactly on a texel border
  of their face (the NumPy route's matrix product rounds to one side, the cube-map table to the other);
  at most 2 in one run of 3,741 points. So every point within ``CUBE_VISIBILITY_ATOL = 1e-6`` except at
  most ``CUBE_VISIBILITY_BAD = 0.1%`` of them (3 of the 3,741 eye pixels).
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import graded
from geomlib.grading.cases import stored_input
from geomlib.grading.checks import format_vec
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture

from .cases_cube_glsl import ROOM_GRID, STORED, STORED_HIDDEN, ties_points
from .cases_glsl import eye_points
from .support import VISIBILITY_SHAPES, gpu_array, visibility_picture

CUBE_DEPTH_ATOL = 1e-3
CUBE_TEXELS_BAD = 1e-3
CUBE_VISIBILITY_ATOL = 1e-6
CUBE_VISIBILITY_BAD = 1e-3
CUBE_DEPTH_LABEL = (
    "glsl_cube_depth_maps (shaders/cube_depth.vert + shaders/cube_depth.frag, the cube pass from the light)"
)
CUBE_SHADOW_LABEL = "glsl_point_shadow_visibility (shaders/cube_shadow.frag, the cube lookup's fragment stage)"
FACES = ("+x", "-x", "+y", "-y", "+z", "-z")


def _case(case_id: str):
    return {c.id: c for c in (*STORED, *STORED_HIDDEN)}[case_id]


def _empty(size: int) -> np.ndarray:
    """Where nothing was drawn both routes hold the far plane along the texel's ray, sqrt(1 + x² + y²)."""
    c = (2.0 * np.arange(size) + 1.0) / size - 1.0
    return np.sqrt(1.0 + c[None, :] ** 2 + c[::-1, None] ** 2)


def expect_cube_maps(label: str, got, expected) -> None:
    """Six GPU linear-depth maps against the NumPy ones: the same covered texels and depths within
    CUBE_DEPTH_ATOL there, except on at most CUBE_TEXELS_BAD of the texels. The message names the face and
    the stage that is likely wrong."""
    e = np.asarray(expected, float)
    g = gpu_array(label, got, e, "the maps have shape {got}, expected {expected} (six faces)")
    empty = _empty(e.shape[1])[None]
    cov_e, cov_g = np.abs(e - empty) > 1e-9, np.abs(g - empty) > 1e-9
    coverage = cov_e != cov_g
    depth_bad = cov_e & cov_g & ~(np.abs(g - e) <= CUBE_DEPTH_ATOL)
    nan = np.isnan(g)
    if (coverage | depth_bad).mean() <= CUBE_TEXELS_BAD and not nan.any():
        return

    def where(mask):
        """The first bad texel, as text, and the picture of its face."""
        f, r, c = (int(i) for i in np.argwhere(mask)[0])
        at = f"face {f} ({FACES[f]}) D[{r}, {c}] expected {format_vec(e[f, r, c])}, got {format_vec(g[f, r, c])}"
        return at, failure_picture(f"{label}, face {f} ({FACES[f]})", g[f], e[f], name="D", atol=CUBE_DEPTH_ATOL)

    if nan.any():
        at, picture = where(nan)
        raise Mismatch(f"{label}: {at} (NaN: the fragment stage, cube_depth.frag, wrote NaN)", picture)
    if coverage.mean() > CUBE_TEXELS_BAD or depth_bad.sum() <= coverage.sum():
        at, picture = where(coverage)
        raise Mismatch(
            f"{label}: {at}; {int(coverage.sum())} of {coverage.size} texels are covered in one map and empty in "
            f"the other: the vertex stage (cube_depth.vert: gl_Position = lightSpaceMatrix (position, 1)) places "
            f"the scene wrongly, or cube_depth.frag culls the wrong faces (cull 1 = front: gl_FrontFacing, 2 = back)",
            picture,
        )
    at, picture = where(depth_bad)
    raise Mismatch(
        f"{label}: {at}; the covered texels are right but {int(depth_bad.sum())} depths differ by more than "
        f"{CUBE_DEPTH_ATOL:g}: the fragment stage (cube_depth.frag) must write the linear depth "
        f"length(world - lightPos) / far, with `world` the world position passed on by cube_depth.vert",
        picture,
    )


def check_glsl_cube_depth(lab, case_id: str) -> None:
    """``glsl_cube_depth_maps`` through the stored face matrices against the stored ``cube_distance_maps``."""
    case = _case(case_id)
    inp = case.inputs()
    cull = case.params["cull"]
    key = case_id.removeprefix("hidden-").removeprefix("glsl-cube-linear-").rsplit("-", 2)[0]
    prefix = "hidden-" if case_id.startswith("hidden-") else ""
    Ms = stored_input("shadows", f"{prefix}glsl-cube-matrices-{key}")["Ms"]
    got = lab.glsl_cube_depth_maps(inp["V"], inp["F"], inp["position"], inp["size"], inp["near"], inp["far"], cull,
                                   matrices=Ms)  # fmt: skip
    expected = stored_input("shadows", case_id)["maps"]
    expect_cube_maps(f'{CUBE_DEPTH_LABEL} on "{case_id}" (cull="{cull}")', got, expected)


def check_glsl_cube_shadow(lab, case_id: str) -> None:
    """``glsl_point_shadow_visibility`` per eye pixel against the stored ``linear_point_shadow_visibility``."""
    case = _case(case_id)
    inp = case.inputs()
    got = lab.glsl_point_shadow_visibility(**inp, **case.params)
    e = stored_input("shadows", case_id)["visibility"]
    opts = ", ".join(f"{k}={v!r}" for k, v in case.params.items()) or "the defaults"
    label = f'{CUBE_SHADOW_LABEL} on "{case_id}" ({opts})'
    g = gpu_array(label, got, e, VISIBILITY_SHAPES)
    bad = ~(np.abs(g - e) <= CUBE_VISIBILITY_ATOL)  # NaN counts as wrong
    if bad.mean() <= CUBE_VISIBILITY_BAD and not np.isnan(g).any():
        return
    room = "-room-" in case_id  # the walls of a room around the light, side by side, instead of the eye view
    ties = "-ties-" in case_id  # 10 points on each of the cube's 12 edges, a row per edge
    mask = np.ones((ROOM_GRID, 6 * ROOM_GRID), bool) if room else ties_points()[0] if ties else eye_points()[0]
    i = int(np.flatnonzero(np.isnan(g))[0]) if np.isnan(g).any() else int(np.flatnonzero(bad)[0])
    r, c = (int(x) for x in np.argwhere(mask)[i])
    nan = " (NaN: a division by zero, or a read outside the cube map?)" if np.isnan(g[i]) else ""
    d = np.asarray(inp["P"], float) - np.asarray(inp["position"], float)
    axis = np.abs(d).argmax(axis=1)  # the light's cube face of each point: major axis, its sign
    face = 2 * axis + (d[np.arange(len(d)), axis] < 0)
    per_face = ", ".join(f"{FACES[f]}: {int((bad & (face == f)).sum())}" for f in range(6) if (bad & (face == f)).any())
    where = f"pixel [{r}, {c}] of the eye view"
    if room:
        where = f"wall point [{r}, {c}] (walls +x -x +y -y +z -z side by side)"
    if ties:
        where = (
            f"point {c} of cube edge {r}, exactly between two faces (|d_a| = |d_b|: the first axis's face, as "
            f"cube_face_index, must be read)"
        )
    raise Mismatch(
        f"{label}: {where} expected visibility {e[i]:.6g}, got {g[i]:.6g}{nan}; "
        f"{int(bad.sum())} of {bad.size} points differ by more than {CUBE_VISIBILITY_ATOL:g} (at most "
        f"{CUBE_VISIBILITY_BAD:.1%} may, points on a texel border); by the light's cube face: {per_face}",
        visibility_picture(label, mask, g, e, CUBE_VISIBILITY_ATOL),
    )


# ------------------------------------------------------------------------------ Task 11: cube light pass


@graded(points=2, part="cube light pass", timeout=120)
def test_glsl_cube_depth_maps(lab):
    """shaders/cube_depth.vert + cube_depth.frag against cube_distance_maps: six faces, front faces culled"""
    check_glsl_cube_depth(lab, "glsl-cube-linear-a-64-front")


@graded(points=1, part="cube light pass", timeout=120)
def test_glsl_cube_depth_maps_other_light(lab):
    """another light, no culling, and a far plane that cuts the scene"""
    check_glsl_cube_depth(lab, "glsl-cube-linear-b-48-none")
    check_glsl_cube_depth(lab, "glsl-cube-linear-b-short-48-front")


# ------------------------------------------------------------------------------ Task 12: cube shadow lookup


@graded(points=2, part="cube shadow lookup", timeout=60)
def test_glsl_cube_shadow(lab):
    """shaders/cube_shadow.frag per eye pixel: face choice, the cube-map table and linear depth, default and small bias"""
    check_glsl_cube_shadow(lab, "glsl-cube-eye-defaults")
    check_glsl_cube_shadow(lab, "glsl-cube-eye-small-bias")


@graded(points=1, part="cube shadow lookup", timeout=60)
def test_glsl_cube_shadow_pcf_and_far(lab):
    """3 x 3 PCF within a face, and points beyond the far plane lit"""
    check_glsl_cube_shadow(lab, "glsl-cube-eye-pcf3")
    check_glsl_cube_shadow(lab, "glsl-cube-eye-short-far")


@graded(points=1, part="cube shadow lookup", timeout=60)
def test_glsl_cube_shadow_every_face(lab):
    """a light inside a room: lit and shadowed wall points on all six cube faces (each face's (s, t) table entry)"""
    check_glsl_cube_shadow(lab, "glsl-cube-room-defaults")
    check_glsl_cube_shadow(lab, "glsl-cube-room-pcf3")


@graded(points=1, part="cube shadow lookup", timeout=60)
def test_glsl_cube_shadow_face_ties(lab):
    """points exactly on the cube's edges (|d_a| = |d_b|): the face of the first axis, as cube_face_index"""
    check_glsl_cube_shadow(lab, "glsl-cube-ties-defaults")


@graded(points=1, part="cube light pass", timeout=120)
def test_glsl_cube_depth_maps_inside_a_room(lab):
    """the cube pass from inside a closed room: every texel of all six faces covered; back culling drops the walls"""
    check_glsl_cube_depth(lab, "glsl-cube-linear-room-64-front")
    check_glsl_cube_depth(lab, "glsl-cube-linear-room-48-back")
