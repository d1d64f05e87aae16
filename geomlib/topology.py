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
    "unique_rows",
    "unique_edges",
    "edge_faces",
    "boundary_edges",
    "boundary_loops",
    "vertex_adjacency",
    "valence",
    "vertex_fan_counts",
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


def unique_rows(E: np.ndarray, return_inverse: bool = False, return_counts: bool = False):
    """``np.unique(E, axis=0)`` for non-negative int pairs ``(k, 2)``, via int64 keys (much faster)."""
    E = np.asarray(E, dtype=np.int64)
    n = int(E.max()) + 1 if E.size else 1
    keys = E[:, 0] * n + E[:, 1]
    out = np.unique(keys, return_inverse=return_inverse, return_counts=return_counts)
    if not (return_inverse or return_counts):
        return np.stack([out // n, out % n], axis=1)
    u = out[0]
    res = [np.stack([u // n, u % n], axis=1)]
    res += [np.asarray(o).ravel() for o in out[1:]]
    return tuple(res)


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
    starts, counts = np.unique(B[:, 0], return_counts=True)
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
    lens = np.diff(off)
    m = len(lens)
    # Corner c = (vertex v, face f). Two corners at the same vertex are linked when their faces
    # share an edge through v. Count components of that corner graph per vertex.
    corner_face = np.repeat(np.arange(m), lens)
    pos = np.arange(len(idx)) - np.repeat(off[:-1], lens)
    L = np.repeat(lens, lens)
    nxt = np.repeat(off[:-1], lens) + (pos + 1) % L
    prv = np.repeat(off[:-1], lens) + (pos - 1) % L
    # Directed edge (v -> w) in face f is seen from corner v (outgoing) and corner w (incoming).
    v_out, w_out = idx, idx[nxt]
    # Key each undirected edge incident to v by (v, other endpoint); corners sharing a key are linked.
    keys_v = np.r_[idx, idx]
    keys_o = np.r_[idx[nxt], idx[prv]]
    corners = np.r_[np.arange(len(idx)), np.arange(len(idx))]
    order = np.lexsort((keys_o, keys_v))
    kv, ko, cc = keys_v[order], keys_o[order], corners[order]
    same = (kv[1:] == kv[:-1]) & (ko[1:] == ko[:-1])
    a, b = cc[:-1][same], cc[1:][same]
    N = len(idx)
    G = sp.coo_matrix((np.ones(len(a)), (a, b)), shape=(N, N))
    _, labels = connected_components(G, directed=False)
    del v_out, w_out, corner_face
    fans = np.zeros(n, dtype=np.int64)
    if N:
        pairs = unique_rows(np.stack([idx, labels], axis=1))
        np.add.at(fans, pairs[:, 0], 1)
    return fans


def euler_characteristic(faces, n_vertices: int | None = None) -> int:
    """*Polygons*: χ = V − E + F, counting only vertices that some face uses (unless ``n_vertices``)."""
    idx, off = to_ragged(faces)
    nv = int(n_vertices) if n_vertices is not None else len(np.unique(idx))
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
