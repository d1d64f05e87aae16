"""3D viewing: ``geomlib.view`` / ``geomlib view FILE --html``, and the page in a real headless browser.

The browser test runs Debian's ``chromium`` with software WebGL (SwiftShader), no network and a
fresh profile: the page must load without any console message and draw a non-blank picture.
``./run tests`` installs chromium when it is missing (as it installs libosmesa6), so CI runs the
test; elsewhere it is skipped with the reason when no chromium binary exists.
"""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess

import numpy as np
import pytest

import geomlib
from geomlib import datasets, viewer
from geomlib import mesh_io as io
from geomlib.cli import main
from geomlib.validate import MeshError


def _data(page: str) -> dict:
    return json.loads(re.search(r"const DATA = (\{.*?\});\n", page).group(1))


def test_the_page_carries_the_mesh_and_loads_nothing_from_outside():
    V, Q = datasets.quad_cube()
    page = viewer.html_page(V, Q, title="cube")
    assert not re.search(r"(src|href)\s*=\s*[\"']?(https?:)?//", page) and "@import" not in page
    d = _data(page)
    P = np.frombuffer(base64.b64decode(d["positions"]), "<f4").reshape(-1, 3)
    T = np.frombuffer(base64.b64decode(d["triangles"]), "<u4").reshape(-1, 3)
    E = np.frombuffer(base64.b64decode(d["edges"]), "<u4").reshape(-1, 2)
    np.testing.assert_array_equal(P, V.astype(np.float32))
    assert len(T) == 12 and len(E) == 12  # 6 quads: 12 triangles, but only the 12 cube edges are drawn


def test_face_scalars_colour_whole_faces_and_vertex_scalars_blend():
    V, F = datasets.icosphere(1)
    d = _data(viewer.html_page(V, F, np.arange(len(F), dtype=float)))
    C = np.frombuffer(base64.b64decode(d["colors"]), np.uint8).reshape(-1, 3)
    assert len(C) == 3 * len(F)  # corners split per face
    assert (C[0::3] == C[1::3]).all() and (C[0::3] == C[2::3]).all()
    d = _data(viewer.html_page(V, F, V[:, 2]))
    assert len(np.frombuffer(base64.b64decode(d["colors"]), np.uint8)) == 3 * len(V)


def test_bad_input_and_no_display_give_clear_errors(monkeypatch, tmp_path):
    V, F = datasets.icosphere(0)
    with pytest.raises(MeshError, match=r"scalars has 5 values; expected one per vertex \(12\) or per face \(20\)"):
        viewer.html_page(V, F, np.zeros(5))
    with pytest.raises(MeshError, match="face 0 uses vertex 99"):
        viewer.html_page(V, F + [99, 0, 0])
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.sys, "platform", "linux")
    with pytest.raises(MeshError, match=r"no display.*html="):
        geomlib.view(V, F)
    out = geomlib.view(V, F, html=tmp_path / "ico.html")
    assert out.is_file()


def test_in_a_notebook_the_view_is_an_iframe_widget(monkeypatch):
    V, F = datasets.icosphere(0)
    monkeypatch.setattr(viewer, "in_notebook", lambda: True)
    w = geomlib.view(V, F, V[:, 0])
    html = w._repr_html_()
    assert html.startswith("<iframe srcdoc=") and "const DATA" in html.replace("&quot;", '"')


def test_view_command_writes_a_page(tmp_path, capsys):
    path = tmp_path / "cube.obj"
    io.write_obj(path, *datasets.quad_cube())
    assert main(["view", str(path), "--html", str(tmp_path / "cube.html")]) == 0
    assert "wrote" in capsys.readouterr().out and "cube.obj" in (tmp_path / "cube.html").read_text()


# --------------------------------------------------------------------------------------------
# The page in a real browser
# --------------------------------------------------------------------------------------------

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",  # software WebGL
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--host-resolver-rules=MAP * ~NOTFOUND",  # any network request would fail (and show in the console)
    "--enable-logging=stderr",
    "--v=0",
    "--virtual-time-budget=8000",
]


def _chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("no chromium binary: `./run tests` installs Debian's chromium package (apt-get install chromium)")
    return exe


def open_in_browser(page, tmp_path, size=(800, 600)):
    """Load ``page`` in headless chromium: (status attribute, console lines, screenshot array)."""
    from PIL import Image

    exe = _chromium()
    base = [exe, *CHROMIUM_FLAGS, f"--window-size={size[0]},{size[1]}"]
    url = page.resolve().as_uri()
    dom = subprocess.run(
        [*base, f"--user-data-dir={tmp_path / 'profile1'}", "--dump-dom", url],
        capture_output=True,
        text=True,
        timeout=120,
    )
    status = re.search(r'<body data-status="([^"]*)"', dom.stdout)
    # Software GL reports its own performance notes ("GPU stall due to ReadPixels" when headless
    # chromium reads the frame back); they are not the page's messages. Everything else counts.
    console = [
        ln for ln in dom.stderr.splitlines() if ":CONSOLE" in ln and "GL Driver Message (OpenGL, Performance" not in ln
    ]
    shot = tmp_path / "shot.png"
    subprocess.run(
        [*base, f"--user-data-dir={tmp_path / 'profile2'}", f"--screenshot={shot}", url],
        capture_output=True,
        timeout=120,
    )
    assert shot.is_file(), f"chromium wrote no screenshot: {dom.stderr[-2000:]}"
    return (status.group(1) if status else None), console, np.asarray(Image.open(shot).convert("RGB"))


@pytest.mark.slow
def test_the_page_draws_in_headless_chromium(tmp_path):
    V, F = datasets.icosphere(3)
    page = viewer.write_html(tmp_path / "ico.html", V, F, V[:, 1], title="icosphere", scalar_name="height")
    status, console, img = open_in_browser(page, tmp_path)
    assert not console, "the page wrote to the browser console:\n" + "\n".join(console)
    assert status == "ok", f"the viewer did not finish drawing (status {status!r})"
    # The sphere fills the middle of the window: most pixels there are neither white nor grey text.
    mid = img[150:450, 250:550].astype(int)
    coloured = (mid.max(axis=2) - mid.min(axis=2)) > 40
    assert coloured.mean() > 0.5, f"screenshot is blank: {coloured.mean():.1%} coloured pixels in the middle"
    assert len(np.unique(mid.reshape(-1, 3), axis=0)) > 200  # shading and a colour map, not one flat colour


def test_with_a_display_a_pyvista_window_opens(monkeypatch):
    import pyvista as pv

    shown = {}

    def fake_show(self, *args, **kwargs):  # the window itself needs a screen; record what it would show
        shown["mesh"] = self.mesh
        shown["scalars"] = self.mesh.active_scalars_name
        self.close()

    monkeypatch.setattr(viewer, "has_display", lambda: True)
    monkeypatch.setattr(viewer, "in_notebook", lambda: False)
    monkeypatch.setattr(pv, "OFF_SCREEN", True)
    monkeypatch.setattr(pv.Plotter, "show", fake_show)
    V, Q = datasets.quad_cube()
    assert geomlib.view(V, Q, np.arange(len(V), dtype=float)) is None
    assert shown["mesh"].n_cells == 12 and shown["scalars"] == "scalars"  # 6 quads drawn as 12 triangles


def test_colour_bar_ticks_are_short_and_a_near_zero_end_reads_zero():
    V, F = datasets.icosphere(1)
    s = np.linspace(3.299e-06, 0.0075123, len(V))
    ticks = re.findall(r'class="tick"[^>]*>([^<]*)<', viewer.html_page(V, F, s, scalar_name="dist / diag"))
    assert ticks[:2] == ["0.00751", "0"], ticks
