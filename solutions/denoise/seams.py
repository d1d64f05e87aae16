"""Task 6: the seam fix. Vertices that a UV seam duplicates (same position, different UV) must move as one.

A texture atlas cuts the surface open along seams: every vertex on a seam exists once per chart,
with the same position and a different ``(u, v)``. Seen through ``F`` alone, the copies are
different vertices on the boundary of a cut, so (a) each copy sees only the neighbours on its side
of the cut, and its Laplacian offset is wrong, and (b) each copy reads the offset map at its own
texels and gets a slightly different offset. Either way the copies move apart and the seam
cracks open. The fix: weld by position for the Laplacian, and give all copies the same (mean)
offset and normal when moving.
"""

from __future__ import annotations

import numpy as np

from geomlib.textures import weld_by_position
from geomlib.validate import MeshError, as_array, check_float, check_mesh

__all__ = ["weld_seams", "seam_mean"]


def weld_seams(V, F, tol: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge the copies of every vertex that a UV seam duplicated: one vertex per position.

    Vertices with equal coordinates form a group; group ``g`` becomes vertex ``g`` of the
    welded mesh and every face is re-indexed to the groups, ``Fw = group[F]``. Groups are
    numbered in order of first appearance (the group of vertex 0 is 0, the next new position
    gets 1, ...), so on a mesh without seams this is the identity (``Vw = V``, ``Fw = F``,
    ``group = arange(n)``).

    Seam copies carry exactly the same coordinates (an exporter writes one position and several
    UVs), so exact equality is the default. Sort the rows of ``V`` (``np.lexsort``): equal rows
    become neighbours, and a new group starts wherever a row differs from the one before it. With
    ``tol``, vertices closer than ``tol`` are joined instead
    (:func:`geomlib.textures.weld_by_position`, a k-d tree; slower).

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    tol : float, optional
        Join vertices closer than this (units of ``V``); ``None`` joins equal positions only.

    Returns
    -------
    Vw : (k, 3) float64
        One vertex per group (``k <= n``): the position of its first member, ``Vw[group] == V``
        (up to ``tol``).
    Fw : (m', 3) int64
        ``group[F]``; faces that welding made degenerate (two corners in one group) are dropped.
    group : (n,) int64
        Group of every input vertex, ``0 .. k - 1``.

    Examples
    --------
    >>> V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]]        # vertex 3 copies vertex 1
    >>> Vw, Fw, group = weld_seams(V, [[0, 1, 2], [3, 2, 0]])
    >>> group.tolist(), Fw.tolist()
    ([0, 1, 2, 1], [[0, 1, 2], [1, 2, 0]])
    """
    where = "weld_seams"
    V, F = check_mesh(V, F, where=where)
    if tol is not None:
        tol = check_float(tol, "tol", minimum=0.0, where=where)
    n = len(V)
    # BEGIN PROMPT
    # Vw, Fw, group = ..., ..., ...  # (k, 3) float, (m, 3) int, (n,) int
    # END PROMPT
    # BEGIN SOLUTION: Task 6 (seam fix, weld): group = label of each distinct position (np.lexsort on the rows of V; weld_by_position when tol is given), numbered by first appearance; Vw = V[first vertex of each group]; Fw = group[F]
    if tol is None:
        order = np.lexsort(V.T[::-1])  # stable: equal rows keep increasing vertex order
        Vs = V[order]
        starts = np.r_[True, (Vs[1:] != Vs[:-1]).any(axis=1)] if n else np.zeros(0, bool)
        first = order[starts]  # first vertex of every group, groups in sorted order
        rank = np.empty(len(first), np.int64)
        rank[np.argsort(first)] = np.arange(len(first))  # renumber by first appearance
        group = np.empty(n, np.int64)
        group[order] = rank[np.cumsum(starts) - 1]
        first = np.sort(first)
    else:
        group, k = weld_by_position(V, tol)
        first = np.full(k, n, np.int64)
        np.minimum.at(first, group, np.arange(n))
    Vw = V[first]
    Fw = group[F]
    # END SOLUTION
    # Two corners of one triangle at the same position (a sliver thinner than tol): nothing to keep.
    Fw = Fw[(Fw[:, 0] != Fw[:, 1]) & (Fw[:, 1] != Fw[:, 2]) & (Fw[:, 2] != Fw[:, 0])]
    return Vw, Fw, group


def seam_mean(values, group) -> np.ndarray:
    """Mean of per-vertex ``values`` over every group of seam copies.

    ``out[g] = (1 / |G_g|) sum_{i in G_g} values[i]`` with ``G_g = {i : group[i] = g}``.
    ``out[group]`` gives every copy the same value (use it for offsets and normals, so that the
    copies of a seam vertex move identically).

    Parameters
    ----------
    values : (n,) or (n, c) float
    group : (n,) int
        Group labels ``0 .. k - 1`` from :func:`weld_seams`.

    Returns
    -------
    out : (k,) or (k, c) float64
        ``k = group.max() + 1``; a label that no vertex uses gets 0.
    """
    where = "seam_mean"
    values = as_array(values, "values", where=where)
    if values.ndim not in (1, 2):
        raise MeshError(f"{where}: values has shape {values.shape}, expected (n,) or (n, c)")
    group = as_array(group, "group", shape=(None,), dtype=np.int64, where=where)
    if len(group) != len(values):
        raise MeshError(f"{where}: group has {len(group)} labels but values has {len(values)} rows; expected one each")
    if len(group) and group.min() < 0:
        raise MeshError(f"{where}: group holds a negative label {int(group.min())}")
    k = int(group.max()) + 1 if len(group) else 0
    # BEGIN SOLUTION: Task 6 (seam fix, mean): out[g] = sum of values[i] with group[i] = g, divided by the count of g (np.bincount)
    count = np.bincount(group, minlength=k).astype(np.float64)
    safe = np.maximum(count, 1.0)
    if values.ndim == 1:
        return np.bincount(group, weights=values, minlength=k) / safe
    cols = [np.bincount(group, weights=values[:, c], minlength=k) for c in range(values.shape[1])]
    return np.stack(cols, axis=1) / safe[:, None]
    # END SOLUTION
