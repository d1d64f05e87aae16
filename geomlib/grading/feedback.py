"""Feedback pictures for failed graded checks: reference | submission | difference heat map.

Pictures are a help, never a requirement: any problem making one (no OpenGL, a broken mesh) is
swallowed and the text message stands alone.
"""

from __future__ import annotations

import os

import numpy as np

from geomlib.grading.checks import Context


def _relpath(p) -> str:
    try:
        return os.path.relpath(p)
    except ValueError:
        return str(p)


def _drawn_in_time(path, draw) -> str | None:
    """Run ``draw()`` (which writes ``path``) in a forked child, stopped after
    :data:`~geomlib.grading.tolerances.PICTURE_TIME_S` or the rest of the run's time budget."""
    import time

    from geomlib.grading import sandbox, tolerances

    limit = tolerances.PICTURE_TIME_S
    left = sandbox.remaining_time()
    if left is not None:
        limit = min(limit, left - 1.0)
    if limit <= 0:
        return None
    pid = os.fork()
    if pid == 0:  # pragma: no cover - child
        code = 1
        try:
            draw()
            code = 0
        finally:
            os._exit(code)
    deadline = time.monotonic() + limit
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return _relpath(path) if os.waitstatus_to_exitcode(status) == 0 and os.path.exists(path) else None
        if time.monotonic() > deadline:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            return None
        time.sleep(0.02)


def mesh_picture(ctx: Context, Ve, Fe, Vg, Fg) -> str | None:
    """Render expected and submitted meshes side by side with a distance heat map on the submission."""
    path = ctx.feedback_path()
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None

    def draw():
        _draw_mesh(path, ctx, Ve, Fe, Vg, Fg)

    return _drawn_in_time(path, draw)


def _draw_mesh(path, ctx: Context, Ve, Fe, Vg, Fg) -> None:
    from scipy.spatial import cKDTree

    from geomlib import plot, render
    from geomlib.topology import triangulate_polygons

    Vg = np.asarray(Vg, float)
    Fe_t = triangulate_polygons(np.asarray(Fe))[0] if np.asarray(Fe).shape[1] != 3 else np.asarray(Fe)
    Fg_t = triangulate_polygons(np.asarray(Fg))[0] if np.asarray(Fg).shape[1] != 3 else np.asarray(Fg)
    d, _ = cKDTree(Ve).query(Vg)
    colors = plot.heat_colors(d, vmin=0.0, vmax=max(float(d.max()), 1e-12))
    size = (360, 300)
    a = render.render(Ve, Fe_t, wireframe=len(Fe_t) < 5000, size=size)
    b = render.render(Vg, Fg_t, wireframe=len(Fg_t) < 5000, size=size)
    c = render.render(Vg, Fg_t, colors=colors, size=size)
    bar = plot.colorbar(0.0, max(float(d.max()), 1e-12), cmap="inferno", label="distance", height=size[1])
    captions = ["expected", "submitted", f"distance to nearest expected vertex (max {d.max():.3g})", ""]
    img = plot.panels([a, b, c, bar], captions, title=ctx.label)
    plot.save_png(path, img)


def image_picture(ctx: Context, expected: np.ndarray, got: np.ndarray, per_pixel: np.ndarray) -> str | None:
    """Expected and submitted images in [0, 1] with a per-pixel difference heat map."""
    path = ctx.feedback_path()
    if path is None:
        return None

    def draw():
        _draw_image(path, ctx, expected, got, per_pixel)

    return _drawn_in_time(path, draw)


def _draw_image(path, ctx: Context, expected, got, per_pixel) -> None:
    from geomlib import plot

    def to_rgb(x):
        x = np.clip(x, 0, 1)
        if x.ndim == 2:
            x = np.repeat(x[..., None], 3, axis=2)
        return (x[..., :3] * 255).round().astype(np.uint8)

    vmax = max(float(per_pixel.max()), 1e-12)
    heat = plot.heatmap_image(per_pixel, cmap="inferno", vmin=0.0, vmax=vmax)
    bar = plot.colorbar(0.0, vmax, cmap="inferno", label="|difference|", height=max(128, heat.shape[0]))
    captions = ["expected", "submitted", "|difference|", ""]
    img = plot.panels([to_rgb(expected), to_rgb(got), heat, bar], captions, title=ctx.label)
    plot.save_png(path, img)
