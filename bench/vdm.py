"""Benchmark: lab "vdm" (reference solution) against the anchor libraries, in one run.

Run: ``uv run python bench/vdm.py [--quick]``

1. **Headline**: symmetric Hausdorff and Chamfer distance (relative to the bbox diagonal) between
   the VDM's grid mesh and the original, for naive / +density / +alignment / +diagonals at 16^2,
   32^2, 64^2, on the built-in rock-on-a-plinth, the open sharp box, a height-field patch and, when
   ``../shared/data/meshes`` exists, the disk meshes camelhead and mountain.
2. **Target**: a 64^2 bake with every stage of a ~50k-face mesh (``rock_on_plinth(158)`` and
   ``mountain.obj``), stage by stage, with the transport's share.
3. **Anchors** (same run): parameterization against ``igl.harmonic`` / ``igl.lscm``; uv point
   location against matplotlib's ``TrapezoidMapTriFinder``; the transport (back-and-forth
   method) against POT's exact ``ot.emd`` on the same discrete problem (uniform grid points to
   the field's pixels), with the map difference in pixels and the transport costs.

Times are the best of a few runs. Peak memory: each contender of the transport comparison runs
once in a fresh child process (imports done before the clock starts) and reports the larger of
its tracemalloc peak (NumPy arrays) and its peak resident set size above the baseline
(``resource.getrusage``, which also sees POT's C++ allocations); elsewhere the tracemalloc peak
of one call is shown.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import resource
import time
import tracemalloc
from pathlib import Path

import igl
import numpy as np

from bench.anchors import pixel_centres, pot_transport_map
from bench.measure import SHARED, best_of, peak_mib
from geomlib import datasets
from geomlib.geometry import mesh_distance
from geomlib.mesh_io import read_mesh
from solutions.vdm import (
    align_to_features,
    area_density,
    bake_vdm,
    check_disk,
    choose_diagonals,
    importance_field,
    naive_vdm,
    open_box,
    parameterize_square,
    sample_surface,
    sharp_features,
    transport_grid,
    vdm_to_mesh,
    vertex_importance,
)
from solutions.vdm.transport import bfm_potentials, soft_legendre_map

STAGES = {
    "naive": dict(optimize=False, align=False, diagonals=False),
    "+density": dict(optimize=True, align=False, diagonals=False),
    "+alignment": dict(optimize=True, align=True, diagonals=False),
    "+diagonals": dict(optimize=True, align=True, diagonals=True),
}


def shared_meshes() -> dict:
    out = {}
    if SHARED.is_dir():
        for name in ("camelhead.off", "mountain.obj"):
            if (SHARED / name).is_file():
                V, F = read_mesh(SHARED / name, triangulate=True)
                out[Path(name).stem] = (np.asarray(V, np.float64), np.asarray(F, np.int64))
    return out


# ------------------------------------------------------------------------------------------------


def headline(meshes: dict, resolutions: list[int], n_samples: int) -> None:
    print("\n== Headline: reconstruction error (Hausdorff / Chamfer, relative to the bbox diagonal) ==")
    print(f"{'mesh':<12} {'res':>4}  " + "  ".join(f"{s:>21}" for s in STAGES))
    for name, (V, F) in meshes.items():
        UV = parameterize_square(V, F)
        for res in resolutions:
            cells = []
            for st in STAGES.values():
                vdm = bake_vdm(V, F, res, UV=UV, **st)
                d = mesh_distance(V, F, *vdm_to_mesh(vdm), n_samples=n_samples)
                cells.append(f"{d['hausdorff']:.2e} / {d['chamfer']:.2e}")
            print(f"{name:<12} {res:>4}  " + "  ".join(f"{c:>21}" for c in cells), flush=True)


def target(meshes: dict, res: int) -> None:
    print(f"\n== Target: {res}^2 bake with every stage (<= 10 s), stage by stage ==")
    for name, (V, F) in meshes.items():
        t = {}
        t0 = time.perf_counter()
        UV = parameterize_square(V, F)
        t["parameterize"] = time.perf_counter() - t0
        s = time.perf_counter()
        imp = vertex_importance(V, F)
        fld = importance_field(UV, imp, max(64, res), density=area_density(V, F, UV, max(64, res)))
        t["importance+field"] = time.perf_counter() - s
        s = time.perf_counter()
        G = transport_grid(fld, res)
        t["transport"] = time.perf_counter() - s
        s = time.perf_counter()
        edges, corners = sharp_features(V, F)
        G = align_to_features(G, V, F, UV, edges, corners)
        t["features+align"] = time.perf_counter() - s
        s = time.perf_counter()
        choose_diagonals(G, V, F, UV, edges)
        t["diagonals"] = time.perf_counter() - s
        s = time.perf_counter()
        naive_vdm(V, F, UV, res, grid_uv=G)
        t["sampling"] = time.perf_counter() - s
        total = time.perf_counter() - t0
        parts = ", ".join(f"{k} {v:.2f}s" for k, v in t.items())
        print(
            f"{name:<12} {len(F):>7} faces: total {total:.2f} s ({'OK' if total <= 10 else 'OVER'} the 10 s target); "
            f"transport share {100 * t['transport'] / total:.0f}%\n             {parts}",
            flush=True,
        )


def anchors_parameterization(meshes: dict) -> None:
    print("\n== Anchor: parameterization (ours vs libigl with the same boundary) ==")
    for name, (V, F) in meshes.items():
        _, _, loop = check_disk(V, F)
        t_ours, _, UV = best_of(lambda V=V, F=F: parameterize_square(V, F, "harmonic"))
        bnd = UV[loop]
        t_igl, _, _ = best_of(lambda V=V, F=F, loop=loop, bnd=bnd: igl.harmonic(V, F, loop, bnd, 1))
        t_lscm, _, _ = best_of(lambda V=V, F=F: parameterize_square(V, F, "lscm"), 1)
        t_igl_lscm, _, _ = best_of(lambda V=V, F=F, loop=loop, bnd=bnd: igl.lscm(V, F, loop, bnd), 1)
        print(
            f"{name:<12} {len(F):>7} faces: harmonic ours {t_ours:.3f} s / igl.harmonic {t_igl:.3f} s "
            f"(x{t_ours / t_igl:.2f}, ours adds disk checks + corner choice); lscm (sliding boundary) {t_lscm:.3f} s / "
            f"igl.lscm (pinned) {t_igl_lscm:.3f} s (x{t_lscm / t_igl_lscm:.2f})",
            flush=True,
        )


def anchors_sampling(meshes: dict, k: int) -> None:
    from matplotlib.tri import LinearTriInterpolator, Triangulation

    print(f"\n== Anchor: sampling {k} uv points (ours vs matplotlib TrapezoidMapTriFinder + linear interpolation) ==")
    rng = np.random.default_rng(0)
    X = rng.random((k, 2))
    for name, (V, F) in meshes.items():
        UV = parameterize_square(V, F)
        t_ours, _, P = best_of(lambda V=V, F=F, UV=UV: sample_surface(V, F, UV, X))
        peak = peak_mib(lambda V=V, F=F, UV=UV: sample_surface(V, F, UV, X))

        def mpl(V=V, F=F, UV=UV):
            tri = Triangulation(UV[:, 0], UV[:, 1], F)
            return np.stack([np.asarray(LinearTriInterpolator(tri, V[:, c])(X[:, 0], X[:, 1])) for c in range(3)], 1)

        t_mpl, _, Q = best_of(mpl, 1)
        print(
            f"{name:<12} {len(F):>7} faces: ours {t_ours:.3f} s (peak {peak:.0f} MB) / matplotlib {t_mpl:.3f} s "
            f"(x{t_ours / t_mpl:.2f}); max |difference| {np.nanmax(np.abs(P - Q)):.1e}",
            flush=True,
        )


def _child(queue, which: str, field: np.ndarray, res: int) -> None:
    """Run one transport contender in a fresh process; report time, peak RSS above baseline and output."""
    import ot  # noqa: F401  (imported before the clock starts)

    n = field.shape[0]
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    t = time.perf_counter()
    if which == "ours":
        phi, _, info = bfm_potentials(field, 20)
        tt = np.linspace(0, 1, res) if res else (np.arange(n) + 0.5) / n
        out = soft_legendre_map(phi, tt, tt, 1.0 / n**2).reshape(-1, 2)
        extra = 2 * info["dual"]
    else:
        out, extra = pot_transport_map(field)
    dt = time.perf_counter() - t
    traced = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    rss = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) / 1024  # kB -> MB (Linux)
    queue.put((dt, max(traced, rss), out, extra))


def run_child(which: str, field: np.ndarray, res: int):
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    p = ctx.Process(target=_child, args=(q, which, field, res))
    p.start()
    out = q.get()
    p.join()
    return out


def anchors_transport(sizes: list[int]) -> None:
    print(
        "\n== Anchor: optimal transport, uniform -> importance field of the rock (ours: back-and-forth; POT: ot.emd) =="
    )
    V, F = datasets.rock_on_plinth()
    UV = parameterize_square(V, F)
    for n in sizes:
        field = importance_field(UV, vertex_importance(V, F), n, density=area_density(V, F, UV, n))
        t_ours, m_ours, T_ours, w_ours = run_child("ours", field, 0)  # map at the n^2 pixel centres
        t_pot, m_pot, T_pot, w_pot = run_child("pot", field, 0)
        err = np.linalg.norm(T_ours - T_pot, axis=1) * n
        cost_ours = float(np.mean(np.sum((T_ours - pixel_centres(n)) ** 2, axis=1)))
        print(
            f"{n}x{n} ({n * n} points): ours {t_ours:.2f} s, peak +{m_ours:.0f} MB | POT ot.emd {t_pot:.2f} s, "
            f"peak +{m_pot:.0f} MB | time ratio ours/POT x{t_ours / t_pot:.3f} | W2^2 POT {w_pot:.5f}, ours (dual) "
            f"{w_ours:.5f}, ours (map) {cost_ours:.5f} | map difference mean {err.mean():.2f} px, max {err.max():.2f} px",
            flush=True,
        )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small meshes and sizes only (about a minute)")
    args = ap.parse_args(argv)
    quick = args.quick
    builtin = {
        "rock": datasets.rock_on_plinth(),
        "box": open_box(8),
        "heightfield": datasets.height_field(32),
    }
    shared = {} if quick else shared_meshes()
    if not quick and not shared:
        print(f"(no shared meshes at {SHARED}; built-in meshes only)")
    headline(
        {**builtin, **shared} if not quick else {"rock": builtin["rock"], "box": builtin["box"]},
        [16, 32] if quick else [16, 32, 64],
        5000 if quick else 30000,
    )
    big = {"rock-158": datasets.rock_on_plinth(158)}
    if "mountain" in shared:
        big["mountain"] = shared["mountain"]
    target({"rock-48": builtin["rock"]} if quick else big, 32 if quick else 64)
    anchors_parameterization({"rock-48": builtin["rock"]} if quick else {**big, **shared})
    anchors_sampling({"rock-48": builtin["rock"]} if quick else big, 4096 if quick else 64 * 64 * 16)
    anchors_transport([16, 32] if quick else [32, 64])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
