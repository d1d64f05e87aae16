"""Sample lab operations."""

from geomlib import topology
from geomlib.validate import check_float, check_mesh


def scale_about_centroid(V, F, s=2.0):
    """Scale a mesh about its vertex centroid: v' = c + s (v - c).

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
    s : float

    Returns
    -------
    V2 : (n, 3) float
    """
    V, F = check_mesh(V, F, where="scale_about_centroid")
    s = check_float(s, "s", where="scale_about_centroid")
    # BEGIN SOLUTION: Task 1 (scaling): v' = c + s (v - c) with c the mean of the vertices
    c = V.mean(axis=0)
    return c + s * (V - c)
    # END SOLUTION


def edge_midpoints(V, F):
    """Midpoints of the unique edges, in ``geomlib.topology.unique_edges`` order.

    Returns
    -------
    E : (e, 2) int
    M : (e, 3) float
    """
    V, F = check_mesh(V, F, where="edge_midpoints")
    E = topology.unique_edges(F)
    # BEGIN PROMPT
    # M = ...  # (e, 3)
    # END PROMPT
    # BEGIN SOLUTION: Task 2 (midpoints): M = (V[a] + V[b]) / 2 for every edge (a, b)
    M = 0.5 * (V[E[:, 0]] + V[E[:, 1]])
    # END SOLUTION
    return E, M
