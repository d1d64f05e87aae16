"""Given: run the lab's GLSL shaders (``shaders/tbn.vert``, ``normalmap.frag``, ``displace.vert``, tasks 7-9) headless.

``glsl_tbn``, ``glsl_shade`` and ``glsl_displace`` compute in single precision on the GPU (llvmpipe,
through :mod:`geomlib.gl`) what :func:`geomlib.tangent_space.surface_frames` (taken to world space),
:func:`shade` and :func:`displace` compute in NumPy; the graders compare them with the NumPy
reference outputs.

* The vertex shaders run once per vertex, drawn as points (:func:`geomlib.gl.render_points`): vertex
  ``i`` writes its results to pixel ``(i % width, i // width)`` of float render targets, which are
  read back (the per-vertex route: no rasterisation in between).
* ``normalmap.frag`` runs once per pixel of a G-buffer (:func:`rasterize_mesh`): the pixel's
  interpolated attributes arrive as float textures read with ``texelFetch``, so the shader sees the
  same values as the NumPy code (rounded to float32).
"""

from __future__ import annotations

import numpy as np

from geomlib import gl
from geomlib.validate import MeshError, as_array

from .displacement import checked_displace_inputs, group_mean
from .inputs import as_tangents, normalize_rows
from .shading import checked_shade_inputs

__all__ = ["SHADERS", "shader_path", "glsl_tbn", "glsl_shade", "glsl_displace"]

#: The shader files of the lab, in task order.
SHADERS = ("tbn.vert", "normalmap.frag", "displace.vert")
#: The task each shader file is.
TASKS = {
    "tbn.vert": "Task 7: vertex TBN",
    "normalmap.frag": "Task 8: fragment normal mapping",
    "displace.vert": "Task 9: vertex displacement",
}
#: The most lights ``normalmap.frag`` takes (its uniform arrays have this length).
MAX_LIGHTS = 4

#: Given fragment shaders of the per-vertex route: copy the vertex shader's flat outputs to the targets.
_POINTS_TBN = """#version 330 core
flat in vec3 T_world;
flat in vec3 B_world;
flat in vec3 N_world;
layout(location = 0) out vec4 out_T;
layout(location = 1) out vec4 out_B;
layout(location = 2) out vec4 out_N;
void main() { out_T = vec4(T_world, 1.0); out_B = vec4(B_world, 1.0); out_N = vec4(N_world, 1.0); }
"""


#: ``shader_path("tbn.vert")`` (or ``"tbn"``): ``shaders/tbn.vert`` of this lab.
shader_path = gl.shader_finder(__file__)


def _run_points(name: str, fragment: str, n: int, attributes: dict, textures: dict, uniforms: dict, outputs: int):
    """Run the vertex shader ``shaders/<name>`` on ``n`` vertices; ``outputs`` arrays ``(n, 4)``."""
    source = gl.lab_shader_source(shader_path(name))
    with gl.naming_task(f"shaders/{name}", TASKS[name]):  # the message leads with the file and task
        return gl.render_per_vertex(
            source,
            fragment,
            attributes,
            n,
            textures=textures,
            uniforms=uniforms,
            outputs=outputs,
            name=f"shaders/{name}",
        )


def _model(model, where: str) -> np.ndarray:
    M = np.eye(4) if model is None else as_array(model, "model", shape=(4, 4), where=where)
    if abs(np.linalg.det(M[:3, :3])) < 1e-12:
        raise MeshError(f"{where}: model's 3x3 part is singular (det = 0); normals cannot be transformed")
    return M


def glsl_tbn(N, tangents, model=None):
    """World-space frames ``T, B, N`` ``(n, 3)`` per vertex computed by ``shaders/tbn.vert``.

    With ``M`` the 3x3 part of ``model`` (identity by default)::

        N' = normalize(M^-T N),  T' = normalize(M T - (N' . M T) N'),  B' = sign(w) N' x T'

    which for ``model = None`` is :func:`geomlib.tangent_space.surface_frames` per vertex.
    """
    where = "glsl_tbn"
    N = as_array(N, "N", shape=(None, 3), where=where)
    T = as_tangents(tangents, len(N), where)
    M = _model(model, where)
    if not np.isfinite(N).all() or not np.isfinite(T).all():
        raise MeshError(f"{where}: N and tangents must be finite")
    out = _run_points(
        "tbn.vert", _POINTS_TBN, len(N), {"normal": N, "tangent": T}, {}, {"model": M.astype(np.float32)}, 3
    )
    return tuple(o[:, :3].astype(np.float64) for o in out)


def glsl_shade(
    gbuffer,
    lights,
    eye,
    albedo,
    normal_map=None,
    *,
    ambient: float = 0.1,
    specular: float = 0.3,
    shininess: float = 32.0,
    wrap: str = "clamp",
    background=(1.0, 1.0, 1.0),
) -> np.ndarray:
    """:func:`shade` computed by ``shaders/normalmap.frag`` (same arguments, same result)."""
    where = "glsl_shade"
    need, L, eye, ambient, specular, shininess, bg, tex, alb, nmap = checked_shade_inputs(
        gbuffer, lights, eye, albedo, normal_map, ambient, specular, shininess, wrap, background, where
    )
    if len(L) > MAX_LIGHTS:
        raise MeshError(f"{where}: at most {MAX_LIGHTS} lights (normalmap.frag's uniform arrays), got {len(L)}")
    mask = np.asarray(gbuffer.mask)
    h, w = mask.shape
    attrs = gbuffer.attributes

    def attr(key, k):
        a = np.asarray(attrs[key], dtype=np.float32).reshape(h, w, -1) if key in attrs else np.zeros((h, w, k))
        return a

    textures = {
        "position_in": attr("position", 3),
        "normal_in": attr("normal", 3),
        "uv_in": attr("uv", 2),
        "tangent_in": attr("tangent", 4),
        "normal_map": np.zeros((1, 1, 3)),
        "albedo_map": np.zeros((1, 1, 3)),
    }
    uniforms = {"use_normal_map": 0, "use_albedo_map": int(tex is not None), "albedo": np.zeros(3)}
    if nmap is not None:
        raw = np.asarray(normal_map)  # the shader decodes 2 rgb - 1 itself
        textures["normal_map"] = raw / 255.0 if raw.dtype == np.uint8 else (nmap + 1.0) / 2.0
        uniforms["use_normal_map"] = 1
    if tex is not None:
        textures["albedo_map"] = tex
    else:
        uniforms["albedo"] = alb
    uniforms.update(
        eye=eye,
        ambient=ambient,
        specular=specular,
        shininess=shininess,
        repeat_wrap=int(wrap == "repeat"),
        n_lights=len(L),
    )
    for i, (kind, vec, rgb) in enumerate(L):
        uniforms[f"light_kind[{i}]"] = int(kind == "point")
        uniforms[f"light_vec[{i}]"] = vec
        uniforms[f"light_rgb[{i}]"] = rgb
    source = gl.lab_shader_source(shader_path("normalmap.frag"))
    with gl.naming_task("shaders/normalmap.frag", TASKS["normalmap.frag"]):
        img = gl.render_quad(source, (w, h), textures=textures, uniforms=uniforms, name="shaders/normalmap.frag")
    out = np.empty((h, w, 3))
    out[...] = bg
    out[mask] = np.clip(img[..., :3][mask].astype(np.float64), 0.0, 1.0)
    return out


def glsl_displace(
    V, F, UV, N, height, lam: float = 1.0, bias: float = 0.0, scale: float = 1.0, *, weld_seams=True, wrap="clamp"
):
    """:func:`displace` computed by ``shaders/displace.vert`` (positions only).

    The vertex shader moves every vertex by its own map value; the seam fix stays on the CPU side:
    with ``weld_seams`` the copies of a seam vertex (:func:`geomlib.textures.weld_by_position`) are
    then moved by the mean of their offsets ``d`` (read back from the shader) along their mean normal.
    """
    V, F, UV, n, Hm, lam, bias, scale, group, k = checked_displace_inputs(
        V, F, UV, N, height, lam, bias, scale, weld_seams, wrap, "glsl_displace"
    )
    P, d = _run_points(
        "displace.vert",
        gl.MOVED_OFFSET_FRAGMENT_SHADER,
        len(V),
        {"position": V, "normal": n, "uv": UV},
        {"height": np.asarray(Hm, dtype=np.float64)},
        {"lam": lam, "bias": bias, "scale": scale, "repeat_wrap": int(wrap == "repeat")},
        2,
    )
    V_new = P[:, :3].astype(np.float64)
    if weld_seams and k < len(V):  # the CPU's part: copies of a seam vertex move together
        seam = np.bincount(group, minlength=k)[group] > 1
        dm = group_mean(d[:, :1].astype(np.float64), group, k)[group, 0]
        nm = normalize_rows(group_mean(n, group, k), fallback=(0.0, 0.0, 1.0))[group]
        V_new[seam] = V[seam] + lam * dm[seam, None] * nm[seam]
    return V_new
