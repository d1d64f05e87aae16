import numpy as np

from geomlib.grading import Case, checks

from .cases import TET_F, TET_V

CASES = [
    Case(
        id="tet-scale-half",
        function="scale_about_centroid",
        inputs=lambda: {"V": TET_V + np.array([5.0, 0, 0]), "F": TET_F},
        params={"s": 0.5},
        outputs=("V",),
        check=checks.Allclose(),
        part="scaling",
        points=1,
        visibility="hidden",
    ),
]
