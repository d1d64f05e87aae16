"""Lab "subdivision": Loop subdivision of triangle meshes and Catmull-Clark subdivision of polygon meshes."""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import catmullclark, connectivity, loop
from .catmullclark import *
from .connectivity import *
from .loop import *

__all__ = [name for module in (connectivity, loop, catmullclark) for name in module.__all__]
