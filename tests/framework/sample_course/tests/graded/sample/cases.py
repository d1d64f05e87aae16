import numpy as np

from geomlib.grading import Case, checks

TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])

CASES = [
    Case(
        id="tet-scale",
        function="scale_about_centroid",
        inputs=lambda: {"V": TET_V, "F": TET_F},
        params={"s": 3.0},
        outputs=("V",),
        check=checks.Allclose(),
        part="scaling",
        points=2,
        hint="scale about the centroid, not the origin",
    ),
    Case(
        id="tet-mid",
        function="edge_midpoints",
        inputs=lambda: {"V": TET_V, "F": TET_F},
        outputs=("E", "M"),
        check=checks.All(checks.Equal("E"), checks.Allclose("M")),
        part="midpoints",
        points=2,
    ),
]
