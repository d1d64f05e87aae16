"""Given helpers: input checks shared by every function of the lab (not a task).

Conventions of the whole lab (see ``geomlib.textures`` for the UV/image convention):

* UV space is ``[0, 1]^2``, ``u`` right, ``v`` up; image row 0 is ``v = 1``.
* Every map of this lab (normal map, height map, displacement map) is a SQUARE image of
  ``s x s`` texels, so a texel has the same extent ``1 / s`` in ``u`` and ``v``.
* Tangent-space normal maps hold unit vectors ``(x, y, z)``: ``x`` along the tangent ``T``
  (direction of increasing ``u``), ``y`` along the bitangent ``B`` (increasing ``v``), ``z`` along
  the surface normal ``N``; an undisturbed surface is ``(0, 0, 1)``.
* Tangents follow glTF / pyrender: an ``(n, 4)`` array ``[T, w]`` with ``B = w (N x T)``.

``check_uv`` (:func:`geomlib.validate.check_uv`), ``as_unit_vectors`` and ``normalize_rows``
(:mod:`geomlib.vectors`), ``as_height_map`` and ``fallback_perpendicular``
(:mod:`geomlib.tangent_space`) come from geomlib, shared with the other labs.
"""

from __future__ import annotations

import numpy as np

from geomlib.tangent_space import as_height_map, fallback_perpendicular
from geomlib.validate import MeshError, as_array, as_image, check_choice, check_float, check_uv
from geomlib.vectors import as_unit_vectors, normalize_rows

__all__ = [
    "check_uv",
    "as_unit_vectors",
    "as_height_map",
    "as_normal_map",
    "as_encoded_map",
    "as_tangents",
    "check_lights",
    "normalize_rows",
    "fallback_perpendicular",
]


def _square(img: np.ndarray, name: str, where: str) -> None:
    if img.shape[0] != img.shape[1]:
        raise MeshError(
            f"{where}: {name} is {img.shape[0]}x{img.shape[1]} texels; maps in this lab are square (s x s texels)"
        )


def as_encoded_map(img, where: str, name: str = "img") -> np.ndarray:
    """A square 8-bit RGB image ``(s, s, 3)`` uint8 (an encoded normal map)."""
    a = as_image(img, name, where=where)
    if a.ndim != 3 or a.shape[2] != 3:
        c = 1 if a.ndim == 2 else a.shape[2]
        raise MeshError(f"{where}: {name} has {c} channel(s) (shape {a.shape}); a normal map is an RGB image (s, s, 3)")
    if a.dtype != np.uint8:
        raise MeshError(f"{where}: {name} has dtype {a.dtype}; an encoded normal map is uint8 (0..255)")
    _square(a, name, where)
    return a


def as_normal_map(img, where: str, name: str = "normal_map") -> np.ndarray:
    """A square tangent-space normal map as float64 ``(s, s, 3)`` vectors (not yet normalised).

    uint8 images are decoded with the affine part of the encoding, ``n = 2 rgb / 255 - 1``; float
    images are taken as vectors. Normalise after interpolation, as a GPU does.
    """
    a = as_image(img, name, where=where)
    if a.ndim != 3 or a.shape[2] != 3:
        c = 1 if a.ndim == 2 else a.shape[2]
        raise MeshError(f"{where}: {name} has {c} channel(s) (shape {a.shape}); a normal map is an RGB image (s, s, 3)")
    _square(a, name, where)
    if a.dtype == np.uint8:
        return a.astype(np.float64) * (2.0 / 255.0) - 1.0
    if a.dtype.kind != "f":
        raise MeshError(f"{where}: {name} has dtype {a.dtype}; expected uint8 (encoded) or floats (unit vectors)")
    return as_array(a, name, dtype=np.float64, where=where)


def as_tangents(T, n: int, where: str, name: str = "tangents") -> np.ndarray:
    """Per-vertex tangents ``(n, 4)`` ``[T, w]`` in glTF / pyrender convention (``w`` = +-1)."""
    T = as_array(T, name, shape=(None, 4), where=where)
    if len(T) != n:
        raise MeshError(f"{where}: {name} has {len(T)} rows but V has {n}; expected one [T, w] row per vertex")
    return T


def check_lights(lights, where: str) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Validate light dicts; return ``(kind, vector, rgb * intensity)`` per light.

    Each light is a dict with ``"type"`` (``"directional"``, default, or ``"point"``),
    ``"direction"`` (directional: the way the light TRAVELS, e.g. ``(0, 0, -1)`` shines down -z)
    or ``"position"`` (point light, no fall-off), optional ``"color"`` (RGB in [0, 1], default
    white) and ``"intensity"`` (>= 0, default 1).
    """
    if isinstance(lights, dict):
        lights = [lights]
    if not isinstance(lights, list | tuple) or len(lights) == 0:
        raise MeshError(f"{where}: lights must be a non-empty list of light dicts, got {lights!r}")
    out = []
    for i, s in enumerate(lights):
        if not isinstance(s, dict):
            raise MeshError(f"{where}: lights[{i}] must be a dict, got {s!r}")
        extra = sorted(set(s) - {"type", "direction", "position", "color", "intensity"})
        if extra:
            raise MeshError(f"{where}: lights[{i}] has unknown keys {extra}")
        kind = check_choice(s.get("type", "directional"), f"lights[{i}]['type']", ("directional", "point"), where=where)
        key = "direction" if kind == "directional" else "position"
        if key not in s:
            raise MeshError(f"{where}: lights[{i}] is a {kind} light and needs a '{key}'")
        vec = as_array(s[key], f"lights[{i}]['{key}']", shape=(3,), where=where)
        if kind == "directional":
            if not np.any(vec):
                raise MeshError(f"{where}: lights[{i}]['direction'] is the zero vector")
            vec = vec / np.linalg.norm(vec)
        color = as_array(s.get("color", (1.0, 1.0, 1.0)), f"lights[{i}]['color']", shape=(3,), where=where)
        if color.min() < 0:
            raise MeshError(f"{where}: lights[{i}]['color'] has a negative component")
        inten = check_float(s.get("intensity", 1.0), f"lights[{i}]['intensity']", minimum=0.0, where=where)
        out.append((kind, vec, color * inten))
    return out
