"""Planted submissions of the sdf and relief labs graded as users grade them (issue 23, items 1 and 4).

- sdf, zeros: ``soft_shadow`` and ``ambient_occlusion`` return zeros; every case of theirs must fail
  (the "three" scene's hidden references were all zeros and gave such a submission 4 points).
- relief, hanging shader: the student's fragment shader loops forever; the time-out message must name
  the shader file, the task and the cause.

Each grades a copy of the reference solution with one file changed, with ``geomlib grade`` on this
course, restricted to the part concerned.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from geomlib.grading.results import plain_text

pytestmark = [pytest.mark.slow, pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")]

COURSE = Path(__file__).resolve().parents[2]


def _planted(lab: str, edit) -> Path:
    """A world-readable submission folder holding a copy of ``solutions/<lab>`` changed by ``edit(folder)``."""
    work = Path(tempfile.mkdtemp(prefix=f"geomlib-planted-{lab}-"))
    work.chmod(0o755)
    shutil.copytree(COURSE / "solutions" / lab, work / lab, ignore=shutil.ignore_patterns("__pycache__"))
    edit(work / lab)
    for p in [work, *work.rglob("*")]:
        p.chmod(0o755 if p.is_dir() else 0o644)
    return work


def _grade(impl: Path, lab: str, *extra: str, timeout: float = 600) -> dict:
    results = impl / "results.json"
    env = {**os.environ, "GEOMLIB_ROOT": str(COURSE), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    cmd = [sys.executable, "-m", "geomlib.cli", "grade", "--impl", str(impl), "--lab", lab, "--results", str(results)]
    p = subprocess.run([*cmd, *extra], cwd=impl, env=env, capture_output=True, text=True, timeout=timeout)
    assert results.is_file(), f"no results.json:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    data = json.loads(results.read_text())
    for t in data["tests"]:
        t["text"] = plain_text(t.get("output", ""))
    return data


def _replace(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, f"{path.name}: {old!r} not found once"
    path.write_text(text.replace(old, new))


def test_sdf_zeros_for_shadows_and_occlusion_earn_nothing():
    def zeros(lab: Path) -> None:
        for fn in ("soft_shadow", "ambient_occlusion"):
            _replace(
                lab / "shadow.py",
                f'    where = "{fn}"\n',
                f'    where = "{fn}"\n    return np.zeros(len(np.asarray(P, dtype=np.float64)))  # planted\n',
            )

    impl = _planted("sdf", zeros)
    try:
        r = _grade(impl, "sdf", "--part", "soft shadows")
    finally:
        shutil.rmtree(impl, ignore_errors=True)
    planted = [t for t in r["tests"] if "soft_shadow" in t["name"] or "ambient_occlusion" in t["name"]]
    hidden_three = [t for t in planted if "-three" in t["name"]]
    assert len(hidden_three) == 3, [t["name"] for t in planted]
    assert all(t["status"] == "failed" for t in planted), [(t["name"], t["score"]) for t in planted]
    assert sum(t["score"] for t in planted) == 0
    # push_out was left correct: it still earns its points (the grading itself ran)
    assert all(t["status"] == "passed" for t in r["tests"] if "push_out" in t["name"])
