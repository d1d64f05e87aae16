"""Feedback pictures for failed graded checks: reference | submission | difference heat map.

:func:`default_picture` chooses the picture for a wrong array (rows marked on a mesh, a grid as an
image, free points); :func:`failure_picture` draws it for a hand-written graded test, named after
the test (:func:`begin_test`, called by the grading plugin).

Pictures are a help, never a requirement: any problem making one (no OpenGL, a broken mesh) is
swallowed and the text message stands alone. Each picture is drawn in a forked child under a time
limit (:func:`_drawn_in_time`), so a huge wrong mesh costs seconds, not the run.
"""

from __future__ import annotations

import os
import re

import numpy as np

from geomlib.grading.context import Context


def count(n: int, one: str, many: str) -> str:
    """``1 vertex``, ``2 vertices``: a count with its noun in the right number (picture captions)."""
    return f"{n} {one if n == 1 else many}"


def _relpath(p) -> str:
    try:
        return os.path.relpath(p)
    except ValueError:
        return str(p)


#: Pictures drawn so far in this process (see :func:`_picture_allowed`).
_DRAWN = [0]


def _picture_allowed() -> bool:
    """False when pictures are switched off (``GEOMLIB_NO_FEEDBACK_PICTURES`` set) or when this run has
    drawn ``GEOMLIB_MAX_FEEDBACK_PICTURES`` already. The autograder sets a cap: a student needs a picture
    of the first failures of each task, and every picture costs seconds of the run and ~0.2 MB of
    results.json."""
    from geomlib.grading.settings import GradingSettings

    run = GradingSettings.build()
    if not run.pictures:
        return False
    return run.max_pictures is None or _DRAWN[0] < run.max_pictures


def _drawn_in_time(path, draw) -> str | None:
    """Run ``draw()`` (which writes ``path``) in a forked child, stopped after
    :data:`~geomlib.grading.tolerances.PICTURE_TIME_S` or the rest of the run's time budget."""
    import time

    from geomlib.grading import sandbox, tolerances

    if not _picture_allowed():
        return None
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
            if os.waitstatus_to_exitcode(status) != 0 or not os.path.exists(path):
                return None
            _DRAWN[0] += 1
            return _relpath(path)
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
    if path is None:
        return None

    def draw(V=V):  # the body rebinds V
        from geomlib import plot

        V = np.asarray(V, float)
        P = np.asarray(points, float).reshape(-1, 3)
        # Marked points are drawn by index: append them as extra (unreferenced) vertices.
        W = np.vstack([V, P])
        idx = np.arange(len(V), len(W))
        size = (480, 400)
        # A flat mesh is best seen from above; on a closed one, marks on the far side show from behind.
        # Zoomed out a little: a mark on the outline is not cut in half by the frame.
        extent = np.ptp(V, axis=0) if len(V) else np.zeros(3)
        second = (
            ("top", "seen from above")
            if extent[2] <= 1e-6 * max(extent.max(), 1e-12)
            else ("three_quarter_back", "seen from behind")
        )
        views = [
            _draw(
                W, F, wireframe=len(F) < 5000, highlight_points=idx, point_radius=5.0, size=size, camera=cam, zoom=0.92
            )
            for cam in ("three_quarter", second[0])
        ]
        img = plot.panels(views, [caption, second[1]], title=ctx.label)
        plot.save_png(path, img)

    return _drawn_in_time(path, draw)


def heat_on_mesh_picture(ctx: Context, V, F, values, caption: str, label: str) -> str | None:
    """The mesh coloured by a per-vertex error, with its colour bar beside it (two views)."""
    path = ctx.feedback_path()
    if path is None:
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
        ax.set_title(f"{ctx.label}\n{int(bad.sum())} of {len(e)} rows of {name} wrong", fontsize=9)
        fig.tight_layout()
        fig.savefig(path)
        plt.close(fig)

    return _drawn_in_time(path, draw)


# ------------------------------------------------------------------------------ which picture for a wrong array
# One choice for every comparison: the reference cases (through geomlib.grading.diagnose) and the
# hand-written graded tests (expect_close, a lab's own comparisons through failure_picture).


def default_picture(ctx: Context, inputs: dict, expected: dict, got: dict, *, atol: float = 1e-8, rtol: float = 0.0):
    """A picture for a wrong array: rows on the input mesh, or a grid output as an image, or free points.

    ``inputs`` holds the mesh, if any, as ``V`` and ``F`` (or ``faces``, ``Q``); ``expected`` and
    ``got`` map output names to arrays. A row is wrong where it differs by more than
    ``atol + rtol * |expected|``. Returns the picture's path, or None when none fits.
    """
    return (
        rows_on_mesh(ctx, inputs, expected, got, atol=atol, rtol=rtol)
        or grid_image(ctx, expected, got)
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


def grid_image(ctx: Context, expected: dict, got: dict):
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

        return image_picture(ctx, up(show(e3)), up(show(g3)), up(np.nan_to_num(err, nan=float(span.max()))))
    return None


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
        if per_vertex and bad.sum() > 20:
            err = np.linalg.norm(np.nan_to_num(g - e, nan=np.inf).reshape(len(e), -1), axis=1)
            err[~np.isfinite(err)] = np.nan
            return heat_on_mesh_picture(
                ctx, V, F, err, f"{int(bad.sum())} of {len(e)} rows of {name} wrong", f"|{name} error|"
            )
        if per_vertex:
            points, what = V[bad], f"{count(int(bad.sum()), 'vertex', 'vertices')} where {name} is wrong"
        else:
            points, what = e[bad], f"where the {count(int(bad.sum()), 'wrong row', 'wrong rows')} of {name} should be"
        return highlight_picture(ctx, V, F, points, what)
    return None


# ------------------------------------------------------------------------------ pictures for hand-written tests
# A hand-written graded test (tests/graded/<lab>/test_<lab>.py) has no case id and no feedback
# folder of its own: the grading plugin announces each graded test here (begin_test/end_test), and
# failure_picture names its pictures after the test and the compared output.

_TEST: dict = {}


def _file_safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.\-]+", "_", text).strip("_")


def begin_test(feedback_dir, lab: str, test_id: str) -> None:
    """Pictures of failures from now on go to ``feedback_dir/lab/<test_id>-<output>.png`` (grading plugin)."""
    _TEST.clear()
    _TEST.update(dir=feedback_dir, lab=lab, id=_file_safe(test_id) or "test", used=set())


def end_test() -> None:
    _TEST.clear()


def picture_context(label: str, name: str = "output") -> Context | None:
    """A :class:`Context` whose picture is this test's own, or None outside a graded test.

    Each call reserves a new file name (``<test>-<name>.png``, then ``-2``, ``-3``, ...), so several
    failing comparisons in one test never overwrite each other's picture.
    """
    if not _TEST or _TEST.get("dir") is None:
        return None
    stem = f"{_TEST['id']}-{_file_safe(name) or 'output'}"
    k, case_id = 1, stem
    while case_id in _TEST["used"]:
        k += 1
        case_id = f"{stem}-{k}"
    _TEST["used"].add(case_id)
    return Context(label=label, lab=_TEST["lab"], case_id=case_id, feedback_dir=_TEST["dir"])


def failure_picture(label: str, got, expected, *, name: str = "output", mesh=None, atol: float = 1e-8, rtol=0.0):
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
        return default_picture(ctx, inputs, {name: e}, {name: g}, atol=max(atol, 1e-12), rtol=rtol)
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
