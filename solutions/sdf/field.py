"""Sampled distance fields: the dense grid and its trilinear lookup (Task 6, dense part).

A grid stores ``phi`` at the samples ``x_ijk = origin + spacing (i, j, k)`` (``values[i, j, k]``,
``i`` along x). Between samples the field is interpolated trilinearly, which is exact for planes
and within ``O(h^2)`` of a smooth field.

Outside the grid's box the stored field says nothing, so queries there return a *lower bound* on
the distance to a surface that lies inside the box: with ``q`` the point of the box closest to
``p`` and ``phi(q) >= 0``, every surface point ``s`` in the box satisfies
``|p - s|^2 >= |p - q|^2 + |q - s|^2`` (``q`` is the projection of ``p`` onto a convex set), so
``phi(p) >= sqrt(|p - q|^2 + phi(q)^2)``. It equals the grid on the box and grows like the
distance to the box, so sphere tracing walks straight into the box without stalling on its skin.
Where ``phi(q) < 0`` (a surface cut by the box) ``phi(q) + |p - q|`` is used (1-Lipschitz, continuous).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.validate import MeshError, as_array, check_float

from .analytic import as_points

__all__ = ["SDFGrid", "grid_points", "trilinear", "outside_rule", "check_grid"]


def check_grid(values, origin, spacing, where: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Validate a grid (given): values ``(a, b, c)`` with every side >= 2, finite origin, spacing > 0."""
    values = as_array(values, "values", dtype=np.float64, shape=(None, None, None), where=where)
    if min(values.shape) < 2:
        raise MeshError(f"{where}: the grid needs at least 2 samples per axis, got shape {values.shape}")
    origin = as_array(origin, "origin", dtype=np.float64, shape=(3,), where=where)
    spacing = check_float(spacing, "spacing", where=where)
    if spacing <= 0:
        raise MeshError(f"{where}: spacing must be > 0 (a grid with zero extent), got {spacing}")
    return values, origin, spacing


def grid_points(origin, spacing: float, shape) -> np.ndarray:
    """The sample positions ``(a*b*c, 3)`` in ``values.reshape(-1)`` order (given)."""
    axes = [origin[k] + spacing * np.arange(shape[k]) for k in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)


def outside_rule(P, Q, phi_q) -> np.ndarray:
    """The field at points ``P`` from the box points ``Q = clamp(P)`` and the field there (given).

    ``sqrt(|P - Q|^2 + phi_q^2)`` where ``phi_q >= 0``, ``phi_q + |P - Q|`` elsewhere (see the module
    docstring); equals ``phi_q`` inside the box.
    """
    PQ = P - Q
    dq = np.sqrt(np.einsum("ij,ij->i", PQ, PQ))
    return np.where(phi_q >= 0, np.hypot(dq, phi_q), phi_q + dq)


def trilinear(values, origin, spacing: float, P, *, validate: bool = True) -> np.ndarray:
    """Trilinear interpolation of a grid at points ``P`` (with the outside rule beyond the box).

    Parameters
    ----------
    values : (a, b, c) array_like
        Samples, ``values[i, j, k]`` at ``origin + spacing * (i, j, k)``.
    origin : (3,) array_like
    spacing : float
    P : (n, 3) array_like
    validate : bool
        Check the grid (skipped by :class:`SDFGrid`, which checked it once when it was made: a
        sphere tracer calls this for every step).

    Returns
    -------
    d : (n,) float64

    Notes
    -----
    Clamp ``P`` to the box (``Q``), take the continuous index ``u = (Q - origin) / spacing``, the cell
    ``i0 = min(floor(u), shape - 2)`` and the fractions ``f = u - i0``; blend the 8 corners with
    weights ``prod_k (f_k if corner_k else 1 - f_k)``. Then apply :func:`outside_rule`.
    """
    where = "trilinear"
    if validate:
        values, origin, spacing = check_grid(values, origin, spacing, where)
        P = as_points(P, where)
    else:
        P = np.asarray(P, np.float64)
    shape = np.array(values.shape)
    hi = origin + spacing * (shape - 1)
    Q = np.maximum(P, origin)
    np.minimum(Q, hi, out=Q)  # np.clip(P, origin, hi), without its overhead
    # BEGIN SOLUTION: Task 6 (queries): trilinear: u = (Q - origin)/h, i0 = clip(floor(u), 0, shape-2), f = u - i0, blend the 8 corners with weights prod(f or 1 - f), then outside_rule(P, Q, phi_q)
    # (a sphere tracer calls this for every step: in-place arithmetic, no temporaries it can avoid)
    f = Q - origin
    f /= spacing  # u >= 0, so truncation is floor
    i0 = f.astype(np.int64)
    np.minimum(i0, shape - 2, out=i0)
    f -= i0  # the fractions u - i0
    sx, sy = shape[1] * shape[2], shape[2]
    base = i0[:, 0] * sx + i0[:, 1] * sy + i0[:, 2]  # flat index of corner (0, 0, 0)
    flat = values.reshape(-1)
    # corner (dx, dy, dz) is at base + offset: gather it from the array shifted by that offset
    c = [flat[dx * sx + dy * sy + dz :].take(base) for dx in (0, 1) for dy in (0, 1) for dz in (0, 1)]
    # blend along z, then y, then x: 7 lerps a + w (b - a), each written in place into b
    for w in (f[:, 2], f[:, 1], f[:, 0]):
        for a, b in zip(c[0::2], c[1::2], strict=True):
            b -= a
            b *= w
            b += a
        c = c[1::2]  # 8 -> 4 -> 2 -> 1 blended values
    phi = c[0]
    outside = P[:, 0] != Q[:, 0]  # the outside rule changes nothing inside the box
    outside |= P[:, 1] != Q[:, 1]
    outside |= P[:, 2] != Q[:, 2]
    out = np.flatnonzero(outside)
    phi[out] = outside_rule(P[out], Q[out], phi[out])
    return phi
    # END SOLUTION


@dataclass(frozen=True)
class SDFGrid:
    """A dense signed distance grid.

    Attributes
    ----------
    values : (a, b, c) float64
        ``values[i, j, k] = phi(origin + spacing * (i, j, k))``.
    origin : (3,) float64
    spacing : float
    """

    values: np.ndarray
    origin: np.ndarray
    spacing: float

    def __post_init__(self):
        values, origin, spacing = check_grid(self.values, self.origin, self.spacing, "SDFGrid")
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "spacing", spacing)

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(self.values.shape)

    @property
    def upper(self) -> np.ndarray:
        """The far corner of the grid's box."""
        return self.origin + self.spacing * (np.array(self.values.shape) - 1)

    @property
    def nbytes(self) -> int:
        return int(self.values.nbytes)

    def points(self) -> np.ndarray:
        """Sample positions, ``(a*b*c, 3)``."""
        return grid_points(self.origin, self.spacing, self.values.shape)

    def sample(self, P) -> np.ndarray:
        """Trilinear lookup at ``P (n, 3)`` (see :func:`trilinear`)."""
        return trilinear(self.values, self.origin, self.spacing, as_points(P, "SDFGrid.sample"), validate=False)

    def __call__(self, P) -> np.ndarray:
        return self.sample(P)
