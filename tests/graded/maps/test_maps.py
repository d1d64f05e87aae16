"""Graded tests of the lab "maps": stored references plus hand-checkable cases, identities and bad input.

Expected values here are worked out by hand (comments) or are closed forms; none comes from the
solution.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.grading import expect_close, graded, reference_tests
from geomlib.grading.cases import hidden_cases
from geomlib.grading.checks import format_vec
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture, marked_picture

from ..common import expect_rejected
from .cases import CASES, LIGHT, quad_gbuffer, texel_uv, unit_vectors, wave

test_references = reference_tests(CASES)


def unit(x):
    x = np.asarray(x, float)
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def wave_normals(s: int, k: float) -> np.ndarray:
    """The exact unit normals of the height field ``k * wave(s)``: normalize(-k dh/du, -k dh/dv, 1)."""
    u, v = texel_uv(s)
    hu = np.pi * np.cos(2 * np.pi * u) * np.cos(2 * np.pi * v)
    hv = -np.pi * np.sin(2 * np.pi * u) * np.sin(2 * np.pi * v)
    return unit(np.stack([-k * hu, -k * hv, np.ones_like(u)], axis=-1))


def expect_frames(lab, mesh: tuple, where: str, hints: dict, **expected) -> None:
    """``tangent_frames(V, F, UV)`` of ``mesh``: each of ``T``, ``B``, ``N``, ``w`` given in ``expected`` equals
    its one value at every vertex (exactly for the sign ``w``, within 1e-12 for the vectors)."""
    V, F, UV = mesh
    T, B, N, w = lab.tangent_frames(V, F, UV)
    frames = {"T": T, "B": B, "N": N, "w": w}
    for name, value in expected.items():
        every_vertex = np.tile(value, (len(V), 1)) if np.ndim(value) else np.full(len(V), value)
        atol = 0 if name == "w" else 1e-12
        label = f"tangent_frames {name} {where}"
        expect_close(label, frames[name], every_vertex, atol=atol, hint=hints.get(name), mesh=(V, F))


def expect(condition: bool, message: str) -> None:
    if not condition:
        raise Mismatch(message)


def expect_map_close(label: str, got, expected, atol: float, hint: str | None = None) -> None:
    """Per-texel comparison of (h, w, c) maps; the message names the first texel that differs."""
    e = np.asarray(expected, float)
    g = np.asarray(got, float)
    if g.shape != e.shape:
        raise Mismatch(f"{label}: result has shape {g.shape}, expected {e.shape}")
    per = np.abs(g - e).max(axis=-1)
    bad = ~(per <= atol)  # NaN counts as bad
    if bad.any():
        r, c = (int(i) for i in np.argwhere(bad)[0])
        raise Mismatch(
            f"{label}: [{r}, {c}] expected {format_vec(e[r, c])}, got {format_vec(g[r, c])}; {int(bad.sum())} of "
            f"{bad.size} texels differ by more than {atol:g}" + (f" — {hint}" if hint else ""),
            failure_picture(label, g, e, name="map", atol=atol),
        )


# ------------------------------------------------------------------------------ tangent frames


@graded(points=1, part="tangent frames")
def test_one_triangle_by_hand(lab):
    """one triangle: T along +u, B along +v, w = +1"""
    # P1 - P0 = (2, 0, 0) with du = 1, P2 - P0 = (0, 1, 0) with dv = 1: dP/du = (2, 0, 0), dP/dv = (0, 1, 0).
    V = np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0.0]])
    F = [[0, 1, 2]]
    hints = {"w": "w = sign((N x T) . B_sum)"}
    T, B, N = [1.0, 0, 0], [0.0, 1, 0], [0.0, 0, 1]
    expect_frames(lab, (V, F, [[0, 0], [1, 0], [0, 1]]), "on one triangle", hints, T=T, B=B, N=N, w=1)


@graded(points=1, part="tangent frames")
def test_mirrored_uvs_flip_w(lab):
    """mirrored UVs (u -> 1 - u) give w = -1 and T = -x, while B still points along +v"""
    V, F, UV = datasets.uv_grid(3)
    UVm = UV.copy()
    UVm[:, 0] = 1.0 - UVm[:, 0]
    hints = {"w": "the UV triangles run clockwise: det < 0", "B": "B = w (N x T)"}
    expect_frames(lab, (V, F, UVm), "with mirrored UVs", hints, w=-1, T=[-1.0, 0, 0], B=[0.0, 1, 0])


@graded(points=1, part="tangent frames")
def test_frames_are_orthonormal_without_nan(lab):
    """random and partly degenerate UVs: unit T, B, N, T . N = 0, B = w N x T, T along the faces' dP/du, no NaN"""
    V, F = datasets.icosphere(2)
    UV = np.random.default_rng(0).random((len(V), 2))
    UV[F[:6].ravel()] = 0.3
    T, B, N, w = (np.asarray(a, float) for a in lab.tangent_frames(V, F, UV))
    expect(
        np.isfinite(T).all() and np.isfinite(B).all() and np.isfinite(N).all(),
        "tangent_frames returned NaN or inf (degenerate UV triangles must be skipped)",
    )
    for name, X in (("T", T), ("B", B), ("N", N)):
        expect_close(f"tangent_frames |{name}|", np.linalg.norm(X, axis=1), np.ones(len(V)), atol=1e-9, mesh=(V, F))
    expect_close(
        "tangent_frames T . N",
        np.sum(T * N, axis=1),
        np.zeros(len(V)),
        atol=1e-9,
        hint="Gram-Schmidt: T - (N . T) N",
        mesh=(V, F),
    )
    expect_close(
        "tangent_frames B - w N x T", B - w[:, None] * np.cross(N, T), np.zeros_like(B), atol=1e-9, mesh=(V, F)
    )
    # Orthonormal is not enough (any frame built from N passes the checks above): T points where u grows.
    # The handout's sum T_sum = sum over usable faces of area * unit(dP/du) (unit(dP/du) sign-adjusted by
    # det, as dividing by det does), and T = normalize(T_sum - (N . T_sum) N), so T . T_sum = |T_sum - (N .
    # T_sum) N| > 0 wherever a usable face gives a tangential T_sum.
    E1, E2 = V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    d1, d2 = UV[F[:, 1]] - UV[F[:, 0]], UV[F[:, 2]] - UV[F[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    dPdu = d2[:, 1:2] * E1 - d1[:, 1:2] * E2
    area = 0.5 * np.linalg.norm(np.cross(E1, E2), axis=1)
    usable = np.abs(det) > 1e-6
    face_t = np.zeros_like(dPdu)
    face_t[usable] = unit(dPdu[usable]) * (area * np.sign(det))[usable, None]
    T_sum = np.zeros_like(V)
    for k in range(3):
        np.add.at(T_sum, F[:, k], face_t)
    tangential = np.linalg.norm(T_sum - np.sum(N * T_sum, axis=1)[:, None] * N, axis=1)
    has_u = tangential > 1e-3 * np.linalg.norm(T_sum, axis=1) + 1e-12
    along = np.sum(T * T_sum, axis=1)
    bad = np.flatnonzero(has_u & ~(along > 0.5 * tangential))
    expect(
        bad.size == 0,
        f"tangent_frames: at vertex {bad[0] if bad.size else -1} T does not point where u grows "
        f"(T . T_sum = {along[bad[0]] if bad.size else 0:.3g}, where T_sum is the area-weighted sum of the unit "
        f"dP/du of its faces); {bad.size} of {int(has_u.sum())} vertices with a usable face",
    )


# ------------------------------------------------------------------------------ encode / decode


@graded(points=1, part="encode/decode")
def test_codes_by_hand(lab):
    """(0, 0, 1) -> (128, 128, 255), (1, 0, 0) -> (255, 128, 128), (-1, 0, 0) -> (0, 128, 128)"""
    # 255 (x + 1) / 2: -1 -> 0, 0 -> 127.5 -> 128, +1 -> 255.
    n = np.array([[[0, 0, 1.0], [1, 0, 0]], [[-1, 0, 0], [0, -1, 0]]])
    img = np.asarray(lab.encode_normal_map(n))
    expect(img.dtype == np.uint8, f"encode_normal_map should return uint8, got {img.dtype}")
    expect_map_close(
        "encode_normal_map on axis directions",
        img,
        [[[128, 128, 255], [255, 128, 128]], [[0, 128, 128], [128, 0, 128]]],
        atol=0,
    )


@graded(points=1, part="encode/decode")
def test_decode_by_hand(lab):
    """decode (255, 128, 128) = normalize(1, 1/255, 1/255)"""
    got = lab.decode_normal_map(np.array([[[255, 128, 128]]], np.uint8))
    expect_close(
        "decode_normal_map((255, 128, 128))",
        got,
        unit([[[1.0, 1 / 255, 1 / 255]]]),
        atol=1e-12,
        hint="n = normalize(2 rgb / 255 - 1)",
    )


@graded(points=2, part="encode/decode")
def test_round_trip_within_one_code(lab):
    """decode(encode(n)) is within 1/255 of n in every component (random directions)"""
    n = unit_vectors((96, 96), 4)
    back = np.asarray(lab.decode_normal_map(lab.encode_normal_map(n)), float)
    err = np.abs(back - n).max()
    if not err <= 1.0 / 255.0:
        raise Mismatch(
            f"decode(encode(n)) is off by up to {err * 255:.3f}/255 in a component, allowed 1/255 — plain rounding gets "
            f"about 1.3/255 after renormalising: try the 8 floor/ceil codes around 255 (n + 1) / 2 and keep the one "
            f"that decodes closest to n",
            failure_picture("decode(encode(n)) vs n", back, n, name="normals", atol=1.0 / 255.0),
        )


# ------------------------------------------------------------------------------ height -> normals


@graded(points=1, part="height to normals")
def test_ramp_by_hand(lab):
    """H = u (rising to the right), strength 0.5: n = normalize(-0.5, 0, 1) inside"""
    u, v = texel_uv(8)
    n = np.asarray(lab.height_to_normal_map(u, 0.5), float)
    # dH/du = 1 exactly for a ramp: n = (-0.5, 0, 1) / sqrt(1.25).
    expect_close("height_to_normal_map(H = u)[3, 3]", n[3, 3], unit([-0.5, 0.0, 1.0]), atol=1e-12)


@graded(points=1, part="height to normals")
def test_v_points_up(lab):
    """H = v (higher towards row 0, the top of the image): the normal leans to -y"""
    u, v = texel_uv(8)
    n = np.asarray(lab.height_to_normal_map(v, 0.5), float)
    expect_close(
        "height_to_normal_map(H = v)[3, 3]",
        n[3, 3],
        unit([0.0, -0.5, 1.0]),
        atol=1e-12,
        hint="v grows upwards: dH/dv = (H[r - 1, c] - H[r + 1, c]) s / 2",
    )


@graded(points=1, part="height to normals")
def test_matches_the_analytic_gradient(lab):
    """a smooth wave h(u, v): normals within 1e-3 of the exact ones (central differences are second order)"""
    s, k = 64, 0.1
    exact = wave_normals(s, k)
    expect_map_close(
        "height_to_normal_map(wave) vs exact normals",
        lab.height_to_normal_map(wave(s), k, "wrap"),
        exact,
        atol=1e-3,
        hint="n = normalize(-k dH/du, -k dH/dv, 1); check the signs and that v grows towards row 0",
    )


# ------------------------------------------------------------------------------ shading


@graded(points=1, part="shading")
def test_lambert_by_hand(lab):
    """light at 60 degrees, no ambient, no specular: colour = albedo * cos 60 = albedo / 2, also with zero normals"""
    g, eye = quad_gbuffer(8)
    d = (np.sin(np.pi / 3), 0.0, -np.cos(np.pi / 3))
    img = np.asarray(lab.shade(g, [{"direction": d}], eye, (0.8, 0.6, 0.4), ambient=0.0, specular=0.0), float)
    expect_close(
        "shade: Lambert term",
        img[g.mask],
        np.tile([0.4, 0.3, 0.2], (int(g.mask.sum()), 1)),
        atol=1e-5,
        hint="diffuse = albedo max(n . l, 0) with l = -direction",
    )
    expect_close("shade: background pixels", img[~g.mask], np.ones((int((~g.mask).sum()), 3)), atol=0)
    # A zero interpolated normal is shaded with n = (0, 0, 1) (the docstring): a light at 60 degrees from the
    # vertical, towards (1, 1, 0), gives albedo / 2 again (a fallback tilted towards x or y gives another colour).
    g.attributes["normal"] = np.zeros_like(np.asarray(g.attributes["normal"]))
    d = (np.sin(np.pi / 3) / np.sqrt(2), np.sin(np.pi / 3) / np.sqrt(2), -np.cos(np.pi / 3))
    img = np.asarray(lab.shade(g, [{"direction": d}], eye, (0.8, 0.6, 0.4), ambient=0.0, specular=0.0), float)
    expect_close(
        "shade with zero normals in the G-buffer",
        img[g.mask],
        np.tile([0.4, 0.3, 0.2], (int(g.mask.sum()), 1)),
        atol=1e-5,
        hint="a zero-length normal falls back to (0, 0, 1)",
    )


@graded(points=1, part="shading")
def test_flat_normal_map_changes_nothing(lab):
    """a normal map full of (0, 0, 1) gives the same image as no normal map (a lit quad with a highlight)"""
    g, eye = quad_gbuffer(16)
    plain = lab.shade(g, LIGHT, eye, (0.7, 0.7, 0.7))
    img = np.asarray(plain, float)
    if not (img.size and np.isfinite(img).all() and img.max() > 0.1 and np.ptp(img) > 0.01):
        raise Mismatch(
            "shade without a normal map: the quad faces the light, so it is lit, and the specular highlight "
            f"varies across it; got values from {np.nanmin(img) if img.size else 'nothing'} to "
            f"{np.nanmax(img) if img.size else 'nothing'}"
        )
    flat = lab.shade(g, LIGHT, eye, (0.7, 0.7, 0.7), np.tile([0.0, 0.0, 1.0], (4, 4, 1)))
    expect_map_close(
        "shade with a flat normal map vs without", flat, plain, atol=1e-5, hint="tangent space (0, 0, 1) is N'"
    )


@graded(points=2, part="shading")
def test_normal_mapped_quad_matches_the_closed_form(lab):
    """wave relief z = 0.05 h: shading with the exact normals as a float map agrees with Lambert by hand"""
    s, k = 32, 0.05
    m = wave_normals(s, k)
    g, eye = quad_gbuffer(s)  # one pixel per texel, at the texel centres
    img = np.asarray(
        lab.shade(g, [{"direction": (0, 0, -1)}], eye, (1.0, 1.0, 1.0), m, ambient=0.0, specular=0.0), float
    )
    # Light straight down: colour = n . (0, 0, 1) = m_z (T = x, B = y, N = z on this quad).
    expect_map_close(
        "shade: normal-mapped quad, light from above",
        img[..., :1],
        m[..., 2:],
        atol=1e-5,
        hint="n = normalize(m_x T' + m_y B' + m_z N')",
    )


# ------------------------------------------------------------------------------ displacement


@graded(points=1, part="displacement")
def test_constant_map_by_hand(lab):
    """constant h = 0.75, (bias, scale) = (-1, 2), lam = 0.1, radial normals: radius 1 + 0.1 (-1 + 1.5) = 1.05"""
    V, F, UV = datasets.uv_sphere(8, 16)
    Vd = np.asarray(lab.displace(V, F, UV, V, np.full((4, 4), 0.75), lam=0.1, bias=-1.0, scale=2.0), float)
    expect_close(
        "displace: radius after a constant offset",
        np.linalg.norm(Vd, axis=1),
        np.full(len(V), 1.05),
        atol=1e-12,
        mesh=(V, F),
    )


@graded(points=1, part="displacement")
def test_seam_copies_move_together(lab):
    """UV sphere with a random map: vertices that share a position still share it after displacement, each moved by at most lam; copies whose normals cancel move along +z"""
    V, F, UV = datasets.uv_sphere(8, 16)
    H = np.random.default_rng(1).random((16, 16))
    Vd = np.asarray(lab.displace(V, F, UV, None, H, lam=0.2), float)
    if Vd.shape != V.shape:
        raise Mismatch(f"displace: got shape {Vd.shape}, expected {V.shape} (one position per vertex)")
    step = np.linalg.norm(Vd - V, axis=1)
    if not (step.max() <= 0.2 + 1e-9 and step.max() > 0.02):
        raise Mismatch(
            f"displace(lam=0.2) with heights in [0, 1]: vertices moved between {step.min():.3g} and {step.max():.3g}; "
            "each moves lam h <= 0.2 along its normal, and the random map moves some of them"
        )
    key = np.round(V, 9)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    gaps = np.linalg.norm(Vd - Vd[first][inv.ravel()], axis=1)
    if not gaps.max() < 1e-12:
        raise Mismatch(
            f"displace: copies of a seam vertex end up {gaps.max():.3g} apart (the seam cracks open); average their "
            "offsets and normals when weld_seams=True",
            marked_picture("displace: seam copies", V, F, V[~(gaps < 1e-12)], "seam vertices whose copies split"),
        )
    # Copies whose normals cancel move along (0, 0, 1), as the docstring says: two triangles cut apart, the
    # copies 1 and 3 (at (1, 0, 0)) facing +z and -z, a constant map h = 1/2: P' = P + 0.5 (0, 0, 1).
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])
    F = np.array([[0, 1, 2], [3, 5, 4]])
    UV = np.array([[0.0, 0.0], [0.45, 0.0], [0.0, 0.45], [0.55, 0.55], [0.55, 1.0], [1.0, 1.0]])
    N = np.tile([0.0, 0.0, 1.0], (6, 1))
    N[3] = [0.0, 0.0, -1.0]
    Vd = np.asarray(lab.displace(V, F, UV, N, np.full((4, 4), 0.5)), float)
    expect_close(
        "displace of seam copies whose normals cancel (vertices 1 and 3)", Vd[[1, 3]], [[1, 0, 0.5], [1, 0, 0.5]],
        atol=1e-12, hint="a zero mean normal falls back to (0, 0, 1)", mesh=(V, F),
    )  # fmt: skip


# ------------------------------------------------------------------------------ baking


@graded(points=2, part="baking")
def test_baked_height_field_matches_exact_normals(lab):
    """relief z = 0.05 h baked onto the flat square: within 1 degree of the exact normals"""
    from .cases import bake_flat_inputs

    args = bake_flat_inputs()
    n = np.asarray(lab.bake_normal_map(**args, size=32), float)
    s, k = 32, 0.05
    u, v = texel_uv(s)
    hu = np.pi * np.cos(2 * np.pi * u) * np.cos(2 * np.pi * v)
    hv = -np.pi * np.sin(2 * np.pi * u) * np.sin(2 * np.pi * v)
    exact = unit(np.stack([-k * hu, -k * hv, np.ones_like(u)], axis=-1))
    ang = np.degrees(np.arccos(np.clip(np.sum(unit(n) * exact, axis=-1), -1, 1)))
    if not ang.max() < 1.0:
        raise Mismatch(
            f"bake_normal_map: baked normals are up to {ang.max():.2f} degrees off the exact ones (allowed 1)",
            failure_picture("bake_normal_map vs exact normals", n, exact, name="normals"),
        )


# ------------------------------------------------------------------------------ bad input (given validation)


@graded(points=0, part="bad input")
def test_missing_uvs(lab):
    """tangent_frames without UVs says UV is missing"""
    V, F, _ = datasets.uv_grid(2)
    expect_rejected(lab, "tangent_frames", V, F, None, match="UV is missing", label="tangent_frames(UV=None)")


@graded(points=0, part="bad input")
def test_uv_out_of_range(lab):
    """displace with UVs outside [0, 1] names the row"""
    V, F, UV = datasets.uv_grid(2)
    expect_rejected(
        lab,
        "displace",
        V,
        F,
        UV + 2.0,
        None,
        np.zeros((4, 4)),
        match="outside the texture square",
        label="displace(UV + 2)",
    )


@graded(points=0, part="bad input")
def test_non_square_map(lab):
    """a non-square height map is rejected"""
    expect_rejected(lab, "height_to_normal_map", np.zeros((8, 6)), match="square", label="height_to_normal_map(8x6)")


@graded(points=0, part="bad input")
def test_wrong_image_modes(lab):
    """decode needs uint8 RGB; shade needs an RGB normal map"""
    expect_rejected(
        lab, "decode_normal_map", np.zeros((4, 4, 4), np.uint8), match="4 channel", label="decode_normal_map(RGBA)"
    )
    expect_rejected(lab, "decode_normal_map", np.zeros((4, 4, 3)), match="uint8", label="decode_normal_map(float)")
    g, eye = quad_gbuffer(4)
    expect_rejected(
        lab, "shade", g, LIGHT, eye, (1, 1, 1), np.zeros((4, 4)), match="1 channel", label="shade(grey normal map)"
    )


# ------------------------------------------------------------------------------ the GLSL route (tasks 7-9)

#: Tolerances of the GLSL route, from the measured agreement of the solution's shaders with the
#: stored NumPy references (llvmpipe, float32; the handout's table lists p99 / p99.9 / max):
#: frames agree to 2.4e-7 at most, so 1e-5 (40x that, still 1e-5 rad of a frame's direction);
#: shading to 2.1e-6 at most, so the lab's own shading tolerance 1e-4 (a quarter of an 8-bit level);
#: displaced positions to 3.6e-7 mesh units at most, so 1e-5 (lam (bias + scale h) is at most 0.5 here).
GLSL_FRAME_ATOL = 1e-5
GLSL_SHADE_ATOL = 1e-4
GLSL_DISPLACE_ATOL = 1e-5
STAGE = {
    "glsl_tbn": ("shaders/tbn.vert", "vertex stage"),
    "glsl_shade": ("shaders/normalmap.frag", "fragment stage"),
    "glsl_displace": ("shaders/displace.vert", "vertex stage"),
}


def _case(case_id: str):
    return {c.id: c for c in (*CASES, *hidden_cases("maps", package=__package__))}[case_id]


def expect_glsl_rows(label: str, got, expected, atol: float, mesh=None, name: str = "output") -> None:
    """Per-vertex (or per-pixel) results of a shader within ``atol`` of the NumPy reference, everywhere."""
    e = np.asarray(expected, float)
    g = np.asarray(got, float)
    if g.shape != e.shape:
        raise Mismatch(f"{label}: the shader's output has shape {g.shape}, expected {e.shape}")
    per = np.abs(g - e).reshape(len(e), -1).max(axis=1) if e.ndim == 2 else np.abs(g - e).max(axis=-1)
    bad = ~(per <= atol)  # NaN counts as wrong
    if not bad.any():
        return
    first = tuple(int(i) for i in np.argwhere(bad)[0])
    where = f"vertex {first[0]}" if e.ndim == 2 else f"pixel [{first[0]}, {first[1]}]"
    nan = " (NaN: a division by zero or normalize(0)?)" if np.isnan(g[first]).any() else ""
    raise Mismatch(
        f"{label}: {where} expected {format_vec(e[first])}, got {format_vec(g[first])}{nan}; "
        f"{int(bad.sum())} of {bad.size} {'vertices' if e.ndim == 2 else 'pixels'} differ by more than {atol:g}",
        failure_picture(label, g, e, name=name, mesh=mesh, atol=atol),
    )


def _label(function: str, case_id: str) -> str:
    path, stage = STAGE[function]
    return f'{function} ({path}, the {stage}) on "{case_id}"'


def check_glsl_tbn(lab, case_id: str, model=None) -> None:
    """``shaders/tbn.vert`` fed the stored frame of a tangent case (``N``, ``[T, w]``) gives it back in world
    space: with ``model = s R + t`` (rotation R, uniform scale s) the expected frame is ``R T, R B, R N``."""
    from geomlib.grading.cases import load_reference

    case = _case(case_id)
    ref = load_reference("maps", case)
    R = np.eye(3) if model is None else np.asarray(model, float)[:3, :3]
    R = R / np.cbrt(np.linalg.det(R))  # the rotation of s R
    inp = case.inputs()
    got = lab.glsl_tbn(ref["N"], np.column_stack([ref["T"], ref["w"]]), model)
    label = _label("glsl_tbn", case_id) + ("" if model is None else " with a rotated and scaled model matrix")
    for k, g in zip("TBN", got, strict=True):
        expect_glsl_rows(f"{label}, {k}", g, ref[k] @ R.T, GLSL_FRAME_ATOL, mesh=(inp["V"], inp["F"]), name=k)


def check_glsl_shade(lab, case_id: str) -> None:
    from geomlib.grading.cases import load_reference

    case = _case(case_id)
    got = lab.glsl_shade(**case.inputs(), **case.params)
    expect_glsl_rows(
        _label("glsl_shade", case_id), got, load_reference("maps", case)["image"], GLSL_SHADE_ATOL, name="image"
    )


def check_glsl_displace(lab, case_id: str) -> None:
    from geomlib.grading.cases import load_reference

    case = _case(case_id)
    inp = case.inputs()
    got = lab.glsl_displace(**inp, **case.params)
    b, s = case.params.get("bias", 0.0), case.params.get("scale", 1.0)
    label = _label("glsl_displace", case_id) + f" (bias, scale) = ({b:g}, {s:g})"
    expect_glsl_rows(label, got, load_reference("maps", case)["V"], GLSL_DISPLACE_ATOL, mesh=(inp["V"], inp["F"]))


def rotation_model() -> np.ndarray:
    """2 R_z(30 deg) R_x(-50 deg) plus a translation (the translation must not reach directions)."""
    a, b = np.radians(30), np.radians(-50)
    Rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    Rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    M = np.eye(4)
    M[:3, :3] = 2.0 * Rz @ Rx
    M[:3, 3] = (0.3, -1.0, 2.0)
    return M


@graded(points=1, part="vertex TBN", timeout=60)
def test_glsl_tbn_by_hand(lab):
    """non-uniform scale diag(2, 1, 1): normals by the inverse transpose, B = w N' x T'"""
    # n = (1, 0, 1)/sqrt2: M^-T n ~ (1/2, 0, 1) -> N' = (1, 0, 2)/sqrt5; T = (1, 0, -1)/sqrt2: M T ~ (2, 0, -1),
    # already orthogonal to N' -> T' = (2, 0, -1)/sqrt5; N' x T' = (0, 1, 0), so B' = (0, w, 0).
    n = np.array([[1.0, 0, 1], [1.0, 0, 1]]) / np.sqrt(2)
    t = np.array([[1.0, 0, -1, np.sqrt(2)], [1.0, 0, -1, -np.sqrt(2)]]) / np.sqrt(2)  # w = +1, then -1
    T, B, N = lab.glsl_tbn(n, t, np.diag([2.0, 1.0, 1.0, 1.0]))
    label = "glsl_tbn (shaders/tbn.vert, the vertex stage) with model = diag(2, 1, 1)"
    expect_glsl_rows(label + ", N", N, np.tile([1.0, 0, 2], (2, 1)) / np.sqrt(5), GLSL_FRAME_ATOL, name="N")
    expect_glsl_rows(label + ", T", T, np.tile([2.0, 0, -1], (2, 1)) / np.sqrt(5), GLSL_FRAME_ATOL, name="T")
    expect_glsl_rows(label + ", B (w = +1, -1)", B, [[0.0, 1, 0], [0.0, -1, 0]], GLSL_FRAME_ATOL, name="B")


@graded(points=2, part="vertex TBN", timeout=60)
def test_glsl_tbn(lab):
    """shaders/tbn.vert against the NumPy frames: a UV sphere, a mirrored torus (w = -1), a rotated model"""
    check_glsl_tbn(lab, "tangents-uv-sphere")
    check_glsl_tbn(lab, "tangents-mirrored-torus")
    check_glsl_tbn(lab, "tangents-mirrored-torus", rotation_model())


@graded(points=3, part="fragment normal mapping", timeout=60)
def test_glsl_shade(lab):
    """shaders/normalmap.frag against shade(): no map, a float map, a uint8 map, a torus with two lights"""
    for case_id in ("shade-quad-plain", "shade-quad-float-map", "shade-quad-uint8-map", "shade-torus-two-lights"):
        check_glsl_shade(lab, case_id)


@graded(points=2, part="vertex displacement", timeout=60)
def test_glsl_displace(lab):
    """shaders/displace.vert against displace(), the lecture's three (bias, scale): (0, 1), (-1, 2), (-1, 5)"""
    check_glsl_displace(lab, "displace-grid-wave")
    check_glsl_displace(lab, "displace-sphere-bias-1-scale-2")
    check_glsl_displace(lab, "displace-sphere-unwelded")
