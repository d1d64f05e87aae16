"""Feedback pictures for failed graded checks: reference | submission | difference heat map.

Pictures are a help, never a requirement: any problem making one (no OpenGL, a broken mesh) is
swallowed and the text message stands alone. Each picture is drawn in a forked child under a time
limit (:func:`_drawn_in_time`), so a huge wrong mesh costs seconds, not the run.
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


def _beside(img: np.ndarray, bar: np.ndarray, gap: int = 8) -> np.ndarray:
    """``bar`` (a colour bar) right next to ``img`` (its heat map), as one picture on white."""
    from geomlib import plot

    a, b = plot.to_rgb8(img), plot.to_rgb8(bar)
    h = max(a.shape[0], b.shape[0])

    def pad(x):
        top = (h - x.shape[0]) // 2
        out = np.full((h, x.shape[1], 3), 255, np.uint8)
        out[top : top + x.shape[0]] = x
        return out

    return np.hstack([pad(a), np.full((h, gap, 3), 255, np.uint8), pad(b)])


def _draw(V, F, **options):
    """Render triangles, or polygons with their true edges."""
    from geomlib import render

    F = np.asarray(F) if not isinstance(F, list) else F
    if isinstance(F, np.ndarray) and F.ndim == 2 and F.shape[1] == 3:
        return render.render(V, F, **options)
    return render.render_polygons(V, F, **options)


def mesh_picture(ctx: Context, Ve, Fe, Vg, Fg) -> str | None:
    """Render expected and submitted meshes side by side with a distance heat map on the submission."""
    path = ctx.feedback_path()
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None

    def draw(Vg=Vg):  # defaults: the body rebinds these names
        from scipy.spatial import cKDTree

        from geomlib import plot

        Vg = np.asarray(Vg, float)
        n_faces = len(Fe)
        d, _ = cKDTree(Ve).query(Vg)
        vmax = max(float(d.max()), 1e-12)
        colors = plot.heat_colors(d, vmin=0.0, vmax=vmax)
        size = (360, 300)
        a = _draw(Ve, Fe, wireframe=n_faces < 5000, size=size)
        b = _draw(Vg, Fg, wireframe=len(Fg) < 5000, size=size)
        c = _draw(Vg, Fg, colors=colors, size=size)
        bar = plot.colorbar(0.0, vmax, cmap="inferno", label="distance", height=size[1])
        captions = ["expected", "submitted", f"distance to the nearest expected vertex (max {d.max():.3g})"]
        img = plot.panels([a, b, _beside(c, bar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def image_picture(ctx: Context, expected: np.ndarray, got: np.ndarray, per_pixel: np.ndarray) -> str | None:
    """Expected and submitted images in [0, 1] with a per-pixel difference heat map."""
    path = ctx.feedback_path()
    if path is None:
        return None

    def draw(expected=expected, got=got, per_pixel=per_pixel):  # the body rebinds these names
        from geomlib import plot

        def to_rgb(x):
            x = np.clip(x, 0, 1)
            if x.ndim == 2:
                x = np.repeat(x[..., None], 3, axis=2)
            return (x[..., :3] * 255).round().astype(np.uint8)

        k = max(1, 256 // max(per_pixel.shape[:2]))  # small images: blow up, nearest texel
        if k > 1:
            expected, got, per_pixel = (
                np.repeat(np.repeat(x, k, axis=0), k, axis=1) for x in (expected, got, per_pixel)
            )
        vmax = max(float(per_pixel.max()), 1e-12)
        heat = plot.heatmap_image(per_pixel, cmap="inferno", vmin=0.0, vmax=vmax)
        bar = plot.colorbar(0.0, vmax, cmap="inferno", label="|difference|", height=max(128, heat.shape[0]))
        captions = ["expected", "submitted", "|difference| per pixel"]
        img = plot.panels([to_rgb(expected), to_rgb(got), _beside(heat, bar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def highlight_picture(ctx: Context, V, F, points, caption: str, *, suffix: str = "") -> str | None:
    """The input mesh with ``points`` ((k, 3) positions: the wrong vertices, edge midpoints, ...)
    marked in red, for failures that are about rows of a matrix rather than a drawn result."""
    path = ctx.feedback_path(suffix)
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None

    def draw(V=V):  # the body rebinds V
        from geomlib import plot

        V = np.asarray(V, float)
        P = np.asarray(points, float).reshape(-1, 3)
        # Marked points are drawn by index: append them as extra (unreferenced) vertices.
        W = np.vstack([V, P])
        idx = np.arange(len(V), len(W))
        size = (480, 400)
        views = [
            _draw(W, F, wireframe=len(F) < 5000, highlight_points=idx, point_radius=5.0, size=size, camera=cam)
            for cam in ("three_quarter", "top")
        ]
        img = plot.panels(views, [caption, "seen from above"], title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def heat_on_mesh_picture(ctx: Context, V, F, values, caption: str, label: str) -> str | None:
    """The mesh coloured by a per-vertex error, with its colour bar beside it (two views)."""
    path = ctx.feedback_path()
    if path is None or os.environ.get("GEOMLIB_NO_FEEDBACK_PICTURES"):
        return None

    def draw(values=values):  # the body rebinds values
        from geomlib import plot

        values = np.asarray(values, float)
        vmax = max(float(np.nanmax(values)), 1e-12)
        colors = plot.heat_colors(np.nan_to_num(values, nan=vmax), vmin=0.0, vmax=vmax)
        size = (440, 380)
        views = [_draw(V, F, colors=colors, size=size, camera=cam) for cam in ("three_quarter", "top")]
        bar = plot.colorbar(0.0, vmax, cmap="inferno", label=label, height=size[1])
        img = plot.panels([views[0], _beside(views[1], bar)], [caption, "seen from above"], title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def points_picture(ctx: Context, expected: np.ndarray, got: np.ndarray, name: str) -> str | None:
    """Expected and submitted ``(n, 2)`` or ``(n, 3)`` points with no mesh to draw them on (e.g. light-space
    ``(u, v, z)``), seen from above: the first two coordinates, each wrong row joined to where it should be,
    coloured by its error."""
    path = ctx.feedback_path()
    if path is None:
        return None

    def draw():
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.collections import LineCollection

        e, g = np.asarray(expected, float), np.asarray(got, float)
        err = np.linalg.norm(np.nan_to_num(g - e, nan=np.inf, posinf=np.inf, neginf=np.inf), axis=1)
        bad = ~(err <= 1e-8)
        fig, ax = plt.subplots(figsize=(6.4, 5.6), dpi=100)
        ax.scatter(e[:, 0], e[:, 1], s=10, c="#1f77b4", label="expected", zorder=2)
        gf = np.isfinite(g[:, :2]).all(axis=1)
        ax.scatter(g[gf, 0], g[gf, 1], s=14, c="#d62728", marker="x", label="submitted", zorder=3)
        both = bad & gf
        if both.any():
            shown = np.where(np.isfinite(err[both]), err[both], np.nan)
            vmax = max(float(np.nanmax(shown)) if np.isfinite(shown).any() else 1.0, 1e-12)
            lines = LineCollection(
                np.stack([e[both, :2], g[both, :2]], axis=1), cmap="inferno", linewidths=1.5, zorder=1
            )
            lines.set_array(np.nan_to_num(shown, nan=vmax))
            lines.set_clim(0.0, vmax)
            ax.add_collection(lines)
            fig.colorbar(lines, ax=ax, label=f"|{name} error|")
        ax.set_xlabel(f"{name}[:, 0]")
        ax.set_ylabel(f"{name}[:, 1]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(loc="best", fontsize=8)
        ax.set_title(f"{ctx.label}\n{int(bad.sum())} of {len(e)} rows of {name} are wrong", fontsize=9)
        fig.tight_layout()
        fig.savefig(path)
        plt.close(fig)

    return _drawn_in_time(path, draw)
