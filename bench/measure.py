"""How the benchmarks measure: best-of (or median) timing, the tracemalloc peak of a call, the shared meshes."""

from __future__ import annotations

import os
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


def load_average() -> str:
    """``"load average 1.23 0.98 0.75"`` (1, 5 and 15 minutes): printed with every timing table."""
    return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg())


def interleaved(fns: dict, repeat: int) -> dict[str, Timing]:
    """Best-of timings of several contenders, called in turn ``repeat`` times (so a busy spell hits all of them)."""
    runs = {name: ([], [], None) for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            wall, cpu, _ = runs[name]
            w, c, out = _runs(fn, 1)
            runs[name] = (wall + w, cpu + c, out)
    return {name: Timing(min(w), min(c), out) for name, (w, c, out) in runs.items()}


def warm_anchor(make):
    """The anchor's frame call ``make()`` returns, called once to warm it (context, shader compilation,
    upload); ``None``, with the reason printed, where pyrender has no headless OpenGL (the two routes
    are then timed alone)."""
    try:
        frame = make()
        frame()
        return frame
    except Exception as err:  # noqa: BLE001 - any failure to draw means no anchor, said in the table
        print(f"  (pyrender unavailable: {type(err).__name__}: {err})")
        return None


def glsl_route_header(title: str) -> None:
    """Start a GLSL benchmark's table: make geomlib.gl's OpenGL context (timed), print ``title`` with the
    load average, the context line and :data:`ROUTE_HEADER`."""
    from geomlib import gl

    t = time.perf_counter()
    info = gl.renderer_info()  # creates the harness's OpenGL context
    t_ctx = time.perf_counter() - t
    print(f"{title}; {load_average()}")
    print(f"  geomlib.gl on {info['platform'] or 'default'} ({info['renderer']}): context {t_ctx:.3f} s")
    print(ROUTE_HEADER)


#: Column heads of :func:`route_row`.
ROUTE_HEADER = (
    f"  {'scene':<48} {'NumPy s (cpu)':>16} {'GLSL s (cpu)':>16} {'pyrender s':>10} {'NumPy/pyr':>9} "
    f"{'GLSL/pyr':>8} {'GLSL 1st s':>10}   NumPy vs GLSL"
)


def route_row(label: str, numpy: Timing, glsl: Timing, anchor: float | None, first: float, agree: str) -> None:
    """One scene of a GLSL benchmark: the NumPy route, the GLSL route and the pyrender anchor (warm, best of),
    the ratios against the anchor, the GLSL route's first call (shader compilation included) and how the two
    routes' results agree."""
    a = "n/a" if anchor is None else f"{anchor:.3f}"
    r_np = "n/a" if anchor is None else f"{numpy.wall / anchor:.3g}"
    r_gl = "n/a" if anchor is None else f"{glsl.wall / anchor:.3g}"
    print(
        f"  {label:<48} {numpy.wall:7.3f} ({numpy.cpu:6.3f}) {glsl.wall:7.3f} ({glsl.cpu:6.3f}) {a:>10} {r_np:>9} "
        f"{r_gl:>8} {first:>10.3f}   {agree}",
        flush=True,
    )


def compare_routes(name: str, numpy, glsl, anchor, repeat: int, agree) -> None:
    """Time a NumPy route, its GLSL route (first call timed apart: shader compilation) and the pyrender
    ``anchor`` (``None``: no anchor), interleaved, best of ``repeat``; print :func:`route_row` with
    ``agree(numpy_out, glsl_out)``, a few words on how the two results agree."""
    first = best_of(glsl, 1).wall
    r = interleaved({"numpy": numpy, "glsl": glsl, **({} if anchor is None else {"pyrender": anchor})}, repeat)
    pr = r["pyrender"].wall if "pyrender" in r else None
    route_row(name, r["numpy"], r["glsl"], pr, first, agree(r["numpy"].out, r["glsl"].out))
