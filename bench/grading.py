"""Grading speed: all labs' graded tests against the solutions (target <= 60 s) and the stubs (<= 30 s);
the sandbox's cost per call (fork + import + result transfer), the price of isolation; and feedback
speed while a task is wrong (issue #26 item 4).

Feedback speed: a planted wrong task in three labs (subdivision's odd weight 3/8 -> 0.3, Task 1;
vdm's sample_surface 1 % off, Task 2; shadows' light_uvz shifted in u, Task 3) graded as a student
does, warm (a first run writes the bytecode and numba caches), with the default pictures (the first
failure's), in a student's bundle (the lab's stubs, public tests and references: hidden cases run
only on the autograder, so the whole lab with them is printed too, without a target). Targets:
``geomlib grade --task N`` and a notebook's ``check(lab, task=N)`` <= 3 s, the whole lab <= 10 s.
Printed per run: wall time, the CPU time of the run (every process it started:
this bench is a child subreaper, so orphans such as the zygote count too; a loaded machine shows up
as wall >> CPU) and the load average.

The verdict is what can be shown on a shared, loaded machine (see :func:`verdict`): a wall time
within the target is met; otherwise the CPU time decides. CPU <= target means the run's work fits
the target even on one idle core (the run sleeps only in 10 ms polls while it waits for its own
children), so an idle machine meets it ("met (CPU)"); CPU > 2 x target cannot fit on two idle cores
("missed"); in between only an idle machine can tell ("not shown").

    uv run python bench/grading.py             # everything
    uv run python bench/grading.py feedback    # feedback speed only
    uv run python bench/grading.py feedback shadows   # feedback speed of the planted labs named
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: lab: (module, planted source, the task it breaks)
PLANTED = {
    "subdivision": ("loop", None, 1),  # the odd weight 3/8 -> 0.3 (an edit of the solution, below)
    "vdm": (
        "sampling",
        """
        _true_sample_surface = sample_surface

        def sample_surface(V, F, UV, uv_points):
            return 1.01 * _true_sample_surface(V, F, UV, uv_points)
        """,
        2,
    ),
    "shadows": (
        "lookup",
        """
        _true_light_uvz = light_uvz

        def light_uvz(P, M):
            return np.asarray(_true_light_uvz(P, M)) + [0.05, 0.0, 0.0]
        """,
        3,
    ),
}
TARGET_TASK_S = 3.0
TARGET_LAB_S = 10.0


def grade(impl: str) -> tuple[float, dict]:
    out = Path(tempfile.mkdtemp()) / "results.json"
    env = {**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    t = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "geomlib.cli", "grade", "--impl", impl, "--results", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        check=True,
    )
    return time.perf_counter() - t, json.loads(out.read_text())


def sandbox_call_cost(n: int = 50) -> float:
    import numpy as np

    from geomlib.grading.sandbox import LabProxy

    d = Path(tempfile.mkdtemp()) / "lab"
    d.mkdir()
    (d / "ops.py").write_text("def f(x):\n    return x\n")
    lab = LabProxy("lab", d)
    x = np.zeros((10_000, 3))
    lab.f(x)
    t = time.perf_counter()
    for _ in range(n):
        lab.f(x)
    return (time.perf_counter() - t) / n


# ------------------------------------------------------------------------------ feedback speed


def planted(lab: str) -> Path:
    """A submission folder holding ``<lab>/``: a copy of ``solutions/<lab>`` with the lab's planted
    error (tests/framework/course.py's helper)."""
    sys.path.insert(0, str(ROOT))
    from tests.framework.course import appended, planted_solution

    module, source, _ = PLANTED[lab]
    if source is None:

        def edit(dest: Path) -> None:
            p = dest / f"{module}.py"
            text = p.read_text()
            wrong = text.replace("np.tile([3 / 8, 3 / 8, 1 / 8, 1 / 8]", "np.tile([0.3, 0.3, 1 / 8, 1 / 8]")
            assert wrong != text, "the odd weights of solutions/subdivision/loop.py moved: update the plant"
            p.write_text(wrong)
    else:
        edit = appended(module, source, "bench/grading.py")
    return planted_solution(lab, edit).parent


def student_bundle(lab: str) -> Path:
    """What a student grades: a copy of the course holding ``lab``'s stubs, public tests and
    references only (no hidden cases: those run on the autograder), with the grader."""
    sys.path.insert(0, str(ROOT))
    from tests.framework.course import student_copy

    base = Path(tempfile.mkdtemp(prefix=f"geomlib-bench-bundle-{lab}-"))
    os.chmod(base, 0o755)  # the sandbox may run student code as another user, who reads the stubs
    return student_copy(lab, base)


def _student_env(root: Path = ROOT) -> dict:
    # A student's Python writes bytecode (this machine's sessions may not: that would time compiling).
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "GEOMLIB_NO_FEEDBACK_PICTURES")}
    env.pop("GEOMLIB_MAX_FEEDBACK_PICTURES", None)
    if root != ROOT:  # the bundle's own grader and tests
        env["GEOMLIB_ROOT"] = str(root)
        env["PYTHONPATH"] = str(root)
    return env


def _children_cpu() -> float:
    """CPU seconds of every finished descendant (orphans re-parented to this subreaper included)."""
    _reap_orphans()
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _become_subreaper() -> None:
    """Orphans of a run (the zygote, when its grader exits first) come back to this process, so their
    CPU time is counted (Linux; elsewhere they are not)."""
    try:
        import ctypes

        ctypes.CDLL(None).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    except (AttributeError, OSError):
        pass


def _reap_orphans(wait_s: float = 10.0) -> None:
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            time.sleep(0.05)


def verdict(wall: float, cpu: float, target: float) -> tuple[str, bool | None]:
    """``(text, met)``: met by the wall time, or by the CPU time on a loaded machine (see the module
    docstring); ``met`` is None when only an idle machine can tell."""
    if wall <= target:
        return "met", True
    if cpu <= target:
        return "met (CPU <= target: fits one idle core; the wall time is the load's)", True
    if cpu > 2 * target:
        return "MISSED (CPU > 2 x target: more than two idle cores do in time)", False
    return "not shown under load (target < CPU <= 2 x target)", None


def cli_run(impl: Path, lab: str, task: int | None, feedback: Path, root: Path = ROOT) -> tuple[float, float, str]:
    """Wall and CPU seconds of ``geomlib grade`` as a student types it, and its report."""
    args = [
        sys.executable,
        "-m",
        "geomlib.cli",
        "grade",
        "--impl",
        str(impl),
        "--lab",
        lab,
        "--feedback",
        str(feedback),
    ]
    if task is not None:
        args += ["--task", str(task)]
    cpu0, t = _children_cpu(), time.perf_counter()
    p = subprocess.run(args, cwd=root, env=_student_env(root), capture_output=True, text=True)
    return time.perf_counter() - t, _children_cpu() - cpu0, p.stdout + p.stderr


_NOTEBOOK = """
import os, resource, sys, time
from geomlib.grading import check
impl, lab, task, feedback = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
def zygote_cpu():  # the live zygote and the workers it reaped: not in RUSAGE_CHILDREN until it exits
    from geomlib.grading import sandbox
    z = sandbox._STATE.get("zygote")
    try:
        with open(f"/proc/{z.proc.pid}/stat") as f:
            ticks = f.read().rsplit(")", 1)[1].split()[11:15]
    except (AttributeError, OSError):
        return 0.0
    return sum(map(int, ticks)) / os.sysconf("SC_CLK_TCK")
def cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime + zygote_cpu()
check(lab, task=task, impl=impl, feedback_dir=feedback)   # the kernel's first check (imports, workers)
c0, t = cpu(), time.perf_counter()
r = check(lab, task=task, impl=impl, feedback_dir=feedback)  # the student's next try
print(time.perf_counter() - t, cpu() - c0, sum(1 for line in r if line.strip().endswith(".png")))
"""


def notebook_run(impl: Path, lab: str, task: int, feedback: Path, root: Path = ROOT) -> tuple[float, float, int]:
    """Wall and CPU seconds of a second ``check(lab, task=N)`` in one live process (a notebook kernel)."""
    p = subprocess.run(
        [sys.executable, "-c", _NOTEBOOK, str(impl), lab, str(task), str(feedback)],
        cwd=root,
        env=_student_env(root),
        capture_output=True,
        text=True,
        check=True,
    )
    wall, cpu, pictures = p.stdout.split()[-3:]
    return float(wall), float(cpu), int(pictures)


def _pictures(report: str) -> int:
    return sum(1 for line in report.splitlines() if line.strip().endswith(".png"))


def feedback_speed(labs: list[str] | None = None) -> bool:
    print(
        f"feedback speed, a planted wrong task (targets: one task <= {TARGET_TASK_S:g} s, whole lab <= {TARGET_LAB_S:g} s)"
    )
    _become_subreaper()
    ok = True
    for lab, (_, _, task) in PLANTED.items():
        if labs and lab not in labs:
            continue
        impl = planted(lab)
        bundle = student_bundle(lab)
        feedback = Path(tempfile.mkdtemp(prefix="geomlib-bench-feedback-"))
        try:
            for root in (bundle, ROOT):
                cli_run(impl, lab, task, feedback, root)  # warm-up: bytecode, numba caches
            rows = []
            # What a student runs (the bundle: public tests), then the whole lab with the hidden
            # cases as the autograder runs it (no target: students never run those).
            for what, n, root in (
                (f"grade --task {task}", task, bundle),
                ("grade (whole lab)", None, bundle),
                ("grade (whole lab + hidden)", None, ROOT),
            ):
                load = os.getloadavg()[0]
                wall, cpu, report = cli_run(impl, lab, n, feedback, root)
                failing = next((ln for ln in report.splitlines() if ln.startswith("What to fix")), "What to fix (?)")
                target = None if root == ROOT else TARGET_TASK_S if n else TARGET_LAB_S
                rows.append((what, wall, cpu, load, target, _pictures(report), failing))
            load = os.getloadavg()[0]
            wall, cpu, pics = notebook_run(impl, lab, task, feedback, bundle)
            rows.insert(1, (f"check({lab!r}, task={task})", wall, cpu, load, TARGET_TASK_S, pics, ""))
            for what, wall, cpu, load, target, pics, failing in rows:
                if target is None:
                    print(
                        f"  {lab:<12} {what:<28} {wall:5.1f} s wall, {cpu:5.1f} s CPU  (no target; load {load:.1f}) "
                        + failing.rstrip(":")
                    )
                    continue
                text, met = verdict(wall, cpu, target)
                ok &= met is True
                print(
                    f"  {lab:<12} {what:<28} {wall:5.1f} s wall, {cpu:5.1f} s CPU  (target <= {target:g} s: "
                    f"{text}; load {load:.1f}) {pics} picture{'s' if pics != 1 else ''}"
                    + (f"; {failing.rstrip(':')}" if failing else "")
                )
        finally:
            shutil.rmtree(impl, ignore_errors=True)
            shutil.rmtree(bundle, ignore_errors=True)
            shutil.rmtree(feedback, ignore_errors=True)
    return ok


def main() -> None:
    only = sys.argv[1:]
    if not only or "feedback" in only:
        feedback_speed([a for a in only if a in PLANTED])
    if only and "grading" not in only:
        return
    print(f"sandbox: {1000 * sandbox_call_cost():.1f} ms per call (fork, import, 240 kB round trip)")
    for impl, target in (("solutions", 60.0), ("labs", 30.0)):
        seconds, r = grade(impl)
        n = len(r["tests"])
        print(
            f"grade --impl {impl:<9}: {seconds:6.1f} s for {n} graded tests, score {r['score']:g}/{sum(t['max_score'] for t in r['tests']):g}  (target <= {target:g} s: {seconds / target:.2f}x of budget)"
        )


if __name__ == "__main__":
    main()
