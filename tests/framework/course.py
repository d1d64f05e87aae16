"""Helpers to run the geomlib CLI on a copy of the sample course."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

SAMPLE = Path(__file__).parent / "sample_course"
#: The real course (this checkout).
COURSE = Path(__file__).resolve().parents[2]


def run_geomlib(
    root: Path,
    *args: str,
    cwd: Path | None = None,
    env: dict | None = None,
    check: bool = True,
    timeout: float = 300,
    python: str | None = None,
):
    """Run the geomlib CLI in a subprocess on the course at ``root``."""
    e = {**os.environ, "GEOMLIB_ROOT": str(root), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **(env or {})}
    p = subprocess.run(
        [python or sys.executable, "-m", "geomlib.cli", *args],
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


def user_cli(cwd: Path, *args: str, env: dict | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run ``python -m geomlib.cli *args`` in ``cwd`` the way a user does: no ``GEOMLIB_ROOT`` (the
    course is the one ``cwd`` belongs to), ``env`` added to this process's environment. Fails with
    the command's output unless it exits 0."""
    e = {k: v for k, v in os.environ.items() if k != "GEOMLIB_ROOT"}
    e.update(env or {})
    p = subprocess.run(
        [sys.executable, "-m", "geomlib.cli", *args], cwd=cwd, env=e, capture_output=True, text=True, timeout=timeout
    )
    assert p.returncode == 0, f"geomlib {' '.join(args)} failed ({p.returncode}):\n{p.stdout}{p.stderr}"
    return p


def run_autograder(release: Path, lab: str, submission: Path | None) -> dict:
    """Unzip ``release``'s ``autograder-<lab>.zip`` as Gradescope does, submit the lab folder
    ``submission`` (None: an empty submission) and run its ``run_autograder`` with this interpreter;
    the results.json it writes."""
    import zipfile

    root = Path(tempfile.mkdtemp(prefix="geomlib-autograder-"))
    root.chmod(0o755)
    try:
        with zipfile.ZipFile(release / f"autograder-{lab}.zip") as z:
            z.extractall(root / "source")
            names = z.namelist()
        assert "setup.sh" in names and "run_autograder" in names
        assert any("hidden" in n for n in names)  # the autograder does get the hidden tests
        assert not any(n.startswith("solutions/") for n in names)
        (root / "submission").mkdir()
        if submission is not None:
            shutil.copytree(submission, root / "submission" / "labs" / submission.name)
        hidden = root / "source" / "tests" / "reference" / lab / "hidden"
        hidden.chmod(0o700)  # as setup.sh does
        run = root / "source" / "run_autograder"
        run.chmod(0o755)
        env = {k: v for k, v in os.environ.items() if k != "GEOMLIB_ROOT"}
        # The sandbox user's drop is exercised on the real course (test_release_course.py): this
        # interpreter may live where `nobody` cannot read it.
        env.update(
            GEOMLIB_AUTOGRADER_ROOT=str(root),
            GEOMLIB_PYTHON=sys.executable,
            PYTHONPATH=str(root / "source"),
            GEOMLIB_SANDBOX_USER="",
        )
        p = subprocess.run(["bash", str(run)], env=env, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stdout + p.stderr
        return json.loads((root / "results" / "results.json").read_text())
    finally:  # every call unpacks an autograder (1.2 MB): none was ever removed from /tmp
        shutil.rmtree(root, ignore_errors=True)


def grade(root: Path, impl: str, *extra: str, env: dict | None = None, python: str | None = None) -> dict:
    results = root / "results" / f"{Path(impl).name}.json"
    run_geomlib(root, "grade", "--impl", impl, "--results", str(results), *extra, env=env, python=python)
    return json.loads(results.read_text())


def _user_can(user: str, argv: list[str], env: dict) -> bool:
    import pwd

    pw = pwd.getpwnam(user)
    pid = os.fork()
    if pid == 0:
        try:
            os.setgroups([])
            os.setgid(pw.pw_gid)
            os.setuid(pw.pw_uid)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.dup2(devnull, 2)
            os.chdir("/")
            os.execve(argv[0], argv, env)
        finally:
            os._exit(1)
    _, st = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(st) == 0


def sandbox_python(user: str = "nobody") -> tuple[str, dict] | None:
    """A Python (and extra environment) that both root and ``user`` can run the grader with, or None.

    This interpreter if ``user`` can read it; else the system's Python of the same version with this
    environment's site-packages on ``PYTHONPATH`` (how Gradescope's image has it: Python under /usr).
    """
    import sysconfig

    if os.geteuid() != 0:
        return None
    try:
        import pwd

        pwd.getpwnam(user)
    except KeyError:
        return None
    probe = ["-c", "import numpy, scipy.sparse, geomlib.grading.zygote"]
    root = str(Path(__file__).resolve().parents[2])
    base = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "PYTHONPATH": root}
    if _user_can(user, [sys.executable, *probe], base):
        return sys.executable, {}
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    site = sysconfig.get_paths()["purelib"]
    for cand in (f"/usr/bin/{version}", f"/usr/local/bin/{version}"):
        env = {**base, "PYTHONPATH": os.pathsep.join([site, root])}
        if os.path.exists(cand) and _user_can(user, [cand, *probe], env):
            return cand, {"PYTHONPATH": site}
    return None


def sandbox_user_problem(user: str = "nobody") -> str | None:
    """Why grading as ``user`` cannot work here (not root, no such user, no readable Python), or None."""
    if os.geteuid() != 0:
        return "dropping to a sandbox user needs root"
    if sandbox_python(user) is None:
        return f"no Python here that user {user!r} can read (this one is {sys.executable}); see docs/autograder.md"
    return None


def student_copy(lab: str, dest: Path) -> Path:
    """What a student's bundle holds of ``lab`` (``geomlib release``'s own list of the student's
    files: stubs, public graded tests and references, the grader; no hidden material, no solutions),
    copied into ``dest`` (also bench/grading.py's: what a student grades)."""
    from geomlib.grading import impl as _impl
    from geomlib.grading import release
    from geomlib.grading.course import Course

    release._copy(release.student_files(_impl.course_root(), [lab]), dest)
    assert not Course(dest).hidden_paths(), "the copy must hold no hidden material"
    return dest


def planted_solution(lab: str, edit) -> Path:
    """A world-readable copy of the real course's ``solutions/<lab>`` (the sandbox may run student
    code as ``nobody``), changed by ``edit(folder)``; returns the lab folder. Remove its parent after use."""
    from geomlib.grading import impl as _impl

    base = Path(tempfile.mkdtemp(prefix=f"geomlib-plant-{lab}-"))
    dest = base / lab
    shutil.copytree(_impl.course_root() / "solutions" / lab, dest, ignore=shutil.ignore_patterns("__pycache__"))
    edit(dest)
    for p in [base, *base.rglob("*")]:
        os.chmod(p, 0o755 if p.is_dir() else 0o644)
    return dest


def appended(module: str, source: str, who: str):
    """An ``edit`` for :func:`planted_solution` that appends ``source`` to ``<module>.py`` (rebinding a function)."""

    def edit(dest: Path) -> None:
        with open(dest / f"{module}.py", "a") as f:
            f.write(f"\n\n# planted error ({who})\n" + textwrap.dedent(source))

    return edit


def replace_once(path: Path, old: str, new: str) -> None:
    """Replace the one occurrence of ``old`` in the file ``path`` by ``new`` (a planted error); fails
    when ``old`` is not there exactly once, so a planted edit cannot silently miss after the file changed."""
    text = path.read_text()
    assert text.count(old) == 1, f"{path.name}: {old!r} not found once"
    path.write_text(text.replace(old, new))


def shader_edit(shader: str, old: str, new: str):
    """An ``edit`` for :func:`planted_solution`: :func:`replace_once` in the lab's ``shaders/<shader>``."""
    return lambda dest: replace_once(dest / "shaders" / shader, old, new)


def misspelt(shader: str, needle: str, name: str):
    """An ``edit`` that misspells the first ``name`` of the line ``needle`` in ``shaders/<shader>``
    (``name_misspelt``: an undeclared identifier, so the shader does not compile)."""
    return shader_edit(shader, needle, needle.replace(name, name + "_misspelt", 1))


def shader_line(lab: str, shader: str, text: str) -> int:
    """The 1-based line of the solution's ``shaders/<shader>`` in ``lab`` that contains ``text``."""
    from geomlib.grading import impl as _impl

    lines = (_impl.course_root() / "solutions" / lab / "shaders" / shader).read_text().splitlines()
    return next(i for i, ln in enumerate(lines, start=1) if text in ln)


@contextmanager
def planted_lab(lab: str, edit, timeout: float | None = None) -> Iterator:
    """A sandboxed :class:`~geomlib.grading.sandbox.LabProxy` on a :func:`planted_solution` of ``lab``
    changed by ``edit``; the copy is removed on leaving."""
    from geomlib.grading.sandbox import LabProxy

    dest = planted_solution(lab, edit)
    try:
        yield LabProxy(lab, dest, timeout=timeout)
    finally:
        shutil.rmtree(dest.parent, ignore_errors=True)


def failure_of(lab: str, edit, run: Callable, error: type[Exception], timeout: float | None = None) -> str:
    """The message of the ``error`` that ``run(proxy)`` raises on a planted copy of ``lab`` changed by
    ``edit`` (the test fails when it raises nothing)."""
    with planted_lab(lab, edit, timeout) as proxy, pytest.raises(error) as e:
        run(proxy)
    return str(e.value)


# ---------------------------------------------------------------- a lab's shaders (the GLSL routes)


def assert_compile_error_names_its_line(lab: str, shader: str, needle: str, typo: str, run: Callable, head: str,
                                        timeout: float | None = None) -> None:  # fmt: skip
    """Misspell ``typo`` in the line ``needle`` of the solution's ``shaders/<shader>`` (an undeclared
    name, which the driver reports on that very line): the first line of the
    :class:`~geomlib.grading.errors.GradingFailure` that ``run(proxy)`` raises on that copy is ``head``
    (a regular expression: function, shader, task and stage) then `` did not compile, line N`` with N
    that line, and names the misspelt identifier, not the Python wrapper."""
    from geomlib.grading.errors import GradingFailure

    line = shader_line(lab, shader, needle)
    first = failure_of(lab, misspelt(shader, needle, typo), run, GradingFailure, timeout=timeout).splitlines()[0]
    m = re.match(rf"{head} did not compile, line (?P<line>\d+)", first)
    assert m, first
    assert int(m.group("line")) == line, (first, line)
    assert f"{typo}_misspelt" in first and "glsl.py" not in first, first


def assert_hang_names_its_task(lab: str, shader: str, task: str) -> None:
    """The shader watchdog's message for a hang in ``labs/<lab>/shaders/<shader>`` names the shader
    followed by ``(<task>`` and says what a hang usually is."""
    from geomlib.grading import shader_watch

    msg = shader_watch.timeout_message("glsl_x", 60, f"shaders/{shader}", [COURSE / "labs" / lab])
    assert f"shaders/{shader} ({task}" in msg and "a loop that does not end" in msg, msg


def stub_error_lines(lab: str, shader: str, task: str) -> list[str]:
    """The ``#error`` lines of the stub ``labs/<lab>/shaders/<shader>``, after checking that the stub is
    the solution's shader through :func:`~geomlib.grading.stubs.make_stub` and that it has some, each
    naming ``task`` (``"Task 7 ("``)."""
    from geomlib.grading.stubs import make_stub

    solution = (COURSE / "solutions" / lab / "shaders" / shader).read_text()
    stub = (COURSE / "labs" / lab / "shaders" / shader).read_text()
    assert stub == make_stub(solution, f"shaders/{shader}")
    errors = [ln.strip() for ln in stub.splitlines() if ln.strip().startswith("#error")]
    assert errors and all(e.startswith(f"#error {task}") for e in errors), errors
    return errors


#: A lab's stub ``kernels.py`` with one numba task kernel (``scale``, "Task 1") and one given kernel
#: that calls it (``driver``): the given kernel's machine code holds the submission's. Tests append
#: the given function that calls ``driver``.
NUMBA_TASK_AND_GIVEN_KERNEL = """from numba import njit

from geomlib.jit import use_cache_folder

use_cache_folder(__name__, __file__)


@njit(cache=True)
def scale(x):
    \"\"\"Task 1: twice x.\"\"\"
    raise NotImplementedError("Task 1 (scale)")


@njit(cache=True)
def driver(x):
    return scale(x) + 1.0
"""
