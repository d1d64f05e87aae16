"""Task 8: per-quad diagonals that follow sharp edges.

Each grid cell becomes two triangles. With one global split (every cell cut along ``a-c``) a crease
running along the other diagonal ``b-d`` is cut off in every cell it crosses, leaving a zig-zag.
Per cell we therefore choose the split whose triangles stay closest to the surface, but only in
cells that a sharp edge crosses (elsewhere the global default is kept, so smooth regions stay
regular).

Error of a split: the grid vertices' surface points ``P_k = p(g_k)`` are the corners of the flat
triangles; we put a few sample points ``sum l_k P_k`` on each flat triangle (centroid and three
points toward the corners) and add up their squared distances to the original mesh (closest
point, ``geomlib.geometry.closest_points``). The split with the smaller sum wins. A crease running
along ``a-c`` gives zero error for the ``a-c`` split, while the ``b-d`` split cuts the crease's
corner off and its triangles sink below the surface.

A split whose triangles are not both positive in uv (possible after alignment made a cell
non-convex) is never chosen.
"""

from __future__ import annotations

import numpy as np

from geomlib.geometry import closest_points

from .grid import check_grid_inputs, split_ok, valid_diagonals
from .sampling import sample_surface
from .segments import segment_intersections

__all__ = ["crossed_cells", "choose_diagonals"]

# Barycentric sample points inside a triangle: the centroid and three points toward the corners.
_SAMPLES = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])


def crossed_cells(grid_uv: np.ndarray, S0: np.ndarray, S1: np.ndarray) -> np.ndarray:
    """Cells ``(res-1, res-1)`` whose interior a uv segment ``S0-S1`` passes through (given helper).

    A segment crosses a cell when it meets one of the cell's diagonals strictly between the
    diagonal's ends (a segment running *along* a cell side touches the diagonals only at corners).
    """
    g = np.asarray(grid_uv, np.float64)
    res = g.shape[0]
    a, b, c, d = (x.reshape(-1, 2) for x in (g[:-1, :-1], g[:-1, 1:], g[1:, 1:], g[1:, :-1]))
    crossed = np.zeros(len(a), bool)
    for P0, P1 in ((a, c), (b, d)):
        ip, _, t, _, _ = segment_intersections(P0, P1, S0, S1)
        inner = (t > 1e-9) & (t < 1 - 1e-9)
        crossed[ip[inner]] = True
    return crossed.reshape(res - 1, res - 1)


def choose_diagonals(grid_uv, V, F, UV, edges, *, default: bool = True) -> np.ndarray:
    """Per-cell diagonal: True = split along ``a-c`` (triangles abc, acd), False = ``b-d`` (abd, bcd).

    Parameters
    ----------
    grid_uv : (res, res, 2) float64
        Grid positions in uv (cell ``(i, j)`` has corners ``a=(i,j)``, ``b=(i,j+1)``,
        ``c=(i+1,j+1)``, ``d=(i+1,j)``).
    V, F : triangle mesh
    UV : (n, 2) float64
        The mesh's parameterization.
    edges : (k, 2) int64
        Sharp edges (from :func:`sharp_features`).
    default : bool
        Diagonal of cells that no sharp edge crosses (unless only the other split gives two positive
        triangles there, see :func:`valid_diagonals`).

    Returns
    -------
    diagonals : (res-1, res-1) bool
    """
    where = "choose_diagonals"
    G, V, F, UV, edges = check_grid_inputs(grid_uv, V, F, UV, edges, where)
    diag = valid_diagonals(G, default)
    if len(edges) == 0:
        return diag
    raise NotImplementedError('Task 8 (diagonals): in cells a sharp edge crosses, the split with the smaller surface deviation')
    return diag
