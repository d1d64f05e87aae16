"""How the benchmarks measure: best-of timing, the tracemalloc peak of a call, the shared meshes."""

from __future__ import annotations

import time
import tracemalloc
from pathlib import Path
from typing import Any, NamedTuple

#: Real test meshes next to the project (``../shared/data/meshes``); benchmarks use them when present.
SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "meshes"


class Best(NamedTuple):
    """What :func:`best_of` measured."""

    wall: float  #: seconds, the fastest call
    cpu: float  #: seconds of process CPU time (all threads), the least of the calls
    out: Any  #: what the last call returned


def best_of(fn, repeat: int = 3) -> Best:
    """Call ``fn()`` ``repeat`` times; the best times, since the machine is shared and noisy.

    The CPU time is what a call costs when it does not wait for a busy core (steadier than wall time).
    """
    wall = cpu = float("inf")
    out = None
    for _ in range(repeat):
        c, t = time.process_time(), time.perf_counter()
        out = fn()
        wall, cpu = min(wall, time.perf_counter() - t), min(cpu, time.process_time() - c)
    return Best(wall, cpu, out)


def peak_mib(fn) -> float:
    """The tracemalloc peak of one call of ``fn()`` in MiB (Python and NumPy allocations)."""
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
