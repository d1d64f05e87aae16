"""What ``geomlib refs|stubs build|check`` print (issue 26, item 8), on a copy of the sample course:
builds list only the files that changed and count the others, ``stubs check`` shows the diff of
what is stale, ``refs check`` words its messages for the solution and names each case once."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

from geomlib.grading import checks
from geomlib.grading.checks import Context
from geomlib.grading.errors import Mismatch

from .course import run_geomlib


@pytest.fixture
def course(sample_course, tmp_path):
    root = tmp_path / "course"
    shutil.copytree(sample_course, root)
    return root


def test_refs_build_lists_what_changed_and_counts_the_rest(course):
    p = run_geomlib(course, "refs", "build")
    assert not re.search(r"\.npz|manifest\.json", p.stdout), p.stdout  # nothing changed: no file listed
    n = int(re.search(r"0 reference file\(s\) written \(changed\), (\d+) unchanged", p.stdout).group(1))
    ops = course / "solutions" / "sample" / "ops.py"
    ops.write_text(
        ops.read_text().replace("M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]]) + 1e-3")
    )
    p = run_geomlib(course, "refs", "build")
    listed = [ln.split()[0] for ln in p.stdout.splitlines() if ln.startswith("  ")]
    assert listed == ["sample/tet-mid.npz", "sample/manifest.json"], p.stdout
    assert f"2 reference file(s) written (changed), {n - 2} unchanged" in p.stdout, p.stdout


def test_refs_build_keeps_files_that_hold_the_same_arrays(course):
    # A course set up with another Python patch release writes other zip headers for the same arrays
    # (3.11.2 vs 3.11.7) and records another version: a rebuild must leave such files, and git, alone.
    ref = course / "tests" / "reference" / "sample"
    npz, manifest = ref / "tet-mid.npz", ref / "manifest.json"
    with np.load(npz) as z:
        arrays = {k: z[k] for k in z.files}
    with open(npz, "wb") as f:
        np.savez(f, **arrays)  # same arrays, other bytes (stored, not deflated)
    m = json.loads(manifest.read_text())
    m["versions"]["python"] = "3.11.0"
    manifest.write_text(json.dumps(m, indent=1, sort_keys=True) + "\n")
    before = npz.read_bytes(), manifest.read_text()
    p = run_geomlib(course, "refs", "build")
    assert not re.search(r"\.npz|manifest\.json", p.stdout), p.stdout
    assert "0 reference file(s) written (changed)" in p.stdout, p.stdout
    assert (npz.read_bytes(), manifest.read_text()) == before


def test_stubs_build_and_check_report_what_they_found(course):
    p = run_geomlib(course, "stubs", "build")
    m = re.search(r"labs/: 0 stub file\(s\) written \(changed\), (\d+) unchanged", p.stdout)
    assert m and "wrote" not in p.stdout, p.stdout
    stub = course / "labs" / "sample" / "ops.py"
    stub.write_text(stub.read_text() + "\n# edited by hand\n")
    p = run_geomlib(course, "stubs", "check", check=False)
    assert p.returncode == 1
    assert "--- labs/sample/ops.py (in labs/)" in p.stdout and "+++ labs/sample/ops.py (generated" in p.stdout
    assert "-# edited by hand" in p.stdout, p.stdout
    p = run_geomlib(course, "stubs", "build")
    assert "  wrote labs/sample/ops.py" in p.stdout
    assert f"labs/: 1 stub file(s) written (changed), {int(m.group(1)) - 1} unchanged" in p.stdout, p.stdout


def test_refs_check_names_the_case_once(course):
    ops = course / "solutions" / "sample" / "ops.py"
    ops.write_text(
        ops.read_text().replace("M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])", "M = 0.5 * (V[E[:, 0]] + V[E[:, 1]]) + 1e-3")
    )
    p = run_geomlib(course, "refs", "check", "--no-grade", check=False)
    line = next(ln for ln in p.stdout.splitlines() if ln.startswith("FAIL sample/tet-mid"))
    assert line.count("tet-mid") == 1 and "submitted" not in line, line


def test_mesh_messages_name_the_solution_when_refs_check_compares_it():
    V = np.eye(3)
    F = np.array([[0, 1, 2]])
    ctx = Context(label="c", got_name="recomputed", got_owner="the solution")
    with pytest.raises(Mismatch) as e:
        checks.MeshMatch()({"V": V, "F": F}, {"V": V + 0.5, "F": F}, ctx)
    assert "nearest recomputed vertex" in str(e.value) and "submitted" not in str(e.value), str(e.value)
    with pytest.raises(Mismatch) as e:
        checks.MeshMatch()({"V": V, "F": F}, {"V": V + 0.5, "F": F}, Context(label="c"))
    assert "nearest submitted vertex" in str(e.value)  # the students' wording is unchanged
