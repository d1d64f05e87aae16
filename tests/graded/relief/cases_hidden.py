"""Hidden graded cases of the lab "relief" (not shipped to students)."""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case

from .cases import SCALE, PixelsClose, pixel_uv, random_unit_grid, relief_case, shadow_inputs, smooth_bumps, steps_map


def hidden(case: Case) -> Case:
    case.visibility = "hidden"
    return case


def random_views(height: str, seed: int, p: int = 40):
    def make():
        H = smooth_bumps(64, 3) if height == "bumps" else steps_map(64, 8)
        return {"height": H, "uv": pixel_uv(p, 0.1, 0.9), "view": random_unit_grid(p, seed)}

    return make


CASES = [
    Case(
        id="bump-offset-uint8",
        function="bump_offset",
        inputs=lambda: {"height": (smooth_bumps(48, 3) * 255).astype(np.uint8), "uv": pixel_uv(20, -0.1, 1.1)},
        params={"strength": 0.1},
        outputs=("offset",),
        check=PixelsClose("offset", 1e-9),
        part="bump mapping",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="bump-normal-bumps",
        function="bump_normal",
        inputs=lambda: {"height": smooth_bumps(40, 3), "uv": pixel_uv(32)},
        params={"strength": 0.2},
        outputs=("n",),
        check=PixelsClose("n", 1e-9),
        part="bump mapping",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="parallax-random-views",
        function="parallax_uv",
        inputs=random_views("bumps", 1),
        params={"scale": 0.05, "bias": -0.02},
        outputs=("uv",),
        check=PixelsClose("uv", 1e-9, texels=64),
        part="parallax",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="parallax-limited-random-views",
        function="parallax_uv",
        inputs=random_views("steps", 2),
        params={"scale": SCALE, "offset_limit": True},
        outputs=("uv",),
        check=PixelsClose("uv", 1e-9, texels=64),
        part="parallax",
        points=2,
        visibility="hidden",
    ),
    hidden(relief_case("relief-none-steps-75", "steps", 75, "none", 2, None)),
    hidden(
        relief_case("relief-linear-bumps-40-layers-4-64", "bumps", 40, "linear", 1, None, min_layers=4, max_layers=64)
    ),
    hidden(relief_case("relief-secant-steps-perspective", "steps", "perspective", "secant", 2, None, refine_steps=3)),
    hidden(relief_case("relief-secant-bumps-30", "bumps", 30, "secant", 1, None)),
    hidden(relief_case("relief-binary-bumps-perspective", "bumps", "perspective", "binary", 2, None, refine_steps=8)),
    hidden(relief_case("relief-binary-steps-80", "steps", 80, "binary", 1, None)),
    Case(
        id="shadow-steps-60",
        function="relief_shadow",
        inputs=shadow_inputs("steps", 60),
        params={"scale": SCALE, "layers": 16},
        outputs=("visibility",),
        check=PixelsClose("visibility", 0, 0.995),
        part="self-shadowing",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="shadow-bumps-80",
        function="relief_shadow",
        inputs=shadow_inputs("bumps", 80, p=40),
        params={"scale": 0.1},
        outputs=("visibility",),
        check=PixelsClose("visibility", 0, 0.995),
        part="self-shadowing",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="silhouette-borders",
        function="inside_texture",
        inputs=lambda: {
            "uv": np.array([[[0.0, 0.0], [1.0, 1.0], [1.0 + 1e-12, 0.5]], [[0.5, -1e-12], [0.3, 0.7], [-0.0, 1.0]]])
        },
        outputs=("keep",),
        check=PixelsClose("keep", 0),
        part="silhouettes",
        points=2,
        visibility="hidden",
    ),
]
