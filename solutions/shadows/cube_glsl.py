"""Given: a point light's cube map in linear depth, in NumPy and in GLSL (tasks 11-12, the shaders).

The lecture's point-light shadows store, on each cube face, the *linear* depth of the nearest surface,
its distance to the light over ``far``, instead of the window depth Task 8 stores: it is the same
number on all six faces, has the same precision near and far, and the lookup needs no matrix, only the
direction from the light. This module gives both routes:

* NumPy (the references the shaders are graded against): :func:`cube_linear_depth` turns Task 8's
  window-depth maps into linear ones texel by texel, :func:`cube_distance_maps` is the linear cube
  pass, :func:`linear_point_shadow_visibility` the lookup (Task 8's face choice, Task 3's texel and
  comparison on the linear depths, Task 7's PCF).
* GLSL: :func:`glsl_cube_depth_maps` runs ``shaders/cube_depth.vert`` + ``cube_depth.frag`` (Task 11)
  once per face; :func:`glsl_point_shadow_visibility` runs ``shaders/cube_shadow.frag`` (Task 12) once
  per surface point.

The faces reach ``cube_shadow.frag`` as one 2D texture, the six maps side by side (a ``size x 6 size``
atlas), not as a ``samplerCube``: the course's harness (:mod:`geomlib.gl`) binds 2D float textures
only, and six ``sampler2D`` uniforms would not do either, since GLSL 3.30 indexes an array of samplers
only with a constant and the face changes from fragment to fragment. So the shader does what a
``samplerCube`` does in hardware, OpenGL's face selection and ``(s, t)`` table, itself.
"""

from __future__ import annotations

import numpy as np

from geomlib import gl
from geomlib.raster import MAX_SIZE
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int, check_mesh

from .cubemap import _near_far, cube_depth_maps, cube_face_index, cube_light_matrices
from .glsl import _on_grid
from .lookup import DEFAULT_BIAS_TEXELS, compare_depth, light_uvz, pcf_visibility
from .options import CULL_MODES

__all__ = [
    "CUBE_SHADERS",
    "cube_linear_depth",
    "cube_distance_maps",
    "linear_point_shadow_visibility",
    "glsl_cube_depth_maps",
    "glsl_point_shadow_visibility",
]

#: The shader files of tasks 11-12, in task order.
CUBE_SHADERS = ("cube_depth.vert", "cube_depth.frag", "cube_shadow.frag")
_TASKS = {
    "cube_depth.vert": "Task 11: cube light pass",
    "cube_depth.frag": "Task 11: cube light pass",
    "cube_shadow.frag": "Task 12: cube shadow lookup",
}
_CULL_CODE = {"none": 0, "front": 1, "back": 2}
_shader_path = gl.shader_finder(__file__)


def _named(e: gl.ShaderError, fragment: str, vertex: str | None = None) -> gl.ShaderError:
    """The harness's error with the task after the file name (and the vertex shader's own file name)."""
    msg, label = str(e), f"shaders/{fragment}"
    if vertex is not None and f"{label} (vertex shader)" in msg:
        msg = msg.replace(f"{label} (vertex shader)", f"shaders/{vertex} ({_TASKS[vertex]}) (vertex shader)", 1)
    else:
        msg = msg.replace(label, f"{label} ({_TASKS[fragment]})", 1)
    return gl.ShaderError(msg, log=e.log, lines=e.lines)


def _texel_rays(size: int) -> np.ndarray:
    """``sqrt(1 + x² + y²)`` at the NDC centre ``(x, y)`` of every texel of a 90-degree face (row 0 at the top):
    the distance to the far plane along the texel's ray, over ``far``."""
    c = (2.0 * np.arange(size) + 1.0) / size - 1.0
    return np.sqrt(1.0 + c[None, :] ** 2 + c[::-1, None] ** 2)


def _check_cube(maps, where: str) -> np.ndarray:
    maps = as_array(maps, "maps", where=where)
    if maps.ndim != 3 or maps.shape[0] != 6 or maps.shape[1] != maps.shape[2] or maps.shape[1] == 0:
        raise MeshError(f"{where}: maps has shape {maps.shape}, expected (6, size, size): one map per cube face")
    if maps.shape[1] > min(MAX_SIZE, 8192 // 6):
        raise MeshError(f"{where}: maps are {maps.shape[1]} texels a side; at most {min(MAX_SIZE, 8192 // 6)}")
    return maps


def cube_linear_depth(maps, near: float, far: float) -> np.ndarray:
    """Window-depth cube maps (:func:`cube_depth_maps`) as linear depth: distance to the light over ``far``.

    Parameters
    ----------
    maps : (6, size, size) array_like
        Window depths in ``[0, 1]`` of the six faces (row 0 at the top), 1.0 where nothing was drawn.
    near, far : float
        The faces' near and far distances.

    Returns
    -------
    (6, size, size) float64
        ``|X - light| / far`` for the surface point ``X`` each texel stores. Texel ``(row, col)`` looks
        along NDC ``(x, y) = ((2 col + 1) / size - 1, 1 - (2 row + 1) / size)``; its window depth ``z_w``
        is at eye depth ``t = 2 near far / (far + near - (2 z_w - 1)(far - near))``, and a 90-degree face
        has ``X`` at ``t (x, y, -1)`` in the face's eye space, so the distance is ``t sqrt(1 + x² + y²)``.
        Empty texels (``z_w = 1``) give the far plane along the texel's ray, ``sqrt(1 + x² + y²)``.
    """
    where = "cube_linear_depth"
    maps = _check_cube(maps, where)
    near, far = _near_far(near, far, where)
    z_ndc = 2.0 * maps - 1.0
    t = 2.0 * near * far / ((far + near) - z_ndc * (far - near))
    return t * _texel_rays(maps.shape[1]) / far


def cube_distance_maps(V, F, position, size: int, near: float, far: float, cull: str = "front") -> np.ndarray:
    """The six linear-depth maps of a point light: :func:`cube_linear_depth` of :func:`cube_depth_maps`.

    Returns
    -------
    (6, size, size) float64
        Distance to the light over ``far`` of the nearest surface in every texel of every face (same
        arguments as :func:`cube_depth_maps`).
    """
    return cube_linear_depth(cube_depth_maps(V, F, position, size, near, far, cull), near, far)


def _linear_bias(bias, slope_bias, size: int, where: str) -> float:
    if slope_bias not in (None, 0, 0.0):
        raise MeshError(
            f"{where}: slope_bias={slope_bias!r}; the linear-depth cube map takes a constant bias only (linear depth "
            f"is not affine across a texel, so Task 4's receiver plane does not give its slope): leave it None or 0"
        )
    return DEFAULT_BIAS_TEXELS / size if bias is None else check_float(bias, "bias", minimum=0.0, where=where)


def _pcf(pcf, where: str) -> int:
    k = check_int(pcf, "pcf", minimum=1, maximum=15, where=where)
    if k % 2 == 0:
        raise MeshError(f"{where}: pcf must be odd (a k x k block centred on the texel), got {k}")
    return k


def _points(P, N, where: str) -> tuple[np.ndarray, np.ndarray]:
    P = as_array(P, "P", shape=(None, 3), where=where)
    N = as_array(N, "N", shape=(None, 3), where=where)
    if len(N) != len(P):
        raise MeshError(f"{where}: N has {len(N)} rows but P has {len(P)}; expected one normal per point")
    return P, N


def linear_point_shadow_visibility(
    P, N, maps, position, near: float, far: float, bias: float | None = None, slope_bias: float | None = None,
    pcf: int = 1,
) -> np.ndarray:  # fmt: skip
    """Visibility of a point light through its linear-depth cube map (the NumPy twin of ``cube_shadow.frag``).

    Parameters
    ----------
    P, N : (n, 3) array_like
        Surface points and their normals (``N`` is checked, not used: the bias is constant).
    maps : (6, size, size) array_like
        Linear depths from :func:`cube_distance_maps` (or ``glsl_cube_depth_maps``), same light.
    position : (3,) array_like
    near, far : float
    bias : float, optional
        Constant bias in units of ``far`` (the maps' units); default ``DEFAULT_BIAS_TEXELS / size``.
    slope_bias : None or 0
        Only for the same arguments as :func:`point_shadow_visibility`: linear depth takes no slope bias.
    pcf : int
        Odd PCF block size, read within the point's face (clamped to its border).

    Returns
    -------
    visibility : (n,) float64 in [0, 1]
        For each point, in the face ``cube_face_index(P - position)``: lit beyond the far plane;
        otherwise :func:`compare_depth` (``pcf = 1``) or :func:`pcf_visibility` of the face's map with the
        point's texel from :func:`light_uvz` through the face's matrix and its depth ``|P - position| / far``.
        The light's own position (no direction) is lit.
    """
    where = "linear_point_shadow_visibility"
    P, N = _points(P, N, where)
    maps = _check_cube(maps, where)
    pos = as_array(position, "position", shape=(3,), where=where)
    near, far = _near_far(near, far, where)
    b = _linear_bias(bias, slope_bias, maps.shape[1], where)
    k = _pcf(pcf, where)
    Ms = cube_light_matrices(pos, near, far)
    d = P - pos
    face = cube_face_index(d)
    vis = np.ones(len(P))
    for f in range(6):  # six faces, each vectorised over its points
        sel = np.flatnonzero((face == f) & d.any(axis=1))
        if len(sel) == 0:
            continue
        uvz = light_uvz(P[sel], Ms[f])
        inside = uvz[:, 2] <= 1.0  # beyond the far plane: lit (u, v are inside by the face's choice)
        uvz[:, 2] = np.linalg.norm(d[sel], axis=1) / far
        sel, uvz = sel[inside], uvz[inside]
        if len(sel):
            vis[sel] = compare_depth(maps[f], uvz, b) if k == 1 else pcf_visibility(maps[f], uvz, b, k)
    return vis


def glsl_cube_depth_maps(
    V, F, position, size: int, near: float, far: float, cull: str = "front", *, matrices=None
) -> np.ndarray:
    """:func:`cube_distance_maps` computed by ``shaders/cube_depth.vert`` and ``cube_depth.frag``, one draw per face.

    Parameters
    ----------
    V, F, position, size, near, far, cull
        As for :func:`cube_depth_maps`.
    matrices : (6, 4, 4) array_like, optional
        The faces' light-space matrices; default ``cube_light_matrices(position, near, far)`` (Task 8).

    Returns
    -------
    (6, size, size) float64
        What ``cube_depth.frag`` wrote (``|X - light| / far``) where a face was drawn; elsewhere the far
        plane along the texel's ray, as :func:`cube_linear_depth` gives empty texels.
    """
    where = "glsl_cube_depth_maps"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    pos = as_array(position, "position", shape=(3,), where=where)
    size = check_int(size, "size", minimum=1, maximum=min(MAX_SIZE, 8192), where=where)
    near, far = _near_far(near, far, where)
    check_choice(cull, "cull", CULL_MODES, where=where)
    Ms = cube_light_matrices(pos, near, far) if matrices is None else as_array(matrices, "matrices", where=where)
    if Ms.shape != (6, 4, 4):
        raise MeshError(f"{where}: matrices has shape {Ms.shape}, expected (6, 4, 4): one per cube face")
    vertex = gl.lab_shader_source(_shader_path("cube_depth.vert"))
    fragment = gl.lab_shader_source(_shader_path("cube_depth.frag"))
    empty = _texel_rays(size)
    out = np.empty((6, size, size))
    for i in range(6):
        uniforms = {"lightSpaceMatrix": Ms[i], "lightPos": pos, "far": far, "cull": _CULL_CODE[cull]}
        try:
            img = gl.render_mesh(vertex, fragment, F, {"position": V}, (size, size), uniforms=uniforms,
                                 name="shaders/cube_depth.frag")  # fmt: skip
        except gl.ShaderError as e:
            raise _named(e, "cube_depth.frag", "cube_depth.vert") from None
        out[i] = np.where(img[..., 1] > 0, img[..., 0].astype(np.float64), empty)
    return out


def glsl_point_shadow_visibility(
    P, N, maps, position, near: float, far: float, bias: float | None = None, slope_bias: float | None = None,
    pcf: int = 1,
) -> np.ndarray:  # fmt: skip
    """:func:`linear_point_shadow_visibility` computed by ``shaders/cube_shadow.frag`` (same arguments, same result).

    The points are laid out row by row on the pixels of an image and read with ``texelFetch``; the
    six maps are one ``size x 6 size`` float texture (see the module's notes).
    """
    where = "glsl_point_shadow_visibility"
    P, N = _points(P, N, where)
    maps = _check_cube(maps, where)
    bad = ~np.isfinite(maps)
    if bad.any():
        f, r, c = (int(i) for i in np.argwhere(bad)[0])
        raise MeshError(f"{where}: maps[{f}, {r}, {c}] is {maps[f, r, c]}; a cube map's depths must be finite")
    pos = as_array(position, "position", shape=(3,), where=where)
    near, far = _near_far(near, far, where)
    b = _linear_bias(bias, slope_bias, maps.shape[1], where)
    k = _pcf(pcf, where)
    if len(P) == 0:
        return np.ones(0)
    grid = gl.point_grid(len(P))
    uniforms = {"lightPos": pos, "far": far, "bias": b, "pcf": k}
    textures = {"position_in": _on_grid(P, grid), "cube_maps": np.concatenate(list(maps), axis=1)}
    source = gl.lab_shader_source(_shader_path("cube_shadow.frag"))
    try:
        img = gl.render_quad(source, grid, textures=textures, uniforms=uniforms, name="shaders/cube_shadow.frag")
    except gl.ShaderError as e:
        raise _named(e, "cube_shadow.frag") from None
    return img[..., 0].reshape(-1)[: len(P)].astype(np.float64)
