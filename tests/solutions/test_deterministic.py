"""The reference solutions give the same bytes on every machine, compiled or not (issue #24, part 4).

The committed ``docs/figures/simplification/series.png`` once differed from a build on another
machine in 0.97% of its pixels. The cause was not numba: the Python greedy loop's placement called
``np.linalg.det`` and ``np.linalg.solve``, whose last bits depend on the OpenBLAS kernel the CPU
selects at run time (AVX-512 vs AVX2 vs SSE), and ``norm ** 3`` went through numpy's SIMD ``pow``;
one flipped bit in a cost reorders the heap. These tests run the labs' graded cases

* with the numba kernels compiled and with ``NUMBA_DISABLE_JIT=1`` (plain Python), byte for byte,
  and check that the chosen cases together call every kernel of each lab's numba module;
* every case's inputs (of every lab, as ``geomlib refs check`` digests them) on this machine and
  on an emulated other one, byte for byte;
* on this machine and on an emulated other one, byte for byte: numba compiling for the generic
  x86-64 CPU (no AVX, no FMA), OpenBLAS running its oldest x86-64 kernels, numpy its baseline
  loops (no AVX2/AVX-512 dispatch) and glibc's libm its non-FMA code — the switches a different
  CPU flips;
* and check that numba's on-disk cache keeps one entry per CPU target (a kernel compiled for one
  CPU is never loaded on another, and both stay) and that a second process loads a kernel instead of
  compiling it;
* and check that no kernel is compiled for a literal argument type (a kernel called with a constant,
  ``flip(..., -1)``, is compiled for ``Literal[int](-1)`` and again for int64: the same code twice in
  every process that compiles it).

Compiling is nearly all of the time (about 53 of the 60 CPU seconds of a compiled run; the runs
themselves take a few), and each kind of compile happens once per source: this process compiles every
kernel for this CPU into the solutions' own cache (which the rest of the suite then loads), the emulated
other machine compiles every kernel for the generic CPU into a cache folder of its own that persists
between runs (:func:`other_machine_cache`: a later run of the suite loads them, as it loads this CPU's),
and the cache checks run in an empty folder with one quick kernel. The plain-Python run and the other
machine's run start before this process compiles, so they overlap where a core is free.

Why not one CPU target for every machine (numba's generic target everywhere, so that the other machine
would load this process's kernels): measured on the kernels' benches (best of 3 CPU times per case,
three alternating rounds of host-target and generic-target processes, znver3), the generic target is
7% slower in geometric mean over 21 remeshing, simplification and sdf cases and 10-30% slower on
several (remeshing the spot cage at 1.5x: 9.9 -> 11.1 ms, measured before its projection was compiled).

The environment variables are read when numba, numpy and OpenBLAS load, so every other setting
runs in a fresh interpreter (``tests/solutions/kernel_digests.py``).
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from geomlib.jit import cache_folder
from tests.solutions import kernel_digests

ROOT = Path(__file__).resolve().parents[2]

#: Graded cases that together call every numba kernel and run in a few seconds as plain Python.
NO_JIT_RUNS = [
    "simplification/simplify-height-field-10pct[fast]",
    "simplification/simplify-sharp-box-10pct[fast]",
    "simplification/hidden-simplify-rock-20pct[fast]",
    "remeshing/split-bumpy-sphere",
    "remeshing/hidden-split-torus",
    "remeshing/remesh-wavy-patch",
    "remeshing/remesh-bumpy-sphere",  # the tips' pass of the clean-up (kernels.cover_pass)
    "remeshing/hidden-remesh-height-field",
    "remeshing/hidden-remesh-box8-features",  # the sliver clean-up (kernels.clean_pass: its flips and collapses)
    "sdf/hidden-bvh-closest-box",
    "sdf/hidden-bvh-band-wedge",
    "sdf/hidden-vote-wedge",
]

#: The same, the Python simplification loop on those meshes, and the handout figure's airplane series.
MACHINE_RUNS = [
    *NO_JIT_RUNS,
    "simplification/simplify-height-field-10pct[greedy]",
    "simplification/simplify-sharp-box-10pct[greedy]",
    "simplification/hidden-simplify-rock-20pct[greedy]",
    "simplification/series-airplane-50pct",
    "simplification/series-airplane-10pct",
    "simplification/series-airplane-2pct",
]

#: Another machine, as far as one machine can play it: what a different CPU changes in numba's code
#: generation, OpenBLAS's kernel choice, numpy's SIMD dispatch and glibc's libm variants. (Unknown
#: names are ignored on CPUs that have no such kernels or features.)
OTHER_MACHINE = {
    "NUMBA_CPU_NAME": "generic",
    "OPENBLAS_CORETYPE": "Prescott",
    "NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR",
    "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F",  # libm's exp/log/sin/pow have FMA variants
}
PINNED = ("NUMBA_DISABLE_JIT", "NUMBA_CPU_FEATURES", *OTHER_MACHINE)  # cleared from the inherited environment

pytestmark = pytest.mark.skipif(
    os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="compares compiled kernels: needs numba's JIT"
)


#: Time limits of the subprocesses, for hangs only: the other machine's run (compiling every kernel
#: for the generic CPU, then the Python loops) needs about one CPU minute; a loaded 2-core machine
#: gave it a tenth of a core (600 s was not enough there).
DIGESTS_TIMEOUT = 3600
PROBE_TIMEOUT = 1800


class Digests:
    """``kernel_digests.py`` started in a fresh interpreter with ``env`` (on top of a clean
    environment); :meth:`result` waits for it. Started before this process compiles its own kernels
    (:func:`here`), so on a machine with a free core the runs overlap."""

    def __init__(self, runs: list[str], folder: Path, **env: str):
        base = {k: v for k, v in os.environ.items() if k not in PINNED}
        self.env = env
        self.out, self.err = folder / "stdout", folder / "stderr"
        with self.out.open("w") as out, self.err.open("w") as err:
            self.process = subprocess.Popen(
                [sys.executable, str(ROOT / "tests" / "solutions" / "kernel_digests.py"), *runs],
                cwd=ROOT,
                env={**base, "PYTHONPATH": str(ROOT), **env},
                stdout=out,
                stderr=err,
                text=True,
            )

    def result(self, timeout: float = DIGESTS_TIMEOUT) -> dict:
        try:
            code = self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise
        assert code == 0, f"kernel_digests.py with {self.env} failed:\n{self.err.read_text()[-3000:]}"
        return json.loads(self.out.read_text().strip().splitlines()[-1])

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def other_machine_cache() -> Path:
    """The numba cache folder of the emulated other machine's run: kept between runs of the suite
    (beside this file when writable, else in the user's private temporary folder, as
    :func:`geomlib.jit.cache_folder` chooses), apart from the solutions' own cache (two processes
    writing one index at once can lose each other's entries). numba keeps an entry per source file
    version and CPU target, so a changed kernel module is compiled again."""
    return cache_folder("tests.solutions.other_machine", Path(__file__).resolve().parent)


@pytest.fixture(scope="module")
def started(tmp_path_factory):
    """The plain-Python run of :data:`NO_JIT_RUNS` and the emulated other machine's run of
    :data:`MACHINE_RUNS` (its kernels compiled into, or loaded from, :func:`other_machine_cache`),
    both started at once."""
    runs = {
        "plain": Digests(NO_JIT_RUNS, tmp_path_factory.mktemp("no-jit"), NUMBA_DISABLE_JIT="1"),
        "other": Digests(
            ["--case-inputs", *MACHINE_RUNS],
            tmp_path_factory.mktemp("other"),
            NUMBA_CACHE_DIR=str(other_machine_cache()),
            **OTHER_MACHINE,
        ),
    }
    yield runs
    for r in runs.values():
        r.stop()


@pytest.fixture(scope="module")
def here(started) -> dict:
    """Digests of :data:`MACHINE_RUNS` in this process (compiled kernels, this machine), computed
    while the subprocesses of ``started`` run."""
    return kernel_digests.compute(MACHINE_RUNS)


@pytest.fixture(scope="module")
def plain(started, here) -> dict:
    return started["plain"].result()


@pytest.fixture(scope="module")
def other(started, here) -> dict:
    """Digests of :data:`MACHINE_RUNS` on the emulated other machine, its kernels compiled for the generic CPU."""
    return started["other"].result()


def differing(a: dict, b: dict, runs: list[str]) -> list[str]:
    return [r for r in runs if a[r] != b[r]]


def numba_kernels(lab: str) -> set[str]:
    """Names of the ``@njit`` functions defined in the lab's kernel module."""
    from numba.core.dispatcher import Dispatcher

    name = kernel_digests.KERNEL_MODULES[lab]
    module = importlib.import_module(name)
    return {k for k, v in vars(module).items() if isinstance(v, Dispatcher) and v.py_func.__module__ == name}


def test_every_numba_module_is_covered():
    # A new lab with compiled kernels must be added to kernel_digests.KERNEL_MODULES and to the runs.
    found = {
        f"solutions.{p.parent.name}.{p.stem}"
        for p in sorted((ROOT / "solutions").glob("*/*.py"))
        if "from numba import" in p.read_text(encoding="utf-8") or "import numba" in p.read_text(encoding="utf-8")
    }
    assert found == set(kernel_digests.KERNEL_MODULES.values()), (
        f"modules importing numba: {sorted(found)}; covered by tests/solutions/kernel_digests.py: "
        f"{sorted(kernel_digests.KERNEL_MODULES.values())}"
    )


def test_compiled_kernels_give_the_bytes_of_plain_python(here, plain):
    for lab in kernel_digests.KERNEL_MODULES:
        missing = numba_kernels(lab) - set(plain["kernels"][lab])
        assert not missing, f"{lab}: the cases of NO_JIT_RUNS never call the kernels {sorted(missing)}; add a case"
    diff = differing(here["digests"], plain["digests"], NO_JIT_RUNS)
    assert not diff, (
        f"compiled and plain-Python (NUMBA_DISABLE_JIT=1) kernels give different bytes on {diff}: "
        "look for fastmath, FMA contraction, parallel reductions or ** / math functions that numba "
        "and CPython evaluate differently"
    )


def test_every_cases_inputs_are_the_same_bytes_on_another_machine(other):
    # The inputs digests ``geomlib refs check`` compares with the references' manifests, of every
    # case of every lab: references built on one CPU must hold on another (27 cases failed on an
    # AVX2 machine with references built on an AVX-512 one). Inputs are built with geomlib.portable.
    here = kernel_digests.case_inputs()
    theirs = other["case_inputs"]
    assert set(theirs) == set(here)
    moved = sorted(k for k in here if here[k] != theirs[k])
    assert not moved, (
        f"{len(moved)} cases' inputs differ on an emulated other CPU ({OTHER_MACHINE}): {moved[:12]}; "
        "a generator calls numpy's exp/sin/cos/arctan2/power, math.*, BLAS (@, np.dot, 1-D norm) or einsum: "
        "use geomlib.portable"
    )


def literal_signatures(lab: str) -> tuple[dict[str, list], list[str]]:
    """``({kernel: [signatures]}, [kernels])``: the signatures with a literal argument type
    (``Literal[int](-1)``) that numba's cache of the lab's kernel module holds for its current
    source, and the kernels it holds nothing for (inlined ones aside). Every process that compiled
    them wrote them there: a run that loaded its kernels from the cache sees them as well as one
    that compiled them."""
    from numba.core import types
    from numba.core.dispatcher import Dispatcher

    module = importlib.import_module(kernel_digests.KERNEL_MODULES[lab])
    found, unindexed = {}, []
    for name, disp in vars(module).items():
        if not isinstance(disp, Dispatcher) or disp.py_func.__module__ != module.__name__:
            continue
        sigs = [key[0] for key in disp._cache._cache_file._load_index()]
        if not sigs and disp.targetoptions.get("inline", "never") != "always":
            unindexed.append(name)
        if literal := [s for s in sigs if any(isinstance(t, types.Literal) for t in s)]:
            found[name] = literal
    return found, unindexed


def test_each_kernel_is_compiled_once_per_argument_types(here):
    # A kernel that another kernel calls with a constant (``flip(..., -1)``, or a variable first
    # set to one) is compiled for the literal (``Literal[int](-1)``) and again for int64: the same
    # code compiled twice in every process that compiles it (this one, the other machine's, each
    # grader's). ``here`` ran every case, so every kernel they call has its cache index.
    checked = {lab: literal_signatures(lab) for lab in kernel_digests.KERNEL_MODULES}
    unindexed = {lab: u for lab, (_, u) in checked.items() if u}
    assert not unindexed, (
        f"numba's cache holds nothing for these kernels after the runs (nothing to check): {unindexed}"
    )
    found = {lab: f for lab, (f, _) in checked.items() if f}
    assert not found, (
        f"kernels compiled for a literal argument (pass a typed value, np.int64(-1), instead of a constant): {found}"
    )


def test_another_machine_gives_the_same_bytes(here, other):
    assert other["jit"]["cpu"] == OTHER_MACHINE["NUMBA_CPU_NAME"], (
        f"the emulated other machine's numba compiled for {other['jit']['cpu']!r}, not {OTHER_MACHINE['NUMBA_CPU_NAME']!r}"
    )
    moved = differing(here["inputs"], other["inputs"], MACHINE_RUNS)
    assert not moved, f"the inputs of {moved} differ on an emulated other CPU ({OTHER_MACHINE})"
    diff = differing(here["digests"], other["digests"], MACHINE_RUNS)
    assert not diff, (
        f"an emulated other CPU ({OTHER_MACHINE}) gives different bytes on {diff}: something depends on "
        "the CPU's SIMD kernels (np.linalg / BLAS, numpy's dispatched pow/exp/log, numba's CPU target)"
    )


#: The cache probe: the remeshing kernel ``faces_min_angle`` (smallest angle of every face: arctan2,
#: sqrt; the quickest to compile of the kernels the solutions call from Python, a second; numba's
#: cache keys every kernel the same way) on a fixed random mesh, with the argument types the solutions
#: call it with (the remeshing lab's relocation step), so that the entry this process compiled is the
#: one looked up: the output's digest, and what numba's cache did for the kernel in the process.
CACHE_PROBE = """
import json
from numba.core import config
from solutions.remeshing.kernels import faces_min_angle
from tests.solutions.kernel_digests import digest, probe_mesh
out = digest(faces_min_angle(*probe_mesh()))
s = faces_min_angle.stats
print(json.dumps({"cpu": config.CPU_NAME, "digest": out,
                  "hits": sum(s.cache_hits.values()), "misses": sum(s.cache_misses.values())}))
"""


def probe_cache(cache: Path, **env: str) -> dict:
    base = {k: v for k, v in os.environ.items() if k not in PINNED}
    out = subprocess.run(
        [sys.executable, "-c", CACHE_PROBE],
        cwd=ROOT,
        env={**base, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(cache), **env},
        capture_output=True,
        text=True,
        timeout=PROBE_TIMEOUT,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_the_kernel_cache_keeps_cpu_targets_apart_and_serves_a_second_process(here, tmp_path):
    # numba keys a cache entry on (signature, (target triple, CPU name, CPU features)): machine code
    # compiled for one CPU is not loaded for another, and the other's is kept beside it. A grader
    # forks a worker per call: only the first process on a machine may compile. In an empty folder:
    # the generic CPU compiles, this CPU compiles too (does not load the generic code), then both load.
    generic = {"NUMBA_CPU_NAME": "generic"}
    made = probe_cache(tmp_path, **generic)
    assert (made["hits"], made["misses"]) == (0, 1), f"the generic CPU did not compile into an empty cache: {made}"
    first = probe_cache(tmp_path)
    assert (first["hits"], first["misses"]) == (0, 1), f"this CPU loaded the generic CPU's machine code: {first}"
    second = probe_cache(tmp_path)
    assert (second["hits"], second["misses"]) == (1, 0), f"a second process compiled again: {second}"
    kept = probe_cache(tmp_path, **generic)
    assert (kept["hits"], kept["misses"]) == (1, 0), f"the generic CPU's entry was not kept (or not loaded): {kept}"
    from solutions.remeshing.kernels import faces_min_angle  # compiled by ``here``, in the solutions' own cache

    mine = kernel_digests.digest(faces_min_angle(*kernel_digests.probe_mesh()))
    for r in (made, first, second, kept):
        assert r["digest"] == mine, f"a kernel loaded from the cache gives other bytes: {r} (this process: {mine})"
