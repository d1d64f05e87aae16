"""Figures of the lab "relief", rendered with the lab's own functions.

The imports are relative, so the same file copied next to a student's implementation
(``labs/relief/figures.py``) renders the student's results; a task not implemented yet shows as a
labelled grey panel. Every image is a NumPy "fragment shader" over geomlib's rasterizer G-buffer:
a quad (z = 0, tangent frame = the world axes) seen in perspective, each pixel's tangent-space
view vector ``normalize(eye - position)``, the method's uv, then Lambert shading with the bump
normal at that uv and, where asked, the relief's self-shadow. The true displaced geometry is a
dense grid displaced by the height field, rasterized the same way.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import camera, datasets
from geomlib.labfigures import Drawn, MeshView, figure_name, lab_figure_makers, partial_figure
from geomlib.plot import Figure, colorbar, heatmap_image, line_plot, panels, save_png
from geomlib.raster import rasterize
from geomlib.taskref import find_task

from .bump import bump_normal
from .heights import bricks, bumps
from .inputs import height_at
from .parallax import parallax_uv
from .relief import REFINEMENTS, relief_uv
from .shadow import relief_shadow
from .silhouette import inside_texture
from .truth import exact_uv, uv_error_texels

__all__ = ["make_figures", "make_view", "quad_gbuffer", "shade"]

#: Tasks whose panels the figure being drawn had to leave out (its caption then names the first).
_MISSING: list[str] = []

LAB = "relief"
SCALE = 0.08
LIGHT = np.array([-0.55, 0.45, 0.7])  # tangent space = world: towards the light, up-left
BACKGROUND = 0.93


def quad_gbuffer(size: int, eye=(0.5, -0.55, 0.75)):
    """The unit quad z = 0 seen from ``eye``: per-pixel mask, uv and tangent-space view vectors."""
    V, F, UV = datasets.uv_grid(1)
    eye = np.asarray(eye, float)
    M = camera.perspective(42, 1.0, 0.1, 10.0) @ camera.look_at(eye, (0.5, 0.45, 0.0), (0, 0, 1))
    g = rasterize(V, F, M, size, size, attributes={"position": V, "uv": UV})
    view = eye - g.attributes["position"]
    view /= np.maximum(np.linalg.norm(view, axis=-1, keepdims=True), 1e-12)
    view[~g.mask] = (0.0, 0.0, 1.0)
    return g.mask, g.attributes["uv"], view, M, eye


def albedo(H: np.ndarray, uv: np.ndarray, kind: str) -> np.ndarray:
    """Colour at uv: bricks red with grey mortar, bumps a warm sand; from the height (nearest texel)."""
    s = H.shape[0]
    c = np.clip((uv[..., 0] * s).astype(int), 0, s - 1)
    r = np.clip(((1 - uv[..., 1]) * s).astype(int), 0, s - 1)
    h = H[r, c][..., None]
    if kind == "bricks":
        return np.where(h > 0.6, [0.72, 0.33, 0.24], [0.62, 0.60, 0.56])
    return (0.55 + 0.35 * h) * np.array([0.92, 0.80, 0.60])


def shade(H, kind, mask, uv, normal, visibility=None) -> np.ndarray:
    """Lambert + ambient with the given tangent-space normals; background outside ``mask``."""
    ndl = np.clip(normal @ (LIGHT / np.linalg.norm(LIGHT)), 0, None)
    vis = 1.0 if visibility is None else visibility[..., None]
    img = albedo(H, uv, kind) * (0.25 + 0.75 * ndl[..., None] * vis)
    img[~mask] = BACKGROUND
    return np.clip(img, 0, 1)


def _missing(size: int) -> np.ndarray:
    return np.full((size, size, 3), 0.8)


def _try(fn, size):
    try:
        return fn(), None
    except NotImplementedError as e:
        task = find_task(str(e))
        _MISSING.append(task.label if task else "?")
        return None, f" (not implemented yet: {str(e).split(':')[0]})"


def _method_panels(H, kind, size):
    mask, uv, view, _, _ = quad_gbuffer(size)
    m = mask
    up = np.zeros_like(view)
    up[..., 2] = 1.0
    imgs, caps = [], []

    def add(label, make):
        out, note = _try(make, size)
        imgs.append(out if out is not None else _missing(size))
        caps.append(label + (note or ""))

    add("flat", lambda: shade(H, kind, m, uv, up))
    add("bump (Blinn)", lambda: shade(H, kind, m, uv, bump_normal(H, uv, strength=SCALE)))

    def shifted(uv2):
        return shade(H, kind, m, uv2, bump_normal(H, uv2, strength=SCALE))

    add("parallax", lambda: shifted(parallax_uv(H, uv, view, scale=SCALE)))
    add("offset-limited", lambda: shifted(parallax_uv(H, uv, view, scale=SCALE, offset_limit=True)))
    add("steep (no refinement)", lambda: shifted(relief_uv(H, uv, view, scale=SCALE, refine="none")[0]))
    for r in ("linear", "secant", "binary"):
        add(f"POM, {r}", lambda r=r: shifted(relief_uv(H, uv, view, scale=SCALE, refine=r)[0]))

    def pom_shadow():
        # The refinement that suits the map: secant on smooth bumps, bisection on the bricks' steps. A hit left
        # slightly under the surface (bisection's half interval) would shadow itself (acne).
        refine = "binary" if kind == "bricks" else "secant"
        hit, depth, _ = relief_uv(H, uv, view, scale=SCALE, refine=refine)
        vis = relief_shadow(H, hit, depth, LIGHT, scale=SCALE)
        keep = m & inside_texture(hit)
        return shade(H, kind, keep, hit, bump_normal(H, hit, strength=SCALE), vis)

    add(f"POM ({'binary' if kind == 'bricks' else 'secant'}) + self-shadow, uv outside [0, 1] discarded", pom_shadow)
    truth, _ = exact_uv(H, uv, view, scale=SCALE, samples=1024)
    add("exact ray / height-field hit", lambda: shifted(truth))
    add("true displaced geometry (rasterized grid)", lambda: _displaced(H, kind, size))
    return imgs, caps


def _displaced(H, kind, size):
    """A grid displaced by the height field (z = -scale (1 - h)), rasterized from the same camera."""
    s = H.shape[0]
    n = min(s, 128)
    Vg, F = datasets.grid_patch(n - 1)
    V = Vg.copy()
    V[:, :2] = Vg[:, :2] * (n - 1) / n + 0.5 / n
    r = np.clip(((1 - V[:, 1]) * s).astype(int), 0, s - 1)
    c = np.clip((V[:, 0] * s).astype(int), 0, s - 1)
    V[:, 2] = -SCALE * (1 - H[r, c])
    _, _, _, M, _ = quad_gbuffer(size)
    g = rasterize(V, F, M, size, size, attributes={"uv": V[:, :2]})
    uv = g.attributes["uv"]
    return shade(H, kind, g.mask, uv, bump_normal(H, uv, strength=SCALE))


@figure_name("methods_bumps")
def _fig_methods(out: Path, quick: bool) -> list[Figure]:
    size = 120 if quick else 220
    figs = []
    for kind, H in (("bricks", bricks(128 if quick else 256)), ("bumps", bumps(128 if quick else 256))):
        imgs, caps = _method_panels(H, kind, size)
        mask, _, view, _, _ = quad_gbuffer(size)
        deg = np.degrees(np.arccos(view[mask][:, 2]))
        img = panels(
            imgs,
            caps,
            ncols=4,
            title=f"{kind}: from flat to the true relief (scale {SCALE}, seen at {deg.min():.0f}-{deg.max():.0f} degrees)",
        )
        figs.append(
            Figure(
                save_png(out / f"methods_{kind}.png", img),
                f"The {kind} height map on one quad: flat and bump shading keep the texture in place; parallax shifts "
                f"it once (far too much at grazing angles), offset limiting caps the shift; steep parallax steps "
                f"through layers (visible bands), POM refines the hit (linear, secant, binary); self-shadowing darkens "
                f"what the relief hides from the light, and discarding uv outside [0, 1] carves the near edge. The last "
                f"two panels are the exact intersection and a rasterized displaced grid.",
                LAB,
            )
        )
    return figs


@figure_name("uv_error")
def _fig_errors(out: Path, quick: bool) -> Drawn:
    size = 96 if quick else 200
    H = bricks(256)
    mask, uv, view, _, _ = quad_gbuffer(size)
    truth, _ = exact_uv(H, uv, view, scale=SCALE, samples=1024)
    rows, caps = [], []
    vmax = 2.0
    for label, fn in (
        ("parallax", lambda: parallax_uv(H, uv, view, scale=SCALE)),
        ("steep", lambda: relief_uv(H, uv, view, scale=SCALE, refine="none")[0]),
        ("POM linear", lambda: relief_uv(H, uv, view, scale=SCALE, refine="linear")[0]),
        ("POM secant", lambda: relief_uv(H, uv, view, scale=SCALE, refine="secant")[0]),
        ("POM binary", lambda: relief_uv(H, uv, view, scale=SCALE, refine="binary")[0]),
    ):
        got, note = _try(fn, size)
        if got is None:
            rows.append(_missing(size))
            caps.append(label + note)
            continue
        e = uv_error_texels(got, truth, 256)
        e[~mask] = np.nan
        rows.append(heatmap_image(np.minimum(e, vmax), vmin=0, vmax=vmax))
        caps.append(f"{label}: p99 {np.nanpercentile(e, 99):.3g} texels")
    rows.append(colorbar(0, vmax, "inferno", label="uv error (texels, clipped at 2)"))
    caps.append("")
    img = panels(rows, caps, ncols=3, title="uv error against the exact intersection, bricks (256 x 256 map)")
    return Drawn(
        img,
        "Per-pixel distance (in texels) between each method's uv and the exact ray / height-field hit on the bricks. "
        "Parallax is off by many texels everywhere but straight down; steep parallax by up to a layer; linear POM "
        "errs along the bevels; after secant or binary refinement only isolated pixels on the bevels stay off "
        "(the secant step can stall on a bevel's kink; bisection cannot).",
    )


@figure_name("error_vs_angle")
def _fig_error_vs_angle(out: Path, quick: bool) -> Drawn:
    p = 48 if quick else 128
    t = (np.arange(p) + 0.5) / p
    uv = np.stack(np.meshgrid(t, t[::-1]), axis=-1)
    angles = np.array([15, 30, 45, 60, 75, 80] if not quick else [30, 60, 75])
    curves = {}
    for kind, H in (("bumps", bumps(256)), ("bricks", bricks(256))):
        for deg in angles:
            a = np.radians(deg)
            V = np.array([np.sin(a) * np.cos(0.3), np.sin(a) * np.sin(0.3), np.cos(a)])
            truth, _ = exact_uv(H, uv, V, scale=SCALE)
            for m in ("parallax", *REFINEMENTS):
                try:
                    got = (
                        parallax_uv(H, uv, V, scale=SCALE)
                        if m == "parallax"
                        else relief_uv(H, uv, V, scale=SCALE, refine=m)[0]
                    )
                except NotImplementedError as e:
                    task = find_task(str(e))
                    _MISSING.append(task.label if task else "?")
                    continue
                e = np.percentile(uv_error_texels(got, truth, 256), 99)
                curves.setdefault(f"{m} ({kind})", []).append(max(e, 1e-6))
    names = [k for k in curves if len(curves[k]) == len(angles)]
    if not names:
        img = panels([_missing(200)], ["not implemented yet"])
    else:
        img = line_plot(
            [angles] * len(names),
            [curves[k] for k in names],
            names,
            xlabel="view angle from the normal (degrees)",
            ylabel="p99 uv error (texels, floor 1e-6)",
            title="Error against the exact hit vs view angle (scale 0.08, 256 x 256 maps)",
            logy=True,
            size=(900, 560),
        )
    return Drawn(
        img,
        "p99 uv error (log scale) of each method against the exact intersection as the view tilts. Every error grows "
        "with the angle; on the smooth bumps the secant refinement is exact to round-off, on the bricks' sharp steps "
        "it is not and binary search is the more reliable refinement.",
    )


@figure_name("steps")
def _fig_steps(out: Path, quick: bool) -> Drawn:
    size = 120 if quick else 220
    H = bricks(256)
    mask, uv, view, _, _ = quad_gbuffer(size)
    try:
        _, _, steps = relief_uv(H, uv, view, scale=SCALE, refine="none")
    except NotImplementedError as e:
        task = find_task(str(e))
        _MISSING.append(task.label if task else "?")
        img = panels([_missing(size)], ["relief_uv: not implemented yet"])
    else:
        from .relief import layer_count

        n = layer_count(view[..., 2], 8, 32).astype(float)
        n[~mask] = np.nan
        st = steps.astype(float)
        st[~mask] = np.nan
        img = panels(
            [
                heatmap_image(n, "viridis", 8, 32),
                heatmap_image(st, "viridis", 0, 32),
                colorbar(0, 32, "viridis", label="layers"),
            ],
            ["layer count n (more at grazing angles)", "layers marched to the hit", ""],
            title="Layers of the march (bricks)",
        )
    return Drawn(
        img,
        "Left: the layer count n = floor(8 + 24 (1 - view_z) + 1/2) per pixel grows towards the far, grazing part "
        "of the quad. Right: the layer where the march stopped; the deep mortar joints take the most layers.",
    )


# The curved mesh of the silhouette figure: half a cylinder of radius R around the y axis, length W,
# textured once. u runs around the arc (u = 0 at -x, 1/2 on top, 1 at +x), v along the axis; the
# frame (dP/du, dP/dv, outward normal) is right-handed like the quad's (x, y, z).
_ARC_R, _ARC_W, _ARC_DEPTH = 0.5, 1.6, 0.08
_ARC_EYE = np.array([3.0, -1.2, 1.2])
_ARC_LIGHT = np.array([0.7, -0.5, 0.6]) / np.linalg.norm([0.7, -0.5, 0.6])


def _arc(uv, depth=None):
    """Positions, unit tangent, bitangent and normal (each (..., 3)) of the half cylinder at ``uv``,
    the positions moved ``depth`` (...) inward along the normal."""
    t = np.pi * (1.0 - uv[..., 0])
    zero, one = np.zeros_like(t), np.ones_like(t)
    N = np.stack([np.cos(t), zero, np.sin(t)], axis=-1)
    T = np.stack([np.sin(t), zero, -np.cos(t)], axis=-1)  # dP/du / (pi R)
    B = np.stack([zero, one, zero], axis=-1)  # dP/dv / W
    P = np.stack([_ARC_R * np.cos(t), _ARC_W * (uv[..., 1] - 0.5), _ARC_R * np.sin(t)], axis=-1)
    if depth is not None:
        P = P - depth[..., None] * N
    return P, T, B, N


def _arc_render(size, cells, depth=None):
    """Rasterize the half cylinder (displaced by ``depth(uv)`` when given) from ``_ARC_EYE``: mask and uv."""
    Vg, F = datasets.grid_patch(cells)
    uv = Vg[:, :2]
    P, *_ = _arc(uv, None if depth is None else depth(uv))
    M = camera.perspective(30, 1.0, 0.1, 10.0) @ camera.look_at(_ARC_EYE, (0.0, 0.0, 0.3), (0, 0, 1))
    g = rasterize(P, F, M, size, size, attributes={"uv": uv})
    return g.mask, g.attributes["uv"]


def _arc_shade(H, mask, uv, normal_ts):
    """Lambert + ambient with tangent-space normals turned into world space on the cylinder."""
    _, T, B, N = _arc(uv)
    n = T * normal_ts[..., :1] + B * normal_ts[..., 1:2] + N * normal_ts[..., 2:]
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
    img = albedo(H, uv, "bumps") * (0.25 + 0.75 * np.clip(n @ _ARC_LIGHT, 0, None)[..., None])
    img[~mask] = BACKGROUND
    return np.clip(img, 0, 1)


@figure_name("silhouette")
def _fig_silhouette(out: Path, quick: bool) -> Drawn:
    size = 160 if quick else 300
    H = bumps(128 if quick else 256)
    mask, uv = _arc_render(size, 64)
    P, T, B, N = _arc(uv)
    v = _ARC_EYE - P
    # The tangent-space view in uv units: a step of 1 in u is pi R long on the surface, in v it is W
    # long; the depth stays in world units, so relief_uv's shift scale * d * view_xy / view_z is in uv.
    view = np.stack(
        [(T * v).sum(-1) / (np.pi * _ARC_R), (B * v).sum(-1) / _ARC_W, np.maximum((N * v).sum(-1), 1e-4)], axis=-1
    )
    view /= np.linalg.norm(view, axis=-1, keepdims=True)
    view[~mask] = (0.0, 0.0, 1.0)
    strength = _ARC_DEPTH / (np.pi * _ARC_R)  # the bump's slope per unit of u, in world units (u is pi R long)

    def pom():
        hit, _, _ = relief_uv(H, uv, view, scale=_ARC_DEPTH, refine="secant")
        keep = mask & inside_texture(hit)
        return _arc_shade(H, keep, hit, bump_normal(H, hit, strength=strength)), keep

    made, note = _try(pom, size)
    pom_img, pom_mask = made if made is not None else (_missing(size), mask)
    true_mask, true_uv = _arc_render(
        size, 96 if quick else 200, depth=lambda q: _ARC_DEPTH * (1 - height_at(H, q[:, 0], q[:, 1]))
    )
    up = np.zeros(true_uv.shape[:2] + (3,))
    up[..., 2] = 1.0
    bumped, _ = _try(lambda: bump_normal(H, true_uv, strength=strength), size)
    true_img = _arc_shade(H, true_mask, true_uv, up if bumped is None else bumped)
    # Outline comparison: grey where both cover the pixel, red where only POM does (the notches the
    # real relief cuts into the outline), blue where only the displaced mesh does.
    cmp = np.full((size, size, 3), BACKGROUND)
    cmp[pom_mask & true_mask] = (0.62, 0.62, 0.62)
    cmp[pom_mask & ~true_mask] = (0.85, 0.12, 0.10)
    cmp[~pom_mask & true_mask] = (0.15, 0.35, 0.85)
    only_pom = int((pom_mask & ~true_mask).sum())
    only_true = int((~pom_mask & true_mask).sum())
    img = panels(
        [pom_img, true_img, cmp],
        [
            "POM (secant) + discard, on the smooth half cylinder" + (note or ""),
            "true geometry: the cylinder displaced by the bumps",
            f"outlines: both (grey), POM only (red, {only_pom} px), displaced only (blue, {only_true} px)",
        ],
        title="Silhouette on a curved mesh: relief mapping cannot change the outline",
    )
    return Drawn(
        img,
        "Smooth bumps, up to 0.08 deep, on a half cylinder of radius 0.5 seen from the side: the far top edge is "
        "the silhouette. Relief mapping only moves the texture inside the triangles that are drawn, so its "
        "outline stays the straight top line of the cylinder, while the truly displaced surface dips between the "
        "bumps and its outline is wavy (red: pixels POM draws that are empty in reality). Discarding uv outside "
        "[0, 1] carves only at the patch's ends (blue: the displaced surface is there, POM discarded the pixels). "
        "Shell mapping would give the relief a volume.",
    )


@figure_name("relief_3d")
def fig_view(quick: bool) -> MeshView:
    H = bricks(64 if quick else 128)
    s = H.shape[0]
    Vg, F = datasets.grid_patch(s - 1)
    V = Vg.copy()
    V[:, :2] = Vg[:, :2] * (s - 1) / s + 0.5 / s
    r = np.clip(((1 - V[:, 1]) * s).astype(int), 0, s - 1)
    c = np.clip((V[:, 0] * s).astype(int), 0, s - 1)
    V[:, 2] = -SCALE * (1 - H[r, c])  # the relief lies below the polygon
    n = bump_normal(H, V[:, :2], strength=SCALE)
    tilt = np.degrees(np.arccos(np.clip(n[:, 2] / np.linalg.norm(n, axis=1), -1, 1)))
    return MeshView(
        V, F, tilt, title="Bricks as real geometry", up="z",
        cmap="viridis", scalar_name="bump-normal tilt (degrees)",
        caption="Turn it: the bricks as real geometry (a grid moved down by scale · (1 − h)), each vertex coloured "
        "by how far the bump-mapped normal (Task 1) tilts from the quad's. Parallax and relief mapping imitate "
        "this relief on one flat quad; seen edge-on, that quad's silhouette stays a straight line.",
    )  # fmt: skip


#: The figures in order; one drawn without some of its panels names the missing task in its caption.
FIGURES = [
    partial_figure(build, _MISSING)
    for build in (_fig_methods, _fig_errors, _fig_error_vs_angle, _fig_steps, _fig_silhouette)
]

make_figures, make_view = lab_figure_makers(
    LAB, __name__, FIGURES, fig_view, draws_lab=False, quick="Smaller images (for the notebook and tests)."
)
