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


def sandbox_user_problem(user: str = "nobody") -> str | None:
    """Why grading as ``user`` cannot work here (not root, no such user, Python unreadable), or None."""
    import pwd

    import numpy

    if os.geteuid() != 0:
        return "dropping to a sandbox user needs root"
    try:
        pw = pwd.getpwnam(user)
    except KeyError:
        return f"no user {user!r}"
    paths = [os.path.dirname(os.__file__), os.path.dirname(numpy.__file__)]
    pid = os.fork()
    if pid == 0:
        try:
            os.setgroups([])
            os.setgid(pw.pw_gid)
            os.setuid(pw.pw_uid)
            ok = all(os.access(p, os.R_OK | os.X_OK) for p in paths)
        except BaseException:  # noqa: BLE001
            ok = False
        os._exit(0 if ok else 1)
    _, st = os.waitpid(pid, 0)
    if os.waitstatus_to_exitcode(st) != 0:
        return f"user {user!r} cannot read this Python ({paths[0]}); install Python where it can (docs/autograder.md)"
    return None
