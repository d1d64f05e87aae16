"""Figures of the signed-distance lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The file
is copied into ``labs/sdf/`` with the stubs, so there it draws *your* results once your functions
work (a figure whose tasks are missing is replaced by a panel naming them); compare with
``docs/figures/sdf/``. Numbers in the captions and panel labels are measured when the figure is made.
Images are sphere-traced by :func:`render_sdf` (the lab's own tracer); the hit mask is compared with
geomlib's rasterizer.

Longer than most modules (about 650 lines): one builder per figure of the handout, each with the
measurements its caption quotes; they share the scene set-up at the top.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import camera, datasets, raster
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
from geomlib.plot import colorbar, heatmap_image, line_plot, panels

from .analytic import op_difference, op_union, sd_box, sd_capsule, sd_plane, sd_sphere, sd_torus, smooth_union
from .bricks import EMPTY_INSIDE, EMPTY_OUTSIDE, compress_bricks
from .field import SDFGrid, grid_points
from .gradient import gradient_central, gradient_tetra
from .mesh_sdf import sdf_grid
from .shadow import ambient_occlusion, push_out, soft_shadow
from .trace import render_sdf
from .truth import mesh_visibility

LAB = "sdf"
GAP = 8


def _u8(img):
    return np.round(np.clip(img, 0, 1) * 255).astype(np.uint8)


def _missing(size, what: str, error: BaseException | None = None) -> np.ndarray:
    """A grey panel standing in for a picture whose tasks are not implemented yet (noted in _MISSING)."""
    if error is not None:
        _MISSING.attempt(_raise, error)
    return missing_panel(max(size[0], 160), max(size[1], 260), f"not implemented yet:\n{what}")


def _raise(error):
    raise error


def _with_bar(img, lo, hi, cmap, label):
    bar = colorbar(lo, hi, cmap, label=label, height=img.shape[0])
    return np.hstack([img, np.full((img.shape[0], GAP, 3), 255, np.uint8), bar])


def _up(img, k):
    return np.repeat(np.repeat(img, k, 0), k, 1)


def _contours(values2d, step):
    """Pixels where the field crosses a multiple of ``step`` (iso-lines), and the zero crossing."""
    k = np.floor(values2d / step)
    line = np.zeros(values2d.shape, bool)
    line[:-1] |= k[:-1] != k[1:]
    line[:, :-1] |= k[:, :-1] != k[:, 1:]
    s = values2d < 0
    zero = np.zeros(values2d.shape, bool)
    zero[:-1] |= s[:-1] != s[1:]
    zero[:, :-1] |= s[:, :-1] != s[:, 1:]
    return line, zero


def _slice_image(values2d, r, step, scale=3):
    """A diverging heat map of a slice (rows = +y down) with iso-lines every ``step`` and the zero line in black."""
    img = heatmap_image(np.clip(values2d, -r, r).T[::-1], "RdBu", -r, r)
    line, zero = _contours(values2d, step)
    img[line.T[::-1]] = (img[line.T[::-1]] * 0.55).astype(np.uint8)
    img[zero.T[::-1]] = 0
    return np.repeat(np.repeat(img, scale, 0), scale, 1)


# ----------------------------------------------------------------------------------- scenes


#: The scene's two CSG results: a box (centre, half size) minus a sphere (radius), and a capsule
#: smoothly joined to a sphere (centre, radius); the slices of the figures cut through them.
BOX_C, BOX_H, CARVE_R = (0.0, 0.0, 0.5), 0.5, 0.65
BLOB_C, BLOB_R = (-1.5, 0.3, 0.3), 0.3
CARVE_Y = 0.45  # the slice through the carved box: the sphere leaves a round hole of radius sqrt(R^2 - y^2)


def csg_field(P):
    """The analytic scene: (box minus sphere) on a plane, a torus, a capsule smoothly joined to a sphere."""
    carved = op_difference(sd_box(P, BOX_C, [BOX_H] * 3), sd_sphere(P, BOX_C, CARVE_R))
    ring = sd_torus(P, [1.5, 0.2, 0.25], 0.45, 0.15)
    blob = smooth_union(sd_capsule(P, [-1.5, 0.3, 0.2], [-1.2, -0.2, 1.0], 0.18), sd_sphere(P, BLOB_C, BLOB_R), 0.25)
    return op_union(op_union(op_union(carved, ring), blob), sd_plane(P, [0.0, 0.0, 1.0], 0.0))


def _slice_xz(y, nx, nz):
    """The scene's field on the plane at ``y``: x in [-2.2, 2.2], z in [-0.4, 1.4], ``(nx, nz)`` samples."""
    X, Z = np.meshgrid(np.linspace(-2.2, 2.2, nx), np.linspace(-0.4, 1.4, nz), indexing="ij")
    return csg_field(np.c_[X.ravel(), np.full(X.size, y), Z.ravel()]).reshape(X.shape)


def _camera(eye, target, size, fov=40.0):
    return camera.perspective_look_at(eye, target, [0, 0, 1], fov, size[1] / size[0], 0.05, 30.0)


__all__ = ["make_figures", "make_view"]

#: Tasks whose panels the figure being drawn had to leave out (its caption then names the first).
_MISSING = MissingTasks()

_CACHE: dict = {}
ISO = 0.1  # the slices' iso-line spacing
TUBE = 0.35  # the torus's tube radius (it is raised by as much, so it rests on z = 0)


def _torus_grid(quick):
    key = ("torus", quick)
    if key not in _CACHE:
        V, F = datasets.torus(1.0, TUBE, 48, 24)
        V = V + [0, 0, TUBE]
        _CACHE[key] = (V, F, sdf_grid(V, F, 36 if quick else 64))
    return _CACHE[key]


# ---------------------------------------------------------------------------------- figures


@figure_name("sdf_csg")
def fig_csg(out: Path, quick: bool) -> Drawn:
    size = (150, 220) if quick else (300, 440)
    M = _camera([0.4, -4.2, 2.4], [0.0, 0.0, 0.4], size)
    budget = 96
    R = _MISSING.attempt(render_sdf, csg_field, M, size[1], size[0], max_steps=budget)
    img = _missing(size, "Task 1 (analytic SDFs) and Task 8 (sphere tracing)") if R is None else _u8(R["image"])
    n = 120 if quick else 220
    slices, ys = [], (CARVE_Y, BLOB_C[1])
    for y in ys:
        d = _MISSING.attempt(_slice_xz, y, n, n // 2)
        slices.append(_missing(size, "Task 1 (analytic SDFs)") if d is None else _slice_image(d, 0.5, 0.1, 2))
    slices[-1] = _with_bar(slices[-1], -0.5, 0.5, "RdBu", "phi")
    page = panels(
        [img, *slices],
        [
            "sphere-traced: box minus sphere, torus,\ncapsule smoothly joined to a sphere, plane",
            f"slice y = {ys[0]} through the carved box:\na square with the sphere's round hole",
            f"slice y = {ys[1]} through the smooth union\n(capsule and sphere, the blend filled in)",
        ],
        ncols=3,
        title="Analytic SDFs and CSG: red inside, blue outside, iso-lines every 0.1, zero line black",
    )
    if R is None:
        return Drawn(page, "An analytic scene built with min, max(a, -b) and the smooth union, and two slices.")
    missed = ~R["hit"]
    return Drawn.claimed(
        page,
        "An analytic scene built with min (union), max(a, -b) (difference) and the smooth union, rendered by "
        "sphere tracing, and its field on two slices, each through one CSG result: at y = {carve_y} the box of "
        "half size {box_h} minus the sphere of radius {carve_r}, which there leaves a round hole of radius "
        "{hole:.2f} in the square; at y = {blob_y} the capsule smoothly joined to the sphere of radius {blob_r}. "
        "The ground ends at a curved horizon: {budget_misses} of the {misses} missed pixels are rays that used up "
        "the {budget}-step budget at grazing angles, where every step is as short as the distance to the plane "
        "below; {beyond} went past the far plane.",
        carve_y=CARVE_Y, box_h=BOX_H, carve_r=CARVE_R, hole=float(np.sqrt(CARVE_R**2 - CARVE_Y**2)),
        blob_y=BLOB_C[1], blob_r=BLOB_R, budget_misses=int((missed & (R["steps"] >= budget)).sum()),
        misses=int(missed.sum()), budget=budget,
        beyond=int((missed & (R["steps"] < budget)).sum()),
    )  # fmt: skip


@figure_name("sdf_slices")
def fig_slices(out: Path, quick: bool) -> Drawn:
    def make():
        V, F, g = _torus_grid(quick)
        r = 0.6
        m = 120 if quick else 220
        u = np.linspace(g.origin[0], g.upper[0], m)
        A, B = np.meshgrid(u, u, indexing="ij")
        top = g.sample(np.c_[A.ravel(), B.ravel(), np.full(A.size, TUBE)]).reshape(m, m)
        side = g.sample(np.c_[A.ravel(), np.zeros(A.size), B.ravel() - g.origin[0] + g.origin[2]]).reshape(m, m)
        a = _slice_image(top, r, ISO, 2 if quick else 1)
        b = _slice_image(side, r, ISO, 2 if quick else 1)
        return [a, _with_bar(b, -r, r, "RdBu", "phi")], g

    try:
        imgs, g = make()
        caps = [f"z = {TUBE} (through the tube centres)", "y = 0 (across the ring)"]
        title = f"Mesh SDF of a torus (2,304 faces) on a {g.shape[0]}^3 grid"
    except NotImplementedError as e:
        imgs, caps, title = [_missing((200, 200), f"Tasks 2-4 ({str(e)[:50]})", e)], [""], "Mesh SDF"
    return Drawn.claimed(
        panels(imgs, caps, title=title),
        "The signed distance of a torus mesh (pseudonormal sign, BVH closest points), looked up trilinearly on "
        "two slices: red inside, blue outside, iso-lines every {iso}, the surface (zero line) in black. The "
        "torus (tube radius {tube}) is raised by {tube} so that it rests on z = 0, which is why z = {tube} "
        "cuts through the tube centres.",
        iso=ISO,
        tube=TUBE,
    )


def _sphere_grid(quick):
    """An icosphere of radius 1 on a grid: thick enough for bricks that lie entirely inside the band."""
    key = ("sphere", quick)
    if key not in _CACHE:
        V, F = datasets.icosphere(3, radius=1.0)
        _CACHE[key] = (V, F, sdf_grid(V, F, 36 if quick else 64))
    return _CACHE[key]


def _brick_lines(img, n, up, colour=(110, 110, 110)):
    """Draw the brick boundaries (every 7 samples) on a plane image of ``n`` samples drawn ``up`` x ``up``."""
    for s in range(0, n, 7):
        p = min(s * up + up // 2, img.shape[0] - 1)
        img[p, :] = colour
        img[:, p] = colour
    return img


@figure_name("sdf_bricks")
def fig_bricks(out: Path, quick: bool) -> Drawn:
    try:
        V, F, g = _sphere_grid(quick)
        band = 4
        B = compress_bricks(g, band_voxels=band)
        n = g.shape[0]
        # one x-z plane of grid samples for both maps: the middle sample row (y) of the middle brick layer
        j = B.table.shape[1] // 2
        k = min(7 * j + 3, n - 1)
        up = 4
        # per sample of the plane: the state of the brick that owns it (sample s belongs to brick s // 7)
        owner = np.minimum(np.arange(n) // 7, B.table.shape[0] - 1)
        T = B.table[owner][:, j][:, owner]  # (x, z)
        state = np.where(T >= 0, 2, np.where(T == EMPTY_INSIDE, 1, 0)).astype(float)
        zero = np.zeros((n, n), bool)
        s = g.values[:, k, :] < 0
        zero[:-1] |= s[:-1] != s[1:]
        zero[:, :-1] |= s[:, :-1] != s[:, 1:]

        def plane(rgb):  # x to the right, z up, drawn up x up, brick lines and the surface on top
            img = _up(rgb[:, ::-1].transpose(1, 0, 2).copy(), up)
            img = _brick_lines(img[::-1], n, up)[::-1]
            img[_up(zero[:, ::-1].T, up)] = (20, 20, 20)
            return img

        occ_img = plane(heatmap_image(state, "viridis", 0, 2))
        X = grid_points(g.origin, g.spacing, g.shape)
        err = (B.sample(X) - np.clip(g.values.ravel(), -B.r, B.r)).reshape(g.shape) / B.step
        inband = np.abs(g.values) < B.r
        e2 = np.where(inband[:, k, :], err[:, k, :], np.nan)
        err_img = plane(heatmap_image(e2, "RdBu", -0.5, 0.5, nan_color=(245, 245, 245)))
        # a 1-D profile along x through the centre of the plane: the float grid, clamped, and the bricks
        m = 8 * n
        x = np.linspace(g.origin[0], g.origin[0] + (n - 1) * g.spacing, m)
        zc = g.origin[2] + (n // 2) * g.spacing
        line = np.c_[x, np.full(m, g.origin[1] + k * g.spacing), np.full(m, zc)]
        dense = g.sample(line) / g.spacing
        bricked = B.sample(line) / g.spacing
        w = max(occ_img.shape[0] + 120, 360)  # the quick figure's plots stay readable
        prof = line_plot(
            [x, x, x], [dense, np.clip(dense, -band, band), bricked],
            ["float grid (trilinear)", "clamped to the band +-r", "8-bit bricks"],
            xlabel="x", ylabel="distance (voxels)", title="along x through the centre", size=(w + 60, w), markers=False,
        )  # fmt: skip
        xs = g.origin[0] + np.arange(n) * g.spacing
        prof_e = line_plot(
            [xs], [err[:, k, n // 2]], ["bricks - clamped grid"], xlabel="x (grid samples)",
            ylabel="error (quantisation steps 2r/255)", title="the same line: quantisation error", size=(w + 60, w),
        )  # fmt: skip
        dense_bytes = g.values.astype(np.float32).nbytes
        inside = int((B.table == EMPTY_INSIDE).sum())
        outside = int((B.table == EMPTY_OUTSIDE).sum())
        caps = [
            "bricks owning the samples of one x-z plane (grey lines: brick grid; black: the surface): "
            "yellow kept, teal dropped inside (-r), purple dropped outside (+r)",
            "quantisation error in steps at the same samples, inside the band (grey: outside the band)",
            "distance along the line z = centre of the same plane",
            "error at the grid samples on that line",
        ]
        imgs = [occ_img, _with_bar(err_img, -0.5, 0.5, "RdBu", "error / step"), prof, prof_e]
        title = (
            f"8^3 bricks (7 cells + apron), r = {band} voxels, uint8: {B.nbytes / 1024:.0f} KiB vs dense float32 "
            f"{dense_bytes / 1024:.0f} KiB ({dense_bytes / B.nbytes:.1f}x smaller)"
        )
    except NotImplementedError as e:
        imgs, caps, title = [_missing((200, 200), f"Tasks 2-6 ({str(e)[:50]})", e)], [""], "Bricks"
        return Drawn(panels(imgs, caps, title=title), "Which bricks are stored, and the bricked field's error.")
    return Drawn.claimed(
        panels(imgs, caps, ncols=2, title=title),
        "A sphere mesh (radius {radius} units, {radius_vox:.1f} voxels) on a {n}^3 grid, cut into bricks of 8^3 "
        "samples. Top left: the bricks that own the samples of one x-z plane, with the brick grid and the surface: "
        "of the {total} bricks, {kept} are kept, {inside} are dropped because every sample is at least r = {band} "
        "voxels inside (read back as -r) and {outside} because every sample is at least r outside (read as +r). "
        "Top right: on the same plane, the error of the bricked 8-bit field against the float grid clamped to the "
        "band, in quantisation steps 2r/255: at most {max_err:.3f} steps over the whole grid, within half a step. "
        "Bottom: one line through the centre of that plane: the float grid's distance, clamped to +-r, and what "
        "the bricks return (the clamp flattens the field beyond the band, inside and out); the quantisation error "
        "on that line stays within half a step.",
        radius=1.0, radius_vox=1.0 / float(g.spacing), n=n, total=int(B.table.size), kept=len(B.codes),
        inside=inside, outside=outside, band=band, max_err=float(np.nanmax(np.abs(err[inband]))),
    )  # fmt: skip


@figure_name("sdf_normals")
def fig_normals(out: Path, quick: bool) -> Drawn:
    size = (120, 160) if quick else (240, 320)
    try:
        n = 40 if quick else 64
        x = np.linspace(-1.7, 1.7, n)
        h = x[1] - x[0]
        X = grid_points(np.full(3, -1.7), h, (n, n, n))

        def exact(P):
            return sd_torus(P, [0.0, 0.0, 0.0], 1.0, 0.4)

        g = SDFGrid(exact(X).reshape(n, n, n), np.full(3, -1.7), h)
        M = _camera([0.0, -3.6, 2.4], [0, 0, 0], size)
        R = render_sdf(g, M, size[1], size[0])
        hit = R["hit"]
        Ph = R["points"][hit]
        true = gradient_central(exact, Ph, 1e-6)
        imgs, caps, errs = [], [], []
        for name, fn, taps in (("6-tap central", gradient_central, 6), ("4-tap tetrahedral", gradient_tetra, 4)):
            N = fn(g, Ph, 0.5 * h)
            e = np.degrees(np.arccos(np.clip(np.sum(N * true, axis=1), -1, 1)))
            errs.append(e)
            im = np.full(hit.shape, np.nan)
            im[hit] = e
            imgs.append(im)
            caps.append(f"{name} ({taps} lookups): mean {e.mean():.2f}°, p99 {np.percentile(e, 99):.2f}°")
        # one log scale for both: on a linear one the second-order stencil's map is uniformly black
        lo = float(np.floor(np.log10(max(np.percentile(errs[0], 1), 1e-6))))
        hi = float(np.ceil(np.log10(max(np.percentile(e, 99) for e in errs))))
        pics = [
            heatmap_image(np.log10(np.maximum(im, 10**lo)), "inferno", lo, hi, nan_color=(255, 255, 255)) for im in imgs
        ]
        pics[-1] = _with_bar(pics[-1], lo, hi, "inferno", "log10 angle error (°)")
        title = f"Normals from a {n}^3 grid of a torus: angle to the true normal at the sphere-traced hits, h = half a voxel"
    except NotImplementedError as e:
        pics, caps, title = [_missing(size, f"Tasks 6-8 ({str(e)[:50]})", e)], [""], "Gradients"
        return Drawn(panels(pics, caps, title=title), "Normals of a sampled torus field: 6-tap and 4-tap stencils.")
    return Drawn.claimed(
        panels(pics, caps, title=title),
        "The angle between the finite-difference normal of a sampled torus field and the exact normal, at every "
        "sphere-traced hit, same step h for both, on one logarithmic colour scale (10^{lo:.0f} to 10^{hi:.0f} "
        "degrees). The 4-tap tetrahedral stencil needs two thirds of the lookups but is only first-order accurate "
        "(mean {mean4:.2f} degrees against {mean6:.2f} for central differences, {ratio:.0f} times larger): its error "
        "is h times the mixed second derivatives of the field, largest where the torus curves diagonally to the "
        "grid axes. Central differences are second order: what is left of their error, visible only on the log "
        "scale, is the grid itself, stripes along the sample planes where the trilinear lookup's slope jumps.",
        lo=lo,
        hi=hi,
        mean4=float(errs[1].mean()),
        mean6=float(errs[0].mean()),
        ratio=float(errs[1].mean() / errs[0].mean()),
    )


@figure_name("sdf_trace")
def fig_trace(out: Path, quick: bool) -> Drawn:
    size = (120, 160) if quick else (300, 400)
    try:
        V, F, g = _torus_grid(quick)
        M = _camera([0.6, -3.2, 2.6], [0.0, 0.0, 0.3], size)
        R = render_sdf(g, M, size[1], size[0], max_steps=64)
        gb = raster.rasterize(V, F, M, size[1], size[0])
        diff = np.mean(R["hit"] != gb.mask)
        steps = R["steps"].astype(float)
        st = _with_bar(heatmap_image(steps, "magma", 0, 64), 0, 64, "magma", "steps")
        mask = np.full((*size, 3), 255, np.uint8)
        mask[R["hit"] & gb.mask] = (150, 150, 150)
        # the differing pixels are single pixels along silhouettes: drawn 3 x 3 so they can be seen
        for only, colour in ((R["hit"] & ~gb.mask, (220, 60, 40)), (~R["hit"] & gb.mask, (40, 90, 220))):
            grown = only.copy()
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    grown |= np.roll(np.roll(only, dy, 0), dx, 1)
            mask[grown] = colour
        pics = [_u8(R["image"]), st, mask]
        caps = [
            "sphere-traced, 4-tap normals, Lambert",
            f"field evaluations per pixel (mean {steps.mean():.1f}; grazing rays\nnear silhouettes take the most)",
            f"hit mask vs rasterizer: {100 * diff:.2f}% of pixels differ\n(red: traced only, blue: rasterized only;\n"
            "each drawn 3 x 3 pixels)",
        ]
        title = f"Sphere tracing the {g.shape[0]}^3 torus field"
    except NotImplementedError as e:
        pics, caps, title = [_missing(size, f"Tasks 2-8 ({str(e)[:50]})", e)], [""], "Sphere tracing"
    return Drawn(
        panels(pics, caps, title=title),
        "Sphere tracing the sampled torus: the shaded image, the step-count heat map (the engine's view of where "
        "the time goes) and the hit mask against geomlib's rasterizer of the same mesh and camera, which differs "
        "only along silhouettes.",
    )


def _shadow_setup(quick):
    S, SF = datasets.icosphere(3, radius=0.5)
    S = S + [0.0, 0.0, 0.9]
    n = 40 if quick else 96
    xs = np.linspace(-2.0, 2.0, n)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    P = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 1e-3)]
    return S, SF, P, n


@figure_name("sdf_soft_shadows")
def fig_soft_shadows(out: Path, quick: bool) -> Drawn:
    try:
        S, SF, P, n = _shadow_setup(quick)
        gs = sdf_grid(S, SF, 32 if quick else 48, padding=0.6)

        def field(Q):
            return np.minimum(gs.sample(Q), Q[:, 2])  # the sphere mesh's grid and the ground plane z = 0

        light = np.array([0.8, -0.5, 3.2])
        up = 3 if quick else 2
        rays = 48 if quick else 256
        pics, caps, numbers = [], [], {}
        radii = (0.15, 0.5, 1.0)
        for i, R in enumerate(radii):
            est = soft_shadow(field, P, light, R, max_steps=48)
            imp = soft_shadow(field, P, light, R, max_steps=48, improved=True)
            truth = mesh_visibility(S, SF, P, light, R, n=rays)
            row = [est, imp, truth]
            framed = []
            for v in row:
                im = _up(heatmap_image(v.reshape(n, n)[::-1], "gray", 0, 1), up)
                im[[0, -1]] = im[:, [0, -1]] = (120, 120, 120)  # the sampled square ends here
                framed.append(im)
            pics += framed
            numbers.update({f"e{i}": float(np.mean(np.abs(est - truth))), f"i{i}": float(np.mean(np.abs(imp - truth)))})
            numbers["dmax"] = max(numbers.get("dmax", 0.0), float(np.max(np.abs(imp - est))))
            caps += [
                f"R = {R}: course formula\nmean |error| {numbers[f'e{i}']:.3f}",
                f"R = {R}: improved\nmean |error| {numbers[f'i{i}']:.3f}",
                f"R = {R}: Monte-Carlo truth\n({rays} rays per point)",
            ]
            err = np.abs(est - truth).reshape(n, n)[::-1]
            pics.append(_with_bar(_up(heatmap_image(err, "inferno", 0, 0.5), up), 0, 0.5, "inferno", "|V - truth|"))
            caps.append(f"R = {R}: per-pixel |error| (formula)\nmax {err.max():.2f}")
        page = panels(pics, caps, ncols=4, title="Soft shadows of a sphere mesh on the ground, seen from above")
    except NotImplementedError as e:
        page = panels([_missing((200, 200), f"Tasks 2-9 ({str(e)[:50]})", e)], [""], title="Soft shadows")
        return Drawn(page, "Soft shadows of a sphere mesh: the course formula, the improved variant, the truth.")
    box = _banding_panels(quick, light, up)
    page = _stack([page, box["page"]])
    worse = sum(numbers[f"i{i}"] > numbers[f"e{i}"] for i in range(len(radii)))
    return Drawn.claimed(
        page,
        "Visibility of a spherical light of radius R (rows: {r0}, {r1}, {r2}) on the ground under a sphere mesh, "
        "seen from above (framed: the sampled square; the largest penumbra runs past it): the course formula "
        "min d/(t tan alpha), the improved variant, a Monte-Carlo area-light truth cast with geomlib's watertight "
        "rays, and the per-pixel error of the formula. The formula drops to zero wherever the ray to the light's "
        "centre is blocked, so its umbra is the hard shadow of the centre and only the outer half of the true "
        "penumbra survives: the error is a ring on the inner penumbra that widens with R (mean {e0:.3f}, {e1:.3f}, "
        "{e2:.3f}). The improved variant only tightens the estimate (it changes V by at most {dmax:.2f}), so it "
        "is closer to the truth in {better} of {rows} rows (mean {i0:.3f}, {i1:.3f}, {i2:.3f}): neither recovers the "
        "inner penumbra. What it does fix shows on a box, whose sharp edges a march with steps as long as the "
        "distance skips past (bottom, R = {rb}): the formula's sampled minimum lies above the minimum along the "
        "whole ray (marched in {fine} small steps), in streaks that follow the march's sample positions (blue, mean "
        "{pb_mean:.4f}, up to {pb_max:.3f}); the improved variant's estimate of the closest approach between two "
        "samples cuts that overestimate (mean {ib_mean:.4f}, up to {ib_max:.3f}), undershooting by at most "
        "{ib_under:.3f} (red). The profile across the box's shadow puts the two errors side by side: the streaks "
        "are small next to the error of all three estimates against the area-light truth on that line (the "
        "formula's up to {prof_err:.2f}), which no way of marching recovers.",
        r0=radii[0], r1=radii[1], r2=radii[2], better=len(radii) - worse, rows=len(radii),
        **numbers, **box["numbers"],
    )  # fmt: skip


#: The box of the banding demonstration: centre and half size (it stands on the ground)
SHADOW_BOX_C, SHADOW_BOX_H = (0.0, 0.0, 0.8), (0.5, 0.5, 0.5)


def _stack(pages):
    """Stack pictures vertically, centred, on white."""
    w = max(p.shape[1] for p in pages)
    out = []
    for p in pages:
        left = (w - p.shape[1]) // 2
        out.append(np.pad(p, ((0, 0), (left, w - p.shape[1] - left), (0, 0)), constant_values=255))
    return np.concatenate(out, axis=0)


def _ray_minimum(field, P, light, R, k):
    """The course formula's limit: ``min phi(x(t)) / (t tan alpha)`` over ``k`` evenly spaced ``t``, clamped."""
    L = light - P
    D = np.linalg.norm(L, axis=1)
    ldir = L / D[:, None]
    tan_a = R / np.sqrt(D**2 - R**2)
    V = np.ones(len(P))
    steps = np.linspace(0.0, 1.0, k)[1:]
    for b in range(0, len(steps), 64):  # 64 steps per field call: the same values, a few calls of fixed cost
        s = steps[b : b + 64, None]
        t = 1e-3 * D + s * (D - R - 1e-3 * D)  # (steps, points)
        phi = field((P + t[..., None] * ldir).reshape(-1, 3)).reshape(t.shape)
        V = np.minimum(V, (phi / (t * tan_a)).min(axis=0))
    return np.clip(V, 0.0, 1.0)


def _banding_panels(quick, light, up):
    """The box scene: formula and improved variant against the minimum along the whole ray, and a profile."""
    c, h = np.array(SHADOW_BOX_C), np.array(SHADOW_BOX_H)

    def field(Q):
        return np.minimum(sd_box(Q, c, h), Q[:, 2])

    n = 40 if quick else 96
    xs = np.linspace(-2.0, 2.0, n)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    P = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 1e-3)]
    R = 1.0
    fine = 300 if quick else 1500
    est = soft_shadow(field, P, light, R, max_steps=48)
    imp = soft_shadow(field, P, light, R, max_steps=48, improved=True)
    lim = _ray_minimum(field, P, light, R, fine)
    pics, caps = [], []
    for v, what in ((est, "course formula"), (imp, "improved"), (lim, f"minimum along the ray\n({fine} small steps)")):
        im = _up(heatmap_image(v.reshape(n, n)[::-1], "gray", 0, 1), up)
        im[[0, -1]] = im[:, [0, -1]] = (120, 120, 120)
        pics.append(im)
        caps.append(f"box, R = {R}: {what}")
    s = 0.1
    for v, what in ((est, "formula"), (imp, "improved")):
        im = _up(heatmap_image((v - lim).reshape(n, n)[::-1], "RdBu", -s, s), up)
        pics.append(im)
        caps.append(f"{what} - minimum along the ray\n(blue: above it, red: below)")
    pics[-1] = _with_bar(pics[-1], -s, s, "RdBu", "V difference")
    grid = panels(pics, caps, ncols=5, title="A box: the banding the improved variant removes")
    # the profile across the box's shadow, with the area-light truth of the same box as a mesh
    row = int(np.argmin(np.abs(xs - 0.1)))
    Pr = P[row * n : (row + 1) * n]
    BV, BF = datasets.sharp_box(tuple(2 * h), 8)
    truth = mesh_visibility(BV + c, BF, Pr, light, R, n=64 if quick else 512)
    sel = slice(row * n, (row + 1) * n)
    prof = line_plot(
        [xs] * 4, [est[sel], imp[sel], lim[sel], truth],
        ["course formula", "improved", "minimum along the ray", "Monte-Carlo truth"],
        xlabel=f"x along y = {xs[row]:.2f}", ylabel="visible fraction V", title="Across the box's shadow",
        size=(900, 340) if not quick else (600, 300), markers=False,
    )  # fmt: skip
    under = np.maximum(lim - imp, 0.0)
    numbers = {
        "rb": R, "fine": fine,
        "pb_mean": float(np.mean(np.abs(est - lim))), "pb_max": float(np.max(np.abs(est - lim))),
        "ib_mean": float(np.mean(np.abs(imp - lim))), "ib_max": float(np.max(np.abs(imp - lim))),
        "ib_under": float(under.max()), "prof_err": float(np.max(np.abs(est[sel] - truth))),
    }  # fmt: skip
    return {"page": _stack([grid, prof]), "numbers": numbers}


def _segment_pixels(a, b, shape, k=24):
    """Pixels (rows, cols) on the segments from ``a`` to ``b`` ((m, 2) rows/cols each), ``k`` samples per segment."""
    t = np.linspace(0, 1, k)[None, :, None]
    p = np.rint(a[:, None] + t * (b - a)[:, None]).astype(int).reshape(-1, 2)
    return np.clip(p[:, 0], 0, shape[0] - 1), np.clip(p[:, 1], 0, shape[1] - 1)


@figure_name("sdf_ao_push")
def fig_ao_push(out: Path, quick: bool) -> Drawn:
    size = (120, 160) if quick else (260, 360)
    try:
        M = _camera([0.4, -4.2, 2.4], [0.0, 0.0, 0.4], size)
        R = render_sdf(csg_field, M, size[1], size[0], max_steps=96)
        hit = R["hit"]
        ao = np.full(hit.shape, np.nan)
        ao[hit] = ambient_occlusion(csg_field, R["points"][hit], R["normal"][hit], taps=5, delta=0.06)
        lit = np.where(hit[..., None], R["image"] * np.nan_to_num(ao, nan=1.0)[..., None], 1.0)
        occ = 1.0 - ao
        hi = float(np.nanpercentile(occ, 99.5))
        occ_img = _with_bar(heatmap_image(occ, "magma", 0, hi, nan_color=(255, 255, 255)), 0, hi, "magma", "1 - AO")
        # push-out on the slice through the carved box: random points, before (red), after (blue), the move (line)
        nx, nz = (160, 80) if quick else (300, 150)
        sl = _slice_image(_slice_xz(CARVE_Y, nx, nz), 0.5, 0.1, 2)
        rng = np.random.default_rng(3)
        Pp = np.c_[rng.uniform(-2, 2, 60), np.full(60, CARVE_Y), rng.uniform(-0.3, 1.1, 60)]
        Pp = Pp[csg_field(Pp) < 0.05]
        Q = push_out(csg_field, Pp, radius=0.05, iterations=6)
        off_plane = float(np.abs(Q[:, 1] - CARVE_Y).max()) if len(Q) else 0.0

        def to_px(A):  # rows, cols of the slice image (2x upsampled)
            return np.c_[(1.4 - A[:, 2]) / 1.8 * (nz - 1) * 2, (A[:, 0] + 2.2) / 4.4 * (nx - 1) * 2]

        a, b = to_px(Pp), to_px(Q)
        sl[_segment_pixels(a, b, sl.shape)] = (20, 20, 20)
        for A, col in ((a, (220, 40, 40)), (b, (30, 30, 200))):
            j, i = np.rint(A).astype(int).T
            for dj in (-2, -1, 0, 1, 2):
                for di in (-2, -1, 0, 1, 2):
                    sl[np.clip(j + dj, 0, sl.shape[0] - 1), np.clip(i + di, 0, sl.shape[1] - 1)] = col
        pics = [_u8(lit), occ_img, sl]
        caps = [
            "Lambert shading times distance-field AO\n(5 taps along the normal)",
            "occlusion 1 - AO alone (0 = open; white:\nno surface); it gathers at contacts and creases",
            f"push-out: {len(Pp)} penetrating points (red) moved\nto phi = 0.05 (blue), slice y = {CARVE_Y}",
        ]
        page = panels(pics, caps, ncols=3, title="Ambient occlusion and collision push-out")
    except NotImplementedError as e:
        page = panels([_missing(size, f"Tasks 1, 7-9 ({str(e)[:50]})", e)], [""], title="AO and push-out")
        return Drawn(page, "Ambient occlusion of the analytic scene, and points pushed out of its solids.")
    return Drawn.claimed(
        page,
        "Left: the analytic scene's Lambert shading multiplied by its ambient occlusion from five field taps along "
        "the normal; middle: the occlusion alone, which darkens where objects meet the ground and inside the "
        "carved box; single dark pixels on the carved box's sharp edges are where the 4-tap normal, taken across "
        "the edge, points between the two faces and the taps run into the solid. Right: {points} points "
        "inside the solids (red) pushed out along the 4-tap gradient until they clear the surface by {clear} "
        "(blue; the line is the move), on the slice y = {carve_y} through the carved box (the points leave the "
        "plane by at most {off_plane:.2f}).",
        points=len(Pp), clear=0.05, carve_y=CARVE_Y, off_plane=off_plane,
    )  # fmt: skip


@figure_name("sdf_3d")
def fig_view(quick: bool) -> MeshView:
    V, F, grid = _torus_grid(quick)
    bricks = compress_bricks(grid, band_voxels=4)
    # On the surface the exact distance is 0, so what the bricks return there is their error; the
    # dense grid's own trilinear lookup shows how much of it is interpolation, not quantisation.
    err = np.abs(np.asarray(bricks.sample(V))) / bricks.step
    dense = np.abs(np.asarray(grid.sample(V))) / bricks.step
    return MeshView(
        V, F, np.round(err, 2), title="Brick SDF on the torus surface", up="z",
        cmap="viridis", scalar_name="|d| in quantisation steps",
        caption=Claims(
            "Turn it: the torus, each vertex coloured by the distance the 8-bit brick field returns there "
            "(exactly zero on the surface), in quantisation steps: up to {bricked:.2f} steps. That is interpolation, "
            "not quantisation: the dense float grid's own trilinear lookup already returns up to {dense:.2f} steps "
            "at the vertices, because a trilinear patch between samples is not the curved surface.",
            {"bricked": float(err.max()), "dense": float(dense.max())},
        ),
    )  # fmt: skip


#: The figures in order; one drawn without some of its panels names the missing task in its caption.
FIGURES = [
    partial_figure(build, _MISSING)
    for build in (fig_csg, fig_slices, fig_bricks, fig_normals, fig_trace, fig_soft_shadows, fig_ao_push)
]

make_figures, make_view = lab_figure_makers(
    LAB, __name__, FIGURES, fig_view, draws_lab=False,
    quick="Smaller grids and images (for the notebook and CI).", shared=_CACHE,
)  # fmt: skip
