"""The depth pass: render the scene's depth as seen from the light (Tasks 2 and 5).

The shadow map ``D`` is a square depth image from the light camera ``M``: ``D[row, col]`` is the
window depth ``(z_ndc + 1) / 2`` in ``[0, 1]`` of the surface closest to the light through the
centre of that texel, and ``1`` (the far plane, OpenGL's cleared depth) where nothing is.
Rows follow the rasterizer's image layout: **row 0 is the top** of the map, that is the largest
``y_ndc`` (``v = 1``).

*Culling* (Task 5) drops triangles before they are drawn. Culling the faces that face the light
("front") stores the *back* side of closed objects in the map: the lit front surfaces then sit a
whole object thickness in front of the stored depth and cannot shadow themselves, which removes
acne without a large bias.
"""

from __future__ import annotations

import numpy as np

from geomlib.raster import MAX_SIZE, rasterize
from geomlib.validate import as_array, check_choice, check_int, check_mesh

from .options import CULL_MODES

__all__ = ["CULL_MODES", "cull_faces", "depth_map"]


def cull_faces(V, F, M, cull: str = "front") -> np.ndarray:
    """The triangles that survive face culling from the camera ``M``.

    Parameters
    ----------
    V : (n, 3) array_like
        World positions.
    F : (m, 3) array_like of int
        Triangles.
    M : (4, 4) array_like
        Clip-from-world matrix of the light camera.
    cull : {"front", "back", "none"}
        Which faces to drop. A triangle is *front-facing* when its corners run counter-clockwise in
        NDC (OpenGL's ``glFrontFace(GL_CCW)``): for a closed, outward-oriented mesh these are the
        faces turned towards the camera.

    Returns
    -------
    F_kept : (k, 3) int64
        The rows of ``F`` that are kept, in their original order. Triangles with zero projected area
        (seen exactly edge-on) are kept: they draw nothing anyway.

    Notes
    -----
    Work with the clip coordinates ``(x, y, w)`` of the three corners (``[V, 1] @ M.T``). The twice
    signed area of the projected triangle in NDC is ``det([[x0, y0, w0], [x1, y1, w1], [x2, y2, w2]]) /
    (w0 w1 w2)``, so for triangles in front of the camera (all ``w > 0``)::

        front-facing  <=>  det([[x0, y0, w0], [x1, y1, w1], [x2, y2, w2]]) > 0

    The determinant form needs no division and stays meaningful when a triangle crosses the plane
    of a perspective light (``w = 0``), where NDC areas are not defined: it is the orientation of the
    triangle as seen from the light's position.
    """
    where = "cull_faces"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True, min_faces=0)
    M = as_array(M, "M", shape=(4, 4), where=where)
    check_choice(cull, "cull", CULL_MODES, where=where)
    if cull == "none":
        return F
    raise NotImplementedError('Task 5 (culling): det([x, y, w] of the 3 corners) > 0 <=> front-facing; keep det <= 0 for cull="front", det >= 0 for cull="back"')


def depth_map(V, F, M, size: int, cull: str = "front") -> np.ndarray:
    """Render the shadow map: depth of the closest surface seen from the light.

    Parameters
    ----------
    V : (n, 3) array_like
        World positions of the whole scene.
    F : (m, 3) array_like of int
        Its triangles.
    M : (4, 4) array_like
        Light-space matrix (clip from world), e.g. from :func:`directional_light_matrix`.
    size : int
        The map is ``size x size`` texels (1 .. 32768).
    cull : {"front", "back", "none"}
        Faces dropped before rasterizing (see :func:`cull_faces`).

    Returns
    -------
    D : (size, size) float64
        Window depth in ``[0, 1]`` of the nearest surface through each texel centre; ``1.0`` where
        no triangle covers the texel. Row 0 is the top of the map (``v = 1``).

    Notes
    -----
    Use :func:`geomlib.raster.rasterize` with ``depth_only=True`` (no barycentrics needed) and
    ``cull="none"`` (culling is done here, by :func:`cull_faces`). The rasterizer marks empty pixels
    with ``np.inf``; a depth buffer is cleared to the far plane, 1.
    """
    where = "depth_map"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    M = as_array(M, "M", shape=(4, 4), where=where)
    size = check_int(size, "size", minimum=1, maximum=MAX_SIZE, where=where)
    check_choice(cull, "cull", CULL_MODES, where=where)
    if cull != "none":
        F = cull_faces(V, F, M, cull)
    raise NotImplementedError('Task 2 (depth pass): D = rasterize(V, F, M, size, size, depth_only=True).depth, with empty texels set to 1')
