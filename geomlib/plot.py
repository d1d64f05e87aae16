"""Figure helpers: image panels with captions, colour maps and bars, line plots, deterministic PNGs.

Longer than most modules (about 740 lines) on purpose: it is the one place every figure of every
lab is composed, and its parts (panels, text, colour maps and bars, line plots, the index page)
share the same uint8 canvas conventions and font handling.

Everything returns plain ``(h, w, 3)`` uint8 arrays, so renders (:mod:`geomlib.render`), plots
and colour bars compose freely with :func:`panels` and are written with :func:`save_png`.
Text uses the DejaVu Sans font bundled with matplotlib, drawn by Pillow; line plots use
matplotlib's Agg canvas directly (no pyplot state, no display). Output bytes are deterministic:
the same inputs give the same PNG file.

:class:`Figure` is the record that figure builders (the gallery, every lab's ``figures.py``)
return so the figures command can index them; how a lab's builders become its ``make_figures``
is :mod:`geomlib.labfigures`.

Examples
--------
>>> import numpy as np
>>> from geomlib.plot import panels, heat_colors
>>> a = np.zeros((40, 60, 3), np.uint8)
>>> panels([a, a], ["left", "right"], title="Two panels").shape[2]
3
>>> heat_colors([0.0, 0.5, 1.0]).shape
(3, 3)
"""

from __future__ import annotations

import functools
import importlib.util
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geomlib.validate import MeshError, as_array, as_image, check_float, check_int

__all__ = [
    "Figure",
    "to_rgb8",
    "panels",
    "colorbar",
    "heat_colors",
    "heatmap_image",
    "with_colorbar",
    "line_plot",
    "save_png",
    "write_index",
]


@dataclass(frozen=True)
class Figure:
    """One generated figure.

    Attributes
    ----------
    path : Path
        The PNG file, or an ``.html`` interactive 3D view (:mod:`geomlib.viewer`), which the index
        shows in a frame across the page.
    caption : str
        One or two sentences saying what the figure shows.
    lab : str
        The lab it belongs to (``"gallery"`` for the dataset gallery).
    claims : Claims, optional
        The caption's template and the numbers its builder measured (:class:`geomlib.labfigures.Claims`);
        None for a caption without numbers.
    """

    path: Path
    caption: str
    lab: str
    claims: object = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))


# --------------------------------------------------------------------------------------------
# Images and fonts
# --------------------------------------------------------------------------------------------


@functools.lru_cache(maxsize=16)
def _font(size: int, bold: bool = False):
    """DejaVu Sans from matplotlib's bundled fonts (same glyphs everywhere); Pillow's default otherwise.

    Laid out by Pillow's basic engine, never libraqm: Pillow uses raqm when the system happens to have
    FriBiDi, and raqm places glyphs differently (measured: every figure with text 2 px narrower in a
    Debian 12 root without FriBiDi than on a machine with it), so the committed figures would depend on
    a system library. The basic engine ships inside Pillow's wheel with FreeType: the same pixels on
    every machine. (The course's text is left-to-right Latin, which needs no shaping.)
    """
    from PIL import ImageFont

    try:
        # matplotlib.get_data_path() without importing matplotlib (slow): <package>/mpl-data.
        spec = importlib.util.find_spec("matplotlib")
        data = Path(spec.origin).parent / "mpl-data"
        name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
        return ImageFont.truetype(str(data / "fonts" / "ttf" / name), size, layout_engine=ImageFont.Layout.BASIC)
    except Exception:  # matplotlib missing its data files: still produce a figure
        return ImageFont.load_default(size)


def to_rgb8(image, name: str = "image", *, where: str = "to_rgb8", background=(255, 255, 255)) -> np.ndarray:
    """Any image array as ``(h, w, 3)`` uint8.

    Parameters
    ----------
    image : (h, w), (h, w, 1), (h, w, 3) or (h, w, 4) array_like
        uint8 (0..255), bool, or floats in [0, 1]. Alpha is composited over ``background``.
    name, where : str
        Used in error messages.
    background : RGB uint8
        Colour behind transparent pixels.

    Returns
    -------
    (h, w, 3) uint8
    """
    a = as_image(image, name, channels=(1, 3, 4), where=where)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.dtype == np.uint8:
        f = a.astype(np.float64) / 255.0
    elif a.dtype == np.bool_:
        f = a.astype(np.float64)
    else:
        f = as_array(a, name, dtype=np.float64, where=where)
        lo, hi = float(f.min()), float(f.max())
        if a.dtype.kind in "iu" and lo >= 0 and hi <= 255:
            f = f / 255.0
        elif lo < -1e-6 or hi > 1 + 1e-6:
            raise MeshError(f"{where}: {name} values span [{lo:.6g}, {hi:.6g}]; float images must lie in [0, 1]")
    f = np.clip(f, 0.0, 1.0)
    if f.shape[2] == 1:
        f = np.repeat(f, 3, axis=2)
    if f.shape[2] == 4:
        alpha = f[:, :, 3:]
        f = f[:, :, :3] * alpha + np.asarray(background, dtype=np.float64)[None, None, :3] / 255.0 * (1 - alpha)
    return np.round(f * 255.0).astype(np.uint8)


def _wrap(text: str, font, max_width: float) -> list[str]:
    """Greedy word wrap to ``max_width`` pixels (explicit newlines kept)."""
    lines: list[str] = []
    for para in str(text).split("\n"):
        words = para.split(" ")
        cur = ""
        for w in words:
            trial = w if not cur else f"{cur} {w}"
            if font.getlength(trial) <= max_width or not cur:
                cur = trial
            else:
                lines.append(cur)
                cur = w
        lines.append(cur)
    # A single word longer than the cell is cut with an ellipsis rather than overflowing.
    out = []
    for ln in lines:
        while font.getlength(ln) > max_width and len(ln) > 1:
            ln = ln[:-2] + "…"
        out.append(ln)
    return out


def _line_height(font) -> int:
    asc, desc = font.getmetrics()
    return int(asc + desc + 2)


# --------------------------------------------------------------------------------------------
# Panels
# --------------------------------------------------------------------------------------------


def panels(
    images: Sequence,
    captions: Sequence[str] | None = None,
    ncols: int | None = None,
    title: str | None = None,
    pad: int = 12,
    *,
    font_size: int = 15,
    title_size: int = 20,
    background=(255, 255, 255),
) -> np.ndarray:
    """Lay images out in a grid with a caption under each and an optional title.

    Parameters
    ----------
    images : sequence of images
        Any mix of sizes and formats accepted by :func:`to_rgb8`; each sits centred in its cell
        (cells are as large as the largest image).
    captions : sequence of str, optional
        One caption per image (wrapped to the cell width; ``"\\n"`` forces a break).
    ncols : int, optional
        Number of columns (default: all in one row up to 4 images, else about square).
    title : str, optional
        Bold title above the grid.
    pad : int
        Spacing in pixels around and between cells.
    font_size, title_size : int
        Text sizes in pixels.
    background : RGB uint8
        Page colour.

    Returns
    -------
    (H, W, 3) uint8
    """
    from PIL import Image, ImageDraw

    where = "panels"
    if isinstance(images, np.ndarray) and images.ndim in (2, 3) and images.dtype != object:
        images = [images]
    images = list(images)
    if not images:
        raise MeshError(f"{where}: images is empty, expected at least one image")
    imgs = [to_rgb8(im, f"images[{i}]", where=where) for i, im in enumerate(images)]
    n = len(imgs)
    if captions is not None:
        if isinstance(captions, str):
            captions = [captions]
        captions = [str(c) for c in captions]
        if len(captions) != n:
            raise MeshError(f"{where}: got {len(captions)} captions for {n} images; expected one caption per image")
    ncols = (
        (n if n <= 4 else int(np.ceil(np.sqrt(n))))
        if ncols is None
        else check_int(ncols, "ncols", minimum=1, where=where)
    )
    ncols = min(ncols, n)
    nrows = int(np.ceil(n / ncols))
    pad = check_int(pad, "pad", minimum=0, maximum=1000, where=where)
    font_size = check_int(font_size, "font_size", minimum=4, maximum=200, where=where)
    title_size = check_int(title_size, "title_size", minimum=4, maximum=300, where=where)
    bg = tuple(int(c) for c in background)[:3]

    cw = max(im.shape[1] for im in imgs)
    ch = max(im.shape[0] for im in imgs)
    font = _font(font_size)
    lh = _line_height(font)
    wrapped = [_wrap(c, font, cw) for c in captions] if captions is not None else [[] for _ in imgs]
    cap_h = max(len(w) for w in wrapped) * lh + (pad // 2 if captions is not None else 0)
    tfont = _font(title_size, bold=True)
    tlh = _line_height(tfont)
    W = ncols * cw + (ncols + 1) * pad
    tlines = _wrap(title, tfont, W - 2 * pad) if title else []
    th = len(tlines) * tlh + (pad if tlines else 0)
    H = th + nrows * (ch + cap_h) + (nrows + 1) * pad

    page = Image.new("RGB", (W, H), bg)
    draw = ImageDraw.Draw(page)
    text_rgb = (30, 30, 30) if sum(bg) > 384 else (235, 235, 235)
    for k, line in enumerate(tlines):
        x = (W - tfont.getlength(line)) / 2
        draw.text((x, pad + k * tlh), line, font=tfont, fill=text_rgb)
    for i, (im, lines) in enumerate(zip(imgs, wrapped, strict=True)):
        r, c = divmod(i, ncols)
        x0 = pad + c * (cw + pad)
        y0 = th + pad + r * (ch + cap_h + pad)
        page.paste(Image.fromarray(im), (x0 + (cw - im.shape[1]) // 2, y0 + (ch - im.shape[0]) // 2))
        for k, line in enumerate(lines):
            x = x0 + (cw - font.getlength(line)) / 2
            draw.text((x, y0 + ch + pad // 2 + k * lh), line, font=font, fill=text_rgb)
    return np.asarray(page, dtype=np.uint8).copy()


# --------------------------------------------------------------------------------------------
# Colour maps
# --------------------------------------------------------------------------------------------


def _cmap(name: str, where: str):
    import matplotlib

    if isinstance(name, matplotlib.colors.Colormap):  # a map of one's own (a cut inferno)
        return name
    if not isinstance(name, str) or name not in matplotlib.colormaps:
        some = ", ".join(sorted(n for n in matplotlib.colormaps if not n.endswith("_r"))[:12])
        raise MeshError(f"{where}: unknown colour map {name!r}; use a matplotlib name such as {some}, ...")
    return matplotlib.colormaps[name]


def _range(values: np.ndarray, vmin, vmax, where: str) -> tuple[float, float]:
    finite = values[np.isfinite(values)]
    lo = check_float(vmin, "vmin", where=where) if vmin is not None else (float(finite.min()) if finite.size else 0.0)
    hi = check_float(vmax, "vmax", where=where) if vmax is not None else (float(finite.max()) if finite.size else 1.0)
    if hi < lo:
        raise MeshError(f"{where}: vmax ({hi:.6g}) is smaller than vmin ({lo:.6g})")
    return lo, hi


def _normalise(values: np.ndarray, lo: float, hi: float) -> np.ndarray:
    if hi == lo:  # constant data: the middle of the map, not an arbitrary end
        return np.full(values.shape, 0.5)
    return np.clip((values - lo) / (hi - lo), 0.0, 1.0)


def heat_colors(values, vmin: float | None = None, vmax: float | None = None, cmap: str = "inferno") -> np.ndarray:
    """Map scalars (per vertex, per face, ...) to RGB colours for :func:`geomlib.render.render`.

    Parameters
    ----------
    values : (n,) array_like
        Finite scalars, e.g. per-vertex error.
    vmin, vmax : float, optional
        Colour range (default: the data range); values outside are clamped.
    cmap : str
        Matplotlib colour map name.

    Returns
    -------
    (n, 3) float64
        sRGB colours in [0, 1].
    """
    where = "heat_colors"
    v = as_array(values, "values", shape=(None,), where=where)
    lo, hi = _range(v, vmin, vmax, where)
    return np.asarray(_cmap(cmap, where)(_normalise(v, lo, hi))[:, :3], dtype=np.float64)


def heatmap_image(
    array2d, cmap: str = "inferno", vmin: float | None = None, vmax: float | None = None, *, nan_color=(220, 220, 220)
) -> np.ndarray:
    """Colour a 2-D array (e.g. a per-pixel difference) as an image.

    Parameters
    ----------
    array2d : (h, w) array_like
        Scalars; NaN marks pixels without data, drawn in ``nan_color``.
    cmap : str
        Matplotlib colour map name.
    vmin, vmax : float, optional
        Colour range (default: the range of the finite data).
    nan_color : RGB uint8
        Colour of NaN pixels.

    Returns
    -------
    (h, w, 3) uint8
    """
    where = "heatmap_image"
    a = as_array(array2d, "array2d", shape=(None, None), finite=False, where=where)
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise MeshError(f"{where}: array2d is empty (shape {a.shape})")
    if np.isinf(a).any():
        r, c = (int(i) for i in np.argwhere(np.isinf(a))[0])
        raise MeshError(f"{where}: array2d[{r}, {c}] is {a[r, c]}; use NaN to mark missing pixels")
    lo, hi = _range(a, vmin, vmax, where)
    nan = np.isnan(a)
    rgb = _cmap(cmap, where)(_normalise(np.where(nan, lo, a), lo, hi))[:, :, :3]
    out = np.round(rgb * 255.0).astype(np.uint8)
    out[nan] = np.asarray(nan_color, dtype=np.uint8)[:3]
    return out


def colorbar(
    vmin: float,
    vmax: float,
    cmap: str = "viridis",
    label: str | None = None,
    height: int = 256,
    *,
    bar_width: int = 18,
    ticks: int = 5,
    font_size: int = 13,
    background=(255, 255, 255),
) -> np.ndarray:
    """A vertical colour bar with tick labels, to sit next to heat-map panels.

    Parameters
    ----------
    vmin, vmax : float
        Range of the colour map (as passed to :func:`heat_colors` / :func:`heatmap_image`).
    cmap : str or matplotlib Colormap
        Matplotlib colour map name (or the map itself).
    label : str, optional
        Quantity and unit, written above the bar.
    height : int
        Height of the whole image in pixels.
    bar_width : int
        Width of the colour strip in pixels.
    ticks : int
        About how many tick labels (chosen at round numbers).
    font_size : int
        Text size in pixels.
    background : RGB uint8
        Page colour.

    Returns
    -------
    (height, w, 3) uint8
        ``w`` fits the tick labels.
    """
    from matplotlib.ticker import MaxNLocator
    from PIL import Image, ImageDraw

    where = "colorbar"
    lo, hi = check_float(vmin, "vmin", where=where), check_float(vmax, "vmax", where=where)
    if hi < lo:
        raise MeshError(f"{where}: vmax ({hi:.6g}) is smaller than vmin ({lo:.6g})")
    if hi == lo:
        s = 0.5 * (abs(lo) or 1.0)
        lo, hi = lo - s, hi + s
    height = check_int(height, "height", minimum=48, maximum=8192, where=where)
    bar_width = check_int(bar_width, "bar_width", minimum=2, maximum=500, where=where)
    ticks = check_int(ticks, "ticks", minimum=2, maximum=50, where=where)
    font = _font(check_int(font_size, "font_size", minimum=4, maximum=200, where=where))
    cm = _cmap(cmap, where)
    lh = _line_height(font)
    pad = max(4, lh // 2)
    top = pad + (lh + pad // 2 if label else 0) + lh // 2
    bottom = height - pad - lh // 2
    if bottom - top < 8:
        raise MeshError(
            f"{where}: height {height} is too small for the labels; use at least {height + 8 - (bottom - top)}"
        )
    vals = [
        float(t)
        for t in MaxNLocator(nbins=ticks - 1).tick_values(lo, hi)
        if lo - 1e-12 * (hi - lo) <= t <= hi + 1e-12 * (hi - lo)
    ]
    span = max(abs(lo), abs(hi))
    labels = [f"{(0.0 if abs(t) < 1e-12 * span else t):.4g}" for t in vals]
    label_w = max((font.getlength(s) for s in labels), default=0)
    x0 = pad
    tick_len = 5
    W = int(np.ceil(x0 + bar_width + tick_len + 4 + label_w + pad))
    if label:
        W = max(W, int(np.ceil(font.getlength(label))) + 2 * pad)
    page = Image.new("RGB", (W, height), tuple(int(c) for c in background)[:3])
    draw = ImageDraw.Draw(page)
    n = bottom - top
    strip = np.round(cm(np.linspace(1.0, 0.0, n))[:, :3] * 255).astype(np.uint8)
    page.paste(Image.fromarray(np.repeat(strip[:, None, :], bar_width, axis=1)), (x0, top))
    ink = (40, 40, 40)
    draw.rectangle([x0 - 1, top - 1, x0 + bar_width, bottom], outline=ink)
    for t, s in zip(vals, labels, strict=True):
        y = bottom - 1 - (t - lo) / (hi - lo) * (n - 1)
        draw.line([(x0 + bar_width, y), (x0 + bar_width + tick_len, y)], fill=ink, width=1)
        draw.text((x0 + bar_width + tick_len + 4, y), s, font=font, fill=ink, anchor="lm")
    if label:
        draw.text((pad, pad), label, font=font, fill=ink)
    return np.asarray(page, dtype=np.uint8).copy()


# --------------------------------------------------------------------------------------------
# Line plots
# --------------------------------------------------------------------------------------------


def with_colorbar(image, bar, *, gap: int = 6, background=(255, 255, 255)) -> np.ndarray:
    """Put a colour bar right beside its heat-map image (vertically centred), as one image.

    Use it instead of giving the bar its own :func:`panels` cell, which would be as wide as the
    largest panel and leave a blank column.
    """
    a = to_rgb8(image, "image", where="with_colorbar")
    b = to_rgb8(bar, "bar", where="with_colorbar")
    h = max(a.shape[0], b.shape[0])

    out = np.empty((h, a.shape[1] + gap + b.shape[1], 3), np.uint8)
    out[:] = np.asarray(background, np.uint8)
    ta, tb = (h - a.shape[0]) // 2, (h - b.shape[0]) // 2
    out[ta : ta + a.shape[0], : a.shape[1]] = a
    out[tb : tb + b.shape[0], a.shape[1] + gap :] = b
    return out


def line_plot(
    xs_list,
    ys_list,
    labels: Sequence[str] | None = None,
    xlabel: str = "",
    ylabel: str = "",
    title: str | None = None,
    logy: bool = False,
    *,
    logx: bool = False,
    size: tuple[int, int] = (640, 420),
    dpi: int = 100,
    markers: bool = True,
    legend: str = "below",
) -> np.ndarray:
    """Plot one or more curves (convergence, timings, error vs. level) to an image.

    Parameters
    ----------
    xs_list, ys_list : sequence of (k_i,) array_like
        One x and one y array per curve (a single pair of 1-D arrays is one curve).
    labels : sequence of str, optional
        Legend entries, one per curve.
    xlabel, ylabel, title : str
        Axis labels and title.
    logy, logx : bool
        Logarithmic axes (the data must then be positive).
    size : (width, height)
        Image size in pixels.
    dpi : int
        Resolution used to size the text.
    markers : bool
        Mark the data points. Every curve gets its own marker and dash pattern, and earlier curves
        are drawn on top, so curves that coincide stay distinguishable.
    legend : {"below", "inside"}
        Legend under the axes (never over the curves), or matplotlib's best spot inside.

    Returns
    -------
    (height, width, 3) uint8

    Notes
    -----
    Log axes are labelled with plain numbers (``0.6``, ``2``, ``50``), not ``6×10⁻¹``.
    """
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    where = "line_plot"
    if len(xs_list) and np.ndim(xs_list[0]) == 0:
        xs_list, ys_list = [xs_list], [ys_list]
    xs_list, ys_list = list(xs_list), list(ys_list)
    if len(xs_list) != len(ys_list) or not xs_list:
        raise MeshError(
            f"{where}: got {len(xs_list)} x arrays and {len(ys_list)} y arrays; expected one of each per curve"
        )
    if labels is not None:
        labels = [labels] if isinstance(labels, str) else list(labels)
        if len(labels) != len(xs_list):
            raise MeshError(f"{where}: got {len(labels)} labels for {len(xs_list)} curves")
    curves = []
    for i, (x, y) in enumerate(zip(xs_list, ys_list, strict=True)):
        x = as_array(x, f"xs_list[{i}]", shape=(None,), where=where)
        y = as_array(y, f"ys_list[{i}]", shape=(None,), where=where)
        if len(x) != len(y):
            raise MeshError(f"{where}: curve {i} has {len(x)} x values but {len(y)} y values")
        if logy and (y <= 0).any():
            raise MeshError(
                f"{where}: ys_list[{i}] has a value {y[y <= 0][0]:.6g} <= 0, which a log y axis cannot show"
            )
        if logx and (x <= 0).any():
            raise MeshError(
                f"{where}: xs_list[{i}] has a value {x[x <= 0][0]:.6g} <= 0, which a log x axis cannot show"
            )
        curves.append((x, y))
    if not isinstance(size, Sequence) or len(size) != 2:
        raise MeshError(f"{where}: size must be (width, height) in pixels, got {size!r}")
    w = check_int(size[0], "size[0]", minimum=64, maximum=8192, where=where)
    h = check_int(size[1], "size[1]", minimum=64, maximum=8192, where=where)
    dpi = check_int(dpi, "dpi", minimum=20, maximum=600, where=where)
    if legend not in ("below", "inside"):
        raise MeshError(f"{where}: legend must be 'below' or 'inside', got {legend!r}")

    style = {
        "svg.hashsalt": "geomlib",
        "font.family": "DejaVu Sans",
        "font.size": 10.0,
        "axes.grid": True,
        "grid.alpha": 0.35,
        "axes.spines.top": False,
        "axes.spines.right": False,
        "path.simplify": False,
    }
    with matplotlib.rc_context(style):
        fig = MplFigure(figsize=(w / dpi, h / dpi), dpi=dpi, facecolor="white")
        canvas = FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        shapes, dashes = "osD^vP*X", ["-", "--", "-.", ":"]
        for i, (x, y) in enumerate(curves):
            ax.plot(
                x,
                y,
                marker=shapes[i % len(shapes)] if markers else None,
                markersize=4 + 1.5 * (i % 3),
                markerfacecolor="none" if i else None,
                linestyle=dashes[i % len(dashes)],
                linewidth=2.2 if i == 0 else 1.5,
                zorder=10 + len(curves) - i,
                label=labels[i] if labels else None,
            )

        def plain(v, _pos):
            return f"{v:.10g}"

        for k, (axis, log) in enumerate(((ax.xaxis, logx), (ax.yaxis, logy))):
            if log:
                (ax.set_xscale if axis is ax.xaxis else ax.set_yscale)("log")
                values = np.concatenate([c[k] for c in curves])
                decades = np.log10(values.max() / values.min()) if len(values) else 0.0
                # 1-2-5 ticks over short ranges; only powers of ten where those would crowd.
                subs = (1.0, 2.0, 5.0) if decades <= 1.6 else (1.0,)
                axis.set_major_locator(LogLocator(base=10, subs=subs))
                axis.set_major_formatter(FuncFormatter(plain))
                axis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title)
        if labels and legend == "inside":
            ax.legend(frameon=False)
        elif labels:
            # As many columns as fit the width (about 7 px per character at 9 pt, plus the key; generous,
            # because the legend is centred on the axes, which sit right of the y label).
            entry = max(7 * len(t) + 55 for t in labels)
            ncol = int(max(1, min(3, len(labels), (w - 20) // entry)))
            ax.legend(frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=ncol, fontsize=9)
        fig.tight_layout()
        canvas.draw()
        img = np.asarray(canvas.buffer_rgba())[:, :, :3].copy()
    return img


# --------------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------------


def save_png(path, image) -> Path:
    """Write an image as PNG without metadata, so equal images give equal bytes.

    Parameters
    ----------
    path : str or Path
        Target file; missing folders are created.
    image : array_like
        Anything :func:`to_rgb8` accepts (grey and RGBA are flattened to RGB on white).

    Returns
    -------
    Path
        ``path``.
    """
    from PIL import Image

    path = Path(path)
    if path.suffix.lower() != ".png":
        raise MeshError(f"save_png: {path} does not end in .png")
    img = to_rgb8(image, where="save_png")
    path.parent.mkdir(parents=True, exist_ok=True)
    # No pnginfo, dpi or timestamps: Pillow then writes only IHDR/IDAT/IEND, a function of the pixels.
    Image.fromarray(img).save(path, format="PNG", compress_level=6, optimize=False)
    return path


# --------------------------------------------------------------------------------------------
# Index pages
# --------------------------------------------------------------------------------------------

_INDEX_CSS = """
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; margin: 2rem auto; max-width: 1200px;
       padding: 0 1rem; color: #222; background: #fafafa; }
h1 { font-size: 1.6rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.25rem; margin-top: 2.2rem; border-bottom: 1px solid #ddd; padding-bottom: 0.3rem; }
nav a { margin-right: 1rem; color: #2a5db0; text-decoration: none; }
.grid { display: grid; grid-template-columns: repeat(auto-fill, minmax(340px, 1fr)); gap: 1.2rem; }
figure { margin: 0; background: #fff; border: 1px solid #e3e3e3; border-radius: 6px; padding: 0.6rem; }
figure img { width: 100%; height: auto; display: block; }
figcaption { font-size: 0.9rem; line-height: 1.35; margin-top: 0.5rem; color: #333; }
figcaption code { font-size: 0.8rem; color: #777; }
figure.wide { grid-column: 1 / -1; }
figure iframe { width: 100%; height: 480px; border: 0; display: block; }
"""


def _rel(path: Path, out_dir: Path) -> str:
    import os

    return Path(os.path.relpath(Path(path).resolve(), Path(out_dir).resolve())).as_posix()


def write_index(figures: Sequence[Figure], out_dir, *, title: str = "Course figures") -> Path:
    """Write ``index.html`` and ``index.md`` showing every figure with its caption, grouped by lab.

    Labs appear in the order of their first figure; image paths are relative to ``out_dir``, and the
    page needs no external assets.

    Parameters
    ----------
    figures : sequence of Figure
        As returned by :func:`geomlib.gallery.build_gallery` and the labs' ``make_figures``.
    out_dir : str or Path
        Folder that receives the two index files (created if missing).
    title : str
        Page heading.

    Returns
    -------
    Path
        The ``index.html`` file.
    """
    import html

    where = "write_index"
    out = Path(out_dir)
    figs = list(figures)
    for i, f in enumerate(figs):
        if not isinstance(f, Figure):
            raise MeshError(f"{where}: figures[{i}] is a {type(f).__name__}, expected geomlib.plot.Figure")
    groups: dict[str, list[Figure]] = {}
    for f in figs:
        groups.setdefault(f.lab, []).append(f)
    out.mkdir(parents=True, exist_ok=True)

    def anchor(lab: str) -> str:
        return "lab-" + "".join(ch if ch.isalnum() else "-" for ch in lab)

    h = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(title)}</title>",
        f"<style>{_INDEX_CSS}</style>",
        "</head>",
        "<body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{len(figs)} figure(s) in {len(groups)} group(s).</p>",
        "<nav>" + "".join(f'<a href="#{anchor(lab)}">{html.escape(lab)}</a>' for lab in groups) + "</nav>",
    ]
    md = [f"# {title}", "", f"{len(figs)} figure(s) in {len(groups)} group(s).", ""]
    for lab, items in groups.items():
        h.append(f'<h2 id="{anchor(lab)}">{html.escape(lab)}</h2>')
        h.append('<div class="grid">')
        md += [f"## {lab}", ""]
        for f in items:
            rel = _rel(f.path, out)
            src = html.escape(rel, quote=True)
            cap = html.escape(f.caption)
            if f.path.suffix.lower() == ".html":  # an interactive 3D view (geomlib.viewer): the page in a frame
                h.append(
                    f'<figure class="wide"><iframe src="{src}" title="{html.escape(f.caption, quote=True)}" '
                    f'loading="lazy"></iframe><figcaption>{cap} <a href="{src}">Open it alone</a>.<br>'
                    f"<code>{html.escape(rel)}</code></figcaption></figure>"
                )
                md += [f"[Interactive 3D view: {rel}]({rel.replace(' ', '%20')})", "", f"*{f.caption}*", ""]
                continue
            h.append(
                f'<figure><a href="{src}"><img src="{src}" alt="{html.escape(f.caption, quote=True)}" loading="lazy"></a>'
                f"<figcaption>{cap}<br><code>{html.escape(rel)}</code></figcaption></figure>"
            )
            alt = f.caption.replace("[", "(").replace("]", ")").replace("\n", " ")
            md += [f"![{alt}]({rel.replace(' ', '%20')})", "", f"*{f.caption}*", ""]
        h.append("</div>")
    h += ["</body>", "</html>", ""]
    (out / "index.md").write_text("\n".join(md), encoding="utf-8")
    path = out / "index.html"
    path.write_text("\n".join(h), encoding="utf-8")
    return path
