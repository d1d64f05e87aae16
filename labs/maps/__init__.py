"""Lab "maps": tangent frames, normal maps (encode, decode, from heights, baking), per-pixel shading and displacement maps."""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import bake, displacement, encoding, glsl, heightmap, shading, tangents
from .bake import *
from .displacement import *
from .encoding import *
from .glsl import *
from .heightmap import *
from .shading import *
from .tangents import *

#: Exported by their modules for the lab's other modules (input checks and the like), not by the lab.
_MODULE_ONLY = {"cross_rows", "scatter_to_vertices"}
__all__ = [
    name
    for module in (tangents, encoding, heightmap, shading, displacement, bake, glsl)
    for name in module.__all__
    if name not in _MODULE_ONLY
]
