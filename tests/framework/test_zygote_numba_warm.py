"""The zygote of a numba lab builds numba's CPU typing and target contexts once, before it forks: a
worker otherwise builds them at its first compiled call, even one loaded from the cache (1.3 s of CPU
per call of sdf, simplification and remeshing, every graded test and every notebook ``check()``)."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

SCRIPT = """
import os, sys
from pathlib import Path
from geomlib.grading.sandbox import LabProxy

root = Path(sys.argv[1])
stubs, lab = root / "stubs" / "warmlab", root / "warmlab"
stubs.mkdir(parents=True)
lab.mkdir()
(stubs / "ops.py").write_text("from numba import njit\\n\\ndef built():\\n    raise NotImplementedError('Task 1')\\n")
# Read before anything of the lab touches numba: what the worker inherited from the zygote.
(lab / "ops.py").write_text(
    "def built():\\n    from numba.core.registry import cpu_target\\n"
    "    return sorted(k for k in vars(cpu_target) if k.startswith('_toplevel'))\\n"
)
os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
print(LabProxy("warmlab", lab, timeout=120).built())
"""


def test_a_numba_lab_s_worker_inherits_numba_s_built_contexts(tmp_path):
    p = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    built = p.stdout.strip().splitlines()[-1]
    assert "_toplevel_typing_context" in built and "_toplevel_target_context" in built, (
        f"a numba lab's worker builds numba's contexts itself (inherited: {built})"
    )
