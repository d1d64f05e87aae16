"""Lab "subdivision": Loop subdivision of triangle meshes and Catmull-Clark subdivision of polygon meshes."""

from .catmullclark import (
    catmull_clark,
    catmull_clark_step,
    cc_edge_points,
    cc_face_points,
    cc_quads,
    cc_vertex_points,
    polygon_topology,
    scatter_sum,
)
from .connectivity import MeshTopology, mesh_topology
from .loop import (
    WEIGHT_RULES,
    loop_even_matrix,
    loop_faces,
    loop_matrix,
    loop_odd_matrix,
    loop_subdivide,
    loop_topology,
    loop_weight,
    opposite_vertices,
    sparse_from_triplets,
)

__all__ = [
    "WEIGHT_RULES",
    "MeshTopology",
    "mesh_topology",
    "loop_topology",
    "opposite_vertices",
    "sparse_from_triplets",
    "loop_weight",
    "loop_odd_matrix",
    "loop_even_matrix",
    "loop_faces",
    "loop_matrix",
    "loop_subdivide",
    "polygon_topology",
    "scatter_sum",
    "cc_face_points",
    "cc_edge_points",
    "cc_vertex_points",
    "cc_quads",
    "catmull_clark_step",
    "catmull_clark",
]
