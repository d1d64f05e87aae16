"""geomlib.tangent_space.as_height_map: the one check of height, displacement and offset maps."""

from __future__ import annotations

import numpy as np
import pytest

from geomlib.errors import MeshError
from geomlib.tangent_space import as_height_map


def test_integer_images_are_scaled_and_floats_kept():
    assert as_height_map(np.full((2, 2), 255, np.uint8), "f").max() == 1.0
    assert as_height_map(np.full((2, 2), 65535, np.uint16), "f").max() == 1.0
    H = np.array([[0.0, 2.0], [-1.0, 0.5]])
    assert np.array_equal(as_height_map(H, "f"), H)  # any floats without unit_range


@pytest.mark.parametrize(
    "image, message",
    [
        (np.zeros((4, 4, 3)), r"f: image has 3 channels .*single-channel \(grey\) offset map"),
        (np.zeros((4, 8)), r"f: image is 4x8 texels; offset maps are square"),
        (np.full((2, 2), 1.5), r"f: image values span \[1.5, 1.5\]; offset map values lie in \[0, 1\]"),
        (np.array([["a", "b"], ["c", "d"]]), "image"),
    ],
)
def test_messages_name_the_kind_of_map(image, message):
    with pytest.raises(MeshError, match=message):
        as_height_map(image, "f", "image", unit_range=True, what="offset map")
