"""Given helpers: small disk-topology test shapes with known sharp features.

A VDM can only describe a surface that is a topological disk, so closed shapes are opened by
removing their bottom faces.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.validate import check_int, check_mesh

__all__ = ["open_box", "remove_bottom", "grid_mesh"]


def grid_mesh(n: int, m: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A flat ``n x m``-quad grid over ``[0, 1]^2`` (z = 0), each quad split into two triangles.

    Returns ``V ((n+1)(m+1), 3)`` and ``F (2nm, 3)``, counter-clockwise seen from +z.
    """
    m = n if m is None else m
    y, x = np.meshgrid(np.linspace(0, 1, m + 1), np.linspace(0, 1, n + 1), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    q = np.arange((n + 1) * (m + 1)).reshape(m + 1, n + 1)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)
    return V, F


def open_box(n: int = 4, size=(1.0, 1.0, 0.5)) -> tuple[np.ndarray, np.ndarray]:
    """A box ``[0, sx] x [0, sy] x [0, sz]`` without its bottom face: a disk with 8 sharp corners.

    ``geomlib.datasets.sharp_box`` with the faces of its bottom side removed, moved so that its
    bottom rim lies in the plane z = 0 with corners (0, 0, 0) and (sx, sy, 0). Every side is an
    ``n x n`` grid of split quads; normals point outwards. The boundary loop is the bottom rim;
    the 4 top corners are sharp corners (three 90 degree edges meet there) and the 4 top and 4
    vertical edges are sharp creases.

    Parameters
    ----------
    n : int
        Quads per side edge (>= 1).
    size : (3,) float
        Box extents.

    Returns
    -------
    V : (5 n^2 + 4 n + 1, 3) float64
    F : (10 n^2, 3) int64
    """
    n = check_int(n, "n", minimum=1, where="open_box")
    s = np.asarray(size, np.float64)
    V, F = datasets.sharp_box(s, n)
    V, F = remove_bottom(V, F)
    return V + s / 2, F


def remove_bottom(V, F, *, tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Open a closed mesh by deleting every face lying in its lowest z-plane; drop unused vertices.

    Parameters
    ----------
    V, F : triangle mesh
    tol : float
        Faces whose three vertices are within ``tol * (bbox diagonal)`` of ``min z`` are removed.
    """
    V, F = check_mesh(V, F, where="remove_bottom")
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    low = V[:, 2] <= V[:, 2].min() + tol * diag
    F = F[~low[F].all(axis=1)]
    used = np.unique(F)
    remap = np.full(len(V), -1, np.int64)
    remap[used] = np.arange(len(used))
    return V[used], remap[F]
