"""Given helpers: input checks and the height lookup shared by every function of the lab (not a task).

Conventions of the whole lab:

* A height map ``h`` is a square ``(s, s)`` image with values in ``[0, 1]`` (white = high); row 0
  is ``v = 1``, like every texture in geomlib. It is read by bilinear interpolation with
  clamp-to-edge (:func:`height_at`), the way ``GL_LINEAR`` reads a texture.
* The relief lies BELOW the polygon: the surface point at ``uv`` is at depth
  ``scale * (1 - h(uv))`` under it (``h = 1`` touches the polygon). ``scale`` is in UV units.
* Vectors are in tangent space: ``x`` along ``u``, ``y`` along ``v``, ``z`` along the normal.
  ``view`` is the unit vector from the surface towards the eye, ``light`` towards the light;
  both have ``z > 0`` (above the polygon).

``as_height_map`` (:mod:`geomlib.tangent_space`) and ``normalize_rows`` (:mod:`geomlib.vectors`)
come from geomlib, shared with the maps lab.
"""

from __future__ import annotations

import numpy as np

from geomlib.tangent_space import as_height_map
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int
from geomlib.vectors import normalize_rows

__all__ = [
    "as_height_map",
    "check_height",
    "check_uv_points",
    "check_directions",
    "check_view_ray",
    "check_bias",
    "check_depths",
    "height_at",
    "height_lookup",
    "normalize_rows",
]


def check_height(height, where: str) -> np.ndarray:
    """A square height map ``(s, s)`` float64 in ``[0, 1]`` (uint8/uint16 images are scaled)."""
    H = as_height_map(height, where, name="height")
    if H.min() < 0 or H.max() > 1:
        raise MeshError(
            f"{where}: height values span [{H.min():.6g}, {H.max():.6g}]; a height map holds values in [0, 1] "
            f"(white = high)"
        )
    return H


def check_uv_points(uv, where: str, name: str = "uv", *, grid: bool = False) -> np.ndarray:
    """Texture coordinates ``(..., 2)`` float64, finite; with ``grid`` an image of them, ``(h, w, 2)``."""
    a = as_array(uv, name, dtype=np.float64, where=where)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise MeshError(f"{where}: {name} has shape {a.shape}; expected (..., 2) texture coordinates (u, v)")
    if grid and a.ndim != 3:
        raise MeshError(f"{where}: {name} has shape {a.shape}; the GLSL route renders images, expected (h, w, 2)")
    return a


def check_directions(d, shape: tuple, where: str, name: str = "view") -> np.ndarray:
    """Tangent-space unit vectors broadcast to ``shape + (3,)``; each must point above the polygon (z > 0).

    Vectors are normalised here, so any positive length is accepted.
    """
    a = as_array(d, name, dtype=np.float64, where=where)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise MeshError(f"{where}: {name} has shape {a.shape}; expected (3,) or (..., 3) tangent-space vectors")
    try:
        a = np.broadcast_to(a, (*shape, 3))
    except ValueError:
        raise MeshError(
            f"{where}: {name} has shape {a.shape}, which does not broadcast to the uv grid {shape} + (3,)"
        ) from None
    length = np.linalg.norm(a, axis=-1)
    if (length == 0).any():
        raise MeshError(f"{where}: {name} contains the zero vector; every pixel needs a direction")
    a = a / length[..., None]
    if (a[..., 2] <= 0).any():
        i = tuple(int(k) for k in np.argwhere(a[..., 2] <= 0)[0])
        raise MeshError(
            f"{where}: {name}{list(i) if i else ''} = {a[i].round(4).tolist()} has z <= 0; it must point above the "
            f"polygon (tangent space, z along the normal)"
        )
    return a


def check_scale(scale, where: str) -> float:
    return check_float(scale, "scale", minimum=0.0, where=where)


def check_view_ray(height, uv, view, scale, where: str, *, grid: bool = False):
    """The inputs of a view ray through the relief, checked: ``(H, uv, V, scale)``.

    ``H`` from :func:`check_height`, ``uv`` from :func:`check_uv_points` (``grid``: the ``(h, w, 2)``
    image the GLSL route renders), ``V`` the unit view directions, one per uv
    (:func:`check_directions`), and ``scale >= 0``.
    """
    H = check_height(height, where)
    uv = check_uv_points(uv, where, grid=grid)
    return H, uv, check_directions(view, uv.shape[:-1], where), check_scale(scale, where)


def check_depths(depth, shape: tuple, where: str) -> np.ndarray:
    """Depths below the polygon (``>= 0``), one per uv: ``shape`` float64."""
    D = as_array(depth, "depth", dtype=np.float64, where=where)
    if D.shape != shape:
        raise MeshError(f"{where}: depth has shape {D.shape}; expected {shape}, one depth per uv")
    if (D < 0).any():
        raise MeshError(f"{where}: depth has negative values (min {D.min():.6g}); depths below the polygon are >= 0")
    return D


def check_bias(bias, scale: float, where: str) -> float:
    """Parallax mapping's height bias: ``-scale`` by default (the relief lies below the polygon)."""
    return -scale if bias is None else check_float(bias, "bias", where=where)


def check_layers(n, name: str, where: str, minimum: int = 1) -> int:
    return check_int(n, name, minimum=minimum, maximum=4096, where=where)


def check_march(min_layers, max_layers, refine, refine_steps, refinements, where: str) -> tuple[int, int, int]:
    """The ray march's settings (shared by :func:`relief_uv` and its GLSL twin): layer bounds with
    ``1 <= min_layers <= max_layers <= 4096``, ``refine`` one of ``refinements``, ``refine_steps >= 0``."""
    lo = check_layers(min_layers, "min_layers", where)
    hi = check_layers(max_layers, "max_layers", where)
    if hi < lo:
        raise MeshError(f"{where}: max_layers ({hi}) must be >= min_layers ({lo})")
    check_choice(refine, "refine", refinements, where=where)
    return lo, hi, check_layers(refine_steps, "refine_steps", where, minimum=0)


def height_at(H: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Bilinear, clamp-to-edge lookup of the height map at ``(u, v)`` (arrays of one shape).

    Texel ``[r, c]`` has its centre at ``((c + 0.5) / s, 1 - (r + 0.5) / s)``; with ``x = u s - 1/2``,
    ``y = (1 - v) s - 1/2``, ``fx = x - floor(x)``::

        h = (1-fx)(1-fy) H[y0, x0] + fx (1-fy) H[y0, x0+1] + (1-fx) fy H[y0+1, x0] + fx fy H[y0+1, x0+1]

    the same value as ``geomlib.textures.sample_bilinear(H, uv, "clamp")`` without its checks.
    A loop that reads one map many times (a ray march) takes :func:`height_lookup` once instead.
    """
    return height_lookup(H)(u, v)


def height_lookup(H: np.ndarray):
    """:func:`height_at` for one map: ``lookup(u, v)`` gives the same values, bit for bit, and pads
    the map once instead of at every call (a ray march reads it dozens of times per pixel)."""
    s = H.shape[0]
    # Clamping the continuous coordinate to [0, s - 1] first gives the same values (at a clamped
    # border both taps are the border texel, or the weight of the second is 0) with one clip per
    # axis; the map padded by one edge row and column makes x0 + 1 and y0 + 1 always valid.
    flat = np.pad(H, ((0, 1), (0, 1)), mode="edge").ravel()

    def lookup(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        x = np.clip(u * s - 0.5, 0.0, s - 1.0)
        y = np.clip((1.0 - v) * s - 0.5, 0.0, s - 1.0)
        x0 = x.astype(np.intp)  # floor, x >= 0
        y0 = y.astype(np.intp)
        fx, fy = x - x0, y - y0
        i = y0 * (s + 1) + x0
        t00, t01 = flat.take(i), flat.take(i + 1)
        t10, t11 = flat.take(i + (s + 1)), flat.take(i + (s + 2))
        top = t00 + (t01 - t00) * fx
        bot = t10 + (t11 - t10) * fx
        return top + (bot - top) * fy

    return lookup
