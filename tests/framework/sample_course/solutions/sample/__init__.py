"""Sample lab: two tiny tasks on triangle meshes."""

from .ops import edge_midpoints, scale_about_centroid

__all__ = ["edge_midpoints", "scale_about_centroid"]
