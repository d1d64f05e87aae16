"""Graded cases of the lab "maps": inputs built from geomlib only (never from the solution).

Tolerances: geometry and tangent frames to 1e-10 (pure arithmetic); encoded normal maps to one
8-bit code (ties between two codes may round either way); shading to 1e-4 (the reference shades in
single precision, as a GPU does); baked normals to 1e-5 (ray hits are recomputed in double
precision, so only round-off in the frames differs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib import camera, datasets, portable
from geomlib.grading import Case, checks
from geomlib.grading.checks import Context, as_output_array, format_vec
from geomlib.raster import rasterize
from geomlib.textures import triangle_atlas

# ---------------------------------------------------------------------------------- checks


@dataclass
class MapClose:
    """Maps and images ``(h, w, c)`` equal within ``atol`` per texel; the message names the first bad texel.

    ``display`` says how to show the arrays in the feedback picture: ``"image"`` (values in [0, 1]),
    ``"normals"`` (unit vectors, shown as (n + 1) / 2) or ``"codes"`` (uint8).
    """

    output: str
    atol: float
    display: str = "image"

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output])
        g = as_output_array(got.get(self.output), self.output, ctx, like=e)
        per = np.abs(g.astype(np.float64) - e.astype(np.float64)).max(axis=-1)
        bad = per > self.atol
        if not bad.any():
            return
        r, c = (int(i) for i in np.argwhere(bad)[0])
        ctx.fail(
            f"{self.output}[{r}, {c}] expected {format_vec(e[r, c])}, got {format_vec(g[r, c])}; "
            f"{int(bad.sum())} of {bad.size} texels differ by more than {self.atol:g}",
            self._picture(e, g, per, ctx),
        )

    def _picture(self, e, g, per, ctx):
        from geomlib.grading import feedback

        def show(x):
            x = x.astype(np.float64)
            x = (x + 1) / 2 if self.display == "normals" else x / 255 if self.display == "codes" else x
            k = max(1, 160 // min(x.shape[:2]))  # enlarge small maps, texels stay sharp
            return np.repeat(np.repeat(x, k, axis=0), k, axis=1)

        k = max(1, 160 // min(per.shape))
        return feedback.image_picture(ctx, show(e), show(g), np.repeat(np.repeat(per, k, axis=0), k, axis=1))


# ---------------------------------------------------------------------------------- inputs


def texel_uv(s: int) -> tuple[np.ndarray, np.ndarray]:
    """U, V (s, s) of the texel centres; row 0 is v = 1 - 0.5 / s."""
    r, c = np.mgrid[0:s, 0:s]
    return (c + 0.5) / s, 1.0 - (r + 0.5) / s


def wave(s: int) -> np.ndarray:
    """h(u, v) = 1/2 + 1/2 sin(2 pi u) cos(2 pi v) at the texel centres (tileable, in [0, 1])."""
    u, v = texel_uv(s)
    return 0.5 + 0.5 * portable.sin(2 * np.pi * u) * portable.cos(2 * np.pi * v)


def random_map(s: int, seed: int, channels: int | None = None) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.random((s, s) if channels is None else (s, s, channels))


def unit_vectors(shape, seed: int) -> np.ndarray:
    g = np.random.default_rng(seed).normal(size=(*shape, 3))
    return g / np.linalg.norm(g, axis=-1, keepdims=True)


def affine_grid(n: int = 4):
    V, F = datasets.grid_patch(n)
    A = np.array([[0.7, 0.4], [-0.3, 0.9]])  # det > 0: not mirrored
    return {"V": V, "F": F, "UV": portable.matmul(V[:, :2], A.T) + [0.1, 0.05]}


def mirrored_torus():
    V, F, UV = datasets.uv_torus(16, 8)
    UV = UV.copy()
    UV[:, 0] = 1.0 - UV[:, 0]
    return {"V": V, "F": F, "UV": UV}


def degenerate_uvs():
    V, F = datasets.icosphere(1)
    V = V * np.array([1.0, 0.8, 0.6])  # an ellipsoid: on the unit sphere the normals are the positions
    UV = np.random.default_rng(7).random((len(V), 2))
    UV[F[:4].ravel()] = 0.5  # the first four triangles (and parts of their neighbours) have zero UV area
    return {"V": V, "F": F, "UV": UV}


def top_camera(size: int):
    """Orthographic camera above the unit square, looking down -z."""
    eye = np.array([0.5, 0.5, 4.0])
    M = portable.matmul(camera.orthographic(-0.5, 0.5, -0.5, 0.5, 0.5, 8.0), camera.look_at(eye, (0.5, 0.5, 0.0)))
    return eye, M


def quad_gbuffer(size: int = 32):
    """The unit square z = 0 seen from above: tangent (1, 0, 0), w = +1, normal (0, 0, 1), UV = (x, y)."""
    V, F, UV = datasets.uv_grid(1)
    eye, M = top_camera(size)
    attrs = {
        "position": V,
        "normal": np.tile([0.0, 0, 1], (4, 1)),
        "uv": UV,
        "tangent": np.tile([1.0, 0, 0, 1], (4, 1)),
    }
    return rasterize(V, F, M, size, size, attributes=attrs), eye


def torus_gbuffer(size: int = 48):
    """A uv_torus seen at an angle, with its analytic frames.

    u = theta / 2 pi (around the z axis), v = phi / 2 pi: T = dP/dtheta / |.| = (-sin theta, cos theta, 0),
    N = (cos phi cos theta, cos phi sin theta, sin phi), and N x T = dP/dphi / |.|, so w = +1.
    """
    n_major, n_minor = 32, 16
    V, F, UV = datasets.uv_torus(n_major, n_minor)
    th, ph = 2 * np.pi * UV[:, 0], 2 * np.pi * UV[:, 1]
    N = np.stack([portable.cos(ph) * portable.cos(th), portable.cos(ph) * portable.sin(th), portable.sin(ph)], axis=1)
    T = np.stack([-portable.sin(th), portable.cos(th), np.zeros_like(th), np.ones_like(th)], axis=1)
    eye = np.array([0.4, -2.4, 1.8])
    M = camera.perspective_look_at(eye, (0, 0, 0), (0, 0, 1), 40, 1.0, 0.5, 8.0)
    g = rasterize(V, F, M, size, size, attributes={"position": V, "normal": N, "uv": UV, "tangent": T}, cull="back")
    return g, eye


LIGHT = [{"direction": (-0.5, -0.3, -1.0)}]
TWO_LIGHTS = [
    {"direction": (-0.5, 0.4, -1.0), "intensity": 0.9},
    {"type": "point", "position": (2.0, -2.0, 2.0), "color": (0.9, 0.8, 1.0), "intensity": 0.5},
]


def shade_inputs(kind: str):
    def make():
        if kind == "quad-plain":
            g, eye = quad_gbuffer()
            return {"gbuffer": g, "lights": LIGHT, "eye": eye, "albedo": (0.8, 0.6, 0.4)}
        if kind == "quad-float-map":
            g, eye = quad_gbuffer()
            u, v = texel_uv(16)
            n = np.stack(
                [-0.3 * portable.cos(2 * np.pi * u), 0.2 * portable.sin(2 * np.pi * v), np.ones_like(u)], axis=-1
            )
            return {"gbuffer": g, "lights": LIGHT, "eye": eye, "albedo": (0.7, 0.7, 0.7), "normal_map": n}
        if kind == "quad-uint8-map":
            g, eye = quad_gbuffer()
            rng = np.random.default_rng(3)
            rgb = np.stack(
                [rng.integers(60, 196, (16, 16)), rng.integers(60, 196, (16, 16)), rng.integers(200, 256, (16, 16))],
                axis=-1,
            )
            return {
                "gbuffer": g,
                "lights": LIGHT,
                "eye": eye,
                "albedo": (0.7, 0.7, 0.7),
                "normal_map": rgb.astype(np.uint8),
            }
        if kind == "torus-two-lights":
            g, eye = torus_gbuffer()
            u, v = texel_uv(32)
            n = np.stack(
                [0.4 * portable.sin(8 * np.pi * u), 0.4 * portable.cos(4 * np.pi * v), np.ones_like(u)], axis=-1
            )
            return {"gbuffer": g, "lights": TWO_LIGHTS, "eye": eye, "albedo": (0.8, 0.7, 0.6), "normal_map": n}
        if kind == "torus-texture":
            g, eye = torus_gbuffer()
            albedo = (random_map(8, 11, 3) * 255).astype(np.uint8)
            return {"gbuffer": g, "lights": TWO_LIGHTS, "eye": eye, "albedo": albedo}
        raise ValueError(kind)

    return make


def displace_inputs(mesh: str, s: int = 32):
    def make():
        if mesh == "grid":
            V, F, UV = datasets.uv_grid(12)
            return {"V": V, "F": F, "UV": UV, "N": np.tile([0.0, 0, 1], (len(V), 1)), "height": wave(s)}
        V, F, UV = datasets.uv_sphere(10, 20)
        return {"V": V, "F": F, "UV": UV, "N": None, "height": random_map(s, 5)}

    return make


def bake_flat_inputs():
    """High: the height field z = 0.05 h(x, y) (h = wave); low: the flat unit square with tangent (1, 0, 0), w = +1."""
    Vh, Fh = datasets.height_field(
        48, fn=lambda x, y: 0.05 * (0.5 + 0.5 * portable.sin(2 * np.pi * x) * portable.cos(2 * np.pi * y))
    )
    Vl, Fl, UVl = datasets.uv_grid(2)
    return {
        "V_hi": Vh,
        "F_hi": Fh,
        "V_lo": Vl,
        "F_lo": Fl,
        "UV_lo": UVl,
        "tangents": np.tile([1.0, 0, 0, 1], (len(Vl), 1)),
    }


def bake_sphere_inputs():
    """High: icosphere level 4; low: icosphere level 1 as a triangle atlas with faceted (face) normals.

    Frames by hand: triangle_atlas (mode "uniform") lays every triangle out by a similarity with its
    longest edge (corner i -> i + 1) along +u and the triangle above it (+v, counter-clockwise), so
    T = unit(longest edge), w = +1, and T is already orthogonal to the face normal.
    """
    Vh, Fh = datasets.icosphere(4)
    Vl, Fl = datasets.icosphere(1)
    Vs, Fs, UV, _ = triangle_atlas(Vl, Fl, gutter=0.05)
    P = Vl[Fl]
    E = np.roll(P, -1, axis=1) - P  # edge i: corner i -> i + 1
    longest = np.take_along_axis(E, np.argmax(np.linalg.norm(E, axis=2), axis=1)[:, None, None], axis=1)[:, 0]
    T = np.repeat(longest / np.linalg.norm(longest, axis=1, keepdims=True), 3, axis=0)
    C = np.cross(Vl[Fl[:, 1]] - Vl[Fl[:, 0]], Vl[Fl[:, 2]] - Vl[Fl[:, 0]])
    N = np.repeat(C / np.linalg.norm(C, axis=1, keepdims=True), 3, axis=0)
    tangents = np.column_stack([T, np.ones(len(T))])
    return {"V_hi": Vh, "F_hi": Fh, "V_lo": Vs, "F_lo": Fs, "UV_lo": UV, "N_lo": N, "tangents": tangents}


TANGENTS = ("T", "B", "N", "w")
FRAME_HINT = "dP/du = (dv2 E1 - dv1 E2) / det per face, area-weighted sums per vertex, then T = normalize(T - (N.T) N), w = sign((N x T) . B_sum), B = w N x T"

CASES = [
    # ----------------------------------------------------------------------- tangent frames
    Case(
        id="tangents-affine-grid",
        function="tangent_frames",
        inputs=affine_grid,
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=2,
        hint=FRAME_HINT,
        trivial_outputs={"w": "no mirrored UVs on this mesh: w = +1 everywhere (tangents-mirrored-torus has w = -1)"},
    ),
    Case(
        id="tangents-uv-sphere",
        function="tangent_frames",
        inputs=lambda: dict(zip(("V", "F", "UV"), datasets.uv_sphere(8, 16), strict=True)),
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=2,
        hint="weight each face's unit tangent by its area; the pole copies have their own UVs",
        trivial_outputs={"w": "no mirrored UVs on this mesh: w = +1 everywhere (tangents-mirrored-torus has w = -1)"},
    ),
    Case(
        id="tangents-mirrored-torus",
        function="tangent_frames",
        inputs=mirrored_torus,
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=1,
        hint="mirrored UVs (det < 0) must give w = -1; dividing by a negative det flips dP/du",
        trivial_outputs={
            "w": "the whole UV layout is mirrored: w = -1 everywhere (the other tangent cases have w = +1)"
        },
    ),
    Case(
        id="tangents-degenerate-uvs",
        function="tangent_frames",
        inputs=degenerate_uvs,
        outputs=TANGENTS,
        check=checks.Allclose(atol=1e-10),
        part="tangent frames",
        points=1,
        hint="skip triangles with |det| ~ 0 (zero UV area); a vertex with no usable face gets a fallback tangent, never NaN",
    ),
    # ----------------------------------------------------------------------- encode / decode
    Case(
        id="encode-random",
        function="encode_normal_map",
        inputs=lambda: {"n": unit_vectors((16, 16), 1)},
        outputs=("img",),
        check=MapClose("img", atol=1.0, display="codes"),
        part="encode/decode",
        points=1,
        hint="code = 255 (n + 1) / 2 rounded, as uint8 (one code of slack is allowed here)",
    ),
    Case(
        id="decode-random",
        function="decode_normal_map",
        inputs=lambda: {"img": np.random.default_rng(2).integers(0, 256, (16, 16, 3)).astype(np.uint8)},
        outputs=("n",),
        check=MapClose("n", atol=1e-12, display="normals"),
        part="encode/decode",
        points=1,
        hint="n = normalize(2 rgb / 255 - 1), in float64",
    ),
    # ----------------------------------------------------------------------- height -> normals
    Case(
        id="height-wave-wrap",
        function="height_to_normal_map",
        inputs=lambda: {"H": wave(32)},
        params={"strength": 0.1, "border": "wrap"},
        outputs=("n",),
        check=MapClose("n", atol=1e-12, display="normals"),
        part="height to normals",
        points=2,
        hint="dH/du = (H[r, c+1] - H[r, c-1]) s / 2 and dH/dv = (H[r-1, c] - H[r+1, c]) s / 2 (v grows upwards = towards row 0)",
    ),
    Case(
        id="height-random-clamp",
        function="height_to_normal_map",
        inputs=lambda: {"H": random_map(24, 3)},
        params={"strength": 0.05, "border": "clamp"},
        outputs=("n",),
        check=MapClose("n", atol=1e-12, display="normals"),
        part="height to normals",
        points=1,
        hint="clamp: a neighbour beyond the border is the border texel itself (np.pad mode 'edge')",
    ),
    Case(
        id="height-uint8-anisotropic",
        function="height_to_normal_map",
        inputs=lambda: {"H": (random_map(16, 4) * 255).astype(np.uint8)},
        params={"strength": [0.02, 0.06], "border": "wrap"},
        outputs=("n",),
        check=MapClose("n", atol=1e-12, display="normals"),
        part="height to normals",
        points=1,
        hint="strength (k_u, k_v) scales dH/du and dH/dv separately",
    ),
    # ----------------------------------------------------------------------- shading
    Case(
        id="shade-quad-plain",
        function="shade",
        inputs=shade_inputs("quad-plain"),
        outputs=("image",),
        check=MapClose("image", atol=1e-4),
        part="shading",
        points=1,
        hint="colour = ambient * albedo + sum over lights of L (albedo max(n.l, 0) + specular max(n.h, 0)^shininess when n.l > 0); l = -direction",
    ),
    Case(
        id="shade-quad-float-map",
        function="shade",
        inputs=shade_inputs("quad-float-map"),
        outputs=("image",),
        check=MapClose("image", atol=1e-4),
        part="shading",
        points=2,
        hint="sample the map at the pixel's uv (sample_bilinear), then n = normalize(m_x T' + m_y B' + m_z N') with surface_frames",
    ),
    Case(
        id="shade-quad-uint8-map",
        function="shade",
        inputs=shade_inputs("quad-uint8-map"),
        outputs=("image",),
        check=MapClose("image", atol=1e-4),
        part="shading",
        points=1,
        hint="a uint8 map holds codes: as_normal_map turns them into 2 rgb / 255 - 1 before sampling",
    ),
    Case(
        id="shade-torus-two-lights",
        function="shade",
        inputs=shade_inputs("torus-two-lights"),
        outputs=("image",),
        check=MapClose("image", atol=1e-4),
        part="shading",
        points=2,
        hint="point lights: l = normalize(position - P); every light adds its own diffuse and specular terms",
    ),
    # ----------------------------------------------------------------------- displacement
    Case(
        id="displace-grid-wave",
        function="displace",
        inputs=displace_inputs("grid"),
        params={"lam": 0.2, "bias": 0.0, "scale": 1.0},
        outputs=("V",),
        check=checks.Allclose(atol=1e-10),
        part="displacement",
        points=1,
        hint="P' = P + lam (bias + scale h) n with h read by sample_bilinear at the vertex UV",
    ),
    Case(
        id="displace-sphere-bias-1-scale-2",
        function="displace",
        inputs=displace_inputs("sphere"),
        params={"lam": 0.1, "bias": -1.0, "scale": 2.0},
        outputs=("V",),
        check=checks.Allclose(atol=1e-10),
        part="displacement",
        points=2,
        hint="seam copies (same weld group) must move together: average their offsets and their normals",
    ),
    Case(
        id="displace-sphere-unwelded",
        function="displace",
        inputs=displace_inputs("sphere"),
        params={"lam": 0.1, "bias": -1.0, "scale": 5.0, "weld_seams": False},
        outputs=("V",),
        check=checks.Allclose(atol=1e-10),
        part="displacement",
        points=1,
        hint="with weld_seams=False every vertex uses its own h and its own normal",
    ),
    # ----------------------------------------------------------------------- baking
    Case(
        id="bake-height-field-on-quad",
        function="bake_normal_map",
        inputs=bake_flat_inputs,
        params={"size": 32},
        outputs=("normal_map",),
        check=MapClose("normal_map", atol=1e-5, display="normals"),
        part="baking",
        points=2,
        hint="per texel: P and the frame from the low mesh, project_to_surface along +-N', the high mesh's interpolated normal n, m = normalize(n.T', n.B', n.N')",
    ),
    Case(
        id="bake-sphere-atlas",
        function="bake_normal_map",
        inputs=bake_sphere_inputs,
        params={"size": 48},
        outputs=("normal_map",),
        check=MapClose("normal_map", atol=1e-5, display="normals"),
        part="baking",
        points=2,
        hint="the frame at a texel comes from the interpolated N_lo and [T, w] (surface_frames), as in shade",
    ),
    Case(
        id="bake-height-field-own-frames",
        function="bake_normal_map",
        inputs=lambda: {k: v for k, v in bake_flat_inputs().items() if k != "tangents"},
        params={"size": 32},
        outputs=("normal_map",),
        check=MapClose("normal_map", atol=1e-5, display="normals"),
        part="baking",
        points=1,
        hint="without given tangents the frames come from tangent_frames of the low mesh (Task 1)",
    ),
]
