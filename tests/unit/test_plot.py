"""Tests for geomlib.plot (panels, colour maps, line plots, PNG files, index pages) and geomlib.gallery.

No OpenGL here: the gallery test swaps the renderer for a stub that draws a flat image, so it
checks the files, captions and index the gallery produces, not pixels of pyrender.
Expected colours come from matplotlib's colour maps (an independent library).
"""

from __future__ import annotations

import re
import zlib

import matplotlib
import numpy as np
import pytest
from PIL import Image

from geomlib import gallery, plot, topology
from geomlib.plot import Figure, save_png, write_index
from geomlib.validate import MeshError


def png_chunks(data: bytes) -> list[bytes]:
    """Chunk types of a PNG file, in order (hand-rolled parser, independent of Pillow)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    i, kinds = 8, []
    while i < len(data):
        n = int.from_bytes(data[i : i + 4], "big")
        kind = data[i + 4 : i + 8]
        assert zlib.crc32(data[i + 4 : i + 8 + n]) == int.from_bytes(data[i + 8 + n : i + 12 + n], "big")
        kinds.append(kind)
        i += 12 + n
    return kinds


# -- panels --------------------------------------------------------------------------------------


def test_panels_layout_size():
    a = np.zeros((40, 60, 3), np.uint8)
    b = np.ones((30, 50))  # grey float, smaller: centred in a 40 x 60 cell
    img = plot.panels([a, b, a], ["one", "two", "three"], ncols=2, pad=10)
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    assert img.shape[1] == 2 * 60 + 3 * 10  # two columns of 60 px, three gaps of 10 px
    assert img.shape[0] > 2 * 40 + 3 * 10  # two rows plus captions
    # The first image is pasted at (pad, pad) unchanged.
    assert (img[10:50, 10:70] == 0).all()
    single = plot.panels([a], pad=0)
    assert single.shape == (40, 60, 3) and (single == 0).all()


def test_panels_captions_and_title_draw_text():
    a = np.full((40, 60, 3), 255, np.uint8)
    bare = plot.panels([a, a], pad=8)
    captioned = plot.panels([a, a], ["left", "right"], title="Title", pad=8)
    assert captioned.shape[0] > bare.shape[0]
    assert (captioned < 128).any(), "captions and title are drawn in dark ink"
    assert np.array_equal(captioned, plot.panels([a, a], ["left", "right"], title="Title", pad=8))


def test_panels_bad_input():
    a = np.zeros((10, 10, 3), np.uint8)
    with pytest.raises(MeshError, match=r"panels: got 1 captions for 2 images"):
        plot.panels([a, a], ["x"])
    with pytest.raises(MeshError, match=r"panels: images\[1\] has shape \(10,\)"):
        plot.panels([a, np.zeros(10)])
    with pytest.raises(MeshError, match=r"panels: images is empty"):
        plot.panels([])
    with pytest.raises(MeshError, match=r"float images must lie in \[0, 1\]"):
        plot.panels([a.astype(float) * 3 + 2])


# -- colour maps ---------------------------------------------------------------------------------


def test_heat_colors_match_matplotlib():
    vals = np.array([0.0, 2.5, 5.0, 10.0, 20.0])
    got = plot.heat_colors(vals, vmin=0.0, vmax=10.0, cmap="inferno")
    cm = matplotlib.colormaps["inferno"]
    expected = cm(np.array([0.0, 0.25, 0.5, 1.0, 1.0]))[:, :3]  # 20 is clamped to vmax
    assert got.shape == (5, 3)
    np.testing.assert_allclose(got, expected, atol=1e-12)
    const = plot.heat_colors(np.full(4, 3.0), cmap="viridis")
    np.testing.assert_allclose(const, np.tile(matplotlib.colormaps["viridis"](0.5)[:3], (4, 1)))


def test_heat_colors_bad_input():
    with pytest.raises(MeshError, match=r"heat_colors: values: entry \(1,\) is nan"):
        plot.heat_colors([0.0, np.nan])
    with pytest.raises(MeshError, match=r"values has shape \(2, 2\), expected \(n\)"):
        plot.heat_colors(np.zeros((2, 2)))
    with pytest.raises(MeshError, match=r"unknown colour map 'no-such-map'"):
        plot.heat_colors([0.0, 1.0], cmap="no-such-map")
    with pytest.raises(MeshError, match=r"vmax \(0\) is smaller than vmin \(1\)"):
        plot.heat_colors([0.0, 1.0], vmin=1.0, vmax=0.0)


def test_heatmap_image_values_and_nan():
    a = np.array([[0.0, 1.0], [np.nan, 0.5]])
    img = plot.heatmap_image(a, "viridis", 0.0, 1.0, nan_color=(1, 2, 3))
    cm = matplotlib.colormaps["viridis"]
    assert img.shape == (2, 2, 3) and img.dtype == np.uint8
    assert np.array_equal(img[0, 0], np.round(np.array(cm(0.0)[:3]) * 255).astype(np.uint8))
    assert np.array_equal(img[0, 1], np.round(np.array(cm(1.0)[:3]) * 255).astype(np.uint8))
    assert tuple(img[1, 0]) == (1, 2, 3)
    with pytest.raises(MeshError, match=r"heatmap_image: array2d\[0, 1\] is inf"):
        plot.heatmap_image([[0.0, np.inf]])


def test_colorbar_size_and_gradient():
    img = plot.colorbar(0.0, 0.02, "viridis", label="error", height=200)
    assert img.shape[0] == 200 and img.shape[2] == 3 and 40 < img.shape[1] < 200
    cm = matplotlib.colormaps["viridis"]
    top, bottom = (np.round(np.array(cm(v)[:3]) * 255) for v in (1.0, 0.0))
    # Top of the strip shows vmax's colour, bottom vmin's (strip column 10 px from the left).
    col = img[:, 10].astype(float)
    assert np.abs(col - top).sum(axis=1).min() < 12 and np.abs(col - bottom).sum(axis=1).min() < 12
    with pytest.raises(MeshError, match=r"colorbar: vmax \(-1\) is smaller than vmin \(1\)"):
        plot.colorbar(1.0, -1.0)


# -- line plots and files ------------------------------------------------------------------------


def test_line_plot_size_and_determinism():
    xs = [[1, 2, 3, 4], [1, 2, 3, 4]]
    ys = [[1.0, 0.1, 0.01, 0.001], [1.0, 0.5, 0.25, 0.125]]
    kw = dict(labels=["a", "b"], xlabel="level", ylabel="error", title="convergence", logy=True, size=(400, 300))
    img = plot.line_plot(xs, ys, **kw)
    assert img.shape == (300, 400, 3) and img.dtype == np.uint8
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 10
    assert np.array_equal(img, plot.line_plot(xs, ys, **kw))
    one = plot.line_plot([0, 1, 2], [3, 4, 5], size=(200, 150))  # a single curve as two 1-D arrays
    assert one.shape == (150, 200, 3)


def test_line_plot_bad_input():
    with pytest.raises(MeshError, match=r"line_plot: curve 0 has 3 x values but 2 y values"):
        plot.line_plot([[1, 2, 3]], [[1, 2]])
    with pytest.raises(MeshError, match=r"ys_list\[0\] has a value 0 <= 0"):
        plot.line_plot([[1, 2]], [[0.0, 1.0]], logy=True)
    with pytest.raises(MeshError, match=r"got 1 labels for 2 curves"):
        plot.line_plot([[1], [2]], [[1], [2]], labels=["x"])


def test_save_png_deterministic_without_metadata(tmp_path):
    rng = np.random.default_rng(3)
    img = rng.integers(0, 256, size=(30, 40, 3), dtype=np.uint8)
    p1 = plot.save_png(tmp_path / "a" / "b" / "one.png", img)
    p2 = plot.save_png(tmp_path / "two.png", img)
    assert p1.read_bytes() == p2.read_bytes()
    assert png_chunks(p1.read_bytes()) == [b"IHDR", b"IDAT", b"IEND"]
    assert np.array_equal(np.asarray(Image.open(p1)), img)
    rgba = np.zeros((2, 2, 4), np.uint8)  # fully transparent -> white
    assert (np.asarray(Image.open(plot.save_png(tmp_path / "t.png", rgba))) == 255).all()
    with pytest.raises(MeshError, match=r"does not end in .png"):
        plot.save_png(tmp_path / "x.jpg", img)


# -- index pages and gallery ---------------------------------------------------------------------


def test_write_index_lists_every_figure(tmp_path):
    figs = [
        Figure(tmp_path / "gallery" / "a.png", "Sphere <with> wireframe & dots", "gallery"),
        Figure(tmp_path / "subdivision" / "loop.png", "Loop subdivision, levels 0-3", "subdivision"),
        Figure(tmp_path / "gallery" / "b.png", "Torus", "gallery"),
    ]
    page = plot.write_index(figs, tmp_path)
    assert page == tmp_path / "index.html"
    text = page.read_text(encoding="utf-8")
    for src in ("gallery/a.png", "subdivision/loop.png", "gallery/b.png"):
        assert f'src="{src}"' in text
    assert "Sphere &lt;with&gt; wireframe &amp; dots" in text and "Loop subdivision, levels 0-3" in text
    # Grouped by lab, labs in order of first appearance: both gallery figures before the subdivision one.
    assert text.index("gallery/b.png") < text.index("subdivision/loop.png")
    assert "http" not in text, "no external assets"
    md = (tmp_path / "index.md").read_text(encoding="utf-8")
    assert re.findall(r"^## (\S+)$", md, flags=re.M) == ["gallery", "subdivision"]
    for f in figs:
        assert f"*{f.caption}*" in md
    with pytest.raises(MeshError, match=r"figures\[0\] is a str"):
        plot.write_index(["a.png"], tmp_path)


def test_extraordinary_vertices():
    # Subdivided icosahedra keep exactly 12 valence-5 vertices; a cube's 8 corners have valence 3.
    from geomlib import datasets

    V, F = datasets.icosphere(2)
    assert len(topology.extraordinary_vertices(F, len(V))) == 12
    cube = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    assert list(topology.extraordinary_vertices(cube, 8)) == list(range(8))
    grid = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]  # 3 x 3 vertices: only boundary + one regular
    assert len(topology.extraordinary_vertices(grid, 9)) == 0


def test_build_gallery_files_and_captions(tmp_path, monkeypatch):
    from geomlib import render

    calls = []

    def fake(kind):
        def draw(V, F, **kw):
            calls.append((kind, kw["wireframe"], kw["size"]))
            return np.full((kw["size"][1], kw["size"][0], 3), 200, np.uint8)

        return draw

    monkeypatch.setattr(render, "render", fake("tri"))
    monkeypatch.setattr(render, "render_polygons", fake("poly"))
    figs = gallery.build_gallery(tmp_path, quick=True, names=["icosphere", "quad_cube"])
    assert [c[0] for c in calls] == ["tri", "poly"] and all(c[1] and c[2] == (320, 240) for c in calls)
    assert [f.path.name for f in figs] == ["contact_sheet.png", "icosphere.png", "quad_cube.png"]
    assert all(f.lab == "gallery" and f.path.is_file() for f in figs)
    assert "quad_cube" in figs[2].caption and "8 vertices, 6 polygons" in figs[2].caption
    assert "8 extraordinary vertices" in figs[2].caption
    with pytest.raises(KeyError, match="unknown dataset"):
        gallery.build_gallery(tmp_path, names=["no_such_mesh"])


# --------------------------------------------------------------------------------------------
# Issue 14: legends and labels inside the image, colour bars beside their maps, missing tasks
# --------------------------------------------------------------------------------------------


def test_line_plot_keeps_legend_and_labels_inside_the_image():
    from geomlib.plot import line_plot

    x = np.arange(1, 7.0)
    labels = ["Loop, icosahedron", "Catmull-Clark, cube", "Catmull-Clark, cage", "a fourth, rather long label"]
    for size in ((420, 300), (560, 380), (900, 500)):
        img = line_plot([x] * 4, [4.0**-x * (k + 1) for k in range(4)], labels, xlabel="level", ylabel="move",
                        logy=True, title="convergence", size=size)  # fmt: skip
        border = np.concatenate([img[:2].reshape(-1, 3), img[-2:].reshape(-1, 3),
                                 img[:, :2].reshape(-1, 3), img[:, -2:].reshape(-1, 3)])  # fmt: skip
        assert (border == 255).all(), f"something drawn on the image edge at size {size}"


def test_with_colorbar_puts_the_bar_beside_the_map():
    from geomlib.plot import colorbar, with_colorbar

    heat = np.zeros((100, 80, 3), np.uint8)
    bar = colorbar(0, 1, "viridis", label="x", height=90)
    both = with_colorbar(heat, bar, gap=6)
    assert both.shape == (100, 80 + 6 + bar.shape[1], 3)
    assert (both[:, :80] == 0).all()  # the map untouched, on the left


def test_the_index_frames_interactive_views(tmp_path):
    png = Figure(save_png(tmp_path / "lab" / "a.png", np.zeros((8, 8, 3), np.uint8)), "a picture", "lab")
    page = tmp_path / "lab" / "lab_3d.html"
    page.write_text("<!DOCTYPE html><title>view</title>", encoding="utf-8")
    index = write_index([png, Figure(page, "Turn it: a mesh", "lab")], tmp_path)
    text = index.read_text(encoding="utf-8")
    assert '<iframe src="lab/lab_3d.html"' in text and '<img src="lab/a.png"' in text
    assert "[Interactive 3D view: lab/lab_3d.html](lab/lab_3d.html)" in (tmp_path / "index.md").read_text()
