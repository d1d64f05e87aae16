"""Ground truth and measurements: exact shadows by ray casting, and pyrender's shadows (given).

The shadow map answers "is this point lit?" approximately, from a sampled depth image. The exact
answer comes from casting a ray from the point towards the light and asking whether it hits the
scene (:func:`raycast_visibility`, with :func:`geomlib.geometry.ray_cast`, a watertight ray caster).
:func:`shadow_metrics` compares the two over the pixels the light reaches:

* **agreement**: fraction of pixels where the shadow map and the rays agree (lit = visibility
  >= 0.5), not counting a band of ``band`` pixels along the true shadow edges, where a sampled
  map cannot be exact;
* **acne**: how much of the truly lit surface (outside the band) the map shades dark: the mean of
  ``1 - visibility`` over those pixels (for hard 0/1 shadows, the fraction of them shaded dark);
* **peter-panning**: fraction of the *contact* shadow (pixels in a true shadow cast by another
  object that is closer than ``contact`` along the ray, i.e. right next to where the caster touches
  the receiver) that the map finds lit: shadows detached from their casters.

:func:`pyrender_visibility` renders the same scene with pyrender's own shadow mapping
(``RenderFlags.SHADOWS_DIRECTIONAL``) for comparison.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from geomlib.geometry import ray_cast
from geomlib.validate import check_float, check_int

from .scene import Scene, as_camera, as_light, as_scene
from .shading import EyeBuffer, _light_dirs, eye_gbuffer, light_visibility

__all__ = ["raycast_visibility", "shadow_metrics", "shadow_report", "pyrender_scene", "pyrender_visibility"]


def raycast_visibility(scene, eb: EyeBuffer, light) -> dict:
    """Exact shadows of the eye's points by casting one ray per point towards the light.

    Returns
    -------
    dict of (k,) arrays, one entry per covered pixel of ``eb``
        ``lit`` (bool): no part of the scene lies between the point and the light.
        ``dist`` (float): distance to the nearest occluder along the ray (inf where lit).
        ``other`` (bool): the occluder belongs to another mesh of the scene than the point (a cast
        shadow rather than the object shadowing itself).
        ``reached`` (bool): the light reaches the point's side of the surface at all (``n . l > 0``
        with the face normal turned towards the eye, and inside a spot light's cone). Only these
        pixels are measured.
    """
    S = as_scene(scene, "raycast_visibility")
    L = as_light(light, "raycast_visibility")
    to_light, strength = _light_dirs(L, eb.P)
    n = eb.N_face * np.where(np.einsum("ij,ij->i", eb.N_face, eb.eye - eb.P) < 0, -1.0, 1.0)[:, None]
    reached = (np.einsum("ij,ij->i", n, to_light) > 0) & (strength > 0)
    diag = float(np.linalg.norm(S.bounds[1] - S.bounds[0]))
    eps = 1e-6 * diag
    idx = np.flatnonzero(reached)
    k = len(eb.P)
    out = {"lit": np.zeros(k, bool), "dist": np.full(k, np.inf), "other": np.zeros(k, bool), "reached": reached}
    if len(idx):
        O, Dir = eb.P[idx], np.ascontiguousarray(to_light[idx])
        hit, t, face, _ = ray_cast(S.V, S.F, O, Dir, t_min=eps)
        if L["type"] != "directional":  # occluders beyond the light do not count
            hit &= t < np.linalg.norm(L["position"] - O, axis=1) - eps
        out["lit"][idx] = ~hit
        out["dist"][idx] = np.where(hit, t, np.inf)
        out["other"][idx] = hit & (S.mesh_id[np.maximum(face, 0)] != S.mesh_id[eb.face[idx]])
    return out


def shadow_metrics(vis, truth: dict, mask, *, band: int = 2, contact: float = 0.1) -> dict:
    """Compare shadow-map visibility with the ray-cast truth (see the module docstring).

    Parameters
    ----------
    vis : (k,) float
        Shadow-map visibility of the covered pixels (``mask`` order).
    truth : dict
        From :func:`raycast_visibility` for the same pixels.
    mask : (h, w) bool
        Covered pixels.
    band : int
        Half-width in pixels of the band around true shadow edges left out of agreement and acne.
    contact : float
        A true shadow cast by another object whose occluder is closer than this (world units) is
        contact shadow.

    Returns
    -------
    dict
        ``agreement``, ``acne``, ``peter_panning`` (fractions; NaN when a set is empty) and the pixel
        counts ``measured``, ``lit``, ``contact``.
    """
    band = check_int(band, "band", minimum=0, where="shadow_metrics")
    contact = check_float(contact, "contact", minimum=0.0, where="shadow_metrics")
    lit, reached = truth["lit"], truth["reached"]
    h, w = mask.shape
    lit_img = np.zeros((h, w), bool)
    dark_img = np.zeros((h, w), bool)
    flat = np.flatnonzero(mask.ravel())
    lit_img.ravel()[flat[reached & lit]] = True
    dark_img.ravel()[flat[reached & ~lit]] = True
    if band > 0:
        st = np.ones((2 * band + 1, 2 * band + 1), bool)
        edge = ndimage.binary_dilation(lit_img, st) & ndimage.binary_dilation(dark_img, st)
    else:
        edge = np.zeros((h, w), bool)
    keep = reached & ~edge.ravel()[flat]
    ours_lit = np.asarray(vis) >= 0.5

    def frac(sel):
        return float(sel.mean()) if sel.size else float("nan")

    close = reached & ~lit & truth["other"] & (truth["dist"] < contact)
    return {
        "agreement": frac(ours_lit[keep] == lit[keep]),
        "acne": float(np.mean(1.0 - np.asarray(vis, float)[keep & lit])) if (keep & lit).any() else float("nan"),
        "peter_panning": frac(ours_lit[close]),
        "measured": int(keep.sum()),
        "lit": int((keep & lit).sum()),
        "contact": int(close.sum()),
    }


def shadow_report(
    scene, camera, light, *, size=(256, 256), fov_deg: float = 40.0, band: int = 2, contact: float = 0.1, **options
) -> dict:
    """Shadow-map visibility and ray-cast truth for one view, with :func:`shadow_metrics`.

    ``options`` go to :func:`light_visibility` (``map_size``, ``bias``, ``slope_bias``, ``pcf``,
    ``cull``, ``frustum_fix``, ``bounds``). Returns the metrics plus ``"vis"`` and ``"truth"``
    images ``(h, w)`` (NaN on the background; truth is 1 lit, 0 shadowed, NaN where not measured).
    """
    S = as_scene(scene, "shadow_report")
    eb = eye_gbuffer(S, camera, size, fov_deg)
    vis, _ = light_visibility(S, eb, light, **options)
    truth = raycast_visibility(S, eb, light)
    out = shadow_metrics(vis, truth, eb.mask, band=band, contact=contact)
    lit, reached = truth["lit"], truth["reached"]
    h, w = eb.mask.shape
    flat = np.flatnonzero(eb.mask.ravel())
    vis_img = np.full(h * w, np.nan)
    vis_img[flat] = vis
    truth = np.full(h * w, np.nan)
    truth[flat[reached]] = lit[reached]
    out["vis"], out["truth"] = vis_img.reshape(h, w), truth.reshape(h, w)
    out["reached"] = np.zeros(h * w, bool)
    out["reached"][flat[reached]] = True
    out["reached"] = out["reached"].reshape(h, w)
    return out


def pyrender_scene(scene: Scene, camera, light, *, size=(256, 256), fov_deg: float = 40.0):
    """The scene, camera and directional light as a pyrender scene (flat faces, white matte, no ambient).

    Returns
    -------
    (pyrender.Scene, pyrender.OffscreenRenderer, pyrender module)
        Render with ``renderer.render(scene, flags=pyrender.RenderFlags.SHADOWS_DIRECTIONAL)``.
    """
    from geomlib.camera import look_at
    from geomlib.render import import_pyrender, offscreen_renderer

    pyrender = import_pyrender()
    S = as_scene(scene, "pyrender_scene")
    L = as_light(light, "pyrender_scene")
    if L["type"] != "directional":
        raise ValueError("pyrender_scene: only directional lights are compared")
    eye, target, up = as_camera(camera, "pyrender_scene")
    w, h = size
    B = S.bounds
    c, r = B.mean(axis=0), 0.5 * np.linalg.norm(B[1] - B[0])
    dist = np.linalg.norm(eye - c)
    far = dist + r
    near = max(dist - r, 1e-3 * far)
    Vs, Fs = S.V[S.F.ravel()], np.arange(3 * len(S.F)).reshape(-1, 3)  # flat faces
    fn = np.cross(S.V[S.F[:, 1]] - S.V[S.F[:, 0]], S.V[S.F[:, 2]] - S.V[S.F[:, 0]])
    fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
    mat = pyrender.MetallicRoughnessMaterial(
        baseColorFactor=[1.0, 1.0, 1.0, 1.0], metallicFactor=0.0, roughnessFactor=1.0
    )
    prim = pyrender.Primitive(
        positions=Vs.astype(np.float32), normals=np.repeat(fn, 3, axis=0).astype(np.float32), indices=Fs.astype(np.uint32),
        material=mat,
    )  # fmt: skip
    ps = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
    ps.add(pyrender.Mesh(primitives=[prim]))
    pose = np.linalg.inv(look_at(eye, target, up))
    ps.add(pyrender.PerspectiveCamera(yfov=np.radians(fov_deg), znear=near, zfar=far, aspectRatio=w / h), pose=pose)
    z = -L["direction"]
    helper = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    lp = np.eye(4)
    lp[:3, 0], lp[:3, 1], lp[:3, 2] = x, np.cross(z, x), z  # a directional light shines along its -z axis
    ps.add(pyrender.DirectionalLight(color=[1.0, 1.0, 1.0], intensity=3.0), pose=lp)
    return ps, offscreen_renderer(w, h), pyrender


def pyrender_visibility(scene: Scene, camera, light, *, size=(256, 256), fov_deg: float = 40.0) -> np.ndarray:
    """pyrender's shadows for the same scene, camera and directional light, as a visibility image.

    The scene is rendered twice by pyrender on OSMesa (:func:`pyrender_scene`: lit only by the
    directional light, no ambient, matte material), with and without
    ``RenderFlags.SHADOWS_DIRECTIONAL``; the ratio of the two is pyrender's visibility.

    Returns
    -------
    (h, w) float64
        pyrender's visibility in [0, 1], NaN where the unshadowed render is black (background).
        Only pixels the light reaches (``n . l > 0``) are meaningful.
    """
    ps, rend, pyrender = pyrender_scene(scene, camera, light, size=size, fov_deg=fov_deg)
    plain, _ = rend.render(ps, flags=pyrender.RenderFlags.NONE)
    shadowed, _ = rend.render(ps, flags=pyrender.RenderFlags.SHADOWS_DIRECTIONAL)
    a = np.asarray(plain, float).mean(axis=2)
    b = np.asarray(shadowed, float).mean(axis=2)
    # pyrender writes pow(linear, 1 / 2.2): undo it so partial (PCF) shadows keep their fraction.
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(a > 2.0, np.clip(b / a, 0.0, 1.0) ** 2.2, np.nan)
    return v
