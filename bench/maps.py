"""Benchmark: lab "maps" (reference solution) next to the anchor libraries, in one run.

Run: ``uv run python bench/maps.py [--quick]``

Targets of the issue (this 2-core machine):

- ``shade`` of a 1024 x 1024 G-buffer <= 0.5 s. Anchor: pyrender (OSMesa/EGL) rendering the same
  normal-mapped mesh at 1024 x 1024 with a normal texture (one frame, context and shaders warm,
  read-back included). The rasterization that fills the G-buffer is timed separately.
- ``bake_normal_map`` at 512 x 512 from a ~100k-face mesh <= 10 s. Anchor: libigl's Embree
  ``line_mesh_intersection`` for the same texel points and directions (the ray casts alone).
- ``tangent_frames`` on ~1M faces <= 1 s. No installed library computes tangent frames; the anchor
  is ``igl.per_vertex_normals`` (area-weighted) on the same mesh, a scatter of the same size.
- The GLSL route (issue 27): one 512 x 512 normal-mapped frame by NumPy ``shade``, by the lab's
  ``shaders/normalmap.frag`` (``glsl_shade``) and by pyrender, in one run.

Times are the best of a few runs with the contenders interleaved (the machine is shared and
noisy); next to the wall time of the solution, its CPU time (``time.process_time``, all threads),
which is what the call costs when it does not wait for a busy core. Peak memory is the
tracemalloc peak of one call (NumPy allocations), in MiB.
"""

from __future__ import annotations

import argparse
import time

import igl
import numpy as np
from igl.embree import line_mesh_intersection

from bench.anchors import pyrender_mesh_frame, pyrender_normal_mapped_mesh
from bench.measure import SHARED, best_of, compare_routes, glsl_route_header, load_average, peak_mib, warm_anchor
from geomlib import camera, datasets
from geomlib.textures import rasterize_uv, triangle_atlas
from solutions.maps import (
    bake_normal_map,
    displace,
    encode_normal_map,
    glsl_displace,
    glsl_shade,
    glsl_tbn,
    height_to_normal_map,
    rasterize_mesh,
    shade,
    surface_frames,
    tangent_frames,
    welded_vertex_normals,
)

CPU: dict[str, float] = {}


def timed(fn, key: str | None = None) -> float:
    """Wall time of one call; its CPU time goes to ``CPU[key]`` (the least seen), which :func:`row` prints."""
    t = best_of(fn, 1)
    if key is not None:
        CPU[key] = min(CPU.get(key, np.inf), t.cpu)
    return t.wall


def bumps(s: int, seed: int = 0) -> np.ndarray:
    """A tileable bumpy height map in [0, 1] (sum of random low-frequency waves)."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:s, 0:s] / s
    H = np.zeros((s, s))
    for _ in range(12):
        kx, ky = rng.integers(1, 9, size=2)
        H += rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * (kx * c + ky * r) + rng.uniform(0, 2 * np.pi))
    return (H - H.min()) / (H.max() - H.min())


def row(name: str, ours: float, anchor: float, anchor_name: str, mem: float, target: str) -> None:
    cpu = CPU.get(name, float("nan"))
    print(
        f"  {name:<20} {ours:7.3f} s (cpu {cpu:6.3f} s)   {anchor_name:<30} {anchor:7.3f} s   "
        f"ratio {ours / anchor:6.2f}   peak {mem:7.1f} MiB   {target}"
    )


def bench_tangents(quick: bool, repeat: int) -> None:
    n_major, n_minor = (500, 250) if quick else (1000, 500)
    V, F, UV = datasets.uv_torus(n_major, n_minor)
    print(f"tangent_frames: uv_torus, {len(F):,} faces, {len(V):,} vertices")
    t_ours, t_igl = [], []
    for _ in range(repeat):
        t_ours.append(timed(lambda: tangent_frames(V, F, UV), "tangent_frames"))
        t_igl.append(timed(lambda: igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)))
    mem = peak_mib(lambda: tangent_frames(V, F, UV))
    target = "target <= 1 s at 1M faces" + ("" if not quick else " (quick: 250k faces)")
    row("tangent_frames", min(t_ours), min(t_igl), "igl.per_vertex_normals", mem, target)


def torus_scene(size: int, s_map: int):
    V, F, UV = datasets.uv_torus(96, 48)
    T, _, N, w = tangent_frames(V, F, UV)
    tangents = np.column_stack([T, w])
    nmap = encode_normal_map(height_to_normal_map(bumps(s_map), 0.02, border="wrap"))
    eye = np.array([0.0, -2.2, 2.2])
    view = camera.look_at(eye, (0, 0, 0), (0, 0, 1))
    M = camera.perspective(40, 1.0, 0.5, 10.0) @ view
    return V, F, UV, N, tangents, nmap, eye, view, M


def pyrender_frame(V, F, UV, N, tangents, nmap, view, size: int):
    from geomlib import render as grender

    pyrender = grender.import_pyrender()
    scene = pyrender.Scene(bg_color=[1.0, 1.0, 1.0, 1.0], ambient_light=[0.1] * 3)
    scene.add(pyrender_normal_mapped_mesh(V, F, UV, N, tangents, nmap, base_color=(0.8, 0.7, 0.6), roughness=0.6))
    scene.add(
        pyrender.PerspectiveCamera(yfov=np.radians(40), aspectRatio=1.0, znear=0.5, zfar=10.0), pose=np.linalg.inv(view)
    )
    scene.add(
        pyrender.DirectionalLight(intensity=3.0),
        pose=np.linalg.inv(camera.look_at((1.0, -1.0, 2.0), (0, 0, 0), (0, 0, 1))),
    )
    renderer = pyrender.OffscreenRenderer(size, size)
    return renderer, scene


def bench_shade(quick: bool, repeat: int) -> None:
    size = 512 if quick else 1024
    V, F, UV, N, tangents, nmap, eye, view, M = torus_scene(size, 512)
    t = time.perf_counter()
    g = rasterize_mesh(V, F, M, size, size, UV=UV, N=N, tangents=tangents)
    t_raster = time.perf_counter() - t
    print(
        f"shade: normal-mapped uv_torus ({len(F):,} faces), {size}x{size} G-buffer, {int(g.mask.sum()):,} covered pixels, 2 lights"
    )
    lights = [{"direction": (-1.0, 1.0, -2.0)}, {"direction": (1.0, 0.5, -0.5), "intensity": 0.4}]
    try:
        renderer, scene = pyrender_frame(V, F, UV, N, tangents, nmap, view, size)
        renderer.render(scene)  # warm: context, shader compilation, texture upload
    except Exception as e:  # no headless OpenGL: report ours alone
        print(f"  (pyrender unavailable: {type(e).__name__}: {e})")
        renderer = None
    t_ours, t_pr = [], []
    for _ in range(repeat):
        t_ours.append(timed(lambda: shade(g, lights, eye, (0.8, 0.7, 0.6), nmap), "shade (normal map)"))
        if renderer is not None:
            t_pr.append(timed(lambda: renderer.render(scene)))
    mem = peak_mib(lambda: shade(g, lights, eye, (0.8, 0.7, 0.6), nmap))
    target = "target <= 0.5 s at 1024^2" + (" (quick: 512^2)" if quick else "")
    if renderer is not None:
        row("shade (normal map)", min(t_ours), min(t_pr), "pyrender frame (OSMesa)", mem, target)
        renderer.delete()
    else:
        print(f"  shade (normal map) {min(t_ours):.3f} s, peak {mem:.1f} MiB, {target}")
    print(f"  (rasterize_mesh filling the G-buffer: {t_raster:.3f} s, not part of shade)")


def texel_rays(V, F, UV, size: int):
    """The points and directions bake_normal_map casts from (for the Embree-only anchor)."""
    N_lo = welded_vertex_normals(V, F)
    T, _, _, w = tangent_frames(V, F, UV, N_lo)
    tg = np.column_stack([T, w])
    fid, bary = rasterize_uv(F, UV, size)
    cov = fid >= 0
    f, b = fid[cov], bary[cov]
    P = np.einsum("ki,kij->kj", b, V[F[f]])
    _, _, Ni = surface_frames(np.einsum("ki,kij->kj", b, N_lo[F[f]]), np.einsum("ki,kij->kj", b, tg[F[f]]))
    return P, Ni


def bench_bake_case(name: str, Vh, Fh, Vl, Fl, UVl, size: int, repeat: int) -> None:
    P, D = texel_rays(Vl, Fl, UVl, size)
    print(
        f"bake_normal_map: {name}: high {len(Fh):,} faces, low {len(Fl):,} faces, {size}x{size} map, {len(P):,} covered texels"
    )
    t_ours, t_emb = [], []
    CPU.pop("bake_normal_map", None)
    for _ in range(repeat):
        t_ours.append(timed(lambda: bake_normal_map(Vh, Fh, Vl, Fl, UVl, size), "bake_normal_map"))
        t_emb.append(timed(lambda: line_mesh_intersection(P, D, Vh, Fh)))
    mem = peak_mib(lambda: bake_normal_map(Vh, Fh, Vl, Fl, UVl, size))
    row(
        "bake_normal_map",
        min(t_ours),
        min(t_emb),
        "embree line_mesh_intersection",
        mem,
        "target <= 10 s (100k faces, 512^2)",
    )


def bench_bake(quick: bool, repeat: int) -> None:
    size = 256 if quick else 512
    # Built-in: a bumpy torus of ~100k faces baked onto a coarse torus with the same UVs.
    nm, nn = (120, 60) if quick else (250, 200)
    Vt, Ft, UVt = datasets.uv_torus(nm, nn)
    Vh = displace(Vt, Ft, UVt, None, bumps(256, seed=1), lam=0.04, bias=-0.5)
    Vl, Fl, UVl = datasets.uv_torus(48, 24)
    bench_bake_case("bumpy uv_torus -> uv_torus(48, 24)", Vh, Ft, Vl, Fl, UVl, size, repeat)
    if quick or not SHARED.is_dir():
        return
    import fast_simplification

    from geomlib.mesh_io import read_mesh

    for fname in ("armadillo.obj", "igea.ply"):
        path = SHARED / fname
        if not path.is_file():
            continue
        V, F = read_mesh(path, triangulate=True)
        V = (V - V.min(0)) / np.linalg.norm(V.max(0) - V.min(0))
        Vd, Fd = fast_simplification.simplify(V.astype(np.float32), F.astype(np.int32), target_count=2000)
        Vs, Fs, UV, _ = triangle_atlas(np.asarray(Vd, np.float64), np.asarray(Fd, np.int64), mode="fill")
        bench_bake_case(f"{fname} -> decimated, triangle atlas", V, F, Vs, Fs, UV, size, repeat)


def route_shade(name, scene, g, lights, opts, size: int, repeat: int) -> None:
    from solutions.maps.figures import ALBEDO

    V, F, UV, N, tangents, nmap, eye, view = scene

    def make():
        renderer, pscene = pyrender_frame(V, F, UV, N, tangents, nmap, view, size)
        return lambda: renderer.render(pscene)  # the renderer is deleted with this call (pyrender's __del__)

    compare_routes(
        f"shade: {name}",
        lambda: shade(g, lights, eye, ALBEDO, nmap, **opts),
        lambda: glsl_shade(g, lights, eye, ALBEDO, nmap, **opts),
        warm_anchor(make),
        repeat,
        lambda a, b: f"max {np.abs(a - b).max():.2g} per channel",
    )


def route_displace(name, V, F, UV, H, kw: dict, eye, size: int, repeat: int) -> None:
    compare_routes(
        f"{name}, {len(V):,} v",
        lambda: displace(V, F, UV, None, H, **kw),
        lambda: glsl_displace(V, F, UV, None, H, **kw),
        warm_anchor(lambda: pyrender_mesh_frame(displace(V, F, UV, None, H, **kw), F, (eye, (0, 0, 0)), size)),
        repeat,
        lambda a, b: f"max {np.linalg.norm(a - b, axis=1).max() / kw['lam']:.2g} x lam",
    )


def bench_glsl(repeat: int) -> None:
    """512 x 512 frames of the lab's scenes three ways: the NumPy route, the lab's shaders (``glsl_shade``:
    G-buffer upload, draw of ``normalmap.frag``, read-back; ``glsl_displace``/``glsl_tbn``: the vertices drawn
    as points through ``displace.vert``/``tbn.vert``, read back) and pyrender (OSMesa here), in one run."""
    from solutions.maps.figures import KEY_LIGHTS, bump_tiles, smooth_noise

    size = 512
    glsl_route_header(
        f"GLSL route (issue 27): {size}x{size}, best of {repeat} warm calls, interleaved; ratio = route / pyrender frame"
    )

    # normalmap.frag on two normal-mapped tori: this bench's bumpy one and the lab's figure's (maps_glsl)
    V, F, UV, N, tangents, nmap, eye, view, M = torus_scene(size, 512)
    g = rasterize_mesh(V, F, M, size, size, UV=UV, N=N, tangents=tangents)
    lights = [{"direction": (-1.0, 1.0, -2.0)}, {"direction": (1.0, 0.5, -0.5), "intensity": 0.4}]
    route_shade(f"uv_torus(96, 48), {int(g.mask.sum()):,} px", (V, F, UV, N, tangents, nmap, eye, view), g, lights, {},
                size, repeat)  # fmt: skip
    H = bump_tiles(512, 24, 8)
    nmap2 = encode_normal_map(height_to_normal_map(H, (0.05 / (2 * np.pi), 0.05 / (2 * np.pi * 0.35)), border="wrap"))
    V2, F2, UV2 = datasets.uv_torus(48, 24, 1.0, 0.35)
    N2 = welded_vertex_normals(V2, F2)
    T2, _, _, w2 = tangent_frames(V2, F2, UV2, N2)
    tg2 = np.column_stack([T2, w2])
    eye2 = np.array([0.15, -1.0, 0.85]) * 2.2
    view2 = camera.look_at(eye2, (0, 0, 0), (0, 0, 1))
    g2 = rasterize_mesh(V2, F2, camera.perspective(40, 1.0, 0.5, 10.0) @ view2, size, size, UV=UV2, N=N2, tangents=tg2)
    opts2 = dict(wrap="repeat", specular=0.25, shininess=24.0)
    route_shade(f"torus(48, 24) bump tiles, {int(g2.mask.sum()):,} px", (V2, F2, UV2, N2, tg2, nmap2, eye2, view2),
                g2, KEY_LIGHTS, opts2, size, repeat)  # fmt: skip

    # tbn.vert: the per-vertex frames of the displaced torus's mesh (NumPy: surface_frames per vertex)
    Vt, Ft, UVt = datasets.uv_torus(384, 128, 1.0, 0.35)
    Nt = welded_vertex_normals(Vt, Ft)
    Tt, _, _, wt = tangent_frames(Vt, Ft, UVt, Nt)
    tgt = np.column_stack([Tt, wt])
    compare_routes(
        f"tbn.vert: uv_torus(384, 128), {len(Vt):,} v",
        lambda: surface_frames(Nt, tgt),
        lambda: glsl_tbn(Nt, tgt),
        None,
        repeat,
        lambda a, b: f"max {max(float(np.abs(x - y).max()) for x, y in zip(a, b)):.2g}",
    )

    # displace.vert: the lab's displaced torus (mapped_vs_displaced) and the (bias, scale) sphere (bias_scale)
    route_displace("displace: torus(384, 128) bump tiles", Vt, Ft, UVt, H, dict(lam=0.05, wrap="repeat"),
                   np.array([0.15, -1.0, 0.85]) * 2.2, size, repeat)  # fmt: skip
    Vs, Fs, UVs = datasets.uv_sphere(96, 192)
    Hs = smooth_noise(256, seed=3)
    for bias, scale in ((0.0, 1.0), (-1.0, 2.0), (-1.0, 5.0)):
        kw = dict(lam=0.12, bias=bias, scale=scale, wrap="repeat")
        route_displace(f"displace: uv_sphere(96, 192) ({bias:g}, {scale:g})", Vs, Fs, UVs, Hs, kw,
                       np.array([1.0, -1.2, 0.9]) * 2.0, size, repeat)  # fmt: skip
    print(
        "  (pyrender: the same normal-mapped frame, warm; for displace, the displaced mesh drawn with its upload, "
        "as its vertices change every frame.\n   The NumPy and GLSL tbn/displace routes compute vertices only, "
        "no picture; 'GLSL 1st' is the route's first call: shader compilation + one run)"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller inputs, one repetition")
    args = ap.parse_args(argv)
    repeat = 1 if args.quick else 3
    print(
        f"lab maps benchmark ({'quick' if args.quick else 'full'}); ratio = solution / anchor (lower is better); "
        f"{load_average()}\n"
    )
    bench_tangents(args.quick, repeat)
    bench_shade(args.quick, repeat)
    bench_bake(args.quick, repeat)
    bench_glsl(repeat)
    print(f"\n{load_average()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
