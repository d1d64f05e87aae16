"""Task 2: parallax mapping — one shift of uv along the view direction, with or without offset limiting."""

from __future__ import annotations

import numpy as np

from .inputs import check_bias, check_view_ray, height_at

__all__ = ["parallax_uv"]


def parallax_uv(height, uv, view, *, scale: float, bias: float | None = None, offset_limit: bool = False) -> np.ndarray:
    """Texture coordinates seen through the relief, approximated by one shift (Kaneko et al. 2001).

    The view ray enters the polygon at ``uv`` and goes down, away from the eye; at depth ``d`` it
    is at ``uv - d * view_xy / view_z``. Parallax mapping takes the depth of the surface AT ``uv``
    as if it held along the whole ray. With the height scaled and biased,
    ``hsb = scale * h(uv) + bias`` (``bias = -scale`` by default: the relief lies below the polygon,
    ``-hsb`` is the depth ``scale * (1 - h)``)::

        uv' = uv + hsb * view_xy / view_z          (parallax mapping)
        uv' = uv + hsb * view_xy                   (offset limiting, Welsh 2004)

    Offset limiting does not make the result more accurate: it caps the shift at ``|hsb|``, so
    at grazing angles (``view_z -> 0``) the texture no longer swims far away.

    Parameters
    ----------
    height : (s, s) float in [0, 1], uint8 or uint16
    uv : (..., 2) float
    view : (3,) or (..., 3) float
        Tangent-space direction towards the eye (normalised here), ``z > 0``.
    scale : float >= 0
        Depth of the relief (UV units) where ``h = 0``.
    bias : float, optional
        Default ``-scale``.
    offset_limit : bool

    Returns
    -------
    (..., 2) float64
    """
    where = "parallax_uv"
    H, uv, V, scale = check_view_ray(height, uv, view, scale, where)
    bias = check_bias(bias, scale, where)
    # BEGIN SOLUTION: Task 2 (parallax): hsb = scale h(uv) + bias; uv' = uv + hsb view_xy / view_z (offset limiting: uv + hsb view_xy)
    hsb = scale * height_at(H, uv[..., 0], uv[..., 1]) + bias
    shift = V[..., :2] if offset_limit else V[..., :2] / V[..., 2:3]
    return uv + hsb[..., None] * shift
    # END SOLUTION
