"""Lab "vdm": vector displacement map baking.

Pipeline: parameterize a disk-topology mesh onto the unit square (Task 1), sample it at uv points
(Task 2), bake the naive VDM (Task 3), score vertices by crease sharpness (Task 4), splat the
scores into an importance field (Task 5), move the grid samples by optimal transport toward
important regions (Task 6), snap them onto sharp features (Task 7) and choose per-quad diagonals
along sharp edges (Task 8). :func:`bake_vdm` runs all stages; :func:`vdm_to_mesh` rebuilds the
surface.
"""

from .diagonals import choose_diagonals, crossed_cells
from .features import align_to_features, grid_edges, sharp_features
from .grid import cell_areas, convex_cells, folded_cells, grid_faces, split_ok, uniform_grid, valid_diagonals
from .importance import area_density, edge_sharpness, importance_field, vertex_importance
from .parameterize import boundary_corners, boundary_to_square, check_disk, parameterize_square
from .sampling import barycentric_2d, locate_uv, sample_surface
from .shapes import grid_mesh, open_box, remove_bottom
from .transport import (
    bfm_half_step,
    bfm_potentials,
    inverse_neg_laplacian,
    legendre_transform,
    pushforward,
    soft_legendre_map,
    transport_grid,
)
from .vdm import VDM, bake_vdm, flat_grid, load_vdm, naive_vdm, save_vdm, vdm_to_mesh

__all__ = [
    "VDM",
    "align_to_features",
    "area_density",
    "bake_vdm",
    "barycentric_2d",
    "bfm_half_step",
    "bfm_potentials",
    "boundary_corners",
    "boundary_to_square",
    "cell_areas",
    "check_disk",
    "choose_diagonals",
    "crossed_cells",
    "edge_sharpness",
    "flat_grid",
    "folded_cells",
    "convex_cells",
    "split_ok",
    "valid_diagonals",
    "grid_edges",
    "grid_faces",
    "grid_mesh",
    "importance_field",
    "inverse_neg_laplacian",
    "legendre_transform",
    "load_vdm",
    "locate_uv",
    "naive_vdm",
    "open_box",
    "parameterize_square",
    "pushforward",
    "remove_bottom",
    "sample_surface",
    "save_vdm",
    "sharp_features",
    "soft_legendre_map",
    "transport_grid",
    "uniform_grid",
    "vdm_to_mesh",
    "vertex_importance",
]
