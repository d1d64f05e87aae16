"""Lab "maps": tangent frames, normal maps (encode, decode, from heights, baking), per-pixel shading and displacement maps."""

from .bake import bake_normal_map, barycentric, project_to_surface
from .displacement import displace, group_mean, welded_vertex_normals
from .encoding import decode_normal_map, encode_normal_map
from .heightmap import BORDERS, height_to_normal_map
from .shading import rasterize_mesh, shade, surface_frames
from .tangents import face_uv_gradients, tangent_frames

__all__ = [
    "tangent_frames",
    "face_uv_gradients",
    "encode_normal_map",
    "decode_normal_map",
    "height_to_normal_map",
    "BORDERS",
    "shade",
    "rasterize_mesh",
    "surface_frames",
    "displace",
    "welded_vertex_normals",
    "group_mean",
    "bake_normal_map",
    "project_to_surface",
    "barycentric",
]
