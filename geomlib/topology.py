"""Mesh connectivity: edges, adjacency, valence, boundaries, Euler characteristic.

Every function takes triangle faces ``F`` as an int ``(m, 3)`` array; those marked
*polygons* also take an ``(m, k)`` array of any k, a list of polygons, or the ragged
``(indices, offsets)`` pair that :func:`to_ragged` returns (face ``f`` is
``indices[offsets[f]:offsets[f + 1]]``). All work is vectorised NumPy/SciPy.

Conventions follow libigl: an undirected edge is stored with its smaller index first,
and edges are sorted lexicographically, so ``unique_edges`` is deterministic.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

__all__ = [
    "to_ragged",
    "face_sizes",
    "halfedges",
    "unique_ints",
    "unique_rows",
    "unique_edges",
    "edge_faces",
    "boundary_edges",
    "boundary_loops",
    "vertex_adjacency",
    "valence",
    "vertex_fan_counts",
    "corner_fans",
    "extraordinary_vertices",
    "euler_characteristic",
    "genus",
    "connected_components_faces",
    "is_edge_manifold",
    "is_closed",
    "triangulate_polygons",
]


def to_ragged(faces) -> tuple[np.ndarray, np.ndarray]:
    """*Polygons*: return ``(indices, offsets)`` int64 arrays for any face representation."""
    if isinstance(faces, tuple) and len(faces) == 2 and isinstance(faces[1], np.ndarray) and faces[1].ndim == 1:
        idx, off = faces
        if len(off) and off[0] == 0 and (len(faces[0]) == off[-1]):
            return np.asarray(idx, np.int64), np.asarray(off, np.int64)
    if isinstance(faces, np.ndarray) and faces.dtype != object and faces.ndim == 2:
        m, k = faces.shape
        return faces.astype(np.int64).ravel(), np.arange(0, m * k + 1, k, dtype=np.int64)
    polys = [np.asarray(f, dtype=np.int64) for f in faces]
    lens = np.array([len(p) for p in polys], dtype=np.int64)
    idx = np.concatenate(polys) if polys else np.zeros(0, np.int64)
    return idx, np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)


def face_sizes(faces) -> np.ndarray:
    """*Polygons*: number of corners of each face, ``(m,)``."""
    return np.diff(to_ragged(faces)[1])


def halfedges(faces, offsets: np.ndarray | None = None) -> np.ndarray:
    """*Polygons*: directed edges ``(h, 2)``, face by face in corner order (corner i → i+1).

    Half-edge ``j`` belongs to face ``np.repeat(arange(m), face_sizes)[j]``.
    """
    idx, off = (faces, offsets) if offsets is not None else to_ragged(faces)
    lens = np.diff(off)
    pos = np.arange(len(idx)) - np.repeat(off[:-1], lens)
    nxt = np.repeat(off[:-1], lens) + (pos + 1) % np.repeat(lens, lens)
    return np.stack([idx, idx[nxt]], axis=1)


def unique_ints(keys: np.ndarray, return_inverse: bool = False, return_counts: bool = False):
    """Sorted unique values of an int array, by one argsort.

    ``np.unique`` on int64 without ``return_*`` takes a hash-based path in NumPy 2.3+ that measured
    ~70x slower than sorting here (0.8 s vs 0.012 s for 260k keys), so topology uses this instead.
    """
    keys = np.asarray(keys).ravel()
    if not (return_inverse or return_counts):
        sk = np.sort(keys)  # values only: a plain sort, no argsort
        return sk[np.r_[True, sk[1:] != sk[:-1]]] if len(sk) else sk
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    start = np.r_[True, sk[1:] != sk[:-1]] if len(sk) else np.zeros(0, bool)
    out = [sk[start]]
    if return_inverse:
        inv = np.empty(len(keys), dtype=np.int64)
        inv[order] = np.cumsum(start) - 1
        out.append(inv)
    if return_counts:
        out.append(np.diff(np.r_[np.flatnonzero(start), len(sk)]))
    return tuple(out)


def unique_rows(E: np.ndarray, return_inverse: bool = False, return_counts: bool = False):
    """``np.unique(E, axis=0)`` for non-negative int pairs ``(k, 2)``, via int64 keys (much faster)."""
    E = np.asarray(E, dtype=np.int64)
    n = int(E.max()) + 1 if E.size else 1
    keys = E[:, 0] * n + E[:, 1]
    out = unique_ints(keys, return_inverse=return_inverse, return_counts=return_counts)
    if not (return_inverse or return_counts):
        return np.stack([out // n, out % n], axis=1)
    u = out[0]
    return (np.stack([u // n, u % n], axis=1), *out[1:])


def unique_edges(faces) -> np.ndarray:
    """*Polygons*: undirected edges ``(e, 2)``, smaller index first, lexicographically sorted."""
    he = np.sort(halfedges(faces), axis=1)
    return unique_rows(he) if len(he) else np.zeros((0, 2), np.int64)


def edge_faces(faces) -> tuple[np.ndarray, np.ndarray]:
    """*Polygons*: edges and the faces on each side.

    Returns
    -------
    E : (e, 2) int64
        Unique undirected edges as in :func:`unique_edges`.
    EF : (e, 2) int64
        ``EF[i, 0]`` is the face whose half-edge runs ``E[i, 0] → E[i, 1]``, ``EF[i, 1]`` the face
        running the other way; ``-1`` where there is no such face (boundary). On a non-manifold
        edge one face per direction is kept.
    """
    idx, off = to_ragged(faces)
    he = halfedges(idx, off)
    hf = np.repeat(np.arange(len(off) - 1), np.diff(off))
    und = np.sort(he, axis=1)
    E, inv = unique_rows(und, return_inverse=True)
    EF = np.full((len(E), 2), -1, dtype=np.int64)
    forward = he[:, 0] < he[:, 1]
    EF[inv[forward], 0] = hf[forward]
    EF[inv[~forward], 1] = hf[~forward]
    return E, EF


def _edge_use(faces) -> tuple[np.ndarray, np.ndarray]:
    und = np.sort(halfedges(faces), axis=1)
    return unique_rows(und, return_counts=True)


def boundary_edges(faces) -> np.ndarray:
    """*Polygons*: directed boundary edges ``(b, 2)``, oriented as in their one face."""
    he = halfedges(faces)
    und = np.sort(he, axis=1)
    _, inv, counts = unique_rows(und, return_inverse=True, return_counts=True)
    return he[counts[inv] == 1]


def boundary_loops(faces) -> list[np.ndarray]:
    """*Polygons*: boundary loops as ordered vertex index arrays, longest first.

    Each loop follows the orientation of its faces. Raises :class:`~geomlib.validate.MeshError`
    when a boundary vertex has more than one outgoing boundary edge (boundary pinch).
    """
    from geomlib.validate import MeshError

    B = boundary_edges(faces)
    if len(B) == 0:
        return []
    starts, counts = unique_ints(B[:, 0], return_counts=True)
    if (counts > 1).any():
        raise MeshError(
            f"boundary vertex {int(starts[np.argmax(counts)])} has {counts.max()} outgoing boundary edges (non-manifold boundary)"
        )
    nxt = dict(zip(B[:, 0].tolist(), B[:, 1].tolist(), strict=True))
    seen: set[int] = set()
    loops = []
    for s in B[:, 0].tolist():  # sequential walk: loops are 1-D chains, O(boundary length)
        if s in seen:
            continue
        loop = [s]
        seen.add(s)
        v = nxt[s]
        while v != s:
            loop.append(v)
            seen.add(v)
            v = nxt[v]
        loops.append(np.array(loop, dtype=np.int64))
    loops.sort(key=len, reverse=True)
    return loops


def vertex_adjacency(faces, n_vertices: int | None = None) -> sp.csr_matrix:
    """*Polygons*: symmetric vertex adjacency (CSR, entries 1) along polygon edges.

    Row ``i``'s column indices (``A.indices[A.indptr[i]:A.indptr[i+1]]``) are the neighbours of ``i``.
    """
    E = unique_edges(faces)
    n = int(n_vertices if n_vertices is not None else (E.max() + 1 if len(E) else 0))
    A = sp.coo_matrix((np.ones(2 * len(E)), (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])), shape=(n, n))
    A = A.tocsr()
    A.sort_indices()
    return A


def valence(faces, n_vertices: int | None = None) -> np.ndarray:
    """*Polygons*: number of distinct edge neighbours of every vertex, ``(n,)``."""
    A = vertex_adjacency(faces, n_vertices)
    return np.diff(A.indptr)


def vertex_fan_counts(faces, offsets: np.ndarray | None = None, n_vertices: int | None = None) -> np.ndarray:
    """*Polygons*: for every vertex, the number of edge-connected fans of faces around it.

    A manifold vertex (interior or boundary) has exactly one fan; 0 means unreferenced.
    """
    idx, off = (faces, offsets) if offsets is not None else to_ragged(faces)
    n = int(n_vertices if n_vertices is not None else (idx.max() + 1 if len(idx) else 0))
    N = len(idx)
    if N == 0:
        return np.zeros(n, dtype=np.int64)
    lens = np.diff(off)
    base = np.repeat(off[:-1], lens)
    pos = np.arange(N) - base
    nxt = base + (pos + 1) % np.repeat(lens, lens)
    # Half-edge h runs from corner h (vertex a) to corner nxt[h] (vertex b). Two faces sharing the
    # undirected edge {a, b} link their corners at a and their corners at b: corners of one vertex
    # that end up connected form one fan.
    a, b = idx, idx[nxt]
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    k = key[order]
    same = np.flatnonzero(k[1:] == k[:-1])
    h1, h2 = order[same], order[same + 1]
    lo1 = np.where(a[h1] < b[h1], h1, nxt[h1])  # corner at the smaller endpoint, in each face
    hi1 = np.where(a[h1] < b[h1], nxt[h1], h1)
    lo2 = np.where(a[h2] < b[h2], h2, nxt[h2])
    hi2 = np.where(a[h2] < b[h2], nxt[h2], h2)
    _, owner = corner_fans(idx, np.r_[lo1, hi1], np.r_[lo2, hi2])
    return np.bincount(owner, minlength=n).astype(np.int64)


def corner_fans(
    idx: np.ndarray, rows: np.ndarray, cols: np.ndarray, *, one_per_row: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Group face corners into fans: corners linked across shared edges, around one vertex each.

    Parameters
    ----------
    idx : (c,) int
        Vertex of every corner (ragged face indices).
    rows, cols : (k,) int
        Pairs of corners of the same vertex that lie in faces sharing an edge through it.
    one_per_row : bool
        The caller promises that no corner appears twice in ``rows`` (e.g. each corner linked
        only across its outgoing half-edge). The link graph is then built directly as a CSR
        matrix with int32 indices and no COO copy: on meshes of millions of corners this halves
        the peak memory of the call.

    Returns
    -------
    labels : (c,) int64
        Fan of every corner.
    owner : (f,) int64
        Vertex of every fan; a vertex owning more than one fan is non-manifold.
    """
    N = len(idx)
    if one_per_row and N < 2**31:
        link = np.full(N, -1, dtype=np.int32)
        link[rows] = cols
        has = link >= 0
        indptr = np.zeros(N + 1, dtype=np.int32)
        np.cumsum(has, out=indptr[1:])
        G = sp.csr_matrix((np.ones(int(indptr[-1]), dtype=np.int8), link[has], indptr), shape=(N, N))
        del link, has, indptr
        ncomp, labels = connected_components(G, directed=True, connection="weak")
    else:
        G = sp.coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(N, N))
        ncomp, labels = connected_components(G, directed=False)
    del G
    owner = np.empty(ncomp, dtype=np.int64)
    owner[labels] = idx
    return labels.astype(np.int64), owner


def extraordinary_vertices(faces, n_vertices: int, regular: int | None = None) -> np.ndarray:
    """*Polygons*: interior vertices whose valence is not the regular one.

    Parameters
    ----------
    faces : (m, k) int array, list of polygons, or ``(indices, offsets)``
    n_vertices : int
    regular : int, optional
        Regular valence; default 6 on triangle-dominant meshes (mean face size < 3.5), else 4.

    Returns
    -------
    (k,) int64
        Sorted vertex indices (boundary and unreferenced vertices are never listed).
    """
    idx, off = to_ragged(faces)
    if regular is None:
        regular = 6 if np.mean(np.diff(off)) < 3.5 else 4
    val = valence((idx, off), n_vertices)
    boundary = np.zeros(n_vertices, dtype=bool)
    boundary[boundary_edges((idx, off)).ravel()] = True
    used = np.zeros(n_vertices, dtype=bool)
    used[idx] = True
    return np.flatnonzero(used & ~boundary & (val != regular)).astype(np.int64)


def euler_characteristic(faces, n_vertices: int | None = None) -> int:
    """*Polygons*: χ = V − E + F, counting only vertices that some face uses (unless ``n_vertices``)."""
    idx, off = to_ragged(faces)
    nv = int(n_vertices) if n_vertices is not None else len(unique_ints(idx))
    return nv - len(unique_edges((idx, off))) + (len(off) - 1)


def genus(faces) -> int:
    """*Polygons*: genus of a connected orientable manifold mesh, g = (2 − χ − b) / 2."""
    b = len(boundary_loops(faces))
    return (2 - euler_characteristic(faces) - b) // 2


def connected_components_faces(faces) -> tuple[int, np.ndarray]:
    """*Polygons*: number of edge-connected face components and the label of each face."""
    E, EF = edge_faces(faces)
    ok = (EF >= 0).all(axis=1)
    m = len(to_ragged(faces)[1]) - 1
    G = sp.coo_matrix((np.ones(ok.sum()), (EF[ok, 0], EF[ok, 1])), shape=(m, m))
    return connected_components(G, directed=False)


def is_edge_manifold(faces) -> bool:
    """*Polygons*: True when no edge is used by more than two faces."""
    _, counts = _edge_use(faces)
    return bool((counts <= 2).all())


def is_closed(faces) -> bool:
    """*Polygons*: True when every edge is used by exactly two faces."""
    _, counts = _edge_use(faces)
    return bool((counts == 2).all())


def triangulate_polygons(faces) -> tuple[np.ndarray, np.ndarray]:
    """*Polygons*: fan-triangulate every polygon.

    Returns
    -------
    F : (t, 3) int64
        Triangles.
    source : (t,) int64
        The polygon each triangle came from.
    """
    idx, off = to_ragged(faces)
    lens = np.diff(off)
    ntri = lens - 2
    src = np.repeat(np.arange(len(lens)), ntri)
    k = np.arange(ntri.sum()) - np.repeat(np.cumsum(ntri) - ntri, ntri)
    base = off[:-1][src]
    F = np.stack([idx[base], idx[base + k + 1], idx[base + k + 2]], axis=1)
    return F, src
