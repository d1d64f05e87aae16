"""The geomlib command: help, info, render, and the main job (figures) on built-in data."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from geomlib import datasets, image_io, mesh_io
from geomlib.cli import main
from geomlib.info import summary


def _cli(*args, cwd=None):
    env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_ROOT"}
    return subprocess.run(
        [sys.executable, "-m", "geomlib.cli", *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=600
    )


def test_help_lists_every_command(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    for cmd in ("figures", "grade", "refs", "stubs", "release", "info", "view", "render"):
        assert cmd in out


def test_info_describes_a_quad_mesh_with_a_boundary(tmp_path, capsys):
    V, Q = datasets.quad_cube()
    path = tmp_path / "open_cube.obj"
    mesh_io.write_obj(path, V, Q[1:])  # drop one face: one boundary loop of 4 edges
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "8 vertices" not in out and "vertices       8" in out
    assert "5 quads" in out and "1 loop(s) of 4 edges" in out and "Euler char.    1, genus 0" in out


def test_info_summary_on_a_torus_and_a_non_manifold_mesh():
    V, F = datasets.torus()
    s = summary(V, F)
    assert s["genus"] == 1 and s["boundary_loops"] == [] and s["edge_manifold"]
    V = np.random.default_rng(0).random((5, 3))
    s = summary(V, np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]))
    assert not s["edge_manifold"] and s["genus"] is None


def test_info_reports_a_malformed_file_with_its_line(tmp_path, capsys):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    assert main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "line 4" in err and "bad.obj" in err


def test_view_without_a_display_names_the_command_once(tmp_path, capsys, monkeypatch):
    V, F = datasets.icosphere(1)
    path = tmp_path / "ball.obj"
    mesh_io.write_obj(path, V, F)
    for var in ("DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(var, raising=False)
    assert main(["view", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("geomlib view: no display here") and "view: view:" not in err, err
    # the command to paste, with the file the student gave (it said `geomlib view FILE --html mesh.html`)
    assert f"uv run geomlib view {path} --html ball.html" in err and "FILE" not in err, err


@pytest.mark.render
def test_render_command_writes_a_non_blank_png(tmp_path):
    V, F = datasets.icosphere(2)
    mesh = tmp_path / "sphere.ply"
    mesh_io.write_mesh(mesh, V, F)
    out = tmp_path / "sphere.png"
    p = _cli("render", str(mesh), "-o", str(out), "--wireframe", "--width", "320", "--height", "240")
    assert p.returncode == 0, p.stderr
    img = image_io.read_image(out)
    assert img.shape == (240, 320, 3) and img.std() > 10


def test_info_and_render_refuse_folders_and_fifos(tmp_path, capsys):
    folder = tmp_path / "meshes.obj"
    folder.mkdir()
    targets = [(folder, "is a folder")]
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.obj")
        targets.append((tmp_path / "pipe.obj", "is a FIFO"))  # would hang if opened
    for path, what in targets:
        assert main(["info", str(path)]) == 2
        assert what in capsys.readouterr().err
        assert main(["render", str(path), "-o", str(tmp_path / "x.png")]) == 2
        assert what in capsys.readouterr().err


def test_render_refuses_a_missing_output_folder_before_rendering(tmp_path, capsys):
    mesh = tmp_path / "tet.obj"
    mesh_io.write_mesh(mesh, np.eye(4)[:, :3], [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    out = tmp_path / "nonexistent" / "dir" / "x.png"
    assert main(["render", str(mesh), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "nonexistent/dir does not exist; create it first" in err
    assert not (tmp_path / "nonexistent").exists(), "no folders are created behind the user's back"
    assert main(["render", str(mesh), "-o", str(tmp_path / "x.jpg")]) == 2
    assert "must be a .png file" in capsys.readouterr().err


@pytest.mark.render
def test_render_view_option_sees_spot_like_models_from_the_front(tmp_path):
    """--forward names the way the model faces; --view three_quarter then shows its face."""
    from geomlib.render import render

    V, F = datasets.icosphere(2)
    V = V * [0.6, 0.6, 1.5]  # y up, long along z, with a red "face" at z = -1.5 looking down -z like spot
    colors = np.where((V[:, 2] < -1.0)[:, None], [255, 0, 0], [200, 200, 200]).astype(np.uint8)

    def red(img):
        return ((img[:, :, 0] > 150) & (img[:, :, 1] < 90)).mean()

    kw = dict(colors=colors, up_axis="y", size=(120, 90), flat=True, camera="three_quarter")
    assert red(render(V, F, forward="-z", **kw)) > 5 * max(red(render(V, F, **kw)), 1e-3)
    p = _cli("render", "--help")
    for view in ("front", "back", "left", "right", "top", "bottom", "three_quarter", "three_quarter_back"):
        assert view in p.stdout
    assert "--forward" in p.stdout


@pytest.mark.render
@pytest.mark.slow
def test_main_job_renders_the_gallery_with_an_index(tmp_path):
    p = _cli("figures", "--lab", "gallery", "--quick", "--out", str(tmp_path))
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    index = (tmp_path / "index.html").read_text()
    pngs = sorted(tmp_path.rglob("*.png"))
    assert len(pngs) >= len(datasets.DATASETS)
    for png in pngs:
        rel = png.relative_to(tmp_path).as_posix()
        assert rel in index, f"{rel} is not shown in index.html"
        img = image_io.read_image(png)
        assert img.std() > 5, f"{rel} is blank"
    assert (tmp_path / "index.md").is_file()
