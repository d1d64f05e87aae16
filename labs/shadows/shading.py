"""Shadowed Blinn-Phong rendering through the rasterizer (given code that uses your tasks).

:func:`render_with_shadows` runs the two passes of shadow mapping on a :class:`Scene`:

1. the depth pass from the light (:func:`light_setup`, :func:`depth_map`, or the six maps of
   :func:`cube_depth_maps` for a point light);
2. the eye pass: :func:`eye_gbuffer` rasterizes the scene from the camera, giving for every pixel
   the surface point, its face normal and its shading normal; :func:`shadow_visibility` then says how
   much light reaches each point, and Blinn-Phong shading scales the light's diffuse and specular
   terms by it (the ambient term is not shadowed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.camera import perspective_look_at
from geomlib.geometry import face_normals
from geomlib.raster import rasterize
from geomlib.validate import MeshError, as_array, check_float, check_int

from .cubemap import cube_depth_maps, point_shadow_visibility
from .depth import depth_map
from .lights import directional_light_matrix, spot_light_matrix
from .lookup import DEFAULT_MAX_SLOPE, shadow_visibility
from .options import ShadowOptions, keyword_defaults
from .scene import Scene, as_camera, as_light, as_scene

__all__ = [
    "EyeBuffer",
    "LightSetup",
    "camera_matrix",
    "eye_gbuffer",
    "light_setup",
    "light_visibility",
    "shade",
    "render_with_shadows",
]

#: Background colour of renders (RGB in [0, 1]).
BACKGROUND = (0.92, 0.94, 0.97)


@dataclass(eq=False)
class EyeBuffer:
    """What the eye sees, per pixel (row 0 = top); arrays over the covered pixels are ``(k, ...)``.

    Attributes
    ----------
    mask : (h, w) bool
        Pixels covered by the scene.
    P : (k, 3) float64
        World position of the surface at each covered pixel (in ``mask`` order, row-major).
    N_face : (k, 3) float64
        Unit geometric normal of the visible triangle (for the bias and the ray-cast truth).
    N_shade : (k, 3) float64
        Unit interpolated shading normal.
    albedo : (k, 3) float64
        Surface colour.
    face : (k,) int64
        Visible triangle.
    eye : (3,) float64
        Camera position.
    """

    mask: np.ndarray
    P: np.ndarray
    N_face: np.ndarray
    N_shade: np.ndarray
    albedo: np.ndarray
    face: np.ndarray
    eye: np.ndarray


@dataclass(eq=False)
class LightSetup:
    """Shadow-map matrices of a light: one for directional and spot lights, six for a point light."""

    light: dict
    matrices: np.ndarray  # (1, 4, 4) or (6, 4, 4)
    near: float = 0.0
    far: float = 0.0


def _size(size, where: str) -> tuple[int, int]:
    if not isinstance(size, tuple | list) or len(size) != 2:
        raise MeshError(f"{where}: size must be (width, height) in pixels, got {size!r}")
    return (
        check_int(size[0], "size[0] (width)", minimum=1, maximum=8192, where=where),
        check_int(size[1], "size[1] (height)", minimum=1, maximum=8192, where=where),
    )


def camera_matrix(camera, bounds, size: tuple[int, int], fov_deg: float = 40.0) -> np.ndarray:
    """Clip-from-world matrix of an ``(eye, target[, up])`` camera, near and far fitted to ``bounds``."""
    where = "camera_matrix"
    eye, target, up = as_camera(camera, where)
    B = as_array(bounds, "bounds", shape=(2, 3), where=where)
    c, r = B.mean(axis=0), 0.5 * np.linalg.norm(B[1] - B[0])
    dist = np.linalg.norm(eye - c)
    far = dist + r
    near = max(dist - r, 1e-3 * far)
    w, h = size
    return perspective_look_at(eye, target, up, fov_deg, w / h, near, far)


def eye_gbuffer(scene, camera, size: tuple[int, int] = (512, 512), fov_deg: float = 40.0) -> EyeBuffer:
    """Rasterize the scene from the camera: surface points and normals per pixel (given).

    Parameters
    ----------
    scene : Scene or list of meshes
    camera : (eye, target) or (eye, target, up)
    size : (width, height)
    fov_deg : float
        Vertical field of view.
    """
    where = "eye_gbuffer"
    S = as_scene(scene, where)
    w, h = _size(size, where)
    fov = check_float(fov_deg, "fov_deg", minimum=1.0, maximum=170.0, where=where)
    M = camera_matrix(camera, S.bounds, (w, h), fov)
    g = rasterize(S.V, S.F, M, w, h)
    pix = np.flatnonzero(g.mask.ravel())
    face = g.face_id.ravel()[pix]
    bary = g.bary.reshape(-1, 3)[pix]
    corners = S.F[face]
    P = np.einsum("ki,kij->kj", bary, S.V[corners])
    Ns = np.einsum("ki,kij->kj", bary, S.normals[corners])
    Ns /= np.maximum(np.linalg.norm(Ns, axis=1, keepdims=True), 1e-300)
    Nf = face_normals(S.V, S.F)[face]
    return EyeBuffer(g.mask, P, Nf, Ns, S.face_colors[face], face, as_camera(camera, where)[0])


def light_setup(scene: Scene, light, *, bounds=None) -> LightSetup:
    """The light-space matrices of a light for a scene (given).

    A directional light's orthographic box is fitted to ``bounds`` (default: the scene's bounding
    box); spot and point lights get near and far planes that enclose the scene.
    """
    where = "light_setup"
    L = as_light(light, where)
    B = scene.bounds if bounds is None else as_array(bounds, "bounds", shape=(2, 3), where=where)
    if L["type"] == "directional":
        return LightSetup(L, directional_light_matrix(L["direction"], B)[None])
    pos = L["position"]
    corners = np.array(np.meshgrid(*B.T, indexing="ij")).reshape(3, -1).T
    far = 1.01 * float(np.linalg.norm(corners - pos, axis=1).max())
    gap = float(np.linalg.norm(np.maximum(np.maximum(B[0] - pos, pos - B[1]), 0.0)))  # distance to the box
    near = max(0.95 * gap, 0.01 * far)
    if L["type"] == "spot":
        return LightSetup(L, spot_light_matrix(pos, L["target"], L["fov_deg"], near, far)[None], near, far)
    from .cubemap import cube_light_matrices

    return LightSetup(L, cube_light_matrices(pos, near, far), near, far)


def light_visibility(
    scene,
    eb: EyeBuffer,
    light,
    *,
    map_size: int = 1024,
    bias: float | None = None,
    slope_bias: float | None = None,
    pcf: int = 1,
    cull: str = "none",
    frustum_fix: bool = True,
    bounds=None,
    max_slope: float = DEFAULT_MAX_SLOPE,
    pcf_sampling: str = "grid",
    pcf_samples: int = 16,
    options: ShadowOptions | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Both passes for the eye's points: ``(visibility (k,), shadow maps (1 or 6, s, s))`` (given).

    The shadow options come as keywords or, all at once, as ``options`` (a :class:`ShadowOptions`).
    """
    where = "light_visibility"
    S = as_scene(scene, where)
    map_size = check_int(map_size, "map_size", minimum=1, maximum=2**15, where=where)
    keywords = dict(
        bias=bias, slope_bias=slope_bias, pcf=pcf, cull=cull, frustum_fix=frustum_fix, bounds=bounds,
        max_slope=max_slope, pcf_sampling=pcf_sampling, pcf_samples=pcf_samples,
    )  # fmt: skip
    opts = ShadowOptions.of(options, where, keywords, _LIGHT_VISIBILITY_DEFAULTS)
    setup = light_setup(S, light, bounds=opts.bounds)
    if setup.light["type"] == "point":
        maps = cube_depth_maps(S.V, S.F, setup.light["position"], map_size, setup.near, setup.far, opts.cull)
        vis = point_shadow_visibility(
            eb.P, eb.N_face, maps, setup.light["position"], setup.near, setup.far, options=opts
        )
        return vis, maps
    M = setup.matrices[0]
    D = depth_map(S.V, S.F, M, map_size, opts.cull)
    return shadow_visibility(eb.P, eb.N_face, D, M, options=opts), D[None]


def _light_dirs(L: dict, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors towards the light ``(k, 3)`` and the light's strength at each point ``(k,)``."""
    if L["type"] == "directional":
        return np.broadcast_to(-L["direction"], P.shape), np.ones(len(P))
    to = L["position"] - P
    to /= np.maximum(np.linalg.norm(to, axis=1, keepdims=True), 1e-300)
    if L["type"] == "point":
        return to, np.ones(len(P))
    axis = L["target"] - L["position"]
    axis /= np.linalg.norm(axis)
    cos = -to @ axis
    outer = np.cos(np.radians(L["fov_deg"] / 2))
    inner = np.cos(np.radians(0.8 * L["fov_deg"] / 2))
    t = np.clip((cos - outer) / (inner - outer), 0.0, 1.0)
    return to, t * t * (3 - 2 * t)  # smooth edge of the spot's cone


def shade(
    eb: EyeBuffer,
    vis,
    light,
    *,
    ambient: float = 0.25,
    diffuse: float = 0.85,
    specular: float = 0.25,
    shininess: float = 48.0,
) -> np.ndarray:
    """Blinn-Phong shading of an eye buffer with a light visibility per covered pixel (given).

    ``colour = albedo (ambient + diffuse v s max(n.l, 0)) + specular v s max(n.h, 0)^shininess [n.l > 0]``
    with ``v`` the visibility and ``s`` the spot-cone factor; background pixels get :data:`BACKGROUND`.

    Returns
    -------
    (h, w, 3) float64
        RGB in [0, 1].
    """
    where = "shade"
    for name, value in (("ambient", ambient), ("diffuse", diffuse), ("specular", specular), ("shininess", shininess)):
        check_float(value, name, minimum=0.0, where=where)
    L = as_light(light, where)
    vis = as_array(vis, "vis", shape=(len(eb.P),), where=where)
    to_light, strength = _light_dirs(L, eb.P)
    n = eb.N_shade * np.where(np.einsum("ij,ij->i", eb.N_shade, eb.eye - eb.P) < 0, -1.0, 1.0)[:, None]
    view = eb.eye - eb.P
    view /= np.maximum(np.linalg.norm(view, axis=1, keepdims=True), 1e-300)
    half = to_light + view
    half /= np.maximum(np.linalg.norm(half, axis=1, keepdims=True), 1e-300)
    nl = np.einsum("ij,ij->i", n, to_light)
    nh = np.clip(np.einsum("ij,ij->i", n, half), 0.0, 1.0)
    lit = vis * strength
    rgb = eb.albedo * (ambient + diffuse * lit * np.maximum(nl, 0.0))[:, None]
    rgb += (specular * lit * (nl > 0) * nh**shininess)[:, None]
    h, w = eb.mask.shape
    image = np.tile(np.asarray(BACKGROUND, float), (h, w, 1))
    image.reshape(-1, 3)[eb.mask.ravel()] = np.clip(rgb, 0.0, 1.0)
    return image


def render_with_shadows(
    scene,
    camera,
    light,
    *,
    size: tuple[int, int] = (512, 512),
    fov_deg: float = 40.0,
    map_size: int = 1024,
    bias: float | None = None,
    slope_bias: float | None = None,
    pcf: int = 3,
    cull: str = "none",
    frustum_fix: bool = True,
    bounds=None,
    pcf_sampling: str = "grid",
    pcf_samples: int = 16,
    ambient: float = 0.25,
    diffuse: float = 0.85,
    specular: float = 0.25,
    shininess: float = 48.0,
    return_visibility: bool = False,
    options: ShadowOptions | None = None,
):
    """Render a scene with Blinn-Phong shading and shadow-mapped shadows (given).

    Parameters
    ----------
    scene : Scene or list of ``(V, F[, color[, smooth]])`` meshes
    camera : (eye, target) or (eye, target, up)
        World-space camera (default up: +z).
    light : dict or (3,) direction
        See :mod:`.scene`: directional, spot or point light.
    size : (width, height)
        Image size in pixels.
    fov_deg : float
        Vertical field of view of the camera.
    map_size : int
        Shadow-map size in texels.
    bias, slope_bias, pcf, frustum_fix, pcf_sampling, pcf_samples
        As in :func:`shadow_visibility` (``frustum_fix`` does not apply to point lights).
    cull : {"front", "back", "none"}
        Culling in the depth pass. The default draws every face: with the slope-scaled bias there is
        no acne to hide, and front-face culling would lose the self-shadows of thin parts.
    bounds : (2, 3) array_like, optional
        Box a directional light's map is fitted to (default: the scene's bounding box).
    ambient, diffuse, specular, shininess : float
        Blinn-Phong parameters: ``colour = albedo (ambient + diffuse v s max(n.l, 0)) + specular v s
        max(n.h, 0)^shininess [n.l > 0]`` with ``v`` the visibility and ``s`` the spot-cone factor.
    return_visibility : bool
        Also return the visibility image.
    options : ShadowOptions, optional
        The shadow options at once, checked when made (then leave their keywords at the defaults).

    Returns
    -------
    image : (height, width, 3) float64
        RGB in [0, 1]; background pixels have :data:`BACKGROUND`.
    visibility : (height, width) float64, only with ``return_visibility``
        Light visibility per pixel, NaN on the background.
    """
    where = "render_with_shadows"
    S = as_scene(scene, where)
    w, h = _size(size, where)
    eb = eye_gbuffer(S, camera, (w, h), fov_deg)
    L = as_light(light, where)
    keywords = dict(
        bias=bias, slope_bias=slope_bias, pcf=pcf, cull=cull, frustum_fix=frustum_fix, bounds=bounds,
        pcf_sampling=pcf_sampling, pcf_samples=pcf_samples,
    )  # fmt: skip
    opts = ShadowOptions.of(options, where, keywords, _RENDER_DEFAULTS)
    vis, _ = light_visibility(S, eb, L, map_size=map_size, options=opts)
    image = shade(eb, vis, L, ambient=ambient, diffuse=diffuse, specular=specular, shininess=shininess)
    if not return_visibility:
        return image
    V = np.full((h, w), np.nan)
    V.ravel()[eb.mask.ravel()] = vis
    return image, V


_LIGHT_VISIBILITY_DEFAULTS = keyword_defaults(light_visibility)
_RENDER_DEFAULTS = keyword_defaults(render_with_shadows)
