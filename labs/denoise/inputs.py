"""Given helpers: input checks shared by every function of the lab (not a task).

Conventions of the lab (the texture convention is the one of :mod:`geomlib.textures`):

* ``V`` float ``(n, 3)``, ``F`` int ``(m, 3)`` triangles, ``N`` ``(n, 3)`` one normal per vertex.
  Normals are normalised here, so the lab's formulas may assume ``|n_i| = 1``.
* UV space is ``[0, 1]^2``, ``u`` right, ``v`` up; image row 0 is ``v = 1``.
* Offset maps are SQUARE single-channel images ``(s, s)``: ``uint8`` (8 bits), ``uint16``
  (16 bits) or floats in ``[0, 1]``. A texel value ``h`` stands for the offset ``bias + scale h``.

``normalize_rows`` and ``as_unit_normals`` are :func:`geomlib.vectors.normalize_rows` and
:func:`geomlib.vectors.as_unit_vectors`, ``check_uv`` is :func:`geomlib.validate.check_uv`
(``in_range=True``: offset maps are baked inside the texture square); all shared with the other labs.
"""

from __future__ import annotations

import numpy as np

from geomlib.tangent_space import as_height_map
from geomlib.textures import WRAP_MODES
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_mesh, check_uv
from geomlib.vectors import as_unit_vectors as as_unit_normals
from geomlib.vectors import normalize_rows

__all__ = [
    "WEIGHTS",
    "BITS",
    "normalize_rows",
    "as_unit_normals",
    "as_offsets",
    "as_scalars",
    "check_uv",
    "check_bits",
    "check_weld",
    "check_weights",
    "as_offset_image",
]

#: Laplacian weights of :func:`laplacian_offsets`.
WEIGHTS = ("uniform", "cotan")

#: Bit depths of a baked offset map.
BITS = (8, 16)


def as_offsets(delta, where: str, name: str = "delta") -> np.ndarray:
    """Laplacian offsets ``(n, 3)`` float64, finite."""
    return as_array(delta, name, shape=(None, 3), where=where)


def as_scalars(s, n: int, where: str, name: str = "s") -> np.ndarray:
    """One finite scalar per vertex, ``(n,)`` float64."""
    s = as_array(s, name, shape=(None,), where=where)
    if len(s) != n:
        raise MeshError(f"{where}: {name} has {len(s)} values but V has {n}; expected one value per vertex")
    return s


def check_bits(bits, where: str) -> int:
    """Bit depth of an offset map: 8 or 16."""
    if isinstance(bits, bool) or not isinstance(bits, int | np.integer) or int(bits) not in BITS:
        raise MeshError(f"{where}: bits must be 8 or 16, got {bits!r}")
    return int(bits)


def check_weld(weld, where: str) -> bool:
    if not isinstance(weld, bool | np.bool_):
        raise MeshError(f"{where}: weld must be True or False, got {weld!r}")
    return bool(weld)


def check_weights(weights, where: str) -> str:
    return check_choice(weights, "weights", WEIGHTS, where=where)


def as_offset_image(image, where: str, name: str = "image") -> np.ndarray:
    """A square single-channel offset map as float64 ``(s, s)`` in ``[0, 1]``.

    ``uint8`` images are divided by 255 and ``uint16`` images by 65535 (the inverse of the
    quantisation in :func:`bake_offset_map`); float images must already lie in ``[0, 1]``
    (:func:`geomlib.tangent_space.as_height_map`, shared with the maps and relief labs).
    """
    return as_height_map(image, where, name, unit_range=True, what="offset map")


def checked_map_inputs(V, F, UV, N, image, bias, scale, lam, weld, wrap, where: str):
    """The arguments of denoising through the offset map, checked once for both routes (NumPy
    :func:`denoise_with_map` and GLSL :func:`glsl_denoise_with_map`): ``(V, F, UV, N, H, bias, scale,
    lam, weld)`` with ``N`` unit rows and ``H`` the map as floats; ``wrap`` is only checked."""
    V, F = check_mesh(V, F, where=where)
    UV = check_uv(UV, len(V), where, in_range=True)
    N = as_unit_normals(N, len(V), where)
    H = as_offset_image(image, where)
    bias = check_float(bias, "bias", where=where)
    scale = check_float(scale, "scale", where=where)
    lam = check_float(lam, "lam", minimum=0.0, maximum=1.0, where=where)
    check_choice(wrap, "wrap", WRAP_MODES, where=where)
    return V, F, UV, N, H, bias, scale, lam, check_weld(weld, where)
