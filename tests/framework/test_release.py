"""`geomlib release` on the sample course: the bundle leaks nothing, the per-lab zip grades, failures are clean.

The real course is released and graded end to end in ``test_release_course.py``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from geomlib.grading.results import validate_results

from .course import run_autograder, run_geomlib, user_cli


@pytest.fixture(scope="module")
def release(sample_course) -> Path:
    out = Path(tempfile.mkdtemp(prefix="geomlib-release-"))
    out.chmod(0o755)
    try:
        # --no-check: release's grading of the solutions before it packages is repetition here (this
        # module grades them through the released autograder); test_release_refuses.py tests the check.
        run_geomlib(sample_course, "release", str(out), "--no-check")
        yield out
    finally:  # every run left one behind in /tmp
        shutil.rmtree(out, ignore_errors=True)


def test_student_bundle_has_no_solutions_and_no_hidden_material(release, sample_course):
    student = release / "student"
    files = [p.relative_to(student).as_posix() for p in student.rglob("*") if p.is_file()]
    assert "labs/sample/ops.py" in files and "tests/graded/sample/test_sample.py" in files
    assert "tests/reference/sample/tet-scale.npz" in files
    assert not any(f.startswith("solutions/") for f in files)
    assert not any("hidden" in f for f in files), [f for f in files if "hidden" in f]
    assert not any(f.startswith(("tests/framework", "tests/unit", "tests/solutions")) for f in files)
    # No line from inside a solution block appears anywhere in the bundle.
    secret = "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])"
    assert secret in (sample_course / "solutions" / "sample" / "ops.py").read_text()
    for p in student.rglob("*"):
        if p.is_file() and p.suffix in (".py", ".md", ".ipynb", ".txt", ".toml"):
            assert secret not in p.read_text(), p
    assert sorted(p.name for p in release.iterdir()) == ["autograder-sample.zip", "student", "student.zip"]
    with zipfile.ZipFile(release / "student.zip") as z:
        assert not any("solutions/" in n or "hidden" in n for n in z.namelist())


def test_student_bundle_grades_its_stubs_to_zero_without_errors(release):
    student = release / "student"
    env = {"PYTHONPATH": str(student), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    p = user_cli(student, "grade", "--results", "r.json", env=env)
    r = json.loads((student / "r.json").read_text())
    validate_results(r)
    assert r["score"] == 0 and r["tests"]
    assert all(
        t["status"] == "failed" and "not implemented yet" in t["output"] for t in r["tests"] if t["max_score"] > 0
    )
    assert "geomlib-sample" not in p.stdout  # it graded its own copy, not the instructors' course


def _autograder(release: Path, submission_labs: Path | None) -> dict:
    return run_autograder(release, "sample", submission_labs)


def test_run_autograder_grades_a_correct_submission_with_hidden_tests(release, sample_course):
    r = _autograder(release, sample_course / "solutions" / "sample")
    validate_results(r)
    assert r["score"] == 7  # includes the hidden case
    assert any(t["visibility"] == "hidden" for t in r["tests"])


def test_run_autograder_on_an_empty_submission_says_what_to_upload(release):
    r = _autograder(release, None)
    validate_results(r)
    assert r["score"] == 0 and "no folder sample/ or labs/sample/" in r["output"]


# ------------------------------------------------------------------------------ failures, leaks


@pytest.fixture
def course_copy(sample_course):
    """A private copy of the built sample course, removed afterwards (every run left three in /tmp)."""
    base = Path(tempfile.mkdtemp(prefix="geomlib-sample-copy-"))
    try:
        root = base / "course"
        shutil.copytree(sample_course, root, symlinks=True)
        yield root
    finally:
        shutil.rmtree(base, ignore_errors=True)


def _plant(root: Path, lines: list[str]) -> None:
    """Add ``lines`` to a public test helper that ships to students."""
    helper = root / "tests" / "graded" / "sample" / "cases.py"
    helper.write_text(helper.read_text() + "\n\ndef _planted(V, E, tol=None):\n" + "".join(f"    {x}\n" for x in lines))


def test_a_planted_leak_stops_the_release_with_one_line_and_leaves_nothing(course_copy):
    root = course_copy
    _plant(root, ["M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "return M"])
    out = root.parent / "dist"
    out.mkdir()
    (out / "keep.txt").write_text("an earlier file")
    p = run_geomlib(root, "release", str(out), check=False)
    assert p.returncode == 1, p.stdout + p.stderr
    err = p.stderr.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in p.stderr, p.stderr
    assert err[0].startswith("geomlib release: error:") and "tests/graded/sample/cases.py" in err[0]
    assert "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])" in err[0] and "Task 2 (midpoints)" in err[0]
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]  # nothing half-written, nothing removed


def test_generic_lines_of_a_solution_block_are_not_leaks(course_copy):
    # Lines that the library ships anyway (`return False`, `if tol is None:`) give nothing away,
    # even inside a solution block: a helper may use them.
    root = course_copy
    ops = root / "solutions" / "sample" / "ops.py"
    text = ops.read_text().replace(
        "    c = V.mean(axis=0)\n",
        "    if tol is None:\n        pass\n    if False:\n        return False\n    c = V.mean(axis=0)\n",
    )
    ops.write_text(text)
    _plant(root, ["if tol is None:", "    return False"])
    from geomlib.grading import release as rel

    secrets = rel.secret_lines(root)
    task1 = next(v for k, v in secrets.items() if "Task 1" in k)
    assert "c = V.mean(axis=0)" in task1 and "if tol is None:" not in task1 and "return False" not in task1
    out = root.parent / "dist"
    # packaging only: the planted lines break the solution, which the release check would refuse
    p = run_geomlib(root, "release", str(out), "--no-check", check=False)
    assert p.returncode == 0, p.stdout + p.stderr


def test_an_unknown_lab_or_stale_stubs_give_one_clear_line(course_copy):
    root = course_copy
    p = run_geomlib(root, "release", str(root.parent / "dist"), "--lab", "nope", check=False)
    assert p.returncode == 1 and p.stderr.strip() == "geomlib release: error: unknown lab(s) nope; known: sample"
    stub = root / "labs" / "sample" / "ops.py"
    stub.write_text(stub.read_text() + "\n# edited by hand\n")
    p = run_geomlib(root, "release", str(root.parent / "dist"), check=False)
    assert p.returncode == 1 and "labs/ is stale" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not (root.parent / "dist").exists() or not any((root.parent / "dist").iterdir())


def test_run_autograder_copies_the_submission_without_following_links(release, sample_course, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP SECRET")
    lab = tmp_path / "sub" / "sample"
    shutil.copytree(sample_course / "solutions" / "sample", lab)
    (lab / "notes.txt").symlink_to(secret)
    (lab / "outside").symlink_to(tmp_path)
    from geomlib.grading.submission import copy_lab, find_lab

    assert find_lab(tmp_path / "sub", "sample") == lab
    skipped = copy_lab(lab, tmp_path / "copy")
    assert sorted(skipped) == ["notes.txt (symbolic link)", "outside (symbolic link)"]
    assert not (tmp_path / "copy" / "notes.txt").exists() and not (tmp_path / "copy" / "outside").exists()
    assert (tmp_path / "copy" / "ops.py").read_text() == (lab / "ops.py").read_text()


def _setup_packages(tmp_path: Path, libraries: str, dri: bool) -> list[str]:
    """Run the system-package block of the released setup.sh with a fake ``ldconfig`` (listing
    ``libraries``) and a fake ``apt-get`` that records what it is asked to install."""
    from geomlib.grading.release import SETUP_SH

    block = "need=()" + SETUP_SH.split("\nneed=()", 1)[1].split("\nfi\n", 1)[0] + "\nfi\n"
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(parents=True)
    (bin_dir / "ldconfig").write_text(f"#!/bin/sh\nprintf '%s\\n' {libraries!r}\n")
    log = tmp_path / "apt.log"
    (bin_dir / "apt-get").write_text(f'#!/bin/sh\necho "$@" >> {log}\n')
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    dri_dir = tmp_path / "dri"
    dri_dir.mkdir()
    if dri:
        (dri_dir / "swrast_dri.so").write_text("")
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}", "GEOMLIB_DRI_DIR": str(dri_dir)}
    p = subprocess.run(["bash", "-c", "set -euo pipefail\n" + block], env=env, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    lines = log.read_text().splitlines() if log.exists() else []
    return [w for line in lines if line.startswith("install") for w in line.split() if not w.startswith("-")][1:]


def test_setup_installs_what_osmesa_and_egl_need_only_when_missing(tmp_path):
    everything = "libOSMesa.so.8 libGL.so.1 libXrender.so.1 libEGL.so.1 libEGL_mesa.so.0"
    assert _setup_packages(tmp_path / "a", everything, dri=True) == []
    wanted = _setup_packages(tmp_path / "b", "libc.so.6", dri=False)
    assert {"libosmesa6", "libgl1", "libxrender1", "libegl1", "libegl-mesa0", "libgl1-mesa-dri"} <= set(wanted)
    assert _setup_packages(tmp_path / "c", "libOSMesa.so.8 libGL.so.1 libXrender.so.1 libEGL.so.1", dri=True) == [
        "libegl-mesa0"
    ]
    # pyrender's import loads libGL and libXrender (pyglet's viewer): a Debian 12 root without them
    # could not render
    only_gl = "libOSMesa.so.8 libEGL.so.1 libEGL_mesa.so.0"
    assert _setup_packages(tmp_path / "d", only_gl, dri=True) == ["libgl1", "libxrender1"]


def test_setup_syncs_with_the_system_certificate_store(tmp_path):
    """setup.sh's ``uv sync`` trusts the system's certificate store, as ``./run``'s does (issue 26).

    Walked in a Debian 12 root built like the dev container's image behind a TLS-intercepting proxy
    whose CA is in the system store: the bootstrap's download of uv (Python, system store) worked,
    then ``uv sync`` (its own bundled roots) failed with "invalid peer certificate: UnknownIssuer".
    Here the whole script runs with a fake ``uv`` that records its environment, and with no
    certificate variable of this machine (SSL_CERT_FILE, ...) to help it."""
    from geomlib.grading.release import SETUP_SH

    src = tmp_path / "ag" / "source"
    (src / "geomlib" / "grading").mkdir(parents=True)
    shutil.copy(
        Path(__file__).resolve().parents[2] / "geomlib" / "grading" / "bootstrap.py", src / "geomlib" / "grading"
    )
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    log = tmp_path / "uv.log"
    (bin_dir / "ldconfig").write_text(
        "#!/bin/sh\necho libOSMesa.so.8 libGL.so.1 libXrender.so.1 libEGL.so.1 libEGL_mesa.so.0\n"
    )
    (bin_dir / "apt-get").write_text("#!/bin/sh\nexit 1\n")
    (bin_dir / "uv").write_text(
        f'#!/bin/sh\nif [ "$1" = --version ]; then echo "uv 99.0.0"; exit 0; fi\n'
        f'echo "$1 UV_SYSTEM_CERTS=${{UV_SYSTEM_CERTS:-}}" >> {log}\nexit 3\n'
    )
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    dri_dir = tmp_path / "dri"
    dri_dir.mkdir()
    (dri_dir / "swrast_dri.so").write_text("")
    env = {k: v for k, v in os.environ.items() if not any(w in k for w in ("CERT", "CA_BUNDLE", "UV_"))}
    env.update(
        PATH=f"{bin_dir}:{os.environ['PATH']}",
        GEOMLIB_DRI_DIR=str(dri_dir),
        GEOMLIB_AUTOGRADER_ROOT=str(tmp_path / "ag"),
        GEOMLIB_AUTOGRADER_PYTHON=sys.executable,
        GEOMLIB_UV=str(bin_dir / "uv"),
        GEOMLIB_SANDBOX_USER="",
    )
    p = subprocess.run(["bash", "-c", SETUP_SH], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 3, p.stdout + p.stderr  # stopped by the fake uv's sync, nothing before it
    assert log.read_text().splitlines() == ["sync UV_SYSTEM_CERTS=1"]
