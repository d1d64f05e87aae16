"""Where the render camera is: preset views that frame the mesh, look-at triples and poses.

The presets come from the one table :data:`geomlib.camera.VIEWS` (shared with the rasterizer
labs' :func:`geomlib.camera.camera_presets`); look-at triples go through
:func:`geomlib.camera.look_at`, so a render and a rasterizer given the same ``(eye, target, up)``
see the same picture. pyrender wants camera-to-world poses: ``pose = pose_from_view(look_at(...))``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from geomlib.camera import AXES, VIEWS, look_at, pose_from_view, view_frame
from geomlib.render.options import _check_size
from geomlib.validate import MeshError, as_array, check_choice, check_float

__all__ = ["camera_pose", "resolve_camera"]


def camera_pose(
    V,
    view: str = "three_quarter",
    *,
    fov_deg: float = 35.0,
    size: tuple[int, int] = (640, 480),
    zoom: float = 1.0,
    up_axis: str = "z",
    margin: float = 0.06,
    forward: str | None = None,
) -> np.ndarray:
    """Camera-to-world pose of a preset view that frames the points ``V``.

    The camera looks at the points from a fixed direction (see :data:`VIEWS`), is centred on
    their projected extent, and is moved back until every point lies inside the image with a
    ``margin``. The result depends only on the arguments (deterministic).

    Parameters
    ----------
    V : (n, 3) array_like
        Points to frame (usually the mesh vertices).
    view : str
        A view of :data:`geomlib.camera.VIEWS`, the table the rasterizer labs use too (see
        :func:`geomlib.camera.view_frame`). With ``up_axis="z"`` (model facing -y): ``front`` looks
        from -y towards +y, ``right`` (alias ``side``) from +x, ``top`` down the -z axis (+y up in
        the image), ``three_quarter`` from the front right, 35 degrees azimuth and 25 degrees
        elevation. With ``up_axis="y"`` (model facing +z) the same views rotated so that ``front``
        looks from +z. ``forward`` names another facing, e.g. ``"-z"`` for a y-up model that looks
        down -z.
    fov_deg : float
        Vertical field of view in degrees.
    size : (width, height)
        Image size in pixels (only the aspect ratio matters).
    zoom : float
        Values > 1 move the camera closer (the object fills more than the frame).
    up_axis : {"z", "y"}
        World axis that points up (the course's datasets are z-up; many scanned meshes are y-up).
    margin : float
        Fraction of the half-image kept free around the object.
    forward : one of :data:`geomlib.camera.AXES`, optional
        The way the model faces (default ``-y`` when z is up, ``+z`` when y is up).

    Returns
    -------
    (4, 4) float64
        Camera-to-world pose (OpenGL convention, camera looks down its -z axis).
    """
    where = "camera_pose"
    P = as_array(V, "V", shape=(None, 3), where=where)
    if len(P) == 0:
        raise MeshError(f"{where}: V is empty, nothing to frame")
    check_choice(view, "view", tuple(VIEWS), where=where)
    check_choice(up_axis, "up_axis", ("y", "z"), where=where)
    if forward is not None:
        check_choice(forward, "forward", AXES, where=where)
    fov = np.radians(check_float(fov_deg, "fov_deg", minimum=1.0, maximum=170.0, where=where))
    zoom = check_float(zoom, "zoom", minimum=1e-3, where=where)
    margin = check_float(margin, "margin", minimum=0.0, maximum=0.9, where=where)
    w, h = _check_size(size, where)
    back, up = view_frame(view, up_axis, forward)
    back = back / np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    upv = np.cross(back, right)

    lo, hi = P.min(axis=0), P.max(axis=0)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    center = (lo + hi) / 2
    ty = np.tan(fov / 2) * (1.0 - margin)
    tx = ty * w / h
    rel = P - center
    x, y, z = rel @ right, rel @ upv, rel @ back
    # Centre the projected extent: a sideways shift s changes x/(d - z) by about s/d; two passes suffice.
    for _ in range(3):
        d = float(np.max(np.maximum(z + np.abs(x) / tx, z + np.abs(y) / ty)))
        d = max(d, float(z.max()) + 1e-3 * diag, 1e-6 * diag)
        depth = d - z
        u, v = x / depth, y / depth
        sx, sy = (u.max() + u.min()) / 2 * d, (v.max() + v.min()) / 2 * d
        x, y = x - sx, y - sy
        center = center + sx * right + sy * upv
    d = float(np.max(np.maximum(z + np.abs(x) / tx, z + np.abs(y) / ty)))
    d = max(d, float(z.max()) + 1e-3 * diag, 1e-6 * diag)
    d = float(z.max()) + (d - float(z.max())) / zoom
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, upv, back, center + d * back
    return pose


def resolve_camera(camera, V: np.ndarray, *, fov_deg, size, zoom, up_axis, forward, where: str) -> np.ndarray:
    """The camera-to-world pose for the ``camera`` option: a preset name, ``(eye, target, up)`` or a pose."""
    if isinstance(camera, str):
        check_choice(camera, "camera", tuple(VIEWS), where=where)
        return camera_pose(V, camera, fov_deg=fov_deg, size=size, zoom=zoom, up_axis=up_axis, forward=forward)
    try:
        shape = np.shape(camera)
    except ValueError:  # ragged
        shape = ()
    if shape == (4, 4):
        pose = as_array(camera, "camera", shape=(4, 4), where=where)
        R = pose[:3, :3]
        if not np.allclose(pose[3], [0, 0, 0, 1]) or not np.allclose(R.T @ R, np.eye(3), atol=1e-6):
            raise MeshError(
                f"{where}: camera pose must be a rigid camera-to-world matrix (orthonormal rotation, "
                f"last row (0, 0, 0, 1))"
            )
        return pose
    if isinstance(camera, Sequence) and len(camera) == 3:
        eye, target, up = (as_array(v, f"camera[{i}]", shape=(3,), where=where) for i, v in enumerate(camera))
        try:
            return pose_from_view(look_at(eye, target, up))
        except MeshError as e:
            raise MeshError(f"{where}: camera {str(e).removeprefix('look_at: ')}") from None
    raise MeshError(
        f"{where}: camera must be one of {tuple(VIEWS)}, an (eye, target, up) triple or a 4x4 pose; got {camera!r}"
    )
