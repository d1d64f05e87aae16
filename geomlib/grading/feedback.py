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


def mesh_picture(ctx: Context, Ve, Fe, Vg, Fg) -> str | None:
    """Render expected and submitted meshes side by side with a distance heat map on the submission."""
    path = ctx.feedback_path()
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None
    try:
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
        return _relpath(path)
    except Exception:
        return None


def image_picture(ctx: Context, expected: np.ndarray, got: np.ndarray, per_pixel: np.ndarray) -> str | None:
    """Expected and submitted images in [0, 1] with a per-pixel difference heat map."""
    path = ctx.feedback_path()
    if path is None:
        return None
    try:
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
        return _relpath(path)
    except Exception:
        return None


def highlight_picture(ctx: Context, V, F, points, caption: str, *, suffix: str = "") -> str | None:
    """The input mesh with ``points`` ((k, 3) positions: the wrong vertices, edge midpoints, ...)
    marked in red, for failures that are about rows of a matrix rather than a drawn result."""
    path = ctx.feedback_path(suffix)
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None
    try:
        from geomlib import plot, render
        from geomlib.topology import triangulate_polygons

        V = np.asarray(V, float)
        F = np.asarray(F)
        T = F if F.ndim == 2 and F.shape[1] == 3 else triangulate_polygons(F)[0]
        P = np.asarray(points, float).reshape(-1, 3)
        size = (480, 400)
        views = [
            render.render(V, T, wireframe=len(T) < 5000, highlight_points=P, point_radius=5.0, size=size, camera=cam)
            for cam in ("three_quarter", "top")
        ]
        img = plot.panels(views, [caption, "seen from above"], title=ctx.label)
        plot.save_png(path, img)
        return _relpath(path)
    except Exception:
        return None
