"""Benchmark: lab "remeshing" (isotropic remeshing) against gpytoolbox's ``remesh_botsch``, trueform and CGAL, in one run.

Run: ``uv run python bench/remeshing.py [--quick] [--iterations N]``

The other tools are benchmark-only, not dependencies of the course: they are looked up in a
throwaway virtual environment (``--gpy-python``, default ``/tmp/gpyvenv/bin/python``; make it with
``uv venv /tmp/gpyvenv && VIRTUAL_ENV=/tmp/gpyvenv uv pip install gpytoolbox trueform cgal``) and
run there in a subprocess on the same input, timed inside that process. A tool that is not
installed is skipped with a message. CGAL's Python bindings cannot protect feature edges, so CGAL
runs only on meshes remeshed without features.

Per mesh of ``--meshes`` (default ``../shared/data/meshes``; every ``.obj/.off/.ply/.stl`` there,
read by ``igl.read_triangle_mesh`` and given as the same arrays to every contender; a mesh that is
not a manifold, oriented triangle mesh is skipped with the reason) and per target h = 1.5x and
0.75x its mean edge, it runs ``isotropic_remesh(V, F, h)`` with its defaults and gpytoolbox's
``remesh_botsch`` (``--iterations``, boundary kept, same h), then prints one table over the whole
set: faces, minimum angle, edge-length std / mean, Hausdorff distance to the input relative to
its bbox diagonal (``geomlib.geometry.mesh_distance``) and time (best of ``--repeat``, default 2; wall
clock, or with ``--cpu`` each process's CPU time, steadier on a loaded machine; on a case whose
one run of each takes under ``--round-limit`` seconds, ``--rounds`` times ``--repeat`` runs of ours
and of gpytoolbox's, alternating one by one with gpytoolbox's process kept up, so that both meet
the same swings of a shared machine's load), ours / gpytoolbox
with the ratios, and a summary line of the targets (met / not met): minimum angle no worse on
every case, Hausdorff <= 1.15x on every case and <= 1x in geometric mean, time <= 1x. Other
tools (``--tools trueform CGAL``) are listed below it. It also reports the kernels' first-call
cost (compile with a fresh numba cache, in a subprocess, and cache load; ``--no-first-call``
skips it). ``--quick`` uses the built-in bumpy sphere and height field; ``--only NAME ...``
restricts the set; ``--json`` writes the cases.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import igl
import numpy as np

from bench.measure import SHARED
from geomlib import datasets
from geomlib.geometry import mesh_distance
from solutions.remeshing import isotropic_remesh
from solutions.remeshing.figures import quality as mesh_quality

ROOT = Path(__file__).resolve().parents[1]

# Each tool runs in the throwaway environment: it reads in.npz (V, F, h, its, feature_edges or the
# feature angle, the clock and the number of runs) and writes out.npz (V, F, t = best time of the
# runs, timed inside that process).
TOOL_SCRIPTS = {
    "gpytoolbox": r"""
import sys, time, numpy as np
from gpytoolbox import icosphere, remesh_botsch
d = np.load(sys.argv[1])
V, F, h, its = d["V"], d["F"].astype(np.int32), float(d["h"]), int(d["its"])
fe = d["feature_edges"].reshape(-1, 2).astype(np.int32)
remesh_botsch(*icosphere(2), i=2, h=0.3, project=True)  # warm up on a small mesh, as ours is before timing
best = np.inf
clock = time.process_time if int(d["cpu"]) else time.perf_counter
for _ in range(int(d["repeat"])):
    t = clock()
    U, G = remesh_botsch(V, F, i=its, h=h, feature_edges=fe if len(fe) else None, project=True)
    best = min(best, clock() - t)
np.savez(sys.argv[2], V=U, F=G, t=best)
""",
    # trueform splits edges longer than target_length (not 4/3 of it) and relaxes 3 times per
    # iteration by default; run as documented, with its own feature detection when asked for.
    "trueform": r"""
import sys, time, numpy as np
import trueform as tf
d = np.load(sys.argv[1])
V, F, h, its, fa = d["V"], d["F"].astype(np.int32), float(d["h"]), int(d["its"]), float(d["feature_angle"])
best = np.inf
clock = time.process_time if int(d["cpu"]) else time.perf_counter
for _ in range(int(d["repeat"])):
    t = clock()
    G, U = tf.isotropic_remeshed((F, V), h, iterations=its, feature_angle=fa)
    best = min(best, clock() - t)
np.savez(sys.argv[2], V=U, F=G, t=best)
""",
    # CGAL's Python bindings (SWIG) take a Polyhedron_3, built from an OFF file; features are not
    # protected here (the bindings expose no edge-constraint map), so it runs only without them.
    "CGAL": r"""
import sys, time, tempfile, os, numpy as np
from CGAL.CGAL_Polyhedron_3 import Polyhedron_3
from CGAL import CGAL_Polygon_mesh_processing as PMP
d = np.load(sys.argv[1])
V, F, h, its = d["V"], d["F"], float(d["h"]), int(d["its"])
if float(d["feature_angle"]) >= 0:
    sys.exit("features are not protected through CGAL's Python bindings: skipped")
tmp = tempfile.mkdtemp()
with open(os.path.join(tmp, "in.off"), "w") as f:
    f.write(f"OFF\n{len(V)} {len(F)} 0\n")
    np.savetxt(f, V, fmt="%.17g")
    np.savetxt(f, np.column_stack([np.full(len(F), 3), F]), fmt="%d")
best = np.inf
clock = time.process_time if int(d["cpu"]) else time.perf_counter
for _ in range(int(d["repeat"])):
    P = Polyhedron_3(os.path.join(tmp, "in.off"))
    t = clock()
    PMP.isotropic_remeshing([f for f in P.facets()], h, P, its)
    best = min(best, clock() - t)
P.write_to_file(os.path.join(tmp, "out.off"))
lines = open(os.path.join(tmp, "out.off")).read().split()
n, m = int(lines[1]), int(lines[2])
U = np.array(lines[4 : 4 + 3 * n], float).reshape(n, 3)
G = np.array(lines[4 + 3 * n : 4 + 3 * n + 4 * m], np.int64).reshape(m, 4)[:, 1:]
np.savez(sys.argv[2], V=U, F=G, t=best)
""",
}
#: gpytoolbox in a process that stays up: one run per line ``run`` on its stdin (it prints the time),
#: then ``save`` writes out.npz; so that its runs alternate with ours one by one (:func:`paired_runs`).
GPY_SERVER = r"""
import sys, time, numpy as np
from gpytoolbox import icosphere, remesh_botsch
d = np.load(sys.argv[1])
V, F, h, its = d["V"], d["F"].astype(np.int32), float(d["h"]), int(d["its"])
fe = d["feature_edges"].reshape(-1, 2).astype(np.int32)
remesh_botsch(*icosphere(2), i=2, h=0.3, project=True)  # warm up on a small mesh, as ours is before timing
clock = time.process_time if int(d["cpu"]) else time.perf_counter
for line in sys.stdin:
    if line.strip() != "run":
        break
    t = clock()
    U, G = remesh_botsch(V, F, i=its, h=h, feature_edges=fe if len(fe) else None, project=True)
    print(clock() - t, flush=True)
np.savez(sys.argv[2], V=U, F=G, t=0.0)
"""


#: What each tool needs importable in the throwaway environment.
TOOL_MODULES = {"gpytoolbox": "gpytoolbox", "trueform": "trueform", "CGAL": "CGAL.CGAL_Polygon_mesh_processing"}


def quality(V0, F0, V, F) -> dict:
    """The lab figures' quality measures (:func:`solutions.remeshing.figures.quality`) and the
    Hausdorff distance to the input relative to its bounding-box diagonal."""
    return {**mesh_quality(V, F), "hausdorff": mesh_distance(V0, F0, V, F, n_samples=50_000)["hausdorff"]}


#: The two targets of the comparison, as multiples of the input's mean edge length.
FACTORS = (1.5, 0.75)


def meshes(quick: bool, folder: Path, only: list[str] | None = None) -> tuple[list, list]:
    """``([(name, V, F)], [(name, why skipped)])``: every mesh file of ``folder`` (as
    ``igl.read_triangle_mesh`` reads it, the same arrays for every contender), or with ``quick``
    (or no folder) the built-in bumpy sphere and height field."""
    from geomlib.errors import MeshError
    from geomlib.validate import check_mesh

    out, skipped = [], []
    if folder.is_dir() and not quick:
        for path in sorted(folder.iterdir()):
            if path.suffix.lower() not in (".obj", ".off", ".ply", ".stl"):
                continue
            name = path.stem
            if only and name not in only:
                continue
            V, F = igl.read_triangle_mesh(str(path))
            try:
                V, F = check_mesh(V, F.astype(np.int64), where=name, manifold=True)
            except MeshError as e:
                skipped.append((name, str(e)))
                continue
            out.append((name, V, F))
        if only:  # in the order asked for (small meshes first keeps a loaded run's early rows)
            out.sort(key=lambda c: only.index(c[0]))
    else:
        if not quick:
            print(f"no folder {folder}: the built-in meshes instead (give the shared set with --meshes)")
        V, F = datasets.icosphere(4)
        out.append(("bumpy sphere", datasets.add_noise(V, 0.01, seed=0, direction="normal", F=F), F))
        out.append(("height field", *datasets.height_field(48)))
    return out, skipped


def run_tool(tool, py, V, F, h, its, feature_angle, cpu=False, repeat=2):
    """Run ``tool`` (a key of :data:`TOOL_SCRIPTS`) in the environment of ``py``: (V, F, time) or (None, why)."""
    with tempfile.TemporaryDirectory() as tmp:
        feat = np.zeros((0, 2), np.int64)
        if feature_angle is not None:  # the same sharp edges for both
            from solutions.remeshing import sharp_edges

            feat = sharp_edges(V, F, feature_angle)
        fa = -1.0 if feature_angle is None else float(feature_angle)
        np.savez(f"{tmp}/in.npz", V=V, F=F, h=h, its=its, feature_edges=feat, feature_angle=fa, cpu=cpu, repeat=repeat)
        script = TOOL_SCRIPTS[tool]
        r = subprocess.run([py, "-c", script, f"{tmp}/in.npz", f"{tmp}/out.npz"], capture_output=True, text=True)
        if r.returncode:
            return None, r.stderr.strip().splitlines()[-1] if r.stderr else "failed"
        d = np.load(f"{tmp}/out.npz")
        return (d["V"], d["F"].astype(np.int64), float(d["t"])), None


def paired_runs(py, V, F, h, its, clock, cpu, runs):
    """``runs`` runs of ours and of gpytoolbox (in one process of ``py`` that stays up), alternating
    one by one, so that both meet the same moments of a shared machine's load: ``(ours, gpy, why)``
    with ``ours = (V, F, best time)`` and ``gpy`` the same or None (``why`` says what failed)."""
    best, res = np.inf, None
    with tempfile.TemporaryDirectory() as tmp:
        np.savez(f"{tmp}/in.npz", V=V, F=F, h=h, its=its, feature_edges=np.zeros((0, 2), np.int64), cpu=cpu)
        p = subprocess.Popen(
            [py, "-c", GPY_SERVER, f"{tmp}/in.npz", f"{tmp}/out.npz"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        gbest = np.inf
        try:
            for _ in range(runs):
                t = clock()
                res = isotropic_remesh(V, F, h, iterations=its)
                best = min(best, clock() - t)
                p.stdin.write("run\n")
                p.stdin.flush()
                gbest = min(gbest, float(p.stdout.readline()))
            p.stdin.write("save\n")
            p.stdin.flush()
        except (BrokenPipeError, ValueError):
            pass
        _, err = p.communicate()
        ours = (*res, best)
        if p.returncode or not np.isfinite(gbest):
            return ours, None, (err.strip().splitlines() or ["failed"])[-1]
        d = np.load(f"{tmp}/out.npz")
        return ours, (d["V"], d["F"].astype(np.int64), gbest), None


def first_call_costs() -> dict:
    code = (
        "import time; t = time.perf_counter(); from geomlib import datasets; "
        "from solutions.remeshing import isotropic_remesh as r; V, F = datasets.rock_on_plinth(16); "
        "r(V, F, 0.07, iterations=2); print(time.perf_counter() - t)"
    )
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        for label in ("compile (empty numba cache)", "cache load"):
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            r = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True)
            out[label] = float(r.stdout.strip() or "nan")
    return out


def _gmean(x) -> float:
    return float(np.exp(np.mean(np.log(x))))


def summary(cases: list[dict]) -> list[tuple[str, bool, str]]:
    """The targets of the comparison with gpytoolbox: ``(target, met, what was measured)``."""
    worse = [c for c in cases if c["ours"]["min_angle"] < c["gpy"]["min_angle"]]
    hd = np.array([c["ours"]["hausdorff"] / c["gpy"]["hausdorff"] for c in cases])
    tr = np.array([c["ours"]["time"] / c["gpy"]["time"] for c in cases])
    return [
        ("minimum angle no worse on every case", not worse, f"worse in {len(worse)} of {len(cases)}"),
        ("Hausdorff <= 1.15x on every case", bool(hd.max() <= 1.15), f"max {hd.max():.2f}x"),
        ("Hausdorff <= 1x in geometric mean", _gmean(hd) <= 1.0, f"{_gmean(hd):.2f}x"),
        ("time <= 1x on every case", bool(tr.max() <= 1.0), f"{tr.min():.2f}-{tr.max():.2f}x"),
    ]


def table(cases: list[dict]) -> str:
    """One table over the whole set: ours / gpytoolbox per case, with the ratios, and the summary."""
    head = (
        f"{'mesh':<20}{'h':>6}{'faces':>15}{'min angle (deg)':>18}{'edge std/mean':>15}"
        f"{'Hausdorff (x1e-3 diag)':>24}{'ratio':>7}{'time (s)':>14}{'ratio':>7}"
    )
    lines = [head, "-" * len(head)]
    for c in cases:
        o, g = c["ours"], c["gpy"]
        lines.append(
            f"{c['mesh']:<20}{c['factor']:>5.2f}x"
            f"{o['faces']:>8}/{g['faces']:<6}"
            f"{o['min_angle']:>9.1f} /{g['min_angle']:>5.1f}  "
            f"{o['edge_cv']:>7.3f} /{g['edge_cv']:.3f}"
            f"{1e3 * o['hausdorff']:>13.3f} /{1e3 * g['hausdorff']:<8.3f}"
            f"{o['hausdorff'] / g['hausdorff']:>7.2f}"
            f"{o['time']:>7.2f} /{g['time']:<5.2f}{o['time'] / g['time']:>7.2f}"
        )
    lines.append("-" * len(head))
    lines.append("targets: " + "; ".join(f"{t}: {'met' if ok else 'NOT met'} ({m})" for t, ok, m in summary(cases)))
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="the built-in meshes instead of the shared set")
    ap.add_argument("--meshes", type=Path, default=SHARED, help=f"folder of test meshes (default {SHARED})")
    ap.add_argument("--only", nargs="*", help="mesh names (file stems) to run, default all")
    ap.add_argument("--iterations", type=int, default=10)
    ap.add_argument("--gpy-python", default="/tmp/gpyvenv/bin/python")
    ap.add_argument("--tools", nargs="*", default=["gpytoolbox"], help=f"contenders among {list(TOOL_SCRIPTS)}")
    ap.add_argument("--json", type=Path, help="also write the cases here")
    ap.add_argument("--repeat", type=int, default=2, help="runs per case and tool, the best time counts")
    ap.add_argument(
        "--rounds",
        type=int,
        default=10,
        help="on a case whose one run of ours and gpytoolbox's takes under --round-limit seconds, "
        "--rounds x --repeat runs of each, alternating one by one (a small mesh's milliseconds swing with the load)",
    )
    ap.add_argument("--round-limit", type=float, default=2.0, help="see --rounds (seconds of CPU or wall time)")
    ap.add_argument(
        "--cpu", action="store_true", help="time = CPU time of the process (time.process_time): steadier under load"
    )
    ap.add_argument("--no-first-call", action="store_true", help="skip measuring the compile and cache-load cost")
    args = ap.parse_args()
    tools = [
        t
        for t in args.tools
        if Path(args.gpy_python).exists()
        and subprocess.run([args.gpy_python, "-c", f"import {TOOL_MODULES[t]}"], capture_output=True).returncode == 0
    ]
    for t in args.tools:
        if t not in tools:
            print(f"{t} not found at {args.gpy_python}: its comparison is skipped (see the module docstring)")
    clock = time.process_time if args.cpu else time.perf_counter
    costs = {} if args.no_first_call else first_call_costs()
    print(
        "first call of isotropic_remesh (tiny mesh, fresh process): "
        + ", ".join(f"{k} {v:.2f} s" for k, v in costs.items())
    )
    # Warm up in this process with a call that reaches every compiled stage (relocation and the
    # cover step too: an icosphere never does, and the first timed case then paid the cache load,
    # 3-4x on the 100-face spot cage when it ran first).
    isotropic_remesh(*datasets.rock_on_plinth(16), 0.07, iterations=2)
    from geomlib.geometry import mean_edge_length

    found, skipped = meshes(args.quick, args.meshes, args.only)
    for name, why in skipped:
        print(f"skipped {name}: {why}")
    cases, others = [], []
    for name, V, F in found:
        for factor in FACTORS:
            h = factor * mean_edge_length(V, F)
            best, res, runs = np.inf, None, {}
            for tool in tools:  # one round: each contender's --repeat runs, the tools in their own processes
                runs[tool] = run_tool(tool, args.gpy_python, V, F, h, args.iterations, None, args.cpu, args.repeat)
            t = clock()
            res = isotropic_remesh(V, F, h, iterations=args.iterations)
            best = clock() - t
            slowest = best + max((r[0][2] for r in runs.values() if r[0] is not None), default=0.0)
            if "gpytoolbox" in tools and slowest < args.round_limit:
                # a small case, whose milliseconds swing with a shared machine's load: ours and
                # gpytoolbox's runs alternate one by one (the other tools keep their round)
                ours_, g, err = paired_runs(
                    args.gpy_python, V, F, h, args.iterations, clock, args.cpu, args.rounds * args.repeat
                )
                res, best = ours_[:2], ours_[2]  # the alternating runs only, as gpytoolbox's
                runs["gpytoolbox"] = (g, err)
            else:
                for _ in range(args.repeat - 1):
                    t = clock()
                    res = isotropic_remesh(V, F, h, iterations=args.iterations)
                    best = min(best, clock() - t)
            ours = {"time": best, **quality(V, F, *res)}
            for tool in tools:
                g, err = runs[tool]
                if g is None:
                    print(f"{name} at {factor}x: {tool}: {err}")
                    continue
                q = {"time": g[2], **quality(V, F, g[0], g[1])}
                if tool == "gpytoolbox":
                    cases.append({"mesh": name, "factor": factor, "h": h, "ours": ours, "gpy": q})
                else:
                    others.append((name, factor, tool, q))
            print(f"{name} at {factor}x (h = {h:.4g}) done, load {os.getloadavg()[0]:.1f}", flush=True)
            if cases and cases[-1]["mesh"] == name and cases[-1]["factor"] == factor:
                print(table(cases[-1:]).splitlines()[2], flush=True)  # the row now: a run cut short keeps it
    cols = ("time", "faces", "min_angle", "below_30", "edge_cv", "valence6", "hausdorff")
    if others:
        print(f"{'mesh':<20}{'h':>6} {'method':<12}" + "".join(f"{c:>11}" for c in cols))
        for name, factor, who, q in others:
            print(f"{name:<20}{factor:>5.2f}x {who:<12}" + "".join(f"{q[c]:>11.4g}" for c in cols))
    if cases:
        print()
        print(
            f"isotropic_remesh(V, F, h) (defaults) / gpytoolbox remesh_botsch ({args.iterations} iterations, "
            "boundary kept, same h); h in multiples of the input's mean edge; Hausdorff distance to the "
            f"input relative to its bounding-box diagonal; time ({'CPU' if args.cpu else 'wall'}) best of {args.repeat} "
            f"(x {args.rounds}, alternating one by one, where one run of each takes under {args.round_limit:g} s); "
            f"load average {', '.join(f'{x:.1f}' for x in os.getloadavg())}"
        )
        print(table(cases))
    if args.json:
        args.json.write_text(json.dumps({"first_call": costs, "cases": cases, "skipped": skipped}, default=float))
    print(json.dumps({"first_call": costs}))


if __name__ == "__main__":
    main()
