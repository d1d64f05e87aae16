"""Lab "shadows": shadow mapping for directional, spot and point lights, with bias, culling, frustum handling and PCF."""

from .cubemap import (
    CUBE_DIRECTIONS,
    CUBE_FACES,
    CUBE_UPS,
    cube_depth_maps,
    cube_face_index,
    cube_light_matrices,
    point_shadow_visibility,
)
from .depth import CULL_MODES, cull_faces, depth_map
from .lights import directional_light_matrix, light_up_vector, spot_light_matrix
from .lookup import (
    DEFAULT_BIAS_TEXELS,
    DEFAULT_MAX_SLOPE,
    DEFAULT_SLOPE_BIAS,
    PCF_SAMPLINGS,
    compare_depth,
    light_uvz,
    outside_frustum,
    pcf_visibility,
    poisson_disk,
    poisson_pcf_visibility,
    receiver_depth_gradient,
    shadow_bias,
    shadow_visibility,
)
from .scene import CLASSIC_CAMERA, CLASSIC_LIGHT, Scene, as_scene, classic_scene, make_scene, torus_scene
from .shading import EyeBuffer, camera_matrix, eye_gbuffer, light_setup, light_visibility, render_with_shadows, shade
from .truth import pyrender_scene, pyrender_visibility, raycast_visibility, shadow_metrics, shadow_report

__all__ = [
    # Task 1: light matrices
    "light_up_vector",
    "directional_light_matrix",
    "spot_light_matrix",
    # Tasks 2 and 5: depth pass and culling
    "CULL_MODES",
    "cull_faces",
    "depth_map",
    # Tasks 3, 4, 6, 7: lookup, bias, frustum, PCF
    "DEFAULT_BIAS_TEXELS",
    "DEFAULT_SLOPE_BIAS",
    "DEFAULT_MAX_SLOPE",
    "light_uvz",
    "compare_depth",
    "receiver_depth_gradient",
    "shadow_bias",
    "outside_frustum",
    "pcf_visibility",
    "shadow_visibility",
    # given: Poisson-disk PCF (an option of shadow_visibility)
    "PCF_SAMPLINGS",
    "poisson_disk",
    "poisson_pcf_visibility",
    # Task 8: point lights
    "CUBE_FACES",
    "CUBE_DIRECTIONS",
    "CUBE_UPS",
    "cube_light_matrices",
    "cube_face_index",
    "cube_depth_maps",
    "point_shadow_visibility",
    # given: scenes, rendering, truth
    "Scene",
    "make_scene",
    "as_scene",
    "classic_scene",
    "torus_scene",
    "CLASSIC_CAMERA",
    "CLASSIC_LIGHT",
    "EyeBuffer",
    "camera_matrix",
    "eye_gbuffer",
    "light_setup",
    "light_visibility",
    "shade",
    "render_with_shadows",
    "raycast_visibility",
    "shadow_metrics",
    "shadow_report",
    "pyrender_scene",
    "pyrender_visibility",
]
