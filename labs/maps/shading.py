"""Task 4: a NumPy "fragment shader": per-pixel Blinn-Phong over the rasterizer's G-buffer, with normal maps."""

from __future__ import annotations

import numpy as np

from geomlib.geometry import vertex_normals
from geomlib.raster import GBuffer, rasterize
from geomlib.tangent_space import surface_frames
from geomlib.textures import WRAP_MODES, sample_bilinear
from geomlib.validate import MeshError, as_array, as_image, check_choice, check_float, check_mesh

from .inputs import (
    as_normal_map,
    as_tangents,
    as_unit_vectors,
    check_lights,
    check_uv,
    normalize_rows,
)

__all__ = ["shade", "rasterize_mesh", "surface_frames"]


def rasterize_mesh(V, F, M, width: int, height: int, *, UV=None, N=None, tangents=None, cull: str = "back") -> GBuffer:
    """Given: rasterize a mesh into a G-buffer with the attributes :func:`shade` reads.

    Parameters
    ----------
    V, F : mesh
    M : (4, 4) float
        Clip-from-world matrix ``projection @ view`` (:mod:`geomlib.camera`).
    width, height : int
    UV : (n, 2) float, optional
        Stored as attribute ``"uv"`` (needed for normal maps and albedo textures).
    N : (n, 3) float, optional
        Vertex normals, attribute ``"normal"`` (default: area-weighted vertex normals).
    tangents : (n, 4) float, optional
        ``[T, w]`` per vertex (from :func:`tangent_frames`), attribute ``"tangent"``.
    cull : {"none", "back", "front"}

    Returns
    -------
    GBuffer
        With attributes ``"position"`` (world), ``"normal"`` and, when given, ``"uv"`` and ``"tangent"``.
    """
    where = "rasterize_mesh"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    N = (
        normalize_rows(vertex_normals(V, F), fallback=(0.0, 0.0, 1.0))
        if N is None
        else as_unit_vectors(N, len(V), where)
    )
    attrs = {"position": V, "normal": N}
    if UV is not None:
        attrs["uv"] = check_uv(UV, len(V), where)
    if tangents is not None:
        attrs["tangent"] = as_tangents(tangents, len(V), where)
    return rasterize(V, F, M, width, height, attributes=attrs, cull=cull)


def _check_gbuffer(g, need: tuple[str, ...], where: str) -> None:
    if not hasattr(g, "mask") or not hasattr(g, "attributes"):
        raise MeshError(
            f"{where}: gbuffer must be a geomlib.raster.GBuffer (from rasterize or rasterize_mesh), got {type(g).__name__}"
        )
    argument = {"uv": "UV=", "tangent": "tangents=", "normal": "N=", "position": ""}
    for key in need:
        if key not in g.attributes:
            raise MeshError(
                f"{where}: gbuffer has no '{key}' attribute (it has {sorted(g.attributes)}); rasterize with "
                f"attributes={{'{key}': ...}} or use rasterize_mesh(..., {argument.get(key, '')}...)"
            )


def checked_shade_inputs(
    gbuffer, lights, eye, albedo, normal_map, ambient, specular, shininess, wrap, background, where: str
):
    """Given: the arguments of :func:`shade`, checked once for both routes (NumPy :func:`shade` and
    GLSL :func:`~solutions.maps.glsl.glsl_shade`).

    Returns
    -------
    need : tuple of str
        The G-buffer attributes the call reads (checked present).
    L : list of (kind, (3,), (3,))
        The lights (:func:`~solutions.maps.inputs.check_lights`).
    eye : (3,) float64
    ambient, specular, shininess : float
    bg : (3,) float64
    tex : (s, s, 3) float64 in [0, 1] or None
        The albedo texture, when ``albedo`` is an image.
    alb : (3,) float64 or None
        The constant albedo, when it is not.
    nmap : (s, s, 3) float64 or None
        The decoded normal map's vectors (not normalised).
    """
    need = ("position", "normal")
    texture_albedo = np.ndim(albedo) == 3
    if normal_map is not None or texture_albedo:
        need += ("uv",)
    if normal_map is not None:
        need += ("tangent",)
    _check_gbuffer(gbuffer, need, where)
    L = check_lights(lights, where)
    eye = as_array(eye, "eye", shape=(3,), where=where)
    check_choice(wrap, "wrap", WRAP_MODES, where=where)
    ambient = check_float(ambient, "ambient", minimum=0.0, where=where)
    specular = check_float(specular, "specular", minimum=0.0, where=where)
    shininess = check_float(shininess, "shininess", minimum=0.0, where=where)
    bg = as_array(background, "background", shape=(3,), where=where)
    tex = alb = None
    if texture_albedo:
        tex = as_image(albedo, "albedo", channels=3, where=where)
        tex = tex.astype(np.float64) / 255.0 if tex.dtype == np.uint8 else as_array(tex, "albedo", where=where)
    else:
        alb = as_array(albedo, "albedo", shape=(3,), where=where)
    nmap = as_normal_map(normal_map, where) if normal_map is not None else None
    return need, L, eye, ambient, specular, shininess, bg, tex, alb, nmap


def shade(
    gbuffer,
    lights,
    eye,
    albedo,
    normal_map=None,
    *,
    ambient: float = 0.1,
    specular: float = 0.3,
    shininess: float = 32.0,
    wrap: str = "clamp",
    background=(1.0, 1.0, 1.0),
) -> np.ndarray:
    """Blinn-Phong shading of every covered pixel of a G-buffer, optionally with a normal map.

    Per pixel with world position ``P`` and unit normal ``n`` (the interpolated vertex normal,
    or, with a normal map, the map's tangent-space normal ``m`` taken to world space by the
    interpolated frame of :func:`surface_frames`, ``n = normalize(m_x T' + m_y B' + m_z N')``)::

        v = normalize(eye - P)                          towards the viewer
        l = -direction   or   normalize(position - P)   towards the light
        h = normalize(l + v)                            half vector
        colour = ambient * albedo
               + sum over lights  L * (albedo * max(n . l, 0) + specular * max(n . h, 0)^shininess [n . l > 0])

    with ``L`` the light's colour times intensity. The geometry stays flat; only ``n`` changes. A
    pixel whose ``n`` has zero length before normalising is shaded with ``n = (0, 0, 1)``.
    Background pixels get ``background``. The result is clipped to ``[0, 1]`` (no gamma).

    Parameters
    ----------
    gbuffer : GBuffer
        From :func:`rasterize_mesh` (or :func:`geomlib.raster.rasterize`) with attributes
        ``"position"`` and ``"normal"``, plus ``"uv"`` and ``"tangent"`` ((n, 4), ``[T, w]``) when a
        normal map or an albedo texture is used.
    lights : list of dict
        See :func:`solutions.maps.inputs.check_lights`: ``{"direction": (3,)}`` (directional, the
        way the light travels) or ``{"type": "point", "position": (3,)}``; optional ``"color"``,
        ``"intensity"``.
    eye : (3,) float
        Camera position (world).
    albedo : (3,) RGB in [0, 1], or an image (h, w, 3)
        Diffuse colour, or a texture read at the pixel's UV (uint8 images are scaled to [0, 1]).
    normal_map : (s, s, 3) uint8 or float, optional
        Tangent-space normal map: encoded uint8 codes (turned into ``2 rgb / 255 - 1``) or float
        vectors. Read with bilinear filtering at the pixel's UV; the filtered vector is normalised
        (after filtering, as a GPU does).
    ambient, specular, shininess : float
        Material: ambient factor, specular colour (white, this factor) and Blinn exponent.
    wrap : {"clamp", "repeat"}
        Texture lookups outside ``[0, 1]^2``.
    background : (3,) RGB

    Returns
    -------
    (h, w, 3) float64 in [0, 1]

    Raises
    ------
    MeshError
        Missing attributes, bad lights, maps or parameters.
    """
    need, L, eye, ambient, specular, shininess, bg, tex, alb, nmap = checked_shade_inputs(
        gbuffer, lights, eye, albedo, normal_map, ambient, specular, shininess, wrap, background, "shade"
    )

    mask = np.asarray(gbuffer.mask)
    h, w = mask.shape
    out = np.empty((h, w, 3))
    out[...] = bg
    pix = np.flatnonzero(mask)
    # Single precision, as a GPU's fragment shader: half the memory traffic of float64.
    f32 = np.float32
    A = {k: np.take(np.asarray(gbuffer.attributes[k]).reshape(h * w, -1), pix, axis=0).astype(f32) for k in need}
    P, Ni = A["position"], A["normal"]
    color = sample_bilinear(tex, A["uv"], wrap=wrap, dtype=f32) if tex is not None else alb.astype(f32)
    if nmap is not None:
        nmap = nmap.astype(f32)
    eye = eye.astype(f32)
    n = ...  # (k, 3) unit shading normal of every covered pixel (k = len(pix))
    raise NotImplementedError("Task 4 (normal): n = normalize(m_x T' + m_y B' + m_z N') with the map's m, else normalize(interpolated normal)")
    c = ...  # (k, 3) colour of every covered pixel
    raise NotImplementedError('Task 4 (Blinn-Phong): ambient*albedo + sum L (albedo max(n.l, 0) + ks max(n.h, 0)^p [n.l > 0])')
    out.reshape(-1, 3)[pix] = np.clip(c, 0.0, 1.0)
    return out
