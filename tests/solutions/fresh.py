"""Run a snippet of Python in a fresh interpreter at the course root (for the kernels' plain-Python runs)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run_python(code: str, **env: str) -> str:
    """The last line ``code`` prints, run by this Python in a fresh interpreter at the course root with
    ``env`` added to the environment (``NUMBA_DISABLE_JIT="1"``: the kernels as plain Python); the
    interpreter must exit 0."""
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT), **env},
        capture_output=True,
        text=True,
        timeout=1800,  # hangs only: seconds of work, but a loaded machine gives a fraction of a core
    )
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.strip().splitlines()[-1]
