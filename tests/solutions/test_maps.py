"""Cross-checks of the "maps" reference solution against closed forms, libigl, trimesh, NumPy and pyrender.

Independent references used here:

- closed forms: a height field ``z = k h(u, v)`` with an analytic gradient gives the exact normal map,
  the exact displaced surface and the exact shading; a sphere gives the exact normals a bake must
  reproduce; affine UV maps of a plane give the exact tangents;
- ``numpy.gradient`` / ``numpy.roll`` (finite differences), ``scipy.ndimage`` (via geomlib.textures),
  ``igl.per_vertex_normals`` (recomputed normals), ``trimesh`` (watertightness after displacement),
  ``geomlib.geometry.ray_cast`` (a watertight BVH ray caster, independent of the Embree ray casts
  the baker uses);
- pyrender 0.1.45 renders a normal-mapped plane (``normalTexture`` + our tangents). What pyrender
  actually does, read from its shaders: ``mesh.vert`` builds a TBN from the ``tangents`` attribute,
  but ``mesh.frag`` only uses it under ``HAS_TANGENTS``, which ``renderer.py`` never defines; the
  fragment shader always rebuilds the frame from screen-space derivatives of position and UV,
  ``t = dP/du`` (Gram-Schmidt against the interpolated normal) and ``b = n x t``. So pyrender
  ignores the tangents we pass and has no handedness: it agrees with us on ordinary UVs and
  disagrees on mirrored ones (tested below).
"""

from __future__ import annotations

import igl
import numpy as np
import pytest
import trimesh

from bench.anchors import pyrender_normal_mapped_mesh
from geomlib import camera, datasets
from geomlib.geometry import ray_cast, vertex_normals
from geomlib.textures import rasterize_uv, triangle_atlas, weld_by_position
from geomlib.validate import MeshError
from solutions.maps import (
    bake_normal_map,
    decode_normal_map,
    displace,
    encode_normal_map,
    height_to_normal_map,
    project_to_surface,
    rasterize_mesh,
    shade,
    surface_frames,
    tangent_frames,
    welded_vertex_normals,
)

# --------------------------------------------------------------------------- closed forms


def texel_uv(s: int) -> tuple[np.ndarray, np.ndarray]:
    """U, V (s, s) of the texel centres (row 0 = v near 1)."""
    r, c = np.mgrid[0:s, 0:s]
    return (c + 0.5) / s, 1.0 - (r + 0.5) / s


def wave(u, v):
    """h(u, v) in [0, 1], periodic with period 1 in u and v."""
    return 0.5 + 0.5 * np.sin(2 * np.pi * u) * np.cos(2 * np.pi * v)


def wave_grad(u, v):
    return (
        np.pi * np.cos(2 * np.pi * u) * np.cos(2 * np.pi * v),
        -np.pi * np.sin(2 * np.pi * u) * np.sin(2 * np.pi * v),
    )


def analytic_normals(u, v, k):
    hu, hv = wave_grad(u, v)
    n = np.stack([-k * hu, -k * hv, np.ones_like(hu)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def angle_deg(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(unit(a) * unit(b), axis=-1), -1.0, 1.0)))


def top_view(size: int = 128):
    """Orthographic camera looking down -z at the unit square."""
    eye = np.array([0.5, 0.5, 4.0])
    M = camera.orthographic(-0.5, 0.5, -0.5, 0.5, 0.5, 8.0) @ camera.look_at(eye, (0.5, 0.5, 0.0))
    return eye, M


# =========================================================================== tangent frames


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_tangents_of_an_affine_uv_map_are_its_inverse_columns(seed):
    """UV = A (x, y) + c on a plane: dP/du and dP/dv are the columns of A^-1 (in 3-D, z = 0)."""
    rng = np.random.default_rng(seed)
    V, F = datasets.grid_patch(6)
    A = rng.normal(size=(2, 2))
    UV = V[:, :2] @ A.T + rng.normal(size=2)
    T, B, N, w = tangent_frames(V, F, UV)
    Ainv = np.linalg.inv(A)
    dPdu = np.array([Ainv[0, 0], Ainv[1, 0], 0.0])
    dPdv = np.array([Ainv[0, 1], Ainv[1, 1], 0.0])
    np.testing.assert_allclose(N, np.tile([0, 0, 1.0], (len(V), 1)), atol=1e-12)
    np.testing.assert_allclose(T, np.tile(unit(dPdu), (len(V), 1)), atol=1e-12)
    assert np.all(w == np.sign(np.linalg.det(A)))
    # B = w N x T is the part of dP/dv orthogonal to T, pointing the same way.
    assert np.all(B @ dPdv > 0)
    np.testing.assert_allclose(B, w[:, None] * np.cross(N, T), atol=1e-12)


def test_mirrored_uvs_flip_w():
    V, F, UV = datasets.uv_grid(4)
    _, _, _, w = tangent_frames(V, F, UV)
    assert np.all(w == 1)
    UVm = UV.copy()
    UVm[:, 0] = 1.0 - UVm[:, 0]
    T, B, N, wm = tangent_frames(V, F, UVm)
    assert np.all(wm == -1)
    np.testing.assert_allclose(T, np.tile([-1.0, 0, 0], (len(V), 1)), atol=1e-12)
    np.testing.assert_allclose(B, np.tile([0.0, 1, 0], (len(V), 1)), atol=1e-12)  # still along +v


def test_sphere_and_torus_tangents_follow_the_parameter_lines():
    """T is the average of the chords' directions dP/du of the faces around a vertex.

    Away from the seam, faces on both sides make that average nearly the exact east direction
    (the split diagonals tilt it by less than a degree); on the seam only one side exists, so
    T is off by exactly half a segment angle, 180 / n_lon degrees.
    """
    n_lon = 48
    V, F, UV = datasets.uv_sphere(24, n_lon)
    T, B, N, w = tangent_frames(V, F, UV)
    ring = np.abs(V[:, 2]) < 0.9  # away from the poles (the parameterization is singular there)
    inner = ring & (UV[:, 0] > 0) & (UV[:, 0] < 1)
    seam = ring & ~inner
    phi = np.arctan2(V[:, 1], V[:, 0])
    east = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)], axis=1)  # u = longitude / 2 pi grows east
    assert angle_deg(T[inner], east[inner]).max() < 0.5
    np.testing.assert_allclose(angle_deg(T[seam], east[seam]), 180 / n_lon, atol=1e-9)
    assert np.all(w[ring] == 1)
    Vt, Ft, UVt = datasets.uv_torus(96, 24)
    Tt, _, _, wt = tangent_frames(Vt, Ft, UVt)
    theta = np.arctan2(Vt[:, 1], Vt[:, 0])
    around = np.stack([-np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=1)
    inner_t = (UVt[:, 0] > 0) & (UVt[:, 0] < 1)
    assert angle_deg(Tt[inner_t], around[inner_t]).max() < 1.0
    np.testing.assert_allclose(angle_deg(Tt[~inner_t], around[~inner_t]), 180 / 96, atol=1e-9)
    assert np.all(wt == 1)


def test_frames_are_orthonormal_and_never_nan_with_degenerate_uvs():
    V, F = datasets.icosphere(2)
    rng = np.random.default_rng(3)
    UV = rng.random((len(V), 2))
    UV[F[:10].ravel()] = 0.25  # ten triangles (and their neighbours partly) with zero UV area
    UV[F[20, 1]] = UV[F[20, 0]]  # one more degenerate (two equal UV corners)
    T, B, N, w = tangent_frames(V, F, UV)
    for X in (T, B, N):
        assert np.all(np.isfinite(X))
        np.testing.assert_allclose(np.linalg.norm(X, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.sum(T * N, axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(B, w[:, None] * np.cross(N, T), atol=1e-12)
    assert set(np.unique(w)) <= {-1.0, 1.0}


def test_given_normals_are_used_and_the_pyrender_tangent_array_is_n_by_4():
    V, F, UV = datasets.uv_grid(3)
    tilt = unit(np.tile([0.0, 0.3, 1.0], (len(V), 1)))
    T, B, N, w = tangent_frames(V, F, UV, N=2 * tilt)
    np.testing.assert_allclose(N, tilt, atol=1e-12)
    np.testing.assert_allclose(np.sum(T * N, axis=1), 0.0, atol=1e-12)
    tangents = np.column_stack([T, w])
    assert tangents.shape == (len(V), 4)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"UV": None}, "UV is missing"),
        ({"UV": np.zeros((3, 2))}, "UV has 3 rows but V has 16"),
        ({"UV": np.full((16, 2), np.nan)}, "non-finite"),
        ({"N": np.zeros((16, 3))}, "zero vector"),
    ],
)
def test_tangent_frames_bad_input(kwargs, match):
    V, F, UV = datasets.uv_grid(3)
    args = {"V": V, "F": F, "UV": UV, **kwargs}
    with pytest.raises(MeshError, match=match):
        tangent_frames(**args)


# =========================================================================== encode / decode


def test_round_trip_within_one_code():
    rng = np.random.default_rng(0)
    n = unit(rng.normal(size=(450, 450, 3)))
    special = unit(np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [1, -1, 0], [-1, -1, -1.0]]))
    n[0, : len(special)] = special
    back = decode_normal_map(encode_normal_map(n))
    assert np.abs(back - n).max() <= 1.0 / 255.0
    np.testing.assert_allclose(np.linalg.norm(back, axis=2), 1.0, atol=1e-12)


def test_codes_by_hand():
    n = np.array([[[0, 0, 1.0], [1, 0, 0]], [[-1, 0, 0], [0, -1, 0]]])
    enc = encode_normal_map(n)
    # 255 (x + 1) / 2: -1 -> 0, 0 -> 127.5 -> 128, 1 -> 255.
    np.testing.assert_array_equal(enc, [[[128, 128, 255], [255, 128, 128]], [[0, 128, 128], [128, 0, 128]]])
    rnd = np.random.default_rng(1).normal(size=(8, 8, 3))
    np.testing.assert_array_equal(encode_normal_map(rnd, method="round"), np.round((unit(rnd) + 1) / 2 * 255))
    # decode (255, 128, 128): (2*255/255 - 1, 2*128/255 - 1, ...) = (1, 1/255, 1/255), normalised.
    dec = decode_normal_map(np.array([[[255, 128, 128]]], np.uint8))
    np.testing.assert_allclose(dec[0, 0], unit(np.array([1.0, 1 / 255, 1 / 255])), atol=1e-15)


def test_plain_rounding_exceeds_one_code_after_renormalising():
    """Why "nearest" exists: textbook rounding is off by up to ~1.34 codes once decoded vectors are normalised."""
    rng = np.random.default_rng(2)
    n = unit(rng.normal(size=(300, 300, 3)))
    assert np.abs(decode_normal_map(encode_normal_map(n, method="round")) - n).max() > 1.0 / 255.0


def test_png_round_trip_is_lossless(tmp_path):
    from geomlib.image_io import read_image, write_image

    n = height_to_normal_map(wave(*texel_uv(32)), 0.2, border="wrap")
    enc = encode_normal_map(n)
    write_image(tmp_path / "n.png", enc)
    np.testing.assert_array_equal(read_image(tmp_path / "n.png"), enc)


@pytest.mark.parametrize(
    ("fn", "img", "match"),
    [
        (decode_normal_map, np.zeros((4, 6, 3), np.uint8), "square"),
        (decode_normal_map, np.zeros((4, 4, 3)), "dtype float64.*uint8"),
        (decode_normal_map, np.zeros((4, 4, 4), np.uint8), "4 channel"),
        (decode_normal_map, np.zeros((4, 4), np.uint8), "1 channel"),
        (encode_normal_map, np.zeros((4, 4, 3)), "zero vector"),
        (encode_normal_map, np.ones((4, 5, 3)), "square"),
        (encode_normal_map, np.ones((4, 4)), "channel"),
    ],
)
def test_encode_decode_bad_input(fn, img, match):
    with pytest.raises(MeshError, match=match):
        fn(img)


# =========================================================================== height -> normals


def test_height_normals_match_the_analytic_gradient_to_second_order():
    k = 0.1
    errs = []
    for s in (32, 64, 128):
        U, V = texel_uv(s)
        n = height_to_normal_map(wave(U, V), k, border="wrap")
        errs.append(np.abs(n - analytic_normals(U, V, k)).max())
    assert errs[-1] < 2e-4
    # Central differences: halving the texel size divides the error by ~4.
    assert 3.5 < errs[0] / errs[1] < 4.5 and 3.5 < errs[1] / errs[2] < 4.5


def test_height_normals_agree_with_numpy_gradient():
    rng = np.random.default_rng(4)
    H = rng.random((40, 40))
    k, s = 0.3, 40
    # np.gradient along axis 1 = d/dcol, axis 0 = d/drow; v grows up, so dH/dv = -dH/drow; one texel = 1/s.
    gr, gc = np.gradient(H)
    ref = unit(np.stack([-k * gc * s, k * gr * s, np.ones_like(H)], axis=-1))
    got = height_to_normal_map(H, k, border="clamp")
    np.testing.assert_allclose(got[1:-1, 1:-1], ref[1:-1, 1:-1], atol=1e-12)
    # wrap: central differences with periodic neighbours (np.roll).
    gc_w = (np.roll(H, -1, axis=1) - np.roll(H, 1, axis=1)) / 2
    gr_w = (np.roll(H, -1, axis=0) - np.roll(H, 1, axis=0)) / 2
    ref_w = unit(np.stack([-k * gc_w * s, k * gr_w * s, np.ones_like(H)], axis=-1))
    np.testing.assert_allclose(height_to_normal_map(H, k, border="wrap"), ref_w, atol=1e-12)


def test_ramps_tilt_the_right_way():
    s = 16
    U, V = texel_uv(s)
    # H = u rises to the right: the relief faces left (-x); slope k, so n = (-k, 0, 1)/|.|.
    n = height_to_normal_map(U, 0.5, border="wrap")
    np.testing.assert_allclose(n[5, 5], unit(np.array([-0.5, 0.0, 1.0])), atol=1e-12)
    # H = v rises towards row 0 (the top of the image): n leans to -y.
    n = height_to_normal_map(V, 0.5)
    np.testing.assert_allclose(n[5, 5], unit(np.array([0.0, -0.5, 1.0])), atol=1e-12)
    # Flat maps and zero strength give (0, 0, 1).
    np.testing.assert_allclose(height_to_normal_map(np.full((8, 8), 0.3), 2.0), np.tile([0, 0, 1.0], (8, 8, 1)))
    np.testing.assert_allclose(height_to_normal_map(U, 0.0), np.tile([0, 0, 1.0], (s, s, 1)))


def test_uint8_heights_are_scaled():
    H = (np.arange(16)[None, :].repeat(16, 0) * 17).astype(np.uint8)  # 0..255 left to right
    np.testing.assert_allclose(height_to_normal_map(H, 0.5), height_to_normal_map(H / 255.0, 0.5), atol=1e-15)


@pytest.mark.parametrize(
    ("H", "kwargs", "match"),
    [
        (np.zeros((8, 8, 3)), {}, "3 channels"),
        (np.zeros((8, 6)), {}, "square"),
        (np.zeros((8, 8)), {"border": "mirror"}, "border must be one of"),
        (np.zeros((8, 8)), {"strength": np.nan}, "finite"),
    ],
)
def test_height_to_normal_map_bad_input(H, kwargs, match):
    with pytest.raises(MeshError, match=match):
        height_to_normal_map(H, **kwargs)


# =========================================================================== shading


def flat_quad_gbuffer(size=128):
    V, F, UV = datasets.uv_grid(1)
    T, _, _, w = tangent_frames(V, F, UV)
    eye, M = top_view()
    return rasterize_mesh(V, F, M, size, size, UV=UV, tangents=np.column_stack([T, w])), eye


def test_lambert_and_specular_by_hand():
    """shade works in single precision (as a GPU does): results agree with hand values to 2e-7."""
    g, eye = flat_quad_gbuffer(16)
    albedo = (0.8, 0.6, 0.4)
    # Light straight down: n.l = 1, no ambient, no specular -> exactly the albedo.
    img = shade(g, [{"direction": (0, 0, -1)}], eye, albedo, ambient=0.0, specular=0.0)
    np.testing.assert_allclose(img[g.mask], np.tile(albedo, (g.mask.sum(), 1)), atol=2e-7, rtol=0)
    # Light at 60 degrees from the normal: cos 60 = 1/2.
    d = (np.sin(np.pi / 3), 0.0, -np.cos(np.pi / 3))
    img = shade(g, [{"direction": d, "intensity": 1.0}], eye, albedo, ambient=0.0, specular=0.0)
    np.testing.assert_allclose(img[g.mask], np.tile(0.5 * np.array(albedo), (g.mask.sum(), 1)), atol=2e-7, rtol=0)
    # Ambient only (light from below): 0.25 * albedo.
    img = shade(g, [{"direction": (0, 0, 1)}], eye, albedo, ambient=0.25)
    np.testing.assert_allclose(img[g.mask], np.tile(0.25 * np.array(albedo), (g.mask.sum(), 1)), atol=2e-7, rtol=0)
    # Light straight down, viewer above: h = normalize(l + v) with l = +z; specular = ks (h . n)^p with n = +z.
    img = shade(g, [{"direction": (0, 0, -1)}], eye, (0.2, 0.2, 0.2), ambient=0.0, specular=0.5, shininess=8)
    P = g.attributes["position"][8, 8]
    hz = unit(np.array([0.0, 0.0, 1.0]) + unit(eye - P))[2]
    np.testing.assert_allclose(img[8, 8], 0.2 + 0.5 * hz**8, atol=2e-7, rtol=0)
    assert (img[~g.mask] == 1.0).all()  # background


def test_flat_normal_map_changes_nothing():
    g, eye = flat_quad_gbuffer()
    lights = [
        {"direction": (-1.0, -0.5, -1.0)},
        {"type": "point", "position": (2.0, 1.0, 1.0), "color": (1, 0.5, 0.5), "intensity": 0.5},
    ]
    plain = shade(g, lights, eye, (0.7, 0.7, 0.7))
    flat_u8 = np.tile(np.array([128, 128, 255], np.uint8), (8, 8, 1))
    flat_f = np.tile([0.0, 0.0, 1.0], (8, 8, 1))
    # (128, 128, 255) decodes to (1/255, 1/255, 1) normalised: about 0.3 degrees off (0, 0, 1).
    np.testing.assert_allclose(shade(g, lights, eye, (0.7, 0.7, 0.7), flat_u8), plain, atol=0.01)
    np.testing.assert_allclose(shade(g, lights, eye, (0.7, 0.7, 0.7), flat_f), plain, atol=2e-7, rtol=0)


def test_normal_mapped_quad_equals_displaced_grid_equals_analytic():
    """Closed form: z = k h(u, v) on the unit square, seen from above with one directional light.

    (a) flat quad + height_to_normal_map(h) vs (b) flat quad + analytic normal map: the finite
    differences are second order, so they agree to 1e-4; (c) the displaced dense grid (256 x 256
    cells) with recomputed vertex normals, rasterized and shaded per pixel: it differs from (a) only
    by the grid's piecewise-linear normals, mean |difference| < 2e-3 and 99% of pixels < 0.02
    (the largest differences sit on the outermost ring of pixels, where boundary vertex normals are one-sided).
    """
    s, k, size = 256, 0.05, 128
    U, V = texel_uv(s)
    H = wave(U, V)
    lights = [{"direction": (-1.0, -0.5, -1.0)}]
    g, eye = flat_quad_gbuffer(size)
    mapped = shade(g, lights, eye, (0.8, 0.7, 0.6), height_to_normal_map(H, k, border="wrap"), wrap="repeat")
    exact = shade(g, lights, eye, (0.8, 0.7, 0.6), analytic_normals(U, V, k), wrap="repeat")
    assert np.abs(mapped - exact).max() < 1e-4
    Vg, Fg, UVg = datasets.uv_grid(256)
    Vd, Nd = displace(Vg, Fg, UVg, np.tile([0, 0, 1.0], (len(Vg), 1)), H, lam=k, return_normals=True)
    _, M = top_view()
    gd = rasterize_mesh(Vd, Fg, M, size, size, N=Nd)
    displaced = shade(gd, lights, eye, (0.8, 0.7, 0.6))
    both = g.mask & gd.mask
    d = np.abs(mapped - displaced).max(axis=2)[both]
    assert d.mean() < 2e-3
    assert np.percentile(d, 99) < 0.02


def _pyrender_plane(enc, UV, tangents, eye, light_dir, size):
    from geomlib import render as grender

    pyrender = grender.import_pyrender()  # chooses the headless platform and applies the project's one shim
    V, F, _ = datasets.uv_grid(1)
    V = V - [0.5, 0.5, 0.0]
    N = np.tile([0.0, 0.0, 1.0], (len(V), 1))
    scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
    scene.add(pyrender_normal_mapped_mesh(V, F, UV, N, tangents, enc, base_color=(0.8, 0.8, 0.8), roughness=1.0))
    view = camera.look_at(eye, (0, 0, 0))
    scene.add(
        pyrender.PerspectiveCamera(yfov=np.radians(40), aspectRatio=1.0, znear=0.5, zfar=5.0), pose=np.linalg.inv(view)
    )
    z = -unit(np.asarray(light_dir, float))
    x = unit(np.cross([0.0, 1.0, 0.0], z))
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2] = x, np.cross(z, x), z
    scene.add(pyrender.DirectionalLight(intensity=3.0), pose=pose)
    r = pyrender.OffscreenRenderer(size, size)
    try:
        col, depth = r.render(scene)
    finally:
        r.delete()
    # pyrender writes linear colour ** (1 / 2.2); undo it to compare radiance.
    return (np.asarray(col[..., :3], float) / 255.0) ** 2.2, np.asarray(depth) > 0, V, F, view


@pytest.mark.render
@pytest.mark.parametrize("mirrored", [False, True])
def test_pyrender_normal_mapped_plane_matches_shade(mirrored):
    """Correlation of per-pixel brightness between pyrender and shade (Lambert only, no ambient).

    pyrender shades with a PBR model (roughness 1, metallic 0), so brightness levels differ but
    bright and dark places coincide: correlation > 0.99. With mirrored UVs pyrender's derivative
    frame has no handedness, so it matches shade with w forced to +1 and NOT the correct w = -1
    frame (correlation < 0.95 there).
    """
    s, size = 128, 160
    U, V = texel_uv(s)
    H = 0.5 + 0.5 * np.sin(4 * np.pi * U) * np.cos(2 * np.pi * V)
    enc = encode_normal_map(height_to_normal_map(H, 0.08, border="wrap"))
    Vq, Fq, UV = datasets.uv_grid(1)
    Vq = Vq - [0.5, 0.5, 0.0]
    if mirrored:
        UV = UV.copy()
        UV[:, 0] = 1.0 - UV[:, 0]
    T, _, N, w = tangent_frames(Vq, Fq, UV)
    tangents = np.column_stack([T, w])
    eye, light = np.array([0.3, -0.4, 2.0]), (-0.6, 0.3, -1.0)
    ref, covered, _, _, view = _pyrender_plane(enc, UV, tangents, eye, light, size)
    M = camera.perspective(40, 1.0, 0.5, 5.0) @ view
    lights = [{"direction": light}]

    def ours(tg):
        g = rasterize_mesh(Vq, Fq, M, size, size, UV=UV, tangents=tg)
        return shade(g, lights, eye, (0.8, 0.8, 0.8), enc, ambient=0.0, specular=0.0), g.mask

    img, mask = ours(tangents)
    assert (mask == covered).mean() > 0.995  # same camera, same pixels
    both = mask & covered
    corr = np.corrcoef(ref.mean(axis=2)[both], img.mean(axis=2)[both])[0, 1]
    if not mirrored:
        assert corr > 0.99
        return
    assert np.all(w == -1)
    assert corr < 0.95
    right_handed = tangents.copy()
    right_handed[:, 3] = 1.0
    img_rh, _ = ours(right_handed)
    assert np.corrcoef(ref.mean(axis=2)[both], img_rh.mean(axis=2)[both])[0, 1] > 0.99


def test_shade_bad_input():
    g, eye = flat_quad_gbuffer(8)
    Vq, Fq, UVq = datasets.uv_grid(1)
    _, M = top_view()
    no_tangents = rasterize_mesh(Vq, Fq, M, 8, 8, UV=UVq)
    nm = np.tile([0.0, 0.0, 1.0], (4, 4, 1))
    light = [{"direction": (0, 0, -1)}]
    with pytest.raises(MeshError, match="no 'tangent' attribute"):
        shade(no_tangents, light, eye, (1, 1, 1), nm)
    with pytest.raises(MeshError, match="1 channel"):
        shade(g, light, eye, (1, 1, 1), np.zeros((4, 4)))
    with pytest.raises(MeshError, match="square"):
        shade(g, light, eye, (1, 1, 1), np.ones((4, 8, 3)))
    with pytest.raises(MeshError, match="needs a 'direction'"):
        shade(g, [{"type": "directional"}], eye, (1, 1, 1))
    with pytest.raises(MeshError, match="GBuffer"):
        shade(np.zeros((8, 8)), light, eye, (1, 1, 1))


# =========================================================================== displacement


@pytest.mark.parametrize(("bias", "scale"), [(0.0, 1.0), (-1.0, 2.0), (-1.0, 5.0)])
def test_constant_map_scales_a_sphere_by_hand(bias, scale):
    V, F, UV = datasets.uv_sphere(12, 24)
    h0, lam = 0.75, 0.1
    H = np.full((8, 8), h0)
    Vd = displace(V, F, UV, V, H, lam=lam, bias=bias, scale=scale)  # N = V: exact radial normals
    # Every point moves radially by lam (bias + scale h0): the radius becomes 1 + that.
    np.testing.assert_allclose(np.linalg.norm(Vd, axis=1), 1.0 + lam * (bias + scale * h0), atol=1e-12)


def test_displaced_grid_follows_the_height_field():
    s, k = 64, 0.2
    U, V = texel_uv(s)
    H = wave(U, V)
    Vg, Fg, UVg = datasets.uv_grid(40)
    Vd = displace(Vg, Fg, UVg, np.tile([0, 0, 1.0], (len(Vg), 1)), H, lam=k, bias=-0.5, scale=1.0, wrap="repeat")
    np.testing.assert_allclose(Vd[:, :2], Vg[:, :2], atol=1e-15)
    # Bilinear interpolation of a smooth function: error <= (texel^2 / 8) max|h''| ~ (1/64)^2 / 8 * 2 pi^2.
    bound = k * (1 / s) ** 2 / 8 * 2 * (2 * np.pi) ** 2 * 0.5
    assert np.abs(Vd[:, 2] - k * (wave(UVg[:, 0], UVg[:, 1]) - 0.5)).max() <= bound


def test_seams_stay_closed_only_when_welded():
    V, F, UV = datasets.uv_sphere(16, 32)
    rng = np.random.default_rng(5)
    H = rng.random((32, 32))
    group, k = weld_by_position(V)
    welded = displace(V, F, UV, None, H, lam=0.2)
    cracked = displace(V, F, UV, None, H, lam=0.2, weld_seams=False)
    spread_w = np.zeros(k)
    spread_c = np.zeros(k)
    np.maximum.at(
        spread_w, group, np.linalg.norm(welded - welded[np.unique(group, return_index=True)[1]][group], axis=1)
    )
    np.maximum.at(
        spread_c, group, np.linalg.norm(cracked - cracked[np.unique(group, return_index=True)[1]][group], axis=1)
    )
    assert spread_w.max() == 0.0
    assert spread_c.max() > 0.01
    # trimesh, independently: merging coincident vertices closes the welded sphere but not the cracked one.
    tw = trimesh.Trimesh(welded, F, process=False)
    tw.merge_vertices()
    tc = trimesh.Trimesh(cracked, F, process=False)
    tc.merge_vertices()
    assert tw.is_watertight and not tc.is_watertight


def test_recomputed_normals_match_libigl():
    Vg, Fg, UVg = datasets.uv_grid(30)
    H = wave(*texel_uv(32))
    Vd, Nd = displace(Vg, Fg, UVg, None, H, lam=0.1, return_normals=True)
    ref = igl.per_vertex_normals(Vd, Fg, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    np.testing.assert_allclose(Nd, ref, atol=1e-10)


def test_welded_normals_are_equal_across_the_seam():
    V, F, UV = datasets.uv_torus(24, 12)
    N = welded_vertex_normals(V, F)
    group, _ = weld_by_position(V)
    first = np.unique(group, return_index=True)[1]
    np.testing.assert_allclose(N, N[first][group], atol=1e-14)
    # Away from seams they equal ordinary area-weighted normals.
    plain = vertex_normals(V, F)
    interior = (UV > 0).all(axis=1) & (UV < 1).all(axis=1)
    np.testing.assert_allclose(N[interior], plain[interior], atol=1e-12)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"UV": "out"}, r"row \d+ is .*outside the texture square"),
        ({"UV": None}, "UV is missing"),
        ({"height": np.zeros((8, 8, 3))}, "3 channels"),
        ({"height": np.full((8, 8), 1.5)}, r"values span \[1\.5, 1\.5\]"),
        ({"height": np.zeros((8, 4))}, "square"),
        ({"wrap": "mirror"}, "wrap must be one of"),
    ],
)
def test_displace_bad_input(change, match):
    V, F, UV = datasets.uv_grid(4)
    args = {"V": V, "F": F, "UV": UV, "N": None, "height": np.zeros((8, 8))}
    for key, value in change.items():
        args[key] = UV + 0.5 if (isinstance(value, str) and value == "out") else value
    with pytest.raises(MeshError, match=match):
        displace(**args)


# =========================================================================== baking


def test_project_to_surface_agrees_with_the_watertight_ray_caster():
    Vh, Fh = datasets.icosphere(4)
    rng = np.random.default_rng(6)
    P = unit(rng.normal(size=(500, 3))) * rng.uniform(0.9, 1.1, size=(500, 1))
    D = unit(P + 0.1 * rng.normal(size=P.shape))
    face, bary, hit = project_to_surface(Vh, Fh, P, D, max_distance=0.5)
    assert hit.all()
    X = np.einsum("ki,kij->kj", bary, Vh[Fh[face]])
    hf, tf, _, _ = ray_cast(Vh, Fh, P, D)
    hb, tb, _, _ = ray_cast(Vh, Fh, P, -D)
    t = np.where(np.where(hf, tf, np.inf) <= np.where(hb, tb, np.inf), tf, -tb)
    ref = P + t[:, None] * D
    # Same points (project_to_surface redoes Embree's single-precision hits in double precision).
    np.testing.assert_allclose(X, ref, atol=1e-9)


def _atlas_frames(V, F, UV, N_lo, size):
    """Per covered texel: low-mesh point P and frame (T', B', N'), rebuilt from the given helpers."""
    fid, bary = rasterize_uv(F, UV, size)
    cov = fid >= 0
    f, b = fid[cov], bary[cov]
    T, _, _, w = tangent_frames(V, F, UV, N_lo)
    tg = np.column_stack([T, w])
    P = np.einsum("ki,kij->kj", b, V[F[f]])
    Ti, Bi, Ni = surface_frames(np.einsum("ki,kij->kj", b, N_lo[F[f]]), np.einsum("ki,kij->kj", b, tg[F[f]]))
    return cov, P, Ti, Bi, Ni


def test_baked_sphere_normals_are_the_analytic_sphere_normals():
    """High: icosphere level 5 (radius 1); low: icosphere level 1, FACETED (face normals), in a triangle atlas.

    Along the low normal N' from P, the unit sphere is hit at X = P + t N' with |X| = 1, and the
    exact normal there is X. The baked map, taken back to world space with the same frame, must
    reproduce it within 1 degree (the high mesh is itself a polygonal sphere), although the
    faceted low mesh's own normals are off by more than 10 degrees near its corners.
    """
    Vh, Fh = datasets.icosphere(5)
    Vl, Fl = datasets.icosphere(1)
    Vs, Fs, UV, _ = triangle_atlas(Vl, Fl)
    N_face = np.repeat(unit(np.cross(Vl[Fl[:, 1]] - Vl[Fl[:, 0]], Vl[Fl[:, 2]] - Vl[Fl[:, 0]])), 3, axis=0)
    size = 128
    img = bake_normal_map(Vh, Fh, Vs, Fs, UV, size, N_lo=N_face)
    cov, P, Ti, Bi, Ni = _atlas_frames(Vs, Fs, UV, N_face, size)
    m = img[cov]
    world = m[:, :1] * Ti + m[:, 1:2] * Bi + m[:, 2:3] * Ni
    pn = np.sum(P * Ni, axis=1)
    t = -pn + np.sqrt(pn**2 - (np.sum(P * P, axis=1) - 1.0))  # |P + t N'| = 1, the root near 0
    X = P + t[:, None] * Ni
    assert angle_deg(Ni, X).max() > 10.0
    assert angle_deg(world, X).max() < 1.0
    np.testing.assert_allclose(np.linalg.norm(img, axis=2), 1.0, atol=1e-12)


def test_smooth_low_sphere_needs_an_almost_flat_map():
    """On an icosphere, interpolated vertex normals already point along the sphere normal (vertices = normals)."""
    Vh, Fh = datasets.icosphere(5)
    Vs, Fs, UV, _ = triangle_atlas(*datasets.icosphere(1))
    img, mask = bake_normal_map(Vh, Fh, Vs, Fs, UV, 96, return_mask=True)
    assert angle_deg(img[mask], np.array([0.0, 0.0, 1.0])).max() < 1.0


def test_baking_a_height_field_onto_a_flat_quad_gives_its_normals():
    """High: z = k h(x, y) (a fine grid); low: the flat unit square. Vertical rays hit (x, y, k h(x, y))."""
    k = 0.05
    Vh, Fh = datasets.height_field(200, fn=lambda x, y: k * wave(x, y))
    Vl, Fl, UVl = datasets.uv_grid(2)
    img = bake_normal_map(Vh, Fh, Vl, Fl, UVl, 64, tangents=np.tile([1.0, 0, 0, 1], (len(Vl), 1)))
    U, V = texel_uv(64)
    assert angle_deg(img, analytic_normals(U, V, k)).max() < 0.5


def test_baking_a_mesh_onto_itself_is_flat_and_padding_fills_the_gutters():
    V, F, UV = datasets.uv_torus(24, 12)
    img, mask = bake_normal_map(V, F, V, F, UV, 64, return_mask=True)
    assert mask.all()  # the torus charts tile the square
    assert angle_deg(img, np.array([0.0, 0.0, 1.0])).max() < 0.5
    Vl, Fl = datasets.icosphere(1)
    Vs, Fs, UVs, _ = triangle_atlas(Vl, Fl, gutter=0.1)
    Vh, Fh = datasets.icosphere(4)
    img, mask = bake_normal_map(Vh, Fh, Vs, Fs, UVs, 128, padding=2, return_mask=True)
    from scipy import ndimage

    band = ndimage.binary_dilation(mask, structure=np.ones((3, 3)), iterations=2) & ~mask
    # Padded texels copy chart values (normals near (0, 0, 1) on this smooth sphere), not the background.
    assert band.any() and angle_deg(img[band], np.array([0.0, 0.0, 1.0])).max() < 5.0
    np.testing.assert_allclose(np.linalg.norm(img, axis=2), 1.0, atol=1e-12)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"UV_lo": "out"}, "outside the texture square"),
        ({"UV_lo": None}, "UV_lo is missing"),
        ({"size": 0}, "size must be >= 1"),
        ({"max_distance": -1.0}, "max_distance must be >= 0"),
        ({"F_hi": np.array([[0, 1, 99]])}, "uses vertex 99"),
    ],
)
def test_bake_bad_input(change, match):
    V, F, UV = datasets.uv_grid(2)
    args = {"V_hi": V, "F_hi": F, "V_lo": V, "F_lo": F, "UV_lo": UV, "size": 8}
    for key, value in change.items():
        args[key] = UV - 0.5 if (isinstance(value, str) and value == "out") else value
    with pytest.raises(MeshError, match=match):
        bake_normal_map(**args)
