"""Figures of the signed-distance lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The file
is copied into ``labs/sdf/`` with the stubs, so there it draws *your* results once your functions
work (a figure whose tasks are missing is replaced by a panel naming them); compare with
``docs/figures/sdf/``. Numbers in the captions and panel labels are measured when the figure is made.
Images are sphere-traced by :func:`render_sdf` (the lab's own tracer); the hit mask is compared with
geomlib's rasterizer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import camera, datasets, raster
from geomlib.labfigures import Drawn, MeshView, figure_name, lab_figure_makers, partial_figure
from geomlib.plot import colorbar, heatmap_image, panels
from geomlib.taskref import find_task

from .analytic import op_difference, op_union, sd_box, sd_capsule, sd_plane, sd_sphere, sd_torus, smooth_union
from .bricks import EMPTY_INSIDE, compress_bricks
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


def _missing(size, what: str) -> np.ndarray:
    """A grey panel standing in for a picture whose tasks are not implemented yet."""
    import textwrap

    from PIL import Image, ImageDraw

    task = find_task(what)
    _MISSING.append(task.label if task else "?")
    h, w = max(size[0], 160), max(size[1], 260)
    im = Image.new("RGB", (w, h), (235, 235, 235))
    text = "not implemented yet:\n" + "\n".join(textwrap.wrap(what, max(20, w // 7)))
    ImageDraw.Draw(im).multiline_text((10, 10), text, fill=(90, 90, 90))
    return np.asarray(im)


def _try(fn, size, what):
    try:
        return fn()
    except NotImplementedError as e:
        return _missing(size, f"{what}\n({str(e)[:60]})")


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


def csg_field(P):
    """The analytic scene: (box minus sphere) on a plane, a torus, a capsule smoothly joined to a sphere."""
    carved = op_difference(sd_box(P, [0.0, 0.0, 0.5], [0.5, 0.5, 0.5]), sd_sphere(P, [0.0, 0.0, 0.5], 0.65))
    ring = sd_torus(P, [1.5, 0.2, 0.25], 0.45, 0.15)
    blob = smooth_union(
        sd_capsule(P, [-1.5, 0.3, 0.2], [-1.2, -0.2, 1.0], 0.18), sd_sphere(P, [-1.5, 0.3, 0.3], 0.3), 0.25
    )
    return op_union(op_union(op_union(carved, ring), blob), sd_plane(P, [0.0, 0.0, 1.0], 0.0))


def _camera(eye, target, size, fov=40.0):
    return camera.perspective(fov, size[1] / size[0], 0.05, 30.0) @ camera.look_at(eye, target, [0, 0, 1])


__all__ = ["make_figures", "make_view"]

#: Tasks whose panels the figure being drawn had to leave out (its caption then names the first).
_MISSING: list[str] = []

_CACHE: dict = {}


def _torus_grid(quick):
    key = ("torus", quick)
    if key not in _CACHE:
        V, F = datasets.torus(1.0, 0.35, 48, 24)
        V = V + [0, 0, 0.35]
        _CACHE[key] = (V, F, sdf_grid(V, F, 36 if quick else 64))
    return _CACHE[key]


# ---------------------------------------------------------------------------------- figures


@figure_name("sdf_csg")
def fig_csg(out: Path, quick: bool) -> Drawn:
    size = (150, 220) if quick else (300, 440)
    M = _camera([0.4, -4.2, 2.4], [0.0, 0.0, 0.4], size)

    def trace():
        R = render_sdf(csg_field, M, size[1], size[0], max_steps=96)
        return _u8(R["image"])

    def sl():
        n = 120 if quick else 220
        x = np.linspace(-2.2, 2.2, n)
        z = np.linspace(-0.4, 1.4, n // 2)
        X, Z = np.meshgrid(x, z, indexing="ij")
        P = np.c_[X.ravel(), np.zeros(X.size), Z.ravel()]
        d = csg_field(P).reshape(X.shape)
        return _with_bar(_slice_image(d, 0.5, 0.1, 2), -0.5, 0.5, "RdBu", "phi")

    img = _try(trace, size, "Task 1 (analytic SDFs) and Task 8 (sphere tracing)")
    sli = _try(sl, size, "Task 1 (analytic SDFs)")
    page = panels(
        [img, sli],
        [
            "sphere-traced: box minus sphere, torus,\ncapsule smoothly joined to a sphere, plane",
            "slice y = 0: phi (red inside, blue outside),\niso-lines every 0.1, zero line black",
        ],
        title="Analytic SDFs and CSG",
    )
    return Drawn(
        page,
        "An analytic scene built with min (union), max(a, -b) (difference) and the smooth union, rendered by "
        "sphere tracing, and its field on the slice y = 0 with iso-lines every 0.1 and the zero line in black.",
    )


@figure_name("sdf_slices")
def fig_slices(out: Path, quick: bool) -> Drawn:
    def make():
        V, F, g = _torus_grid(quick)
        r = 0.6
        m = 120 if quick else 220
        u = np.linspace(g.origin[0], g.upper[0], m)
        A, B = np.meshgrid(u, u, indexing="ij")
        top = g.sample(np.c_[A.ravel(), B.ravel(), np.full(A.size, 0.35)]).reshape(m, m)
        side = g.sample(np.c_[A.ravel(), np.zeros(A.size), B.ravel() - g.origin[0] + g.origin[2]]).reshape(m, m)
        a = _slice_image(top, r, 0.1, 2 if quick else 1)
        b = _slice_image(side, r, 0.1, 2 if quick else 1)
        return [a, _with_bar(b, -r, r, "RdBu", "phi")], g

    try:
        imgs, g = make()
        caps = ["z = 0.35 (through the tube centres)", "y = 0 (across the ring)"]
        title = f"Mesh SDF of a torus (2,304 faces) on a {g.shape[0]}^3 grid"
    except NotImplementedError as e:
        imgs, caps, title = [_missing((200, 200), f"Tasks 2-4 ({str(e)[:50]})")], [""], "Mesh SDF"
    return Drawn(
        panels(imgs, caps, title=title),
        "The signed distance of a torus mesh (pseudonormal sign, BVH closest points), looked up trilinearly on "
        "two slices: red inside, blue outside, iso-lines every 0.1, the surface (zero line) in black.",
    )


@figure_name("sdf_bricks")
def fig_bricks(out: Path, quick: bool) -> Drawn:
    try:
        V, F, g = _torus_grid(quick)
        B = compress_bricks(g, band_voxels=4)
        n = g.shape[0]
        k = int(np.argmin(np.abs(g.origin[2] + g.spacing * np.arange(n) - 0.35)))
        # occupancy of the vertical brick layer through the ring's centre (x-z)
        T = B.table[:, B.table.shape[1] // 2, :]
        occ = np.where(T >= 0, 2, np.where(T == EMPTY_INSIDE, 1, 0)).astype(float)
        occ_img = heatmap_image(occ.T[::-1], "viridis", 0, 2)
        occ_img = np.repeat(np.repeat(occ_img, 24, 0), 24, 1)
        X = grid_points(g.origin, g.spacing, g.shape)
        err = (B.sample(X) - g.values.ravel()).reshape(g.shape) / B.step
        band = np.abs(g.values) < B.r
        e2 = np.where(band[:, :, k], err[:, :, k], np.nan).T[::-1]
        err_img = heatmap_image(e2, "RdBu", -0.5, 0.5, nan_color=(255, 255, 255))
        err_img = np.repeat(np.repeat(err_img, 4, 0), 4, 1)
        dense = g.values.astype(np.float32).nbytes
        caps = [
            f"bricks of the x-z layer through the centre: yellow kept\n({len(B.codes)} of {B.table.size} in all), "
            "teal dropped inside (-r),\npurple dropped outside (+r)",
            f"quantisation error in steps at the samples of z = 0.35\ninside the band (max over the grid "
            f"{np.nanmax(np.abs(err[band])):.3f}); white = outside",
        ]
        imgs = [occ_img, _with_bar(err_img, -0.5, 0.5, "RdBu", "error / step")]
        title = (
            f"8^3 bricks (7 cells + apron), r = 4 voxels, uint8: {B.nbytes / 1024:.0f} KiB vs dense float32 "
            f"{dense / 1024:.0f} KiB ({dense / B.nbytes:.1f}x smaller)"
        )
    except NotImplementedError as e:
        imgs, caps, title = [_missing((200, 200), f"Tasks 2-6 ({str(e)[:50]})")], [""], "Bricks"
    return Drawn(
        panels(imgs, caps, title=title),
        "Left: which bricks of one brick layer are stored and which are dropped (entirely more than r outside or "
        "inside). Right: the error of the bricked, 8-bit field at the grid samples inside the band, in "
        "quantisation steps 2r/255; it stays within half a step. The title gives the memory against a dense "
        "float32 grid.",
    )


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
        hi = float(max(np.percentile(e, 99) for e in errs))
        pics = [heatmap_image(im, "inferno", 0, hi, nan_color=(255, 255, 255)) for im in imgs]
        pics[-1] = _with_bar(pics[-1], 0, hi, "inferno", "angle error (°)")
        title = f"Normals from a {n}^3 grid of a torus: angle to the true normal at the sphere-traced hits, h = half a voxel"
    except NotImplementedError as e:
        pics, caps, title = [_missing(size, f"Tasks 6-8 ({str(e)[:50]})")], [""], "Gradients"
    return Drawn(
        panels(pics, caps, title=title),
        "The angle between the finite-difference normal of a sampled torus field and the exact normal, at every "
        "sphere-traced hit, same step h for both. The 4-tap tetrahedral stencil needs two thirds of the lookups "
        "but is only first-order accurate: its error is h times the mixed second derivatives of the field "
        "(largest where the torus curves diagonally to the grid axes), while central differences are second order.",
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
        mask[R["hit"] & ~gb.mask] = (220, 60, 40)
        mask[~R["hit"] & gb.mask] = (40, 90, 220)
        pics = [_u8(R["image"]), st, mask]
        caps = [
            "sphere-traced, 4-tap normals, Lambert",
            f"field evaluations per pixel (mean {steps.mean():.1f}; grazing rays\nnear silhouettes take the most)",
            f"hit mask vs rasterizer: {100 * diff:.2f}% of pixels differ\n(red: traced only, blue: rasterized only)",
        ]
        title = f"Sphere tracing the {g.shape[0]}^3 torus field"
    except NotImplementedError as e:
        pics, caps, title = [_missing(size, f"Tasks 2-8 ({str(e)[:50]})")], [""], "Sphere tracing"
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
        pics, caps = [], []
        for R in (0.15, 0.5, 1.0):
            est = soft_shadow(field, P, light, R, max_steps=48)
            imp = soft_shadow(field, P, light, R, max_steps=48, improved=True)
            truth = mesh_visibility(S, SF, P, light, R, n=rays)
            row = [est, imp, truth]
            pics += [_up(heatmap_image(v.reshape(n, n)[::-1], "gray", 0, 1), up) for v in row]
            caps += [
                f"R = {R}: course formula\nmean |error| {np.mean(np.abs(est - truth)):.3f}",
                f"R = {R}: improved\nmean |error| {np.mean(np.abs(imp - truth)):.3f}",
                f"R = {R}: Monte-Carlo truth\n({rays} rays per point)",
            ]
            err = np.abs(est - truth).reshape(n, n)[::-1]
            pics.append(_with_bar(_up(heatmap_image(err, "inferno", 0, 0.5), up), 0, 0.5, "inferno", "|V - truth|"))
            caps.append(f"R = {R}: per-pixel |error| (formula)\nmax {err.max():.2f}")
        page = panels(pics, caps, ncols=4, title="Soft shadows of a sphere mesh on the ground, seen from above")
    except NotImplementedError as e:
        page = panels([_missing((200, 200), f"Tasks 2-9 ({str(e)[:50]})")], [""], title="Soft shadows")
    return Drawn(
        page,
        "Visibility of a spherical light of radius R (rows) on the ground under a sphere mesh, seen from above: "
        "the course formula min d/(t tan alpha), the improved variant, a Monte-Carlo area-light truth cast with "
        "geomlib's watertight rays, and the per-pixel error of the formula. The formula reaches 0 wherever the "
        "ray to the light's centre is blocked, so its umbra is the hard shadow of the centre and only the "
        "outer half of the true penumbra survives: the error is a ring on the inner penumbra that widens with R.",
    )


@figure_name("sdf_ao_push")
def fig_ao_push(out: Path, quick: bool) -> Drawn:
    size = (120, 160) if quick else (260, 360)
    try:
        M = _camera([0.4, -4.2, 2.4], [0.0, 0.0, 0.4], size)
        R = render_sdf(csg_field, M, size[1], size[0], max_steps=96)
        hit = R["hit"]
        ao = np.full(hit.shape, np.nan)
        ao[hit] = ambient_occlusion(csg_field, R["points"][hit], R["normal"][hit], taps=5, delta=0.06)
        ao_img = _with_bar(heatmap_image(ao, "gray", 0, 1, nan_color=(190, 215, 240)), 0, 1, "gray", "AO")
        # push-out on the slice y = 0: random points, before (red) and after (blue)
        nx, nz = (160, 80) if quick else (300, 150)
        x = np.linspace(-2.2, 2.2, nx)
        z = np.linspace(-0.4, 1.4, nz)
        Xg, Zg = np.meshgrid(x, z, indexing="ij")
        d = csg_field(np.c_[Xg.ravel(), np.zeros(Xg.size), Zg.ravel()]).reshape(Xg.shape)
        sl = _slice_image(d, 0.5, 0.1, 2)
        rng = np.random.default_rng(3)
        Pp = np.c_[rng.uniform(-2, 2, 60), np.zeros(60), rng.uniform(-0.3, 1.1, 60)]
        inside = csg_field(Pp) < 0.05
        Pp = Pp[inside]
        Q = push_out(csg_field, Pp, radius=0.05, iterations=6)
        Q[:, 1] = 0.0  # draw on the slice (the scene is not symmetric in y, so points may leave it slightly)

        def to_px(A):
            i = np.clip(((A[:, 0] + 2.2) / 4.4 * (nx - 1)).round().astype(int) * 2, 0, 2 * nx - 1)
            j = np.clip(((1.4 - A[:, 2]) / 1.8 * (nz - 1)).round().astype(int) * 2, 0, 2 * nz - 1)
            return j, i

        for A, col in ((Pp, (220, 40, 40)), (Q, (30, 30, 200))):
            j, i = to_px(A)
            for dj in (-1, 0, 1):
                for di in (-1, 0, 1):
                    sl[np.clip(j + dj, 0, sl.shape[0] - 1), np.clip(i + di, 0, sl.shape[1] - 1)] = col
        pics = [ao_img, sl]
        caps = [
            "distance-field AO, 5 taps along the normal\n(1 = open; background light blue)",
            f"push-out: {len(Pp)} penetrating points (red) moved\nalong the normal to phi = 0.05 (blue)",
        ]
        page = panels(pics, caps, title="Ambient occlusion and collision push-out")
    except NotImplementedError as e:
        page = panels([_missing(size, f"Tasks 1, 7-9 ({str(e)[:50]})")], [""], title="AO and push-out")
    return Drawn(
        page,
        "Left: ambient occlusion of the analytic scene from five field taps along the normal. Right: points "
        "inside the solids (red) pushed out along the 4-tap gradient until they clear the surface by 0.05 "
        "(blue), on the slice y = 0.",
    )


@figure_name("sdf_3d")
def fig_view(quick: bool) -> MeshView:
    V, F, grid = _torus_grid(quick)
    bricks = compress_bricks(grid, band_voxels=4)
    # On the surface the exact distance is 0, so what the bricks return there is their error.
    err = np.abs(np.asarray(bricks.sample(V))) / bricks.step
    return MeshView(
        V, F, err, title="Brick SDF on the torus surface", up="z",
        cmap="viridis", scalar_name="|d| in quantisation steps",
        caption="Turn it: the torus, each vertex coloured by the distance the 8-bit brick field returns there "
        "(exactly 0 on the surface), in quantisation steps: trilinear lookups of stored samples.",
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
