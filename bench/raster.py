"""Benchmark: geomlib.raster (NumPy) against pyrender on OSMesa, same meshes, cameras and sizes.

Run: ``uv run python bench/raster.py [--quick]``

Prints wall times (best of a few runs), the ratio ours / pyrender, peak extra memory of our
rasterizer, and how well the two depth maps agree (a cross-check, not a speed number).
"""

from __future__ import annotations

import argparse
import os

import numpy as np
import trimesh

from bench.measure import best_of, peak_mib
from geomlib.camera import camera_presets, look_at, perspective
from geomlib.raster import rasterize
from geomlib.render import import_pyrender  # headless platform + the project's one NumPy-2 shim for pyrender

pyrender = import_pyrender()
FOV = 40.0


def icosphere_mesh() -> tuple[np.ndarray, np.ndarray]:
    """20,480 faces: a bumpy icosphere (subdivision level 5)."""
    m = trimesh.creation.icosphere(subdivisions=5)
    V = np.asarray(m.vertices, float)
    V *= 1 + 0.08 * np.sin(6 * V[:, :1]) * np.cos(5 * V[:, 1:2])
    return V, np.asarray(m.faces, np.int64)


def torus_scene(nu: int = 250, nv: int = 100) -> tuple[np.ndarray, np.ndarray]:
    """~50k faces: a bumpy torus standing on a ground quad (a shadow-map scene)."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, nu, endpoint=False), np.linspace(0, 2 * np.pi, nv, endpoint=False))
    r = 0.35 + 0.03 * np.sin(7 * u) * np.sin(5 * v)
    x = (1 + r * np.cos(v)) * np.cos(u)
    z = (1 + r * np.cos(v)) * np.sin(u)
    y = r * np.sin(v) + 0.5
    V = np.stack([x, y, z], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv))
    a = j * nu + i
    b = j * nu + (i + 1) % nu
    c = ((j + 1) % nv) * nu + i
    d = ((j + 1) % nv) * nu + (i + 1) % nu
    F = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([b, c, d], -1).reshape(-1, 3)])
    n = len(V)
    ground = np.array([[-3, -0.1, -3], [3, -0.1, -3], [3, -0.1, 3], [-3, -0.1, 3.0]])
    V = np.concatenate([V, ground])
    F = np.concatenate([F, n + np.array([[0, 2, 1], [0, 3, 2]])])
    return V, F


def camera_for(V: np.ndarray, preset: str) -> tuple[np.ndarray, np.ndarray, float, float]:
    bounds = np.array([V.min(0), V.max(0)])
    eye, target, up = camera_presets(preset, bounds, fov_y_deg=FOV)
    r = 0.5 * np.linalg.norm(bounds[1] - bounds[0])
    dist = np.linalg.norm(eye - target)
    near, far = max(dist - r, 1e-3 * dist), dist + r
    return look_at(eye, target, up), perspective(FOV, 1.0, near, far), near, far


class PyrenderScene:
    def __init__(self, V, F, view, near, far, size):
        self.scene = pyrender.Scene(bg_color=[0, 0, 0, 0], ambient_light=[1.0, 1.0, 1.0])
        self.scene.add(pyrender.Mesh.from_trimesh(trimesh.Trimesh(V, F, process=False), smooth=False))
        cam = pyrender.PerspectiveCamera(yfov=np.radians(FOV), aspectRatio=1.0, znear=near, zfar=far)
        self.scene.add(cam, pose=np.linalg.inv(view))
        self.renderer = pyrender.OffscreenRenderer(size, size)

    def depth(self):
        return self.renderer.render(self.scene, flags=pyrender.RenderFlags.DEPTH_ONLY)

    def color_depth(self):
        return self.renderer.render(self.scene, flags=pyrender.RenderFlags.FLAT)

    def close(self):
        self.renderer.delete()


def linear_depth(window_depth: np.ndarray, near: float, far: float) -> np.ndarray:
    """Eye-space distance along -z from window depth; 0 for background (pyrender's convention)."""
    z_ndc = 2 * window_depth - 1
    with np.errstate(invalid="ignore"):
        lin = 2 * far * near / (far + near - z_ndc * (far - near))
    return np.where(np.isfinite(window_depth), lin, 0.0)


def run(name, V, F, size, depth_only, preset, repeat):
    view, proj, near, far = camera_for(V, preset)
    M = proj @ view
    if depth_only:
        ours = lambda: rasterize(V, F, M, size, size, depth_only=True)
    else:
        ours = lambda: rasterize(V, F, M, size, size, attributes={"position": V})
    t_ours, c_ours, g = best_of(ours, repeat)
    mem = peak_mib(ours)
    pr = PyrenderScene(V, F, view, near, far, size)
    try:
        t_first, _, _ = best_of(pr.depth if depth_only else pr.color_depth, 1)
        t_pr, c_pr, out = best_of(pr.depth if depth_only else pr.color_depth, repeat)
    finally:
        pr.close()
    d_pr = out if depth_only else out[1]
    d_ours = linear_depth(g.depth, near, far)
    both = (d_pr > 0) & g.mask
    mask_agree = np.mean((d_pr > 0) == g.mask)
    rel = np.abs(d_ours[both] - d_pr[both]) / d_pr[both]
    kind = "depth only" if depth_only else "full (bary + position)"
    print(
        f"{name:>12s} {preset:>13s} {len(F):6d} faces {size:5d}^2 {kind:22s} ours {t_ours:6.3f} s (cpu {c_ours:6.3f})  "
        f"pyrender {t_pr:6.3f} s (cpu {c_pr:6.3f}, first frame {t_first:6.3f})  ratio {t_ours / t_pr:5.1f}x  "
        f"our peak mem {mem:5.0f} MiB | masks agree on {100 * mask_agree:7.3f}% of pixels, "
        f"median rel. depth diff {np.median(rel):.1e}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one repetition, skip 2048^2")
    args = ap.parse_args()
    repeat = 1 if args.quick else 3
    Vs, Fs = icosphere_mesh()
    Vt, Ft = torus_scene()
    print(
        f"numpy {np.__version__}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; times are best of {repeat}"
    )
    run("icosphere", Vs, Fs, 512, False, "three_quarter", repeat)
    run("icosphere", Vs, Fs, 512, True, "three_quarter", repeat)
    run("torus+ground", Vt, Ft, 512, False, "three_quarter", repeat)
    run("torus+ground", Vt, Ft, 1024, True, "top", repeat)
    run("torus+ground", Vt, Ft, 1024, True, "three_quarter", repeat)
    if not args.quick:
        run("torus+ground", Vt, Ft, 2048, True, "top", repeat)
        run("torus+ground", Vt, Ft, 2048, True, "three_quarter", repeat)
        run("torus+ground", Vt, Ft, 2048, False, "three_quarter", 1)


if __name__ == "__main__":
    main()
