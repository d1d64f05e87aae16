"""Point lights: six shadow maps on the faces of a cube around the light (Task 8, extension).

A point light shines in every direction, which no single perspective frustum covers. Six
90-degree frusta looking along ``+x, -x, +y, -y, +z, -z`` do: together they tile the whole sphere of
directions, like the faces of a cube centred on the light (OpenGL's cube-map textures). A point
``P`` is looked up in the face its direction ``P - light`` points to most: the axis with the largest
absolute coordinate, and its sign.
"""

from __future__ import annotations

import numpy as np

from geomlib.camera import look_at, perspective
from geomlib.raster import MAX_SIZE
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int, check_mesh

from .depth import CULL_MODES, depth_map
from .lookup import DEFAULT_MAX_SLOPE, shadow_visibility
from .options import ShadowOptions, keyword_defaults

__all__ = [
    "CUBE_FACES",
    "CUBE_DIRECTIONS",
    "CUBE_UPS",
    "cube_light_matrices",
    "cube_face_index",
    "cube_depth_maps",
    "point_shadow_visibility",
]

#: Face order of the cube map (as OpenGL's ``GL_TEXTURE_CUBE_MAP_POSITIVE_X + i``).
CUBE_FACES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: Viewing direction of each face's camera.
CUBE_DIRECTIONS = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
#: Up vector of each face's camera (OpenGL's cube-map convention).
CUBE_UPS = np.array([[0.0, -1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [0, -1, 0], [0, -1, 0]])


def _near_far(near, far, where: str) -> tuple[float, float]:
    near = check_float(near, "near", where=where)
    far = check_float(far, "far", where=where)
    if not 0 < near < far:
        raise MeshError(f"{where}: need 0 < near < far, got near={near}, far={far}")
    return near, far


def cube_light_matrices(position, near: float, far: float) -> np.ndarray:
    """Light-space matrices of the six cube faces around a point light.

    Parameters
    ----------
    position : (3,) array_like
        The light.
    near, far : float
        Distances of the near and far planes, ``0 < near < far``.

    Returns
    -------
    Ms : (6, 4, 4) float64
        ``Ms[i] = perspective(90, 1, near, far) @ look_at(position, position + CUBE_DIRECTIONS[i], CUBE_UPS[i])``
        in the order of :data:`CUBE_FACES`.
    """
    where = "cube_light_matrices"
    pos = as_array(position, "position", shape=(3,), where=where)
    near, far = _near_far(near, far, where)
    raise NotImplementedError('Task 8 (cube map): Ms[i] = perspective(90, 1, near, far) @ look_at(position, position + dir_i, up_i)')


def cube_face_index(directions) -> np.ndarray:
    """Which cube face each direction (from the light) falls in.

    Parameters
    ----------
    directions : (n, 3) array_like
        ``P - position`` for points ``P``.

    Returns
    -------
    face : (n,) int64
        Index into :data:`CUBE_FACES`: ``2 a + (d_a < 0)`` with ``a = argmax_i |d_i|`` (the first axis on
        ties). A zero direction gives face 0.
    """
    where = "cube_face_index"
    d = as_array(directions, "directions", shape=(None, 3), where=where)
    raise NotImplementedError('Task 8 (cube map): a = argmax |d_i|; face = 2 a + (d_a < 0)')


def cube_depth_maps(V, F, position, size: int, near: float, far: float, cull: str = "front") -> np.ndarray:
    """The six shadow maps of a point light (given: :func:`depth_map` through each face's matrix).

    Returns
    -------
    maps : (6, size, size) float64
        ``maps[i] = depth_map(V, F, cube_light_matrices(position, near, far)[i], size, cull)``.
    """
    where = "cube_depth_maps"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    size = check_int(size, "size", minimum=1, maximum=MAX_SIZE, where=where)
    check_choice(cull, "cull", CULL_MODES, where=where)
    Ms = cube_light_matrices(position, near, far)
    return np.stack([depth_map(V, F, M, size, cull) for M in Ms])


def point_shadow_visibility(
    P,
    N,
    maps,
    position,
    near: float,
    far: float,
    bias: float | None = None,
    slope_bias: float | None = None,
    pcf: int = 1,
    *,
    max_slope: float = DEFAULT_MAX_SLOPE,
    pcf_sampling: str = "grid",
    pcf_samples: int = 16,
    options: ShadowOptions | None = None,
) -> np.ndarray:
    """Visibility of a point light through its cube of shadow maps.

    Parameters
    ----------
    P, N : (n, 3) array_like
        Surface points and their geometric normals.
    maps : (6, size, size) array_like
        From :func:`cube_depth_maps` with the same ``position``, ``near``, ``far``.
    position : (3,) array_like
        The light.
    near, far : float
        As for the maps.
    bias, slope_bias, pcf, max_slope, pcf_sampling, pcf_samples
        As in :func:`shadow_visibility`, passed on to it (PCF does not cross cube faces: it reads the
        face's border).
    options : ShadowOptions, optional
        All of them at once, checked when made (then leave the keywords at their defaults).

    Returns
    -------
    visibility : (n,) float64 in [0, 1]
        For each point, :func:`shadow_visibility` in the face ``cube_face_index(P - position)``.
    """
    where = "point_shadow_visibility"
    P = as_array(P, "P", shape=(None, 3), where=where)
    N = as_array(N, "N", shape=(None, 3), where=where)
    if len(N) != len(P):
        raise MeshError(f"{where}: N has {len(N)} rows but P has {len(P)}; expected one normal per point")
    maps = as_array(maps, "maps", where=where)
    if maps.ndim != 3 or maps.shape[0] != 6 or maps.shape[1] != maps.shape[2] or maps.shape[1] == 0:
        raise MeshError(f"{where}: maps has shape {maps.shape}, expected (6, size, size): one map per cube face")
    pos = as_array(position, "position", shape=(3,), where=where)
    near, far = _near_far(near, far, where)
    keywords = dict(
        bias=bias, slope_bias=slope_bias, pcf=pcf, max_slope=max_slope, pcf_sampling=pcf_sampling,
        pcf_samples=pcf_samples,
    )  # fmt: skip
    opts = ShadowOptions.of(options, where, keywords, _POINT_DEFAULTS)
    raise NotImplementedError("Task 8 (cube map): face = cube_face_index(P - position); shadow_visibility with maps[face], Ms[face] for each face's points (options=opts passes the other options on)")


_POINT_DEFAULTS = keyword_defaults(point_shadow_visibility)
