"""Public graded cases of the denoise lab: realistic inputs compared with stored references.

Each case calls one lab function on a deterministic input built from ``geomlib.datasets``;
``geomlib refs build --lab denoise`` stored the reference solution's output. Every task has its
own cases, and their inputs never need another task: the map route reads a seeded map made
here (not one you baked), and the seam-fix cases call only ``weld_seams`` and ``seam_mean``.
Per-vertex outputs are compared in vertex order (the order is the input's); a baked map is
compared texel by texel, allowing one quantisation level for rounding ties.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, portable
from geomlib.grading import Case, checks
from geomlib.grading import tolerances as tol

from .support import map_check, noisy, random_map, weld_check


def noisy_mesh(make, sigma_rel: float = 0.3, seed: int = 0, with_normals: bool = False):
    def inputs():
        V, F = make()[:2]
        Vn, N = noisy(V, F, sigma_rel, seed)
        return {"V": Vn, "F": F, "N": N} if with_normals else {"V": Vn, "F": F}

    return inputs


def offsets_on_uv(make, seed: int = 0):
    """A UV mesh and smooth per-vertex offsets (equal on seam copies), for baking."""

    def inputs():
        V, F, UV = make()
        x, y, z = V.T
        s = (
            0.03 * portable.sin(5 * x + 1) * portable.cos(4 * y)
            + 0.01 * z
            + 0.002 * np.round(portable.sin(37 * x + 53 * y + 71 * z + seed), 3)
        )
        return {"V": V, "F": F, "UV": UV, "s": s}

    return inputs


def map_inputs(make, size: int, dtype, seed: int = 0):
    def inputs():
        V, F, UV = make()
        Vn, N = noisy(V, F, 0.3, seed)
        return {"V": Vn, "F": F, "UV": UV, "N": N, "image": random_map(size, seed, dtype)}

    return inputs


def uv_mesh(make):
    return lambda: dict(zip(("V", "F"), make()[:2], strict=True))


def ico3():
    return datasets.icosphere(3)


def small_torus():
    return datasets.torus(n_major=24, n_minor=12)


def nut():
    return datasets.pyvista_mesh("nut")


def small_uv_torus():
    return datasets.uv_torus(24, 12)


def small_uv_sphere():
    return datasets.uv_sphere(8, 16)


def seam_mean_inputs():
    V, _, _ = datasets.uv_sphere(8, 16)
    # group labels: equal positions share a label (numbered by first appearance)
    _, first, inv = np.unique(V, axis=0, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))
    values = np.random.default_rng(5).normal(size=(len(V), 3))
    return {"values": values, "group": rank[inv.ravel()]}


def linear_offsets():
    """s = 1/4 + u/2 + v/4 on a uv grid: linear inside every triangle, so its baked map is linear too."""
    V, F, UV = datasets.uv_grid(8)
    return {"V": V, "F": F, "UV": UV, "s": 0.25 + 0.5 * UV[:, 0] + 0.25 * UV[:, 1], "size": 32, "bits": 16}


# What a test needs from an earlier task (here an offset map, Task 4's output) is stored by
# `geomlib refs build` from the solution and read back with `stored_input`, never computed here.
STORED = [
    Case(id="map-linear-32", function="bake_offset_map", inputs=linear_offsets, outputs=("image", "bias", "scale"),
         check=map_check(), part="stored input", points=0),
]  # fmt: skip

CASES = [
    # ---- Task 1: offsets
    Case(
        id="offsets-uniform-icosphere3",
        function="laplacian_offsets",
        inputs=noisy_mesh(ico3, seed=0),
        params={"weights": "uniform", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.EXACT),
        part="offsets",
        points=1,
        hint="delta_i = p_i minus the plain mean of the vertices joined to i by an edge (each neighbour once)",
    ),
    Case(
        id="offsets-uniform-height-field",
        function="laplacian_offsets",
        inputs=noisy_mesh(lambda: datasets.height_field(10, seed=2), seed=1),
        params={"weights": "uniform", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.EXACT),
        part="offsets",
        points=1,
        hint="an open mesh: a boundary edge belongs to one triangle only, but its end points are still neighbours",
    ),
    Case(
        id="offsets-cotan-torus",
        function="laplacian_offsets",
        inputs=noisy_mesh(small_torus, seed=2),
        params={"weights": "cotan", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.GEOMETRY),
        part="offsets",
        points=1,
        hint="delta_i = p_i - sum_j w_ij p_j / sum_j w_ij with w_ij = (cot alpha_ij + cot beta_ij) / 2",
    ),
    Case(
        id="offsets-cotan-nut",
        function="laplacian_offsets",
        inputs=noisy_mesh(nut, seed=3),
        params={"weights": "cotan", "weld": False},
        outputs=("delta",),
        check=checks.Allclose(atol=tol.GEOMETRY),
        part="offsets",
        points=1,
        hint="delta_i = p_i - sum_j w_ij p_j / sum_j w_ij with w_ij = (cot alpha_ij + cot beta_ij) / 2",
    ),
    # ---- Task 2: projection
    Case(
        id="normal-offsets-random",
        function="normal_offsets",
        inputs=lambda: {
            "delta": np.random.default_rng(1).normal(size=(300, 3)),
            "N": np.random.default_rng(2).normal(size=(300, 3)) * 3.0,
        },
        outputs=("s",),
        check=checks.Allclose(atol=tol.EXACT),
        part="projection on normals",
        points=1,
        hint="s_i = <delta_i, n_i>, one dot product per row (N arrives normalised)",
    ),
    # ---- Task 3: direct denoising
    Case(
        id="denoise-icosphere3-0.7",
        function="denoise_vertices",
        inputs=noisy_mesh(ico3, seed=4, with_normals=True),
        params={"lam": 0.7, "weld": False},
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="direct denoising",
        points=1,
        hint="p'_i = p_i - lam s_i n_i with s from normal_offsets(laplacian_offsets(...), N)",
    ),
    Case(
        id="denoise-torus-cotan-0.3x3",
        function="denoise_vertices",
        inputs=noisy_mesh(small_torus, seed=5, with_normals=True),
        params={"lam": 0.3, "weights": "cotan", "iterations": 3, "weld": False},
        outputs=("V",),
        check=checks.Allclose(atol=tol.GEOMETRY),
        part="direct denoising",
        points=1,
        hint="each iteration recomputes delta from the moved vertices and keeps the same normals N",
    ),
    # ---- Task 4: baking
    Case(
        id="bake-uv-torus-16bit",
        function="bake_offset_map",
        inputs=offsets_on_uv(small_uv_torus),
        params={"size": 64, "bits": 16},
        outputs=("image", "bias", "scale"),
        check=map_check(),
        part="baking the map",
        points=1,
        hint="value = barycentric interpolation of s; bias = min s, scale = max s - min s; q = round(h * 65535) as uint16",
    ),
    Case(
        id="bake-uv-sphere-8bit",
        function="bake_offset_map",
        inputs=offsets_on_uv(small_uv_sphere, seed=1),
        params={"size": 48, "bits": 8},
        outputs=("image", "bias", "scale"),
        check=map_check(),
        part="baking the map",
        points=1,
        hint="the pole triangles leave empty texels: pad with geomlib.textures.dilate(h, covered, padding) before quantising",
    ),
    # ---- Task 5: the map route
    Case(
        id="map-uv-torus-16bit",
        function="denoise_with_map",
        inputs=map_inputs(small_uv_torus, 64, np.uint16, seed=6),
        params={"bias": -0.02, "scale": 0.05, "lam": 0.7, "weld": False},
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="denoising through the map",
        points=1,
        hint="s = bias + scale h(uv) with h read by geomlib.textures.sample_bilinear; p' = p - lam s n",
    ),
    Case(
        id="map-uv-sphere-8bit",
        function="denoise_with_map",
        inputs=map_inputs(small_uv_sphere, 32, np.uint8, seed=7),
        params={"bias": -0.05, "scale": 0.1, "lam": 1.0, "weld": False},
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="denoising through the map",
        points=1,
        hint="s = bias + scale h(uv) with h read by geomlib.textures.sample_bilinear; p' = p - lam s n",
    ),
    # ---- Task 6: the seam fix
    Case(
        id="weld-uv-sphere",
        function="weld_seams",
        inputs=uv_mesh(small_uv_sphere),
        outputs=("Vw", "Fw", "group"),
        check=weld_check(),
        part="seam fix",
        points=1,
        hint="vertices with equal positions form one group (the seam copies and the split poles)",
    ),
    Case(
        id="weld-uv-torus",
        function="weld_seams",
        inputs=uv_mesh(small_uv_torus),
        outputs=("Vw", "Fw", "group"),
        check=weld_check(),
        part="seam fix",
        points=1,
        hint="vertices with equal positions form one group (the torus is cut along two seams; one vertex has 4 copies)",
    ),
    Case(
        id="seam-mean-uv-sphere",
        function="seam_mean",
        inputs=seam_mean_inputs,
        outputs=("mean",),
        check=checks.Allclose(atol=tol.EXACT),
        part="seam fix",
        points=1,
        hint="out[g] = mean of values[i] over the vertices i with group[i] = g",
    ),
]
