"""Fixtures for testing the grading framework on the hermetic sample course."""

from __future__ import annotations

import faulthandler
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

from .course import SAMPLE, run_geomlib


@pytest.fixture(scope="session")
def sample_course() -> Path:
    """A built copy of the sample course (references and stubs generated), shared by the session.

    It lives in a world-readable temporary folder so the sandbox can drop privileges to `nobody`.
    """
    base = Path(tempfile.mkdtemp(prefix="geomlib-sample-"))
    os.chmod(base, 0o755)
    root = base / "course"
    shutil.copytree(SAMPLE, root, ignore=shutil.ignore_patterns("__pycache__"))
    # The release ships the course's own geomlib: give the sample course a copy of ours.
    shutil.copytree(
        Path(__file__).parents[2] / "geomlib", root / "geomlib", ignore=shutil.ignore_patterns("__pycache__", "READY")
    )
    run_geomlib(root, "refs", "build")
    run_geomlib(root, "stubs", "build")
    yield root
    shutil.rmtree(base, ignore_errors=True)


@pytest.fixture(autouse=True)
def _quiet_worker_crashes(request):
    """Keep the hostile-code tests' deliberate segfaults off the terminal.

    Sandbox workers are forked from the test process and inherit pytest's faulthandler, which
    writes a full "Fatal Python error: Segmentation fault" dump to a duplicate of the real stderr
    (past pytest's capture) when a worker crashes on purpose. The grader reports the crash itself.
    """
    if not faulthandler.is_enabled():
        yield
        return
    try:
        from _pytest.faulthandler import fault_handler_stderr_fd_key

        fd = request.config.stash.get(fault_handler_stderr_fd_key, None)
    except ImportError:  # pytest moved it: fall back to the process's stderr
        fd = None
    faulthandler.disable()
    try:
        yield
    finally:
        faulthandler.enable(file=fd if fd is not None else sys.__stderr__)
