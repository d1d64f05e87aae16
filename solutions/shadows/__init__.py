"""Lab "shadows": shadow mapping for directional, spot and point lights, with bias, culling, frustum handling and PCF."""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import cube_glsl, cubemap, depth, glsl, lights, lookup, options, scene, shading, truth
from .cube_glsl import *
from .cubemap import *
from .depth import *
from .glsl import *
from .lights import *
from .lookup import *
from .options import *
from .scene import *
from .shading import *
from .truth import *

#: Exported by their modules for the lab's other modules (input checks and the like), not by the lab.
_MODULE_ONLY = {"check_shadow_map", "as_camera", "as_light", "LightSetup"}
__all__ = [
    name
    for module in (lights, depth, lookup, options, cubemap, scene, shading, truth, glsl, cube_glsl)
    for name in module.__all__
    if name not in _MODULE_ONLY
]
