"""The error every geomlib check raises, and the pieces its messages are made of (leaf module).

This module imports nothing from geomlib, so every other module (``validate``, ``topology``,
``geometry``, ...) can raise :class:`MeshError` without importing each other.
``geomlib.validate.MeshError`` is the same class.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MeshError", "prefix", "fmt_row", "to_int64"]


class MeshError(ValueError):
    """Invalid mesh, array, image or parameter. The message names the problem and the place."""


def prefix(where: str | None) -> str:
    """Message prefix ``"where: "`` naming the public function that was called (empty without one)."""
    return f"{where}: " if where else ""


def fmt_row(row: np.ndarray) -> str:
    """A short ``(a, b, c)`` rendering of one array row for messages."""
    return "(" + ", ".join(f"{x:.6g}" if isinstance(x, float | np.floating) else str(x) for x in row) + ")"


_INT64_MAX = np.iinfo(np.int64).max


def to_int64(a: np.ndarray, name: str, where: str | None = None) -> np.ndarray:
    """Integer values of a numeric array as contiguous int64, or a :class:`MeshError`.

    Booleans, strings and objects are rejected; floats must be finite and integral; values that do
    not fit in int64 (a ``uint64`` index ``2**63``, a float ``1e19``) are reported as too large
    instead of wrapping around to negative numbers.
    """
    p = prefix(where)
    if a.dtype.kind not in "iuf":
        raise MeshError(f"{p}{name} has dtype {a.dtype}, expected integers")
    if a.dtype.kind == "f" and a.size:
        if not np.all(np.isfinite(a)):
            raise MeshError(f"{p}{name} holds NaN or inf, expected integers")
        if not np.all(a == np.round(a)):
            bad = np.argwhere(a != np.round(a))[0]
            raise MeshError(f"{p}{name} holds a non-integer value {a[tuple(bad)]} at {tuple(int(i) for i in bad)}")
    if a.size and a.dtype.kind in "uf":
        big = a > np.uint64(_INT64_MAX) if a.dtype.kind == "u" else np.abs(a) >= 2.0**63
        if big.any():
            bad = np.argwhere(big)[0]
            raise MeshError(
                f"{p}{name} holds {a[tuple(bad)]:.20g} at {tuple(int(i) for i in bad)}, too large for an index (int64)"
            )
    return np.ascontiguousarray(a, dtype=np.int64)
