"""Unit vectors: normalising rows, and checking per-vertex direction arrays.

Shared by the library (normals in :mod:`geomlib.geometry`) and by every lab that takes normals
or directions (maps, denoise, ...), so a zero vector is handled, and reported, the same way
everywhere.
"""

from __future__ import annotations

import numpy as np

from geomlib.errors import MeshError, prefix
from geomlib.validate import as_array

__all__ = ["normalize_rows", "as_unit_vectors"]


def normalize_rows(X, fallback=None) -> np.ndarray:
    """Unit vectors along the last axis; zero-length rows become ``fallback`` (or stay zero).

    Never divides by zero, so never NaN.

    Parameters
    ----------
    X : (..., d) array_like
        Float arrays keep their dtype; anything else becomes float64.
    fallback : (d,) array_like, optional
        Value of rows of length zero (default: they stay zero).

    Returns
    -------
    (..., d) float array
    """
    X = np.asarray(X)
    if X.dtype.kind != "f":
        X = X.astype(np.float64)
    n = np.linalg.norm(X, axis=-1, keepdims=True)
    zero = n == 0
    out = X / np.where(zero, 1.0, n)
    if fallback is not None and zero.any():
        out[zero[..., 0]] = np.asarray(fallback, dtype=X.dtype)
    return out


def as_unit_vectors(N, n: int, where: str | None = None, name: str = "N", *, ref: str = "V") -> np.ndarray:
    """One direction per vertex, ``(n, 3)`` float64, normalised; a zero row is an error.

    Parameters
    ----------
    N : (n, 3) array_like
        Directions (e.g. vertex normals); any non-zero length.
    n : int
        Rows expected (the number of rows of ``ref``).
    where, name : str
        Function and argument names for error messages.
    ref : str
        Name of the array ``N`` must match row for row, for messages (``"V"``).
    """
    p = prefix(where)
    N = as_array(N, name, shape=(None, 3), where=where)
    if len(N) != n:
        raise MeshError(f"{p}{name} has {len(N)} rows but {ref} has {n}; expected one normal per vertex")
    length = np.linalg.norm(N, axis=1)
    if (length == 0).any():
        r = int(np.flatnonzero(length == 0)[0])
        raise MeshError(
            f"{p}{name} row {r} is the zero vector ({int((length == 0).sum())} zero rows); every vertex needs a direction"
        )
    return N / length[:, None]
