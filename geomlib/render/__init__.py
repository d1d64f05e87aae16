"""Headless rendering of triangle and polygon meshes for figures, with pyrender on OSMesa or Mesa EGL.

:func:`render` draws a triangle mesh ``(V, F)`` and returns an ``(h, w, 3)`` uint8 image;
:func:`render_polygons` does the same for polygon meshes (quads of Catmull-Clark, ...), drawing
the true polygon edges as wireframe. Both support per-vertex or per-face colours, textures,
smooth or flat shading, unlit colours, a depth-tested wireframe overlay, highlighted vertices,
directional and spot lights, and shadows.

Every option is a field of :class:`RenderOptions` (one object, documented once); pass one, or the
same names as keywords. Rendering is deterministic: the same call gives the same bytes. Cameras
come from the preset views of :data:`geomlib.camera.VIEWS` (the table the rasterizer labs use)
that frame the mesh, from an ``(eye, target, up)`` triple (:func:`geomlib.camera.look_at`), or from
a 4x4 camera-to-world pose (OpenGL convention: the camera looks down its local -z axis, +y is up
in the image; :func:`geomlib.camera.pose_from_view` turns a view matrix into one).

Modules, one concern each: :mod:`.options` (the options object and its checks), :mod:`.cameras`,
:mod:`.scene` (normalised frame, surface, floor), :mod:`.lights`, :mod:`.shading` (normals),
:mod:`.overlay` (wireframe and dots), :mod:`.context` (headless GL platform, pyrender import,
context cache) and :mod:`.draw` (the entry points and the pipeline).

Importing this module does not import pyrender or OpenGL; the first render does (a few seconds),
after choosing a headless platform (see :func:`backend`). One OpenGL context is created per image
size and reused for every later render.

Examples
--------
>>> import numpy as np
>>> from geomlib.render import render
>>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> img = render(V, F, wireframe=True, size=(320, 240))  # doctest: +SKIP
>>> img.shape, img.dtype  # doctest: +SKIP
((240, 320, 3), dtype('uint8'))
"""

from __future__ import annotations

from geomlib.camera import VIEWS
from geomlib.render.cameras import camera_pose
from geomlib.render.context import backend, close, import_pyrender, offscreen_renderer
from geomlib.render.draw import render, render_polygons
from geomlib.render.options import DEFAULT_BASE_COLOR, DEFAULT_WIRE_COLOR, RenderOptions
from geomlib.render.overlay import auto_wire_opacity

__all__ = [
    "VIEWS",
    "DEFAULT_BASE_COLOR",
    "DEFAULT_WIRE_COLOR",
    "RenderOptions",
    "auto_wire_opacity",
    "backend",
    "camera_pose",
    "render",
    "render_polygons",
    "import_pyrender",
    "offscreen_renderer",
    "close",
]
