"""Camera matrices in OpenGL conventions, as plain functions returning float64 ``(4, 4)`` arrays.

Conventions (see ``docs/cameras.md`` for a diagram):

* World and eye space are right-handed; in eye space the camera sits at the origin, looks down
  ``-z``, ``+x`` is right and ``+y`` is up.
* Points are column vectors in homogeneous coordinates: ``p_clip = P @ V @ p_world`` with
  ``P = perspective(...)`` or ``orthographic(...)`` and ``V = look_at(...)``. For ``(n, 3)`` arrays of
  points write ``np.c_[X, np.ones(n)] @ (P @ V).T``.
* Normalised device coordinates (NDC) are ``p_clip[:3] / p_clip[3]``; the visible volume is the cube
  ``[-1, 1]^3``, near plane at ``z_ndc = -1``, far plane at ``z_ndc = +1``.
* Window coordinates (:func:`viewport`): ``x_win`` in ``[0, width]`` to the right, ``y_win`` in
  ``[0, height]`` upwards, depth ``(z_ndc + 1) / 2`` in ``[0, 1]``.
* Images are arrays ``(height, width)``; row 0 is the TOP of the picture, so pixel ``(row, col)``
  has its centre at ``x_win = col + 0.5``, ``y_win = height - row - 0.5``. :func:`project` returns
  image coordinates ``(x, y) = (x_win, height - y_win)``, in which that centre is ``(col + 0.5, row + 0.5)``.

Examples
--------
>>> import numpy as np
>>> from geomlib.camera import look_at, perspective, project
>>> V = look_at(eye=(0, 0, 3), target=(0, 0, 0))
>>> P = perspective(60, 1.0, 0.1, 10)
>>> xy, depth = project(np.array([[0.0, 0.0, 0.0]]), P @ V, 64, 64)
>>> xy
array([[32., 32.]])
"""

from __future__ import annotations

import numpy as np

from geomlib import portable
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int

__all__ = [
    "look_at",
    "pose_from_view",
    "perspective",
    "perspective_look_at",
    "orthographic",
    "viewport",
    "project",
    "view_frame",
    "camera_presets",
    "VIEWS",
    "PRESETS",
    "AXES",
]

#: The one table of preset viewpoints, used by :func:`camera_presets` (rasterizer labs) and by
#: :func:`geomlib.render.camera_pose` (figures, ``geomlib render --view``). Each entry is
#: ``(azimuth, elevation)`` in degrees in the MODEL's frame: azimuth 0 is in front of the model
#: (on its ``forward`` side), positive azimuth turns towards the viewer's right (the model's left),
#: elevation lifts the camera towards ``up``. ``"side"`` is the old name of ``"right"``.
VIEWS: dict[str, tuple[float, float]] = {
    "front": (0.0, 0.0),
    "three_quarter": (35.0, 25.0),
    "three_quarter_left": (-35.0, 25.0),
    "right": (90.0, 0.0),
    "side": (90.0, 0.0),
    "left": (-90.0, 0.0),
    "back": (180.0, 0.0),
    "three_quarter_back": (215.0, 25.0),
    "top": (0.0, 90.0),
    "bottom": (0.0, -90.0),
}
#: Names accepted by :func:`camera_presets` (every view of :data:`VIEWS`).
PRESETS = tuple(VIEWS)
#: Axis names accepted for ``up_axis`` / ``forward``.
AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: The model's forward axis (the way its face looks) when none is given, per up axis: y-up files
#: follow OpenGL/glTF (the model faces +z, towards a default camera); the course's z-up datasets
#: face -y.
DEFAULT_FORWARD = {"y": "+z", "z": "-y"}


def _vec3(x, name: str, where: str) -> np.ndarray:
    return as_array(x, name, shape=(3,), dtype=np.float64, where=where)


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """View matrix (eye from world) of a camera at ``eye`` looking at ``target`` (``gluLookAt``).

    Parameters
    ----------
    eye, target : array_like (3,)
        Camera position and the point it looks at, in world coordinates.
    up : array_like (3,)
        Approximate up direction; it is made orthogonal to the viewing direction.

    Returns
    -------
    (4, 4) float64
        Rigid transform ``V`` mapping world points to eye space: ``eye`` goes to the origin,
        ``target`` onto the negative ``z`` axis (at ``z = -|target - eye|``) and ``up`` into the
        ``y >= 0`` half of the ``yz`` plane.

    Raises
    ------
    MeshError
        If ``eye == target`` or ``up`` is zero or parallel to the viewing direction.
    """
    where = "look_at"
    eye, target, up = _vec3(eye, "eye", where), _vec3(target, "target", where), _vec3(up, "up", where)
    d = target - eye
    dist = portable.norm(d)  # portable: camera matrices feed stored test inputs (no BLAS)
    if dist == 0 or dist <= 1e-12 * max(np.abs(eye).max(), np.abs(target).max()):
        raise MeshError(
            f"{where}: eye {tuple(eye)} and target {tuple(target)} coincide; the view direction is undefined"
        )
    f = d / dist
    nu = portable.norm(up)
    if nu == 0:
        raise MeshError(f"{where}: up is the zero vector")
    s = np.cross(f, up / nu)
    ns = portable.norm(s)
    if ns < 1e-9:
        raise MeshError(
            f"{where}: up {tuple(up)} is parallel to the view direction {tuple(np.round(f, 6))}; "
            f"choose an up vector that is not along target - eye"
        )
    s /= ns
    u = np.cross(s, f)
    V = np.eye(4)
    V[0, :3], V[1, :3], V[2, :3] = s, u, -f
    V[:3, 3] = -portable.matmul(V[:3, :3], eye)
    return V


def pose_from_view(view) -> np.ndarray:
    """Camera-to-world pose (the inverse of a rigid view matrix such as :func:`look_at`'s).

    Renderers (pyrender, glTF) place a camera with this pose; the rasterizer uses the view matrix.

    Parameters
    ----------
    view : (4, 4) array_like
        Rigid world-to-eye matrix (orthonormal rotation, last row ``(0, 0, 0, 1)``).

    Returns
    -------
    (4, 4) float64
        ``inv(view)``, computed exactly as ``[[R.T, -R.T t], [0, 1]]``: its columns are the camera's
        right, up and back (``+z``, away from what it looks at) axes and its position.
    """
    M = as_array(view, "view", shape=(4, 4), dtype=np.float64, where="pose_from_view")
    pose = np.eye(4)
    pose[:3, :3] = M[:3, :3].T
    pose[:3, 3] = -M[:3, :3].T @ M[:3, 3]
    return pose


def _axis(name, what: str, where: str) -> np.ndarray:
    check_choice(name, what, AXES, where=where)
    v = np.zeros(3)
    v["xyz".index(name[1])] = 1.0 if name[0] == "+" else -1.0
    return v


def view_frame(view: str, up_axis: str = "y", forward: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World directions of a preset view: from the target towards the eye, and up in the image.

    Parameters
    ----------
    view : str
        A name of :data:`VIEWS`.
    up_axis : {"y", "z"} or one of :data:`AXES`
        World axis that points up (``"y"`` = ``"+y"``).
    forward : one of :data:`AXES`, optional
        World axis the model faces (its front); default :data:`DEFAULT_FORWARD`: ``+z`` when y is
        up, ``-y`` when z is up. Must be perpendicular to ``up_axis``.

    Returns
    -------
    back, image_up : (3,) float64 each
        Unit vectors: ``back`` points from the target to the camera, ``image_up`` is up in the image.
        ``top`` looks down ``-up`` with the model's back at the top of the picture; ``bottom``
        looks up with its front at the top.
    """
    where = "view_frame"
    check_choice(view, "view", tuple(VIEWS), where=where)
    up_name = {"y": "+y", "z": "+z"}.get(up_axis, up_axis)
    up = _axis(up_name, "up_axis", where)
    if forward is None:
        forward = DEFAULT_FORWARD.get(up_name[1], None)
        if forward is None or up_name[0] == "-":
            raise MeshError(f"{where}: give forward with up_axis={up_axis!r} (no default forward axis)")
    fwd = _axis(forward, "forward", where)
    if abs(fwd @ up) > 0:
        raise MeshError(f"{where}: forward {forward} must be perpendicular to up_axis {up_name}")
    # Model frame -> world: columns are the model's x (= up x forward), up and forward axes. With
    # signed unit axes it is a signed permutation, so mapping the model-frame vectors is exact.
    M = np.column_stack([np.cross(up, fwd), up, fwd])
    az, el = VIEWS[view]
    if abs(el) == 90.0:
        back, img_up = np.array([0.0, np.sign(el), 0.0]), np.array([0.0, 0.0, -np.sign(el)])
    else:
        a, e = np.radians(az), np.radians(el)
        back = np.array([np.sin(a) * np.cos(e), np.sin(e), np.cos(a) * np.cos(e)])
        back[np.abs(back) < 1e-12] = 0.0  # exact axes for 0/90/180 degrees
        img_up = np.array([0.0, 1.0, 0.0])
    return M @ back, M @ img_up


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """Perspective projection matrix (clip from eye), as ``gluPerspective``.

    Parameters
    ----------
    fov_y_deg : float
        Full vertical field of view in degrees, in ``(0, 180)``.
    aspect : float
        Width / height of the image.
    near, far : float
        Positive distances to the near and far planes, ``0 < near < far``. Eye-space points at
        ``z = -near`` map to ``z_ndc = -1``, at ``z = -far`` to ``z_ndc = +1``.

    Returns
    -------
    (4, 4) float64
        ``[[f/aspect, 0, 0, 0], [0, f, 0, 0], [0, 0, (far+near)/(near-far), 2 far near/(near-far)],
        [0, 0, -1, 0]]`` with ``f = 1 / tan(fov_y / 2)``; clip ``w = -z_eye``.
    """
    where = "perspective"
    fov = check_float(fov_y_deg, "fov_y_deg", minimum=0, maximum=180, where=where)
    if fov <= 0 or fov >= 180:
        raise MeshError(f"{where}: fov_y_deg must be strictly between 0 and 180 degrees, got {fov}")
    aspect = check_float(aspect, "aspect", where=where)
    if aspect <= 0:
        raise MeshError(f"{where}: aspect (width / height) must be positive, got {aspect}")
    near, far = check_float(near, "near", where=where), check_float(far, "far", where=where)
    if not 0 < near < far:
        raise MeshError(f"{where}: need 0 < near < far, got near={near}, far={far}")
    f = 1.0 / float(portable.tan(np.radians(fov) / 2))
    P = np.zeros((4, 4))
    P[0, 0] = f / aspect
    P[1, 1] = f
    P[2, 2] = (far + near) / (near - far)
    P[2, 3] = 2 * far * near / (near - far)
    P[3, 2] = -1.0
    return P


def perspective_look_at(eye, target, up, fov_y_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """Clip-from-world matrix of a perspective camera at ``eye`` looking at ``target``.

    The one place the course composes ``perspective(fov_y_deg, aspect, near, far) @ look_at(eye, target, up)``
    (figures, the shadows lab's eye pass); a light matrix a student writes spells it out.

    Parameters
    ----------
    eye, target, up : array_like, shape (3,)
        As :func:`look_at`.
    fov_y_deg, aspect, near, far : float
        As :func:`perspective`.

    Returns
    -------
    (4, 4) float64
        ``perspective(...) @ look_at(...)``.

    Examples
    --------
    >>> import numpy as np
    >>> M = perspective_look_at((0, 0, 3), (0, 0, 0), (0, 1, 0), 60, 1.0, 0.1, 10)
    >>> bool(np.allclose(M, perspective(60, 1.0, 0.1, 10) @ look_at((0, 0, 3), (0, 0, 0))))
    True
    """
    return portable.matmul(perspective(fov_y_deg, aspect, near, far), look_at(eye, target, up))


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    """Orthographic projection matrix (clip from eye), as ``glOrtho``.

    The eye-space box ``[left, right] x [bottom, top] x [-far, -near]`` maps to the NDC cube
    ``[-1, 1]^3`` (``z = -near`` to ``z_ndc = -1``). Clip ``w`` is always 1. ``near`` may be negative
    (planes behind the eye), but ``near != far``, ``left != right``, ``bottom != top``.

    Returns
    -------
    (4, 4) float64
    """
    where = "orthographic"
    vals = {}
    for name, v in zip(
        ("left", "right", "bottom", "top", "near", "far"), (left, right, bottom, top, near, far), strict=True
    ):
        vals[name] = check_float(v, name, where=where)
    for a, b in (("left", "right"), ("bottom", "top"), ("near", "far")):
        if vals[a] == vals[b]:
            raise MeshError(f"{where}: {a} and {b} are both {vals[a]}; the view volume is flat")
    l, r, b, t, n, f = (vals[k] for k in ("left", "right", "bottom", "top", "near", "far"))
    P = np.eye(4)
    P[0, 0], P[0, 3] = 2 / (r - l), -(r + l) / (r - l)
    P[1, 1], P[1, 3] = 2 / (t - b), -(t + b) / (t - b)
    P[2, 2], P[2, 3] = -2 / (f - n), -(f + n) / (f - n)
    return P


def viewport(width: int, height: int) -> np.ndarray:
    """Viewport matrix (window from NDC), as ``glViewport(0, 0, width, height)`` with ``glDepthRange(0, 1)``.

    ``x_win = (x_ndc + 1) / 2 * width`` (right), ``y_win = (y_ndc + 1) / 2 * height`` (UP, OpenGL's
    ``gl_FragCoord``), ``depth = (z_ndc + 1) / 2``. Image row ``r`` (row 0 = top) spans
    ``y_win`` in ``[height - r - 1, height - r]``; see :func:`project` for image coordinates.

    Returns
    -------
    (4, 4) float64
        Affine matrix acting on ``(x_ndc, y_ndc, z_ndc, 1)``.
    """
    width = check_int(width, "width", minimum=1, where="viewport")
    height = check_int(height, "height", minimum=1, where="viewport")
    W = np.eye(4)
    W[0, 0], W[0, 3] = width / 2, width / 2
    W[1, 1], W[1, 3] = height / 2, height / 2
    W[2, 2], W[2, 3] = 0.5, 0.5
    return W


def project(P, M, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Project world points to image coordinates and window depth.

    Parameters
    ----------
    P : array_like (n, 3)
        World positions.
    M : array_like (4, 4)
        Clip-from-world matrix, ``projection @ view``.
    width, height : int
        Image size in pixels.

    Returns
    -------
    xy : (n, 2) float64
        Image coordinates: ``x`` to the right, ``y`` DOWN (row direction), both in pixels, so the
        centre of pixel ``image[row, col]`` is ``(col + 0.5, row + 0.5)``; ``np.floor(xy)`` gives
        ``(col, row)``. Points on or behind the eye plane (clip ``w <= 0``) get NaN.
    depth : (n,) float64
        Window depth ``(z_ndc + 1) / 2``: 0 on the near plane, 1 on the far plane (NaN where ``w <= 0``).
    """
    where = "project"
    X = as_array(P, "P", shape=(None, 3), where=where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    width = check_int(width, "width", minimum=1, where=where)
    height = check_int(height, "height", minimum=1, where=where)
    C = portable.matmul(X, M[:3, :3].T) + M[:3, 3]
    w = portable.matmul(X, M[3, :3]) + M[3, 3]
    ok = w > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = np.where(ok[:, None], C / np.where(ok, w, 1.0)[:, None], np.nan)
    xy = np.stack([(ndc[:, 0] + 1) / 2 * width, (1 - ndc[:, 1]) / 2 * height], axis=1)
    return xy, (ndc[:, 2] + 1) / 2


def camera_presets(
    name: str,
    bounds,
    *,
    fov_y_deg: float = 45.0,
    margin: float = 1.1,
    up_axis: str = "y",
    forward: str | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fixed viewpoints that frame an axis-aligned bounding box, for reproducible figures.

    Parameters
    ----------
    name : str
        A view of :data:`VIEWS` (see :func:`view_frame`). With the defaults (y up, model facing
        ``+z``): ``"front"`` looks along ``-z`` (from ``+z``); ``"three_quarter"`` looks from azimuth
        35 degrees (from ``+z`` towards ``+x``) and elevation 25 degrees; ``"top"`` looks down ``-y``
        with ``-z`` pointing up in the image (``+x`` stays to the right). The same table frames the
        rendered figures (:func:`geomlib.render.camera_pose`).
    bounds : array_like (2, 3)
        ``[min corner, max corner]``, e.g. ``np.array([V.min(0), V.max(0)])``.
    fov_y_deg : float
        Field of view the returned eye is meant for (use the same value in :func:`perspective`); the
        camera distance is chosen so the bounding sphere fits in the narrower of the two fields of
        view for aspect >= 1.
    margin : float
        Extra room, as a factor on the distance (> 0).
    up_axis, forward : str
        The world's up axis and the model's forward axis (see :func:`view_frame`).

    Returns
    -------
    eye, target, up : (3,) float64 each
        Arguments for :func:`look_at`; ``target`` is the box centre. A good near/far pair is
        ``near = dist - r``, ``far = dist + r`` (clamped to > 0) with ``dist = |eye - target|`` and
        ``r`` the half diagonal of the box.
    """
    where = "camera_presets"
    check_choice(name, "name", PRESETS, where=where)
    B = as_array(bounds, "bounds", shape=(2, 3), where=where)
    if np.any(B[1] < B[0]):
        raise MeshError(f"{where}: bounds must be [min corner, max corner]; got min {tuple(B[0])} > max {tuple(B[1])}")
    fov = check_float(fov_y_deg, "fov_y_deg", minimum=1e-3, maximum=179, where=where)
    margin = check_float(margin, "margin", minimum=1e-6, where=where)
    c = B.mean(axis=0)
    r = 0.5 * np.linalg.norm(B[1] - B[0])
    if r == 0:
        r = 1.0  # a single point: any distance frames it
    dist = margin * r / np.sin(np.radians(fov) / 2)
    d, up = view_frame(name, up_axis, forward)
    return c + dist * d, c, up
