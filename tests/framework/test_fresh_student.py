"""The student guide's set-up and first grade, from student.zip, as an ordinary user (issues 28 and 26).

``geomlib release OUT --lab subdivision`` makes the student bundle; an unprivileged account without
sudo (created here when the tests run as root, else the account running them) unpacks it into an
empty HOME and follows docs/students.md literally, under ``env -i`` with the system PATH:
``./run setup``, then ``uv run geomlib grade --impl labs --lab subdivision``. The set-up must be
quiet (a few lines), install no system package and no browser, never call sudo, and leave ``uv``
where the guide's next command finds it. Before issue 28 the guide's set-up
(``./run tests -q tests/graded/subdivision``) died with "sudo: command not found" on such an
account (``ldconfig`` is not on its PATH) and, as root, apt-installed chromium and ~130 packages.
"""

from __future__ import annotations

import os
import pwd
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import pytest

from .fresh_machine import ROOT, SYSTEM_PATH, clean_env, env_i, system_python, uv_cache_dir, uv_wheel

pytestmark = pytest.mark.slow

STUDENT = "geomlib-student"
IS_ROOT = os.geteuid() == 0


def _student_account(home: Path) -> list[str]:
    """The command prefix that runs as an unprivileged account without sudo (created when root)."""
    if not IS_ROOT:
        return []  # the account running the tests is already an ordinary one
    if shutil.which("runuser") is None or shutil.which("useradd") is None:
        pytest.skip("runuser/useradd are needed to create the unprivileged student account")
    try:
        pwd.getpwnam(STUDENT)
    except KeyError:
        p = subprocess.run(
            ["useradd", "--no-create-home", "--home-dir", str(home), "--shell", "/bin/bash", STUDENT],
            capture_output=True,
            text=True,
        )
        if p.returncode != 0:
            pytest.skip(f"cannot create the unprivileged user {STUDENT}: {p.stderr.strip()}")
    return ["runuser", "-u", STUDENT, "--"]


def _give(path: Path) -> None:
    if IS_ROOT:
        subprocess.run(["chown", "-R", f"{STUDENT}:", str(path)], check=True)


def _student_cache(cache: Path, base: Path) -> Path:
    """The uv cache as the student's own: the unpacked wheels (archive-v0, 1.5 GB) as hard links to
    the machine's cache, in folders the student owns; the small index and metadata entries uv
    rewrites as the student's own copies. No download, no copy of the wheels."""
    if not IS_ROOT:
        return cache
    mine = base / "uv-cache"
    mine.mkdir()
    for entry in cache.iterdir():
        if entry.name == "archive-v0":
            subprocess.run(["cp", "-al", str(entry), str(mine / entry.name)], check=True, timeout=600)
            subprocess.run(
                ["find", str(mine / entry.name), "-type", "d", "-exec", "chown", f"{STUDENT}:", "{}", "+"], check=True
            )
        elif entry.name != ".lock":
            subprocess.run(["cp", "-a", str(entry), str(mine / entry.name)], check=True, timeout=600)
            subprocess.run(["chown", "-R", f"{STUDENT}:", str(mine / entry.name)], check=True)
    subprocess.run(["chown", f"{STUDENT}:", str(mine)], check=True)
    return mine


@pytest.fixture
def base():
    d = Path(tempfile.mkdtemp(prefix="geomlib-fresh-student-"))
    d.chmod(0o755)
    yield d
    subprocess.Popen(["rm", "-rf", str(d)], start_new_session=True)  # thousands of files: do not wait


def test_student_setup_and_first_grade_from_student_zip_without_root(base):
    system_python()
    cache, wheel = uv_cache_dir(), uv_wheel()
    home = base / "home"
    home.mkdir()
    as_student = _student_account(home)

    env = {k: v for k, v in os.environ.items() if k not in ("GEOMLIB_ROOT", "VIRTUAL_ENV", "UV_PROJECT_ENVIRONMENT")}
    # --no-check: release's grading of the solutions before it packages is repetition here (the suite
    # grades them in tests/graded and through the released autograder in test_release_course.py).
    p = subprocess.run(
        [sys.executable, "-m", "geomlib.cli", "release", str(base / "dist"), "--lab", "subdivision", "--no-check"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    shutil.copy(base / "dist" / "student.zip", home)
    shutil.copy(wheel, base / wheel.name)
    _give(home)
    student_cache = _student_cache(cache, base)
    senv = clean_env(home, UV_CACHE_DIR=str(student_cache), GEOMLIB_UV_WHEEL=str(base / wheel.name))
    if IS_ROOT:
        # The cache's files belong to root, so the kernel refuses the student hard links to them
        # (fs.protected_hardlinks); symbolic links into the shared cache instead of copying 1.7 GB.
        senv["UV_LINK_MODE"] = "symlink"

    def student(*cmd: str, cwd: Path, path: str = SYSTEM_PATH, timeout: int = 1500):
        e = {**senv, "PATH": path}
        return subprocess.run([*as_student, *env_i(e), *cmd], cwd=cwd, capture_output=True, text=True, timeout=timeout)

    # Unpack as the guide's reader would (unzip keeps ./run executable).
    if shutil.which("unzip"):
        r = student("unzip", "-q", "student.zip", cwd=home)
        assert r.returncode == 0, r.stderr
    else:
        with zipfile.ZipFile(home / "student.zip") as z:
            for info in z.infolist():
                z.extract(info, home)
                (home / info.filename).chmod((info.external_attr >> 16) & 0o777 or 0o644)
        _give(home)
    course = home / "student"
    assert "./run setup" in (course / "README.md").read_text()  # the guide's own set-up command

    t0 = time.monotonic()
    setup = student("./run", "setup", cwd=course)
    t_setup = time.monotonic() - t0
    log = f"stdout:\n{setup.stdout[-3000:]}\nstderr:\n{setup.stderr[-3000:]}"
    assert setup.returncode == 0, log
    for word in ("sudo", "apt-get install -y", "chromium", "externally-managed", "Traceback"):
        assert word not in setup.stderr + setup.stdout, f"{word!r} in the set-up's output\n{log}"
    lines = [ln for ln in (setup.stdout + setup.stderr).splitlines() if ln.strip()]
    assert len(lines) <= 8, f"the set-up is not quiet ({len(lines)} lines)\n{log}"
    assert "ready" in setup.stderr, log
    assert (home / ".local" / "bin" / "uv").exists(), log

    # The guide's next command, with ~/.local/bin on the PATH as the set-up says.
    t0 = time.monotonic()
    grade = student(
        "uv",
        "run",
        "geomlib",
        "grade",
        "--impl",
        "labs",
        "--lab",
        "subdivision",
        cwd=course,
        path=f"{home}/.local/bin:{SYSTEM_PATH}",
    )
    t_grade = time.monotonic() - t0
    glog = f"stdout:\n{grade.stdout[-3000:]}\nstderr:\n{grade.stderr[-3000:]}"
    assert grade.returncode == 0, glog
    assert "not implemented yet" in grade.stdout and "0 / " in grade.stdout, glog
    print(
        f"student.zip as {'user ' + STUDENT if IS_ROOT else 'this user'}: ./run setup {t_setup:.0f} s, first grade {t_grade:.0f} s"
    )
