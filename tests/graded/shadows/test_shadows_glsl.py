"""Graded tests of the shadows lab's GLSL route (tasks 9-10): the student's shaders against the NumPy route.

Expected values are the NumPy route's outputs stored by ``geomlib refs build`` (the depth-pass cases'
references, and the per-pixel visibilities of ``cases_glsl.py``); none is computed here.

Tolerances, from the measured agreement of the solution's shaders with the NumPy route on llvmpipe
(the handout's section 9 gives the numbers):

* depth maps: covered texels agree exactly (0 of about 0.5 M texels over 5 lights, 3 sizes and the 3
  culling modes); depths differ by at most 3.6e-4 (p99.9 2e-4), because the GPU snaps vertices to
  1/256 of a texel before interpolating depth, an error of the local depth slope times 1/256. So
  ``GLSL_DEPTH_ATOL = 1e-3`` window-depth units (a sixteenth of the default bias of a 64² map) and at
  most ``GLSL_COVERAGE_BAD = 0.1%`` of texels covered on one side only (a texel centre exactly on an edge,
  where the two rasterizers' tie rules may differ);
* visibilities: at most 2.9e-8 apart (float32 of fractions such as 1/9) over the same lights, 2 map
  sizes, 2 point sets and 8 option sets: no 0/1 decision flipped. So ``GLSL_VISIBILITY_ATOL = 1e-6``.
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import graded
from geomlib.grading.cases import hidden_cases, load_reference, stored_input
from geomlib.grading.checks import format_vec
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture

from .cases import CASES
from .cases_glsl import STORED, STORED_HIDDEN, eye_points
from .support import VISIBILITY_SHAPES, gpu_array, small_scene, visibility_picture

GLSL_DEPTH_ATOL = 1e-3
GLSL_COVERAGE_BAD = 1e-3
GLSL_VISIBILITY_ATOL = 1e-6
DEPTH_LABEL = "glsl_depth_map (shaders/depth.vert + shaders/depth.frag, the depth pass from the light)"
SHADOW_LABEL = "glsl_shadow_visibility (shaders/shadow.frag, the shadow pass's fragment stage)"


def _case(case_id: str):
    return {c.id: c for c in (*CASES, *hidden_cases("shadows", package=__package__), *STORED, *STORED_HIDDEN)}[case_id]


def expect_depth_map(label: str, got, expected) -> None:
    """A GPU depth map against the NumPy one: the same covered texels (up to GLSL_COVERAGE_BAD of them),
    depths within GLSL_DEPTH_ATOL there, 1.0 elsewhere. The message says which stage is likely wrong."""
    e = np.asarray(expected, float)
    g = gpu_array(label, got, e, "the map has shape {got}, expected {expected}")
    cov_e, cov_g = e < 1.0, g < 1.0
    coverage = cov_e != cov_g
    per = np.where(cov_e & cov_g, np.abs(g - e), np.where(coverage, np.abs(g - e), 0.0))
    per[np.isnan(g)] = np.inf
    depth_bad = (cov_e & cov_g) & ~(np.abs(g - e) <= GLSL_DEPTH_ATOL)
    if coverage.mean() <= GLSL_COVERAGE_BAD and not depth_bad.any() and not np.isnan(g).any():
        return
    picture = failure_picture(label, g, e, name="D", atol=GLSL_DEPTH_ATOL)
    if np.isnan(g).any():
        r, c = (int(i) for i in np.argwhere(np.isnan(g))[0])
        raise Mismatch(f"{label}: D[{r}, {c}] is NaN (the fragment stage, depth.frag, wrote NaN)", picture)
    if coverage.mean() > GLSL_COVERAGE_BAD:
        r, c = (int(i) for i in np.argwhere(coverage)[0])
        raise Mismatch(
            f"{label}: D[{r}, {c}] expected {format_vec(e[r, c])}, got {format_vec(g[r, c])}; "
            f"{int(coverage.sum())} of {coverage.size} texels are covered in one map and empty (1.0) in the other: "
            f"the vertex stage (depth.vert: gl_Position = lightSpaceMatrix (position, 1)) places the scene wrongly, "
            f"or depth.frag culls the wrong faces (cull 1 = front: gl_FrontFacing, 2 = back)",
            picture,
        )
    r, c = (int(i) for i in np.argwhere(depth_bad)[0])
    raise Mismatch(
        f"{label}: D[{r}, {c}] expected {format_vec(e[r, c])}, got {format_vec(g[r, c])}; the covered texels are "
        f"right but {int(depth_bad.sum())} depths differ by more than {GLSL_DEPTH_ATOL:g}: the fragment stage "
        f"(depth.frag) must write the window depth gl_FragCoord.z, in [0, 1]",
        picture,
    )


def check_glsl_depth(lab, case_id: str) -> None:
    """``glsl_depth_map`` on the inputs of a NumPy depth-pass case against its reference."""
    case = _case(case_id)
    inp = case.inputs()
    cull = case.params.get("cull", "front")
    got = lab.glsl_depth_map(inp["V"], inp["F"], inp["M"], inp["size"], cull)
    expected = load_reference("shadows", case)["D"] if case.points else stored_input("shadows", case_id)["D"]
    expect_depth_map(f'{DEPTH_LABEL} on "{case_id}" (cull="{cull}")', got, expected)


def check_glsl_cube_face(lab, prefix: str, size: int, face: int) -> None:
    """One face of a point light's cube map (stored NumPy depth pass through the stored face matrix)."""
    V, F = small_scene()
    M = stored_input("shadows", f"{prefix}cube-matrices")["Ms"][face]
    got = lab.glsl_depth_map(V, F, M, size, "front")
    expected = stored_input("shadows", f"{prefix}cube-depth-{size}-{face}")["D"]
    expect_depth_map(f'{DEPTH_LABEL} on cube face {face} of a point light (cull="front")', got, expected)


def check_glsl_shadow(lab, case_id: str) -> None:
    """``glsl_shadow_visibility`` per eye pixel against the stored NumPy ``shadow_visibility``."""
    case = _case(case_id)
    got = lab.glsl_shadow_visibility(**case.inputs(), **case.params)
    e = stored_input("shadows", case_id)["visibility"]
    opts = ", ".join(f"{k}={v!r}" for k, v in case.params.items()) or "the defaults"
    label = f'{SHADOW_LABEL} on "{case_id}" ({opts})'
    g = gpu_array(label, got, e, VISIBILITY_SHAPES)
    bad = ~(np.abs(g - e) <= GLSL_VISIBILITY_ATOL)  # NaN counts as wrong
    if not bad.any():
        return
    mask = eye_points()[0]
    r, c = (int(i) for i in np.argwhere(mask)[np.flatnonzero(bad)[0]])
    i = int(np.flatnonzero(bad)[0])
    nan = " (NaN: a division by zero, or a read outside the map?)" if np.isnan(g[i]) else ""
    raise Mismatch(
        f"{label}: pixel [{r}, {c}] of the eye view expected visibility {e[i]:.6g}, got {g[i]:.6g}{nan}; "
        f"{int(bad.sum())} of {bad.size} pixels differ by more than {GLSL_VISIBILITY_ATOL:g}",
        visibility_picture(label, mask, g, e, GLSL_VISIBILITY_ATOL),
    )


# ------------------------------------------------------------------------------ Task 9: light pass


@graded(points=2, part="light pass", timeout=60)
def test_glsl_depth_map(lab):
    """shaders/depth.vert + depth.frag against depth_map: an orthographic and a perspective light, no culling"""
    check_glsl_depth(lab, "depth-ortho-64")
    check_glsl_depth(lab, "depth-spot-48")


@graded(points=1, part="light pass", timeout=60)
def test_glsl_depth_map_front_culled(lab):
    """front-face culling in depth.frag: an orthographic map and the spot light whose far plane cuts the floor"""
    check_glsl_depth(lab, "depth-front-culled")
    check_glsl_depth(lab, "depth-spot-short-64")


# ------------------------------------------------------------------------------ Task 10: shadow.frag


@graded(points=1, part="fragment shadow test", timeout=60)
def test_glsl_shadow_bias(lab):
    """shaders/shadow.frag per eye pixel: a constant bias, then the default constant + slope-scaled bias with a map
    over the middle of the floor (lit beside it)"""
    check_glsl_shadow(lab, "glsl-eye-ortho-constant-bias")
    check_glsl_shadow(lab, "glsl-eye-ortho-defaults")


@graded(points=1, part="fragment shadow test", timeout=60)
def test_glsl_shadow_frustum(lab):
    """beyond a spot light's far plane (z > 1): lit with the fix, read clamped border texels without"""
    check_glsl_shadow(lab, "glsl-eye-spot-short-far")
    check_glsl_shadow(lab, "glsl-eye-spot-short-far-nofix")


@graded(points=2, part="fragment shadow test", timeout=60)
def test_glsl_shadow_pcf(lab):
    """3 x 3 PCF with the receiver-plane gradient (a spot whose far plane cuts the floor), and PCF on the rotated
    Poisson disk"""
    check_glsl_shadow(lab, "glsl-eye-spot-pcf3")
    check_glsl_shadow(lab, "glsl-eye-spot-poisson")
