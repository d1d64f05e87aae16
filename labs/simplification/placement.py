"""Where a contracted pair goes: the point that minimises the summed quadric.

Contracting the pair ``(v1, v2)`` replaces both by one vertex ``v̄`` with quadric ``Q = Q1 + Q2``.
The best ``v̄`` minimises ``vᵀ Q v`` over ``v = (x, y, z, 1)``. Writing

    Q = [[A, b], [bᵀ, c]]      (A: 3×3, b: 3-vector, c: scalar),
    vᵀ Q v = xᵀ A x + 2 bᵀ x + c,

the gradient vanishes where ``A x = -b``. That is the 4×4 system of Garland & Heckbert
``[[A, b], [0 0 0 1]] v̄ = (0, 0, 0, 1)ᵀ``. It has no unique solution when ``A`` is singular:
all planes parallel (a flat neighbourhood: a whole plane of minimisers) or all containing one
direction (a ridge or a cylinder: a line of minimisers). Then we minimise along the segment
``v1 + t (v2 - v1)``, ``t ∈ [0, 1]``, and when even that is flat we take the best of ``v1``,
``v2`` and the midpoint.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array

from .quadrics import quadric_error

__all__ = ["optimal_contraction", "SINGULAR_RCOND"]

#: ``A`` counts as singular when ``|det A| <= SINGULAR_RCOND · ‖A‖_F³`` (scale-free test).
SINGULAR_RCOND = 1e-10

#: Costs closer than this (relative to the cost scale ``trace(A)·L² + |c|``) are ties.
TIE_RTOL = 1e-9


def _floats(x, name: str) -> np.ndarray:
    """float64 array, finite (a light check: this runs once per contraction in the greedy loop)."""
    if not (isinstance(x, np.ndarray) and x.dtype == np.float64):
        x = as_array(x, name, where="optimal_contraction")
    if not np.isfinite(x).all():
        raise MeshError(f"optimal_contraction: {name} holds NaN or inf")
    return x


def optimal_contraction(Q, v1, v2) -> tuple[np.ndarray, np.ndarray]:
    """Best position for contracting ``v1`` and ``v2`` and its quadric cost.

    Parameters
    ----------
    Q : (4, 4) or (k, 4, 4) array_like of float
        Summed quadric ``Q1 + Q2`` of the pair (symmetric).
    v1, v2 : (3,) or (k, 3) array_like of float
        The two vertex positions.

    Returns
    -------
    position : (3,) or (k, 3) float64
        * regular ``A``: the solution of ``A x = -b``;
        * singular ``A`` (``|det A| <= 1e-10 ‖A‖_F³``): the minimiser ``v1 + t* d`` on the
          segment, ``d = v2 - v1``, ``t* = clip(-dᵀ(A v1 + b) / dᵀ A d, 0, 1)``;
        * singular ``A`` and ``dᵀ A d ≈ 0`` (the cost does not change along the segment): the best
          of the midpoint, ``v1`` and ``v2``; ties (costs equal to round-off) go to the midpoint,
          then to ``v1``.
    cost : () or (k,) float64
        ``vᵀ Q v`` at the position, clipped at 0 (round-off can make it slightly negative).

    Examples
    --------
    Three planes x = 1, y = 2, z = 3 meet in one point:

    >>> Q = sum(np.outer(p, p) for p in ([1, 0, 0, -1], [0, 1, 0, -2], [0, 0, 1, -3]))
    >>> position, cost = optimal_contraction(Q, [0, 0, 0], [1, 1, 1])
    >>> position.tolist(), float(cost)
    ([1.0, 2.0, 3.0], 0.0)
    """
    Q, v1, v2 = _floats(Q, "Q"), _floats(v1, "v1"), _floats(v2, "v2")
    single = Q.ndim == 2
    if Q.shape[-2:] != (4, 4) or Q.ndim not in (2, 3):
        raise MeshError(f"optimal_contraction: Q has shape {Q.shape}, expected (4, 4) or (k, 4, 4)")
    expected = (3,) if single else (Q.shape[0], 3)
    for name, v in (("v1", v1), ("v2", v2)):
        if v.shape != expected:
            raise MeshError(
                f"optimal_contraction: {name} has shape {v.shape}, expected {expected} to match Q {Q.shape}"
            )
    Q, v1, v2 = Q.reshape(-1, 4, 4), v1.reshape(-1, 3), v2.reshape(-1, 3)  # batch of k = 1 when single

    raise NotImplementedError('Task 2 (placement): solve A x = -b; singular -> t* = -dᵀ(A v1 + b) / dᵀAd on [0, 1]; else best of mid, v1, v2')
