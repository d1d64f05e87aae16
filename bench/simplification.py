"""Benchmark: lab "simplification" (QEM) against the anchor libraries, in one run.

Run: ``uv run python bench/simplification.py [--quick] [--greedy] [--breakdown] [--only NAME ...]``

First it reports the compile time of the numba kernel (``method="fast"``): a fresh process with
an empty cache folder compiles it, a second process loads it from that cache (numba's
``stats.cache_hits``/``cache_misses`` are printed too). Then, for every mesh and every reduction
level (10% and 1% of the faces kept), it times

* ours, ``method="fast"``: the greedy heap loop compiled with numba (the defaults),
* ours, ``method="fast", refit=True``: the same, then the least-squares fit to the input,
* ours, ``method="greedy"`` (the same heap loop in Python, as the students write it; only with
  ``--greedy``, and only on meshes up to 25,000 faces, since it costs about 1 ms per contraction),
* ``igl.qslim`` (the reference for quality and time),
* ``fast_simplification.simplify``,
* VTK quadric decimation (``pyvista.PolyData.decimate``),

next to each other, and measures on each output: Hausdorff and RMS surface distance relative to
the input's bounding-box diagonal (``geomlib.geometry.mesh_distance``, 50,000 samples per side),
edge-manifoldness, flipped faces (output face normal against the input normal at the closest
point of its centroid), boundary loops kept, faces reached. Times are the best of a few runs
(CPU time of the process: every contender runs on one thread, and on a shared machine wall time
mostly measures the other jobs; the final table gives the wall-time ratio too); ratios are
against ``igl.qslim`` in the same run. Peak memory:
the tracemalloc peak of one call of ours (NumPy allocations; the C++ anchors are invisible to
tracemalloc, so the process's maximum resident set size is printed at the end instead).

With ``--breakdown`` it prints, per mesh and level, where the fast path's time goes instead:
input validation, quadrics, the compiled contraction loop and the least-squares refit, next to
igl.qslim's total.

Meshes: a noise-displaced icosphere (level 6, 81,920 faces; the issue's "100k sphere"), the
built-in torus, sharp box and height field at benchmark resolution, the pyvista airplane, ant
and nut, and the real meshes of ``../shared/data/meshes`` when that folder exists (bunny,
armadillo, fandisk with sharp creases, camelhead with a boundary).
"""

from __future__ import annotations

import argparse
import inspect
import os
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
import warnings
from pathlib import Path

import fast_simplification
import igl
import numpy as np
import pyvista as pv

from bench.measure import SHARED
from geomlib import datasets, topology
from geomlib.geometry import closest_points, face_normals, mesh_distance
from solutions.simplification import qem_simplify

ROOT = Path(__file__).resolve().parents[1]

GREEDY_MAX_FACES = 25_000


def builtin_meshes(quick: bool) -> dict:
    if quick:
        V, F = datasets.icosphere(4)
        return {
            "noisy icosphere 5k": (datasets.add_noise(V, 0.005, seed=1, direction="normal", F=F), F),
            "height field 32": datasets.height_field(32),
        }
    V, F = datasets.icosphere(6)
    return {
        "noisy icosphere 82k": (datasets.add_noise(V, 0.002, seed=1, direction="normal", F=F), F),
        "torus 96x48": datasets.torus(n_major=96, n_minor=48),
        "sharp box 24": datasets.sharp_box(n=24),
        "height field 128": datasets.height_field(128),
        "pyvista airplane": datasets.pyvista_mesh("airplane", manifold=True),
        "pyvista ant": datasets.pyvista_mesh("ant"),
        "pyvista nut": datasets.pyvista_mesh("nut"),
    }


def shared_meshes(quick: bool, folder: Path = SHARED) -> dict:
    """Every triangle mesh of ``../shared/data/meshes``, as ``igl.read_triangle_mesh`` loads it.

    The independent reader's arrays go to every contender unchanged (same vertex order, same
    dtype), so no contender is measured on a mesh another one never saw. Files with quads or
    polygons are left out (they are not triangle meshes).
    """
    from geomlib.mesh_io import read_mesh

    quick_names = ("fandisk.obj", "camelhead.off")
    out = {}
    if not folder.is_dir():
        print(f"no shared meshes: {folder} is not a folder (give --meshes DIR)")
        return out
    for path in sorted(folder.iterdir()):
        if path.suffix not in (".obj", ".off", ".ply") or (quick and path.name not in quick_names):
            continue
        _, F_stored = read_mesh(path)
        if not (isinstance(F_stored, np.ndarray) and F_stored.ndim == 2 and F_stored.shape[1] == 3):
            continue
        V, F = igl.read_triangle_mesh(str(path))
        out[path.name] = (np.ascontiguousarray(V, np.float64), np.ascontiguousarray(F, np.int64))
    return out


def permuted(V, F, seed: int = 0):
    """The same mesh with its vertices renumbered by a fixed random permutation."""
    perm = np.random.default_rng(seed).permutation(len(V))
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(len(V))
    return np.ascontiguousarray(V[perm]), np.ascontiguousarray(inverse[F])


# ----------------------------------------------------------------------------- contenders


def ours_fast(V, F, t):
    return qem_simplify(V, F, t, method="fast", on_unreachable="warn")


def ours_fast_refit(V, F, t):
    return qem_simplify(V, F, t, method="fast", refit=True, on_unreachable="warn")


def ours_greedy(V, F, t):
    return qem_simplify(V, F, t, method="greedy", on_unreachable="warn")


def qslim(V, F, t):
    U, G, _, _ = igl.qslim(V, F.astype(np.int32), t)
    return np.asarray(U), np.asarray(G, np.int64)


def fast_simpl(V, F, t):
    U, G = fast_simplification.simplify(V.astype(np.float32), F.astype(np.int32), 1.0 - t / len(F))
    return np.asarray(U, np.float64), np.asarray(G, np.int64)


def vtk_decimate(V, F, t):
    out = pv.PolyData.from_regular_faces(V, F).decimate(1.0 - t / len(F))
    return np.asarray(out.points, np.float64), np.asarray(out.faces).reshape(-1, 4)[:, 1:].astype(np.int64)


# ----------------------------------------------------------------------------- measures


def flipped_count(V0, F0, V, F) -> int:
    """Faces turned against the input at the closest point to their centroid: more than 120° off, or more
    than 90° for a well-shaped face (quality 4√3 area / Σ edge² > 0.3; a sliver's normal is ill-defined)."""
    C = V[F].mean(axis=1)
    _, face, _ = closest_points(V0, F0, C)
    cos = np.einsum("ij,ij->i", face_normals(V, F), face_normals(V0, F0)[face])
    area2 = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    quality = 2 * np.sqrt(3) * area2 / np.maximum(((V[F] - V[F[:, [1, 2, 0]]]) ** 2).sum(axis=(1, 2)), 1e-300)
    return int(((cos < -0.5) | ((cos < 0) & (quality > 0.3))).sum())


def quality(V0, F0, V, F, n_samples: int) -> dict:
    used = np.unique(F)
    remap = np.full(len(V), -1)
    remap[used] = np.arange(len(used))
    V, F = V[used], remap[F]
    d = mesh_distance(V0, F0, V, F, n_samples=n_samples)
    S = np.sort(F, axis=1)
    return {
        "faces": len(F),
        "hausdorff": d["hausdorff"],
        "rms": d["rms"],
        "manifold": topology.is_edge_manifold(F) and len(np.unique(S, axis=0)) == len(F),
        "flipped": flipped_count(V0, F0, V, F),
        "loops": len(topology.boundary_edges(F)) and _loops(F),
    }


def _loops(F) -> int:
    try:
        return len(topology.boundary_loops(F))
    except Exception:  # a pinched boundary: count it as broken
        return -1


def breakdown(name: str, V, F, t: int, repeats: int) -> None:
    """One line: igl.qslim's time next to the stages of ours (fast path, defaults of qem_simplify)."""
    from geomlib.validate import check_mesh
    from solutions.simplification.compiled import compiled_collapse
    from solutions.simplification.quadrics import vertex_quadrics
    from solutions.simplification.refit import refine_positions

    def best(fn):
        b, out = np.inf, None
        for _ in range(repeats):
            t0 = time.perf_counter()
            out = fn()
            b = min(b, time.perf_counter() - t0)
        return 1000 * b, out

    ms_q, _ = best(lambda: qslim(V, F, t))
    ms_check, _ = best(lambda: check_mesh(V, F, where="bench", manifold=True))
    weight = inspect.signature(qem_simplify).parameters["boundary_weight"].default
    ms_quad, Q = best(lambda: vertex_quadrics(V, F, "area", weight))
    ms_loop, (U, G, N0) = best(lambda: compiled_collapse(V, F, Q, t))
    ms_fit, _ = best(lambda: refine_positions(V, F, U, G, normals0=N0))
    print(
        f"{name[:24]:24s} {len(F):7d} -> {t:6d}  qslim {ms_q:8.1f} ms | ours: check {ms_check:6.1f} + quadrics "
        f"{ms_quad:6.1f} + compiled loop {ms_loop:7.1f} = {ms_check + ms_quad + ms_loop:7.1f} ms "
        f"({(ms_check + ms_quad + ms_loop) / ms_q:4.2f}x qslim) + refit {ms_fit:7.1f} ms "
        f"({(ms_check + ms_quad + ms_loop + ms_fit) / ms_q:4.2f}x qslim in all)"
    )


_COMPILE_PROBE = """
import json, sys, time
t0 = time.perf_counter()
sys.path.insert(0, {root!r})
from geomlib import datasets
from solutions.simplification import qem_simplify
from solutions.simplification.compiled import greedy_collapse
V, F = datasets.icosphere(2)
t1 = time.perf_counter()
qem_simplify(V, F, 40, method="fast", refit=False)
t2 = time.perf_counter()
qem_simplify(V, F, 40, method="fast", refit=False)
t3 = time.perf_counter()
print(json.dumps({{"imports": t1 - t0, "first": t2 - t1, "second": t3 - t2,
                  "hits": sum(greedy_collapse.stats.cache_hits.values()),
                  "misses": sum(greedy_collapse.stats.cache_misses.values())}}))
"""


def compile_time() -> None:
    """First-call time of the compiled kernel in a fresh process: cold (compiles) and warm (cache hit)."""
    import json

    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        for label in ("cold cache (compiles)", "warm cache (loads)"):
            out = subprocess.run(
                [sys.executable, "-c", _COMPILE_PROBE.format(root=str(ROOT))],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            )
            r = json.loads(out.stdout.strip().splitlines()[-1])
            print(
                f"compiled kernel, {label:22s}: first call {r['first']:6.2f} s, second call {1000 * r['second']:5.1f} ms "
                f"(icosphere 320 -> 40 faces; cache hits {r['hits']}, misses {r['misses']}; imports {r['imports']:.2f} s)"
            )
    print()


def timed(fn, V, F, t, repeats: int) -> tuple[float, float, tuple]:
    """Best CPU time and best wall time over ``repeats`` calls, and the last output.

    CPU time (``time.process_time``) is the one compared: ours and igl.qslim both run on one thread,
    and on a machine shared with other jobs wall time mostly measures how long the others held the
    core (the same igl.qslim call took 15 s and 69 s of wall time in two runs at load 10-16).
    """
    best_cpu, best_wall, out = np.inf, np.inf, None
    for _ in range(repeats):
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn(V, F, t)
        best_cpu = min(best_cpu, time.process_time() - c0)
        best_wall = min(best_wall, time.perf_counter() - t0)
    return best_cpu, best_wall, out


def peak_memory_mb(fn, V, F, t) -> float:
    tracemalloc.start()
    fn(V, F, t)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small meshes, one repeat, fewer samples")
    ap.add_argument(
        "--greedy", action="store_true", help=f"also time the greedy loop (meshes <= {GREEDY_MAX_FACES} faces)"
    )
    ap.add_argument("--only", nargs="*", help="substrings of mesh names to run")
    ap.add_argument("--levels", nargs="*", type=float, default=[0.1, 0.01])
    ap.add_argument("--breakdown", action="store_true", help="where the fast path's time goes, against igl.qslim")
    ap.add_argument("--repeats", type=int, help="timed runs per contender, best kept (default 3, 1 with --quick)")
    ap.add_argument("--meshes", type=Path, default=SHARED, help=f"folder of the shared meshes (default {SHARED})")
    ap.add_argument("--shared-only", action="store_true", help="only the meshes of ../shared/data/meshes")
    ap.add_argument("--contenders", nargs="*", help="labels of the contenders to run (igl.qslim always runs)")
    ap.add_argument("--no-permutation", action="store_true", help="skip the vertex-order check")
    ap.add_argument("--no-compile-time", action="store_true", help="skip the compile-time probe")
    args = ap.parse_args()
    repeats = args.repeats or (1 if args.quick else 3)
    n_samples = 20_000 if args.quick else 50_000
    shared = shared_meshes(args.quick, args.meshes)
    meshes = shared if args.shared_only else {**builtin_meshes(args.quick), **shared}
    if args.only:
        meshes = {k: v for k, v in meshes.items() if any(s in k for s in args.only)}
    ours_fast(*datasets.icosphere(1), 20)  # load (or compile) the kernel before anything is timed
    if args.breakdown:
        for name, (V, F) in meshes.items():
            V, F = np.ascontiguousarray(V, np.float64), np.ascontiguousarray(F, np.int64)
            for level in args.levels:
                breakdown(name, V, F, max(4, int(round(level * len(F)))), repeats)
        return
    if not args.no_compile_time:
        compile_time()
    contenders = {
        "ours fast": ours_fast,
        "fast+refit": ours_fast_refit,
        "igl.qslim": qslim,
        "fast-simpl": fast_simpl,
        "VTK": vtk_decimate,
    }
    if args.contenders:
        contenders = {k: v for k, v in contenders.items() if k in args.contenders or k == "igl.qslim"}
    print(
        f"{'mesh':24s} {'keep':>5s} {'method':11s} {'faces':>7s} {'cpu s':>8s} {'/qslim':>7s} "
        f"{'Hausdorff':>10s} {'/qslim':>7s} {'RMS':>10s} {'/qslim':>7s} {'manif':>5s} {'flip':>5s} {'loops':>5s} "
        f"{'perm H':>7s}"
    )
    print(
        "(perm H: Hausdorff on the same mesh with its vertices renumbered, over Hausdorff as read; "
        "'!' marks a contender whose result moves by more than 25% with vertex order)"
    )
    summary, table = [], []
    for name, (V, F) in meshes.items():
        V, F = np.ascontiguousarray(V, np.float64), np.ascontiguousarray(F, np.int64)
        Vp, Fp = permuted(V, F)
        loops0 = _loops(F)
        for level in args.levels:
            t = max(4, int(round(level * len(F))))
            runs = dict(contenders)
            if args.greedy and len(F) <= GREEDY_MAX_FACES:
                runs["ours greedy"] = ours_greedy
            res = {}
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                for label, fn in runs.items():
                    try:
                        sec, wall, (U, G) = timed(fn, V, F, t, 1 if label == "ours greedy" else repeats)
                        q = quality(V, F, U, G, n_samples)
                        q["wall"] = wall
                        if not args.no_permutation and label != "ours greedy":
                            Up, Gp = fn(Vp, Fp, t)
                            q["perm"] = quality(Vp, Fp, Up, Gp, n_samples)["hausdorff"] / q["hausdorff"]
                        res[label] = (sec, q)
                    except Exception as e:  # an anchor failing on a mesh is a result too
                        res[label] = (np.nan, {"error": f"{type(e).__name__}: {e}"[:60]})
            ref_t, ref_q = res["igl.qslim"]
            for label, (sec, q) in res.items():
                if "error" in q:
                    print(f"{name[:24]:24s} {level:5.0%} {label:11s} failed: {q['error']}")
                    continue
                perm = q.get("perm")
                perm_s = "" if perm is None else f"{perm:6.2f}{'!' if abs(np.log(perm)) > np.log(1.25) else ' '}"
                print(
                    f"{name[:24]:24s} {level:5.0%} {label:11s} {q['faces']:7d} {sec:8.3f} {sec / ref_t:7.2f} "
                    f"{q['hausdorff']:10.2e} {q['hausdorff'] / ref_q['hausdorff']:7.2f} {q['rms']:10.2e} "
                    f"{q['rms'] / ref_q['rms']:7.2f} {'yes' if q['manifold'] else 'NO':>5s} {q['flipped']:5d} "
                    f"{q['loops']}/{loops0:<3d} {perm_s:>7s}"
                )
            for label in ("ours fast", "fast+refit"):
                if label not in res:
                    continue
                sec, q = res[label]
                if "error" not in q and "error" not in ref_q:
                    summary.append(
                        (
                            label,
                            name in shared,
                            sec / ref_t,
                            q["hausdorff"] / ref_q["hausdorff"],
                            q["rms"] / ref_q["rms"],
                        )
                    )
                    if label == "ours fast":
                        table.append(
                            (
                                name,
                                level,
                                q["faces"],
                                q["hausdorff"],
                                ref_q["hausdorff"],
                                sec / ref_t,
                                q["wall"] / ref_q["wall"],
                            )
                        )
            print()
    if summary:
        big = max(meshes, key=lambda k: len(meshes[k][1]))
        V, F = meshes[big]
        mem = peak_memory_mb(ours_fast_refit, V, F, max(4, len(F) // 10))
        print(
            f"peak memory of ours (fast+refit), {big} ({len(F)} faces) -> 10%: {mem:.0f} MB (tracemalloc); "
            f"input arrays {(V.nbytes + F.nbytes) / 2**20:.1f} MB"
        )
        print(
            f"max resident set size of this process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB"
        )
        for label in ("ours fast", "fast+refit"):
            r = np.array([s[2:] for s in summary if s[0] == label])
            if len(r):
                print(
                    f"{label} vs igl.qslim over {len(r)} runs (geometric means): time x{np.exp(np.log(r[:, 0]).mean()):.2f}, "
                    f"Hausdorff x{np.exp(np.log(r[:, 1]).mean()):.3f}, RMS x{np.exp(np.log(r[:, 2]).mean()):.3f}; "
                    f"worst: time x{r[:, 0].max():.2f}, Hausdorff x{r[:, 1].max():.2f}, RMS x{r[:, 2].max():.3f}"
                )
        r = np.array([s[2:] for s in summary if s[0] == "ours fast" and s[1]])
        if len(r):
            print(f"\ntargets (ours fast, defaults, against igl.qslim on the {len(r)} runs over the shared meshes):")
            for what, value, limit in (
                ("Hausdorff, worst case", r[:, 1].max(), 1.25),
                ("Hausdorff, geometric mean", np.exp(np.log(r[:, 1]).mean()), 1.0),
                ("time, worst case", r[:, 0].max(), 1.0),
            ):
                print(f"  {what:26s} x{value:5.2f}  (target <= x{limit:.2f}): {'met' if value <= limit else 'NOT MET'}")
    if table:
        print_table(table, shared)


def print_table(table: list, shared: dict) -> None:
    """One Markdown table over every case, ours fast (the defaults) against igl.qslim, for the handout."""
    print(f"\nours fast (defaults) against igl.qslim, every case (load average {os.getloadavg()[0]:.1f}):\n")
    print("| mesh | kept | faces | Hausdorff ours | igl.qslim | ratio | CPU time ratio | wall time ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, level, faces, ours, ref, cpu_ratio, wall_ratio in table:
        label = name if name in shared else f"{name} (built-in)"
        print(
            f"| {label} | {level:.0%} | {faces} | {ours:.2e} | {ref:.2e} | {ours / ref:.2f} | {cpu_ratio:.2f} "
            f"| {wall_ratio:.2f} |"
        )


if __name__ == "__main__":
    main()
