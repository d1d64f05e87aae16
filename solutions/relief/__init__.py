"""Lab "relief": bump, parallax and relief mapping (parallax occlusion mapping) with self-shadowing, in NumPy and in GLSL."""

from .bump import bump_normal, bump_offset
from .glsl import SHADERS, glsl_parallax_uv, glsl_relief_shadow, glsl_relief_uv, shader_path
from .heights import bricks, bumps, texel_uv
from .parallax import parallax_uv
from .relief import REFINEMENTS, layer_count, relief_uv
from .shadow import relief_shadow
from .silhouette import inside_texture
from .truth import exact_uv, uv_error_texels

__all__ = [
    "bump_offset",
    "bump_normal",
    "parallax_uv",
    "relief_uv",
    "layer_count",
    "REFINEMENTS",
    "relief_shadow",
    "inside_texture",
    "glsl_parallax_uv",
    "glsl_relief_uv",
    "glsl_relief_shadow",
    "SHADERS",
    "shader_path",
    "exact_uv",
    "uv_error_texels",
    "bumps",
    "bricks",
    "texel_uv",
]
