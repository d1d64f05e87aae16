"""Benchmark: ``qem_simplify``'s ``crease_angle`` over the shared triangle meshes, against igl.qslim.

Run: ``uv run python bench/simplification_crease.py [--meshes DIR] [--angles 45 60 75 90 None]``

For every triangle mesh of the shared set (read once with ``igl.read_triangle_mesh``, as
``bench/simplification.py`` reads it) at 10% and 1% of the faces, it runs igl.qslim once and
``qem_simplify(method="fast")`` once per crease angle, and prints the Hausdorff distance of each
over igl.qslim's (``geomlib.geometry.mesh_distance``, 50,000 samples per side), then per angle the
geometric mean and the worst case: the default is chosen over the whole set, not on one mesh.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

from bench.measure import SHARED
from bench.simplification import qslim, quality, shared_meshes
from solutions.simplification import qem_simplify


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", type=Path, default=SHARED)
    ap.add_argument("--angles", nargs="*", default=["45", "60", "75", "90", "None"])
    ap.add_argument("--levels", nargs="*", type=float, default=[0.1, 0.01])
    args = ap.parse_args()
    angles = [None if a == "None" else float(a) for a in args.angles]
    rows = []
    print(f"{'mesh':24s} {'keep':>5s} " + " ".join(f"{str(a):>7s}" for a in angles) + "   (Hausdorff / igl.qslim's)")
    for name, (V, F) in shared_meshes(False, args.meshes).items():
        for level in args.levels:
            t = max(4, int(round(level * len(F))))
            ref = quality(V, F, *qslim(V, F, t), 50_000)["hausdorff"]
            r = []
            for a in angles:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    U, G = qem_simplify(V, F, t, method="fast", crease_angle=a, on_unreachable="warn")
                r.append(quality(V, F, U, G, 50_000)["hausdorff"] / ref)
            rows.append((name, level, r))
            print(f"{name[:24]:24s} {level:5.0%} " + " ".join(f"{x:7.3f}" for x in r), flush=True)
    R = np.array([r for _, _, r in rows])
    for k, a in enumerate(angles):
        w = int(R[:, k].argmax())
        print(
            f"crease_angle={a}: geometric mean x{np.exp(np.log(R[:, k]).mean()):.3f}, "
            f"worst x{R[w, k]:.3f} ({rows[w][0]} at {rows[w][1]:.0%}), cases above x1.25: {(R[:, k] > 1.25).sum()}"
        )


if __name__ == "__main__":
    main()
