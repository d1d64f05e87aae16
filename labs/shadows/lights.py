"""Light-space matrices: where the shadow map looks from (Task 1).

A shadow map is a depth image taken *from the light*. Its camera is an ordinary OpenGL camera
(:mod:`geomlib.camera`), so the light-space matrix is ``M = P @ V`` (clip from world):

* a **directional** light (the sun) has parallel rays, so its projection is **orthographic**; the
  view looks along the light direction at the centre of the scene, and the orthographic box is fitted
  tightly around the scene's bounding box, so no texel is wasted on empty space;
* a **spot** light sits at a point and shines into a cone, so its projection is **perspective**.

Both use :func:`light_up_vector` as the camera's up direction (any vector not parallel to the view
direction would do; a fixed rule makes the maps reproducible).
"""

from __future__ import annotations

import numpy as np

from geomlib.camera import look_at, orthographic, perspective
from geomlib.validate import MeshError, as_array, check_float

__all__ = ["light_up_vector", "directional_light_matrix", "spot_light_matrix"]


def light_up_vector(direction) -> np.ndarray:
    """The coordinate axis most perpendicular to ``direction``, used as the light camera's up (given).

    Parameters
    ----------
    direction : (3,) array_like
        Viewing direction of the light camera (non-zero).

    Returns
    -------
    (3,) float64
        ``e_k`` with ``k = argmin_i |direction_i|`` (the first such axis on ties).
    """
    d = np.abs(np.asarray(direction, dtype=np.float64))
    up = np.zeros(3)
    up[int(np.argmin(d))] = 1.0
    return up


def _direction(direction, where: str) -> np.ndarray:
    d = as_array(direction, "direction", shape=(3,), where=where)
    n = np.linalg.norm(d)
    if not n > 0:
        raise MeshError(f"{where}: direction is the zero vector; it must be the way the light travels")
    return d / n


def _bounds(bounds, where: str) -> np.ndarray:
    B = as_array(bounds, "bounds", shape=(2, 3), where=where)
    if np.any(B[1] < B[0]):
        raise MeshError(
            f"{where}: bounds must be [min corner, max corner]; got min {tuple(B[0])} above max {tuple(B[1])}"
        )
    if not np.linalg.norm(B[1] - B[0]) > 0:
        raise MeshError(f"{where}: bounds is a single point {tuple(B[0])}; a shadow map needs a scene with extent")
    return B


def directional_light_matrix(direction, bounds) -> np.ndarray:
    """Light-space matrix ``M = P @ V`` of a directional light, fitted tightly around ``bounds``.

    Parameters
    ----------
    direction : (3,) array_like
        The way the light travels (need not be unit length), e.g. ``(0, 0, -1)`` shines straight down
        in a z-up world.
    bounds : (2, 3) array_like
        ``[min corner, max corner]`` of the scene (``np.array([V.min(0), V.max(0)])``).

    Returns
    -------
    M : (4, 4) float64
        Clip-from-world matrix. Every point of the box maps into the NDC cube ``[-1, 1]^3``, and the
        box touches all six faces of the cube (a tight fit).

    Notes
    -----
    With ``d = direction / |direction|``, ``c`` the centre of the box and ``R`` half its diagonal:

    1. ``V = look_at(c - R d, c, up)`` with ``up = light_up_vector(d)``: a camera on the bounding
       sphere, looking along ``d`` at the centre.
    2. Transform the 8 corners of the box by ``V`` (eye space; the camera looks down ``-z``):
       ``x`` spans ``[l, r]``, ``y`` spans ``[b, t]`` and ``z`` spans ``[z_min, z_max]``.
    3. ``P = orthographic(l, r, b, t, near=-z_max, far=-z_min)`` and ``M = P @ V``.

    Raises
    ------
    MeshError
        If ``direction`` is zero, ``bounds`` is not ``[min, max]``, or the box has no extent in one
        of the light's directions (e.g. a single plane seen exactly edge-on).
    """
    where = "directional_light_matrix"
    d = _direction(direction, where)
    B = _bounds(bounds, where)
    raise NotImplementedError('Task 1 (light matrix): V = look_at(c - R d, c, up); P = orthographic(l, r, b, t, -z_max, -z_min) from the 8 corners in eye space; M = P @ V')


def spot_light_matrix(position, target, fov_deg: float, near: float, far: float) -> np.ndarray:
    """Light-space matrix ``M = P @ V`` of a spot light at ``position`` aimed at ``target``.

    Parameters
    ----------
    position, target : (3,) array_like
        Where the light is and the point it aims at.
    fov_deg : float
        Full opening angle of the light's frustum in degrees (the shadow map is square), in (0, 180).
    near, far : float
        Distances of the near and far planes from the light, ``0 < near < far``.

    Returns
    -------
    M : (4, 4) float64
        ``perspective(fov_deg, 1, near, far) @ look_at(position, target, up)`` with
        ``up = light_up_vector(target - position)``.
    """
    where = "spot_light_matrix"
    pos = as_array(position, "position", shape=(3,), where=where)
    tgt = as_array(target, "target", shape=(3,), where=where)
    if np.array_equal(pos, tgt):
        raise MeshError(f"{where}: position and target coincide at {tuple(pos)}; the light has no direction")
    fov = check_float(fov_deg, "fov_deg", where=where)
    if not 0 < fov < 180:
        raise MeshError(f"{where}: fov_deg must be strictly between 0 and 180 degrees, got {fov}")
    near = check_float(near, "near", where=where)
    far = check_float(far, "far", where=where)
    if not 0 < near < far:
        raise MeshError(f"{where}: need 0 < near < far, got near={near}, far={far}")
    raise NotImplementedError('Task 1 (light matrix): M = perspective(fov, 1, near, far) @ look_at(position, target, up)')
