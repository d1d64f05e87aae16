"""Pictures for every geometric or image failure: a planted wrong submission per lab is graded on the
lab's reference cases, and every failing case whose output is geometric gets a feedback picture.

Geometric here: the case's inputs hold a mesh (``V`` and ``F``/``faces``), or an output is a grid or
image (``(h, w, c)``, or ``(h, w)`` with both sides at least 8, booleans included: vdm's diagonals),
or points with no mesh (``(n, 2)`` or ``(n, 3)``: shadows' light-space ``(u, v, z)``).
Not geometric, and so allowed without a picture: outputs on free-standing random vectors with no
mesh or grid to draw them on (denoise's ``normal_offsets`` on random ``delta``/``N``: a list of
scalars). Hand-written graded tests (``test_<lab>.py``) call ``expect_close`` without a feedback
folder and are not covered here.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from geomlib.grading.cases import load_cases, load_reference, run_case
from geomlib.grading.errors import Mismatch
from geomlib.grading.sandbox import LabProxy

from .test_diagnose import _plant

# lab, module, planted source, at least this many failing cases, at least this many with pictures
PLANTS = {
    "vdm": (
        "sampling",
        """
        _true_sample_surface = sample_surface

        def sample_surface(V, F, UV, uv_points):
            return 1.01 * _true_sample_surface(V, F, UV, uv_points)
        """,
        8,
    ),
    "denoise": (
        "laplacian",
        """
        _true_normal_offsets = normal_offsets

        def normal_offsets(delta, N):
            return 0.8 * _true_normal_offsets(delta, N)
        """,
        3,
    ),
    "shadows": (
        "lookup",
        """
        _true_light_uvz = light_uvz

        def light_uvz(P, M):
            return np.asarray(_true_light_uvz(P, M)) + [0.05, 0.0, 0.0]
        """,
        3,
    ),
}


def _geometric(case, expected: dict) -> bool:
    inputs = case.inputs()
    if "V" in inputs and any(k in inputs for k in ("F", "faces", "Q")):
        return True
    for e in expected.values():
        e = np.asarray(e)
        if e.dtype.kind not in "fb":
            continue
        if e.ndim == 3 and min(e.shape[:2]) >= 2 and e.shape[2] <= 4:
            return True
        if e.ndim == 2 and min(e.shape) >= 8:
            return True
        if e.dtype.kind == "f" and e.ndim == 2 and e.shape[1] in (2, 3) and len(e) >= 2:
            return True  # free-standing points (light-space (u, v, z)): a scatter picture
    return False


@pytest.mark.parametrize("lab", list(PLANTS))
def test_every_geometric_failure_has_a_picture(lab, tmp_path):
    module, source, at_least = PLANTS[lab]
    folder = _plant(lab, module, source)
    proxy = LabProxy(lab, folder)
    failing, missing = [], []
    try:
        for case in load_cases(lab, hidden=True, probes=False):
            try:
                run_case(proxy, case, feedback_dir=tmp_path)
            except Mismatch as e:
                failing.append(case.id)
                if _geometric(case, load_reference(lab, case)) and not (e.feedback and (tmp_path / lab).is_dir()):
                    missing.append(case.id)
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)
    assert len(failing) >= at_least, f"the plant should fail at least {at_least} cases, failed {failing}"
    assert not missing, f"failing geometric cases without a feedback picture: {missing}"
    drawn = list((tmp_path / lab).glob("*.png"))
    assert drawn and all(p.stat().st_size > 1000 for p in drawn), drawn
