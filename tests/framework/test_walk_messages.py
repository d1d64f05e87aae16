"""Messages a student reads, as found in the fresh-clone walk of docs/students.md (issue 26):
subdivision's matrix messages quote the sum of the row they show; what the code printed follows the
exception's message as a sentence of its own."""

from __future__ import annotations

import json

import numpy as np
import scipy.sparse as sp

from geomlib.grading.sandbox import StudentError, _outcome
from tests.graded.subdivision.support import matrix_mismatch


def test_the_sum_quoted_is_the_sum_of_the_row_shown():
    # Both rows are wrong and neither sums to 1; the message shows row 0, so it quotes row 0's sum
    # (it quoted the row furthest from 1: "row 0: ... (row 1 sums to 0.85)" in the walk, where the
    # rows differed from 0.85 in the last bit only).
    expected = sp.csr_matrix(np.array([[0.375, 0.375, 0.125, 0.125], [0.125, 0.375, 0.125, 0.375]]))
    got = np.array([[0.3, 0.3, 0.125, 0.125], [0.125, 0.2, 0.125, 0.3]])
    msg = matrix_mismatch("S_odd", expected, sp.csr_matrix(got))
    assert msg.startswith("S_odd row 0:") and "(row 0 sums to 0.85;" in msg, msg


def test_a_row_that_sums_to_one_points_at_the_row_that_does_not():
    expected = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5]])
    got = np.array([[0.6, 0.4, 0.0], [0.0, 0.5, 0.4]])  # row 0 wrong but sums to 1; row 1 sums to 0.9
    msg = matrix_mismatch("S", expected, got)
    assert msg.startswith("S row 0:") and "(row 1 sums to 0.9;" in msg, msg


def test_what_the_code_printed_follows_the_exception_as_its_own_sentence():
    """A NameError after a debugging print read "name 'undefined_name' is not defined Your code
    printed: ..." (no full stop between the two)."""
    info = {
        "kind": "exception",
        "type": "NameError",
        "message": "name 'undefined_name' is not defined",
        "mro": ["NameError", "Exception"],
        "frames": [
            {"file": "subdivision/loop.py", "line": 132, "function": "loop_weight", "code": "return u / undefined_name"}
        ],
    }
    reply = {"printed": "debug: n = [3. 4. 6.]\n", "data": b"E" + json.dumps(info).encode(), "why": None, "status": 0}
    try:
        _outcome("loop_weight", reply, 30.0, 4096, 1 << 20)
    except StudentError as e:
        msg = str(e)
    else:
        raise AssertionError("no StudentError")
    assert "is not defined. Your code printed: 'debug: n = [3. 4. 6.]'" in msg, msg


def test_a_lab_folder_given_as_the_implementation_is_graded(tmp_path):
    """`geomlib grade --impl path/to/subdivision --lab subdivision` (the folder a student uploads) was
    graded as the folder *holding* the lab: every test read "lab folder .../subdivision/subdivision is
    missing from the submission" (fresh-clone walk, issue 26)."""
    import shutil

    from geomlib.grading.course import course
    from geomlib.grading.grade import grade

    lab = tmp_path / "subdivision"
    shutil.copytree(course().lab("subdivision").solution, lab)
    data = grade(str(lab), ["subdivision"], task=1, pictures="none", feedback_dir=tmp_path / "feedback")
    assert data["tests"] and all(t["status"] == "passed" for t in data["tests"]), data["report"]


def test_progress_lines_reach_a_log_file_as_they_happen(tmp_path):
    """`geomlib grade-all ... > log` (or `| tee`) showed no progress line ("[1/3] bob: 0/151") until
    the last submission was graded: Python block-buffers stdout that is not a terminal (fresh-clone
    walk, issue 26). Every command's stdout is line-buffered, also into a pipe."""
    import subprocess
    import sys

    from geomlib import datasets, mesh_io

    mesh = tmp_path / "mesh.obj"
    mesh_io.write_mesh(str(mesh), *datasets.icosphere(0))
    code = "import sys, geomlib.cli as c; c.main(['info', sys.argv[1]]); print('line-buffered:', sys.stdout.line_buffering)"
    p = subprocess.run([sys.executable, "-c", code, str(mesh)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and "line-buffered: True" in p.stdout, p.stdout + p.stderr
