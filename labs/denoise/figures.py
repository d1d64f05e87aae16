"""Figures of the denoise lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The
file is copied into ``labs/denoise/`` with the stubs, so there it renders *your* results: run
``make_figures`` once your functions work and compare with ``docs/figures/denoise/``.
Built-in meshes only (``geomlib.datasets``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import datasets
from geomlib.geometry import vertex_normals
from geomlib.labfigures import Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import colorbar, heat_colors, heatmap_image, line_plot, panels, with_colorbar
from geomlib.render import camera_pose, render

__all__ = ["make_figures", "make_view"]

LAB = "denoise"
CMAP = "YlOrRd"  # light at zero error, so the shape stays readable where the error vanishes
DIVERGING = "RdBu_r"  # signed offsets: blue sinks in, red sticks out
BACK = (0.75, 0.1, 0.1)  # colour of back faces: what shows through a crack
LOW_NOISE = 0.05  # noise (x mean edge length) at which the curvature leak dominates


def _passes(n: int) -> str:
    return f"{n} pass" if n == 1 else f"{n} passes"


def _blank(size: tuple[int, int]) -> np.ndarray:
    return np.full((size[1], size[0], 3), 255, np.uint8)


def _seam_normals(X: np.ndarray, F: np.ndarray, group: np.ndarray) -> np.ndarray:
    """Vertex normals computed across seams (copies share one normal), for smooth shading."""
    k = int(group.max()) + 1
    cnt = np.bincount(group, minlength=k)[:, None]
    Xw = np.stack([np.bincount(group, weights=X[:, i], minlength=k) for i in range(3)], axis=1) / cnt
    return vertex_normals(Xw, group[F])[group]


# --------------------------------------------------------------------------------------------
# 1. the lambda sequence with error heat maps


@figure_name("lambda_sequence")
def fig_lambda_sequence(out: Path, L, quick: bool) -> Drawn:
    size = (180, 125) if quick else (190, 134)
    V, F = datasets.torus(n_major=64, n_minor=32) if quick else datasets.torus(n_major=96, n_minor=48)
    lams = (0.3, 0.7, 1.0)
    pose = camera_pose(V, "three_quarter", size=size)
    images, captions = [], []
    ratios = {}
    for sigma in (0.3, LOW_NOISE):
        Vn, N = L.make_noisy(V, F, sigma, 0)
        results = [(f"noisy ({sigma} h)", Vn)] + [(f"λ = {lam}", L.denoise_vertices(Vn, F, N, lam)) for lam in lams]
        errs = [np.asarray(L.surface_error(V, F, X)) for _, X in results]
        e0 = errs[0].mean()
        ratios[sigma] = [e.mean() / e0 for e in errs[1:]]
        hi = float(np.percentile(errs[0], 99))
        if sigma == 0.3:
            for title, X in results:
                images.append(render(X, F, camera=pose, size=size))
                captions.append(title)
            images.append(_blank((90, size[1])))
            captions.append("")
        for (_, X), e in zip(results, errs, strict=True):
            images.append(render(X, F, camera=pose, size=size, colors=heat_colors(e, 0.0, hi, cmap=CMAP)))
            captions.append(f"{sigma} h noise: {e.mean() / e0:.2f}x")
        images.append(colorbar(0.0, hi, CMAP, label="dist / diag", height=size[1]))
        captions.append("")
    img = panels(images, captions, ncols=5, title="Laplacian denoising along clean normals, one pass (torus)")
    hi_r, lo_r = ratios[0.3], ratios[LOW_NOISE]
    return Drawn(
        img,
        "Noisy torus (Gaussian noise of 0.3 mean edge lengths h along random directions) and one denoising pass "
        "p' = p − λ ⟨δ, n⟩ n with λ = 0.3, 0.7, 1 (top), with each vertex's distance to the clean "
        "surface and the mean error relative to the noisy input (middle): it falls to "
        f"{hi_r[0]:.2f}x, {hi_r[1]:.2f}x and {hi_r[2]:.2f}x. Bottom: the same at low noise ({LOW_NOISE} h), where "
        f"λ = 0.3, 0.7, 1 end at {lo_r[0]:.2f}x, {lo_r[1]:.2f}x and {lo_r[2]:.2f}x: the curvature part of δ "
        "shrinks the whole torus, most on its outer rim where the mean curvature is largest.",
    )


# --------------------------------------------------------------------------------------------
# 2. error vs iterations


def _error_curves(L, V, F, sigma: float, iterations: int):
    Vn, N = L.make_noisy(V, F, sigma, 0)
    e0 = float(np.mean(L.surface_error(V, F, Vn)))
    xs, ys, labels = [], [], []
    for weights in ("uniform", "cotan"):
        for lam in (0.3, 0.7, 1.0):
            X, curve = Vn, [1.0]
            for _ in range(iterations):  # one pass at a time, to measure after each
                X = L.denoise_vertices(X, F, N, lam, weights=weights)
                curve.append(float(np.mean(L.surface_error(V, F, X))) / e0)
            xs.append(np.arange(iterations + 1))
            ys.append(np.array(curve))
            labels.append(f"{weights}, λ = {lam}")
    return xs, ys, labels


@figure_name("error_vs_iterations")
def fig_iterations(out: Path, L, quick: bool) -> Drawn:
    V, F = datasets.torus(n_major=64, n_minor=32) if quick else datasets.torus(n_major=96, n_minor=48)
    iterations = 3 if quick else 5
    size = (460, 340) if quick else (560, 400)
    plots, best = [], {}
    for sigma in (0.3, LOW_NOISE):
        xs, ys, labels = _error_curves(L, V, F, sigma, iterations)
        plots.append(
            line_plot(
                xs, ys, labels, xlabel="iterations", ylabel="mean error / noisy mean error",
                title=f"noise {sigma} x mean edge length", logy=True, size=size,
            )
        )  # fmt: skip
        i = int(np.argmin([y.min() for y in ys]))
        best[sigma] = (labels[i], int(np.argmin(ys[i])), float(ys[i].min()))
    img = panels(plots, ["high noise", "low noise"], ncols=2, title="Mean distance to the clean torus vs iterations")
    (b_hi, it_hi, r_hi), (b_lo, it_lo, r_lo) = best[0.3], best[LOW_NOISE]
    return Drawn(
        img,
        "Mean vertex distance to the clean surface after 0 to "
        f"{iterations} passes, relative to the noisy input (log scale), for uniform and cotangent weights. Every pass "
        "removes part of the noise but also shrinks the surface by the curvature part of δ, so each curve has a "
        f"best iteration count. At high noise the best here is {b_hi} after {_passes(it_hi)} ({r_hi:.2f}x); at low "
        f"noise it is {b_lo} after {_passes(it_lo)} ({r_lo:.2f}x), and large λ or many passes make it worse than "
        "doing nothing.",
    )


# --------------------------------------------------------------------------------------------
# 3. the offset map


def _noisy_sphere(L, quick: bool):
    """The latitude-longitude UV sphere of the offset-map figures (one seam) and its noisy copy:
    ``V, F, UV`` and ``Vn, N`` of ``make_noisy(V, F, 0.3, seed 0)``."""
    V, F, UV = datasets.uv_sphere(24, 48) if quick else datasets.uv_sphere(32, 64)
    Vn, N = L.make_noisy(V, F, 0.3, 0)
    return V, F, UV, Vn, N


def _sphere_offset_map(L, quick: bool):
    """:func:`_noisy_sphere`, its normal offsets ``s`` (no seam fix) and their 16-bit offset map of
    ``res x res`` texels: ``V, F, UV, Vn, N, s, res, (image, bias, scale)``."""
    V, F, UV, Vn, N = _noisy_sphere(L, quick)
    s = np.asarray(L.normal_offsets(L.laplacian_offsets(Vn, F), N))
    res = 192 if quick else 256
    return V, F, UV, Vn, N, s, res, L.bake_offset_map(Vn, F, UV, s, res, 16)


@figure_name("offset_map")
def fig_offset_map(out: Path, L, quick: bool) -> Drawn:
    V, F, UV, Vn, N, s, res, (img16, bias, scale) = _sphere_offset_map(L, quick)
    side = 220 if quick else 256
    grey = np.asarray(img16, np.float64) / 65535.0
    lim = float(np.abs(s).max())
    up = max(1, side // res)
    heat_map = heatmap_image(bias + scale * grey, DIVERGING, -lim, lim)
    pose = camera_pose(V, "three_quarter", size=(side, side))  # default margin: the whole sphere in frame
    bar = colorbar(-lim, lim, DIVERGING, label="offset s", height=side)
    images = [
        np.repeat(np.repeat(np.round(grey * 255).astype(np.uint8), up, axis=0), up, axis=1),
        with_colorbar(np.repeat(np.repeat(heat_map, up, axis=0), up, axis=1), bar),
        render(Vn, F, camera=pose, size=(side, side)),
        with_colorbar(render(Vn, F, camera=pose, size=(side, side), uv=UV, texture=heat_map, flat=True), bar),
    ]
    captions = [
        f"stored 16-bit map, {res}x{res} texels (grey = h)",
        "decoded offsets bias + scale h",
        "the noisy sphere",
        "its offset map on the surface",
    ]
    return Drawn(
        panels(images, captions, ncols=2, title="Offset map of a noisy UV sphere"),
        "The normal offsets s = ⟨δ, n⟩ of a noisy latitude-longitude sphere baked into a 16-bit offset map: "
        "u runs once around the sphere, v from the south pole (bottom row of the image) to the north pole (top). "
        f"bias = {bias:.4f} and scale = {scale:.4f} map the offsets onto [0, 1]. Bottom: the noisy sphere and the "
        "decoded map drawn on it as a texture: red vertices stick out of their neighbourhood, blue ones sink in "
        "(red dominates: the sphere's curvature adds about h²/(2R) to every offset); inside each triangle the map "
        "interpolates the three corner offsets linearly.",
    )


@figure_name("denoise_glsl")
def fig_glsl(out: Path, L, quick: bool) -> Drawn:
    """The map-driven pass by the NumPy route and by ``shaders/denoise.vert`` (task 7), and the difference."""
    V, F, UV, Vn, N, s, res, (img16, bias, scale) = _sphere_offset_map(L, quick)
    lam = 1.0
    X_np = np.asarray(L.denoise_with_map(Vn, F, UV, N, img16, bias, scale, lam), np.float64)
    X_gl = np.asarray(L.glsl_denoise_with_map(Vn, F, UV, N, img16, bias, scale, lam), np.float64)
    h = float(np.linalg.norm(Vn[F[:, 1]] - Vn[F[:, 0]], axis=1).mean())
    d = np.linalg.norm(X_np - X_gl, axis=1) / h  # in mean edge lengths of the noisy mesh
    moved = np.linalg.norm(X_np - Vn, axis=1) / h
    side = 220 if quick else 256
    pose = camera_pose(V, "three_quarter", size=(side, side))
    hi = max(float(d.max()), 1e-12)
    images = [
        render(X_np, F, camera=pose, size=(side, side)),
        render(X_gl, F, camera=pose, size=(side, side)),
        with_colorbar(
            render(X_gl, F, camera=pose, size=(side, side), colors=heat_colors(d, 0.0, hi, cmap=CMAP)),
            colorbar(0.0, hi, CMAP, label="|p' NumPy - p' GLSL| / h", height=side),
        ),
    ]
    captions = [
        f"NumPy route: denoise_with_map, λ = {lam:g}",
        "GLSL route: shaders/denoise.vert",
        f"difference per vertex, in mean edges h\nmax {d.max():.2g} h (a vertex moved {np.median(moved):.2g} h)",
    ]
    return Drawn.claimed(
        panels(images, captions, ncols=3, title="The vertex shader against the NumPy route (offset map of a sphere)"),
        "The noisy sphere of the offset-map figure denoised once from its {res}² 16-bit offset map, "
        "p' = p − λ (bias + scale h(uv)) n: left by the NumPy route (denoise_with_map), middle by the vertex "
        "shader (glsl_denoise_with_map, the seam fix on the CPU in both), right the distance between the two "
        "results per vertex in mean edge lengths h of the noisy mesh. They differ by at most {dmax:.2g} h "
        "(mean {dmean:.2g} h), float32 texture sampling against float64 bilinear reads, while the pass moves a "
        "vertex by {moved:.2g} h in the median: the two pictures are the same.",
        res=res, dmax=float(d.max()), dmean=float(d.mean()), moved=float(np.median(moved)),
    )  # fmt: skip


# --------------------------------------------------------------------------------------------
# 4. crack vs fixed seam


@figure_name("seam_crack")
def fig_seam(out: Path, L, quick: bool) -> Drawn:
    V, F, UV, Vn, N = _noisy_sphere(L, quick)
    _, _, group = L.weld_seams(V, F)
    res = 256 if quick else 512
    size = (260, 260) if quick else (340, 340)
    rows = []
    for weld, title in ((False, "no seam fix"), (True, "seam fix (weld=True)")):
        s = np.asarray(L.normal_offsets(L.laplacian_offsets(Vn, F, weld=weld), N))
        img, bias, scale = L.bake_offset_map(Vn, F, UV, s, res)
        X = np.asarray(L.denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7, weld=weld))
        k = int(group.max()) + 1
        centre = np.stack([np.bincount(group, weights=X[:, i], minlength=k) for i in range(3)], 1)
        centre /= np.bincount(group, minlength=k)[:, None]
        gap = float(np.linalg.norm(X - centre[group], axis=1).max() * 2)
        rows.append((title, X, gap))
    # The seam is the meridian at longitude 0 (plane y = 0, x > 0). The copies move apart along the normal, so
    # the crack is a step; looked at obliquely from either side, its open wall shows the red back faces inside.
    cams = [
        ((1.3, -0.5, 0.5), (0.95, 0.05, 0.25), (0.0, 0.0, 1.0)),
        ((1.3, 0.5, 0.5), (0.95, -0.05, 0.25), (0.0, 0.0, 1.0)),
    ]
    seam = np.flatnonzero(np.bincount(group)[group] > 1)  # vertices that have a copy
    # Context: the whole sphere seen from the seam's side, the seam's vertices in blue; the two
    # close-ups look at the middle of that meridian from either side.
    overview = ((4.9, -2.2, 0.5), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))  # near the equator: the poles sit on the outline
    images, captions = [], []
    for i, (title, X, gap) in enumerate(rows):
        nrm = _seam_normals(X, F, group)
        if i == 0:  # one overview: the close-ups' region tinted yellow
            near = np.linalg.norm(X - np.mean([c[1] for c in cams], axis=0), axis=1) < 0.3
            tint = np.where(near[:, None], (0.95, 0.8, 0.3), (0.78, 0.8, 0.85))
            images.append(
                render(X, F, normals=nrm, camera=overview, fov_deg=30, size=size, back_color=BACK, colors=tint,
                       highlight_points=seam, point_color=(0.1, 0.2, 0.7), point_radius=2.5)
            )  # fmt: skip
            captions.append("whole sphere (no fix): seam u = 0 = 1 in blue,\nthe close-ups' region in yellow")
        else:
            images.append(np.full((size[1], size[0], 3), 255, np.uint8))
            captions.append("")
        for j, cam in enumerate(cams):
            images.append(
                render(X, F, normals=nrm, camera=cam, fov_deg=30, size=size, back_color=BACK,
                       highlight_points=seam, point_color=(0.1, 0.2, 0.7), point_radius=2.0)
            )  # fmt: skip
            side = "from the u = 1 side" if j == 0 else "from the u = 0 side"
            captions.append(f"{title}, {side}" + (f"\nwidest gap {gap:.1e} (radius 1)" if j == 0 else ""))
    img = panels(images, captions, ncols=3, title="UV seam of a denoised sphere (map route, λ = 0.7)")
    return Drawn(
        img,
        "The latitude-longitude sphere is cut along the meridian u = 0 = 1 (left: the whole sphere, the seam in blue, "
        "the close-ups' region in yellow; middle and right: close-ups of the seam's middle from either side). Every vertex on the seam exists twice (and the "
        "poles once per triangle). Without the fix (top) each copy sees only its own side's neighbours and reads its "
        "own texels, so the copies move apart and the back faces (red) show through the crack (blue dots: the seam's "
        "vertices). Welding by position "
        "for the Laplacian and giving all copies the mean offset and normal (bottom) closes it exactly.",
    )


@figure_name("denoise_3d")
def fig_view(L, quick: bool) -> MeshView:
    V, F = datasets.torus(n_major=64, n_minor=32)
    Vn, N = L.make_noisy(V, F, 0.3, 0)
    X = L.denoise_vertices(Vn, F, N, 0.7)
    err = np.asarray(L.surface_error(V, F, X))
    return MeshView(
        X, F, err, title="Denoised torus (one pass, λ = 0.7)", up="z",
        cmap=CMAP, scalar_name="dist / diag",
        caption="Turn it: a noisy torus after one denoising pass (λ = 0.7), each vertex coloured by its distance "
        "to the clean surface as a fraction of the bounding-box diagonal (dist / diag, as in the figures).",
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (fig_lambda_sequence, fig_iterations, fig_offset_map, fig_seam, fig_glsl), fig_view,
    quick="Smaller meshes, images and iteration counts (for notebooks and smoke tests).",
)  # fmt: skip
