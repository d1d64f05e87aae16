"""Task 3: tangent-space normal maps from height maps (Blinn's bump mapping, as finite differences)."""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, check_choice, check_float

from .inputs import as_height_map

__all__ = ["height_to_normal_map", "BORDERS"]

#: How :func:`height_to_normal_map` reads heights beyond the image border.
BORDERS = ("clamp", "wrap")


def height_to_normal_map(H, strength: float | tuple[float, float] = 1.0, border: str = "clamp") -> np.ndarray:
    """Tangent-space normals of the relief ``z = strength * H(u, v)`` over the unit UV square.

    The relief's surface ``(u, v, strength H)`` has the (unnormalised) normal
    ``(-strength dH/du, -strength dH/dv, 1)`` (Blinn 1978: the height perturbs the normal by its
    gradient). The derivatives are central differences over one texel on each side; a texel is
    ``1 / s`` wide in UV, and ``v`` grows UPWARDS while rows grow downwards::

        dH/du[r, c] = (H[r, c + 1] - H[r, c - 1]) * s / 2
        dH/dv[r, c] = (H[r - 1, c] - H[r + 1, c]) * s / 2
        n[r, c]     = normalize(-k_u dH/du, -k_v dH/dv, 1)      (k_u = k_v = strength)

    Parameters
    ----------
    H : (s, s) float, uint8 or uint16
        Square height map; integer images are scaled to [0, 1] first.
    strength : float or (k_u, k_v)
        Height of the relief in UV units for ``H = 1`` (0 gives a flat map). For a displacement
        ``lam * scale * h`` on a surface whose UV square spans ``L`` units of length, the matching
        strength is ``lam * scale / L``. A pair gives separate factors for ``u`` and ``v``, for
        surfaces whose UV square is stretched (``L_u != L_v``): ``k = lam * scale / L``.
    border : {"clamp", "wrap"}
        Texels beyond the border: ``"clamp"`` repeats the border texel (like ``GL_CLAMP_TO_EDGE``;
        the slope at the border is then halved), ``"wrap"`` reads the opposite side (tileable maps).

    Returns
    -------
    (s, s, 3) float64
        Unit tangent-space normals (``z > 0``).

    Raises
    ------
    MeshError
        Not a square single-channel map, bad ``strength`` or ``border``.
    """
    where = "height_to_normal_map"
    H = as_height_map(H, where, name="H")
    if isinstance(strength, tuple | list | np.ndarray):
        k = np.asarray(strength)
        if k.shape != (2,):
            raise MeshError(f"{where}: strength must be a number or a pair (k_u, k_v), got shape {k.shape}")
        ku = check_float(k[0], "strength[0]", where=where)
        kv = check_float(k[1], "strength[1]", where=where)
    else:
        ku = kv = check_float(strength, "strength", where=where)
    check_choice(border, "border", BORDERS, where=where)
    s = H.shape[0]
    raise NotImplementedError('Task 3 (height to normals): n = normalize(-k_u dH/du, -k_v dH/dv, 1), central differences, v up = row up')
