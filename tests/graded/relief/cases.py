"""Graded cases of the lab "relief": inputs built here from NumPy only (never from the solution).

Tolerances: outputs are compared per pixel. Bump normals and offsets, parallax shifts and the
silhouette mask are pure arithmetic (1e-9). The ray march decides "below the surface or not" per
layer; an equivalent formula written in another order can flip a decision that is a tie to
round-off, so relief-mapping and shadow outputs must match on 99.5% of the pixels (uv and depth
to 1e-7, layer indices and visibility exactly), the rest is allowed to differ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib import portable
from geomlib.grading import Case
from geomlib.grading.checks import Context, as_output_array, format_vec

SCALE = 0.08

# ---------------------------------------------------------------------------------- checks


@dataclass
class PixelsClose:
    """Per-pixel outputs ``(h, w, ...)`` within ``atol`` on at least ``fraction`` of the pixels.

    ``texels`` (optional) is the height map's size: uv differences are then reported in texels.
    """

    output: str
    atol: float
    fraction: float = 1.0
    texels: int | None = None

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output])
        g = as_output_array(got.get(self.output), self.output, ctx, like=e)
        diff = np.abs(g.astype(np.float64) - e.astype(np.float64))
        per = diff.reshape(*e.shape[:2], -1).max(axis=-1) if e.ndim > 2 else diff
        bad = ~(per <= self.atol)  # NaN counts as bad
        if bad.mean() <= 1.0 - self.fraction:
            return
        r, c = (int(i) for i in np.argwhere(bad)[0])
        unit = f" ({per[r, c] * self.texels:.3g} texels)" if self.texels else ""
        allowed = f" (at most {100 * (1 - self.fraction):.2g}% may)" if self.fraction < 1 else ""
        ctx.fail(
            f"{self.output}[{r}, {c}] expected {format_vec(np.atleast_1d(e[r, c]))}, got "
            f"{format_vec(np.atleast_1d(g[r, c]))}{unit}; {int(bad.sum())} of {bad.size} pixels differ by more "
            f"than {self.atol:g}{allowed}"
        )


@dataclass
class AllOf:
    """Several checks of one case, in order."""

    checks: tuple

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        for check in self.checks:
            check(expected, got, ctx)


def relief_check(s: int) -> AllOf:
    return AllOf(
        (
            PixelsClose("steps", 0, 0.995),
            PixelsClose("uv", 1e-7, 0.995, texels=s),
            PixelsClose("depth", 1e-7, 0.995),
        )
    )


# ---------------------------------------------------------------------------------- inputs


def texel_uv(s: int) -> np.ndarray:
    """(s, s, 2) texel centres; row 0 is v = 1 - 0.5 / s."""
    r, c = np.mgrid[0:s, 0:s]
    return np.stack([(c + 0.5) / s, 1.0 - (r + 0.5) / s], axis=-1)


def pixel_uv(p: int, lo: float = 0.0, hi: float = 1.0) -> np.ndarray:
    """(p, p, 2) pixel centres of a p x p image covering [lo, hi]^2 of UV space, row 0 at the top."""
    t = lo + (hi - lo) * (np.arange(p) + 0.5) / p
    return np.stack(np.meshgrid(t, t[::-1]), axis=-1)


def smooth_bumps(s: int, k: int = 2) -> np.ndarray:
    """h = 1/2 + 1/2 sin(2 pi k u) sin(2 pi k v) at the texel centres, in [0, 1]."""
    uv = texel_uv(s)
    return 0.5 + 0.5 * portable.sin(2 * np.pi * k * uv[..., 0]) * portable.sin(2 * np.pi * k * uv[..., 1])


def steps_map(s: int, rows: int = 4) -> np.ndarray:
    """Bricks without bevels: 1 on the bricks, 0.2 in one-texel-wide mortar lines (sharp steps)."""
    r, c = np.mgrid[0:s, 0:s]
    course = r * rows // s
    joint_h = r % (s // rows) == 0
    joint_v = (c + (course % 2) * (s // rows)) % (2 * s // rows) == 0
    return np.where(joint_h | joint_v, 0.2, 1.0)


def direction(deg: float, azimuth_deg: float = 20.0) -> np.ndarray:
    t, a = np.radians(deg), np.radians(azimuth_deg)
    return np.array([portable.sin(t) * portable.cos(a), portable.sin(t) * portable.sin(a), portable.cos(t)])


def perspective_views(p: int, eye=(0.3, 0.8, 0.9)) -> np.ndarray:
    """(p, p, 3) unit vectors from the pixel centres of pixel_uv(p) (on z = 0) towards a nearby eye."""
    uv = pixel_uv(p)
    d = np.asarray(eye) - np.concatenate([uv, np.zeros((p, p, 1))], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def random_unit_grid(p: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(p, p, 3))
    v[..., 2] = np.abs(v[..., 2]) + 0.2  # above the polygon
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def relief_inputs(height: str, view, p: int = 48, s: int = 64):
    def make():
        H = smooth_bumps(s) if height == "bumps" else steps_map(s)
        V = perspective_views(p) if isinstance(view, str) else direction(view)
        return {"height": H, "uv": pixel_uv(p), "view": V}

    return make


def shadow_inputs(height: str, light_deg: float, p: int = 32):
    """Points ON the relief straight below the texel centres: uv = texel centres, depth = scale (1 - H)."""

    def make():
        H = smooth_bumps(p) if height == "bumps" else steps_map(p)
        return {"height": H, "uv": texel_uv(p), "depth": SCALE * (1.0 - H), "light": direction(light_deg, 200.0)}

    return make


def relief_case(cid, height, view, refine, points, hint, *, visibility="visible", **extra):
    s = 64
    return Case(
        id=cid,
        function="relief_uv",
        inputs=relief_inputs(height, view, s=s),
        params={"scale": SCALE, "refine": refine, **extra},
        outputs=("uv", "depth", "steps"),
        check=relief_check(s),
        part="relief mapping",
        points=points,
        hint=hint,
        visibility=visibility,
    )


MARCH_HINT = "d_i = i / n (n = floor(min + (max - min)(1 - view_z) + 1/2)); stop at the first d_i - (1 - h(uv - d_i scale view_xy / view_z)) >= 0"

CASES = [
    # ----------------------------------------------------------------------- task 1: bump mapping
    Case(
        id="bump-offset-bumps",
        function="bump_offset",
        inputs=lambda: {"height": smooth_bumps(32), "uv": pixel_uv(24)},
        params={"strength": 0.05},
        outputs=("offset",),
        check=PixelsClose("offset", 1e-9),
        part="bump mapping",
        points=1,
        hint="(du, dv) = strength ((h(u + 1/s, v) - h(u - 1/s, v)) s / 2, (h(u, v + 1/s) - h(u, v - 1/s)) s / 2), h read with height_at",
    ),
    Case(
        id="bump-normal-steps",
        function="bump_normal",
        inputs=lambda: {"height": steps_map(32), "uv": pixel_uv(24)},
        params={"strength": 0.02},
        outputs=("n",),
        check=PixelsClose("n", 1e-9),
        part="bump mapping",
        points=1,
        hint="n = normalize(-du, -dv, 1) with (du, dv) from bump_offset",
    ),
    # ----------------------------------------------------------------------- task 2: parallax
    Case(
        id="parallax-bumps-45",
        function="parallax_uv",
        inputs=relief_inputs("bumps", 45),
        params={"scale": SCALE},
        outputs=("uv",),
        check=PixelsClose("uv", 1e-9, texels=64),
        part="parallax",
        points=1,
        hint="uv' = uv + (scale h(uv) + bias) view_xy / view_z with bias = -scale",
    ),
    Case(
        id="parallax-limited-perspective",
        function="parallax_uv",
        inputs=relief_inputs("steps", "perspective"),
        params={"scale": SCALE, "offset_limit": True},
        outputs=("uv",),
        check=PixelsClose("uv", 1e-9, texels=64),
        part="parallax",
        points=1,
        hint="offset limiting drops the division by view_z: uv' = uv + (scale h + bias) view_xy",
    ),
    # ----------------------------------------------------------------------- task 3: relief mapping
    relief_case("relief-none-bumps-60", "bumps", 60, "none", 1, MARCH_HINT),
    relief_case(
        "relief-linear-steps-perspective",
        "steps",
        "perspective",
        "linear",
        1,
        "linear: d = a + (b - a) f_a / (f_a - f_b) between the last layer above (a) and the first below (b)",
    ),
    relief_case(
        "relief-secant-bumps-70",
        "bumps",
        70,
        "secant",
        1,
        "secant: x2 = x1 - f1 (x1 - x0) / (f1 - f0), clamped to [a, b], from (x0, x1) = (a, b); keep x1 when f1 = f0",
    ),
    relief_case(
        "relief-binary-steps-60",
        "steps",
        60,
        "binary",
        1,
        "binary: mid = (lo + hi) / 2; f(mid) >= 0 -> hi = mid else lo = mid; d = (lo + hi) / 2 at the end",
    ),
    # ----------------------------------------------------------------------- task 4: self-shadowing
    Case(
        id="shadow-bumps-70",
        function="relief_shadow",
        inputs=shadow_inputs("bumps", 70),
        params={"scale": SCALE},
        outputs=("visibility",),
        check=PixelsClose("visibility", 0, 0.995),
        part="self-shadowing",
        points=1,
        hint="d_k = depth (1 - k / layers), uv_k = uv + (depth - d_k) light_xy / light_z for k = 1..layers; shadow if d_k > scale (1 - h(uv_k))",
    ),
    # ----------------------------------------------------------------------- task 5: silhouettes
    Case(
        id="silhouette-random",
        function="inside_texture",
        inputs=lambda: {"uv": np.random.default_rng(4).uniform(-0.3, 1.3, (16, 16, 2))},
        outputs=("keep",),
        check=PixelsClose("keep", 0),
        part="silhouettes",
        points=1,
        hint="keep a fragment only where 0 <= u <= 1 and 0 <= v <= 1",
    ),
]
