"""Tangent space shared by the texture-space labs (maps, relief): height maps and per-pixel frames.

Conventions (see :mod:`geomlib.textures` for UV and images): UV space is ``[0, 1]^2``, ``u`` right,
``v`` up, image row 0 is ``v = 1``; tangent space has ``x`` along the tangent ``T`` (increasing
``u``), ``y`` along the bitangent ``B`` (increasing ``v``), ``z`` along the normal ``N``; tangents
follow glTF / pyrender, an ``(n, 4)`` array ``[T, w]`` with ``B = w (N x T)``.

* :func:`as_height_map` checks a square single-channel height map and scales integer images to [0, 1];
* :func:`surface_frames` builds orthonormal per-pixel frames from interpolated normals and tangents
  (the convention a normal-map baker and a shader must share);
* :func:`fallback_perpendicular` gives a deterministic perpendicular where a tangent is missing.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array, as_image
from geomlib.vectors import normalize_rows

__all__ = ["as_height_map", "surface_frames", "fallback_perpendicular"]


def fallback_perpendicular(N: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to each unit row of ``N`` (deterministic).

    Uses the coordinate axis least aligned with ``N``: ``e - (N . e) N``, normalised.
    """
    axis = np.argmin(np.abs(N), axis=-1)
    E = np.zeros_like(N)
    np.put_along_axis(E, axis[..., None], 1.0, axis=-1)
    T = E - np.sum(N * E, axis=-1, keepdims=True) * N
    return normalize_rows(T, fallback=(1.0, 0.0, 0.0))


def as_height_map(
    H, where: str, name: str = "height", *, unit_range: bool = False, what: str = "height map"
) -> np.ndarray:
    """A square single-channel map of heights or offsets as float64 ``(s, s)``.

    uint8 and uint16 images are scaled to ``[0, 1]`` (black = 0); float maps are used as they are
    and, with ``unit_range``, must lie in ``[0, 1]``. ``what`` names the kind of map in the
    messages (``"displacement map"``, ``"offset map"``).

    Raises
    ------
    MeshError
        Not an image, several channels, not square, a non-numeric dtype, non-finite values, or
        (with ``unit_range``) values outside [0, 1].
    """
    img = as_image(H, name, where=where)
    if img.ndim == 3:
        raise MeshError(
            f"{where}: {name} has {img.shape[2]} channels (shape {img.shape}); expected a single-channel (grey) "
            f"{what} (s, s)"
        )
    if img.shape[0] != img.shape[1]:
        raise MeshError(f"{where}: {name} is {img.shape[0]}x{img.shape[1]} texels; {what}s are square (s x s texels)")
    if img.dtype == np.uint8:
        return img.astype(np.float64) / 255.0
    if img.dtype == np.uint16:
        return img.astype(np.float64) / 65535.0
    if img.dtype.kind not in "iuf":
        raise MeshError(f"{where}: {name} has dtype {img.dtype}, expected floats, uint8 or uint16")
    out = as_array(img, name, dtype=np.float64, where=where)
    if unit_range and (out.min() < 0 or out.max() > 1):
        raise MeshError(
            f"{where}: {name} values span [{out.min():.6g}, {out.max():.6g}]; {what} values lie in [0, 1] "
            f"(bias and scale turn them into offsets)"
        )
    return out


def surface_frames(normal: np.ndarray, tangent: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal frames from interpolated per-vertex normals and ``[T, w]`` tangents.

    The convention shared by shading with normal maps, baking them and relief mapping (baker and
    shader must agree, or baked detail comes out tilted)::

        N' = normalize(normal)
        T' = normalize(T - (N' . T) N')           (T = tangent[..., :3])
        B' = sign(w) (N' x T')                    (sign(0) = +1)

    Parameters
    ----------
    normal : (..., 3) float
    tangent : (..., 4) float

    Returns
    -------
    T, B, N : (..., 3) float64 each, orthonormal, never NaN.
    """
    Nn = normalize_rows(normal, fallback=(0.0, 0.0, 1.0))
    T = tangent[..., :3] - np.einsum("...i,...i->...", tangent[..., :3], Nn)[..., None] * Nn
    length = np.sqrt(np.einsum("...i,...i->...", T, T))
    bad = length <= 1e-12
    T /= np.where(bad, 1.0, length)[..., None]
    if bad.any():  # tangent parallel to the normal (or zero): any perpendicular direction will do
        T[bad] = fallback_perpendicular(Nn[bad])
    w = np.where(tangent[..., 3:4] < 0, -1.0, 1.0).astype(T.dtype)
    B = np.empty_like(T)
    B[..., 0] = Nn[..., 1] * T[..., 2] - Nn[..., 2] * T[..., 1]
    B[..., 1] = Nn[..., 2] * T[..., 0] - Nn[..., 0] * T[..., 2]
    B[..., 2] = Nn[..., 0] * T[..., 1] - Nn[..., 1] * T[..., 0]
    return T, w * B, Nn
