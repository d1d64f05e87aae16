"""Grading speed: all labs' graded tests against the solutions (target <= 60 s) and the stubs (<= 30 s).

Also the sandbox's cost per call (fork + import + result transfer), the price of isolation.

    uv run python bench/grading.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def grade(impl: str) -> tuple[float, dict]:
    out = Path(tempfile.mkdtemp()) / "results.json"
    env = {**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    t = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "geomlib.cli", "grade", "--impl", impl, "--results", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        check=True,
    )
    return time.perf_counter() - t, json.loads(out.read_text())


def sandbox_call_cost(n: int = 50) -> float:
    import numpy as np

    from geomlib.grading.sandbox import LabProxy

    d = Path(tempfile.mkdtemp()) / "lab"
    d.mkdir()
    (d / "ops.py").write_text("def f(x):\n    return x\n")
    lab = LabProxy("lab", d)
    x = np.zeros((10_000, 3))
    lab.f(x)
    t = time.perf_counter()
    for _ in range(n):
        lab.f(x)
    return (time.perf_counter() - t) / n


def main() -> None:
    print(f"sandbox: {1000 * sandbox_call_cost():.1f} ms per call (fork, import, 240 kB round trip)")
    for impl, target in (("solutions", 60.0), ("labs", 30.0)):
        seconds, r = grade(impl)
        n = len(r["tests"])
        print(
            f"grade --impl {impl:<9}: {seconds:6.1f} s for {n} graded tests, score {r['score']:g}/{sum(t['max_score'] for t in r['tests']):g}  (target <= {target:g} s: {seconds / target:.2f}x of budget)"
        )


if __name__ == "__main__":
    main()
