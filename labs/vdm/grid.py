"""Given helpers: the regular grid a VDM displaces, its cells, triangles and fold test.

Conventions used throughout the lab: a grid has ``res x res`` vertices; vertex ``(i, j)`` (row i,
column j) sits at ``(u, v) = (j, i) / (res - 1)`` on the uniform grid, so rows run along v and row 0
is v = 0. Cell ``(i, j)`` has corners ``a = (i, j)``, ``b = (i, j+1)``, ``c = (i+1, j+1)``,
``d = (i+1, j)``, counter-clockwise in uv. Its diagonal flag is True for the split along ``a-c``
(triangles ``abc``, ``acd``) and False for ``b-d`` (``abd``, ``bcd``).
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array, check_mesh

__all__ = [
    "uniform_grid",
    "cell_areas",
    "split_ok",
    "folded_cells",
    "convex_cells",
    "valid_diagonals",
    "grid_faces",
]


def uniform_grid(res: int) -> np.ndarray:
    """The uniform ``res x res`` grid over ``[0, 1]^2``: ``grid[i, j] = (j, i) / (res - 1)`` (u, v)."""
    t = np.linspace(0.0, 1.0, res)
    v, u = np.meshgrid(t, t, indexing="ij")
    return np.stack([u, v], axis=-1)


def cell_areas(grid_uv) -> np.ndarray:
    """Signed areas of the four corner triangles of every grid cell, ``(res-1, res-1, 4)``.

    Cell ``(i, j)`` has corners ``a = (i, j)``, ``b = (i, j+1)``, ``c = (i+1, j+1)``, ``d = (i+1, j)``
    (counter-clockwise in uv); the corner triangles are ``(d, a, b)``, ``(a, b, c)``, ``(b, c, d)``,
    ``(c, d, a)``. All four are positive exactly when the cell is a strictly convex, unflipped quad
    — then either diagonal splits it into two positive triangles.
    """
    g = np.asarray(grid_uv, np.float64)
    a, b, c, d = g[:-1, :-1], g[:-1, 1:], g[1:, 1:], g[1:, :-1]

    def tri(p, q, r):
        return 0.5 * (
            (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])
        )

    return np.stack([tri(d, a, b), tri(a, b, c), tri(b, c, d), tri(c, d, a)], axis=-1)


def split_ok(grid_uv, *, rel_tol: float = 1e-9) -> np.ndarray:
    """Which diagonal splits of every cell give two positive triangles, ``(res-1, res-1, 2)`` bool.

    ``[..., 0]``: split a-c (triangles abc, cda); ``[..., 1]``: split b-d (dab, bcd). A triangle
    counts as positive when its area exceeds ``rel_tol`` times the area of a uniform cell.
    """
    res = np.asarray(grid_uv).shape[0]
    pos = cell_areas(grid_uv) > rel_tol / (res - 1) ** 2
    return np.stack([pos[..., 1] & pos[..., 3], pos[..., 0] & pos[..., 2]], axis=-1)


def folded_cells(grid_uv, *, rel_tol: float = 1e-9) -> np.ndarray:
    """Boolean ``(res-1, res-1)``: cells that are flipped or folded — neither diagonal split works.

    A cell is usable when at least one of its two splits (:func:`split_ok`) gives two positive
    triangles; it may then be non-convex (e.g. a vertex snapped onto the line through two others),
    and the triangulation must use the working split.
    """
    ok = split_ok(grid_uv, rel_tol=rel_tol)
    return ~(ok[..., 0] | ok[..., 1])


def convex_cells(grid_uv, *, rel_tol: float = 1e-9) -> np.ndarray:
    """Boolean ``(res-1, res-1)``: cells that are strictly convex quads (all four corner triangles positive).

    A grid whose cells are all convex is a bijective map of the square for *any* diagonal choice.
    """
    res = np.asarray(grid_uv).shape[0]
    return (cell_areas(grid_uv) > rel_tol / (res - 1) ** 2).all(axis=-1)


def valid_diagonals(grid_uv, default: bool = True) -> np.ndarray:
    """The global split ``default`` everywhere, except in cells where only the other split works."""
    ok = split_ok(grid_uv)
    use_default = ok[..., 0] if default else ok[..., 1]
    return np.where(use_default, bool(default), not default)


def grid_faces(res: int, diagonals=None) -> np.ndarray:
    """Triangles of the ``res x res`` grid, two per cell, cell by cell (row-major), ``(2 (res-1)^2, 3)``.

    ``diagonals`` ``(res-1, res-1)`` bool picks each cell's split (True: a-c, False: b-d; default
    all True). Vertex ``(i, j)`` has index ``i * res + j``. Triangles are counter-clockwise in uv.
    """
    q = np.arange(res * res).reshape(res, res)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    diag = np.ones(a.shape, bool) if diagonals is None else np.asarray(diagonals, bool).ravel()
    t1 = np.where(diag[:, None], np.stack([a, b, c], 1), np.stack([a, b, d], 1))
    t2 = np.where(diag[:, None], np.stack([a, c, d], 1), np.stack([b, c, d], 1))
    return np.stack([t1, t2], axis=1).reshape(-1, 3).astype(np.int64)


def check_vertex_indices(idx: np.ndarray, name: str, n: int, where: str) -> None:
    """Raise :class:`MeshError` unless every entry of ``idx`` is a vertex index ``0..n-1``."""
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        bad = int(idx.max() if idx.max() >= n else idx.min())
        raise MeshError(f"{where}: {name} holds vertex index {bad}, valid indices are 0..{n - 1}")


def check_grid_inputs(grid_uv, V, F, UV, edges, where: str):
    """Validate the inputs shared by the feature steps: a ``(res, res, 2)`` grid, a mesh, its UVs, sharp edges.

    Returns
    -------
    G : (res, res, 2) float64
    V, F, UV, edges
        Checked arrays (``edges`` as ``(k, 2)`` int64 vertex indices).
    """
    G = as_array(grid_uv, "grid_uv", shape=(None, None, 2), where=where)
    if G.shape[1] != G.shape[0] or G.shape[0] < 2:
        raise MeshError(f"{where}: grid_uv has shape {G.shape}; expected (res, res, 2) with res >= 2")
    V, F = check_mesh(V, F, where=where)
    UV = as_array(UV, "UV", shape=(len(V), 2), where=where)
    edges = as_array(edges, "edges", shape=(None, 2), dtype=np.int64, where=where)
    check_vertex_indices(edges, "edges", len(V), where)
    return G, V, F, UV, edges
