"""Feedback pictures for failed graded checks: reference | submission | difference heat map.

:func:`default_picture` chooses the picture for a wrong array (rows marked on a mesh, a grid as an
image, free points); :func:`failure_picture` draws it for a hand-written graded test, named after
the test (:func:`begin_test`, called by the grading plugin).

Pictures are a help, never a requirement: any problem making one (no OpenGL, a broken mesh) is
swallowed and the text message stands alone. Each picture is drawn in a forked child under a time
limit (:func:`_drawn_in_time`), so a huge wrong mesh costs seconds, not the run.
"""

from __future__ import annotations

import re

import numpy as np

from geomlib.grading.context import Context, picture_stem, set_running_test
from geomlib.grading.picture_run import (  # noqa: F401 - re-exported: the run's picture budget
    _ASYNC,
    _CAP,
    _DRAWN,
    _FAILED,
    _HELD,
    _PENDING,
    MAX_DRAWING,
    PICTURE_CHOICES,
    _drawn_in_time,
    _finish_pending,
    _picture_allowed,
    _relpath,
    picture_wanted,
    pictures_for_run,
    without_pictures,
)


def count(n: int, one: str, many: str) -> str:
    """``1 vertex``, ``2 vertices``: a count with its noun in the right number (picture captions)."""
    return f"{n} {one if n == 1 else many}"


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
    if path is None:
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
        captions = ["expected", "yours", f"difference: distance to the nearest expected vertex (max {d.max():.3g})"]
        img = plot.panels([a, b, _beside(c, bar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def image_picture(
    ctx: Context, expected: np.ndarray, got: np.ndarray, per_pixel: np.ndarray, *, unit: str = ""
) -> str | None:
    """Expected and submitted images in [0, 1] with a per-pixel difference heat map (``per_pixel``, in
    ``unit`` when given: the unit the message uses)."""
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
        label = f"|difference| ({unit})" if unit else "|difference|"
        bar = plot.colorbar(0.0, vmax, cmap="inferno", label=label, height=max(128, heat.shape[0]))
        captions = ["expected", "yours", f"difference: {label} per pixel"]
        img = plot.panels([to_rgb(expected), to_rgb(got), _beside(heat, bar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def _mesh_edges(F, limit: int = 6000) -> np.ndarray:
    """The unique edges of triangles, quads or polygons (a list of index sequences), at most ``limit``
    of them (an even sample of a larger mesh: the see-through outline is for orientation only)."""
    if isinstance(F, np.ndarray) and F.ndim == 2:
        E = np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)
    else:
        E = np.array([(f[i], f[(i + 1) % len(f)]) for f in F for i in range(len(f))], dtype=np.int64).reshape(-1, 2)
    E = np.unique(np.sort(E.astype(np.int64), axis=1), axis=0)
    if len(E) > limit:
        E = E[np.linspace(0, len(E) - 1, limit).astype(np.int64)]
    return E


def _error_cmap():
    """inferno without its palest yellow: the largest errors stay visible on a white page."""
    from matplotlib import colormaps
    from matplotlib.colors import ListedColormap

    return ListedColormap(colormaps["inferno"](np.linspace(0.0, 0.82, 256)), name="inferno_dark")


def _errors(e: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Per-row error ``|g - e|``; a row with NaN or inf where the other has a number counts as the
    largest finite error (or 1); NaN where NaN is expected is no error."""
    e, g = np.asarray(e, float), np.asarray(g, float)
    with np.errstate(invalid="ignore"):
        d = np.where((np.isnan(e) & np.isnan(g)) | (e == g), 0.0, np.abs(g - e)).reshape(len(e), -1)
    err = np.sqrt(np.sum(np.where(np.isfinite(d), d, 0.0) ** 2, axis=1))
    bad = ~np.isfinite(d).all(axis=1)
    if bad.any():
        err[bad] = float(err[~bad].max()) if (~bad).any() and err[~bad].max() > 0 else 1.0
    return err


def rows_picture(
    ctx: Context, V, F, expected, got, caption: str, *, err=None, values=None, yours: str = "", suffix: str = ""
) -> str | None:
    """Wrong rows on a mesh, in three panels seen the same way: **expected** (where the rows should
    be, blue), **yours** (where the submission puts them, orange) and **difference** (each wrong row
    joined to where it should be, coloured by its error). The mesh is a see-through wireframe, so
    markers inside a solid (edge points of an octahedron) stay visible.

    Parameters
    ----------
    expected, got : (k, 3) array_like
        Positions of the wrong rows, expected and submitted (equal for values that are not
        positions: the vertex of each wrong row).
    err : (k,) array_like, optional
        The rows' errors (default ``|got - expected|``).
    values : ((k,), (k,)), optional
        Expected and submitted values per row, to colour the first two panels (one scale), when the
        rows are not positions (``got`` then equals ``expected``).
    caption, yours : str
        Captions of the first two panels.
    """
    path = ctx.feedback_path(suffix)
    if path is None:
        return None

    def draw():
        from matplotlib import colormaps

        from geomlib import plot
        from geomlib.grading.scatter import Panel, view

        W = np.asarray(V, float)
        P = np.asarray(expected, float).reshape(-1, 3)
        G = np.asarray(got, float).reshape(-1, 3)
        e = _errors(P, G) if err is None else np.asarray(err, float).ravel()
        e = np.where(np.isfinite(e), e, float(np.nanmax(np.where(np.isfinite(e), e, 0.0))) or 1.0)
        ok = np.isfinite(G).all(axis=1)
        extent = np.ptp(W, axis=0) if len(W) else np.ones(3)
        flat = bool(extent[2] <= 1e-6 * max(extent.max(), 1e-12))
        E = _mesh_edges(F)
        lo, hi = W.min(axis=0), W.max(axis=0)
        span = max(float((hi - lo).max()), 1e-12)
        # far-off submitted rows are clipped to a box a little larger than the mesh
        box_lo, box_hi = lo - 0.25 * span, hi + 0.25 * span
        Gc = np.clip(np.where(ok[:, None], G, P), box_lo, box_hi)
        vmax = max(float(e.max()) if len(e) else 0.0, 1e-12)
        n = len(P)
        captions = [
            caption,
            yours or ("yours" if values is None else "yours (colour: your value)"),
            f"difference: |error| per row (max {vmax:.3g})",
        ]
        # One orthographic view for the three panels (matplotlib's 3D angles: from above for a flat mesh).
        to2 = view(90, -90) if flat else view(24, -58)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        c2 = corners @ to2
        pad = 0.08 * max(float(np.ptp(c2, axis=0).max()), 1e-12)
        axes = [Panel(c2.min(axis=0) - pad, c2.max(axis=0) + pad, axes=False) for _ in range(3)]
        r = 0.55 * np.sqrt(60 if n <= 50 else 16 if n <= 500 else 6)
        cmap = _error_cmap()
        if values is not None:
            ve, vg = (np.asarray(x, float).ravel() for x in values)
            both = np.concatenate([ve[np.isfinite(ve)], vg[np.isfinite(vg)]]) if n else np.zeros(1)
            vlo, vhi = (float(both.min()), float(both.max())) if both.size else (0.0, 1.0)
            span_v = vhi - vlo if vhi > vlo else 1.0
            viridis = colormaps["viridis"]
        for ax in axes:  # the see-through wireframe: markers inside a solid stay visible
            ax.segments(W[E[:, 0]] @ to2, W[E[:, 1]] @ to2, (0.74, 0.74, 0.74), width=0.7)
        P2, G2 = P @ to2, Gc @ to2
        if values is None:
            axes[0].dots(P2, "#1f77b4", radius=r, edge=(1.0, 1.0, 1.0))
            axes[1].crosses(G2[ok], "#ff7f0e", radius=1.3 * r, width=max(1.0, 0.45 * r), edge=(0, 0, 0))
            axes[2].segments(P2, G2, cmap(np.clip(e / vmax, 0.0, 1.0)), width=1.6)
        else:
            axes[0].dots(P2, viridis(np.clip((ve - vlo) / span_v, 0.0, 1.0)), radius=r, edge=(1.0, 1.0, 1.0))
            vg_ = np.nan_to_num(vg, nan=vhi)
            axes[1].dots(P2, viridis(np.clip((vg_ - vlo) / span_v, 0.0, 1.0)), radius=r, edge=(1.0, 1.0, 1.0))
        axes[2].dots(P2, cmap(np.clip(e / vmax, 0.0, 1.0)), radius=r, edge=(0.5, 0.5, 0.5))
        a, b, c = (ax.image() for ax in axes)
        if values is not None:
            b = _beside(b, plot.colorbar(vlo, vhi, cmap="viridis", label="value (expected | yours)", height=b.shape[0]))
        c = _beside(c, plot.colorbar(0.0, vmax, cmap=cmap, label="|error|", height=c.shape[0]))
        plot.save_png(path, plot.panels([a, b, c], captions, title=ctx.label))

    return _drawn_in_time(path, draw)


def highlight_picture(ctx: Context, V, F, points, caption: str, *, got=None, suffix: str = "") -> str | None:
    """The mesh with ``points`` ((k, 3): where wrong vertices, edge points... should be) marked:
    expected | yours | difference (:func:`rows_picture`). ``got`` ((k, 3)): where the submission has
    them; without it, each point's nearest vertex of ``V`` (the submitted mesh's closest offer)."""
    P = np.asarray(points, float).reshape(-1, 3)
    yours = "yours"
    if got is None and not _picture_allowed():
        got = P  # no picture this time (rows_picture counts it as held back): no nearest vertices either
    if got is None:
        Vf = np.asarray(V, float)
        yours = "the nearest vertex of the mesh to each"
        if len(Vf) and len(P):
            from scipy.spatial import cKDTree

            got = Vf[cKDTree(Vf).query(P)[1]]
        else:
            got = P
    return rows_picture(ctx, V, F, P, got, caption, yours=yours, suffix=suffix)


def heat_on_mesh_picture(ctx: Context, V, F, expected, got, err, caption: str, label: str) -> str | None:
    """Per-vertex values on the mesh, three renders from one camera: expected and submitted values
    (one colour scale; rows of several numbers by their length) and the per-vertex error, each with
    its colour bar."""
    path = ctx.feedback_path()
    if path is None:
        return None

    def draw():
        from geomlib import plot

        def size_of(x):  # rows of several numbers are coloured by their length
            return np.linalg.norm(x, axis=1) if x.shape[1] > 1 else x[:, 0]

        E, G = (np.asarray(x, float).reshape(len(V), -1) for x in (expected, got))
        ve, vg = size_of(E), size_of(G)
        fin = np.concatenate([ve[np.isfinite(ve)], vg[np.isfinite(vg)]])
        lo, hi = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 1.0)
        hi = hi if hi > lo else lo + 1e-12
        e = np.asarray(err, float)
        vmax = max(float(np.nanmax(e)) if np.isfinite(e).any() else 1.0, 1e-12)
        size = (400, 340)
        flat = np.ptp(np.asarray(V, float), axis=0)
        cam = "top" if flat[2] <= 1e-6 * max(flat.max(), 1e-12) else "three_quarter"
        a = _draw(V, F, colors=plot.heat_colors(np.nan_to_num(ve, nan=hi), vmin=lo, vmax=hi, cmap="viridis"),
                  size=size, camera=cam)  # fmt: skip
        b = _draw(V, F, colors=plot.heat_colors(np.nan_to_num(vg, nan=hi), vmin=lo, vmax=hi, cmap="viridis"),
                  size=size, camera=cam)  # fmt: skip
        c = _draw(V, F, colors=plot.heat_colors(np.nan_to_num(e, nan=vmax), vmin=0.0, vmax=vmax), size=size, camera=cam)
        vbar = plot.colorbar(
            lo, hi, cmap="viridis", label="|row| (length)" if E.shape[1] > 1 else "value", height=size[1]
        )
        ebar = plot.colorbar(0.0, vmax, cmap="inferno", label=label, height=size[1])
        captions = ["expected", "yours", f"difference: {caption}"]
        img = plot.panels([a, _beside(b, vbar), _beside(c, ebar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def points_picture(ctx: Context, expected: np.ndarray, got: np.ndarray, name: str) -> str | None:
    """Expected and submitted ``(n, 2)`` or ``(n, 3)`` points with no mesh to draw them on (e.g. light-space
    ``(u, v, z)``), seen from above (the first two coordinates) in three panels: expected | yours |
    difference (each wrong row joined to where it should be, coloured by its error)."""
    path = ctx.feedback_path()
    if path is None:
        return None

    def draw():
        from geomlib import plot
        from geomlib.grading.scatter import Panel

        e, g = np.asarray(expected, float), np.asarray(got, float)
        err = _errors(e, g)
        bad = ~(err <= 1e-8)
        gf = np.isfinite(g[:, :2]).all(axis=1)
        captions = [
            f"expected {name}",
            f"yours ({int(bad.sum())} of {len(e)} rows wrong)",
            f"difference: |{name} error| (max {err.max():.3g})",
        ]
        pts = np.vstack([e[:, :2], g[gf, :2]])
        pts = pts[np.isfinite(pts).all(axis=1)]
        lo, hi = (pts.min(axis=0), pts.max(axis=0)) if len(pts) else (np.zeros(2), np.ones(2))
        pad = 0.05 * max(float((hi - lo).max()), 1e-12)
        vmax = max(float(err.max()), 1e-12)
        cmap = _error_cmap()
        axes = [Panel(lo - pad, hi + pad, f"{name}[:, 0]", f"{name}[:, 1]") for _ in range(3)]
        ef = np.isfinite(e[:, :2]).all(axis=1)
        axes[0].dots(e[ef, :2], "#1f77b4", radius=1.8)
        axes[1].crosses(g[gf, :2], "#ff7f0e")
        both = bad & gf & ef
        axes[2].dots(e[~bad & ef, :2], (0.75, 0.75, 0.75), radius=1.4)
        colors = cmap(np.clip(err / vmax, 0.0, 1.0))
        axes[2].segments(e[both, :2], g[both, :2], colors[both])
        axes[2].dots(e[bad & ef, :2], colors[bad & ef], radius=2.0)
        a, b, c = (ax.image() for ax in axes)
        bar = plot.colorbar(0.0, vmax, cmap=cmap, label=f"|{name} error|", height=c.shape[0])
        img = plot.panels([a, b, _beside(c, bar)], captions, title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


# ------------------------------------------------------------------------------ which picture for a wrong array
# One choice for every comparison: the reference cases (through geomlib.grading.diagnose) and the
# hand-written graded tests (expect_close, a lab's own comparisons through failure_picture).


def default_picture(
    ctx: Context, inputs: dict, expected: dict, got: dict, *, atol: float = 1e-8, rtol: float = 0.0, unit: str = ""
):
    """A picture for a wrong array: rows on the input mesh, or a grid output as an image, or free points.

    ``inputs`` holds the mesh, if any, as ``V`` and ``F`` (or ``faces``, ``Q``); ``expected`` and
    ``got`` map output names to arrays. A row is wrong where it differs by more than
    ``atol + rtol * |expected|``; ``unit`` names the unit of the values (a grid's difference heat
    map says it). Returns the picture's path, or None when none fits.
    """
    if ctx.feedback_dir is None or not picture_wanted():
        return None
    return (
        rows_on_mesh(ctx, inputs, expected, got, atol=atol, rtol=rtol)
        or grid_image(ctx, expected, got, unit=unit)
        or free_points(ctx, inputs, expected, got, atol=atol, rtol=rtol)
    )


def _as_float(x) -> np.ndarray | None:
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        return None


def free_points(ctx: Context, inputs: dict, expected: dict, got: dict, *, atol: float = 1e-8, rtol: float = 0.0):
    """Points with no mesh to draw them on (light-space (u, v, z), sample positions, uv coordinates): a
    scatter of the expected and submitted points, wrong ones joined to where they should be."""
    if "V" in inputs:
        return None  # on a mesh: rows_on_mesh's business
    for name, e in expected.items():
        e = np.asarray(e)
        g = _as_float(got.get(name))
        if g is None or e.dtype.kind != "f" or e.ndim != 2 or e.shape[1] not in (2, 3) or len(e) < 2:
            continue
        if g.shape != e.shape or np.isclose(g, e, rtol=rtol, atol=atol).all():
            continue
        return points_picture(ctx, e, g, name)
    return None


def grid_image(ctx: Context, expected: dict, got: dict, *, unit: str = ""):
    """Expected and submitted (h, w, c) grids (displacements, positions, maps) as images, with the
    per-texel error as a heat map; channels are scaled by the expected values' range."""
    for name, e in expected.items():
        e = np.asarray(e)
        if e.dtype.kind == "b" and e.ndim == 2 and min(e.shape) >= 2:
            e = e.astype(float)  # a per-cell choice (diagonals): drawn as 0/1, the wrong cells lit
        g = _as_float(got.get(name))
        # (h, w, c) grids, or (h, w) scalar images; an (n, 3) list of points is not an image.
        if (
            g is None
            or e.dtype.kind != "f"
            or e.ndim not in (2, 3)
            or g.shape != e.shape
            or min(e.shape[:2]) < (2 if e.ndim == 3 else 8)
        ):
            continue
        if e.ndim == 3 and e.shape[2] not in (1, 2, 3, 4):
            continue
        e3 = e if e.ndim == 3 else e[..., None]
        g3 = g if g.ndim == 3 else g[..., None]
        err = np.abs(g3 - e3).max(axis=2)
        if not (err > 1e-12).any():
            continue
        lo = e3.min(axis=(0, 1))
        span = np.maximum(e3.max(axis=(0, 1)) - lo, 1e-12)

        def show(x, lo=lo, span=span):
            x = np.clip((x - lo) / span, 0, 1)
            if x.shape[2] == 2:
                x = np.concatenate([x, np.zeros_like(x[..., :1])], axis=2)
            return x[..., :3] if x.shape[2] >= 3 else x[..., 0]

        k = max(1, 256 // max(e.shape[:2]))  # small grids: one block of k x k pixels per texel

        def up(x, k=k):
            return np.repeat(np.repeat(x, k, axis=0), k, axis=1)

        return image_picture(ctx, up(show(e3)), up(show(g3)), up(np.nan_to_num(err, nan=float(span.max()))), unit=unit)
    return None


def _positions_like(e: np.ndarray, V: np.ndarray) -> bool:
    """Whether per-vertex ``(n, 3)`` rows look like positions near the mesh (moved vertices), not
    directions (unit normals) or other vectors: within the mesh's box grown by its size."""
    lo, hi = V.min(axis=0), V.max(axis=0)
    span = max(float((hi - lo).max()), 1e-12)
    fin = e[np.isfinite(e).all(axis=1)]
    unit = len(fin) and np.allclose(np.linalg.norm(fin, axis=1), 1.0, atol=1e-6)
    return bool(len(fin)) and not unit and bool(((fin >= lo - span) & (fin <= hi + span)).all())


def rows_on_mesh(ctx: Context, inputs: dict, expected: dict, got: dict, *, atol: float = 1e-8, rtol: float = 0.0):
    """A wrong array of points or per-vertex values on an input mesh: the mesh with the wrong rows marked
    (at the vertex for per-vertex rows, else where the point should be), or coloured by the error when
    more than 20 per-vertex rows are wrong.

    Per-vertex outputs have one row per vertex of any shape (``(n,)`` values, ``(n, 3)`` positions,
    ``(n, 4, 4)`` quadrics); other outputs are drawn only as ``(k, 3)`` points.
    """
    V = inputs.get("V")
    F = next((inputs[k] for k in ("F", "faces", "Q") if k in inputs), None)
    if V is None or F is None:
        return None
    V = np.asarray(V, float)
    if V.ndim != 2 or V.shape[1] != 3:
        return None
    for name, e in expected.items():
        e = np.asarray(e)
        g = _as_float(got.get(name))
        if g is None or e.dtype.kind != "f" or e.ndim == 0 or g.shape != e.shape:
            continue
        per_vertex = len(e) == len(V)
        if not per_vertex and not (e.ndim == 2 and e.shape[1] == 3):
            continue
        bad = ~np.isclose(g, e, rtol=rtol, atol=atol).reshape(len(e), -1).all(axis=1)
        if not bad.any():
            continue
        err = _errors(e, g)
        if per_vertex and bad.sum() > 20:
            return heat_on_mesh_picture(
                ctx, V, F, e, g, err, f"{int(bad.sum())} of {len(e)} rows of {name} wrong", f"|{name} error|"
            )
        if e.ndim == 2 and e.shape[1] == 3 and (not per_vertex or _positions_like(e, V)):
            # points (odd vertices, edge points, moved vertices): where they should be and where they are
            what = f"expected: where the {count(int(bad.sum()), 'wrong row', 'wrong rows')} of {name} should be"
            return rows_picture(
                ctx, V, F, e[bad], g[bad], what, err=err[bad], yours=f"yours: where your code puts them ({name})"
            )
        what = f"expected: {count(int(bad.sum()), 'vertex', 'vertices')} where {name} is wrong (colour: value)"
        size = (
            np.linalg.norm(e.reshape(len(e), -1), axis=1),
            np.linalg.norm(np.nan_to_num(g).reshape(len(g), -1), axis=1),
        )
        values = (size[0][bad], size[1][bad])
        return rows_picture(ctx, V, F, V[bad], V[bad], what, err=err[bad], values=values)
    return None


# ------------------------------------------------------------------------------ pictures for hand-written tests
# A hand-written graded test (tests/graded/<lab>/test_<lab>.py) has no case id and no feedback
# folder of its own: the grading plugin announces each graded test here (begin_test/end_test), and
# failure_picture names its pictures after the test and the compared output.

_TEST: dict = {}


def _file_safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.\-]+", "_", text).strip("_")


def begin_test(feedback_dir, lab: str, test_id: str) -> None:
    """Pictures of failures from now on go to ``feedback_dir/lab/<test>--<output>.png`` and every
    other picture's name starts with the test's too (grading plugin; ``test_id``: the test's name,
    or its case's id for a reference test, see :func:`geomlib.grading.context.picture_name`)."""
    _TEST.clear()
    stem = picture_stem(test_id)
    _TEST.update(dir=feedback_dir, lab=lab, id=stem, used=set())
    set_running_test(stem)


def end_test() -> None:
    _TEST.clear()
    set_running_test(None)


def picture_context(label: str, name: str = "output") -> Context | None:
    """A :class:`Context` whose picture is this test's own, or None outside a graded test.

    Each call reserves a new file name (``<test>--<name>.png``, then ``-2``, ``-3``, ...), so several
    failing comparisons in one test never overwrite each other's picture.
    """
    if not _TEST or _TEST.get("dir") is None:
        return None
    stem = _file_safe(name) or "output"  # the Context puts the test's name first
    k, case_id = 1, stem
    while case_id in _TEST["used"]:
        k += 1
        case_id = f"{stem}-{k}"
    _TEST["used"].add(case_id)
    return Context(label=label, lab=_TEST["lab"], case_id=case_id, feedback_dir=_TEST["dir"])


def failure_picture(
    label: str, got, expected, *, name: str = "output", mesh=None, atol: float = 1e-8, rtol=0.0, unit: str = ""
):
    """The feedback picture of a failed comparison in a hand-written graded test, or None.

    Parameters
    ----------
    label : str
        The comparison as the message names it (the picture's title).
    got, expected : array_like
        Submitted and expected values of the output ``name``.
    mesh : (V, F) or (V, F, rows), optional
        The mesh the rows of the output belong to (one row per vertex, or points near it, or a
        single point of shape (3,)): the wrong rows are marked on it. ``rows`` (indices or a mask)
        names the vertices of the rows when the output covers only some of them. Without a mesh,
        grids and images are drawn as images, ``(n, 2)`` and ``(n, 3)`` arrays as points.
    atol, rtol : float
        The comparison's tolerance: rows within it are not marked.
    unit : str
        The unit of the values as the message gives them (``"texels"``): pass the values in it, and
        the picture's difference is labelled with it, so text and picture agree.
    """
    ctx = picture_context(label, name)
    if ctx is None:
        return None
    try:
        e, g = np.asarray(expected, float), _as_float(got)
        inputs = {} if mesh is None else {"V": mesh[0], "F": mesh[1]}
        if mesh is not None and len(mesh) == 3 and g is not None and g.shape == e.shape:
            # rows of some vertices only (the interior ones, say): spread onto all vertices, the others right
            rows = np.asarray(mesh[2])
            rows = np.flatnonzero(rows) if rows.dtype == bool else rows.astype(np.int64)
            if len(rows) == len(e):
                full_e = np.zeros((len(mesh[0]), *e.shape[1:]))
                full_g = full_e.copy()
                full_e[rows], full_g[rows] = e, g
                e, g = full_e, full_g
        if mesh is not None and e.shape == (3,) and len(mesh[0]) != 3 and g is not None and g.shape == (3,):
            e, g = e[None], g[None]  # one point (a vertex, an edge point): marked where it should be
        return default_picture(ctx, inputs, {name: e}, {name: g}, atol=max(atol, 1e-12), rtol=rtol, unit=unit)
    except Exception:  # noqa: BLE001 - a picture is a help: the message stands alone
        return None


def marked_picture(label: str, V, F, points, caption: str, *, name: str = "points") -> str | None:
    """For a hand-written graded test: the mesh ``(V, F)`` with ``points`` ((k, 3): where vertices
    should be and are not, say) marked in red, or None outside a graded test."""
    ctx = picture_context(label, name)
    if ctx is None:
        return None
    try:
        return highlight_picture(ctx, V, F, points, caption)
    except Exception:  # noqa: BLE001 - a picture is a help: the message stands alone
        return None
