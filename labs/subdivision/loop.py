"""Loop subdivision of triangle meshes, written as a sparse subdivision matrix.

One Loop step splits every triangle into four. The new mesh has the ``n`` old vertices
("even" vertices, moved) followed by one new vertex per edge ("odd" vertices), and every new
position is a fixed linear combination of old positions. Collecting those weights in a sparse
matrix ``S`` of shape ``(n + e, n)`` gives the whole step as one product ``V' = S @ V``.

Vertex order (the convention of this lab): old vertices keep their indices ``0..n-1``; edge
``i`` of :func:`geomlib.topology.unique_edges` (smaller index first, sorted) becomes vertex
``n + i``. The children of face ``f`` are faces ``4f .. 4f+3``.

References
----------
C. Loop, *Smooth Subdivision Surfaces Based on Triangles*, MSc thesis, University of Utah, 1987.
J. Warren, *Subdivision Methods for Geometric Design*, 1995 (the simplified weight 3/(8n)).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from geomlib.validate import MeshError, as_array, check_choice, check_int, check_mesh

from .connectivity import MeshTopology, mesh_topology

__all__ = [
    "WEIGHT_RULES",
    "loop_topology",
    "sparse_from_triplets",
    "opposite_vertices",
    "loop_weight",
    "loop_odd_matrix",
    "loop_even_matrix",
    "loop_faces",
    "loop_matrix",
    "loop_subdivide",
]

WEIGHT_RULES = ("warren", "loop")


def loop_topology(V, F, *, where: str = "loop_topology") -> tuple[np.ndarray, np.ndarray, MeshTopology]:
    """Validate a triangle mesh for Loop subdivision and compute its connectivity (given).

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        Triangles; the mesh must be manifold and consistently oriented.
    where : str
        Name of the calling function for error messages.

    Returns
    -------
    V : (n, 3) float64
    F : (m, 3) int64
    topo : MeshTopology
        ``topo.E`` (e, 2) edges, ``topo.EH`` the half-edges on both sides (``-1`` on the boundary),
        ``topo.he_edge`` the edge of half-edge ``3f + i`` (= ``F[f, i] -> F[f, (i+1) % 3]``),
        ``topo.boundary_edge``, ``topo.boundary_vertex``, ``topo.valence``.
    """
    # Duplicate faces are caught by the orientation check of mesh_topology, which is much cheaper
    # than check_mesh's row-wise np.unique on large meshes.
    V, F = check_mesh(V, F, where=where, allow_duplicate=True)
    return V, F, mesh_topology(F, len(V), where=where)


def sparse_from_triplets(rows: list, cols: list, vals: list, shape: tuple[int, int]) -> sp.csr_matrix:
    """A CSR matrix from lists of ``(row, column, weight)`` triplet arrays (given).

    Repeated ``(row, column)`` pairs are summed, as in ``scipy.sparse.coo_matrix``. The lists are
    emptied (their arrays are released as soon as they are copied), which keeps peak memory low.
    """
    index = np.int32 if max(shape) < 2**31 - 1 else np.int64

    def take(parts: list, dtype) -> np.ndarray:
        out = np.concatenate([np.asarray(x, dtype=dtype) for x in parts]) if parts else np.zeros(0, dtype)
        parts.clear()
        return out

    r, c, v = take(rows, index), take(cols, index), take(vals, np.float64)
    return sp.csr_matrix((v, (r, c)), shape=shape)


def opposite_vertices(F: np.ndarray, topo: MeshTopology) -> np.ndarray:
    """For every edge, the vertex opposite to it in each of its two triangles (given).

    Returns
    -------
    EO : (e, 2) int64
        ``EO[i, 0]`` is the third corner of the triangle whose half-edge runs ``E[i, 0] -> E[i, 1]``,
        ``EO[i, 1]`` that of the triangle on the other side; ``-1`` where there is no triangle.
        The third corner of half-edge ``j`` (corner ``j -> nxt[j]``) is corner ``prv[j]``.
    """
    Fr = np.asarray(F).ravel()
    return np.where(topo.EH >= 0, Fr[topo.prv[np.maximum(topo.EH, 0)]], -1)


def loop_weight(n, weights: str = "warren") -> np.ndarray:
    """Weight ``u`` that an interior even vertex of valence ``n`` gives to each of its neighbours.

    The moved vertex is ``v' = (1 - n u) v + u * sum(neighbours)``.

    Parameters
    ----------
    n : int or array_like of int, all >= 1
        Valences.
    weights : {"warren", "loop"}
        ``"warren"``: the lecture's rule ``u = 3/16`` if ``n == 3`` else ``u = 3 / (8 n)``
        (J. Warren; this is what ``igl.loop`` uses).
        ``"loop"``: Loop's original ``u = beta(n) = (1/n) (5/8 - (3/8 + 1/4 cos(2 pi / n))^2)``
        (trimesh, VTK and MeshLab use it).
        The two agree for ``n = 3`` (3/16) and ``n = 6`` (1/16).

    Returns
    -------
    u : ndarray of float64, same shape as ``n``

    Examples
    --------
    >>> loop_weight([3, 4, 6], "warren")
    array([0.1875    , 0.09375   , 0.0625    ])
    """
    weights = check_choice(weights, "weights", WEIGHT_RULES, where="loop_weight")
    n = np.asarray(n)
    if n.dtype.kind not in "iuf" or (n.size and (n.min() < 1 or not np.all(n == np.round(n)))):
        raise MeshError(f"loop_weight: n must hold integer valences >= 1, got {n!r}")
    n = n.astype(np.float64)
    raise NotImplementedError('Task 2 (even vertices): warren: 3/16 if n == 3 else 3/(8n); loop: (5/8 - (3/8 + cos(2pi/n)/4)^2)/n')


def loop_odd_matrix(V, F, *, topo: MeshTopology | None = None) -> sp.csr_matrix:
    """Rows of the subdivision matrix for the odd (edge) vertices.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Only its length is used (the matrix does not depend on positions).
    F : (m, 3) array_like of int
        Manifold, consistently oriented triangles.
    topo : MeshTopology, optional
        Connectivity of ``F`` from :func:`loop_topology` (computed when omitted).

    Returns
    -------
    S_odd : (e, n) scipy.sparse.csr_matrix
        Row ``i`` holds the weights of the new vertex on edge ``E[i] = (a, b)`` (``topo.E`` order):

        - interior edge with opposite vertices ``c``, ``d``: ``3/8 a + 3/8 b + 1/8 c + 1/8 d``;
        - boundary edge: the midpoint ``1/2 a + 1/2 b``.

        Every row sums to 1. ``S_odd @ V`` are the odd vertex positions.
    """
    if topo is None:
        V, F, topo = loop_topology(V, F, where="loop_odd_matrix")
    n, e = topo.n_vertices, len(topo.E)
    E, EO = topo.E, opposite_vertices(F, topo)
    inner = np.flatnonzero(~topo.boundary_edge)  # rows of interior edges
    border = np.flatnonzero(topo.boundary_edge)  # rows of boundary edges
    rows, cols, vals = [], [], []  # append arrays of (row, column, weight) triplets of S_odd
    raise NotImplementedError('Task 1 (odd vertices): interior edge (a, b), opposite vertices c, d -> 3/8 (a + b) + 1/8 (c + d)')
    if len(border):
        raise NotImplementedError('Task 4 (boundary rules): boundary edge (a, b) -> midpoint 1/2 (a + b)')
    return sparse_from_triplets(rows, cols, vals, (e, n))


def loop_even_matrix(V, F, weights: str = "warren", *, topo: MeshTopology | None = None) -> sp.csr_matrix:
    """Rows of the subdivision matrix for the even (old) vertices.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Only its length is used.
    F : (m, 3) array_like of int
        Manifold, consistently oriented triangles.
    weights : {"warren", "loop"}
        Weight rule for interior vertices, see :func:`loop_weight`.
    topo : MeshTopology, optional
        Connectivity of ``F`` (computed when omitted).

    Returns
    -------
    S_even : (n, n) scipy.sparse.csr_matrix
        Row ``v`` holds the weights of the moved vertex ``v``:

        - interior vertex of valence ``k`` with neighbours ``w_1..w_k``:
          ``(1 - k u) v + u (w_1 + ... + w_k)``, ``u = loop_weight(k, weights)``;
        - boundary vertex with boundary neighbours ``w_prev``, ``w_next`` (cubic B-spline rule):
          ``3/4 v + 1/8 w_prev + 1/8 w_next`` (interior neighbours get weight 0);
        - a vertex that no face uses stays where it is.

        Every row sums to 1.
    """
    weights = check_choice(weights, "weights", WEIGHT_RULES, where="loop_even_matrix")
    if topo is None:
        V, F, topo = loop_topology(V, F, where="loop_even_matrix")
    n = topo.n_vertices
    E, k = topo.E, topo.valence
    interior = ~topo.boundary_vertex  # (n,) bool; unused vertices (k == 0) count as interior
    rows, cols, vals = [], [], []  # append arrays of (row, column, weight) triplets of S_even
    raise NotImplementedError('Task 2 (even vertices): interior vertex of valence k -> (1 - k u) v + u * sum(neighbours)')
    if not interior.all():
        raise NotImplementedError('Task 4 (boundary rules): boundary vertex -> 3/4 v + 1/8 (its two boundary neighbours)')
    return sparse_from_triplets(rows, cols, vals, (n, n))


def loop_faces(F, *, n_vertices: int | None = None, topo: MeshTopology | None = None) -> np.ndarray:
    """Connectivity of the refined mesh: every triangle split into four.

    Parameters
    ----------
    F : (m, 3) array_like of int
        Manifold, consistently oriented triangles.
    n_vertices : int, optional
        Number ``n`` of old vertices (default ``F.max() + 1``).
    topo : MeshTopology, optional
        Connectivity of ``F`` (computed when omitted).

    Returns
    -------
    F_new : (4m, 3) int64
        For face ``f = (v0, v1, v2)`` with edge vertices ``m01, m12, m20`` (``n + edge index``),
        rows ``4f .. 4f+3`` are ``(v0, m01, m20)``, ``(v1, m12, m01)``, ``(v2, m20, m12)``,
        ``(m01, m12, m20)``: three corner triangles and the middle one, all with the
        orientation of ``f``.
    """
    if topo is None:
        Fa = np.asarray(F)
        n = int(n_vertices) if n_vertices is not None else (int(Fa.max()) + 1 if Fa.size else 0)
        _, F, topo = loop_topology(np.zeros((n, 3)), F, where="loop_faces")
    F = np.asarray(F, dtype=np.int64)
    n = topo.n_vertices
    raise NotImplementedError('Task 3 (connectivity): new vertex of half-edge j is n + he_edge[j]; 4 triangles per face')


def loop_matrix(
    V, F, weights: str = "warren", *, where: str = "loop_matrix", corners=None
) -> tuple[sp.csr_matrix, np.ndarray]:
    """One Loop step as a matrix: ``S`` and the refined faces (given; combines Tasks 1-4).

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
    weights : {"warren", "loop"}
    where : str
        Name of the calling function for error messages.
    corners : array_like of int, optional
        Boundary vertices marked as corners (Hoppe et al. 1994, "Piecewise smooth surface
        reconstruction"): a corner stays where it is (its row of ``S`` is the identity), so the
        boundary curve keeps a sharp corner there instead of rounding it off. Given, not a task:
        the boundary rule of Task 4 is unchanged elsewhere. The old vertices keep their indices
        at every level, so the same indices mark the corners of the refined mesh.

    Returns
    -------
    S : (n + e, n) scipy.sparse.csr_matrix
        ``[S_even; S_odd]``; ``S @ V`` is the refined vertex array.
    F_new : (4m, 3) int64
    """
    weights = check_choice(weights, "weights", WEIGHT_RULES, where=where)
    V, F, topo = loop_topology(V, F, where=where)
    S_odd = loop_odd_matrix(V, F, topo=topo)
    S_even = loop_even_matrix(V, F, weights, topo=topo)
    if corners is not None:
        c = as_array(corners, "corners", shape=(None,), dtype=np.int64, where=where)
        if c.size and (c.min() < 0 or c.max() >= len(V)):
            raise MeshError(f"{where}: corners must be vertex indices in [0, {len(V)}), got {c.min()}..{c.max()}")
        if not topo.boundary_vertex[c].all():
            raise MeshError(f"{where}: corners must be boundary vertices; {c[~topo.boundary_vertex[c]][:5]} are not")
        fixed = np.zeros(len(V))
        fixed[c] = 1.0
        S_even = (sp.diags(1.0 - fixed) @ S_even + sp.diags(fixed)).tocsr()  # a corner's row: the identity
    F_new = loop_faces(F, topo=topo)
    del topo  # release the connectivity before stacking: keeps the peak memory low
    return sp.vstack([S_even, S_odd], format="csr"), F_new


def loop_subdivide(V, F, levels: int = 1, weights: str = "warren", return_matrix: bool = False):
    """Loop subdivision of a manifold triangle mesh, ``levels`` times.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles; the mesh must be manifold and consistently oriented. Open meshes use the
        boundary rules (edge midpoints; ``3/4, 1/8, 1/8`` along the boundary).
    levels : int, >= 0
        Number of subdivision steps; 0 returns copies of the input.
    weights : {"warren", "loop"}
        Even-vertex weight rule (see :func:`loop_weight`). ``"warren"`` matches ``igl.loop``,
        ``"loop"`` matches ``trimesh.remesh.subdivide_loop`` and VTK on closed meshes.
    return_matrix : bool
        Also return the sparse subdivision matrix of all levels together.

    Returns
    -------
    V_new : (n_L, 3) float64
        Each level maps ``n`` vertices to ``n + e``: old vertices first (same indices),
        then one vertex per edge in :func:`geomlib.topology.unique_edges` order.
    F_new : (4^levels m, 3) int64
    S : (n_L, n) scipy.sparse.csr_matrix
        Only with ``return_matrix=True``: ``S @ V == V_new``; ``S = S_L ... S_2 S_1``.

    Raises
    ------
    MeshError
        Non-triangle faces, a non-manifold or inconsistently oriented mesh, bad indices or
        values, ``levels`` not an integer >= 0, an unknown ``weights`` rule.

    Examples
    --------
    >>> V = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    >>> V1, F1 = loop_subdivide(V, [[0, 1, 2]])
    >>> V1.shape, F1.shape
    ((6, 3), (4, 3))
    """
    V, F = check_mesh(V, F, where="loop_subdivide", allow_duplicate=True)
    levels = check_int(levels, "levels", minimum=0, where="loop_subdivide")
    weights = check_choice(weights, "weights", WEIGHT_RULES, where="loop_subdivide")
    if levels == 0:
        mesh_topology(F, len(V), where="loop_subdivide")  # the same checks as for levels >= 1
        V, F = V.copy(), F.copy()
    S_all = sp.identity(len(V), format="csr") if return_matrix else None
    raise NotImplementedError('Task 5 (several levels): repeat S, F = loop_matrix(V, F, weights); V = S @ V; S_all = S @ S_all')
    if return_matrix:
        return V, F, S_all
    return V, F
