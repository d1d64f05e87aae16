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
from geomlib.labfigures import (
    Claims,
    Drawn,
    MeshView,
    MissingTasks,
    figure_name,
    lab_figure_makers,
    missing_panel,
    partial_figure,
)
from geomlib.plot import Figure, colorbar, heatmap_image, line_plot, panels, save_png
from geomlib.raster import rasterize

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
_MISSING = MissingTasks()

LAB = "relief"
SCALE = 0.08
LIGHT = np.array([-0.55, 0.45, 0.7])  # tangent space = world: towards the light, up-left
BACKGROUND = 0.93
ZOOM = 3  # magnification of the methods figures' close-up
LAYERS = (8, 32)  # min and max layers of the march in the steps figure (relief_uv's defaults)


def quad_gbuffer(size: int, eye=(0.5, -0.55, 0.75)):
    """The unit quad z = 0 seen from ``eye``: per-pixel mask, uv and tangent-space view vectors."""
    V, F, UV = datasets.uv_grid(1)
    eye = np.asarray(eye, float)
    M = camera.perspective_look_at(eye, (0.5, 0.45, 0.0), (0, 0, 1), 42, 1.0, 0.1, 10.0)
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
    return missing_panel(size, size) / 255.0


def _try(fn, size):
    """``(fn(), None)``, or ``(None, note)`` when ``fn`` needs a task not implemented yet (noted in _MISSING)."""
    out = _MISSING.attempt(fn)
    return (out, None) if out is not None else (None, f" (not implemented yet: Task {_MISSING[-1]})")


def _method_panels(H, kind, size, dropped: dict):
    """The method panels, their labels and, per panel, the "not implemented yet" note of a panel left out
    (else None); ``dropped`` receives where the discard pass cut (pixel counts)."""
    mask, uv, view, _, _ = quad_gbuffer(size)
    m = mask
    up = np.zeros_like(view)
    up[..., 2] = 1.0
    imgs, caps, notes = [], [], []

    def add(label, make):
        out, note = _try(make, size)
        imgs.append(out if out is not None else _missing(size))
        caps.append(label + (note or ""))
        notes.append(note)

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
        out = hit[m & ~keep]
        rows = np.nonzero(m & ~keep)[0]
        quad_rows = np.nonzero(m.any(axis=1))[0]
        dropped.update(
            dropped=len(out), far=int((out[:, 1] > 1).sum()), near=int((out[:, 1] < 0).sum()),
            left=int((out[:, 0] < 0).sum()), right=int((out[:, 0] > 1).sum()),
            # how far down the quad's image the cut reaches: 0 = its far (top) edge, 100 = its near edge
            reach=float(100 * (rows.max() - quad_rows.min()) / max(quad_rows.max() - quad_rows.min(), 1)) if len(rows) else 0.0,
        )  # fmt: skip
        return shade(H, kind, keep, hit, bump_normal(H, hit, strength=SCALE), vis)

    add(f"POM ({'binary' if kind == 'bricks' else 'secant'}) + self-shadow, uv outside [0, 1] discarded", pom_shadow)
    truth, _ = exact_uv(H, uv, view, scale=SCALE, samples=1024)
    add("exact ray / height-field hit", lambda: shifted(truth))
    add("true displaced geometry (rasterized grid)", lambda: _displaced(H, kind, size))
    return imgs, caps, notes


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
        dropped: dict = {}
        imgs, caps, notes = _method_panels(H, kind, size, dropped)
        mask, _, view, _, _ = quad_gbuffer(size)
        deg = np.degrees(np.arccos(view[mask][:, 2]))
        # A close-up of the far, grazing edge, where the methods differ most: steep parallax over POM (secant).
        rows = np.nonzero(mask.any(axis=1))[0]
        r0, h, c0, w = rows.min() + 2, size // 7, size // 3, size // 3
        shown = (4, 6)
        note = next((notes[i] for i in shown if notes[i]), None)  # a crop of a stand-in panel would be blank
        if note:
            imgs.append(missing_panel((2 * h + 4) * ZOOM, w * ZOOM) / 255.0)
        else:
            crops = [np.asarray(imgs[i], float)[r0 : r0 + h, c0 : c0 + w] for i in shown]
            gap = np.ones((4, w, 3))
            imgs.append(np.repeat(np.repeat(np.vstack([crops[0], gap, crops[1]]), ZOOM, 0), ZOOM, 1))
        caps.append(
            f"x{ZOOM} close-up of the far edge: steep (top, one band per layer) and POM secant (bottom)" + (note or "")
        )
        img = panels(
            imgs,
            caps,
            ncols=4,
            title=f"{kind}: from flat to the true relief (scale {SCALE}, seen at {deg.min():.0f}-{deg.max():.0f} degrees)",
        )
        template = (
            f"The {kind} height map on one quad, scale {{scale}}: flat and bump shading keep the texture in place; "
            "parallax shifts it once (far too much at grazing angles), offset limiting caps the shift; steep "
            "parallax steps through layers (bands, one per layer: see the close-up of the far edge, last panel), "
            "POM refines the "
            "hit (linear, secant, binary); self-shadowing darkens what the relief hides from the light."
        )
        if dropped:
            template += (
                " Discarding uv outside [0, 1] carves the FAR edge and the far halves of the sides, where the "
                "ray, going down and away from the eye, leaves the texture: of the {dropped} pixels dropped, "
                "{far} left through the far edge (v > 1), {left} and {right} through the sides, {near} through "
                "the near edge; none lies beyond {reach:.0f}% of the way down the quad's image."
            )
        template += " The last two panels are the exact intersection and a rasterized displaced grid."
        claims = Claims(template, {"scale": SCALE, **dropped})
        figs.append(Figure(save_png(out / f"methods_{kind}.png", img), claims.caption(), LAB, claims))
    return figs


@figure_name("uv_error")
def _fig_errors(out: Path, quick: bool) -> Drawn:
    size = 96 if quick else 200
    H = bricks(256)
    mask, uv, view, _, _ = quad_gbuffer(size)
    truth, _ = exact_uv(H, uv, view, scale=SCALE, samples=1024)
    rows, caps = [], []
    lo, hi = -3.0, 2.0  # log10 of the error in texels: 0.001 to 100
    EXACT = 0.01  # texels: below this a pixel counts as exact
    exact, p99 = {}, {}
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
        key = label.split()[-1]
        exact[key] = float(100 * np.mean(e[mask] < EXACT))
        p99[key] = float(np.nanpercentile(e, 99))
        rows.append(heatmap_image(np.clip(np.log10(np.maximum(e, 1e-12)), lo, hi), vmin=lo, vmax=hi))
        caps.append(f"{label}: p99 {p99[key]:.3g} texels,\nexact (< {EXACT}) on {exact[key]:.0f}% of pixels")
    rows.append(colorbar(lo, hi, "inferno", label="log10 uv error (texels)"))
    caps.append("")
    img = panels(rows, caps, ncols=3, title="uv error against the exact hit, bricks (256^2 map)")
    if "parallax" not in exact or "steep" not in exact:
        return Drawn(img, "Per-pixel distance (in texels, log scale) between each method's uv and the exact hit.")
    tops = float(100 * np.mean(height_at(H, uv[mask][:, 0], uv[mask][:, 1]) >= 1.0))
    return Drawn.claimed(
        img,
        "Per-pixel distance (in texels, log scale) between each method's uv and the exact ray / height-field hit "
        "on the bricks. Parallax is exact (under {exact_below} texel) on {parallax_exact:.0f}% of the pixels: the flat brick "
        "tops ({tops:.0f}% of the pixels see h = 1 at their entry point), where h = 1 means no shift at all; its "
        "error lives in the joints and bevels, where it reaches {parallax_p99:.3g} texels (p99) against "
        "{steep_p99:.3g} for steep parallax (at most a layer). Linear POM errs along the bevels; after secant or "
        "binary refinement only isolated pixels on the bevels stay off (the secant step can stall on a bevel's "
        "kink; bisection cannot).",
        exact_below=EXACT, parallax_exact=exact["parallax"], tops=tops, parallax_p99=p99["parallax"], steep_p99=p99["steep"],
    )  # fmt: skip


@figure_name("error_vs_angle")
def _fig_error_vs_angle(out: Path, quick: bool) -> Drawn:
    p = 48 if quick else 128
    t = (np.arange(p) + 0.5) / p
    uv = np.stack(np.meshgrid(t, t[::-1]), axis=-1)
    angles = np.array([15, 30, 45, 60, 75, 80] if not quick else [30, 60, 75])
    methods = ("parallax", "offset-limited", *REFINEMENTS)
    curves: dict = {}
    for kind, H in (("bumps", bumps(256)), ("bricks", bricks(256))):
        for deg in angles:
            a = np.radians(deg)
            V = np.array([np.sin(a) * np.cos(0.3), np.sin(a) * np.sin(0.3), np.cos(a)])
            truth, _ = exact_uv(H, uv, V, scale=SCALE)
            for m in methods:
                if m in ("parallax", "offset-limited"):
                    got = _MISSING.attempt(parallax_uv, H, uv, V, scale=SCALE, offset_limit=m == "offset-limited")
                else:
                    got = _MISSING.attempt(relief_uv, H, uv, V, scale=SCALE, refine=m)
                    got = None if got is None else got[0]
                if got is not None:
                    e = np.percentile(uv_error_texels(got, truth, 256), 99)
                    curves.setdefault(kind, {}).setdefault(m, []).append(max(e, 1e-6))
    plots = []
    for kind in ("bumps", "bricks"):
        done = {m: c for m, c in curves.get(kind, {}).items() if len(c) == len(angles)}
        if not done:
            plots.append(_missing(200))
            continue
        # every method in every panel, in the same order: the same colour and marker on both maps
        plots.append(
            line_plot(
                [angles] * len(done), list(done.values()), [{"none": "steep (none)"}.get(m, m) for m in done],
                xlabel="view angle from the normal (degrees)", ylabel="p99 uv error (texels, floor 1e-6)",
                title=f"{kind}", logy=True, size=(560, 520),
            )
        )  # fmt: skip
    img = panels(plots, None, title=f"Error against the exact hit vs view angle (scale {SCALE}, 256^2 maps)")
    sec = {k: curves.get(k, {}).get("secant") for k in ("bumps", "bricks")}
    if sec["bumps"] is None or sec["bricks"] is None or "offset-limited" not in curves.get("bricks", {}):
        return Drawn(img, "p99 uv error (log scale) of each method against the exact intersection as the view tilts.")
    i75 = int(np.argmax(angles >= 75))
    return Drawn.claimed(
        img,
        "p99 uv error (log scale) of each method against the exact intersection as the view tilts, on a "
        "{pixels} x {pixels} grid of pixels (the handout's table, from bench/relief.py, samples a finer grid, so "
        "single stalled pixels move its p99 differently). The errors grow with the angle. On the smooth bumps secant "
        "refinement is the most accurate: at most {sec_bumps:.1g} texels up to {max_deg} degrees; on the bricks' "
        "sharp steps it can stall on a bevel ({sec_bricks:.2g} texels at {deg75} degrees) and binary search is "
        "the more reliable refinement. Offset limiting is not a more accurate parallax: on the bumps it is "
        "further off than plain parallax at {deg75} degrees ({ol_bumps:.3g} vs {px_bumps:.3g} texels); on the "
        "bricks it is closer there ({ol_bricks:.3g} vs {px_bricks:.3g}) only because the plain shift overshoots "
        "by even more.",
        pixels=p, sec_bumps=max(sec["bumps"]), max_deg=int(angles.max()), sec_bricks=sec["bricks"][i75],
        deg75=int(angles[i75]), ol_bumps=curves["bumps"]["offset-limited"][i75],
        px_bumps=curves["bumps"]["parallax"][i75], ol_bricks=curves["bricks"]["offset-limited"][i75],
        px_bricks=curves["bricks"]["parallax"][i75],
    )  # fmt: skip


@figure_name("steps")
def _fig_steps(out: Path, quick: bool) -> Drawn:
    size = 120 if quick else 220
    H = bricks(256)
    mask, uv, view, _, _ = quad_gbuffer(size)
    marched = _MISSING.attempt(
        relief_uv, H, uv, view, scale=SCALE, refine="none", min_layers=LAYERS[0], max_layers=LAYERS[1]
    )
    if marched is None:
        img = panels([_missing(size)], ["relief_uv: not implemented yet"])
    else:
        from .relief import layer_count

        steps = marched[2]
        n = layer_count(view[..., 2], *LAYERS).astype(float)
        n[~mask] = np.nan
        st = steps.astype(float)
        st[~mask] = np.nan
        lo, hi = int(np.nanmin(n)), int(np.nanmax(n))

        def with_bar(img, vmin, vmax, label):  # each panel its own bar, right next to it
            bar = colorbar(
                vmin,
                vmax,
                "viridis",
                label=label,
                height=img.shape[0],
                ticks=vmax - vmin + 1 if vmax - vmin <= 8 else 5,
            )
            return np.hstack([img, np.full((img.shape[0], 8, 3), 255, np.uint8), bar])

        img = panels(
            [
                with_bar(heatmap_image(n, "viridis", *LAYERS), *LAYERS, "n (layers)"),
                with_bar(heatmap_image(st, "viridis", 0, LAYERS[1]), 0, LAYERS[1], "layer of the hit"),
            ],
            ["layer count n (more at grazing angles)", "layers marched to the hit"],
            title="Layers of the march (bricks)",
        )  # fmt: skip
        return Drawn.claimed(
            img,
            "Left: the layer count n = floor(min + (max - min)(1 - view_z) + 1/2) per pixel, with min = {min_layers} "
            "and max = {max_layers} layers, grows from {lo} at the near edge to {hi} towards the far, grazing part of "
            "the quad (colour bar {min_layers}-{max_layers}). Right: the layer where the march stopped (colour bar "
            "from zero to {max_layers}); the deep mortar joints take the most layers.",
            min_layers=LAYERS[0],
            max_layers=LAYERS[1],
            lo=lo,
            hi=hi,
        )
    return Drawn(img, "The layer count per pixel and the layer where the march stopped.")


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
    M = camera.perspective_look_at(_ARC_EYE, (0.0, 0.0, 0.3), (0, 0, 1), 30, 1.0, 0.1, 10.0)
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
    bumped, bump_note = _try(lambda: bump_normal(H, true_uv, strength=strength), size)
    true_img = _arc_shade(H, true_mask, true_uv, up if bumped is None else bumped)
    # Outline comparison: grey where both cover the pixel, red where only POM does (the notches the
    # real relief cuts into the outline), blue where only the displaced mesh does.
    cmp = np.full((size, size, 3), BACKGROUND)
    cmp[pom_mask & true_mask] = (0.62, 0.62, 0.62)
    cmp[pom_mask & ~true_mask] = (0.85, 0.12, 0.10)
    cmp[~pom_mask & true_mask] = (0.15, 0.35, 0.85)
    only_pom = int((pom_mask & ~true_mask).sum())
    only_true = int((~pom_mask & true_mask).sum())
    outlines = f"outlines: both (grey), POM only (red, {only_pom} px), displaced only (blue, {only_true} px)"
    img = panels(
        [pom_img, true_img, cmp if note is None else _missing(size)],  # no POM outline to compare yet
        [
            "POM (secant) + discard, on the smooth half cylinder" + (note or ""),
            "true geometry: the cylinder displaced by the bumps" + (f", flat shaded{bump_note}" if bump_note else ""),
            outlines if note is None else "outlines of POM and of the displaced cylinder" + note,
        ],
        title="Silhouette on a curved mesh: relief mapping cannot change the outline",
    )
    template = (
        "Smooth bumps, up to {depth} deep, on a half cylinder of radius {radius} seen from the side: the far top "
        "edge is the silhouette. Relief mapping only moves the texture inside the triangles that are drawn, so its "
        "outline stays the straight top line of the cylinder, while the truly displaced surface dips between the "
        "bumps and its outline is wavy"
    )
    if note is not None:  # the pixel counts compare POM's outline, not drawn yet
        return Drawn.claimed(
            img, template + ". Shell mapping would give the relief a volume.", depth=_ARC_DEPTH, radius=_ARC_R
        )
    return Drawn.claimed(
        img,
        template + " (red, {only_pom} pixels: POM draws them, they are empty in reality). "
        "Discarding uv outside [0, 1] carves only at the patch's ends (blue, {only_true} pixels: the displaced "
        "surface is there, POM discarded them). Shell mapping would give the relief a volume.",
        depth=_ARC_DEPTH,
        radius=_ARC_R,
        only_pom=only_pom,
        only_true=only_true,
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
