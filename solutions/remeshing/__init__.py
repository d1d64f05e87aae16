"""Lab "remeshing": isotropic remeshing (Botsch & Kobbelt 2004).

Tasks, in order:

1-3. local operations on a mutable corner table (:mod:`.kernels`): edge split, edge collapse
     (link condition, no-flip test, no edge longer than the split bound), edge flip; exposed on
     geomlib's half-edge structure as :func:`split_edge`, :func:`collapse_edge`, :func:`flip_edge`;
4-6. the stages :func:`split_long_edges`, :func:`collapse_short_edges`, :func:`equalize_valences`;
7.   features: :func:`sharp_edges`;
8-9. :func:`tangential_relaxation`, :func:`project_to_surface`;
10.  the loop :func:`isotropic_remesh`;
11.  extension: :func:`max_curvature`, :func:`adaptive_target_length` (target length per vertex
     from curvature; ``isotropic_remesh(..., adaptive=True)`` or a per-vertex ``target_length``).
"""

from .remesh import (
    RemeshState,
    SurfaceProjector,
    adaptive_target_length,
    collapse_edge,
    collapse_short_edges,
    equalize_valences,
    flip_edge,
    isotropic_remesh,
    make_state,
    max_curvature,
    project_to_surface,
    sharp_edges,
    split_edge,
    split_long_edges,
    state_mesh,
    tangential_relaxation,
)

__all__ = [
    "RemeshState",
    "make_state",
    "state_mesh",
    "split_edge",
    "collapse_edge",
    "flip_edge",
    "sharp_edges",
    "split_long_edges",
    "collapse_short_edges",
    "equalize_valences",
    "tangential_relaxation",
    "project_to_surface",
    "isotropic_remesh",
    "max_curvature",
    "adaptive_target_length",
    "SurfaceProjector",
]
