"""Task 3: steep parallax / relief mapping (parallax occlusion mapping): march the view ray, then refine the hit."""

from __future__ import annotations

import numpy as np

from .inputs import check_march, check_view_ray, height_lookup

__all__ = ["relief_uv", "layer_count", "REFINEMENTS"]

#: Refinements of the hit between the last two layers accepted by :func:`relief_uv`.
REFINEMENTS = ("none", "linear", "secant", "binary")


def layer_count(view_z, min_layers: int, max_layers: int) -> np.ndarray:
    """Given: layers of the march, more at grazing angles: ``n = floor(min + (max - min)(1 - view_z) + 1/2)``.

    ``view_z = n . v`` is 1 looking straight down (``min_layers``) and tends to 0 at grazing
    angles (``max_layers``).
    """
    return np.floor(min_layers + (max_layers - min_layers) * (1.0 - np.asarray(view_z)) + 0.5).astype(np.int64)


def relief_uv(
    height,
    uv,
    view,
    *,
    scale: float,
    min_layers: int = 8,
    max_layers: int = 32,
    refine: str = "secant",
    refine_steps: int = 5,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the view ray through ``uv`` first meets the relief (Policarpo et al. 2005, Tatarchuk 2006).

    The ray enters the polygon at ``uv`` and goes down; at normalised depth ``d`` in [0, 1] (the
    real depth is ``scale * d``) it is at ``uv(d) = uv - d * scale * view_xy / view_z``. It is
    below the surface where ``f(d) = d - (1 - h(uv(d))) >= 0`` (``f(1) = h >= 0``: it always
    ends below). The march steps through ``n`` layers (:func:`layer_count`)::

        d_i = i / n,  i = 0, 1, ..., n;     the hit layer is the first i with f(d_i) >= 0

    then refines the crossing between ``a = d_(i-1)`` (above, ``f_a < 0``) and ``b = d_i``
    (below, ``f_b >= 0``); with ``i = 0`` (``h(uv) = 1``) the hit is ``d = 0``:

    * ``"none"``   (steep parallax mapping): ``d = b``;
    * ``"linear"`` (parallax occlusion mapping): where the line through ``(a, f_a)``, ``(b, f_b)``
      crosses zero, ``d = a + (b - a) f_a / (f_a - f_b)``;
    * ``"secant"``: ``refine_steps`` secant steps ``x2 = x1 - f1 (x1 - x0) / (f1 - f0)`` from
      ``(x0, x1) = (a, b)``, each clamped to ``[a, b]`` (the first step is the linear one; a step
      with ``f1 = f0`` keeps ``x1``); ``d`` is the last iterate. Fast on smooth maps, but a step in
      the height field (bricks) can stall it on the wrong side of the edge;
    * ``"binary"``: ``refine_steps`` bisections of ``[a, b]`` keeping ``f(lo) < 0 <= f(hi)``;
      ``d = (lo + hi) / 2``. Halves the error each step, whatever the map.

    Parameters
    ----------
    height : (s, s) float in [0, 1], uint8 or uint16
    uv : (..., 2) float
    view : (3,) or (..., 3) float
        Tangent-space direction towards the eye (normalised here), ``z > 0``.
    scale : float >= 0
        Depth of the relief (UV units) where ``h = 0``.
    min_layers, max_layers : int, 1 <= min_layers <= max_layers
    refine : {"none", "linear", "secant", "binary"}
    refine_steps : int >= 0
        Iterations of ``"secant"`` and ``"binary"``.

    Returns
    -------
    uv : (..., 2) float64
        Texture coordinates of the hit.
    depth : (...) float64
        Its depth below the polygon, ``scale * d`` (UV units).
    steps : (...) int64
        The hit layer ``i`` (height samples taken by the march minus one; ``n`` on a map of zeros).

    Notes
    -----
    The march is sequential along each ray (every layer depends on the one before), so it loops
    over layers; each iteration works on all the pixels still marching at once.
    """
    where = "relief_uv"
    H, uv, V, scale = check_view_ray(height, uv, view, scale, where)
    lo_n, hi_n, steps_n = check_march(min_layers, max_layers, refine, refine_steps, REFINEMENTS, where)

    shape = uv.shape[:-1]
    u0, v0 = uv[..., 0].ravel(), uv[..., 1].ravel()
    # uv moves by (du, dv) per unit of normalised depth d.
    du = (-scale * V[..., 0] / V[..., 2]).ravel()
    dv = (-scale * V[..., 1] / V[..., 2]).ravel()
    n = layer_count(V[..., 2], lo_n, hi_n).ravel()

    h = height_lookup(H)  # height_at(H, ...) with the map padded once, not at every layer

    def f(k, d):
        """Depth below the surface of the ray point at normalised depth d (pixels k)."""
        return d - (1.0 - h(u0[k] + d * du[k], v0[k] + d * dv[k]))

    P = u0.size
    hit = np.zeros(P, dtype=np.int64)  # the hit layer i of each pixel
    f_hit = np.zeros(P)  # f(d_i) there (>= 0)
    f_above = np.zeros(P)  # f(d_(i-1)), the layer above (< 0)
    raise NotImplementedError('Task 3 (march): d_i = i / n for i = 0..n, stop at the first f(d_i) = d_i - (1 - h(uv(d_i))) >= 0')
    b = hit / n
    a = np.maximum(hit - 1, 0) / n
    d = b.copy()
    ref = np.flatnonzero(hit > 0)  # i = 0: the ray hits at the polygon, nothing to refine
    a_r, b_r, fa, fb = a[ref], b[ref], f_above[ref], f_hit[ref]
    if refine == "linear":
        raise NotImplementedError('Task 3 (linear): d = a + (b - a) f_a / (f_a - f_b)')
    elif refine == "secant":
        raise NotImplementedError('Task 3 (secant): x2 = x1 - f1 (x1 - x0) / (f1 - f0) clamped to [a, b], refine_steps times from (x0, x1) = (a, b)')
    elif refine == "binary":
        raise NotImplementedError('Task 3 (binary): refine_steps bisections of [a, b] keeping f(lo) < 0 <= f(hi); d = (lo + hi) / 2')
    out = np.stack([u0 + d * du, v0 + d * dv], axis=-1).reshape(*shape, 2)
    return out, (scale * d).reshape(shape), hit.reshape(shape)
