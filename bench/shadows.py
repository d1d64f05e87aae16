"""Benchmark: shadow mapping (solutions.shadows, NumPy rasterizer) next to pyrender's on OSMesa.

Run: ``uv run python bench/shadows.py [--quick] [--no-glsl]``

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

Then the GLSL route (issue 27) on the lab's scenes (classic, bumpy torus), one {frame}^2 frame three ways,
best of a few warm calls, interleaved: the NumPy route (eye G-buffer, ``depth_map`` 1024^2 and
``shadow_visibility`` PCF 3, ``shade``), the GLSL route (the same eye G-buffer and shading, the two passes by
``shaders/depth.vert`` + ``depth.frag`` and ``shadow.frag``: ``glsl_depth_map``, ``glsl_shadow_visibility``)
and pyrender's own shadowed frame (``SHADOWS_DIRECTIONAL``, warm). The point light (tasks 11-12): six 512^2
linear-depth faces and the lookup, ``cube_distance_maps`` + ``linear_point_shadow_visibility`` against
``cube_depth.vert``/``.frag`` + ``cube_shadow.frag``; pyrender 0.1.45 has no point-light shadows
("Point light shadows not implemented"), so its anchor is the same frame lit by a point light without
shadows. GLSL and pyrender both run on OSMesa in this one process.

Target (issue 8): depth map 1024^2 + shaded frame 512^2 of a 50k-face scene <= 3 s on this machine.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from bench.measure import SHARED, best_of, compare_routes, glsl_route_header, load_average, peak_mib
from geomlib.mesh_io import read_mesh
from solutions.shadows import (
    CLASSIC_CAMERA,
    CLASSIC_LIGHT,
    classic_scene,
    cube_distance_maps,
    depth_map,
    eye_gbuffer,
    glsl_cube_depth_maps,
    glsl_depth_map,
    glsl_point_shadow_visibility,
    glsl_shadow_visibility,
    light_setup,
    light_visibility,
    linear_point_shadow_visibility,
    make_scene,
    pyrender_scene,
    pyrender_visibility,
    raycast_visibility,
    render_with_shadows,
    shade,
    shadow_metrics,
    shadow_visibility,
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


def agreement(tol: float = 1e-6):
    """How two visibility images agree: pixels differing by more than the graded tolerance, and the max."""

    def agree(a, b):
        d = np.abs(a[1] - b[1])
        return f"{int((d > tol).sum()):,} of {d.size:,} px > {tol:g}, max {d.max():.2g}"

    return agree


def pyrender_point_frame(scene, camera, position, size: int):
    """pyrender's frame of the scene lit by a point light at ``position`` (no shadows: not in pyrender 0.1.45)."""
    ps, rend, pyrender = pyrender_scene(scene, camera, TORUS_LIGHT, size=(size, size))
    for node in list(ps.light_nodes):
        ps.remove_node(node)
    pose = np.eye(4)
    pose[:3, 3] = position
    ps.add(pyrender.PointLight(color=[1.0, 1.0, 1.0], intensity=30.0), pose=pose)
    return lambda: rend.render(ps, flags=pyrender.RenderFlags.NONE)


def glsl_scene(name, scene, camera, light, point_light, frame: int, repeat: int) -> None:
    """The directional and the point light's rows of one scene (see :func:`bench_glsl`)."""
    size = (frame, frame)

    def frame_of(passes, lit):
        def run():
            eb = eye_gbuffer(scene, camera, size)
            vis = passes(eb)
            return shade(eb, vis, lit), vis

        return run

    M = light_setup(scene, light).matrices[0]

    def numpy_dir(eb):
        return shadow_visibility(eb.P, eb.N_face, depth_map(scene.V, scene.F, M, 1024, "none"), M, pcf=3)

    def glsl_dir(eb):
        return glsl_shadow_visibility(eb.P, eb.N_face, glsl_depth_map(scene.V, scene.F, M, 1024, "none"), M, pcf=3)

    ps, rend, pyrender = pyrender_scene(scene, camera, light, size=size)
    flags = pyrender.RenderFlags.SHADOWS_DIRECTIONAL
    rend.render(ps, flags=flags)  # warm: upload, shaders
    compare_routes(
        f"{name} ({len(scene.F):,} f), directional, map 1024^2",
        frame_of(numpy_dir, light),
        frame_of(glsl_dir, light),
        lambda: rend.render(ps, flags=flags),
        repeat,
        agreement(),
    )
    setup = light_setup(scene, point_light)
    pos, near, far = setup.light["position"], setup.near, setup.far

    def numpy_point(eb):
        C = cube_distance_maps(scene.V, scene.F, pos, 512, near, far, cull="front")
        return linear_point_shadow_visibility(eb.P, eb.N_face, C, pos, near, far)

    def glsl_point(eb):
        C = glsl_cube_depth_maps(scene.V, scene.F, pos, 512, near, far, cull="front")
        return glsl_point_shadow_visibility(eb.P, eb.N_face, C, pos, near, far)

    point_frame = pyrender_point_frame(scene, camera, pos, frame)
    point_frame()  # warm
    compare_routes(
        f"{name}, point light, cube 6 x 512^2",
        frame_of(numpy_point, point_light),
        frame_of(glsl_point, point_light),
        point_frame,
        repeat,
        agreement(),
    )
    eb = eye_gbuffer(scene, camera, size)
    t_eye = best_of(lambda: eye_gbuffer(scene, camera, size), repeat)
    vis = np.ones(len(eb.P))
    t_shade = best_of(lambda: shade(eb, vis, light), repeat)
    print(
        f"  {'':<48} (of each frame, NumPy in both routes: eye G-buffer {t_eye.wall:.3f} s, shade {t_shade.wall:.3f} s)",
        flush=True,
    )


def bench_glsl(scenes, frame: int, repeat: int) -> None:
    from solutions.shadows.figures import POINT_LIGHT

    glsl_route_header(
        f"\nGLSL route (issue 27): one {frame}x{frame} frame, best of {repeat} warm calls, interleaved; "
        f"ratio = route / pyrender frame"
    )
    for name, scene, camera, light in scenes:
        glsl_scene(name, scene, camera, light, POINT_LIGHT, frame, repeat)
    print(
        "  (pyrender directional: its own shadowed frame, 2048^2 shadow map; point light: pyrender's frame without\n"
        "   shadows, which pyrender 0.1.45 does not implement for point lights. 'GLSL 1st': the route's first call,\n"
        "   shader compilation included. NumPy vs GLSL: visibility per covered pixel, graded tolerance 1e-6)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller frames, one repeat, no shared meshes")
    ap.add_argument("--no-glsl", action="store_true", help="skip the GLSL route")
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
    print(
        f"shadow mapping, frame {frame}x{frame}, map 1024^2, PCF 3; pyrender on OSMesa (warm, best of {repeat}); "
        f"{load_average()}"
    )
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
    if not args.no_glsl:
        bench_glsl(scenes[:2], frame, repeat)  # the lab's scenes: classic and bumpy torus
    print(f"\n{load_average()}")


if __name__ == "__main__":
    main()
