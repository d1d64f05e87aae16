"""Half-edge connectivity of a polygon mesh, computed once per subdivision level (given code).

Both subdivision schemes need the same facts about the coarse mesh: its unique edges, which
faces lie on either side of every edge, which edges and vertices are on the boundary, and the
valence of every vertex. :func:`mesh_topology` computes all of them in one sort of the
half-edge keys and, at the same time, checks that the mesh is manifold and consistently
oriented (subdivision rules are only defined there).

Faces are stored *ragged*: face ``f`` is ``idx[off[f]:off[f + 1]]`` (see
:func:`geomlib.topology.to_ragged`); a triangle mesh ``F (m, 3)`` is ``idx = F.ravel()``,
``off = 0, 3, 6, ...``. Half-edge ``j`` runs from corner ``j`` to the next corner of the same
face, ``idx[j] -> idx[nxt[j]]``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from geomlib.topology import corner_fans
from geomlib.validate import MeshError

__all__ = ["MeshTopology", "mesh_topology"]


class MeshTopology(NamedTuple):
    """Connectivity of a manifold polygon mesh with ``n`` vertices, ``m`` faces, ``e`` edges, ``h`` half-edges.

    Attributes
    ----------
    idx, off : (h,), (m + 1,) int64
        Ragged faces: face ``f`` is ``idx[off[f]:off[f + 1]]``.
    nxt, prv : (h,) int64
        Next / previous corner (= half-edge) in the same face.
    he_face : (h,) int64
        Face of every half-edge.
    he_edge : (h,) int64
        Undirected edge of every half-edge (row of ``E``).
    E : (e, 2) int64
        Unique undirected edges, smaller index first, sorted lexicographically
        (the order of :func:`geomlib.topology.unique_edges`).
    EH : (e, 2) int64
        ``EH[i, 0]`` is the half-edge running ``E[i, 0] -> E[i, 1]``, ``EH[i, 1]`` the one running
        back; ``-1`` where there is none (boundary edge).
    EF : (e, 2) int64
        The faces of those half-edges (``-1`` on the boundary).
    boundary_edge : (e,) bool
        Edges with only one face.
    boundary_vertex : (n,) bool
        Vertices on a boundary edge.
    valence : (n,) int64
        Number of edges at every vertex (0 for a vertex no face uses).
    """

    idx: np.ndarray
    off: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    he_face: np.ndarray
    he_edge: np.ndarray
    E: np.ndarray
    EH: np.ndarray
    EF: np.ndarray
    boundary_edge: np.ndarray
    boundary_vertex: np.ndarray
    valence: np.ndarray

    @property
    def n_vertices(self) -> int:
        return len(self.valence)

    @property
    def n_faces(self) -> int:
        return len(self.off) - 1


def mesh_topology(faces, n_vertices: int, *, where: str | None = None, name: str = "F") -> MeshTopology:
    """Half-edge connectivity of a polygon mesh; raise :class:`MeshError` unless it is manifold and oriented.

    Parameters
    ----------
    faces : (m, k) int array, or ``(idx, off)`` ragged pair
        Faces with indices already validated to lie in ``0..n_vertices-1`` and no repeated corner.
    n_vertices : int
        Number of vertices ``n``.
    where : str, optional
        Name of the calling function, used as prefix of error messages.
    name : str
        Name of the face argument in error messages.

    Returns
    -------
    MeshTopology

    Raises
    ------
    MeshError
        An edge in more than two faces, two faces traversing an edge in the same direction
        (inconsistent orientation or duplicate faces), or a vertex whose faces form several fans.

    Notes
    -----
    One ``argsort`` of the ``h`` undirected edge keys ``min * n + max`` groups the half-edges of
    each edge; everything else is gathers and ``bincount``. Fans are counted as connected components
    of the corner graph (corner ``j`` is linked to the corner of the same vertex across its
    outgoing half-edge); every component belongs to one vertex, so a vertex is manifold exactly
    when it owns one component. Cost O(h log h), about 3x cheaper than a general manifold check.
    """
    p = f"{where}: " if where else ""
    if isinstance(faces, tuple):
        idx, off = (np.asarray(a, dtype=np.int64) for a in faces)
    else:
        Fa = np.asarray(faces, dtype=np.int64)
        idx, off = Fa.ravel(), np.arange(0, Fa.size + 1, max(Fa.shape[1], 1), dtype=np.int64)
    n = int(n_vertices)
    lens = np.diff(off)
    h = len(idx)
    he_face = np.repeat(np.arange(len(lens), dtype=np.int64), lens)
    if len(lens) and (lens == lens[0]).all():
        k = int(lens[0])
        base = np.arange(0, h, k, dtype=np.int64)[:, None]
        nxt = (base + np.roll(np.arange(k), -1)).ravel()
        prv = (base + np.roll(np.arange(k), 1)).ravel()
    else:
        start = np.repeat(off[:-1], lens)
        pos = np.arange(h, dtype=np.int64) - start
        L = lens[he_face]
        nxt = start + (pos + 1) % L
        prv = start + (pos - 1) % L
        del start, pos, L
    # Temporaries are freed as soon as possible: this runs on meshes of millions of half-edges.
    b = idx[nxt]
    forward = idx < b  # half-edge runs from the smaller to the larger index
    keys = np.minimum(idx, b)
    keys *= n
    keys += np.maximum(idx, b)
    del b
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    del keys
    new = np.empty(h, dtype=bool)
    new[:1] = True
    np.not_equal(sk[1:], sk[:-1], out=new[1:])
    first = np.flatnonzero(new)
    E = np.stack([sk[first] // n, sk[first] % n], axis=1)
    del sk
    e = len(first)
    counts = np.diff(np.append(first, h))
    if (counts > 2).any():
        i = int(np.flatnonzero(counts > 2)[0])
        hs = order[first[i] : first[i] + counts[i]]
        fs = sorted(set(he_face[hs].tolist()))
        corners = {f: frozenset(idx[off[f] : off[f + 1]].tolist()) for f in fs}
        dup = [(f, g) for f in fs for g in fs if f < g and corners[f] == corners[g]]
        if dup:
            raise MeshError(f"{p}{name}: faces {dup[0][0]} and {dup[0][1]} are duplicates (same corners)")
        raise MeshError(
            f"{p}{name}: edge ({E[i, 0]}, {E[i, 1]}) is shared by {counts[i]} faces {tuple(fs)}; "
            f"subdivision needs an edge-manifold mesh (each edge in at most 2 faces)"
        )
    del counts, first
    he_edge = np.empty(h, dtype=np.int64)
    he_edge[order] = np.cumsum(new) - 1
    del order, new
    # Each edge has at most 2 half-edges; both in the same direction means the two faces disagree.
    fw = np.flatnonzero(forward)
    bw = np.flatnonzero(~forward)
    del forward
    bad = (np.bincount(he_edge[fw], minlength=e) > 1) | (np.bincount(he_edge[bw], minlength=e) > 1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        hs = np.flatnonzero(he_edge == i)[:2]
        f0, f1 = sorted(he_face[hs].tolist())
        u, v = int(idx[hs[0]]), int(idx[nxt[hs[0]]])
        same = frozenset(idx[off[f0] : off[f0 + 1]].tolist()) == frozenset(idx[off[f1] : off[f1 + 1]].tolist())
        raise MeshError(
            f"{p}{name}: faces {f0} and {f1} are duplicates (same corners)"
            if same
            else f"{p}{name}: faces {f0} and {f1} both traverse edge ({u}, {v}) in the same direction; "
            f"the mesh is not consistently oriented"
        )
    EH = np.full((e, 2), -1, dtype=np.int64)
    EH[he_edge[fw], 0] = fw
    EH[he_edge[bw], 1] = bw
    del fw, bw
    boundary_edge = (EH < 0).any(axis=1)
    valence = np.bincount(E.ravel(), minlength=n).astype(np.int64)
    boundary_vertex = np.zeros(n, dtype=bool)
    boundary_vertex[E[boundary_edge].ravel()] = True
    # Fans: link corner j with the corner of the same vertex across its outgoing half-edge j, i.e.
    # the corner after the twin half-edge. Every corner has at most one such link.
    inner = np.flatnonzero(~boundary_edge)
    h0, h1 = EH[inner, 0], EH[inner, 1]
    del inner
    _, owner = corner_fans(idx, np.concatenate([h0, h1]), np.concatenate([nxt[h1], nxt[h0]]), one_per_row=True)
    del h0, h1
    fans = np.bincount(owner, minlength=n)
    if (fans > 1).any():
        v = int(np.flatnonzero(fans > 1)[0])
        raise MeshError(
            f"{p}{name}: vertex {v} is non-manifold (its faces form {int(fans[v])} separate fans); "
            f"subdivision needs a vertex-manifold mesh"
        )
    EF = np.where(EH >= 0, he_face[np.maximum(EH, 0)], -1)
    return MeshTopology(idx, off, nxt, prv, he_face, he_edge, E, EH, EF, boundary_edge, boundary_vertex, valence)
