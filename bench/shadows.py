"""Benchmark: shadow mapping (solutions.shadows, NumPy rasterizer) next to pyrender's on OSMesa.

Run: ``uv run python bench/shadows.py [--quick]``

For each scene (built-in: the classic scene and a 50k-face bumpy torus; plus meshes from
``../shared/data/meshes`` standing on a floor, when that folder exists) it prints:

* time of our 1024^2 depth map, and of a full 512^2 shaded frame with it (depth pass + G-buffer +
  lookup + Blinn-Phong), next to pyrender's time for the same scene, camera and directional light
  with ``RenderFlags.SHADOWS_DIRECTIONAL`` (its 2048^2 shadow map; a warm ``render`` call of a
  built scene, best of a few; "pyr 1st" is building the scene plus its first render, which uploads
  the mesh), and the ratio ours / pyrender (warm);
* peak extra memory of our frame (tracemalloc);
* quality against the ray-cast truth (one ray per pixel, :func:`geomlib.geometry.ray_cast`):
  agreement at a 2048^2 map (without a 2-pixel band at shadow edges), acne of our defaults and of
  pyrender's shadows, and how often our shadow regions agree with pyrender's.

Target (issue 8): depth map 1024^2 + shaded frame 512^2 of a 50k-face scene <= 3 s on this machine.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from bench.measure import SHARED, best_of, peak_mib
from geomlib.mesh_io import read_mesh
from solutions.shadows import (
    CLASSIC_CAMERA,
    CLASSIC_LIGHT,
    classic_scene,
    depth_map,
    eye_gbuffer,
    light_setup,
    light_visibility,
    make_scene,
    pyrender_scene,
    pyrender_visibility,
    raycast_visibility,
    render_with_shadows,
    shadow_metrics,
    torus_scene,
)

TORUS_CAMERA = (np.array([0.0, -5.5, 3.2]), np.array([0.0, 0.0, 1.2]))
TORUS_LIGHT = {"type": "directional", "direction": np.array([0.5, 0.3, -0.8])}


def mesh_on_floor(path: Path):
    """A shared mesh scaled to height 2 (y-up file -> z-up), standing on a 6 x 6 floor."""
    V, F = read_mesh(path, triangulate=True)
    V = np.asarray(V, float)[:, [0, 2, 1]] * np.array([1.0, -1.0, 1.0])  # y up -> z up, keeping orientation
    lo, hi = V.min(0), V.max(0)
    V = (V - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])) * (2.0 / (hi[2] - lo[2]))
    floor = (np.array([[-3.0, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    scene = make_scene([(*floor, (0.86, 0.86, 0.82)), (V, np.asarray(F), (0.80, 0.62, 0.45), True)])
    return scene, (np.array([3.5, -5.5, 3.0]), np.array([0.0, 0.0, 0.9])), TORUS_LIGHT


def bench_scene(name, scene, camera, light, *, frame: int, repeat: int, quality: int | None) -> dict:
    M = light_setup(scene, light).matrices[0]
    t_map, _, _ = best_of(lambda: depth_map(scene.V, scene.F, M, 1024), repeat)
    t_frame, _, _ = best_of(
        lambda: render_with_shadows(scene, camera, light, size=(frame, frame), map_size=1024, pcf=3), repeat
    )
    mem = peak_mib(lambda: render_with_shadows(scene, camera, light, size=(frame, frame), map_size=1024, pcf=3))
    t_build, _, (ps, rend, pyrender) = best_of(
        lambda: pyrender_scene(scene, camera, light, size=(frame, frame)), 1
    )  # scene upload happens in the first render
    flags = pyrender.RenderFlags.SHADOWS_DIRECTIONAL
    t_first, _, _ = best_of(lambda: rend.render(ps, flags=flags), 1)
    t_py, _, _ = best_of(lambda: rend.render(ps, flags=flags), max(repeat, 3))
    row = {"scene": name, "faces": len(scene.F), "map": t_map, "frame": t_frame, "py": t_py, "mem": mem}
    row["py_first"] = t_build + t_first
    if quality:
        size = (quality, quality * 3 // 4)
        eb = eye_gbuffer(scene, camera, size)
        t0 = time.perf_counter()
        truth = raycast_visibility(scene, eb, light)
        row["rays"] = (len(eb.P), time.perf_counter() - t0)
        v2048, _ = light_visibility(scene, eb, light, map_size=2048, pcf=1)
        row["agree2048"] = shadow_metrics(v2048, truth, eb.mask)["agreement"]
        ours, _ = light_visibility(scene, eb, light, map_size=2048, pcf=3)
        row["acne"] = shadow_metrics(ours, truth, eb.mask)["acne"]
        row["pp"] = shadow_metrics(ours, truth, eb.mask)["peter_panning"]
        pv = pyrender_visibility(scene, camera, light, size=size).ravel()[np.flatnonzero(eb.mask.ravel())]
        pv = np.nan_to_num(pv)
        mp = shadow_metrics(pv, truth, eb.mask)
        row["py_acne"], row["py_agree"] = mp["acne"], mp["agreement"]
        sel = truth["reached"]
        row["vs_py"] = float(np.mean((pv[sel] >= 0.5) == (ours[sel] >= 0.5)))
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller frames, one repeat, no shared meshes")
    args = ap.parse_args()
    frame, repeat, quality = (256, 1, 320) if args.quick else (512, 3, 640)
    scenes = [
        ("classic", classic_scene(), CLASSIC_CAMERA, CLASSIC_LIGHT),
        ("bumpy torus", torus_scene(), TORUS_CAMERA, TORUS_LIGHT),
    ]
    if SHARED.is_dir() and not args.quick:
        for fname in ("bunny_hr.obj", "armadillo.obj"):
            if (SHARED / fname).is_file():
                scenes.append((fname, *mesh_on_floor(SHARED / fname)))
    print(f"shadow mapping, frame {frame}x{frame}, map 1024^2, PCF 3; pyrender on OSMesa (warm, best of {repeat})")
    print(
        f"{'scene':>16} {'faces':>7} {'map s':>7} {'frame s':>8} {'pyrender s':>10} {'ratio':>7} "
        f"{'pyr 1st s':>9} {'peak MB':>8}"
    )
    rows = []
    for name, scene, camera, light in scenes:
        r = bench_scene(name, scene, camera, light, frame=frame, repeat=repeat, quality=quality)
        rows.append(r)
        print(
            f"{name:>16} {r['faces']:>7} {r['map']:>7.3f} {r['frame']:>8.3f} {r['py']:>10.3f} "
            f"{r['frame'] / r['py']:>7.1f} {r['py_first']:>9.3f} {r['mem']:>8.1f}",
            flush=True,
        )
    print(f"\nquality against ray casting ({quality}x{quality * 3 // 4} pixels, 2-pixel edge band excluded)")
    print(
        f"{'scene':>16} {'rays':>8} {'ray s':>6} {'agree@2048':>10} {'acne ours':>10} {'acne pyr':>9} "
        f"{'agree pyr':>9} {'ours=pyr':>8} {'peter-pan':>9}"
    )
    for r in rows:
        n, t = r["rays"]
        print(
            f"{r['scene']:>16} {n:>8} {t:>6.1f} {100 * r['agree2048']:>9.2f}% {100 * r['acne']:>9.3f}% "
            f"{100 * r['py_acne']:>8.3f}% {100 * r['py_agree']:>8.2f}% {100 * r['vs_py']:>7.2f}% "
            f"{100 * r['pp']:>8.1f}%"
        )
    torus = next(r for r in rows if r["scene"] == "bumpy torus")
    ok = torus["map"] + torus["frame"] <= 3.0 if frame == 512 else None
    print(
        f"\ntarget: 50k faces, 1024^2 map + {frame}^2 frame: {torus['frame']:.2f} s (frame includes its map)"
        + ("" if ok is None else f" -> {'OK' if torus['frame'] <= 3.0 else 'MISSED'} (<= 3 s)")
    )


if __name__ == "__main__":
    main()
