"""Task 4: self-shadowing — march from the hit point towards the light through the height field."""

from __future__ import annotations

import numpy as np

from .inputs import check_depths, check_directions, check_height, check_layers, check_scale, check_uv_points, height_at

__all__ = ["relief_shadow"]


def relief_shadow(height, uv, depth, light, *, scale: float, layers: int = 32) -> np.ndarray:
    """Visibility of the light from the relief point at ``uv``, ``depth`` (1 lit, 0 in shadow).

    The shadow ray leaves the hit point (``uv``, ``depth`` below the polygon) towards the light
    and rises to the polygon in ``layers`` equal steps; at step ``k = 1 .. layers``::

        d_k  = depth (1 - k / layers)                       (its depth)
        uv_k = uv + (depth - d_k) light_xy / light_z        (where it is)

    The point is in shadow when some ray point lies below the relief, ``d_k > scale (1 - h(uv_k))``
    (a hard shadow; at ``k = layers`` the ray is at the polygon, above every relief point).

    Parameters
    ----------
    height : (s, s) float in [0, 1], uint8 or uint16
    uv : (..., 2) float
        Hit points, e.g. from :func:`relief_uv`.
    depth : (...) float >= 0
        Their depth below the polygon (UV units), e.g. from :func:`relief_uv`.
    light : (3,) or (..., 3) float
        Tangent-space direction towards the light (normalised here), ``z > 0``.
    scale : float >= 0
        The relief's depth scale (the one the hits were found with).
    layers : int >= 1

    Returns
    -------
    (...) float64 in {0, 1}

    Notes
    -----
    Loops over the ``layers`` steps (each a vectorised lookup for every pixel not yet in shadow).
    """
    where = "relief_shadow"
    H = check_height(height, where)
    uv = check_uv_points(uv, where)
    shape = uv.shape[:-1]
    D = check_depths(depth, shape, where)
    L = check_directions(light, shape, where, name="light")
    scale = check_scale(scale, where)
    n = check_layers(layers, "layers", where)
    raise NotImplementedError('Task 4 (shadow): d_k = depth (1 - k/layers), uv_k = uv + (depth - d_k) light_xy / light_z; shadow if any d_k > scale (1 - h(uv_k))')
