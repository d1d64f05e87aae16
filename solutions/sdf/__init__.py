"""Lab "sdf": signed distance fields — analytic SDFs and CSG, mesh SDFs through a BVH, signs, bricks,
sphere tracing, soft shadows, ambient occlusion and push-out.

Tasks: 1 analytic SDFs and CSG (:mod:`analytic`); 2 point-triangle distance and the brute force
(:mod:`triangle`); 3 the BVH, its closest-point walk and the narrow band (:mod:`bvh`,
:mod:`kernels`, :mod:`mesh_sdf`); 4 signs (:mod:`sign`); 5 bricks (:mod:`bricks`); 6 lookups
and instancing (:mod:`field`, :mod:`bricks`, :mod:`queries`); 7 gradients (:mod:`gradient`);
8 sphere tracing (:mod:`trace`); 9 soft shadows, AO, push-out (:mod:`shadow`).
"""

from .analytic import (
    op_difference,
    op_intersection,
    op_union,
    sd_box,
    sd_capsule,
    sd_plane,
    sd_sphere,
    sd_torus,
    smooth_union,
)
from .bricks import BRICK, EMPTY_INSIDE, EMPTY_OUTSIDE, BrickSDF, brick_sample, compress_bricks, encode_bricks
from .bvh import BVH, build_bvh, bvh_arrays, bvh_closest
from .field import SDFGrid, grid_points, outside_rule, trilinear
from .gradient import TETRA, gradient_central, gradient_tetra
from .mesh_sdf import SIGN_METHODS, grid_box, grid_sdf_values, sdf_grid, signed_distance
from .queries import instances_distance
from .scene import as_field, make_scene, scene_distance
from .shadow import ambient_occlusion, push_out, soft_shadow
from .sign import (
    VOTE_DIRECTIONS,
    pseudonormals,
    sign_normal,
    sign_pseudonormal,
    sign_vote,
    winding_number,
)
from .trace import camera_rays, render_sdf, sphere_trace
from .triangle import REGIONS, brute_force_distance, point_triangle_distance
from .truth import cone_directions, mesh_visibility, sphere_occluder_visibility

__all__ = [
    # Task 1
    "sd_sphere",
    "sd_box",
    "sd_plane",
    "sd_capsule",
    "sd_torus",
    "op_union",
    "op_intersection",
    "op_difference",
    "smooth_union",
    # Task 2
    "REGIONS",
    "point_triangle_distance",
    "brute_force_distance",
    # Task 3
    "BVH",
    "build_bvh",
    "bvh_arrays",
    "bvh_closest",
    "grid_sdf_values",
    # Task 4
    "VOTE_DIRECTIONS",
    "pseudonormals",
    "sign_normal",
    "sign_pseudonormal",
    "sign_vote",
    "winding_number",
    "SIGN_METHODS",
    "signed_distance",
    "sdf_grid",
    "grid_box",
    # Tasks 5 and 6
    "BRICK",
    "EMPTY_OUTSIDE",
    "EMPTY_INSIDE",
    "encode_bricks",
    "brick_sample",
    "BrickSDF",
    "compress_bricks",
    "SDFGrid",
    "grid_points",
    "outside_rule",
    "trilinear",
    "instances_distance",
    # Task 7
    "TETRA",
    "gradient_central",
    "gradient_tetra",
    # Task 8
    "sphere_trace",
    "camera_rays",
    "render_sdf",
    # Task 9
    "soft_shadow",
    "ambient_occlusion",
    "push_out",
    # given: fields as data, truths
    "as_field",
    "make_scene",
    "scene_distance",
    "cone_directions",
    "sphere_occluder_visibility",
    "mesh_visibility",
]
