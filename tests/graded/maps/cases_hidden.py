"""Hidden graded cases of the lab "maps" (not shipped to students)."""

from __future__ import annotations

import numpy as np

from geomlib import datasets, portable
from geomlib.grading import Case, checks

from .cases import TANGENTS, MapClose, displace_inputs, shade_inputs, texel_uv, unit_vectors

# Axis directions and diagonals (not normalised: encode_normal_map normalises first).
AXES = np.array(
    [[[1, 0, 0], [0, -1, 0], [0, 0, 1], [1, 1, 1]], [[-1, -1, 0], [0, 1, 1], [1, 0, -1], [0.2, -0.3, 0.9]]], dtype=float
)


def rock_atlas():
    from geomlib.textures import triangle_atlas

    V, F = datasets.rock_on_plinth(16, seed=1)
    Vs, Fs, UV, _ = triangle_atlas(V, F, mode="fill")
    return {"V": Vs, "F": Fs, "UV": UV}


def torus_finer_bake():
    """A coarse torus baked onto a finer one of the same radii, with its analytic tangents
    T = (-sin theta, cos theta, 0), w = +1. The finer facets tilt the normals by a few degrees: a
    torus baked onto itself gives the flat map (0, 0, 1), which a bake that does nothing also gives."""
    V, F, UV = datasets.uv_torus(20, 10)
    V_hi, F_hi = datasets.torus(1.0, 0.35, 33, 17)
    th = 2 * np.pi * UV[:, 0]
    tangents = np.stack([-portable.sin(th), portable.cos(th), np.zeros_like(th), np.ones_like(th)], axis=1)
    return {"V_hi": V_hi, "F_hi": F_hi, "V_lo": V, "F_lo": F, "UV_lo": UV, "tangents": tangents}


CASES = [
    Case(
        id="tangents-rock-atlas",
        function="tangent_frames",
        inputs=rock_atlas,
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=7,
        visibility="hidden",
        trivial_outputs={"w": "no mirrored UVs on this mesh: w = +1 everywhere (tangents-mirrored-torus has w = -1)"},
    ),
    Case(
        id="tangents-torus-given-normals",
        function="tangent_frames",
        inputs=lambda: {
            **dict(zip(("V", "F", "UV"), datasets.uv_torus(12, 6), strict=True)),
            "N": np.tile([0.0, 0.0, 1.0], ((12 + 1) * (6 + 1), 1)) + 0.1,
        },
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=7,
        visibility="hidden",
    ),
    Case(
        id="encode-axes-and-diagonals",
        function="encode_normal_map",
        inputs=lambda: {"n": np.concatenate([unit_vectors((2, 4), 9), AXES], axis=0)},
        outputs=("img",),
        check=MapClose("img", atol=1.0, display="codes"),
        part="encode/decode",
        points=9,
        visibility="hidden",
    ),
    Case(
        id="height-wave-clamp-strong",
        function="height_to_normal_map",
        inputs=lambda: {
            "H": 0.5 + 0.5 * portable.sin(2 * np.pi * texel_uv(20)[0]) * portable.cos(4 * np.pi * texel_uv(20)[1])
        },
        params={"strength": 0.5, "border": "clamp"},
        outputs=("n",),
        check=MapClose("n", atol=1e-12, display="normals"),
        part="height to normals",
        points=11,
        visibility="hidden",
    ),
    Case(
        id="shade-torus-texture",
        function="shade",
        inputs=shade_inputs("torus-texture"),
        outputs=("image",),
        check=MapClose("image", atol=1e-4),
        part="shading",
        points=15,
        visibility="hidden",
    ),
    Case(
        id="displace-sphere-bias0-scale1-repeat",
        function="displace",
        inputs=displace_inputs("sphere", s=16),
        params={"lam": 0.3, "bias": 0.0, "scale": 1.0, "wrap": "repeat"},
        outputs=("V",),
        check=checks.Allclose(atol=1e-10),
        part="displacement",
        points=9,
        visibility="hidden",
    ),
    Case(
        id="bake-torus-onto-a-finer-torus",
        function="bake_normal_map",
        inputs=torus_finer_bake,
        params={"size": 32, "padding": 2},
        outputs=("normal_map",),
        check=MapClose("normal_map", atol=1e-5, display="normals"),
        part="baking",
        points=9,
        visibility="hidden",
    ),
]
