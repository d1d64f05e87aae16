"""Graded tests of the lab "relief": stored references, hand-checkable cases, the GLSL route and bad input.

Expected values here are worked out by hand (comments) or are the stored NumPy references of the
cases (the GLSL shaders are compared with them); none comes from the solution at test time.
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import expect_close, expect_raises, graded, reference_tests
from geomlib.grading.cases import hidden_cases, load_reference
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture

from ..common import expect_rejected
from .cases import CASES, SCALE, direction, pixel_uv, texel_uv

test_references = reference_tests(CASES)
BY_ID = {c.id: c for c in CASES}

#: The GLSL route: the same math in float32 agrees with the NumPy reference to 0.05 texel on
#: 99.9% of the pixels (rare float32 ties at a layer boundary land one layer off).
GLSL_TEXELS = 0.05
GLSL_FRACTION = 0.999
SHADER_OF = {"glsl_parallax_uv": "parallax", "glsl_relief_uv": "relief", "glsl_relief_shadow": "shadow"}


def expect_glsl_matches(label: str, got, expected, *, atol: float, unit: str = "", scale_to: float = 1.0):
    """``got`` within ``atol`` of ``expected`` (per pixel, max over channels) on GLSL_FRACTION of the pixels."""
    e = np.asarray(expected, float)
    g = np.asarray(got, float)
    if g.shape != e.shape:
        raise Mismatch(f"{label}: the shader's output has shape {g.shape}, expected {e.shape}")
    per = np.abs(g - e).reshape(*e.shape[:2], -1).max(axis=-1) * scale_to
    bad = ~(per <= atol)
    if bad.mean() > 1 - GLSL_FRACTION:
        r, c = (int(i) for i in np.argwhere(bad)[0])
        raise Mismatch(
            f"{label}: pixel [{r}, {c}] differs from the NumPy reference by {per[r, c]:.3g}{unit}; "
            f"{int(bad.sum())} of {bad.size} pixels differ by more than {atol:g}{unit} "
            f"(at most {100 * (1 - GLSL_FRACTION):.2g}% may)",
            # the picture in the message's unit: values scaled like the text's (uv * s = texels)
            failure_picture(label, g * scale_to, e * scale_to, name="shader output", atol=atol, unit=unit.strip()),
        )


def check_glsl_case(lab, case_id: str, function: str) -> None:
    """Run the student's shader on a NumPy case's inputs and compare with that case's stored reference."""
    case = BY_ID.get(case_id) or {c.id: c for c in hidden_cases("relief", package=__package__)}[case_id]
    got = getattr(lab, function)(**case.inputs(), **case.params)
    expected = load_reference("relief", case)
    label = f'{function} (shaders/{SHADER_OF[function]}.frag) on "{case_id}"'
    s = case.inputs()["height"].shape[0]
    if function == "glsl_relief_shadow":
        expect_glsl_matches(
            label + ", visibility", np.asarray(got)[..., None], expected["visibility"][..., None], atol=0
        )
        return
    if function == "glsl_parallax_uv":
        expect_glsl_matches(label, got, expected["uv"], atol=GLSL_TEXELS, unit=" texels", scale_to=s)
        return
    uv, depth, steps = got
    expect_glsl_matches(label + ", uv", uv, expected["uv"], atol=GLSL_TEXELS, unit=" texels", scale_to=s)
    expect_glsl_matches(label + ", steps", np.asarray(steps)[..., None], expected["steps"][..., None], atol=0)
    # depth = scale d: 0.05 texel of uv travel is 0.05 / s * view_z / |view_xy| of depth at most; allow 1e-3 scale.
    expect_glsl_matches(
        label + ", depth", np.asarray(depth)[..., None], expected["depth"][..., None], atol=1e-3 * SCALE
    )


# ------------------------------------------------------------------------------ task 1: bump mapping


@graded(points=1, part="bump mapping")
def test_bump_by_hand(lab):
    """flat and ramp height maps: n = (0, 0, 1) and normalize(-k, 0, 1)"""
    s = 16
    uv = texel_uv(s)[2:-2, 2:-2]  # away from the clamped border
    n = lab.bump_normal(np.full((s, s), 0.3), uv, strength=0.5)
    expect_close("bump_normal on a flat map", n, np.broadcast_to([0.0, 0, 1], n.shape), atol=1e-12)
    # h = u at the texel centres: dh/du = ((c + 1.5) / s - (c - 0.5) / s) * s / 2 = 1, dh/dv = 0.
    ramp = np.broadcast_to((np.arange(s) + 0.5) / s, (s, s))
    n = lab.bump_normal(ramp, uv, strength=0.5)
    expect_close(
        "bump_normal on the ramp h = u",
        n,
        np.broadcast_to(np.array([-0.5, 0, 1]) / np.sqrt(1.25), n.shape),
        atol=1e-12,
        hint="dh/du by central differences one texel (1/s) each way, times s / 2",
    )
    D = lab.bump_offset(ramp, uv, strength=0.5)
    expect_close("bump_offset on the ramp h = u", D, np.broadcast_to([0.5, 0.0], D.shape), atol=1e-12)


# ------------------------------------------------------------------------------ task 2: parallax


@graded(points=1, part="parallax")
def test_parallax_by_hand(lab):
    """h = 1 does not shift; h = 0 at 45 degrees shifts by scale (limited: scale sin 45)"""
    uv = pixel_uv(6)
    v = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5)])
    got = lab.parallax_uv(np.ones((8, 8)), uv, v, scale=0.1)
    expect_close("parallax_uv on h = 1", got, uv, atol=1e-12, hint="hsb = scale h + bias = 0 where h = 1")
    # h = 0: hsb = -scale, view_xy / view_z = (1, 0): uv' = uv - (0.1, 0).
    got = lab.parallax_uv(np.zeros((8, 8)), uv, v, scale=0.1)
    expect_close("parallax_uv on h = 0 at 45 degrees", got, uv - [0.1, 0.0], atol=1e-12)
    got = lab.parallax_uv(np.zeros((8, 8)), uv, v, scale=0.1, offset_limit=True)
    expect_close("parallax_uv(offset_limit=True) on h = 0", got, uv - [0.1 * np.sqrt(0.5), 0.0], atol=1e-12)


# ------------------------------------------------------------------------------ task 3: relief mapping


@graded(points=1, part="relief mapping")
def test_relief_on_flat_maps_by_hand(lab):
    """h = 0: hit at the bottom layer; h = 1: at the polygon; h = 1/2: the refinements find d = 1/2; two flat halves"""
    uv = pixel_uv(4)
    v = direction(45, 0.0)  # view_z = cos 45: n = floor(8 + 24 (1 - 0.7071) + 0.5) = 15 layers
    for refine in ("none", "linear", "secant", "binary"):
        got, depth, steps = lab.relief_uv(np.zeros((8, 8)), uv, v, scale=0.1, refine=refine)
        expect_close(f"relief_uv(refine={refine!r}) steps on h = 0", steps, np.full((4, 4), 15), atol=0)
        # The crossing is at d = 1 = b, found exactly except by bisection: 5 halvings of [14/15, 1] keep
        # moving lo up (f < 0 below d = 1), so d = 1 - (1/15) / 64.
        d = 1 - 1 / 960 if refine == "binary" else 1.0
        expect_close(f"relief_uv(refine={refine!r}) depth on h = 0", depth, np.full((4, 4), 0.1 * d), atol=1e-12)
        expect_close(f"relief_uv(refine={refine!r}) uv on h = 0", got, uv - [0.1 * d, 0.0], atol=1e-12)
        got, depth, steps = lab.relief_uv(np.ones((8, 8)), uv, v, scale=0.1, refine=refine)
        expect_close(
            f"relief_uv(refine={refine!r}) on h = 1", got, uv, atol=1e-12, hint="f(0) = 0 >= 0: the hit is at i = 0"
        )
    # h = 1/2: layer 8 (d = 8/15) is the first below; linear: 7/15 + (1/15)(1/30)/(1/30 + 1/30) = 1/2 exactly.
    half = np.full((8, 8), 0.5)
    for refine in ("linear", "secant"):
        _, depth, steps = lab.relief_uv(half, uv, v, scale=0.1, refine=refine)
        expect_close(f"relief_uv(refine={refine!r}) steps on h = 1/2", steps, np.full((4, 4), 8), atol=0)
        expect_close(f"relief_uv(refine={refine!r}) depth on h = 1/2", depth, np.full((4, 4), 0.05), atol=1e-12)
    _, depth, _ = lab.relief_uv(half, uv, v, scale=0.1, refine="binary", refine_steps=5)
    # 5 bisections of [7/15, 8/15] leave an interval of 1/480; its midpoint is within 1/960 of 1/2.
    expect_close("relief_uv(refine='binary') depth on h = 1/2", depth, np.full((4, 4), 0.05), atol=0.1 / 960 + 1e-12)
    # Two flat halves: h = 1/4 for u < 1/2 (texel columns 0-3), h = 1/2 beyond. The rays of the pixels at
    # u = 1/8, 3/8 stay left of u = 7/16 (last texel centre at 1/4) and those at u = 5/8, 7/8 right of
    # 9/16, so each sees one flat height. h = 1/4: layer 12 (d = 12/15) is the first below;
    # linear: 11/15 + (1/15)(1/60)/(1/60 + 1/20) = 3/4 exactly (depth 0.075).
    steps_of = np.where(uv[..., 0] < 0.5, 12, 8)
    depth_of = np.where(uv[..., 0] < 0.5, 0.075, 0.05)
    halves = np.where(np.arange(8) < 4, 0.25, 0.5)[None, :].repeat(8, axis=0)
    for refine in ("linear", "secant", "binary"):
        _, depth, steps = lab.relief_uv(halves, uv, v, scale=0.1, refine=refine, refine_steps=5)
        expect_close(f"relief_uv(refine={refine!r}) steps on h = 1/4 | 1/2", steps, steps_of, atol=0)
        expect_close(f"relief_uv(refine={refine!r}) depth on h = 1/4 | 1/2", depth, depth_of,
                     atol=0.1 / 960 + 1e-12 if refine == "binary" else 1e-12)  # fmt: skip


# ------------------------------------------------------------------------------ task 4: self-shadowing


@graded(points=1, part="self-shadowing")
def test_shadow_of_a_wall_by_hand(lab):
    """a wall lit at 45 degrees shadows the floor up to scale beyond it"""
    s = 64
    H = np.zeros((s, s))
    H[:, : s // 2] = 1.0  # a wall of height 1 for u < 1/2
    u = np.array([0.52, 0.58, 0.62, 0.7, 0.9])
    uv = np.stack([u, np.full_like(u, 0.5)], axis=-1)
    # The floor (depth scale = 0.1) at u sees the light (towards -u, 45 degrees) over the wall iff u - 1/2 > 0.1.
    vis = lab.relief_shadow(H, uv, np.full(5, 0.1), np.array([-1.0, 0.0, 1.0]), scale=0.1, layers=64)
    expect_close("relief_shadow behind a wall", vis, [0.0, 0.0, 1.0, 1.0, 1.0], atol=0)
    vis = lab.relief_shadow(H, uv, np.full(5, 0.1), np.array([1.0, 0.0, 1.0]), scale=0.1, layers=64)
    expect_close("relief_shadow lit from the open side", vis, np.ones(5), atol=0)


# ------------------------------------------------------------------------------ the GLSL route


@graded(points=1, part="GLSL parallax", timeout=60)
def test_glsl_parallax(lab):
    """shaders/parallax.frag against the NumPy reference"""
    check_glsl_case(lab, "parallax-bumps-45", "glsl_parallax_uv")
    check_glsl_case(lab, "parallax-limited-perspective", "glsl_parallax_uv")


@graded(points=1, part="GLSL relief mapping", timeout=60)
def test_glsl_relief(lab):
    """shaders/relief.frag against the NumPy reference (steep and secant)"""
    check_glsl_case(lab, "relief-none-bumps-60", "glsl_relief_uv")
    check_glsl_case(lab, "relief-secant-bumps-70", "glsl_relief_uv")


@graded(points=1, part="GLSL self-shadowing", timeout=60)
def test_glsl_shadow(lab):
    """shaders/shadow.frag against the NumPy reference"""
    check_glsl_case(lab, "shadow-bumps-70", "glsl_relief_shadow")


# ------------------------------------------------------------------------------ bad input (given validation)


def expect_uv_rejected(
    lab, function: str, label: str, match: str, heights=None, view=(0, 0, 1.0), scale=0.1, **kwargs
) -> None:
    """``function(heights, pixel_uv(2), view, scale=scale, **kwargs)`` must raise a MeshError (default
    ``heights``: a flat 8 x 8 map; default ``view``: straight down)."""
    H = np.zeros((8, 8)) if heights is None else heights
    expect_rejected(lab, function, H, pixel_uv(2), view, scale=scale, match=match, label=label, **kwargs)


@graded(points=0, part="bad input")
def test_view_below_the_polygon_is_rejected(lab):
    expect_uv_rejected(lab, "relief_uv", "relief_uv(view with z < 0)", "z <= 0", view=(0.3, 0.0, -0.5))


@graded(points=0, part="bad input")
def test_unknown_refinement_is_rejected(lab):
    expect_uv_rejected(lab, "relief_uv", "relief_uv(refine='newton')", "refine", refine="newton")


@graded(points=0, part="bad input")
def test_bad_height_maps_are_rejected(lab):
    expect_uv_rejected(lab, "parallax_uv", "parallax_uv(8x6 height map)", "square", heights=np.zeros((8, 6)))
    expect_raises(
        lambda: lab.bump_normal(np.full((8, 8), 1.5), pixel_uv(2), strength=0.1),
        "MeshError",
        match=r"\[0, 1\]",
        label="bump_normal(heights above 1)",
    )
    H = np.zeros((8, 8))
    H[2, 3] = np.nan
    expect_uv_rejected(lab, "relief_uv", "relief_uv(NaN height)", "NaN|finite", heights=H)


@graded(points=0, part="bad input")
def test_bad_parameters_are_rejected(lab):
    label = "relief_uv(min_layers > max_layers)"
    expect_uv_rejected(lab, "relief_uv", label, "max_layers", min_layers=16, max_layers=8)
    label = "relief_shadow(depth of the wrong shape)"
    H, uv = np.zeros((8, 8)), pixel_uv(2)
    expect_rejected(
        lab, "relief_shadow", H, uv, np.zeros(3), (0, 0, 1.0), scale=0.1, match="depth has shape", label=label
    )
    expect_uv_rejected(lab, "parallax_uv", "parallax_uv(scale < 0)", "scale", scale=-0.1)
