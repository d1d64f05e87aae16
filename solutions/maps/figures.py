"""Figures of the lab "maps", rendered with the lab's own functions.

The imports are relative, so the same file copied next to a student's implementation
(``labs/maps/figures.py``) renders the student's results. Shaded images come from the lab's NumPy
fragment shader (:func:`shade` over :func:`rasterize_mesh`); the displacement figure uses
:func:`geomlib.render.render` (pyrender). Only built-in data is used.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import camera, datasets
from geomlib.labfigures import Claims, Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import Figure, colorbar, heatmap_image, panels, save_png, with_colorbar
from geomlib.textures import triangle_atlas

__all__ = ["make_figures", "make_view", "bump_tiles", "smooth_noise"]

LAB = "maps"
ALBEDO = (0.80, 0.66, 0.52)
BACKGROUND = (1.0, 1.0, 1.0)
#: Blinn-Phong settings of every shaded picture (NumPy and GLSL routes).
SHADING = {"background": BACKGROUND, "specular": 0.25, "shininess": 24.0}
#: Radii (R around, r across) of the bumpy torus and the height ``lambda`` of its bumps.
TORUS_RADII, BUMP_HEIGHT = (1.0, 0.35), 0.05
# Two lighting set-ups (directions in which the light travels; z is up in every scene here).
KEY_LIGHTS = [
    {"direction": (0.6, 0.5, -0.8), "intensity": 0.95},
    {"direction": (-0.7, 0.2, -0.4), "intensity": 0.25, "color": (0.85, 0.9, 1.0)},
]
GRAZING_LIGHTS = [{"direction": (-1.0, -0.15, -0.18), "intensity": 1.1, "color": (1.0, 0.93, 0.82)}]


def bump_tiles(s: int, nu: int, nv: int, radius: float = 0.38) -> np.ndarray:
    """A tileable height map of ``nu x nv`` round bumps (a cos^2 profile), values in [0, 1]."""
    r, c = np.mgrid[0:s, 0:s]
    u, v = (c + 0.5) / s, 1.0 - (r + 0.5) / s
    fu, fv = (u * nu) % 1.0 - 0.5, (v * nv) % 1.0 - 0.5
    d = np.hypot(fu, fv) / radius
    return np.cos(0.5 * np.pi * np.minimum(d, 1.0)) ** 2


def smooth_noise(s: int, seed: int = 0, waves: int = 14) -> np.ndarray:
    """A smooth tileable random height map in [0, 1] (a sum of random low-frequency waves)."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:s, 0:s] / s
    H = np.zeros((s, s))
    for _ in range(waves):
        kx, ky = rng.integers(1, 7, size=2) * rng.choice([-1, 1], size=2)
        H += rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * (kx * c + ky * r) + rng.uniform(0, 2 * np.pi))
    return (H - H.min()) / (H.max() - H.min())


def _view(V: np.ndarray, direction, size: int, fov: float = 30.0, margin: float = 1.04):
    """Eye and clip-from-world matrix of a camera looking at the bounding box of V from ``direction`` (z up)."""
    lo, hi = V.min(axis=0), V.max(axis=0)
    c, r = (lo + hi) / 2, 0.5 * float(np.linalg.norm(hi - lo))
    d = np.asarray(direction, float)
    d /= np.linalg.norm(d)
    dist = margin * r / np.sin(np.radians(fov) / 2)
    eye = c + dist * d
    M = camera.perspective_look_at(eye, c, (0, 0, 1), fov, 1.0, max(dist - 1.2 * r, 1e-3), dist + 1.2 * r)
    return eye, M


def _display(img) -> np.ndarray:
    """Linear RGB in [0, 1] as 8-bit display values (gamma 2.2)."""
    return (np.clip(img, 0.0, 1.0) ** (1 / 2.2) * 255).round().astype(np.uint8)


def _shaded(L, V, F, eye, M, size, lights, *, N=None, UV=None, tangents=None, normal_map=None, wrap="clamp"):
    g = L.rasterize_mesh(V, F, M, size, size, UV=UV, N=N, tangents=tangents)
    return _display(L.shade(g, lights, eye, ALBEDO, normal_map, wrap=wrap, **SHADING))


def _bumpy_torus(L, s: int):
    """The normal-mapped torus of the first and the GLSL figures: ``24 x 8`` bumps (an ``s x s`` height
    map) on a ``48 x 24`` UV torus. Returns ``H``, its normal map, ``V, F, UV``, the welded normals and
    the tangents ``(T, w)`` as one ``(n, 4)`` array."""
    H = bump_tiles(s, 24, 8)
    R, r, lam = TORUS_RADII + (BUMP_HEIGHT,)
    # Tangent-space slope of the relief: the UV square spans 2 pi R around and 2 pi r across.
    nmap = L.height_to_normal_map(H, (lam / (2 * np.pi * R), lam / (2 * np.pi * r)), border="wrap")
    V, F, UV = datasets.uv_torus(48, 24, R, r)
    N = L.welded_vertex_normals(V, F)
    T, _, _, w = L.tangent_frames(V, F, UV, N)
    return H, nmap, V, F, UV, N, np.column_stack([T, w])


def _grey(H: np.ndarray) -> np.ndarray:
    return (np.clip(H, 0, 1) * 255).round().astype(np.uint8)


def _thumb(img: np.ndarray, size: int) -> np.ndarray:
    """A map shown at ``size x size`` pixels next to the renders (Pillow's area-averaging resize)."""
    from PIL import Image

    return np.asarray(Image.fromarray(img).resize((size, size), Image.Resampling.BOX))


@figure_name("mapped_vs_displaced")
def _fig_mapped_vs_displaced(out: Path, L, quick: bool) -> list[Figure]:
    size, s = (160, 256) if quick else (300, 512)
    H, nmap, V, F, UV, N, tg = _bumpy_torus(L, s)
    dm, dn = (144, 48) if quick else (384, 128)
    Vd0, Fd, UVd = datasets.uv_torus(dm, dn, *TORUS_RADII)
    Vd, Nd = L.displace(Vd0, Fd, UVd, None, H, lam=BUMP_HEIGHT, wrap="repeat", return_normals=True)
    eye, M = _view(Vd, (0.15, -1.0, 0.85), size, margin=0.8)
    figs = []
    for name, lights, label in (
        ("mapped_vs_displaced", KEY_LIGHTS, "key and fill light"),
        ("mapped_vs_displaced_grazing", GRAZING_LIGHTS, "one grazing light"),
    ):
        plain = _shaded(L, V, F, eye, M, size, lights, N=N)
        mapped = _shaded(L, V, F, eye, M, size, lights, N=N, UV=UV, tangents=tg, normal_map=nmap, wrap="repeat")
        real = _shaded(L, Vd, Fd, eye, M, size, lights, N=Nd)
        imgs = [plain, mapped, real]
        caps = [
            f"plain: {len(F):,} faces, smooth normals",
            f"normal-mapped: the same {len(F):,} faces, per-pixel normals from the {s}x{s} map",
            f"displaced: {len(Fd):,} faces moved by λh along the normal",
        ]
        if name == "mapped_vs_displaced":
            imgs = [_thumb(_grey(H), size), _thumb(L.encode_normal_map(nmap), size)] + imgs
            caps = ["height map h (24 x 8 bumps)", "its tangent-space normal map (RGB = (n + 1) / 2)"] + caps
        img = panels(imgs, caps, ncols=len(imgs), title=f"Normal mapping vs displacement, {label}")
        path = save_png(out / f"{name}.png", img)
        figs.append(
            Figure(
                path,
                f"A torus shaded per pixel by the lab's Blinn-Phong shader ({label}). Normal mapping changes only the "
                f"normals: lit, the bumps look like the displaced ones, but the silhouette and the outline of the "
                f"inner ring stay smooth; displacement moves vertices and needs a {len(Fd) // len(F)}x denser mesh "
                f"(this shader casts no shadows, so neither version shows bump shadows).",
                LAB,
            )
        )
    return figs


@figure_name("maps_glsl")
def _fig_glsl(out: Path, L, quick: bool) -> Drawn:
    """The normal-mapped torus by the NumPy shader and by ``tbn.vert`` + ``normalmap.frag`` (tasks 7-8)."""
    size, s = (160, 256) if quick else (300, 512)
    H, nmap, V, F, UV, N, tg = _bumpy_torus(L, s)
    eye, M = _view(V, (0.15, -1.0, 0.85), size, margin=0.8)
    g = L.rasterize_mesh(V, F, M, size, size, UV=UV, N=N, tangents=tg)
    opts = dict(wrap="repeat", **SHADING)
    a = np.asarray(L.shade(g, KEY_LIGHTS, eye, ALBEDO, nmap, **opts), np.float64)
    b = np.asarray(L.glsl_shade(g, KEY_LIGHTS, eye, ALBEDO, nmap, **opts), np.float64)
    d = np.abs(a - b).max(axis=2)  # linear RGB in [0, 1], the largest channel
    d8 = d * 255
    hi = max(float(d8.max()), 1e-9)
    images = [
        _display(a),
        _display(b),
        with_colorbar(
            heatmap_image(d8, "magma_r", 0.0, hi),
            colorbar(0.0, hi, "magma_r", label="|NumPy - GLSL| x 255", height=size),
        ),
    ]
    covered = np.asarray(g.mask)
    captions = [
        "NumPy route: shade (the G-buffer's Blinn-Phong)",
        "GLSL route: tbn.vert + normalmap.frag",
        f"|difference|, largest RGB channel, in 8-bit levels\nmax {d8.max():.2g}",
    ]
    return Drawn.claimed(
        panels(images, captions, ncols=3, title="The shaders against the NumPy route (normal-mapped torus)"),
        "The normal-mapped torus of the first figure under the key and fill lights, shaded on one G-buffer twice: "
        "left by the NumPy route (shade), middle by the shaders (glsl_shade: the TBN matrix from tbn.vert, the "
        "tangent-space normal decoded and turned to world space and lit in normalmap.frag), right their difference "
        "per pixel, the largest of the three linear RGB channels in 8-bit levels (steps of 1/255). Over the "
        "{n:,} covered pixels they differ by at most {mx:.2g} levels (mean {mean:.2g}; {over:,} pixels above half "
        "a level, where rounding to whole levels could show): float32 against float64 arithmetic, the same picture.",
        n=int(covered.sum()), mx=float(d8.max()), mean=float(d8[covered].mean()), over=int((d8 > 0.5).sum()),
    )  # fmt: skip


@figure_name("bias_scale")
def _fig_bias_scale(out: Path, L, quick: bool) -> Drawn:
    from geomlib.render import render

    size, s = (160, 128) if quick else (300, 256)
    # Fade to mid-grey towards v = 0 and v = 1: every pole of the UV sphere is a whole row of the map.
    v = 1.0 - (np.arange(s) + 0.5) / s
    fade = np.minimum(1.0, (np.sin(np.pi * v) / np.sin(0.2 * np.pi)) ** 2)  # flat (zero slope) at the poles
    H = 0.5 + (smooth_noise(s, seed=3) - 0.5) * fade[:, None]
    V, F, UV = datasets.uv_sphere(32, 64) if quick else datasets.uv_sphere(96, 192)
    lam = 0.12
    imgs, caps = [_thumb(_grey(H), size)], ["displacement map h in [0, 1] (black = 0), mid-grey at the poles"]
    pairs = ((0.0, 1.0), (-1.0, 2.0), (-1.0, 5.0))
    for bias, scale in pairs:
        Vd = L.displace(V, F, UV, None, H, lam=lam, bias=bias, scale=scale, wrap="repeat")
        rad = np.linalg.norm(Vd, axis=1)
        imgs.append(render(Vd, F, camera="three_quarter", up_axis="z", size=(size, size)))
        caps.append(
            f"(bias, scale) = ({bias:g}, {scale:g}): offsets λ·[{bias:g}, {bias + scale:g}], radius {rad.min():.2f}..{rad.max():.2f}"
        )
    img = panels(imgs, caps, ncols=4, title="Displacement P' = P + λ (bias + scale h) n, λ = 0.12")
    (b0, s0), (b1, s1), (b2, s2) = pairs
    return Drawn.claimed(
        img,
        "One displacement map applied to a UV sphere with three (bias, scale) pairs: ({b0:g}, {s0:g}) only pushes "
        "outwards, ({b1:g}, {s1:g}) maps mid-grey to no offset so the surface moves both ways, ({b2:g}, {s2:g}) "
        "exaggerates the peaks. Seam copies are welded, so the sphere stays closed.",
        b0=b0, s0=s0, b1=b1, s1=s1, b2=b2, s2=s2,
    )  # fmt: skip


def _rock(L, quick: bool):
    """A detailed rock (built-in) and its decimated version with a one-chart-per-triangle atlas."""
    import fast_simplification

    Vh, Fh = datasets.rock_on_plinth(64 if quick else 160, seed=2)
    target = 400 if quick else 1200
    Vl, Fl = fast_simplification.simplify(Vh.astype(np.float32), Fh.astype(np.int32), target_count=target)
    Vl, Fl = np.asarray(Vl, np.float64), np.asarray(Fl, np.int64)
    # Decimated triangles vary a lot in size and shape: every chart gets half a cell (mode="fill").
    Vs, Fs, UV, src = triangle_atlas(Vl, Fl, gutter=0.04, mode="fill")
    N_lo = L.welded_vertex_normals(Vs, Fs)
    return Vh, Fh, Vl, Fl, Vs, Fs, UV, N_lo


@figure_name("bake")
def _fig_bake(out: Path, L, quick: bool) -> list[Figure]:
    size, s = (160, 128) if quick else (300, 512)
    Vh, Fh, Vl, Fl, Vs, Fs, UV, N_lo = _rock(L, quick)
    nmap, mask = L.bake_normal_map(Vh, Fh, Vs, Fs, UV, s, N_lo=N_lo, padding=4, return_mask=True)
    T, _, _, w = L.tangent_frames(Vs, Fs, UV, N_lo)
    tg = np.column_stack([T, w])
    Nh = L.welded_vertex_normals(Vh, Fh)
    eye, M = _view(Vh, (0.9, -1.0, 0.9), size, margin=0.85)
    enc = L.encode_normal_map(nmap)
    figs = []
    shots = {}
    for key, lights in (("key", KEY_LIGHTS), ("grazing", GRAZING_LIGHTS)):
        shots[key] = [
            _shaded(L, Vs, Fs, eye, M, size, lights, N=N_lo),
            _shaded(L, Vs, Fs, eye, M, size, lights, N=N_lo, UV=UV, tangents=tg, normal_map=enc),
            _shaded(L, Vh, Fh, eye, M, size, lights, N=Nh),
        ]
    caps = [
        f"decimated: {len(Fl):,} faces, smooth normals",
        f"decimated + baked {s}x{s} normal map",
        f"original: {len(Fh):,} faces",
    ]
    # Texels outside every chart would be flat-normal lilac like the flat areas: paint them dark grey.
    shown = np.array(enc[..., :3], dtype=np.uint8, copy=True)
    shown[~np.asarray(mask, bool)] = (70, 70, 70)
    img = panels(
        [_thumb(shown, size)] + shots["key"],
        [
            f"baked normal map, one chart per triangle: {100 * mask.mean():.0f}% of texels inside charts "
            "(dark grey: unused), flat areas lilac"
        ]
        + caps,
        ncols=4,
        title="Baking a normal map from a detailed rock onto its decimated version",
    )
    claims = Claims(
        "The built-in rock ({high:,} faces) decimated to {low:,} faces with fast-simplification; every "
        "triangle gets its own chart (triangle_atlas) and bake_normal_map casts from each texel along the low "
        "normal onto the detailed rock. Read back by the shader, the map restores the ridges and bumps the "
        "decimation removed.",
        {"high": len(Fh), "low": len(Fl)},
    )
    figs.append(Figure(save_png(out / "bake.png", img), claims.caption(), LAB, claims))
    img = panels(
        shots["key"] + shots["grazing"],
        [c + " — key + fill" for c in caps] + [c + " — grazing light" for c in caps],
        ncols=3,
        title="The baked rock under two lighting set-ups",
    )
    figs.append(
        Figure(
            save_png(out / "bake_lighting.png", img),
            "The same three rocks lit from above-front (key and fill, top row) and by a single grazing light from the "
            "side (bottom row). The baked normals respond to the light like the real geometry does; only the "
            "silhouette (the rock's outline, the plinth's corners) gives the simplified mesh away.",
            LAB,
        )
    )
    return figs


@figure_name("maps_3d")
def _fig_view(L, quick: bool) -> MeshView:
    R, r, lam = 1.0, 0.4, 0.045
    s = 128 if quick else 256
    H = bump_tiles(s, 24, 8)
    Vd0, Fd, UVd = datasets.uv_torus(*((144, 48) if quick else (288, 96)), R, r)
    Vd = L.displace(Vd0, Fd, UVd, None, H, lam=lam, wrap="repeat")
    return MeshView(
        Vd, Fd, title="Displaced torus (displace, Task 5)", up="z", edges=False,
        caption=Claims(
            "Turn it: the torus displaced by the bump height map ({faces:,} faces, coarser than the figures' mesh), "
            "the geometry a normal map imitates.",
            {"faces": len(Fd)},
        ),
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (_fig_mapped_vs_displaced, _fig_bias_scale, _fig_bake, _fig_glsl), _fig_view,
    quick="Smaller images and meshes (for the notebook and tests).",
)  # fmt: skip
