"""Task 1: Blinn bump mapping — the height field's gradient perturbs the normal (in tangent space)."""

from __future__ import annotations

import numpy as np

from geomlib.validate import check_float

from .inputs import check_height, check_uv_points, height_at

__all__ = ["bump_offset", "bump_normal"]


def bump_offset(height, uv, *, strength: float) -> np.ndarray:
    """Blinn's offset vector ``(du, dv) = strength * (dh/du, dh/dv)`` at ``uv``, by central differences.

    The derivatives step one texel (``1 / s`` in UV) each way, reading the height bilinearly
    (:func:`~.inputs.height_at`, clamp-to-edge)::

        dh/du = (h(u + 1/s, v) - h(u - 1/s, v)) * s / 2
        dh/dv = (h(u, v + 1/s) - h(u, v - 1/s)) * s / 2

    On a flat polygon (tangent space: ``T = x``, ``B = y``, ``N = z``) Blinn's perturbed normal
    ``N + D`` with ``D = -(du T + dv B)`` is the normal of the surface ``z = strength * h(u, v)``:
    see :func:`bump_normal`.

    Parameters
    ----------
    height : (s, s) float in [0, 1], uint8 or uint16
    uv : (..., 2) float
    strength : float
        Height of the relief in UV units for ``h = 1`` (the lab's ``scale``).

    Returns
    -------
    (..., 2) float64
    """
    where = "bump_offset"
    H = check_height(height, where)
    uv = check_uv_points(uv, where)
    k = check_float(strength, "strength", where=where)
    s = H.shape[0]
    u, v = uv[..., 0], uv[..., 1]
    raise NotImplementedError('Task 1 (bump offset): (du, dv) = strength * ((h(u+1/s) - h(u-1/s)) s/2, (h(v+1/s) - h(v-1/s)) s/2)')


def bump_normal(height, uv, *, strength: float) -> np.ndarray:
    """Tangent-space normal of the bump-mapped polygon at ``uv`` (Blinn 1978)::

        n = normalize(-du, -dv, 1)        with (du, dv) = bump_offset(height, uv, strength=strength)

    At texel centres this is exactly the maps lab's ``height_to_normal_map(height, strength,
    border="clamp")`` (the same central differences).

    Parameters
    ----------
    height : (s, s) float in [0, 1], uint8 or uint16
    uv : (..., 2) float
    strength : float

    Returns
    -------
    (..., 3) float64 unit vectors, ``z > 0``.
    """
    check_height(height, "bump_normal")  # validated here too, so bad input is named by this function
    raise NotImplementedError('Task 1 (bump normal): n = normalize(-du, -dv, 1) from bump_offset')
