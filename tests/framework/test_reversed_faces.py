"""Face comparisons count the expected faces that a submission gives with reversed orientation.

The count is made for all missing faces at once (subdivision's forged outputs in
test_informative_references.py once spent seconds of CPU on it, a face at a time); these
tests pin what it counts: reversed faces, not faces that are only missing.
"""

from __future__ import annotations

import numpy as np
import pytest

from geomlib.grading import checks
from geomlib.grading.checks import Context
from geomlib.grading.errors import Mismatch
from tests.graded.subdivision.support import faces_mismatch

#: A strip of six triangles over eight vertices (no face is the reverse of another).
V = np.array([[x, y, 0.0] for x in range(4) for y in range(2)])
F = np.array([[0, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5], [4, 6, 5], [5, 6, 7]])


def _submitted() -> np.ndarray:
    """Faces 1 and 3 reversed (and rotated), face 5 replaced by another triangle."""
    G = F.copy()
    G[1] = [3, 2, 1]
    G[3] = [4, 3, 5]
    G[5] = [5, 7, 4]
    return G


def test_mesh_match_counts_the_reversed_faces_among_the_missing():
    with pytest.raises(Mismatch) as e:
        checks.MeshMatch()({"V": V, "F": F}, {"V": V, "F": _submitted()}, Context(label="c"))
    assert "3 of 6 expected faces are missing" in str(e.value), e.value
    assert "2 of them appear with reversed orientation" in str(e.value), e.value


def test_subdivision_faces_mismatch_counts_the_reversed_faces_among_the_missing():
    msg = faces_mismatch("F", F, _submitted())
    assert msg.startswith("3 of 6 expected faces are missing"), msg
    assert "; 2 appear with reversed orientation" in msg, msg
