"""Benchmark: lab "denoise" (reference solution) next to the anchor libraries, in one run.

Run: ``uv run python bench/denoise.py [--quick] [--no-quality] [--no-timing] [--no-glsl]``

Three parts:

1. **Timing** (ratio = solution / anchor, lower is better; peak = tracemalloc peak of one call):

   - ``laplacian_offsets`` uniform: libigl (``igl.adjacency_matrix``, then ``V - A V / deg``) and
     trimesh (``smoothing.laplacian_calculation(equal_weight=True)``, then ``V - L V``). Timed with
     ``weld=False`` (the same job) and with the default ``weld=True`` (plus the seam welding).
   - ``laplacian_offsets`` cotan: ``igl.cotmatrix`` then ``-(L V) / (-diag L)``.
   - ``denoise_vertices`` (one pass): trimesh ``filter_laplacian(iterations=1)`` (a uniform
     Laplacian step, not projected on normals) and VTK's ``vtkSmoothPolyDataFilter`` through
     pyvista (``smooth(n_iter=1)``; note VTK updates vertices in place, Gauss-Seidel style, so its
     result differs from the Jacobi step of the lab).
   - ``bake_offset_map`` at 1024^2: pyrender (OSMesa/EGL) drawing the UV layout with the offsets as
     vertex colours into a 1024^2 frame, unlit, read back (8 bits only; context warm).
   - ``denoise_with_map``: ``scipy.ndimage.map_coordinates(order=1)`` bilinear lookup + the move.

2. **Quality** (the headline): noisy inputs from the lab's ``make_noisy`` (Gaussian noise of
   ``sigma_rel`` times the mean edge length along random directions, clean normals kept); mean and
   max distance of the vertices to the clean surface, relative to the bbox diagonal, before, and
   after/before ratios for lambda in {0.3, 0.7, 1}, iterations 1-5, uniform vs cotan weights, at a
   high (0.3) and a low (0.1) noise level; then the map route (one pass, lambda = 0.7) with 8- and
   16-bit maps next to the direct route. Meshes without UVs get a one-chart-per-triangle atlas
   (:func:`geomlib.textures.triangle_atlas`), so every vertex there is a seam vertex.

3. **GLSL route** (issue 27), ``--no-glsl`` skips it: the map-driven pass (``denoise_with_map``,
   NumPy) against ``shaders/denoise.vert`` (``glsl_denoise_with_map``: every vertex drawn as a point,
   moved in the vertex stage, read back; the seam fix on the CPU) and against pyrender drawing the
   same denoised mesh at 512^2 (built and uploaded in the frame, as its vertices change every pass),
   on the meshes with UVs: the lab's figure sphere (16-bit 256^2 map, lambda = 1), uv_sphere, uv_torus
   and the shared meshes with UVs (1024^2 maps, lambda = 0.7), and a dense uv_torus(400, 200) (80k
   vertices). One process, OSMesa for both.

Meshes: built-in (icosphere 4, torus, pyvista "nut", uv_sphere, uv_torus) and, when present, the
real meshes in ``../shared/data/meshes``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import igl
import numpy as np

from bench.anchors import pyrender_mesh_frame
from bench.measure import SHARED, best_of, compare_routes, glsl_route_header, load_average, peak_mib, warm_anchor
from geomlib import datasets, mesh_io
from geomlib.textures import rasterize_uv, triangle_atlas
from solutions.denoise import (
    bake_offset_map,
    denoise_vertices,
    denoise_with_map,
    error_stats,
    glsl_denoise_with_map,
    laplacian_offsets,
    make_noisy,
    normal_offsets,
    weld_seams,
)

REAL = ["spot_triangulated.obj", "cow.off", "fandisk.obj", "rocker-arm.obj", "camelhead.off", "mountain.obj",
        "bunny_hr.obj", "armadillo.obj", "igea.ply"]  # fmt: skip
REAL_QUICK = ["spot_triangulated.obj", "fandisk.obj"]


# --------------------------------------------------------------------------------------------
# inputs


def obj_with_uvs(path: Path):
    """An OBJ with texture coordinates as a seam-split triangle mesh ``(V, F, UV)``; UVs scaled into [0, 1]^2."""
    d = mesh_io.read_obj(path, triangulate=True)
    pairs = np.stack([np.asarray(d.faces).ravel(), np.asarray(d.face_uv).ravel()], axis=1)
    keys, inv = np.unique(pairs, axis=0, return_inverse=True)
    V, UV = d.V[keys[:, 0]], d.UV[keys[:, 1]]
    UV = (UV - UV.min(axis=0)) / (UV.max(axis=0) - UV.min(axis=0)).max()
    return V, inv.reshape(-1, 3).astype(np.int64), UV


def load(name: str):
    """``(V, F, UV or None)`` of a built-in or shared mesh."""
    if name == "icosphere4":
        return (*datasets.icosphere(4), None)
    if name == "torus":
        return (*datasets.torus(), None)
    if name == "nut":
        return (*datasets.pyvista_mesh("nut"), None)
    if name == "uv_sphere":
        return datasets.uv_sphere(32, 64)
    if name == "uv_torus":
        return datasets.uv_torus()
    path = SHARED / name
    d = mesh_io.read_obj(path, triangulate=True) if path.suffix == ".obj" else None
    if d is not None and d.face_uv is not None:
        return obj_with_uvs(path)
    V, F = mesh_io.read_mesh(path, triangulate=True)
    return V, np.asarray(F, np.int64), None


def mesh_names(quick: bool) -> list[str]:
    names = ["icosphere4", "torus", "nut", "uv_sphere", "uv_torus"]
    if SHARED.is_dir():
        names += [n for n in (REAL_QUICK if quick else REAL) if (SHARED / n).is_file()]
    else:
        print(f"(no shared meshes at {SHARED}; built-in meshes only)")
    return names


def row(name: str, ours: float, mem: float, anchors: list[tuple[str, float]]) -> None:
    parts = "   ".join(f"{a:<26} {t:7.3f} s  ratio {ours / t:5.2f}" for a, t in anchors)
    print(f"  {name:<30} {ours:7.3f} s  peak {mem:7.1f} MiB   {parts}")


def igl_uniform(V, F):
    A = igl.adjacency_matrix(F)
    deg = np.asarray(A.sum(axis=1)).ravel()
    return V - (A @ V) / deg[:, None]


def trimesh_uniform(V, F):
    import trimesh

    L = trimesh.smoothing.laplacian_calculation(trimesh.Trimesh(V, F, process=False), equal_weight=True)
    return V - L @ V


def igl_cotan(V, F):
    L = igl.cotmatrix(V, F)
    return -(L @ V) / (-L.diagonal())[:, None]


def trimesh_filter(V, F, lam):
    import trimesh

    m = trimesh.Trimesh(V.copy(), F, process=False)
    trimesh.smoothing.filter_laplacian(m, lamb=lam, iterations=1, volume_constraint=False)
    return np.asarray(m.vertices)


def vtk_smooth(V, F, lam):
    import pyvista as pv

    m = pv.PolyData(V, np.column_stack([np.full(len(F), 3), F]).ravel())
    return m.smooth(n_iter=1, relaxation_factor=lam, boundary_smoothing=False, convergence=0.0).points


def scipy_map_route(V, UV, N, img, bias, scale, lam):
    from scipy.ndimage import map_coordinates

    h, w = img.shape
    H = img.astype(np.float64) / (255.0 if img.dtype == np.uint8 else 65535.0)
    coords = np.stack([(1.0 - UV[:, 1]) * h - 0.5, UV[:, 0] * w - 0.5])
    s = bias + scale * map_coordinates(H, coords, order=1, mode="nearest")
    return V - lam * s[:, None] * N


class PyrenderBaker:
    """The UV layout drawn by pyrender with the offsets as unlit vertex colours (8-bit frame)."""

    def __init__(self, size: int):
        from geomlib import render as grender

        self.pyrender = grender.import_pyrender()
        self.size = size
        self.renderer = self.pyrender.OffscreenRenderer(size, size)

    def __call__(self, F, UV, s):
        pr = self.pyrender
        h = (s - s.min()) / max(float(s.max() - s.min()), 1e-300)
        prim = pr.Primitive(
            positions=np.column_stack([UV, np.zeros(len(UV))]).astype(np.float32),
            color_0=np.repeat(h[:, None], 3, axis=1).astype(np.float32),
            indices=F.astype(np.uint32),
            material=pr.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0], doubleSided=True),
        )
        scene = pr.Scene(bg_color=[0.0, 0.0, 0.0, 1.0])
        scene.add(pr.Mesh([prim]))
        pose = np.eye(4)
        pose[:3, 3] = [0.5, 0.5, 1.0]
        scene.add(pr.OrthographicCamera(xmag=0.5, ymag=0.5, znear=0.1, zfar=2.0), pose=pose)
        color, _ = self.renderer.render(scene, flags=pr.RenderFlags.FLAT)
        return color[:, :, 0]

    def close(self):
        self.renderer.delete()


def time_mesh(name: str, repeat: int, baker) -> None:
    V, F, UV = load(name)
    Vn, N = make_noisy(V, F, 0.3, 0)
    print(f"{name}: {len(V):,} vertices, {len(F):,} faces{'' if UV is None else ', with UVs'}")
    t = best_of(lambda: laplacian_offsets(Vn, F, weld=False), repeat).wall
    mem = peak_mib(lambda: laplacian_offsets(Vn, F, weld=False))
    anchors = [("igl adjacency", best_of(lambda: igl_uniform(Vn, F), repeat).wall),
               ("trimesh laplacian", best_of(lambda: trimesh_uniform(Vn, F), repeat).wall)]  # fmt: skip
    row("offsets uniform (weld=False)", t, mem, anchors)
    t = best_of(lambda: laplacian_offsets(Vn, F), repeat).wall
    row("offsets uniform (weld=True)", t, peak_mib(lambda: laplacian_offsets(Vn, F)), anchors)
    t = best_of(lambda: laplacian_offsets(Vn, F, "cotan", weld=False), repeat).wall
    mem = peak_mib(lambda: laplacian_offsets(Vn, F, "cotan", weld=False))
    row("offsets cotan (weld=False)", t, mem, [("igl cotmatrix", best_of(lambda: igl_cotan(Vn, F), repeat).wall)])
    t = best_of(lambda: denoise_vertices(Vn, F, N, 0.7), repeat).wall
    mem = peak_mib(lambda: denoise_vertices(Vn, F, N, 0.7))
    anchors = [("trimesh filter_laplacian", best_of(lambda: trimesh_filter(Vn, F, 0.7), repeat).wall),
               ("VTK smooth (pyvista)", best_of(lambda: vtk_smooth(Vn, F, 0.7), repeat).wall)]  # fmt: skip
    row("denoise_vertices (1 pass)", t, mem, anchors)
    if UV is None:
        return
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    t = best_of(lambda: bake_offset_map(Vn, F, UV, s, 1024), repeat).wall
    mem = peak_mib(lambda: bake_offset_map(Vn, F, UV, s, 1024))
    t_r = best_of(lambda: rasterize_uv(F, UV, 1024), repeat).wall
    if baker is not None:
        baker(F, UV, s)  # warm: shaders, buffers
        row(
            "bake_offset_map 1024^2",
            t,
            mem,
            [("pyrender UV draw 1024^2", best_of(lambda: baker(F, UV, s), repeat).wall)],
        )
    else:
        print(f"  bake_offset_map 1024^2 {t:7.3f} s  peak {mem:7.1f} MiB")
    print(f"  {'':<30} (of which the given geomlib.textures.rasterize_uv: {t_r:.3f} s)")
    img, bias, scale = bake_offset_map(Vn, F, UV, s, 1024)
    t = best_of(lambda: denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7), repeat).wall
    mem = peak_mib(lambda: denoise_with_map(Vn, F, UV, N, img, bias, scale, 0.7))
    t_sc = best_of(lambda: scipy_map_route(Vn, UV, N, img, bias, scale, 0.7), repeat).wall
    row("denoise_with_map", t, mem, [("scipy map_coordinates", t_sc)])


def bench_timing(names: list[str], quick: bool) -> None:
    repeat = 1 if quick else 3
    print("TIMING  (ratio = solution / anchor; lower is better)")
    baker = None
    try:
        baker = PyrenderBaker(1024)
    except Exception as e:  # no headless OpenGL
        print(f"  (pyrender unavailable: {type(e).__name__}: {e})")
    # warm-up: first calls import and initialise VTK and trimesh, which is not what we time
    Vw, Fw = datasets.icosphere(1)
    vtk_smooth(Vw, Fw, 0.5)
    trimesh_filter(Vw, Fw, 0.5)
    trimesh_uniform(Vw, Fw)
    for name in names:
        time_mesh(name, repeat, baker)
    if baker is not None:
        baker.close()
    print()


# --------------------------------------------------------------------------------------------
# quality


def copy_spread(X: np.ndarray, group: np.ndarray) -> float:
    """Largest distance of a vertex from the mean of its seam group: the width of a crack."""
    k = int(group.max()) + 1
    c = np.stack([np.bincount(group, weights=X[:, i], minlength=k) for i in range(3)], 1)
    c /= np.bincount(group, minlength=k)[:, None]
    return float(np.linalg.norm(X - c[group], axis=1).max())


def fmt(r: dict, e0: dict) -> str:
    return f"{r['mean'] / e0['mean']:4.2f}/{r['max'] / e0['max']:4.2f}"


def atlas_size(m: int, cap: int) -> int:
    """Map size giving about 16 texels per atlas cell, as a power of two within [256, cap]."""
    k = int(np.ceil(np.sqrt(m)))
    return int(min(cap, max(256, 2 ** int(np.ceil(np.log2(16 * k))))))


def bench_quality(names: list[str], quick: bool) -> None:
    lams = (0.3, 0.7, 1.0)
    iters = 3 if quick else 5
    noise_levels = (0.3,) if quick else (0.3, 0.1)
    print(
        "QUALITY  distance of the vertices to the clean surface / bbox diagonal; 'a/b' = mean ratio / max ratio (after / before)"
    )
    for name in names:
        V, F, UV = load(name)
        for sigma in noise_levels:
            Vn, N = make_noisy(V, F, sigma, 0)
            e0 = error_stats(V, F, Vn)
            print(
                f"{name} ({len(V):,} v), noise {sigma} x mean edge: before mean {e0['mean']:.2e}, max {e0['max']:.2e}"
            )
            for w in ("uniform", "cotan"):
                for lam in lams:
                    X, cells = Vn, []
                    for _ in range(iters):
                        X = denoise_vertices(X, F, N, lam, weights=w)
                        cells.append(fmt(error_stats(V, F, X), e0))
                    print(f"  {w:<7} lam={lam:<3}  iterations 1..{iters}: " + "  ".join(cells))
        # map route, one pass at lambda = 0.7 (high noise)
        if UV is None:
            if len(F) > (3000 if quick else 25_000):
                continue
            size = atlas_size(len(F), 1024 if quick else 2048)
            # a gutter of 2.5 texels around every chart, so bilinear lookups never read a neighbouring chart
            cell = size / np.ceil(np.sqrt(len(F)))
            Vs, Fs, UVs, _ = triangle_atlas(V, F, gutter=min(0.3, 2.5 / cell))
            how = f"triangle atlas, {cell:.0f} texels per cell"
        else:
            Vs, Fs, UVs = V, F, UV
            how = "own UVs"
            size = 512 if quick else 1024
        Vn, N = make_noisy(Vs, Fs, 0.3, 0)
        e0 = error_stats(Vs, Fs, Vn)
        direct = denoise_vertices(Vn, Fs, N, 0.7)
        s = normal_offsets(laplacian_offsets(Vn, Fs), N)
        cells = [f"direct {fmt(error_stats(Vs, Fs, direct), e0)}"]
        for bits in (8, 16):
            img, bias, scale = bake_offset_map(Vn, Fs, UVs, s, size, bits)
            Xm = denoise_with_map(Vn, Fs, UVs, N, img, bias, scale, 0.7)
            gap = np.linalg.norm(Xm - direct, axis=1).max() / (0.7 * scale)
            cells.append(
                f"{bits}-bit {fmt(error_stats(Vs, Fs, Xm), e0)} (max |map - direct| / lam = {gap:.1e} x scale)"
            )
        # the same without the seam fix: offsets of the cut mesh, copies moved independently
        s_cut = normal_offsets(laplacian_offsets(Vn, Fs, weld=False), N)
        Xc = denoise_with_map(Vn, Fs, UVs, N, *bake_offset_map(Vn, Fs, UVs, s_cut, size), 0.7, weld=False)
        crack = copy_spread(Xc, weld_seams(Vs, Fs)[2]) / float(np.linalg.norm(Vs.max(0) - Vs.min(0)))
        print(
            f"  map route ({how}, {size}^2, lam=0.7, 1 pass): "
            + "   ".join(cells)
            + f"   crack without seam fix {crack:.1e} diag"
        )
    print()


# --------------------------------------------------------------------------------------------
# GLSL route


def glsl_case(name: str, V, F, UV, res: int, bits: int, lam: float, repeat: int) -> None:
    Vn, N = make_noisy(V, F, 0.3, 0)
    s = normal_offsets(laplacian_offsets(Vn, F), N)
    img, bias, scale = bake_offset_map(Vn, F, UV, s, res, bits)
    X = denoise_with_map(Vn, F, UV, N, img, bias, scale, lam)
    c, r = 0.5 * (X.min(0) + X.max(0)), 0.5 * float(np.linalg.norm(X.max(0) - X.min(0)))
    eye = c + np.array([0.6, -1.0, 0.7]) / np.linalg.norm([0.6, -1.0, 0.7]) * 2.9 * r
    # The anchor's camera has near 0.5, far 10: scale the mesh to a unit radius around the origin.
    frame = warm_anchor(lambda: pyrender_mesh_frame((X - c) / r, F, ((eye - c) / r, (0, 0, 0)), 512))
    h = float(np.linalg.norm(Vn[F[:, 1]] - Vn[F[:, 0]], axis=1).mean())
    compare_routes(
        f"{name}, {len(V):,} v, {res}^2 {bits}-bit, lam {lam:g}",
        lambda: denoise_with_map(Vn, F, UV, N, img, bias, scale, lam),
        lambda: glsl_denoise_with_map(Vn, F, UV, N, img, bias, scale, lam),
        frame,
        repeat,
        lambda a, b: f"max {np.linalg.norm(a - b, axis=1).max() / h:.2g} h (mean edge)",
    )


def bench_glsl(names: list[str], quick: bool) -> None:
    repeat = 1 if quick else 3
    glsl_route_header(
        f"GLSL ROUTE  denoise_with_map vs shaders/denoise.vert vs pyrender drawing the denoised mesh at 512^2, "
        f"best of {repeat}, interleaved; ratio = route / pyrender frame"
    )
    glsl_case("figure sphere (32, 64)", *datasets.uv_sphere(32, 64), 256, 16, 1.0, repeat)
    for name in names:
        V, F, UV = load(name)
        if UV is not None:
            glsl_case(name, V, F, UV, 512 if quick else 1024, 8, 0.7, repeat)
    if not quick:  # where the vertex stage has work to do: 80k vertices
        glsl_case("uv_torus(400, 200)", *datasets.uv_torus(400, 200), 1024, 16, 0.7, repeat)
    print(
        "  (NumPy and GLSL compute the moved vertices, no picture; pyrender: the denoised mesh drawn, its upload\n"
        "   and trimesh's vertex normals included; 'GLSL 1st' is the route's first call: shader compilation + one run)\n"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer meshes and settings, one repetition")
    ap.add_argument("--no-timing", action="store_true")
    ap.add_argument("--no-quality", action="store_true")
    ap.add_argument("--no-glsl", action="store_true", help="skip the GLSL route")
    args = ap.parse_args(argv)
    names = mesh_names(args.quick)
    print(f"lab denoise benchmark ({'quick' if args.quick else 'full'}); {load_average()}\n")
    if not args.no_timing:
        bench_timing(names, args.quick)
    if not args.no_glsl:
        bench_glsl(names, args.quick)
    if not args.no_quality:
        bench_quality(names, args.quick)
    print(load_average())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
