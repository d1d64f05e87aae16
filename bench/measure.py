"""How the benchmarks measure: best-of (or median) timing, the tracemalloc peak of a call, the shared meshes."""

from __future__ import annotations

import time
import tracemalloc
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

#: Real test meshes next to the project (``../shared/data/meshes``); benchmarks use them when present.
SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "meshes"


class Timing(NamedTuple):
    """What :func:`best_of` or :func:`medians` measured over a few calls."""

    wall: float  #: seconds of wall-clock time
    cpu: float  #: seconds of process CPU time, all threads
    out: Any  #: what the last call returned


def best_of(fn, repeat: int = 3) -> Timing:
    """Call ``fn()`` ``repeat`` times; the least wall and CPU times (the machine is shared and noisy)."""
    wall, cpu, out = _runs(fn, repeat)
    return Timing(min(wall), min(cpu), out)


def medians(fn, repeat: int) -> Timing:
    """Call ``fn()`` ``repeat`` times; the median wall and CPU times (for calls whose time varies run to run)."""
    wall, cpu, out = _runs(fn, repeat)
    return Timing(float(np.median(wall)), float(np.median(cpu)), out)


def _runs(fn, repeat: int) -> tuple[list[float], list[float], Any]:
    """Wall and process CPU seconds (all threads) of each of ``repeat`` calls, and the last result.

    The CPU time is what a call costs when it does not wait for a busy core: the steadier number.
    """
    wall, cpu, out = [], [], None
    for _ in range(repeat):
        c, t = time.process_time(), time.perf_counter()
        out = fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return wall, cpu, out


def peak_mib(fn) -> float:
    """The tracemalloc peak of one call of ``fn()`` in MiB (Python and NumPy allocations)."""
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
