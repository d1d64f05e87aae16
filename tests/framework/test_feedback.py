"""A failing geometry or image check writes a feedback picture (expected | submitted | difference)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geomlib import datasets, image_io
from geomlib.grading import checks
from geomlib.grading.errors import Mismatch


@pytest.mark.render
def test_mesh_mismatch_writes_a_three_panel_picture(tmp_path, monkeypatch):
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.chdir(tmp_path)
    V, F = datasets.icosphere(2)
    bent = V.copy()
    bent[V[:, 2] > 0.5] *= 1.1
    ctx = checks.Context(
        label='loop_subdivide on "ico"', lab="subdivision", case_id="ico", feedback_dir=Path("feedback")
    )
    with pytest.raises(Mismatch) as e:
        checks.MeshMatch()({"V": V, "F": F}, {"V": bent, "F": F}, ctx)
    assert e.value.feedback == "feedback/subdivision/ico.png"
    assert "(see feedback/subdivision/ico.png)" in str(e.value)
    img = image_io.read_image(tmp_path / e.value.feedback)
    assert img.shape[1] > 2.5 * img.shape[0] / 1.5 and img.std() > 10  # three panels side by side, not blank


def test_image_mismatch_writes_a_difference_map(tmp_path):
    expected = np.zeros((32, 32, 3), np.uint8)
    got = expected.copy()
    got[8:16, 8:16] = 200
    ctx = checks.Context(label="shade", lab="maps", case_id="quad", feedback_dir=tmp_path)
    with pytest.raises(Mismatch) as e:
        checks.ImageMatch()({"image": expected}, {"image": got}, ctx)
    assert "6.25% of pixels differ" in str(e.value) and "row 8, column 8" in str(e.value)
    assert (tmp_path / "maps" / "quad.png").is_file()
