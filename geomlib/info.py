"""``geomlib info FILE``: a one-screen description of a mesh file that a student can trust.

Besides counts, face kinds, boundary loops, components, Euler characteristic and bounding box,
:func:`summary` names every defect that breaks the lab functions, with a count and the first few
indices: duplicate faces, degenerate faces, duplicate vertices, unreferenced vertices,
non-manifold edges and non-manifold vertices.

Definitions (all computed here with vectorised NumPy/SciPy on the ragged face arrays of
:mod:`geomlib.topology`):

- *duplicate face*: a face whose set of vertex indices equals an earlier face's (either
  orientation, any starting corner); the count is the number of extra copies.
- *degenerate face*: a face that repeats a vertex index (e.g. ``[4, 4, 7]``), or whose (vector)
  area is below ``1e-12`` times the squared bounding-box diagonal.
- *duplicate vertex*: a vertex at exactly the same position as an earlier vertex.
- *unreferenced vertex*: a vertex no face uses.
- *non-manifold edge*: an undirected edge used by more than two faces (a duplicated face makes
  each of its edges non-manifold).
- *non-manifold vertex*: a vertex whose faces form more than one edge-connected fan (a "bow tie").
- *components*: groups of faces connected through shared edges; a duplicated face belongs to the
  component of the face it copies.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from geomlib import mesh_io, topology

__all__ = ["describe", "summary", "DEFECTS"]

#: Defect keys of :func:`summary`, in the order ``describe`` prints them, with their labels.
DEFECTS = {
    "duplicate_faces": "duplicate faces",
    "degenerate_faces": "degenerate faces",
    "duplicate_vertices": "duplicate vertices",
    "unreferenced_vertices": "unreferenced vertices",
    "non_manifold_edges": "non-manifold edges",
    "non_manifold_vertices": "non-manifold vertices",
}

#: Faces whose area is below this fraction of the squared bounding-box diagonal count as degenerate.
AREA_TOL = 1e-12

#: How many example indices each defect lists.
N_EXAMPLES = 5


def _face_keys(idx: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Sorted vertex indices of every face, padded with -1 to the largest face: ``(m, kmax)``."""
    lens = np.diff(off)
    m, kmax = len(lens), int(lens.max()) if len(lens) else 0
    keys = np.full((m, kmax), -1, dtype=np.int64)
    face = np.repeat(np.arange(m), lens)
    pos = np.arange(len(idx)) - np.repeat(off[:-1], lens)
    keys[face, pos] = idx
    keys.sort(axis=1)  # -1 padding first, then the vertex indices: equal sets give equal rows
    return keys


def _repeats(rows: np.ndarray) -> np.ndarray:
    """Indices of rows equal to an earlier row (the extra copies), sorted."""
    if len(rows) == 0:
        return np.zeros(0, np.int64)
    _, first = np.unique(rows, axis=0, return_index=True)
    extra = np.ones(len(rows), dtype=bool)
    extra[first] = False
    return np.flatnonzero(extra).astype(np.int64)


def _face_areas(V: np.ndarray, idx: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Norm of every face's vector area (half the sum of corner cross products), ``(m,)``."""
    lens = np.diff(off)
    he = topology.halfedges(idx, off)
    cross = np.cross(V[he[:, 0]], V[he[:, 1]])
    face = np.repeat(np.arange(len(lens)), lens)
    vec = np.zeros((len(lens), 3))
    np.add.at(vec, face, cross)
    return 0.5 * np.linalg.norm(vec, axis=1)


def _components(idx: np.ndarray, off: np.ndarray) -> int:
    """Number of groups of faces connected through shared undirected edges."""
    m = len(off) - 1
    if m == 0:
        return 0
    und = np.sort(topology.halfedges(idx, off), axis=1)
    _, edge = topology.unique_rows(und, return_inverse=True)
    face = np.repeat(np.arange(m), np.diff(off))
    ne = int(edge.max()) + 1
    # Bipartite face-edge graph: every edge has a face, so its components are the face components.
    G = sp.coo_matrix((np.ones(len(face)), (face, m + edge)), shape=(m + ne, m + ne))
    return int(connected_components(G, directed=False)[0])


def summary(V: np.ndarray, faces) -> dict:
    """Counts, defects, face kinds, boundary loops, components, genus and bbox of a mesh.

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions.
    faces : (m, k) int array, list of polygons, or ``(indices, offsets)``
        Faces, 0-based.

    Returns
    -------
    dict
        ``vertices``, ``faces``, ``face_kinds`` ({corners: count}), ``edges``; for every key of
        :data:`DEFECTS` its count and ``<key>_examples`` (up to :data:`N_EXAMPLES` face, vertex or
        edge indices; edges as vertex pairs); ``degenerate_repeated`` and ``degenerate_zero_area``
        (the two kinds of degenerate face); ``edge_manifold``, ``vertex_manifold``,
        ``boundary_loops`` (lengths, or None when the boundary is not a set of simple loops),
        ``components``, ``euler_characteristic``, ``genus`` (None unless one closed-or-bounded
        manifold component), ``bbox_min``, ``bbox_max``, ``bbox_diagonal``.
    """
    V = np.asarray(V, dtype=np.float64)
    idx, off = topology.to_ragged(faces)
    n = len(V)
    sizes = np.diff(off)
    kinds = {int(k): int(c) for k, c in zip(*np.unique(sizes, return_counts=True), strict=True)}
    lo, hi = (V.min(axis=0), V.max(axis=0)) if n else (np.zeros(3), np.zeros(3))
    diag = float(np.linalg.norm(hi - lo))

    keys = _face_keys(idx, off)
    dup_faces = _repeats(keys)
    # Padding (-1) of a shorter face is not a repeated vertex: only compare real indices.
    same = (keys[:, 1:] == keys[:, :-1]) & (keys[:, :-1] >= 0)
    repeated = np.flatnonzero(same.any(axis=1))
    zero = np.flatnonzero(_face_areas(V, idx, off) <= AREA_TOL * diag**2) if len(sizes) else np.zeros(0, np.int64)
    zero = np.setdiff1d(zero, repeated)
    degenerate = np.union1d(repeated, zero)

    dup_verts = _repeats(V)
    used = np.zeros(n, dtype=bool)
    used[idx] = True
    unreferenced = np.flatnonzero(~used)

    und = np.sort(topology.halfedges(idx, off), axis=1) if len(idx) else np.zeros((0, 2), np.int64)
    E, counts = topology.unique_rows(und, return_counts=True) if len(und) else (und, np.zeros(0, np.int64))
    nm_edges = E[counts > 2]
    fans = topology.vertex_fan_counts(idx, off, n)
    nm_verts = np.flatnonzero(fans > 1)

    edge_manifold = len(nm_edges) == 0
    vertex_manifold = len(nm_verts) == 0
    try:
        loops = topology.boundary_loops((idx, off)) if edge_manifold and len(idx) else ([] if edge_manifold else None)
    except ValueError:  # MeshError: a boundary pinch
        loops = None
    ncomp = _components(idx, off)
    chi = topology.euler_characteristic((idx, off)) if len(idx) else 0
    genus = None
    if loops is not None and ncomp == 1 and edge_manifold and vertex_manifold and len(dup_faces) == 0:
        genus = (2 - chi - len(loops)) // 2

    out = {
        "vertices": n,
        "faces": len(sizes),
        "face_kinds": kinds,
        "edges": len(E),
    }
    for key, found in (
        ("duplicate_faces", dup_faces),
        ("degenerate_faces", degenerate),
        ("duplicate_vertices", dup_verts),
        ("unreferenced_vertices", unreferenced),
        ("non_manifold_edges", nm_edges),
        ("non_manifold_vertices", nm_verts),
    ):
        out[key] = len(found)
        out[f"{key}_examples"] = np.asarray(found[:N_EXAMPLES]).tolist()
    out.update(
        degenerate_repeated=len(repeated),
        degenerate_zero_area=len(zero),
        edge_manifold=edge_manifold,
        vertex_manifold=vertex_manifold,
        boundary_loops=None if loops is None else [len(lp) for lp in loops],
        components=ncomp,
        euler_characteristic=int(chi),
        genus=genus,
        bbox_min=lo.tolist(),
        bbox_max=hi.tolist(),
        bbox_diagonal=diag,
    )
    return out


def _examples(s: dict, key: str) -> str:
    ex = s[f"{key}_examples"]
    if key == "non_manifold_edges":
        what, shown = "edges", ", ".join(f"({a}, {b})" for a, b in ex)
    else:
        what, shown = ("faces" if key.endswith("faces") else "vertices"), ", ".join(map(str, ex))
    more = ", …" if s[key] > len(ex) else ""
    return f"{what} {shown}{more}"


def describe(path) -> str:
    """Human-readable :func:`summary` of the mesh in ``path`` (OBJ, OFF, PLY)."""
    V, faces = mesh_io.read_mesh(path)
    s = summary(V, faces)
    names = {3: "triangles", 4: "quads"}
    kinds = ", ".join(f"{c:,} {names.get(k, f'{k}-gons')}" for k, c in s["face_kinds"].items()) or "none"
    loops = s["boundary_loops"]
    lines = [
        f"{path}",
        f"  vertices       {s['vertices']:,}",
        f"  faces          {s['faces']:,} ({kinds})",
        f"  edges          {s['edges']:,}",
        f"  manifold       edges: {'yes' if s['edge_manifold'] else 'NO'}, vertices: {'yes' if s['vertex_manifold'] else 'NO'}",
        "  boundary       "
        + (
            "unknown (non-manifold edges or a pinched boundary)"
            if loops is None
            else "closed (no boundary)"
            if not loops
            else f"{len(loops)} loop(s) of {', '.join(map(str, loops))} edges"
        ),
        f"  components     {s['components']} (faces connected through shared edges)",
        f"  Euler char.    {s['euler_characteristic']}" + (f", genus {s['genus']}" if s["genus"] is not None else ""),
        "  bbox           "
        + " .. ".join("(" + ", ".join(f"{x:.4g}" for x in v) + ")" for v in (s["bbox_min"], s["bbox_max"]))
        + f", diagonal {s['bbox_diagonal']:.4g}",
        "  defects",
    ]
    for key, label in DEFECTS.items():
        count = s[key]
        line = f"    {label:<22} {count:,}"
        if count:
            line += f"  ({_examples(s, key)})"
            if key == "degenerate_faces":
                line += f" [{s['degenerate_repeated']:,} repeat a vertex, {s['degenerate_zero_area']:,} have zero area]"
        lines.append(line)
    if not any(s[k] for k in DEFECTS):
        lines.append("    none: no duplicate, degenerate or unreferenced elements, manifold everywhere")
    return "\n".join(lines)
