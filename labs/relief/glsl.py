"""Given: run the lab's GLSL shaders (``shaders/*.frag``, tasks 2-4) headless, with the NumPy functions' signatures.

``glsl_parallax_uv``, ``glsl_relief_uv`` and ``glsl_relief_shadow`` take the same arguments as
:func:`parallax_uv`, :func:`relief_uv` and :func:`relief_shadow` (on a grid of pixels: ``uv`` is
``(h, w, 2)``) and return the same values, computed by ``shaders/parallax.frag``,
``shaders/relief.frag`` and ``shaders/shadow.frag`` in single precision on the GPU (llvmpipe,
through :mod:`geomlib.gl`). The graders compare them with the NumPy reference outputs.

Every pixel is one fragment; its inputs (``uv``, ``view``, ``depth``, ``light``) arrive as float
textures read with ``texelFetch`` at the fragment's own pixel, so the shader sees the same values
as the NumPy code (rounded to float32).
"""

from __future__ import annotations

import numpy as np

from geomlib import gl

from .inputs import (
    check_bias,
    check_depths,
    check_directions,
    check_height,
    check_layers,
    check_march,
    check_scale,
    check_uv_points,
    check_view_ray,
)
from .relief import REFINEMENTS

__all__ = ["SHADERS", "shader_path", "glsl_parallax_uv", "glsl_relief_uv", "glsl_relief_shadow"]

#: The shader files of the lab, in task order.
SHADERS = ("parallax", "relief", "shadow")
#: The task each shader file is.
TASKS = {"parallax": "Task 2: parallax", "relief": "Task 3: march and refine", "shadow": "Task 4: shadow"}


#: ``shader_path("parallax")``: ``shaders/parallax.frag`` of this lab.
shader_path = gl.shader_finder(__file__)


def _run(name: str, size: tuple[int, int], textures: dict, uniforms: dict) -> np.ndarray:
    source = gl.lab_shader_source(shader_path(name))
    with gl.naming_task(f"shaders/{name}.frag", TASKS[name]):  # the message leads with the file and task
        return gl.render_quad(source, size, textures=textures, uniforms=uniforms, name=f"shaders/{name}.frag")


def glsl_parallax_uv(height, uv, view, *, scale: float, bias: float | None = None, offset_limit: bool = False):
    """:func:`parallax_uv` computed by ``shaders/parallax.frag``; ``uv`` is ``(h, w, 2)``."""
    where = "glsl_parallax_uv"
    H, uv, V, scale = check_view_ray(height, uv, view, scale, where, grid=True)
    bias = check_bias(bias, scale, where)
    out = _run(
        "parallax",
        (uv.shape[1], uv.shape[0]),
        {"height": H, "uv_in": uv, "view_in": V},
        {"scale": scale, "bias": bias, "offset_limit": int(bool(offset_limit))},
    )
    return out[..., :2].astype(np.float64)


def glsl_relief_uv(
    height,
    uv,
    view,
    *,
    scale: float,
    min_layers: int = 8,
    max_layers: int = 32,
    refine: str = "secant",
    refine_steps: int = 5,
):
    """:func:`relief_uv` computed by ``shaders/relief.frag``; ``uv`` is ``(h, w, 2)``."""
    where = "glsl_relief_uv"
    H, uv, V, scale = check_view_ray(height, uv, view, scale, where, grid=True)
    lo, hi, steps = check_march(min_layers, max_layers, refine, refine_steps, REFINEMENTS, where)
    out = _run(
        "relief",
        (uv.shape[1], uv.shape[0]),
        {"height": H, "uv_in": uv, "view_in": V},
        {
            "scale": scale,
            "min_layers": lo,
            "max_layers": hi,
            "refine": REFINEMENTS.index(refine),
            "refine_steps": steps,
        },
    )
    return out[..., :2].astype(np.float64), out[..., 2].astype(np.float64), np.rint(out[..., 3]).astype(np.int64)


def glsl_relief_shadow(height, uv, depth, light, *, scale: float, layers: int = 32):
    """:func:`relief_shadow` computed by ``shaders/shadow.frag``; ``uv`` is ``(h, w, 2)``."""
    where = "glsl_relief_shadow"
    H = check_height(height, where)
    uv = check_uv_points(uv, where, grid=True)
    D = check_depths(depth, uv.shape[:-1], where)
    L = check_directions(light, uv.shape[:-1], where, name="light")
    out = _run(
        "shadow",
        (uv.shape[1], uv.shape[0]),
        {"height": H, "uv_in": uv, "depth_in": D, "light_in": L},
        {"scale": check_scale(scale, where), "layers": check_layers(layers, "layers", where)},
    )
    return out[..., 0].astype(np.float64)
