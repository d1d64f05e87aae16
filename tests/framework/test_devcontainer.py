"""The dev container is built by the autograder's own set-up script (issue 28, item 3).

Docker does not run in CI, so the definition is checked statically: devcontainer.json builds
.devcontainer/Dockerfile from the course folder; the Dockerfile copies the course to
``$GEOMLIB_AUTOGRADER_ROOT/source`` and runs ``geomlib/grading/setup.sh`` there, the very file
``geomlib release`` ships as every autograder's ``setup.sh`` (tests/framework/test_release_course.py
runs that script for real); the container's uv environment is the one the script builds; opening
the folder runs the students' ``./run setup``. The student bundle carries the dev container.
"""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

from geomlib.grading import release

ROOT = Path(__file__).resolve().parents[2]
SETUP = ROOT / "geomlib" / "grading" / "setup.sh"


def _dockerfile() -> list[tuple[str, str]]:
    """(instruction, arguments) of the dev container's Dockerfile, continuation lines joined."""
    text = (ROOT / ".devcontainer" / "Dockerfile").read_text().replace("\\\n", " ")
    out = []
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            word, _, rest = line.partition(" ")
            out.append((word.upper(), rest.strip()))
    return out


def test_devcontainer_builds_its_image_with_the_autograders_setup_script():
    spec = json.loads((ROOT / ".devcontainer" / "devcontainer.json").read_text())
    assert (ROOT / ".devcontainer" / spec["build"]["dockerfile"]).is_file()
    assert (ROOT / ".devcontainer" / spec["build"]["context"]).resolve() == ROOT  # the course folder

    steps = _dockerfile()
    copies = [args.split() for word, args in steps if word == "COPY"]
    assert [".", "/opt/geomlib/source"] in copies, copies
    runs = [shlex.split(args) for word, args in steps if word == "RUN"]
    setup_runs = [r for r in runs if any(a.endswith("geomlib/grading/setup.sh") for a in r)]
    assert len(setup_runs) == 1, runs
    (run,) = setup_runs
    env = dict(a.split("=", 1) for a in run if re.fullmatch(r"[A-Z_]+=.*", a))
    script = next(a for a in run if a.endswith("setup.sh"))
    # setup.sh installs into $GEOMLIB_AUTOGRADER_ROOT/source: where the course was copied.
    assert script == f"{env['GEOMLIB_AUTOGRADER_ROOT']}/source/geomlib/grading/setup.sh"
    assert env.get("GEOMLIB_SETUP_DEV") == "1"  # with the students' tools (JupyterLab)
    # Nothing else installs anything: the image is what setup.sh makes it.
    assert not [r for r in runs if r is not run and {"apt-get", "pip", "uv"} & set(r)], runs

    # The container uses the environment setup.sh built ($SRC/.venv) and the students' set-up.
    assert spec["containerEnv"]["UV_PROJECT_ENVIRONMENT"] == f"{env['GEOMLIB_AUTOGRADER_ROOT']}/source/.venv"
    assert 'UV_PROJECT_ENVIRONMENT="$SRC/.venv"' in SETUP.read_text()
    assert spec["postCreateCommand"] == "./run setup"


def test_the_released_setup_script_is_that_file():
    assert SETUP.read_text() == release.SETUP_SH
    assert SETUP.stat().st_mode & 0o111  # runnable as it is (the Dockerfile runs it with bash anyway)
    text = SETUP.read_text()
    assert text.count("@LAB@") == 1  # the one place geomlib release writes the lab's name
    assert "pip install" not in text and "--break-system-packages" not in text  # PEP 668: uv via bootstrap.py
    assert "geomlib/grading/bootstrap.py" in text


def test_the_student_bundle_carries_the_dev_container():
    files = {rel.as_posix() for _, rel in release.student_files(ROOT, ["subdivision"])}
    assert {".devcontainer/devcontainer.json", ".devcontainer/Dockerfile", ".dockerignore", "run"} <= files
    assert "geomlib/grading/setup.sh" in files and "geomlib/grading/bootstrap.py" in files
