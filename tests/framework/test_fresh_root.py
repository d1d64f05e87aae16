"""The README's main job on a fresh machine, as root (issue 28, item 1).

A fresh clone of this repository's HEAD runs ``./run figures --lab subdivision --quick`` under ``env -i``
with the system PATH, an empty HOME, no uv on the PATH and the system ``python3`` (on Debian 12 and
Ubuntu 24.04 "externally managed", PEP 668: ``pip install`` is refused). The uv package cache is
shared (``UV_CACHE_DIR``) and so is one verified copy of uv's wheel, so what is tested is the
set-up, not the download. Before issue 28, ``./run`` stopped at ``python3 -m pip install uv`` with
"error: externally-managed-environment".

``--quick`` (smaller pictures, the same builders): what is tested here is that the set-up reaches a
working ``geomlib figures``; the same lab's figures at full size are drawn, and compared with the
committed ones, by tests/test_figures_reproduce.py in the same suite run.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

from .fresh_machine import ROOT, SYSTEM_PATH, clean_env, env_i, system_python, uv_cache_dir, uv_wheel

pytestmark = pytest.mark.slow


@pytest.fixture
def fresh(tmp_path_factory):
    base = Path(tempfile.mkdtemp(prefix="geomlib-fresh-root-"))
    yield base
    subprocess.Popen(["rm", "-rf", str(base)], start_new_session=True)  # thousands of files: do not wait


def test_run_figures_in_a_fresh_clone_as_root_with_the_system_python(fresh):
    if os.geteuid() != 0:
        pytest.skip("the README's fresh-machine route is run as root (the student route covers other users)")
    if shutil.which("git") is None:
        pytest.skip("git is needed to clone the repository")
    python = system_python()
    cache, wheel = uv_cache_dir(), uv_wheel()
    clone, home, out = fresh / "clone", fresh / "home", fresh / "figures"
    home.mkdir()
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True, timeout=300)
    # UV_COMPILE_BYTECODE=0: ./run's bytecode compile of the whole locked environment (about 20 s of
    # CPU; no outcome of this test depends on it) is the same line on the same lock that set up the
    # environment running this suite (CI's `./run tests`); setup.sh's compile is checked in
    # test_release_course.py. (test_fresh_student.py's symbolic links into the shared uv cache
    # compile nothing: uv skips linked files.)
    env = clean_env(home, UV_CACHE_DIR=str(cache), GEOMLIB_UV_WHEEL=str(wheel), UV_COMPILE_BYTECODE="0")
    t0 = time.monotonic()
    p = subprocess.run(
        [*env_i(env), "./run", "figures", "--lab", "subdivision", "--quick", "--out", str(out)],
        cwd=clone,
        capture_output=True,
        text=True,
        timeout=1500,
    )
    seconds = time.monotonic() - t0
    log = f"stdout:\n{p.stdout[-3000:]}\nstderr:\n{p.stderr[-3000:]}"
    assert p.returncode == 0, log
    assert "externally-managed" not in p.stderr and "pip install" not in p.stderr, log
    # uv was not on the PATH: the bootstrap put its own into the empty HOME, no root-owned place.
    if shutil.which("uv", path=SYSTEM_PATH) is None:
        assert "installing uv" in p.stderr, log
        assert list((home / ".local" / "share" / "geomlib").glob("uv-*/uv")), log
    # The environment is built on the system Python (the point of the test), not on a pyenv one.
    cfg = (clone / ".venv" / "pyvenv.cfg").read_text()
    assert f"home = {Path(python).resolve().parent}" in cfg or f"home = {Path(python).parent}" in cfg, cfg
    pictures = sorted(out.rglob("*.png"))
    assert (out / "index.html").is_file() and len(pictures) >= 3, log
    print(f"fresh clone, env -i, root: ./run figures --lab subdivision --quick in {seconds:.0f} s")
