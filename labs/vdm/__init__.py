"""Lab "vdm": vector displacement map baking.

Pipeline: parameterize a disk-topology mesh onto the unit square (Task 1), sample it at uv points
(Task 2), bake the naive VDM (Task 3), score vertices by crease sharpness (Task 4), splat the
scores into an importance field (Task 5), move the grid samples by optimal transport toward
important regions (Task 6), snap them onto sharp features (Task 7) and choose per-quad diagonals
along sharp edges (Task 8). :func:`bake_vdm` runs all stages; :func:`vdm_to_mesh` rebuilds the
surface.
"""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import diagonals, features, grid, importance, parameterize, sampling, shapes, transport, vdm
from .diagonals import *
from .features import *
from .grid import *
from .importance import *
from .parameterize import *
from .sampling import *
from .shapes import *
from .transport import *
from .vdm import *

#: Exported by their modules for the lab's other modules (input checks and the like), not by the lab.
_MODULE_ONLY = {"SQUARE_CORNERS", "map_at_nodes"}
__all__ = [
    name
    for module in (parameterize, sampling, vdm, importance, transport, features, diagonals, grid, shapes)
    for name in module.__all__
    if name not in _MODULE_ONLY
]
