"""Digests of the reference solutions' outputs on the graded cases, for ``test_deterministic.py``.

Run as a script in a fresh interpreter with the environment under test (``NUMBA_DISABLE_JIT=1``,
``NUMBA_CPU_NAME=generic``, ``OPENBLAS_CORETYPE=...``, ``NPY_DISABLE_CPU_FEATURES=...``: numba,
numpy and OpenBLAS read them when they load, so one process cannot switch them)::

    python tests/solutions/kernel_digests.py [--case-inputs] LAB/ID [LAB/ID ...]

It prints one JSON object on its last line: ``digests`` maps each ``LAB/ID`` to the sha256 of its
output (every returned array's dtype, shape and bytes), so two runs agree only when they agree
bit for bit; ``inputs`` holds the same for the run's inputs; ``kernels`` maps each lab to the functions of its numba module that ran (recorded
only with ``NUMBA_DISABLE_JIT=1``, when the kernels are plain Python functions). With
``--case-inputs``, ``case_inputs`` holds :func:`case_inputs`: the inputs digest of every case of
every lab, as ``geomlib refs check`` computes it. With the JIT on, ``jit`` holds the CPU name
numba compiled for (the one its cache key names) and, per lab, how many of the kernel module's
compiled versions numba's cache served (``hits``) and how many it compiled (``misses``).

Run ids are the graded case ids of ``tests/graded/<lab>/cases*.py``; for simplification, whose
graded cases only run the lab's Python loop, ``<case id>[greedy]`` and ``<case id>[fast]`` run a
``qem_simplify`` case through the Python loop and through the compiled one, and
``series-airplane-<p>pct`` is the handout figure's simplification of the airplane to p% of its
faces (the run whose result differed between machines, issue #24).
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import json
import os
import sys
from functools import partial
from pathlib import Path
from types import FunctionType

ROOT = Path(__file__).resolve().parents[2]

#: The module of numba kernels of each lab that has one.
KERNEL_MODULES = {
    "simplification": "solutions.simplification.compiled",
    "remeshing": "solutions.remeshing.kernels",
    "sdf": "solutions.sdf.kernels",
}


def _feed(h, value) -> None:
    import numpy as np

    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            h.update(f.name.encode())
            _feed(h, getattr(value, f.name))
    elif isinstance(value, tuple | list):
        h.update(b"(%d" % len(value))
        for v in value:
            _feed(h, v)
        h.update(b")")
    elif isinstance(value, dict):
        for k in sorted(value):
            h.update(str(k).encode())
            _feed(h, value[k])
    else:
        a = np.ascontiguousarray(value)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())


def digest(value) -> str:
    """sha256 of ``value``'s arrays (dtype, shape, bytes), through tuples, lists, dicts and dataclasses."""
    h = hashlib.sha256()
    _feed(h, value)
    return h.hexdigest()


def probe_mesh():
    """A fixed small random mesh ``(V, F)`` (float64, int64) for ``test_deterministic``'s cache probe."""
    import numpy as np

    rng = np.random.default_rng(24)
    return rng.random((40, 3)), (np.arange(60)[:, None] + np.array([0, 1, 3])) % 40


def runs(lab: str) -> dict:
    """``{run id: (inputs, function)}``: every run of the lab this script knows; it computes ``function(**inputs())``."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from geomlib.grading.cases import load_cases

    module = importlib.import_module(f"solutions.{lab}")
    out = {}
    for case in load_cases(lab, probes=False):
        if lab != "simplification":
            out[case.id] = (case.inputs, partial(getattr(module, case.function), **case.params))
        elif case.function == "qem_simplify":
            for method in ("greedy", "fast"):
                if method == "fast" and case.params.get("pair_threshold", 0) > 0:
                    continue  # the compiled loop contracts edges only
                out[f"{case.id}[{method}]"] = (case.inputs, partial(module.qem_simplify, **case.params, method=method))
    if lab == "simplification":
        # the handout figure series.png (solutions.simplification.figures.fig_series)
        from solutions.simplification.figures import airplane

        def series(V, F, percent):
            return module.qem_simplify(V, F, max(4, round(percent / 100 * len(F))))

        for percent in (50, 10, 2):
            inputs = partial(lambda percent: dict(zip("VF", airplane(), strict=True), percent=percent), percent)
            out[f"series-airplane-{percent}pct"] = (inputs, series)
    return out


def _record_kernels(labs) -> tuple[dict[str, set[str]], list]:
    """``({lab: names of the functions of its kernel module that get called}, undo)``.

    Only with ``NUMBA_DISABLE_JIT=1``, when the kernels are plain functions: each function of the
    kernel module is replaced by one that notes its name and puts the function back, so only the
    first call of each pays (a profile hook on every call, numpy's included, doubled the run's time).
    The kernels call each other through the module's globals and the solutions reach them as
    ``module.name``, so every first call goes through the replacement."""
    called: dict[str, set[str]] = {}
    undo = []
    for lab in labs:
        if lab not in KERNEL_MODULES:
            continue
        module = importlib.import_module(KERNEL_MODULES[lab])
        called[lab] = names = set()
        for name, f in list(vars(module).items()):
            if isinstance(f, FunctionType) and f.__module__ == module.__name__:

                def first(*args, _name=name, _f=f, _names=names, _module=module, **kwargs):
                    _names.add(_name)
                    setattr(_module, _name, _f)
                    return _f(*args, **kwargs)

                setattr(module, name, first)
                undo.append((module, name, f))
    return called, undo


def compute(wanted: list[str], record: bool = False) -> dict:
    """``{"digests": {lab/id: sha256}, "inputs": {lab/id: sha256}, "kernels": {lab: [names]}}`` for ``wanted`` (``lab/id``)."""
    labs = sorted({w.split("/", 1)[0] for w in wanted})
    available = {f"{lab}/{rid}": call for lab in labs for rid, call in runs(lab).items()}
    unknown = [w for w in wanted if w not in available]
    if unknown:
        raise KeyError(f"kernel_digests: no run {unknown}; runs: {sorted(available)}")
    inputs = {w: available[w][0]() for w in wanted}
    input_digests = {w: digest(inputs[w]) for w in wanted}  # before the calls (in case one writes to them)
    called, undo = _record_kernels(labs) if record else ({}, [])
    try:
        digests = {w: digest(available[w][1](**inputs[w])) for w in wanted}
    finally:
        for module, name, f in undo:
            setattr(module, name, f)
    return {
        "digests": digests,
        "inputs": input_digests,
        "kernels": {lab: sorted(names) for lab, names in called.items()},
    }


def jit_state(labs) -> dict:
    """``{"cpu": name, "cache": {lab: {"hits": n, "misses": n}}}``: the CPU numba's code generator
    compiles for in this process, as its cache key names it, and what numba's cache did for each
    lab's kernels in this process (summed over the kernel module's functions)."""
    from numba.core.dispatcher import Dispatcher
    from numba.core.registry import cpu_target

    cache = {}
    for lab in labs:
        if lab in KERNEL_MODULES:
            kernels = [
                d for d in vars(importlib.import_module(KERNEL_MODULES[lab])).values() if isinstance(d, Dispatcher)
            ]
            cache[lab] = {
                "hits": sum(sum(d.stats.cache_hits.values()) for d in kernels),
                "misses": sum(sum(d.stats.cache_misses.values()) for d in kernels),
            }
    return {"cpu": cpu_target.target_context.codegen().magic_tuple()[1], "cache": cache}


def case_inputs() -> dict[str, str]:
    """``{lab/id: inputs digest}`` of every stored input and case of every lab: the digest
    ``geomlib refs check`` compares with the manifests (``inputs_digest`` of ``case.inputs()`` and
    its parameters), so equal digests on two machines mean equal inputs, byte for byte."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from geomlib.grading import impl
    from geomlib.grading.cases import inputs_digest, load_cases, load_stored

    return {
        f"{lab}/{case.id}": inputs_digest(case.inputs(), case.params)
        for lab in impl.lab_names()
        for case in load_stored(lab) + load_cases(lab)
    }


def main(argv: list[str]) -> None:
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    with_inputs = "--case-inputs" in argv
    argv = [a for a in argv if a != "--case-inputs"]
    no_jit = os.environ.get("NUMBA_DISABLE_JIT") == "1"
    out = compute(argv, record=no_jit)
    if not no_jit:
        out["jit"] = jit_state(sorted({a.split("/", 1)[0] for a in argv}))
    if with_inputs:
        out["case_inputs"] = case_inputs()
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1:])
