"""Tasks 4 and 5: store the normal offsets in a texture (an offset map) and denoise by sampling it.

Baking rasterizes the per-vertex offsets ``s`` over UV space: every texel centre inside a UV
triangle gets the barycentric interpolation of the triangle's three offsets. The values are
mapped to ``[0, 1]`` by ``h = (s - bias) / scale`` and quantised to 8 or 16 bits, and the charts
are padded outward (dilated) so bilinear lookups near a chart border never read the empty
background. Denoising through the map is then a vertex-shader operation, exactly like scalar
displacement mapping (lab "maps"): ``p' = p - lam (bias + scale h(uv)) n``.
"""

from __future__ import annotations

import numpy as np

from geomlib.textures import dilate, rasterize_uv, sample_bilinear
from geomlib.validate import check_int, check_mesh

from .inputs import as_scalars, check_bits, check_uv, checked_map_inputs, normalize_rows
from .seams import seam_mean, weld_seams

__all__ = ["bake_offset_map", "denoise_with_map", "quantisation_step"]


def quantisation_step(scale: float, bits: int) -> float:
    """Given: the offset one quantisation level stands for, ``scale / (2^bits - 1)``.

    Rounding to the nearest level changes a baked offset by at most half of it.
    """
    return float(scale) / float(2 ** int(bits) - 1)


def bake_offset_map(V, F, UV, s, size: int, bits: int = 16, *, padding: int | None = 8):
    """Bake per-vertex offsets into a square offset map (a displacement texture).

    1. **Rasterize** UV space (given: :func:`geomlib.textures.rasterize_uv`): for every texel
       centre, the triangle ``f`` that covers it (``-1`` if none) and barycentric weights
       ``(b0, b1, b2)``.
    2. **Interpolate**: a covered texel gets ``value = b0 s[F[f, 0]] + b1 s[F[f, 1]] + b2 s[F[f, 2]]``.
    3. **Normalise**: ``bias = min(s)``, ``scale = max(s) - min(s)``, ``h = (value - bias) / scale``
       in ``[0, 1]`` (if all offsets are equal, ``scale = 0`` and ``h = 0``).
    4. **Pad** the charts (:func:`geomlib.textures.dilate` with ``padding`` iterations), so
       bilinear lookups near a chart border read chart values, not the empty background.
       Texels out of reach stay 0.
    5. **Quantise**: ``q = round(h (2^bits - 1))`` as ``uint8`` (8 bits) or ``uint16`` (16 bits).

    Decoding reverses it: ``offset = bias + scale q / (2^bits - 1)``, off by at most half a
    quantisation step :func:`quantisation_step` at the texel centres.

    Parameters
    ----------
    V : (n, 3) float
        Vertex positions (only checked: baking happens in UV space).
    F : (m, 3) int
        Triangles; ``UV[F]`` are the UV triangles.
    UV : (n, 2) float
        Texture coordinates in ``[0, 1]^2``, one per vertex.
    s : (n,) float
        The offset of every vertex (e.g. :func:`normal_offsets`).
    size : int
        The map is ``size x size`` texels.
    bits : {8, 16}
    padding : int or None
        Dilation iterations (texels of padding around the charts); ``None`` fills every texel.

    Returns
    -------
    image : (size, size) uint8 or uint16
        Row 0 is ``v = 1`` (see :mod:`geomlib.textures`).
    bias, scale : float
        ``offset = bias + scale h`` with ``h = image / (2^bits - 1)``.

    Raises
    ------
    MeshError
        Invalid mesh, UVs outside ``[0, 1]^2``, wrong number of offsets, bad ``size``, ``bits``
        or ``padding``.
    """
    where = "bake_offset_map"
    V, F = check_mesh(V, F, where=where)
    UV = check_uv(UV, len(V), where, in_range=True)
    s = as_scalars(s, len(V), where)
    size = check_int(size, "size", minimum=2, maximum=8192, where=where)
    bits = check_bits(bits, where)
    if padding is not None:
        padding = check_int(padding, "padding", minimum=0, where=where)
    face_id, bary = rasterize_uv(F, UV, size)
    covered = face_id >= 0
    image, bias, scale = ..., ..., ...  # (size, size) uint8/uint16, float, float
    raise NotImplementedError('Task 4 (bake): value = sum_k bary_k s[F[face_id, k]]; bias = min s, scale = max s - min s; h = (value - bias)/scale; h = dilate(h, covered, padding); q = round(h (2^bits - 1))')
    return image, bias, scale


def denoise_with_map(
    V, F, UV, N, image, bias: float, scale: float, lam: float, *, weld: bool = True, wrap: str = "clamp"
) -> np.ndarray:
    """Denoise by reading each vertex's offset from an offset map: ``p' = p - lam (bias + scale h(uv)) n``.

    ``h(uv)`` is the map value at the vertex's texture coordinates, read with bilinear filtering
    (:func:`geomlib.textures.sample_bilinear`, as a GPU's ``GL_LINEAR`` lookup); ``uint8`` maps
    are divided by 255 and ``uint16`` maps by 65535 first (given). With the map of
    :func:`bake_offset_map` this reproduces :func:`denoise_vertices` up to the quantisation and
    the resampling of the map.

    Seams (Task 6): the copies of a seam vertex sit at different UVs, so they read different
    texels and get slightly different offsets, and the seam cracks open. With ``weld`` the copies
    (:func:`weld_seams`) all move by the mean of their offsets along the mean of their normals.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    UV : (n, 2) float
        Texture coordinates in ``[0, 1]^2``.
    N : (n, 3) float
        Clean vertex normals (normalised here).
    image : (s, s) uint8, uint16, or float in [0, 1]
        The offset map.
    bias, scale : float
        As returned by :func:`bake_offset_map`.
    lam : float
        Step ``lambda`` in ``[0, 1]``.
    weld : bool
        Move the copies of a seam vertex together.
    wrap : {"clamp", "repeat"}
        Lookups outside the texture (see :func:`geomlib.textures.sample_bilinear`).

    Returns
    -------
    V_new : (n, 3) float64

    Raises
    ------
    MeshError
        Invalid mesh, UVs or normals, a map that is not square and single-channel, bad
        ``lam``, ``bias``, ``scale`` or ``wrap``.
    """
    where = "denoise_with_map"
    V, F, UV, N, H, bias, scale, lam, weld = checked_map_inputs(V, F, UV, N, image, bias, scale, lam, weld, wrap, where)
    s = ...  # (n,) offsets read from the map
    raise NotImplementedError('Task 5 (denoising through the map): h = sample_bilinear(H, UV, wrap); s = bias + scale h')
    if weld:
        _, _, group = weld_seams(V, F)
        s = seam_mean(s, group)[group]
        N = normalize_rows(seam_mean(N, group))[group]
    V_new = ...  # (n, 3)
    raise NotImplementedError("Task 5 (denoising through the map): p' = p - lam s n")
    return V_new
