"""The zygote imports numba (a quarter second of CPU) only for a lab whose course stubs use it (issue 26,
item 4: ``geomlib grade --task N`` starts a new zygote every time), and still for such a lab, so that its
workers do not import numba per call; without known stubs, everything is preloaded."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

SCRIPT = """
import os, sys
from pathlib import Path
from geomlib.grading.sandbox import LabProxy

root, stub_import = Path(sys.argv[1]), sys.argv[2]
stubs, lab = root / "stubs" / "prelab", root / "prelab"
stubs.mkdir(parents=True)
lab.mkdir()
given = stub_import + "\\n" if stub_import not in ("", "none") else ""
(stubs / "ops.py").write_text(given + "def loaded():\\n    raise NotImplementedError('Task 1')\\n")
# numba loaded before the lab's package: by the zygote (the stub's own import runs in the worker, after).
(lab / "ops.py").write_text(
    "import sys\\n\\ndef loaded():\\n    names = list(sys.modules)\\n"
    "    return ['numba' in names and names.index('numba') < names.index('_graded_prelab')]\\n"
)
if stub_import != "none":
    os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
print(LabProxy("prelab", lab, timeout=120).loaded()[0])
"""


def _numba_in_worker(tmp_path, stub_import: str) -> bool:
    p = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(tmp_path), stub_import], capture_output=True, text=True, timeout=300
    )
    assert p.returncode == 0, p.stderr[-2000:]
    return p.stdout.split()[-1] == "True"


def test_a_worker_of_a_lab_without_numba_starts_without_it(tmp_path):
    assert not _numba_in_worker(tmp_path, ""), "the zygote imported numba for a lab whose stubs do not use it"


@pytest.mark.parametrize("stub_import", ["from numba import njit", "from geomlib.jit import use_cache_folder"])
def test_a_worker_of_a_numba_lab_inherits_numba(tmp_path, stub_import):
    assert _numba_in_worker(tmp_path, stub_import), "a numba lab's worker imported numba itself"


def test_without_known_stubs_everything_is_preloaded(tmp_path):
    assert _numba_in_worker(tmp_path, "none")
