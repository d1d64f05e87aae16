"""Task 1: fixed-boundary parameterization of a disk-topology mesh onto the unit square.

A vector displacement map deforms a flat ``res x res`` grid into the mesh, so every mesh vertex
first needs a position ``(u, v)`` in ``[0, 1]^2``. We pin the mesh's single boundary loop to the
square's perimeter and solve for the interior:

* the boundary loop is split at four *corner* vertices into four sides, and each side is mapped
  to one edge of the square **by arc length** (a boundary vertex at 30% of its side's length goes
  to 30% of the square's edge);
* ``method="harmonic"`` places the interior by the cotangent Laplace equation ``L u = 0``
  (``igl.harmonic``), ``method="tutte"`` by the uniform (graph) Laplacian — Tutte's embedding,
  which is guaranteed to be bijective for a convex boundary;
* ``method="lscm"`` minimises the least-squares conformal energy (``igl.lscm``) with the four
  corners pinned and every other boundary vertex free to *slide* along its own edge of the square.

References: Floater, "Parametrization and smooth approximation of surface triangulations" (1997);
Lévy et al., "Least squares conformal maps for automatic texture atlas generation" (2002).
"""

from __future__ import annotations

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from geomlib import topology
from geomlib.validate import MeshError, as_array, check_choice, check_mesh

__all__ = ["check_disk", "boundary_corners", "boundary_to_square", "parameterize_square", "SQUARE_CORNERS"]

#: The square's corners in counter-clockwise order; boundary corner k goes to SQUARE_CORNERS[k].
SQUARE_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def check_disk(V, F, *, where: str = "check_disk") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate a triangle mesh of disk topology and return ``(V, F, loop)``.

    A disk is a connected, manifold, consistently oriented mesh with exactly one boundary loop and
    genus 0, i.e. Euler characteristic ``chi = V - E + F = 1``.

    Returns
    -------
    V : (n, 3) float64
    F : (m, 3) int64
    loop : (b,) int64
        The boundary loop, ordered as the faces orient it (counter-clockwise seen from the side the
        normals point to).

    Raises
    ------
    MeshError
        Naming what is wrong: several components, no boundary (closed surface), several boundary
        loops (holes), a handle (genus > 0) or unused vertices.
    """
    V, F = check_mesh(V, F, where=where, manifold=True)
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    if not used.all():
        v = int(np.flatnonzero(~used)[0])
        raise MeshError(
            f"{where}: vertex {v} is not used by any face ({int((~used).sum())} unused vertices); "
            f"remove unreferenced vertices before parameterizing"
        )
    ncomp, _ = topology.connected_components_faces(F)
    if ncomp != 1:
        raise MeshError(f"{where}: the mesh has {ncomp} connected components; a disk has exactly one")
    loops = topology.boundary_loops(F)
    if len(loops) == 0:
        raise MeshError(
            f"{where}: the mesh is closed (no boundary loop); a disk needs exactly one boundary loop — "
            f"cut it open first (e.g. remove the bottom faces)"
        )
    if len(loops) > 1:
        raise MeshError(
            f"{where}: the mesh has {len(loops)} boundary loops (lengths {[len(lp) for lp in loops]}); "
            f"a disk has exactly one — fill the holes or cut the mesh"
        )
    chi = topology.euler_characteristic(F, len(V))
    if chi != 1:
        g = (1 - chi) // 2
        raise MeshError(
            f"{where}: the mesh is not a disk: Euler characteristic {chi} (expected 1) with one boundary "
            f"loop means genus {g}; cut its handles first"
        )
    return V, F, loops[0]


def boundary_corners(V: np.ndarray, loop: np.ndarray) -> np.ndarray:
    """Choose the four boundary vertices that go to the square's corners.

    Given helper. Every boundary vertex gets a *turning angle* (the angle between its incoming and
    outgoing boundary edges, 0 on a straight boundary). The first corner is the sharpest vertex
    (ties: the one with the smallest ``x + y``, so that a mesh lying in the xy-plane keeps u ~ x,
    v ~ y); corner k = 1, 2, 3 is the sharpest vertex within +-1/8 of the perimeter around the arc
    length position ``k/4`` after it. On a smooth boundary this gives four equal arcs; on a
    square-ish boundary it finds the real corners.

    Parameters
    ----------
    V : (n, 3) float64
    loop : (b,) int64
        Ordered boundary loop, ``b >= 4``.

    Returns
    -------
    (4,) int64
        Positions **in the loop** (indices into ``loop``), in loop order.
    """
    P = V[loop]
    e_out = np.roll(P, -1, axis=0) - P
    e_in = P - np.roll(P, 1, axis=0)
    seg = np.linalg.norm(e_out, axis=1)
    cos_t = np.einsum("ij,ij->i", e_in, e_out) / np.maximum(np.linalg.norm(e_in, axis=1) * seg, 1e-300)
    turn = np.arccos(np.clip(cos_t, -1.0, 1.0))
    # Round so that equal-looking angles tie exactly and the x + y rule decides.
    turn = np.round(turn, 6)
    total = seg.sum()
    first = int(np.lexsort((P[:, 0] + P[:, 1], -turn))[0])
    order = np.roll(np.arange(len(loop)), -first)
    s = np.concatenate([[0.0], np.cumsum(seg[order])[:-1]]) / total  # arc length from the first corner
    corners = [0]
    for k in (1, 2, 3):
        window = np.flatnonzero(np.abs(s - k / 4) <= 1 / 8)
        window = window[window > corners[-1]]
        if len(window) == 0:  # very coarse loop: take the next vertex
            window = np.array([corners[-1] + 1])
        corners.append(int(window[np.argmax(turn[order[window]] - 1e-9 * np.abs(s[window] - k / 4))]))
    return order[np.array(corners)]


def boundary_to_square(V, loop, corners) -> np.ndarray:
    """Map a boundary loop onto the unit square's perimeter, by arc length on each side.

    Side k runs along the loop from corner k to corner k+1 (the last side back to corner 0) and
    lands on the square's edge from ``SQUARE_CORNERS[k]`` to ``SQUARE_CORNERS[k + 1]``: a vertex at
    arc length ``s`` from its side's start, on a side of length ``L``, goes to
    ``c_k + (s / L) (c_{k+1} - c_k)``. Corner vertices land exactly on the square's corners.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    loop : (b,) int64
        Ordered boundary loop (mesh vertex indices).
    corners : (4,) int64
        Positions **in ``loop``** (indices into ``loop``, in loop order) of the four corner vertices.

    Returns
    -------
    (b, 2) float64
        uv of ``loop[i]`` in row i.

    Examples
    --------
    A 2 x 1 rectangle with one extra vertex in the middle of each long side:

    >>> V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> boundary_to_square(V, np.arange(6), np.array([0, 2, 3, 5])).tolist()
    [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 1.0], [0.5, 1.0], [0.0, 1.0]]
    """
    where = "boundary_to_square"
    V = as_array(V, "V", shape=(None, 3), where=where)
    loop = as_array(loop, "loop", shape=(None,), dtype=np.int64, where=where)
    corners = as_array(corners, "corners", shape=(4,), dtype=np.int64, where=where)
    b = len(loop)
    if b < 4 or loop.min() < 0 or loop.max() >= len(V):
        raise MeshError(f"{where}: loop must hold at least 4 vertex indices in 0..{len(V) - 1}")
    if corners.min() < 0 or corners.max() >= b or not np.all(np.diff((corners - corners[0]) % b) > 0):
        raise MeshError(f"{where}: corners {corners.tolist()} must be 4 distinct positions in the loop, in loop order")
    raise NotImplementedError('Task 1a (boundary): side k by arc length, uv = c_k + (s / L) (c_{k+1} - c_k)')


def _uniform_laplacian(F: np.ndarray, n: int) -> sp.csr_matrix:
    A = topology.vertex_adjacency(F, n)
    return (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()


def parameterize_square(V, F, method: str = "harmonic", *, corners=None) -> np.ndarray:
    """Map a disk-topology mesh onto the unit square with its boundary fixed on the square's edges.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    F : (m, 3) int64
        Triangles of a disk: connected, manifold, one boundary loop, genus 0.
    method : {"harmonic", "tutte", "lscm"}
        ``"harmonic"``: interior solves the cotangent Laplace equation ``L u = 0`` with the
        boundary fixed (``igl.harmonic`` with ``k = 1``). ``"tutte"``: the same with uniform weights
        (every interior vertex at the mean of its neighbours; bijective for a convex boundary).
        ``"lscm"``: least-squares conformal map (``igl.lscm``'s energy ``z^T Q z``) with the four
        corners pinned and the other boundary vertices sliding along their edge of the square.
    corners : (4,) int, optional
        Mesh vertex indices of the four boundary vertices that go to (0,0), (1,0), (1,1), (0,1), in
        boundary-loop order. Default: :func:`boundary_corners`.

    Returns
    -------
    UV : (n, 2) float64
        Texture coordinates in ``[0, 1]^2``. Boundary vertices lie on the square's edges (side k by
        arc length for harmonic/tutte), corners exactly on the square's corners; the triangles keep
        their orientation (positive signed area in uv).

    Raises
    ------
    MeshError
        When the mesh is not a disk, ``method`` is unknown, or ``corners`` are not 4 distinct
        boundary vertices in loop order.

    Examples
    --------
    >>> from geomlib import datasets
    >>> V, F = datasets.grid_patch(4)  # the flat unit square maps to itself
    >>> bool(np.allclose(parameterize_square(V, F), V[:, :2]))
    True
    """
    where = "parameterize_square"
    V, F, loop = check_disk(V, F, where=where)
    method = check_choice(method, "method", ("harmonic", "tutte", "lscm"), where=where)
    if len(loop) < 4:
        raise MeshError(f"{where}: the boundary loop has {len(loop)} vertices; at least 4 are needed for the corners")
    if corners is None:
        cpos = boundary_corners(V, loop)
    else:
        c = as_array(corners, "corners", shape=(4,), dtype=np.int64, where=where)
        where_in_loop = np.full(len(V), -1)
        where_in_loop[loop] = np.arange(len(loop))
        if c.min() < 0 or c.max() >= len(V) or (where_in_loop[c] < 0).any():
            raise MeshError(f"{where}: corners {c.tolist()} must be vertices of the boundary loop")
        cpos = where_in_loop[c]
        shift = (cpos - cpos[0]) % len(loop)
        if len(set(cpos.tolist())) != 4 or not np.all(np.diff(shift) > 0):
            raise MeshError(
                f"{where}: corners {c.tolist()} must be 4 distinct boundary vertices in boundary-loop order"
            )
    bnd_uv = boundary_to_square(V, loop, cpos)
    raise NotImplementedError('Task 1b (interior): boundary fixed, interior solves L u = 0 (cotangent or uniform weights)')


def _lscm_sliding(V, F, loop, cpos, bnd_uv):
    """LSCM with corners pinned and boundary vertices sliding along their square edge (given helper).

    ``igl.lscm`` returns the energy matrix ``Q`` (2n x 2n, unknowns stacked as ``[u; v]``). On the
    edges ``v = 0`` / ``v = 1`` the v-coordinate is fixed and u is free, on ``u = 0`` / ``u = 1`` the
    reverse; we solve ``min z^T Q z`` over the free unknowns.
    """
    n = len(V)
    _, Q = igl.lscm(V, F, loop[cpos], SQUARE_CORNERS)
    fixed = np.zeros(2 * n, bool)
    value = np.zeros(2 * n)
    corner_v = loop[cpos]
    fixed[corner_v] = fixed[corner_v + n] = True
    value[corner_v], value[corner_v + n] = SQUARE_CORNERS[:, 0], SQUARE_CORNERS[:, 1]
    on_u_edge = np.isclose(bnd_uv[:, 0], 0) | np.isclose(bnd_uv[:, 0], 1)  # u fixed, v slides
    on_v_edge = np.isclose(bnd_uv[:, 1], 0) | np.isclose(bnd_uv[:, 1], 1)
    fixed[loop[on_u_edge]] = True
    value[loop[on_u_edge]] = bnd_uv[on_u_edge, 0]
    fixed[loop[on_v_edge] + n] = True
    value[loop[on_v_edge] + n] = bnd_uv[on_v_edge, 1]
    Q = sp.csr_matrix(Q)
    free = np.flatnonzero(~fixed)
    A = Q[free][:, free]
    rhs = -Q[free][:, np.flatnonzero(fixed)] @ value[fixed]
    z = value.copy()
    z[free] = spla.splu(A.tocsc()).solve(rhs)
    return np.stack([z[:n], z[n:]], axis=1)
