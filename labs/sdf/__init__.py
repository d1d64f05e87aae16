"""Lab "sdf": signed distance fields — analytic SDFs and CSG, mesh SDFs through a BVH, signs, bricks,
sphere tracing, soft shadows, ambient occlusion and push-out.

Tasks: 1 analytic SDFs and CSG (:mod:`analytic`); 2 point-triangle distance and the brute force
(:mod:`triangle`); 3 the BVH, its closest-point walk and the narrow band (:mod:`bvh`,
:mod:`kernels`, :mod:`mesh_sdf`); 4 signs (:mod:`sign`); 5 bricks (:mod:`bricks`); 6 lookups
and instancing (:mod:`field`, :mod:`bricks`, :mod:`queries`); 7 gradients (:mod:`gradient`);
8 sphere tracing (:mod:`trace`); 9 soft shadows, AO, push-out (:mod:`shadow`).
"""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import analytic, bricks, bvh, field, gradient, mesh_sdf, queries, scene, shadow, sign, trace, triangle, truth
from .analytic import *
from .bricks import *
from .bvh import *
from .field import *
from .gradient import *
from .mesh_sdf import *
from .queries import *
from .scene import *
from .shadow import *
from .sign import *
from .trace import *
from .triangle import *
from .truth import *

#: Exported by their modules for the lab's other modules (input checks and the like), not by the lab.
_MODULE_ONLY = {"as_points", "check_grid", "face_normals_unit"}
__all__ = [
    name
    for module in (
        analytic,
        triangle,
        bvh,
        mesh_sdf,
        sign,
        bricks,
        field,
        queries,
        gradient,
        trace,
        shadow,
        scene,
        truth,
    )
    for name in module.__all__
    if name not in _MODULE_ONLY
]
