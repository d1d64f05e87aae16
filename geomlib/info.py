"""``geomlib info FILE``: a one-screen description of a mesh file."""

from __future__ import annotations

import numpy as np

from geomlib import mesh_io, topology

__all__ = ["describe", "summary"]


def summary(V: np.ndarray, faces) -> dict:
    """Counts, face kinds, manifoldness, boundary loops, components, genus and bbox of a mesh."""
    idx, off = topology.to_ragged(faces)
    sizes = np.diff(off)
    kinds = {int(k): int(c) for k, c in zip(*np.unique(sizes, return_counts=True), strict=True)}
    used = topology.unique_ints(idx)
    edge_manifold = topology.is_edge_manifold((idx, off))
    fans = topology.vertex_fan_counts(idx, off, len(V))
    vertex_manifold = bool((fans[used] == 1).all())
    try:
        loops = topology.boundary_loops((idx, off)) if edge_manifold else None
    except ValueError:
        loops = None
    ncomp, _ = topology.connected_components_faces((idx, off))
    chi = topology.euler_characteristic((idx, off))
    genus = None
    if loops is not None and ncomp == 1 and edge_manifold and vertex_manifold:
        genus = (2 - chi - len(loops)) // 2
    lo, hi = V.min(axis=0), V.max(axis=0)
    return {
        "vertices": len(V),
        "unreferenced_vertices": len(V) - len(used),
        "faces": len(sizes),
        "face_kinds": kinds,
        "edges": len(topology.unique_edges((idx, off))),
        "edge_manifold": edge_manifold,
        "vertex_manifold": vertex_manifold,
        "boundary_loops": None if loops is None else [len(lp) for lp in loops],
        "components": int(ncomp),
        "euler_characteristic": int(chi),
        "genus": genus,
        "bbox_min": lo.tolist(),
        "bbox_max": hi.tolist(),
        "bbox_diagonal": float(np.linalg.norm(hi - lo)),
    }


def describe(path) -> str:
    """Human-readable :func:`summary` of the mesh in ``path`` (OBJ, OFF, PLY)."""
    V, faces = mesh_io.read_mesh(path)
    s = summary(V, faces)
    names = {3: "triangles", 4: "quads"}
    kinds = ", ".join(f"{c} {names.get(k, f'{k}-gons')}" for k, c in s["face_kinds"].items())
    loops = s["boundary_loops"]
    lines = [
        f"{path}",
        f"  vertices       {s['vertices']:,}"
        + (f" ({s['unreferenced_vertices']:,} unreferenced)" if s["unreferenced_vertices"] else ""),
        f"  faces          {s['faces']:,} ({kinds})",
        f"  edges          {s['edges']:,}",
        f"  manifold       edges: {'yes' if s['edge_manifold'] else 'NO'}, vertices: {'yes' if s['vertex_manifold'] else 'NO'}",
        "  boundary       "
        + (
            "unknown (non-manifold)"
            if loops is None
            else "closed (no boundary)"
            if not loops
            else f"{len(loops)} loop(s) of {', '.join(map(str, loops))} edges"
        ),
        f"  components     {s['components']}",
        f"  Euler char.    {s['euler_characteristic']}" + (f", genus {s['genus']}" if s["genus"] is not None else ""),
        "  bbox           "
        + " .. ".join("(" + ", ".join(f"{x:.4g}" for x in v) + ")" for v in (s["bbox_min"], s["bbox_max"]))
        + f", diagonal {s['bbox_diagonal']:.4g}",
    ]
    return "\n".join(lines)
