"""Given: run the lab's GLSL shader ``shaders/denoise.vert`` (task 7) headless.

``glsl_denoise_with_map`` takes the arguments of :func:`denoise_with_map` and computes the same
positions in single precision on the GPU (llvmpipe, through :mod:`geomlib.gl`): every vertex is
drawn as one point, the vertex shader reads its offset from the map and moves it, and vertex ``i``
writes ``p'`` and ``s`` to pixel ``(i % width, i // width)`` of float render targets, read back here.
The seam fix stays on the CPU side: with ``weld`` the copies of a seam vertex (:func:`weld_seams`)
then move by the mean of their offsets ``s`` (read back from the shader) along their mean normal.
"""

from __future__ import annotations

import numpy as np

from geomlib import gl

from .inputs import checked_map_inputs, normalize_rows
from .seams import seam_mean, weld_seams

__all__ = ["SHADERS", "shader_path", "glsl_denoise_with_map"]

#: The shader files of the lab, in task order.
SHADERS = ("denoise.vert",)
#: The task each shader file is.
TASKS = {"denoise.vert": "Task 7: vertex denoising"}


#: ``shader_path("denoise.vert")``: ``shaders/denoise.vert`` of this lab.
shader_path = gl.shader_finder(__file__)


def _run_points(name: str, n: int, attributes: dict, textures: dict, uniforms: dict) -> list[np.ndarray]:
    source = gl.lab_shader_source(shader_path(name))
    with gl.naming_task(f"shaders/{name}", TASKS[name]):  # the message leads with the file and task
        return gl.render_per_vertex(
            source, gl.MOVED_OFFSET_FRAGMENT_SHADER, attributes, n, textures=textures, uniforms=uniforms, outputs=2,
            name=f"shaders/{name}",
        )  # fmt: skip


def glsl_denoise_with_map(
    V, F, UV, N, image, bias: float, scale: float, lam: float, *, weld: bool = True, wrap: str = "clamp"
) -> np.ndarray:
    """:func:`denoise_with_map` computed by ``shaders/denoise.vert``: ``p' = p - lam (bias + scale h(uv)) n``."""
    where = "glsl_denoise_with_map"
    V, F, UV, N, H, bias, scale, lam, weld = checked_map_inputs(V, F, UV, N, image, bias, scale, lam, weld, wrap, where)
    P, s = _run_points(
        "denoise.vert",
        len(V),
        {"position": V, "normal": N, "uv": UV},
        {"height": H},
        {"lam": lam, "bias": bias, "scale": scale, "repeat_wrap": int(wrap == "repeat")},
    )
    V_new = P[:, :3].astype(np.float64)
    if weld:  # the CPU's part: copies of a seam vertex move together
        _, _, group = weld_seams(V, F)
        seam = np.bincount(group)[group] > 1
        sm = seam_mean(s[:, 0].astype(np.float64), group)[group]
        Nm = normalize_rows(seam_mean(N, group))[group]
        V_new[seam] = V[seam] - lam * sm[seam, None] * Nm[seam]
    return V_new
