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

from .course import planted_solution, replace_once, student_copy

pytestmark = [pytest.mark.slow, pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")]

COURSE = Path(__file__).resolve().parents[2]


def _planted(lab: str, edit) -> Path:
    """A world-readable submission folder holding a copy of ``solutions/<lab>`` changed by ``edit(folder)``."""
    return planted_solution(lab, edit).parent


def _grade(
    impl: Path, lab: str, *extra: str, timeout: float = 600, env_extra: dict | None = None, course: Path = COURSE
) -> dict:
    results = impl / "results.json"
    env = {**os.environ, "GEOMLIB_ROOT": str(course), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **(env_extra or {})}
    cmd = [sys.executable, "-m", "geomlib.cli", "grade", "--impl", str(impl), "--lab", lab, "--results", str(results)]
    p = subprocess.run([*cmd, *extra], cwd=impl, env=env, capture_output=True, text=True, timeout=timeout)
    assert results.is_file(), f"no results.json:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    data = json.loads(results.read_text())
    for t in data["tests"]:
        t["text"] = plain_text(t.get("output", ""))
    return data


def test_sdf_zeros_for_shadows_and_occlusion_earn_nothing():
    def zeros(lab: Path) -> None:
        for fn in ("soft_shadow", "ambient_occlusion"):
            replace_once(
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


def _hanging_relief_shader(lab: Path) -> None:
    """A march that never ends in ``shaders/relief.frag``.

    llvmpipe stops any fragment after 65535 loop turns in all (so ``while (true)`` alone ends, with a
    wrong answer, in a few seconds); 1024 dependent texture reads a turn (each address depends on the
    sum so far, so none can be merged) make it run for many minutes (256 took 170 s on 48 x 48 pixels).
    """
    reads = "".join(
        f"        spin += texelFetch(height, ivec2(int(spin * 1e9) & 7, {i % 8}), 0).r * 1e-9;\n" for i in range(1024)
    )
    frag = lab / "shaders" / "relief.frag"
    replace_once(
        frag,
        "    float f_above = 0.0;\n",
        f"    float spin = 0.0;\n    while (spin >= 0.0) {{\n{reads}    }}\n    float f_above = 0.0;\n",
    )
    replace_once(frag, "scale * d, float(hit));", "scale * d, float(hit) + spin);")


def test_relief_hanging_shader_time_out_names_the_shader_the_task_and_the_cause():
    impl = _planted("relief", _hanging_relief_shader)
    # Graded in the student's bundle, as the student who wrote the loop grades it: the part's public
    # test only. The planted shader never ends, so each test of the part waits out the whole limit
    # with llvmpipe spinning (3.8 s of CPU a test); the instructors' course added the hidden test's
    # wait, and its message is made by the same code (a second hang in one run: test_glsl_worker.py).
    bundle = Path(tempfile.mkdtemp(prefix="geomlib-relief-bundle-"))
    bundle.chmod(0o755)  # the sandbox user may read the course it is graded with
    course = student_copy("relief", bundle / "course")
    try:
        # What the message needs is only that the call reached its shader before the limit: a fresh
        # process gets from start to the shader's compile in 0.84 s of CPU (imports, inputs, GL
        # context; 1.1 s of wall clock at a load of 17 on 2 cores), a worker forked from the grader's
        # zygote in less; 6 s is x7 above the former and passed at 4 s on that loaded machine.
        r = _grade(
            impl,
            "relief",
            "--part",
            "GLSL relief mapping",
            timeout=900,
            env_extra={"GEOMLIB_TIME_LIMIT": "6"},
            course=course,
        )
    finally:
        shutil.rmtree(impl, ignore_errors=True)
        shutil.rmtree(bundle, ignore_errors=True)
    tests = [t for t in r["tests"] if "relief" in t["name"].lower()]
    assert len(tests) == 1 and all(t["status"] == "failed" and t["score"] == 0 for t in tests), tests
    text = tests[0]["text"]
    assert "glsl_relief_uv did not finish within 6 s" in text, text
    assert "shaders/relief.frag" in text and "Task 3 (march and refine)" in text, text
    assert "a loop that does not end or a very long one" in text, text
    assert "Python loop" not in text, text
