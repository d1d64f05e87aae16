"""Lab "relief": bump, parallax and relief mapping (parallax occlusion mapping) with self-shadowing, in NumPy and in GLSL."""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import bump, glsl, heights, parallax, relief, shadow, silhouette, truth
from .bump import *
from .glsl import *
from .heights import *
from .parallax import *
from .relief import *
from .shadow import *
from .silhouette import *
from .truth import *

__all__ = [
    name for module in (bump, parallax, relief, shadow, silhouette, glsl, truth, heights) for name in module.__all__
]
