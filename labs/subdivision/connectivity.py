"""Half-edge connectivity of a polygon mesh, computed once per subdivision level (given code).

Both subdivision schemes need the same facts about the coarse mesh: its unique edges, which
faces lie on either side of every edge, which edges and vertices are on the boundary, and the
valence of every vertex. They are all fields of geomlib's one half-edge structure,
:class:`geomlib.topology.HalfEdgeMesh`, which :func:`mesh_topology` builds in one sort of the
half-edge keys while checking that the mesh is manifold and consistently oriented (subdivision
rules are only defined there).

Faces are stored *ragged*: face ``f`` is ``idx[off[f]:off[f + 1]]`` (see
:func:`geomlib.topology.to_ragged`); a triangle mesh ``F (m, 3)`` is ``idx = F.ravel()``,
``off = 0, 3, 6, ...``. Half-edge ``j`` runs from corner ``j`` to the next corner of the same
face, ``idx[j] -> idx[nxt[j]]``.
"""

from __future__ import annotations

from geomlib.topology import HalfEdgeMesh, halfedge_mesh

__all__ = ["MeshTopology", "mesh_topology"]

#: The connectivity the lab reads (the fields it uses most: ``idx``, ``off``, ``nxt``, ``prv``,
#: ``he_face``, ``he_edge``, ``twin``, ``E``, ``EH``, ``EF``, ``boundary_edge``,
#: ``boundary_vertex``, ``valence``; see :class:`geomlib.topology.HalfEdgeMesh`).
MeshTopology = HalfEdgeMesh


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
    """
    return halfedge_mesh(faces, n_vertices, manifold=True, checked=True, name=name, where=where)
