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

    # BEGIN SOLUTION: Task 2 (placement): solve A x = -b; singular -> t* = -dᵀ(A v1 + b) / dᵀAd on [0, 1]; else best of mid, v1, v2
    # Every step is an elementwise product or sum in a fixed order (the adjugate of A instead of
    # np.linalg.det / np.linalg.solve, and no ``** 3``), so the result is the same on every CPU:
    # LAPACK's and np.power's last bits depend on which SIMD kernels the machine runs, and one
    # flipped bit in a cost can reorder the greedy loop. It is also the compiled loop's formula
    # (``compiled.place``), operation for operation.
    def dot(x, y):
        return x[:, 0] * y[:, 0] + x[:, 1] * y[:, 1] + x[:, 2] * y[:, 2]

    def cross(x, y):
        return np.stack(
            [x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1], x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2],
             x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]], axis=1)  # fmt: skip

    A, b, c = Q[:, :3, :3], Q[:, :3, 3], Q[:, 3, 3]
    A0, A1, A2 = A[:, 0], A[:, 1], A[:, 2]  # rows
    adj0, adj1, adj2 = cross(A1, A2), cross(A2, A0), cross(A0, A1)  # A⁻¹ = [adj0 adj1 adj2] / det (A symmetric)
    det = dot(A0, adj0)
    norm = np.sqrt(dot(A0, A0) + dot(A1, A1) + dot(A2, A2))  # Frobenius norm
    regular = np.abs(det) > SINGULAR_RCOND * (norm * norm * norm)
    position = np.empty((len(Q), 3))
    if regular.any():
        s = (-1.0 / det[regular])[:, None]  # x = -A⁻¹ b
        br = b[regular]
        position[regular] = s * (adj0[regular] * br[:, 0:1] + adj1[regular] * br[:, 1:2] + adj2[regular] * br[:, 2:3])
    singular = ~regular
    if singular.any():
        # The minimum on the segment v1 + t d, or, when the cost is flat along it, the best of the
        # midpoint, v1 and v2 (ties within round-off in that order of preference).
        S0, S1, S2, bs, cs = A0[singular], A1[singular], A2[singular], b[singular], c[singular]
        p1, p2 = v1[singular], v2[singular]
        d = p2 - p1
        Ad = np.stack([dot(S0, d), dot(S1, d), dot(S2, d)], axis=1)
        dAd = dot(d, Ad)
        slope = dot(Ad, p1) + dot(d, bs)  # dᵀ(A v1 + b), A symmetric
        trace = S0[:, 0] + S1[:, 1] + S2[:, 2]
        length2 = dot(d, d)
        reach = np.maximum(dot(p1, p1), dot(p2, p2)) + length2
        scale = trace * reach + np.abs(cs)  # size of the terms whose round-off we must ignore
        on_segment = dAd > TIE_RTOL * trace * length2
        t = np.minimum(np.maximum(np.divide(-slope, dAd, out=np.zeros_like(dAd), where=on_segment), 0.0), 1.0)
        # Flat along the segment: compare the midpoint, v1, v2 (in that order of preference).
        cand = np.stack([0.5 * (p1 + p2), p1, p2], axis=1)  # (s, 3, 3)
        cand_cost = quadric_error(Q[singular][:, None], cand)  # (s, 3)
        best = cand_cost.min(axis=1, keepdims=True)
        pick = np.argmax(cand_cost <= best + TIE_RTOL * scale[:, None], axis=1)
        fallback = cand[np.arange(len(cand)), pick]
        t = t[:, None]
        position[singular] = np.where(on_segment[:, None], p1 + t * d, fallback)
    cost = np.maximum(quadric_error(Q, position), 0.0)
    if single:
        return position[0], cost[0]  # (3,) and a 0-d float
    return position, cost
    # END SOLUTION
