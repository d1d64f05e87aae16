"""Hidden graded cases of the denoise lab (not shipped to students): the same tasks on other inputs."""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.grading import Case, checks
from geomlib.grading import tolerances as tol

from .cases import map_inputs, noisy_mesh, offsets_on_uv, uv_mesh
from .support import SPLIT_F, SPLIT_UV, SPLIT_V, map_check, weld_check


def ant():
    return datasets.pyvista_mesh("ant")


def split_offsets():
    return {"V": SPLIT_V, "F": SPLIT_F, "UV": SPLIT_UV, "s": np.array([0.1, -0.2, 0.3, -0.2, 0.3, 0.05])}


CASES = [
    Case(
        id="hidden-offsets-uniform-ant",
        function="laplacian_offsets",
        inputs=noisy_mesh(ant, seed=11),
        params={"weights": "uniform", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.EXACT),
        part="offsets",
        points=7,
        visibility="hidden",
    ),
    Case(
        id="hidden-offsets-cotan-height-field",
        function="laplacian_offsets",
        inputs=noisy_mesh(lambda: datasets.height_field(8, seed=3), seed=12),
        params={"weights": "cotan", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.GEOMETRY),
        part="offsets",
        points=7,
        visibility="hidden",
    ),
    Case(
        id="hidden-normal-offsets-random",
        function="normal_offsets",
        inputs=lambda: {
            "delta": np.random.default_rng(21).normal(size=(500, 3)),
            "N": np.random.default_rng(22).normal(size=(500, 3)) * 0.5,
        },
        outputs=("s",),
        check=checks.Allclose(atol=tol.EXACT),
        part="projection on normals",
        points=3,
        visibility="hidden",
    ),
    Case(
        id="hidden-denoise-ant-1.0x2",
        function="denoise_vertices",
        inputs=noisy_mesh(ant, seed=13, with_normals=True),
        params={"lam": 1.0, "iterations": 2, "weld": False},
        outputs=("V",),
        check=checks.Allclose(atol=tol.GEOMETRY),
        part="direct denoising",
        points=14,
        visibility="hidden",
    ),
    Case(
        id="hidden-bake-split-padding-2",
        function="bake_offset_map",
        inputs=split_offsets,
        params={"size": 32, "bits": 16, "padding": 2},
        outputs=("image", "bias", "scale"),
        check=map_check(),
        part="baking the map",
        points=5,
        visibility="hidden",
    ),
    Case(
        id="hidden-bake-uv-torus-8bit",
        function="bake_offset_map",
        inputs=offsets_on_uv(lambda: datasets.uv_torus(16, 10), seed=4),
        params={"size": 40, "bits": 8},
        outputs=("image", "bias", "scale"),
        check=map_check(),
        part="baking the map",
        points=4,
        visibility="hidden",
    ),
    Case(
        id="hidden-map-uv-grid-repeat",
        function="denoise_with_map",
        inputs=map_inputs(lambda: datasets.uv_grid(12), 24, np.uint16, seed=8),
        params={"bias": 0.0, "scale": 0.02, "lam": 0.5, "weld": False, "wrap": "repeat"},
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="denoising through the map",
        points=11,
        visibility="hidden",
    ),
    Case(
        id="hidden-weld-split",
        function="weld_seams",
        inputs=lambda: {"V": SPLIT_V, "F": SPLIT_F},
        outputs=("Vw", "Fw", "group"),
        check=weld_check(),
        part="seam fix",
        points=7,
        visibility="hidden",
    ),
    Case(
        id="hidden-weld-uv-sphere-fine",
        function="weld_seams",
        inputs=uv_mesh(lambda: datasets.uv_sphere(20, 40)),
        outputs=("Vw", "Fw", "group"),
        check=weld_check(),
        part="seam fix",
        points=7,
        visibility="hidden",
    ),
]
