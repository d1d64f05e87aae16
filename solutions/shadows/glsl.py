"""Given: run the lab's GLSL shaders (``shaders/depth.vert`` + ``depth.frag``, ``shadow.frag``; tasks 9-10) headless.

``glsl_depth_map`` and ``glsl_shadow_visibility`` take the arguments of :func:`depth_map` and
:func:`shadow_visibility` and compute the same results in single precision on the GPU (llvmpipe,
through :mod:`geomlib.gl`); the graders compare them with the NumPy reference outputs.

* The light pass draws the scene's triangles (:func:`geomlib.gl.render_mesh`, depth-tested) through
  ``depth.vert`` (``gl_Position = lightSpaceMatrix (P, 1)``) and ``depth.frag`` (culling by
  ``gl_FrontFacing``, the window depth ``gl_FragCoord.z`` written to a float target), read back as
  the ``(size, size)`` map with row 0 at the top; texels nothing covers hold 1.0, the far plane.
* ``shadow.frag`` runs once per surface point: the points are laid out row by row on the pixels of
  an image, their positions and normals arrive as float textures read with ``texelFetch``, and the
  map is a float texture read texel by texel (the comparison is done in the shader, as the NumPy
  code does it, not by a ``sampler2DShadow``).
"""

from __future__ import annotations

import numpy as np

from geomlib import gl
from geomlib.raster import MAX_SIZE
from geomlib.validate import MeshError, as_array, check_choice, check_int, check_mesh

from .lookup import (
    _SHADOW_VISIBILITY_DEFAULTS,
    DEFAULT_BIAS_TEXELS,
    DEFAULT_MAX_SLOPE,
    DEFAULT_SLOPE_BIAS,
    _texel_angle,
    check_shadow_map,
    poisson_disk,
)
from .options import CULL_MODES, ShadowOptions

__all__ = ["SHADERS", "shader_path", "glsl_depth_map", "glsl_shadow_visibility"]

#: The shader files of the lab, in task order.
SHADERS = ("depth.vert", "depth.frag", "shadow.frag")
#: The task each shader file is.
TASKS = {
    "depth.vert": "Task 9: light pass",
    "depth.frag": "Task 9: light pass",
    "shadow.frag": "Task 10: fragment shadow test",
}
#: The most Poisson-disk samples ``shadow.frag`` takes (its ``disk`` uniform array has this length).
MAX_DISK_SAMPLES = 64
_CULL_CODE = {"none": 0, "front": 1, "back": 2}


#: ``shader_path("depth.vert")`` (or ``"shadow"``): ``shaders/<name>`` of this lab.
shader_path = gl.shader_finder(__file__)


def _source(name: str) -> str:
    return gl.lab_shader_source(shader_path(name))


def _renamed(e: gl.ShaderError, fragment: str, vertex: str | None = None) -> gl.ShaderError:
    """The harness's error with the task after the file name (and the vertex shader's own file name)."""
    msg = str(e)
    if vertex is not None and f"shaders/{fragment} (vertex shader)" in msg:
        msg = msg.replace(
            f"shaders/{fragment} (vertex shader)", f"shaders/{vertex} ({TASKS[vertex]}) (vertex shader)", 1
        )
    else:
        msg = msg.replace(f"shaders/{fragment}", f"shaders/{fragment} ({TASKS[fragment]})", 1)
    return gl.ShaderError(msg, log=e.log, lines=e.lines)


def glsl_depth_map(V, F, M, size: int, cull: str = "front") -> np.ndarray:
    """:func:`depth_map` computed by ``shaders/depth.vert`` and ``shaders/depth.frag`` (same arguments, same result).

    The GPU rasterizes as :func:`geomlib.raster.rasterize` does (texel centres, the nearest surface
    kept by the depth test), in single precision; culling happens in ``depth.frag`` by
    ``gl_FrontFacing``, which is the NumPy route's counter-clockwise test in NDC.
    """
    where = "glsl_depth_map"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    M = as_array(M, "M", shape=(4, 4), where=where)
    size = check_int(size, "size", minimum=1, maximum=min(MAX_SIZE, 8192), where=where)
    check_choice(cull, "cull", CULL_MODES, where=where)
    vertex, fragment = _source("depth.vert"), _source("depth.frag")
    try:
        out = gl.render_mesh(
            vertex,
            fragment,
            F,
            {"position": V},
            (size, size),
            uniforms={"lightSpaceMatrix": M, "cull": _CULL_CODE[cull]},
            name="shaders/depth.frag",
        )
    except gl.ShaderError as e:
        raise _renamed(e, "depth.frag", "depth.vert") from None
    return np.where(out[..., 1] > 0, out[..., 0].astype(np.float64), 1.0)


def _on_grid(a: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    w, h = size
    out = np.zeros((w * h, 3))
    out[: len(a)] = a
    return out.reshape(h, w, 3)


def _rotation_texture(size: int) -> np.ndarray:
    """Angles of texels ``(floor(x), floor(y))`` for ``x, y`` in ``-1 .. size`` (GL texel ``(x + 1, y + 1)``)."""
    t = np.arange(-1, size + 1)
    fy, fx = np.meshgrid(t, t, indexing="ij")  # image row j holds floor(y) = j - 1 before the flip
    angles = _texel_angle(fy.ravel(), fx.ravel()).reshape(fy.shape)
    return angles[::-1]  # the harness uploads row 0 as the top (GL's last row)


def glsl_shadow_visibility(
    P,
    N,
    D,
    M,
    bias: float | None = None,
    slope_bias: float | None = None,
    pcf: int = 1,
    *,
    frustum_fix: bool = True,
    max_slope: float = DEFAULT_MAX_SLOPE,
    pcf_sampling: str = "grid",
    pcf_samples: int = 16,
    options: ShadowOptions | None = None,
) -> np.ndarray:
    """:func:`shadow_visibility` computed by ``shaders/shadow.frag`` (same arguments, same result).

    At most :data:`MAX_DISK_SAMPLES` Poisson-disk samples (the shader's uniform array).
    """
    where = "glsl_shadow_visibility"
    P = as_array(P, "P", shape=(None, 3), where=where)
    N = as_array(N, "N", shape=(None, 3), where=where)
    if len(N) != len(P):
        raise MeshError(f"{where}: N has {len(N)} rows but P has {len(P)}; expected one normal per point")
    if len(P) == 0:
        return np.ones(0)
    D = check_shadow_map(D, where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise MeshError(f"{where}: M is singular; a light-space matrix must be invertible") from None
    size = D.shape[0]
    if size > 8192:
        raise MeshError(f"{where}: D is {size} x {size}; the GPU route takes maps up to 8192 texels a side")
    keywords = dict(
        bias=bias, slope_bias=slope_bias, pcf=pcf, frustum_fix=frustum_fix, max_slope=max_slope,
        pcf_sampling=pcf_sampling, pcf_samples=pcf_samples,
    )  # fmt: skip
    opts = ShadowOptions.of(options, where, keywords, _SHADOW_VISIBILITY_DEFAULTS)
    if opts.pcf_sampling == "poisson" and opts.pcf_samples > MAX_DISK_SAMPLES:
        raise MeshError(f"{where}: at most {MAX_DISK_SAMPLES} Poisson samples (shadow.frag's disk array)")
    grid = gl.point_grid(len(P))
    poisson = opts.pcf_sampling == "poisson" and opts.pcf > 1
    uniforms = {
        "lightSpaceMatrix": M,
        "lightInverse": Minv,
        "bias": DEFAULT_BIAS_TEXELS / size if opts.bias is None else opts.bias,
        "slope_bias": DEFAULT_SLOPE_BIAS if opts.slope_bias is None else opts.slope_bias,
        "max_slope": opts.max_slope,
        "pcf": opts.pcf,
        "poisson": int(poisson),
        "n_disk": opts.pcf_samples if poisson else 0,
        "frustum_fix": int(opts.frustum_fix),
    }
    if poisson:
        for i, (dx, dy) in enumerate(poisson_disk(opts.pcf_samples) * (opts.pcf / 2)):
            uniforms[f"disk[{i}]"] = np.array([dx, dy])
    textures = {
        "position_in": _on_grid(P, grid),
        "normal_in": _on_grid(N, grid),
        "shadow_map": D,
        "rotation": _rotation_texture(size) if poisson else np.zeros((1, 1)),
    }
    source = _source("shadow.frag")
    try:
        img = gl.render_quad(source, grid, textures=textures, uniforms=uniforms, name="shaders/shadow.frag")
    except gl.ShaderError as e:
        raise _renamed(e, "shadow.frag") from None
    return img[..., 0].reshape(-1)[: len(P)].astype(np.float64)
