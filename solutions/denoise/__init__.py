"""Lab "denoise": Laplacian displacement denoising, directly and through a baked offset map.

Tasks, in order (each graded on its own):

1. :func:`laplacian_offsets` — ``delta_i = p_i - mean of neighbours`` (uniform, then cotan weights)
2. :func:`normal_offsets` — ``s_i = <delta_i, n_i>``
3. :func:`denoise_vertices` — ``p'_i = p_i - lam s_i n_i``
4. :func:`bake_offset_map` — rasterize ``s`` over UV space, normalise, pad, quantise
5. :func:`denoise_with_map` — the same step with ``s`` read from the map
6. :func:`weld_seams`, :func:`seam_mean` — the seam fix (independent of 1-5; may be done first)
7. ``shaders/denoise.vert`` (run by :func:`glsl_denoise_with_map`) — task 5's step in a GLSL vertex shader

Given: :func:`make_noisy`, :func:`surface_error`, :func:`error_stats`, :func:`quantisation_step`.
"""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import denoise, glsl, laplacian, noise, offsetmap, seams
from .denoise import *
from .glsl import *
from .laplacian import *
from .noise import *
from .offsetmap import *
from .seams import *

__all__ = [name for module in (laplacian, denoise, offsetmap, seams, noise, glsl) for name in module.__all__]
