"""Fixtures for testing the grading framework on the hermetic sample course."""

from __future__ import annotations

import os
import shutil
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
