"""Lab "remeshing": isotropic remeshing (Botsch & Kobbelt 2004).

Tasks, in order:

1-3. local operations on a mutable corner table (:mod:`.kernels`, its state in :mod:`.state`):
     edge split, edge collapse (link condition, no-flip test, no edge longer than the split
     bound), edge flip; exposed on geomlib's half-edge structure as :func:`split_edge`,
     :func:`collapse_edge`, :func:`flip_edge` (:mod:`.operations`);
4-6. the passes of :mod:`.kernels` behind the stages :func:`split_long_edges`,
     :func:`collapse_short_edges`, :func:`equalize_valences` (:mod:`.stages`);
7.   features: :func:`sharp_edges` (:mod:`.stages`);
8-9. :func:`tangential_relaxation`, :func:`project_to_surface` (:mod:`.stages`);
10.  the loop :func:`isotropic_remesh` (:mod:`.remesh`);
11.  extension: :func:`max_curvature`, :func:`adaptive_target_length` (:mod:`.adaptive`; target
     length per vertex from curvature; ``isotropic_remesh(..., adaptive=True)`` or a per-vertex
     ``target_length``).
"""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import adaptive, operations, remesh, stages, state
from .adaptive import *
from .operations import *
from .remesh import *
from .stages import *
from .state import *

__all__ = [name for module in (state, operations, stages, remesh, adaptive) for name in module.__all__]
