"""Figures of the shadow-mapping lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The file
is copied into ``labs/shadows/`` with the stubs, so there it renders *your* results (once your
functions work); compare them with ``docs/figures/shadows/``. Numbers in the captions (acne,
peter-panning, agreement) are measured against exact ray-cast shadows when the figure is made.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib.camera import project
from geomlib.labfigures import Claims, Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import colorbar, heatmap_image, panels, with_colorbar

__all__ = ["make_figures", "make_view"]

LAB = "shadows"
#: A closer look at the shadows of the tall box, the floating cube and the sphere.
ZOOM_CAMERA = (np.array([1.2, -2.5, 3.0]), np.array([0.3, 1.2, 0.0]), np.array([0.0, 0.0, 1.0]))
TORUS_CAMERA = (np.array([0.0, -5.5, 3.2]), np.array([0.0, 0.0, 1.2]), np.array([0.0, 0.0, 1.0]))
TORUS_LIGHT = {"type": "directional", "direction": np.array([0.5, 0.3, -0.8])}
SPOT_LIGHT = {
    "type": "spot",
    "position": np.array([-3.0, -3.5, 5.0]),
    "target": np.array([0.0, 0.0, 0.0]),
    "fov_deg": 70.0,
}
POINT_LIGHT = {"type": "point", "position": np.array([0.2, -0.3, 2.6])}


def _u8(img: np.ndarray) -> np.ndarray:
    return np.round(np.clip(img, 0, 1) * 255).astype(np.uint8)


def _pct(x: float) -> str:
    return "n/a" if not np.isfinite(x) else (f"{100 * x:.1f}%" if x >= 0.001 else f"{100 * x:.2f}%")


class _Measured:
    """Eye buffer and ray-cast truth of one view, shared by the panels of a figure."""

    def __init__(self, L, scene, camera, light, size):
        self.L, self.scene, self.camera, self.light, self.size = L, scene, camera, light, size
        self.eb = L.eye_gbuffer(scene, camera, size)
        self.truth = L.raycast_visibility(scene, self.eb, light)

    def render(self, band: int = 2, **options) -> tuple[np.ndarray, dict]:
        """The shaded image (uint8) with these shadow options, and its metrics against the truth.

        ``band`` as in ``shadow_metrics``: 0 counts every pixel, edges included.
        """
        L = self.L
        vis, _ = L.light_visibility(self.scene, self.eb, self.light, **options)
        return _u8(L.shade(self.eb, vis, self.light)), L.shadow_metrics(vis, self.truth, self.eb.mask, band=band)

    def panel(self, caption: str, **options) -> tuple[np.ndarray, str]:
        img, m = self.render(**options)
        return img, f"{caption}\nacne {_pct(m['acne'])}, peter-panning {_pct(m['peter_panning'])}"


_CACHE: dict = {}


def _panel_size(quick: bool) -> tuple[int, int]:
    """The (width, height) of every rendered panel."""
    return (240, 180) if quick else (400, 300)


def _measured(L, view: str, quick: bool) -> _Measured:
    """The classic scene under its light, seen from the course's camera (``view="classic"``) or from
    closer (``"zoom"``): one :class:`_Measured` per view and size, shared by the figures of one run."""
    size = _panel_size(quick)
    key = (view, size)
    if key not in _CACHE:
        camera = {"classic": L.CLASSIC_CAMERA, "zoom": ZOOM_CAMERA}[view]
        _CACHE[key] = _Measured(L, L.classic_scene(), camera, L.CLASSIC_LIGHT, size)
    return _CACHE[key]


@figure_name("shadows_bias")
def fig_bias(out: Path, L, quick: bool) -> Drawn:
    meas = _measured(L, "classic", quick)
    ms = 1024
    rows = [
        meas.panel("no bias, no culling: acne", map_size=ms, bias=0.0, slope_bias=0.0, cull="none", pcf=1),
        meas.panel("constant bias 0.002", map_size=ms, bias=0.002, slope_bias=0.0, cull="none", pcf=1),
        meas.panel("too much bias (0.1): peter-panning", map_size=ms, bias=0.1, slope_bias=0.0, cull="none", pcf=1),
        meas.panel("defaults: 1/size + 1.5 x slope", map_size=ms, pcf=1),
        meas.panel("front-face culling, no bias", map_size=ms, bias=0.0, slope_bias=0.0, cull="front", pcf=1),
        meas.panel("front-face culling + defaults", map_size=ms, cull="front", pcf=1),
    ]
    page = panels(
        [r[0] for r in rows], [r[1] for r in rows], ncols=3, title="Shadow acne, bias and peter-panning (1024² map)"
    )
    return Drawn(
        page,
        "Bias against acne. Without bias, every lit surface shadows itself in stripes (acne); a constant bias "
        "fixes flat surfaces seen head-on but not slanted ones; a large bias lifts the shadows off their "
        "casters (peter-panning: contact shadows at the box bases vanish). The slope-scaled default and "
        "front-face culling remove acne. Numbers: acne = share of truly lit surface shaded dark, "
        "peter-panning = share of contact shadow lost, both against ray-cast shadows.",
    )


def _outline(img: np.ndarray, meas: _Measured, corners: np.ndarray, colour=(255, 200, 0)) -> np.ndarray:
    """``img`` with the closed polygon ``corners`` (k, 3) of the world drawn in, seen by ``meas``'s camera."""
    from PIL import Image, ImageDraw

    w, h = meas.size
    M = meas.L.camera_matrix(meas.camera, meas.scene.bounds, (w, h))
    xy, _ = project(corners, M, w, h)
    page = Image.fromarray(img)
    ImageDraw.Draw(page).line([tuple(p) for p in np.vstack([xy, xy[:1]])], fill=colour, width=2)
    return np.asarray(page)


def _floor_footprint(M: np.ndarray) -> np.ndarray:
    """(4, 3): where the edges of an orthographic light map ``M`` (clip from world) meet the floor z = 0."""
    Minv = np.linalg.inv(M)
    out = []
    for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        a, b = (Minv @ np.array([x, y, z, 1.0]) for z in (-1.0, 1.0))
        a, b = a[:3] / a[3], b[:3] / b[3]
        out.append(a + (b - a) * (a[2] / (a[2] - b[2])))  # the light ray through this map corner, at z = 0
    return np.array(out)


@figure_name("shadows_frustum")
def fig_frustum(out: Path, L, quick: bool) -> Drawn:
    half, top = 1.5, 2.1
    B = np.array([[-half, -half, 0.0], [half, half, top]])  # the map covers the middle of the floor only
    meas = _measured(L, "classic", quick)
    off = meas.panel("frustum fix off: border texels repeat, far side dark", map_size=1024, bounds=B, frustum_fix=False)
    on = meas.panel("fix on: outside is lit (the sphere's shadow too)", map_size=1024, bounds=B, frustum_fix=True)
    full = meas.panel("map fitted to the whole scene", map_size=1024)
    foot = _floor_footprint(L.light_setup(meas.scene, meas.light, bounds=B).matrices[0])
    imgs = [_outline(off[0], meas, foot), _outline(on[0], meas, foot), full[0]]
    page = panels(
        imgs, [off[1], on[1], full[1]], title="Points outside the light's frustum (yellow: where the map ends)"
    )
    return Drawn.claimed(
        page,
        "A directional light whose map is fitted to the box [-{half:g}, {half:g}]² x [{floor:g}, {top:g}] in the middle of "
        "the floor; yellow outlines where the map's edges meet the floor (the slanted light's view of that box). "
        "Points outside it read clamped border texels, so the texels along the map's edge repeat outwards as "
        "dark wedges, and points beyond its far plane (z > 1) always compare as shadowed; treating both as lit "
        "fixes it, but shadows that fall outside the map (the sphere's) are lost. Right: the map fitted tightly "
        "to the scene's bounds covers everything.",
        half=half, floor=B[0, 2], top=top,
    )  # fmt: skip


@figure_name("shadows_resolution")
def fig_resolution(out: Path, L, quick: bool) -> Drawn:
    meas = _measured(L, "zoom", quick)
    sizes = (256, 1024, 2048) if quick else (256, 1024, 4096)
    rows = []
    for s in sizes:
        # Away from shadow edges every map size agrees with ray casting; what resolution changes is the
        # edges. So count every shaded pixel (band=0) whose lit/dark verdict differs from the truth.
        img, m = meas.render(band=0, map_size=s, pcf=1)
        wrong = round((1.0 - m["agreement"]) * m["measured"])
        rows.append((img, f"{s}² map, PCF 1\n{wrong:,} pixels differ from ray casting"))
    page = panels([r[0] for r in rows], [r[1] for r in rows], title="Shadow-map resolution")
    return Drawn(
        page,
        "The same view with shadow maps of increasing size (hard 0/1 comparison). A coarse map makes jagged, "
        "blocky shadow edges (each texel is a block of the floor). The count under each panel is the number of "
        "pixels whose lit/shadowed verdict differs from exact ray-cast shadows: all of them lie along the shadow "
        "edges, and there are fewer as the map grows.",
    )


@figure_name("shadows_pcf")
def fig_pcf(out: Path, L, quick: bool) -> Drawn:
    meas = _measured(L, "zoom", quick)
    res, sizes = 512, (1, 3, 5)
    poisson = dict(map_size=res, pcf=sizes[-1], pcf_sampling="poisson")
    runs = [meas.render(map_size=res, pcf=k) for k in sizes] + [meas.render(**poisson)]
    labels = [f"PCF {k} x {k}, {res}² map" for k in sizes] + ["Poisson disk: 16 samples, radius 2.5 texels"]
    # The close-ups: the window where the 1 x 1 and the Poisson pictures differ most (a shadow edge).
    d = np.abs(runs[0][0].astype(float) - runs[-1][0].astype(float)).sum(axis=2)
    ch, cw = (d.shape[0] // 6, d.shape[1] // 6)
    S = np.pad(d.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    win = S[ch:, cw:] - S[:-ch, cw:] - S[ch:, :-cw] + S[:-ch, :-cw]
    r, c = np.unravel_index(np.argmax(win), win.shape)
    zoom = 4
    imgs, caps = [], []
    for (img, m), label in zip(runs, labels):
        framed = img.copy()
        framed[r : r + ch, [c, c + cw - 1]] = framed[[r, r + ch - 1], c : c + cw] = (255, 200, 0)
        crop = np.repeat(np.repeat(img[r : r + ch, c : c + cw], zoom, 0), zoom, 1)
        imgs += [framed, crop]
        caps += [f"{label}\nacne {_pct(m['acne'])}, peter-panning {_pct(m['peter_panning'])}", f"x{zoom} close-up"]
    page = panels(imgs, caps, ncols=4, title="Percentage-closer filtering (yellow box: the close-up)")
    pp = [m["peter_panning"] for _, m in runs]
    return Drawn.claimed(
        page,
        "Percentage-closer filtering averages the 0/1 shadow test over a k x k block of texels around the "
        "point, turning the staircase of a {res}² map into a soft edge about k texels wide (close-ups on the "
        "right of each panel). It filters the test results, not the depths: averaging depths first would blur "
        "the occluder, not the shadow. The last panel spreads {samples} samples over a disk instead, rotated "
        "differently at every texel: the square block's bands along the edge become fine noise, with {samples} "
        "lookups instead of {block}. The price: a wider filter reaches past the occluder's edge, so "
        "peter-panning (light where the truth is shadow) grows from {pp1:.1f}% (no filter) to {pp5:.1f}% "
        "({k5} x {k5}) and {ppp:.1f}% (Poisson).",
        res=res, samples=len(L.poisson_disk()), block=sizes[-1] ** 2,
        pp1=100 * pp[0], pp5=100 * pp[2], k5=sizes[-1], ppp=100 * pp[3],
    )  # fmt: skip


@figure_name("shadows_pyrender")
def fig_pyrender(out: Path, L, quick: bool) -> Drawn:
    size = _panel_size(quick)
    scene = L.torus_scene(125, 50) if quick else L.torus_scene()
    meas = _Measured(L, scene, TORUS_CAMERA, TORUS_LIGHT, size)
    vis, _ = L.light_visibility(scene, meas.eb, TORUS_LIGHT, map_size=2048, pcf=3)
    ours_img = _u8(L.shade(meas.eb, vis, TORUS_LIGHT))
    ps, rend, pyrender = L.pyrender_scene(scene, TORUS_CAMERA, TORUS_LIGHT, size=size)
    py_img = np.asarray(rend.render(ps, flags=pyrender.RenderFlags.SHADOWS_DIRECTIONAL)[0])[:, :, :3].copy()
    # pyrender clears to black; give its empty pixels our background so the two panels compare.
    py_img[~meas.eb.mask] = ours_img[~meas.eb.mask]
    pv = L.pyrender_visibility(scene, TORUS_CAMERA, TORUS_LIGHT, size=size)
    h, w = meas.eb.mask.shape
    flat = np.flatnonzero(meas.eb.mask.ravel())
    reached = meas.truth["reached"]
    truth_img = np.full(h * w, np.nan)
    truth_img[flat[reached]] = meas.truth["lit"][reached]
    err_ours = np.full(h * w, np.nan)
    err_ours[flat[reached]] = np.abs(vis[reached] - meas.truth["lit"][reached])
    pvk = np.nan_to_num(pv.ravel()[flat])
    err_py = np.full(h * w, np.nan)
    err_py[flat[reached]] = np.abs(pvk[reached] - meas.truth["lit"][reached])
    m_ours = L.shadow_metrics(vis, meas.truth, meas.eb.mask, band=0)
    m_py = L.shadow_metrics(pvk, meas.truth, meas.eb.mask, band=0)

    def wrong(m):
        return f"{round((1.0 - m['agreement']) * m['measured']):,} pixels differ from the truth"

    grey = (205, 215, 230)
    images = [
        ours_img,
        py_img,
        heatmap_image(truth_img.reshape(h, w), "gray", 0, 1, nan_color=grey),
        heatmap_image(err_ours.reshape(h, w), "magma_r", 0, 1, nan_color=grey),
        with_colorbar(
            heatmap_image(err_py.reshape(h, w), "magma_r", 0, 1, nan_color=grey),
            colorbar(0, 1, "magma_r", label="|visibility - truth|", height=h),
        ),
    ]
    captions = [
        f"ours: 2048² map, PCF 3\nacne {_pct(m_ours['acne'])}, {wrong(m_ours)}",
        f"pyrender SHADOWS_DIRECTIONAL\nacne {_pct(m_py['acne'])}, {wrong(m_py)}",
        "ray-cast truth: white lit, black shadow\n(grey-blue: turned away from the light)",
        "error of ours",
        "error of pyrender",
    ]
    page = panels(images, captions, ncols=3, title=f"Against pyrender and exact shadows ({len(scene.F):,} faces)")
    return Drawn(
        page,
        "A bumpy torus above a floor. Our render (Blinn-Phong, receiver-plane slope-scaled bias, no culling) next to "
        "pyrender's own shadow mapping of the same scene, camera and light, and exact shadows by one ray "
        "per pixel. Error maps: pyrender's constant bias leaves acne (dark speckle) on the curved, slanted "
        "parts of the torus; ours differs from the truth only along shadow edges.",
    )


@figure_name("shadows_lights")
def fig_lights(out: Path, L, quick: bool) -> Drawn:
    size = _panel_size(quick)
    scene = L.classic_scene()
    ms = 512 if quick else 1024
    spot = _u8(L.render_with_shadows(scene, L.CLASSIC_CAMERA, SPOT_LIGHT, size=size, map_size=ms))
    point = _u8(L.render_with_shadows(scene, L.CLASSIC_CAMERA, POINT_LIGHT, size=size, map_size=ms))
    M = L.light_setup(scene, L.CLASSIC_LIGHT).matrices[0]
    D = L.depth_map(scene.V, scene.F, M, size[1], cull="none")
    # Empty texels (depth 1) in light grey and a dark frame: the map's square extent stays visible.
    depth_img = heatmap_image(np.where(D < 1, D, np.nan), "viridis", nan_color=(235, 235, 235))
    depth_img = np.pad(depth_img, ((2, 2), (2, 2), (0, 0)), constant_values=60)
    bar = colorbar(float(D[D < 1].min()), float(D[D < 1].max()), "viridis", label="window depth", height=size[1])
    page = panels(
        [with_colorbar(depth_img, bar), spot, point],
        [
            "the directional light's depth map, framed\n(row 0 = top; grey: no surface)",
            "spot light: perspective map, 70° cone",
            "point light: six-face cube map",
        ],
        title="What the light sees, and other lights",
    )
    return Drawn.claimed(
        page,
        "Left: the depth map of the classic scene from the directional light (orthographic, fitted to the "
        "scene's bounds; nearer is darker). The fit is to the bounding box, not to what the light actually sees: "
        "{empty:.0f}% of its texels stay empty (grey), resolution a tighter footprint fit would give back. Right: "
        "the same scene lit by a spot light (one perspective map) and by a point light above the boxes (six square "
        "maps, one per face of a cube).",
        empty=100 * float(np.mean(D >= 1)),
    )


def _vis_image(eb, vis: np.ndarray) -> np.ndarray:
    """A visibility per covered pixel as an (h, w) image, NaN on the background."""
    img = np.full(eb.mask.shape, np.nan)
    img[eb.mask] = vis
    return img


@figure_name("shadows_glsl")
def fig_glsl(out: Path, L, quick: bool) -> Drawn:
    """The same pictures by the NumPy route and by the GLSL shaders (tasks 9-12), and their difference."""
    meas = _measured(L, "zoom", quick)
    S, eb = meas.scene, meas.eb
    ms = 512 if quick else 1024
    # Directional light: depth pass and lookup, PCF 3, the defaults' bias (tasks 2-7 against 9-10).
    M = L.light_setup(S, L.CLASSIC_LIGHT).matrices[0]
    D_np = L.depth_map(S.V, S.F, M, ms, cull="none")
    D_gl = L.glsl_depth_map(S.V, S.F, M, ms, cull="none")
    v_np = L.shadow_visibility(eb.P, eb.N_face, D_np, M, pcf=3)
    v_gl = L.glsl_shadow_visibility(eb.P, eb.N_face, D_gl, M, pcf=3)
    # Point light: the linear cube pass and lookup (tasks 11-12 against their NumPy twins).
    setup = L.light_setup(S, POINT_LIGHT)
    pos, near, far = setup.light["position"], setup.near, setup.far
    cs = ms // 2
    C_np = L.cube_distance_maps(S.V, S.F, pos, cs, near, far, cull="front")
    C_gl = L.glsl_cube_depth_maps(S.V, S.F, pos, cs, near, far, cull="front")
    p_np = L.linear_point_shadow_visibility(eb.P, eb.N_face, C_np, pos, near, far)
    p_gl = L.glsl_point_shadow_visibility(eb.P, eb.N_face, C_gl, pos, near, far)
    grey = (205, 215, 230)
    rows, caps, stats = [], [], {}
    for key, light, a, b, what in (
        ("dir", L.CLASSIC_LIGHT, v_np, v_gl, f"directional light, {ms}² map, PCF 3 x 3"),
        ("pt", POINT_LIGHT, p_np, p_gl, f"point light, six {cs}² linear-depth faces"),
    ):
        diff = np.abs(a - b)
        stats[key] = (int((diff > 1e-6).sum()), float(diff.max()), len(diff))  # 1e-6: the graded tolerance
        rows += [
            _u8(L.shade(eb, a, light)),
            _u8(L.shade(eb, b, light)),
            # On the graded tolerance's scale: how far each pixel is from failing (0..1 visibility
            # would paint every pixel the same colour).
            with_colorbar(
                heatmap_image(_vis_image(eb, diff / 1e-6), "magma_r", 0, 1, nan_color=grey),
                colorbar(0, 1, "magma_r", label="|NumPy - GLSL| / 1e-6", height=eb.mask.shape[0]),
            ),
        ]
        n, mx, tot = stats[key]
        caps += [
            f"NumPy route: {what}",
            "GLSL route: the same, by the shaders",
            f"|difference| in units of the graded tolerance 1e-6\n{n:,} of {tot:,} pixels beyond it, max {mx:.3g}",
        ]
    cov = (D_np < 1) != (D_gl < 1)
    both = (D_np < 1) & (D_gl < 1)
    ecov = np.abs(C_np - C_gl) > 1e-3
    page = panels(rows, caps, ncols=3, title="The shaders against the NumPy route (same scene, same light, same map)")
    d_cov = int(cov.sum())
    # Words that agree with a measured count ("1 texel is", "2 texels are"); the counts stay fields.
    d_differ, p_differ = ("differs" if stats[key][0] == 1 else "differ" for key in ("dir", "pt"))
    texels_are = "texel is" if d_cov == 1 else "texels are"
    return Drawn.claimed(
        page,
        "Each row renders the same view twice: left with the NumPy route (depth_map and shadow_visibility; "
        "cube_distance_maps and linear_point_shadow_visibility), middle with the lab's GLSL shaders "
        "(depth.vert/.frag and shadow.frag; cube_depth.vert/.frag and cube_shadow.frag), right the difference "
        "of the two visibilities per pixel, in units of the graded tolerance {tol_vis:g} (a visibility runs from "
        "shadow to lit). Directional light: "
        "{d_n:,} of {d_t:,} pixels " + d_differ + " by more than {tol_vis:g} (max {d_mx:.3g}); the {ms}² depth "
        "maps agree to {d_depth:.2g} in window depth where both hold a surface, and {d_cov:,} " + texels_are + " "
        "covered in one map only. Point light: {p_n:,} of {p_t:,} pixels " + p_differ + " (max {p_mx:.3g}); the "
        "linear cube maps differ by more than {tol_depth:g} (distance / far) in {p_cov:,} of {p_all:,} texels. "
        "What differs sits on texel borders, where the GPU's rasterizer and the NumPy route round a tie "
        "differently (the handout's GLSL section gives the tolerances).",
        tol_vis=1e-6, tol_depth=1e-3, d_n=stats["dir"][0], d_t=stats["dir"][2], d_mx=stats["dir"][1], ms=ms,
        d_depth=float(np.abs(D_np - D_gl)[both].max()), d_cov=d_cov,
        p_n=stats["pt"][0], p_t=stats["pt"][2], p_mx=stats["pt"][1], p_cov=int(ecov.sum()), p_all=ecov.size,
    )  # fmt: skip


def _refine_soup(V: np.ndarray, F: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Split every triangle into n*n triangles (a soup: no shared vertices), so shadows show per face."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    i, j = i[keep], j[keep]
    bary = np.stack([n - i - j, i, j], axis=1) / n  # (p, 3) points of one triangle
    index = -np.ones((n + 1, n + 1), dtype=np.int64)
    index[i, j] = np.arange(len(i))
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up = (a + b) < n
    dn = (a + b) < n - 1
    T = np.r_[
        np.stack([index[a[up], b[up]], index[a[up] + 1, b[up]], index[a[up], b[up] + 1]], axis=1),
        np.stack([index[a[dn] + 1, b[dn]], index[a[dn] + 1, b[dn] + 1], index[a[dn], b[dn] + 1]], axis=1),
    ]
    P = np.einsum("pk,fkd->fpd", bary, V[F]).reshape(-1, 3)
    return P, (T[None] + (len(i) * np.arange(len(F)))[:, None, None]).reshape(-1, 3)


@figure_name("shadows_3d")
def fig_view(L, quick: bool) -> MeshView:
    scene = L.classic_scene()
    V, F = _refine_soup(scene.V, scene.F, 3 if quick else 5)
    M = L.light_setup(scene, L.CLASSIC_LIGHT).matrices[0]
    res, k = 1024, 3
    D = L.depth_map(scene.V, scene.F, M, res)
    e1, e2 = V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]
    N = np.cross(e1, e2)
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    vis = L.shadow_visibility(V[F].mean(axis=1), N, D, M, pcf=k)
    return MeshView(
        V, F, vis, title="Classic scene: light visibility per face", up="z",
        cmap="gray", clim=(0.0, 1.0), edges=False, scalar_name="visibility",
        caption=Claims(
            "Turn it: every face of the classic scene coloured by the visibility of the directional light the "
            "shadow map gives (white lit, black in shadow, {res} x {res} map, {k} x {k} PCF): the shadows stay "
            "attached to their casters from every side.",
            {"res": res, "k": k},
        ),
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (fig_bias, fig_frustum, fig_resolution, fig_pcf, fig_pyrender, fig_lights, fig_glsl),
    fig_view,
    quick="Smaller images and maps (for the notebook and CI).", shared=_CACHE,
)  # fmt: skip
