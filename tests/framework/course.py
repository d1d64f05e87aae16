"""Helpers to run the geomlib CLI on a copy of the sample course."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SAMPLE = Path(__file__).parent / "sample_course"


def run_geomlib(
    root: Path, *args: str, cwd: Path | None = None, env: dict | None = None, check: bool = True, timeout: float = 300
):
    """Run the geomlib CLI in a subprocess on the course at ``root``."""
    e = {**os.environ, "GEOMLIB_ROOT": str(root), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **(env or {})}
    p = subprocess.run(
        [sys.executable, "-m", "geomlib.cli", *args],
        cwd=cwd or root,
        env=e,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if check and p.returncode != 0:
        raise AssertionError(
            f"geomlib {' '.join(args)} failed ({p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
        )
    return p


def grade(root: Path, impl: str, *extra: str, env: dict | None = None) -> dict:
    results = root / "results" / f"{Path(impl).name}.json"
    run_geomlib(root, "grade", "--impl", impl, "--results", str(results), *extra, env=env)
    return json.loads(results.read_text())
