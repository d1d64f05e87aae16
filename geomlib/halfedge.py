"""The half-edge / corner structure of a polygon mesh, built in one vectorised pass.

:class:`HalfEdgeMesh` is geomlib's one connectivity structure: :mod:`geomlib.topology` (which
re-exports everything here, so ``geomlib.topology.HalfEdgeMesh`` is the usual spelling), the
manifold checks of :mod:`geomlib.validate`, :mod:`geomlib.datasets` and the labs read it. This
module also owns the face representations (:func:`to_ragged`), because the structure is defined
on them. It imports only NumPy, SciPy and :mod:`geomlib.errors`.

Faces are an int ``(m, k)`` array, a list of index sequences of mixed sizes, or the ragged
``(indices, offsets)`` pair (face ``f`` is ``indices[offsets[f]:offsets[f + 1]]``). Corner ``j``
is entry ``j`` of ``indices``; half-edge ``j`` leaves it for the next corner of the same face.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from geomlib.errors import MeshError, fmt_row, prefix, to_int64

__all__ = ["HalfEdgeMesh", "halfedge_mesh", "check_halfedges", "to_ragged", "next_corners", "corner_fans"]

# --------------------------------------------------------------------------------------------
# face representations


def _is_ragged_pair(faces) -> bool:
    """``(indices, offsets)``: two 1-D int arrays, offsets from 0 to ``len(indices)``, every face >= 3.

    The size rule is what keeps a tuple of two polygons given as arrays, e.g. two triangles
    ``(array([1, 2, 3]), array([0, 2, 3]))``, from being misread as faces of sizes 2 and 1.
    """
    if not (isinstance(faces, tuple) and len(faces) == 2):
        return False
    idx, off = faces
    if not all(isinstance(a, np.ndarray) and a.ndim == 1 and a.dtype.kind in "iu" for a in (idx, off)):
        return False
    return len(off) >= 1 and off[0] == 0 and off[-1] == len(idx) and bool((np.diff(off) >= 3).all())


def _ragged(faces) -> tuple[np.ndarray, np.ndarray]:
    """Unchecked conversion to int64 ``(indices, offsets)`` (for faces a public entry already checked)."""
    if _is_ragged_pair(faces):
        return np.asarray(faces[0], np.int64), np.asarray(faces[1], np.int64)
    if isinstance(faces, np.ndarray) and faces.dtype != object and faces.ndim == 2:
        m, k = faces.shape
        return np.asarray(faces, np.int64).ravel(), np.arange(0, m * k + 1, max(k, 1), dtype=np.int64)[: m + 1]
    polys = [np.asarray(f, dtype=np.int64).ravel() for f in faces]
    lens = np.array([len(p) for p in polys], dtype=np.int64)
    idx = np.concatenate(polys) if polys else np.zeros(0, np.int64)
    return idx, np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)


def to_ragged(
    faces, n_vertices: int | None = None, *, name: str = "faces", where: str | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """*Polygons*: check faces and return them as ``(indices, offsets)`` int64 arrays.

    Parameters
    ----------
    faces : (m, k) int array, list of index sequences, or ``(indices, offsets)``
        A tuple of two 1-D int arrays is read as a ragged pair when ``offsets`` runs from 0 to
        ``len(indices)`` and every face has at least 3 corners; pass two polygons as a list.
    n_vertices : int, optional
        When given, every index must be below it.
    name, where : str
        Argument and function names for error messages.

    Raises
    ------
    MeshError
        Faces missing, not integers, negative, past ``n_vertices``, or a polygon of fewer than 3
        corners. Repeated corners within a face are not checked here
        (:func:`geomlib.validate.as_polygons` does).
    """
    p = prefix(where)
    if faces is None:
        raise MeshError(f"{p}{name} is missing (got None)")
    if _is_ragged_pair(faces):
        idx, off = to_int64(faces[0], name, where), np.asarray(faces[1], np.int64)
    elif isinstance(faces, np.ndarray) and faces.dtype != object:
        if faces.ndim != 2:
            raise MeshError(f"{p}{name} has shape {faces.shape}, expected (m, k) faces or a list of polygons")
        if len(faces) and faces.shape[1] < 3:
            raise MeshError(f"{p}{name}: face 0 has {faces.shape[1]} vertices, a polygon needs at least 3")
        idx, off = _ragged(to_int64(faces, name, where))
    else:
        try:
            polys = [np.asarray(f) for f in faces]
        except TypeError:
            raise MeshError(f"{p}{name} must be an (m, k) int array or a list of polygons, got {faces!r}") from None
        for i, a in enumerate(polys):
            if a.ndim != 1 or a.dtype == object:
                raise MeshError(f"{p}{name}: face {i} is not a flat sequence of integer indices")
            polys[i] = to_int64(a, f"{name}: face {i}", where) if a.size else a.astype(np.int64)
        idx, off = _ragged(polys)
    lens = np.diff(off)
    if len(lens) and lens.min() < 3:
        f = int(np.flatnonzero(lens < 3)[0])
        raise MeshError(f"{p}{name}: face {f} has {lens[f]} vertices, a polygon needs at least 3")
    if idx.size and idx.min() < 0:
        f = int(np.searchsorted(off, np.flatnonzero(idx < 0)[0], side="right") - 1)
        raise MeshError(f"{p}{name}: face {f} {fmt_row(idx[off[f] : off[f + 1]])} has a negative index")
    if n_vertices is not None:
        n = _count(n_vertices, "n_vertices", where)
        if idx.size and idx.max() >= n:
            j = int(np.flatnonzero(idx >= n)[0])
            f = int(np.searchsorted(off, j, side="right") - 1)
            raise MeshError(
                f"{p}{name}: face {f} uses vertex {int(idx[j])}, but V has only {n} vertices (valid indices 0..{n - 1})"
            )
    return idx, off


def _count(n, name: str, where: str | None) -> int:
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 0:
        raise MeshError(f"{prefix(where)}{name} must be an integer >= 0, got {n!r}")
    return int(n)


def next_corners(offsets: np.ndarray) -> np.ndarray:
    """Next corner of every corner in its face, ``(h,)`` int64 (the last corner wraps to the first).

    Only the face sizes matter, so this needs ``offsets`` alone; half-edge ``j`` runs from corner
    ``j`` to corner ``next_corners(offsets)[j]``.
    """
    off = np.asarray(offsets, np.int64)
    h, lens = int(off[-1]), np.diff(off)
    if len(lens) and (lens == lens[0]).all():  # one face size: a reshape, no per-corner division
        k = int(lens[0])
        return (np.arange(0, h, k, dtype=np.int64)[:, None] + np.roll(np.arange(k), -1)).ravel()
    nxt = np.arange(1, h + 1, dtype=np.int64)
    nxt[off[1:] - 1] = off[:-1]
    return nxt


# --------------------------------------------------------------------------------------------
# the half-edge structure


@dataclass(frozen=True, eq=False, repr=False)
class HalfEdgeMesh:
    """Corner / half-edge connectivity of a polygon mesh (``n`` vertices, ``m`` faces, ``e`` edges, ``h`` corners).

    Corner ``j`` is entry ``j`` of the ragged faces; half-edge ``j`` runs from it to the next corner
    of its face. Build it with :func:`halfedge_mesh`. The fields up to ``n_vertices`` are stored;
    the others are derived from them on first use and then kept (``cached_property``), so a
    caller pays only for what it reads.

    Attributes
    ----------
    idx, off : (h,), (m + 1,) int64
        Ragged faces: face ``f`` is ``idx[off[f]:off[f + 1]]``; ``idx[j]`` is the vertex of corner ``j``.
    nxt : (h,) int64
        Next corner in the same face (half-edge ``j`` is ``idx[j] -> idx[nxt[j]]``).
    he_edge : (h,) int64
        Undirected edge of every half-edge (row of ``E``).
    E : (e, 2) int64
        Unique undirected edges, smaller index first, sorted lexicographically
        (the order of :func:`unique_edges`).
    EH : (e, 2) int64
        ``EH[i, 0]`` the half-edge running ``E[i, 0] -> E[i, 1]``, ``EH[i, 1]`` the one running back;
        ``-1`` where there is none (on a non-manifold edge the last one of each direction).
    n_vertices : int
    twin : (h,) int64
        The half-edge running the other way along the same edge; ``-1`` on a boundary edge, and
        also on edges that are not a proper pair (more than two faces, or two faces running the
        same way) — :attr:`edge_size` tells those apart.
    prv : (h,) int64
        Previous corner in the same face.
    he_face : (h,) int64
        Face of every corner.
    edge_size : (e,) int64
        Half-edges on every edge: 1 boundary, 2 interior, more = non-manifold edge.
    EF : (e, 2) int64
        The faces of those half-edges (``-1`` where none).
    boundary_edge : (e,) bool
        Edges with exactly one face.
    boundary_vertex : (n,) bool
        Vertices on a boundary edge.
    valence : (n,) int64
        Number of edges at every vertex (0 for a vertex no face uses).
    vertex_corner : (n,) int64
        One outgoing half-edge of every vertex (its boundary half-edge on the boundary), ``-1`` if unused.
    vertex_fans : (n,) int64
        Number of fans at every vertex (1 at a manifold vertex, 0 at an unused one); a fan is a set
        of corners of one vertex linked across shared edges. :meth:`fans` gives the fan of every
        corner.

    Invariants
    ----------
    :func:`check_halfedges` checks them; a mesh edited in place (split, collapse, flip) must keep them:

    1. ``off`` starts at 0, rises by >= 3 per face and ends at ``h``; ``nxt`` cycles through each
       face's corners in order, ``prv`` is its inverse.
    2. ``E[he_edge[j]]`` is ``(idx[j], idx[nxt[j]])`` sorted; rows of ``E`` are distinct, used,
       with ``E[:, 0] < E[:, 1]``.
    3. ``EH[i, 0]`` (when not -1) is a half-edge of edge ``i`` running ``E[i, 0] -> E[i, 1]``,
       ``EH[i, 1]`` one running back. ``twin`` pairs the two, so it is an involution without fixed
       points whose pairs run opposite ways.
    4. On a manifold, oriented mesh every edge has one or two half-edges, ``EH`` lists every
       half-edge once (so ``twin[j] == -1`` exactly on boundary edges) and every used vertex has
       one fan.

    The structure is frozen: an editing operation builds new arrays and a new ``HalfEdgeMesh``
    (``dataclasses.replace``), never writes into these, so the cached fields cannot go stale.
    """

    idx: np.ndarray
    off: np.ndarray
    nxt: np.ndarray
    he_edge: np.ndarray
    E: np.ndarray
    EH: np.ndarray
    n_vertices: int

    @property
    def n_faces(self) -> int:
        return len(self.off) - 1

    @property
    def n_edges(self) -> int:
        return len(self.E)

    @property
    def n_halfedges(self) -> int:
        return len(self.idx)

    def __repr__(self) -> str:
        return (
            f"HalfEdgeMesh(n_vertices={self.n_vertices}, n_faces={self.n_faces}, n_edges={self.n_edges}, "
            f"n_halfedges={self.n_halfedges})"
        )

    @cached_property
    def prv(self) -> np.ndarray:
        prv = np.empty_like(self.nxt)
        prv[self.nxt] = np.arange(len(self.nxt))
        return prv

    @cached_property
    def he_face(self) -> np.ndarray:
        return np.repeat(np.arange(self.n_faces, dtype=np.int64), np.diff(self.off))

    @property
    def edge_size(self) -> np.ndarray:  # not cached: one bincount, and this runs on huge meshes
        return np.bincount(self.he_edge, minlength=self.n_edges).astype(np.int64)

    @cached_property
    def twin(self) -> np.ndarray:
        twin = np.full(len(self.idx), -1, dtype=np.int64)
        e = np.flatnonzero((self.EH >= 0).all(axis=1) & (self.edge_size == 2))
        twin[self.EH[e, 0]] = self.EH[e, 1]
        twin[self.EH[e, 1]] = self.EH[e, 0]
        return twin

    @cached_property
    def EF(self) -> np.ndarray:
        return np.where(self.EH >= 0, self.he_face[np.maximum(self.EH, 0)], -1)

    @cached_property
    def boundary_edge(self) -> np.ndarray:
        return self.edge_size == 1

    @cached_property
    def boundary_vertex(self) -> np.ndarray:
        bv = np.zeros(self.n_vertices, dtype=bool)
        bv[self.E[self.boundary_edge].ravel()] = True
        return bv

    @cached_property
    def valence(self) -> np.ndarray:
        return np.bincount(self.E.ravel(), minlength=self.n_vertices).astype(np.int64)

    @cached_property
    def vertex_corner(self) -> np.ndarray:
        vc = np.full(self.n_vertices, -1, dtype=np.int64)
        vc[self.idx[::-1]] = np.arange(len(self.idx) - 1, -1, -1)  # first corner of every vertex
        bh = np.flatnonzero(self.edge_size[self.he_edge] == 1)
        vc[self.idx[bh]] = bh
        return vc

    def fans(self) -> tuple[np.ndarray, np.ndarray]:
        """``(corner_fan, fan_vertex)``: the fan of every corner and the vertex of every fan.

        Computed on each call (a connected-components pass) and not kept: most callers need only
        :attr:`vertex_fans`, and the labels are as long as the corners.
        """
        idx, nxt = self.idx, self.nxt
        links = self._pair_links()
        if links is not None:
            return corner_fans(idx, *links, one_per_row=True)
        # General case: chain the half-edges of every edge in order and link, for each consecutive
        # pair, their corners at the smaller endpoint and their corners at the larger one.
        order = np.argsort(self.he_edge, kind="stable")
        same = np.flatnonzero(self.he_edge[order[1:]] == self.he_edge[order[:-1]])
        h1, h2 = order[same], order[same + 1]
        up1, up2 = idx[h1] < idx[nxt[h1]], idx[h2] < idx[nxt[h2]]
        lo1, hi1 = np.where(up1, h1, nxt[h1]), np.where(up1, nxt[h1], h1)
        lo2, hi2 = np.where(up2, h2, nxt[h2]), np.where(up2, nxt[h2], h2)
        return corner_fans(idx, np.r_[lo1, hi1], np.r_[lo2, hi2])

    def _pair_links(self) -> tuple[np.ndarray, np.ndarray] | None:
        """``(rows, cols)``: each corner linked to the corner after its half-edge's twin, when every
        edge is a boundary or a proper pair a -> b, b -> a (else None).

        The two corners sit at the same vertex in faces sharing an edge; each corner has at most
        one such link, and each is linked to by at most one.
        """
        EH, nxt = self.EH, self.nxt
        size = self.edge_size
        pair = (EH >= 0).all(axis=1)
        if not ((size <= 2).all() and np.array_equal(pair, size == 2)):
            return None
        h0, h1 = EH[pair, 0], EH[pair, 1]
        return np.concatenate([h0, h1]), np.concatenate([nxt[h1], nxt[h0]])

    @property
    def vertex_fans(self) -> np.ndarray:  # not cached: the manifold check reads it once
        links = self._pair_links()
        if links is None:
            return np.bincount(self.fans()[1], minlength=self.n_vertices).astype(np.int64)
        return _fan_counts(self.idx, *links, self.n_vertices)


def halfedge_mesh(
    faces,
    n_vertices: int | None = None,
    *,
    manifold: bool = False,
    checked: bool = False,
    name: str = "faces",
    where: str | None = None,
) -> HalfEdgeMesh:
    """*Polygons*: build the :class:`HalfEdgeMesh` of a mesh in one vectorised pass.

    Parameters
    ----------
    faces : (m, k) int array, list of polygons, or ``(indices, offsets)``
    n_vertices : int, optional
        Number of vertices; default one past the largest index.
    manifold : bool
        Raise :class:`MeshError` unless the mesh is edge-manifold, consistently oriented and
        vertex-manifold (the checks come almost free with the build).
    checked : bool
        The faces come from a public entry that validated them already (an int64 ``(m, k)``
        array or a ragged pair, indices in range): skip the input checks.
    name, where : str
        Argument and function names for error messages.

    Notes
    -----
    One stable ``argsort`` of the undirected keys ``min * n + max`` groups the half-edges of every
    edge: the first of each group gives ``E``, the group number ``he_edge``, the direction of each
    half-edge its column of ``EH``. Cost O(h log h); temporaries are freed early because this runs
    on meshes of millions of half-edges.
    """
    if checked:
        idx, off = _ragged(faces)
        n = int(n_vertices) if n_vertices is not None else (int(idx.max()) + 1 if idx.size else 0)
    else:
        idx, off = to_ragged(faces, n_vertices, name=name, where=where)
        n = (
            _count(n_vertices, "n_vertices", where)
            if n_vertices is not None
            else (int(idx.max()) + 1 if idx.size else 0)
        )
    h = len(idx)
    nxt = next_corners(off)
    b = idx[nxt]
    keys = np.minimum(idx, b)
    keys *= max(n, 1)
    keys += np.maximum(idx, b)
    del b
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    del keys
    new = np.empty(h, dtype=bool)
    new[:1] = True
    np.not_equal(sk[1:], sk[:-1], out=new[1:])
    first = np.flatnonzero(new)
    E = np.stack([sk[first] // max(n, 1), sk[first] % max(n, 1)], axis=1)
    del sk
    he_edge = np.empty(h, dtype=np.int64)
    he_edge[order] = np.cumsum(new) - 1
    del new
    del order, first
    EH = np.full((len(E), 2), -1, dtype=np.int64)
    j = np.flatnonzero(idx < idx[nxt])  # runs from the smaller to the larger index
    EH[he_edge[j], 0] = j
    j = np.flatnonzero(idx >= idx[nxt])
    EH[he_edge[j], 1] = j
    del j
    H = HalfEdgeMesh(idx, off, nxt, he_edge, E, EH, n)
    if manifold:
        _require_manifold(H, name, where)
    return H


def _same_corners(H: HalfEdgeMesh, f: int, g: int) -> bool:
    return set(H.idx[H.off[f] : H.off[f + 1]].tolist()) == set(H.idx[H.off[g] : H.off[g + 1]].tolist())


def _require_manifold(H: HalfEdgeMesh, name: str, where: str | None) -> None:
    """The manifold and orientation messages of geomlib, in one place."""
    p = prefix(where)
    size = H.edge_size
    if (size > 2).any():
        i = int(np.flatnonzero(size > 2)[0])
        fs = sorted(set(H.he_face[H.he_edge == i].tolist()))
        dup = [(f, g) for f in fs for g in fs if f < g and _same_corners(H, f, g)]
        why = f" (faces {dup[0][0]} and {dup[0][1]} are duplicates: same corners)" if dup else ""
        raise MeshError(
            f"{p}{name}: edge ({H.E[i, 0]}, {H.E[i, 1]}) is shared by {size[i]} faces {tuple(fs)}{why}; "
            f"this needs an edge-manifold mesh (each edge in at most 2 faces)"
        )
    same_way = (size == 2) & (H.EH < 0).any(axis=1)  # two faces running the same way along an edge
    if same_way.any():
        hs = np.flatnonzero(H.he_edge == np.flatnonzero(same_way)[0])
        f0, f1 = sorted(H.he_face[hs].tolist())
        u, v = int(H.idx[hs[0]]), int(H.idx[H.nxt[hs[0]]])
        raise MeshError(
            f"{p}{name}: faces {f0} and {f1} are duplicates (same corners)"
            if _same_corners(H, f0, f1)
            else f"{p}{name}: faces {f0} and {f1} both traverse edge ({u}, {v}) in the same direction; "
            f"the mesh is not consistently oriented"
        )
    fans = H.vertex_fans
    if (fans > 1).any():
        v = int(np.flatnonzero(fans > 1)[0])
        raise MeshError(
            f"{p}{name}: vertex {v} is non-manifold (its faces form {int(fans[v])} separate fans); "
            f"this needs a vertex-manifold mesh"
        )


def check_halfedges(H: HalfEdgeMesh, *, manifold: bool = True) -> None:
    """Raise :class:`MeshError` naming the first broken invariant of a :class:`HalfEdgeMesh`.

    Checks invariants 1-3 of :class:`HalfEdgeMesh` always and 4 with ``manifold``; ``twin`` and the
    other derived fields follow from them. Meant for code
    that edits the structure (edge split, collapse, flip): call it after each operation in tests.
    Cost O(h log h).
    """
    p = "check_halfedges: "
    idx, off, nxt, he_edge, E, EH = H.idx, H.off, H.nxt, H.he_edge, H.E, H.EH
    h, e, n = len(idx), len(E), H.n_vertices
    for nm, a, shape in (("idx", idx, (h,)), ("nxt", nxt, (h,)), ("he_edge", he_edge, (h,)), ("E", E, (e, 2)),
                         ("EH", EH, (e, 2))):  # fmt: skip
        if a.shape != shape or a.dtype != np.int64:
            raise MeshError(f"{p}{nm} has shape {a.shape} and dtype {a.dtype}, expected {shape} int64")
    lens = np.diff(off)
    if len(off) == 0 or off[0] != 0 or off[-1] != h or (len(lens) and lens.min() < 3):
        raise MeshError(f"{p}off must rise from 0 to {h} by at least 3 per face")
    if h and (idx.min() < 0 or idx.max() >= n):
        raise MeshError(f"{p}idx holds a vertex outside 0..{n - 1}")
    bad = np.flatnonzero(nxt != next_corners(off))
    if len(bad):
        raise MeshError(f"{p}nxt[{bad[0]}] is {nxt[bad[0]]}, not the next corner of its face")
    if h and (he_edge.min() < 0 or he_edge.max() >= e):
        raise MeshError(f"{p}he_edge holds an edge outside 0..{e - 1}")
    ends = np.sort(np.stack([idx, idx[nxt]], axis=1), axis=1)
    wrong = np.flatnonzero((E[he_edge] != ends).any(axis=1))
    if len(wrong):
        j = int(wrong[0])
        raise MeshError(f"{p}half-edge {j} runs {fmt_row(ends[j])} but he_edge names edge {fmt_row(E[he_edge[j]])}")
    size = np.bincount(he_edge, minlength=e)
    Es = E[np.lexsort((E[:, 1], E[:, 0]))]
    if e and ((E[:, 0] >= E[:, 1]).any() or (Es[1:] == Es[:-1]).all(axis=1).any() or size.min() < 1):
        raise MeshError(f"{p}E must hold distinct used edges, smaller index first")
    for col in (0, 1):
        has = np.flatnonzero(EH[:, col] >= 0)
        j = EH[has, col]
        if len(j) and j.max() >= h:
            raise MeshError(f"{p}EH[:, {col}] holds a half-edge past {h - 1}")
        wrong = (he_edge[j] != has) | (idx[j] != E[has, col]) | (idx[nxt[j]] != E[has, 1 - col])
        if wrong.any():
            k = int(np.flatnonzero(wrong)[0])
            raise MeshError(
                f"{p}EH[{has[k]}, {col}] = {j[k]} is not a half-edge running "
                f"{E[has[k], col]} -> {E[has[k], 1 - col]} along edge {has[k]}"
            )
    if manifold:
        if (size > 2).any():
            raise MeshError(f"{p}edge {int(np.flatnonzero(size > 2)[0])} has more than two half-edges")
        if np.count_nonzero(EH >= 0) != h:
            raise MeshError(f"{p}EH does not list every half-edge (two half-edges of an edge run the same way)")
        fans = HalfEdgeMesh(idx, off, nxt, he_edge, E, EH, n).vertex_fans  # fresh: no stale cache
        if (fans > 1).any():
            raise MeshError(f"{p}vertex {int(np.flatnonzero(fans > 1)[0])} has {int(fans.max())} fans (non-manifold)")


def _fan_counts(idx: np.ndarray, rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray:
    """Fans per vertex ``(n,)`` when each corner has at most one link out (``rows`` distinct) and
    one in (``cols`` distinct): the links are then paths and cycles, and :func:`corner_fans`'s
    connected components (a sparse matrix and scipy's graph search: most of a small mesh's
    manifold check) come down to pointer doubling.

    After ``r`` doublings every corner knows the corner ``2**r`` links ahead (a path's last corner
    stays put) and the smallest corner on the way; once ``2**r`` reaches the largest number of
    corners at one vertex, a path's corners all name its last corner and a cycle's its smallest
    corner: one name per fan.
    """
    N = len(idx)
    ahead = np.arange(N, dtype=np.int64)
    ahead[rows] = cols
    low = np.minimum(ahead, np.arange(N, dtype=np.int64))
    most = int(np.bincount(idx, minlength=1).max()) if N else 0
    r = 0
    while (1 << r) < most:
        low = np.minimum(low, low[ahead])
        ahead = ahead[ahead]
        r += 1
    out = np.zeros(N, dtype=bool)
    out[rows] = True
    end = ~out[ahead]  # on a path: a corner that links nowhere ahead (a cycle's ahead may be itself)
    name = np.where(end, ahead, low)
    fan = np.zeros(N, dtype=bool)
    fan[name] = True
    return np.bincount(idx[fan], minlength=n).astype(np.int64)


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
    import scipy.sparse as sp  # here, not at the top: 0.25 s of CPU for every importer of geomlib.validate
    from scipy.sparse.csgraph import connected_components

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
