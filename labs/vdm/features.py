"""Task 7: sharp features, and snapping the grid onto them.

A grid triangle can only reproduce a crease if grid vertices lie *on* the crease. After the
transport step the grid is dense near creases but its vertices still straddle them. Alignment
moves single grid vertices (in uv) onto the features:

1. **Sharp edges** are interior mesh edges whose dihedral angle (between the two face normals)
   exceeds ``angle``; **sharp corners** are vertices on more than two sharp edges (a box corner
   has three).
2. **Corner snapping**: the grid vertex nearest to a sharp corner's uv moves exactly onto it.
3. **Edge crossings**: where a grid edge crosses a sharp edge (in uv), the grid edge's nearer end
   moves onto the crossing point.

Rules: a grid vertex moves at most once (the first move locks it); a move that would fold a cell
(leave it with no diagonal split into two positive triangles, see
:func:`folded_cells`) is skipped; boundary vertices only move along their own edge of the square and the square's corners
never move.

Moves are applied in four passes, one per colour ``(i mod 2, j mod 2)``: two vertices of the same
colour never share a cell, so all moves of one pass can be checked for folds at once.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from geomlib.geometry import dihedral_angles
from geomlib.validate import as_array, check_float, check_mesh

from .grid import check_grid_inputs, check_vertex_indices, folded_cells
from .segments import segment_intersections

__all__ = ["sharp_features", "align_to_features", "grid_edges"]


def sharp_features(V, F, angle: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """Sharp edges and sharp corners of a triangle mesh.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
        Consistently oriented triangles.
    angle : float
        Threshold in degrees, ``0 < angle < 180``: an interior edge is sharp when the angle between
        its two face normals is larger (a cube edge: 90).

    Returns
    -------
    edges : (k, 2) int64
        Sharp edges (vertex pairs, smaller index first, sorted).
    corners : (c,) int64
        Sorted vertices on more than two sharp edges.

    Examples
    --------
    A closed box, one quad per side: 12 sharp edges, 8 corners.

    >>> from geomlib import datasets
    >>> V, F = datasets.sharp_box(n=1)
    >>> edges, corners = sharp_features(V, F)
    >>> len(edges), len(corners)
    (12, 8)
    """
    where = "sharp_features"
    V, F = check_mesh(V, F, where=where)
    angle = check_float(angle, "angle", minimum=1e-9, maximum=180.0 - 1e-9, where=where)
    raise NotImplementedError('Task 7a (sharp features): sharp edge = dihedral angle > angle; corner = on > 2 sharp edges')


def grid_edges(res: int) -> np.ndarray:
    """Vertex index pairs of the grid's edges (given helper): horizontal then vertical, ``(2 res (res-1), 2)``.

    Vertex ``(i, j)`` has index ``i * res + j``; every edge runs from its lower to its higher index.
    """
    q = np.arange(res * res).reshape(res, res)
    horizontal = np.stack([q[:, :-1].ravel(), q[:, 1:].ravel()], axis=1)
    vertical = np.stack([q[:-1, :].ravel(), q[1:, :].ravel()], axis=1)
    return np.concatenate([horizontal, vertical]).astype(np.int64)


def _apply_moves(G: np.ndarray, locked: np.ndarray, verts: np.ndarray, targets: np.ndarray) -> int:
    """Try to move grid vertices ``verts`` (flat indices) to ``targets``; returns the number moved.

    All ``verts`` must have one colour (no two share a cell) and be unlocked. Boundary vertices keep
    their edge; a move that folds one of the surrounding cells (:func:`folded_cells`) is undone.
    """
    res = G.shape[0]
    if len(verts) == 0:
        return 0
    i, j = verts // res, verts % res
    targets = targets.copy()
    # Boundary vertices: the target must lie on the same edge; corners of the square never move.
    ok = np.ones(len(verts), bool)
    for on_edge, coord, value in (
        (j == 0, 0, 0.0),
        (j == res - 1, 0, 1.0),
        (i == 0, 1, 0.0),
        (i == res - 1, 1, 1.0),
    ):
        ok &= ~on_edge | (np.abs(targets[:, coord] - value) <= 1e-9)
        targets[on_edge, coord] = value
    ok &= ~(((i == 0) | (i == res - 1)) & ((j == 0) | (j == res - 1)))
    verts, i, j, targets = verts[ok], i[ok], j[ok], targets[ok]
    old = G[i, j].copy()
    G[i, j] = targets
    # The up-to-four cells around each moved vertex (clipped at the border).
    di = np.array([-1, -1, 0, 0])
    dj = np.array([-1, 0, -1, 0])
    ci = i[:, None] + di
    cj = j[:, None] + dj
    valid = (ci >= 0) & (ci < res - 1) & (cj >= 0) & (cj < res - 1)
    bad_cell = folded_cells(G)
    bad = (bad_cell[np.clip(ci, 0, res - 2), np.clip(cj, 0, res - 2)] & valid).any(axis=1)
    G[i[bad], j[bad]] = old[bad]
    locked[i[~bad], j[~bad]] = True
    return int((~bad).sum())


def align_to_features(grid_uv, V, F, UV, edges, corners, *, return_moved: bool = False):
    """Move grid vertices onto sharp corners and sharp-edge crossings (in uv).

    Parameters
    ----------
    grid_uv : (res, res, 2) float64
        Grid positions in the parameter domain (e.g. from :func:`transport_grid`), unfolded.
    V : (n, 3) float64
    F : (m, 3) int64
    UV : (n, 2) float64
        The mesh's parameterization.
    edges : (k, 2) int64
        Sharp edges (mesh vertex pairs), e.g. from :func:`sharp_features`.
    corners : (c,) int64
        Sharp corner vertices.
    return_moved : bool
        Also return a ``(res, res)`` bool mask of the grid vertices that moved.

    Returns
    -------
    grid_uv : (res, res, 2) float64
        The aligned grid: still unfolded; boundary vertices still on their edges.

    Notes
    -----
    Order: first corners (each corner's nearest grid vertex), then edge crossings. For the
    crossings, every unlocked grid vertex takes the closest crossing among the grid edges for
    which it is the nearer end (``t <= 1/2`` along the edge picks the edge's first vertex). Each
    phase runs one pass per vertex colour ``(i mod 2, j mod 2)``; crossings are recomputed
    before every pass because earlier moves bend the grid edges.
    """
    where = "align_to_features"
    G, V, F, UV, edges = check_grid_inputs(grid_uv, V, F, UV, edges, where)
    G = G.copy()
    res = G.shape[0]
    corners = as_array(corners, "corners", shape=(None,), dtype=np.int64, where=where)
    check_vertex_indices(corners, "corners", len(V), where)
    locked = np.zeros((res, res), bool)
    raise NotImplementedError('Task 7b (alignment): snap corners, then the nearer end of each crossed grid edge; once per vertex, no folds')
    return (G, locked) if return_moved else G
