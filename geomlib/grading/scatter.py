"""Scatter panels drawn with Pillow, for the feedback pictures of points with no mesh to draw them on.

A matplotlib figure of three scatter panels cost about 0.8 s of CPU in the picture's process
(importing ``matplotlib.figure`` and its font manager about 0.4 s, a tight ``savefig`` drawing it
twice); a student's ``--task N`` waits for one such picture. These panels draw the same things --
axes with round ticks and labels, markers, segments coloured by their error -- with Pillow and
:mod:`geomlib.plot` (captions, colour bar, deterministic PNG), in about a tenth of that.
"""

from __future__ import annotations

import numpy as np

#: Drawn this many times larger, then scaled down: smooth markers and lines.
_SUPER = 2
#: Side of a panel's data area, in pixels (the longer side when the spans differ).
SIDE = 300
_LEFT, _BOTTOM, _TOP, _RIGHT = 62, 44, 10, 14  # margins for tick labels and axis labels, pixels


def rgb(color) -> tuple[int, int, int]:
    """``"#1f77b4"`` or an RGB(A) in [0, 1] as 8-bit RGB."""
    if isinstance(color, str):
        return tuple(int(color[i : i + 2], 16) for i in (1, 3, 5))
    return tuple(int(round(255 * float(c))) for c in color[:3])


class Panel:
    """One panel: a data rectangle ``lo``..``hi`` (equal scale on both axes) with a frame, ticks and
    axis labels; draw markers and segments in data coordinates, then :meth:`image`."""

    def __init__(self, lo, hi, xlabel: str = "", ylabel: str = "", *, axes: bool = True):
        from PIL import Image, ImageDraw

        self.lo, self.hi = np.asarray(lo, float), np.asarray(hi, float)
        span = np.maximum(self.hi - self.lo, 1e-300)
        self.scale = SIDE / float(span.max())  # pixels per unit, the same along x and y
        self.w, self.h = (span * self.scale).round().astype(int)
        self.xlabel, self.ylabel, self.axes = xlabel, ylabel, axes
        k = _SUPER
        self.margins = (_LEFT, _BOTTOM, _TOP, _RIGHT) if axes else (8, 8, 8, 8)
        left, bottom, top, right = self.margins
        self.size = (left + self.w + right, top + self.h + bottom)
        self.img = Image.new("RGB", (self.size[0] * k, self.size[1] * k), (255, 255, 255))
        self.draw = ImageDraw.Draw(self.img)

    def _px(self, xy) -> np.ndarray:
        """Data ``(n, 2)`` to pixel centres of the large canvas."""
        xy = np.asarray(xy, float).reshape(-1, 2)
        left, _, top, _ = self.margins
        x = left + (xy[:, 0] - self.lo[0]) * self.scale
        y = top + self.h - (xy[:, 1] - self.lo[1]) * self.scale
        return np.stack([x, y], axis=1) * _SUPER

    def dots(self, xy, colors, radius: float = 2.0, edge=None) -> None:
        """Filled discs of ``radius`` pixels; ``colors``: one colour, or one per point; ``edge``: the
        colour of a thin outline (none by default)."""
        r = radius * _SUPER
        outline = rgb(edge) if edge is not None else None
        for (x, y), c in zip(self._px(xy), self._colors(colors, len(np.asarray(xy).reshape(-1, 2))), strict=True):
            self.draw.ellipse([x - r, y - r, x + r, y + r], fill=c, outline=outline, width=1 if outline else 0)

    def crosses(self, xy, color, radius: float = 2.6, width: float = 1.2, edge=None) -> None:
        """``x`` markers; with ``edge``, drawn over a wider cross of that colour (a filled X)."""
        r, lw = radius * _SUPER, max(1, round(width * _SUPER))
        layers = ([(rgb(edge), lw + 2)] if edge is not None else []) + [(rgb(color), lw)]
        for x, y in self._px(xy):
            for c, w in layers:
                self.draw.line([(x - r, y - r), (x + r, y + r)], fill=c, width=w)
                self.draw.line([(x - r, y + r), (x + r, y - r)], fill=c, width=w)

    def segments(self, a, b, colors, width: float = 1.5) -> None:
        lw = max(1, round(width * _SUPER))
        pa, pb = self._px(a), self._px(b)
        for p, q, c in zip(pa, pb, self._colors(colors, len(pa)), strict=True):
            self.draw.line([tuple(p), tuple(q)], fill=c, width=lw)

    @staticmethod
    def _colors(colors, n: int) -> list:
        if isinstance(colors, str) or (np.ndim(colors) == 1 and len(colors) in (3, 4)):
            return [rgb(colors)] * n
        return [rgb(c) for c in colors]

    def image(self) -> np.ndarray:
        """The panel with its frame, ticks, tick labels and axis labels, as ``(h, w, 3)`` uint8."""
        from matplotlib.ticker import MaxNLocator
        from PIL import Image

        from geomlib import plot

        if not self.axes:
            return np.asarray(self.img.resize(self.size, Image.Resampling.LANCZOS), dtype=np.uint8).copy()
        k, ink = _SUPER, (40, 40, 40)
        font = plot._font(11 * k)
        x0, y0, x1, y1 = _LEFT * k, _TOP * k, (_LEFT + self.w) * k, (_TOP + self.h) * k
        self.draw.rectangle([x0, y0, x1, y1], outline=ink, width=k)
        for axis in (0, 1):
            lo, hi = self.lo[axis], self.hi[axis]
            ticks = [t for t in MaxNLocator(nbins=6).tick_values(lo, hi) if lo <= t <= hi]
            for t in ticks:
                text = f"{0.0 if abs(t) < 1e-12 * max(abs(lo), abs(hi)) else t:.4g}"
                if axis == 0:
                    x = self._px([[t, lo]])[0, 0]
                    self.draw.line([(x, y1), (x, y1 + 4 * k)], fill=ink, width=k)
                    self.draw.text((x, y1 + 6 * k), text, font=font, fill=ink, anchor="mt")
                else:
                    y = self._px([[self.lo[0], t]])[0, 1]
                    self.draw.line([(x0 - 4 * k, y), (x0, y)], fill=ink, width=k)
                    self.draw.text((x0 - 6 * k, y), text, font=font, fill=ink, anchor="rm")
        self.draw.text(((x0 + x1) / 2, y1 + 22 * k), self.xlabel, font=font, fill=ink, anchor="mt")
        label = Image.new("RGB", (int(font.getlength(self.ylabel)) + 4 * k, 16 * k), (255, 255, 255))
        from PIL import ImageDraw

        ImageDraw.Draw(label).text((2 * k, 8 * k), self.ylabel, font=font, fill=ink, anchor="lm")
        label = label.rotate(90, expand=True)
        self.img.paste(label, (2 * k, int((y0 + y1) / 2 - label.size[1] / 2)))
        small = self.img.resize(self.size, Image.Resampling.LANCZOS)
        return np.asarray(small, dtype=np.uint8).copy()


def view(elev: float, azim: float) -> np.ndarray:
    """``(3, 2)``: 3D points ``@ view(...)`` are their screen ``(x, y)`` in an orthographic view from
    ``elev`` degrees above the xy-plane and ``azim`` degrees around z (matplotlib's 3D angles): the
    first two rows of :func:`geomlib.camera.look_at` from that direction (one camera in geomlib)."""
    from geomlib.camera import look_at

    e, a = np.radians(elev), np.radians(azim)
    toward_eye = [np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)]
    # up: the direction of growing elevation (z tilted back), which stays defined looking straight down
    up = [-np.sin(e) * np.cos(a), -np.sin(e) * np.sin(a), np.cos(e)]
    return look_at(toward_eye, (0.0, 0.0, 0.0), up=up)[:2, :3].T
