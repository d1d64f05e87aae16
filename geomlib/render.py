"""Headless rendering of triangle and polygon meshes for figures, with pyrender on OSMesa or Mesa EGL.

:func:`render` draws a triangle mesh ``(V, F)`` and returns an ``(h, w, 3)`` uint8 image;
:func:`render_polygons` does the same for polygon meshes (quads of Catmull-Clark, ...), drawing
the true polygon edges as wireframe. Both support per-vertex or per-face colours, textures,
smooth or flat shading, unlit colours, a depth-tested wireframe overlay, highlighted vertices,
directional and spot lights, and shadows.

Rendering is deterministic: the same call gives the same bytes. Cameras come from fixed presets
(``"front"``, ``"three_quarter"``, ``"top"``, ``"side"``) that frame the mesh, from an
``(eye, target, up)`` triple, or from a 4x4 camera-to-world pose (OpenGL convention: the camera
looks down its local -z axis, +y is up in the image).

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

import atexit
import ctypes.util
import os
import sys
from collections.abc import Sequence

import numpy as np

from geomlib import topology
from geomlib.validate import (
    MeshError,
    as_array,
    as_image,
    check_choice,
    check_float,
    check_int,
    check_mesh,
    check_polygon_mesh,
)

__all__ = [
    "VIEWS",
    "DEFAULT_BASE_COLOR",
    "DEFAULT_WIRE_COLOR",
    "backend",
    "camera_pose",
    "render",
    "render_polygons",
    "import_pyrender",
    "offscreen_renderer",
    "close",
]

#: Camera presets accepted by ``camera=``.
VIEWS = ("front", "three_quarter", "top", "side")
#: Default surface colour (sRGB, 0..1): a soft light grey-blue.
DEFAULT_BASE_COLOR = (0.74, 0.80, 0.90)
#: Default wireframe colour (sRGB, 0..1).
DEFAULT_WIRE_COLOR = (0.10, 0.11, 0.16)

_HEADLESS_FIX = (
    "install OSMesa (`sudo apt-get install libosmesa6` on Debian/Ubuntu), or a Mesa EGL driver "
    "(`sudo apt-get install libegl1 libgl1-mesa-dri`) and set PYOPENGL_PLATFORM=egl"
)

# View directions (from the target towards the eye) and image-up vectors for a y-up world.
# three_quarter: azimuth 35 degrees from +z towards +x, elevation 25 degrees.
_AZ, _EL = np.radians(35.0), np.radians(25.0)
_PRESETS_Y_UP = {
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "three_quarter": ((np.sin(_AZ) * np.cos(_EL), np.sin(_EL), np.cos(_AZ) * np.cos(_EL)), (0.0, 1.0, 0.0)),
    "top": ((0.0, 1.0, 0.0), (0.0, 0.0, -1.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
}
# z-up worlds (terrains, CAD): rotate the y-up presets by +90 degrees about x (y -> z, z -> -y).
_Y_TO_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

# Camera-relative 3-point lighting: (direction towards the light in camera coordinates, intensity).
# Camera coordinates: +x right, +y up, +z from the scene towards the viewer.
_KEY = ((-0.65, 0.55, 0.55), 2.8)
_FILL = ((0.85, 0.05, 0.50), 0.9)
_RIM = ((0.20, 0.60, -1.0), 1.4)
_AMBIENT = 0.25


# --------------------------------------------------------------------------------------------
# Platform and renderer cache
# --------------------------------------------------------------------------------------------


def backend() -> str:
    """The headless OpenGL platform used for rendering: ``"osmesa"``, ``"egl"``, or the user's choice.

    A ``PYOPENGL_PLATFORM`` already set in the environment is respected. Otherwise OSMesa is used
    when ``libOSMesa`` is found, else Mesa EGL when ``libEGL`` is found, and the choice is written
    to ``os.environ["PYOPENGL_PLATFORM"]`` (PyOpenGL reads it once, at import).

    Returns
    -------
    str
        The value of ``PYOPENGL_PLATFORM``.

    Raises
    ------
    RuntimeError
        When no headless OpenGL library is installed, or OpenGL was imported before a platform
        was chosen. The message names the fix.
    """
    chosen = os.environ.get("PYOPENGL_PLATFORM")
    if chosen:
        return chosen
    if "OpenGL.platform" in sys.modules:
        raise RuntimeError(
            "geomlib.render: PyOpenGL was imported before a headless platform was chosen, so it uses an "
            "on-screen platform. Set the environment variable PYOPENGL_PLATFORM=osmesa (or egl) before "
            "starting Python, or import geomlib.render before anything that imports OpenGL."
        )
    if ctypes.util.find_library("OSMesa"):
        chosen = "osmesa"
    elif ctypes.util.find_library("EGL"):
        chosen = "egl"
    else:
        raise RuntimeError(
            f"geomlib.render: no headless OpenGL library found (neither libOSMesa nor libEGL). Fix: {_HEADLESS_FIX}"
        )
    os.environ["PYOPENGL_PLATFORM"] = chosen
    return chosen


def import_pyrender():
    """Import and return the ``pyrender`` module, after choosing the headless platform (see :func:`backend`).

    Use this (never a bare ``import pyrender``) in code that builds its own pyrender scenes, e.g.
    cross-checks against pyrender's shadow maps, so the platform and the NumPy shim are in place.
    """
    backend()
    if not hasattr(np, "infty"):
        # Compatibility shim, the only one in the project: pyrender 0.1.45 (its latest release) still
        # uses np.infty in Mesh.bounds, an alias removed in NumPy 2.0.
        np.infty = np.inf  # noqa: NPY201 (setting the alias, not using it)
    import pyrender

    return pyrender


_RENDERERS: dict[tuple[int, int], object] = {}


def offscreen_renderer(width: int, height: int):
    """The shared ``pyrender.OffscreenRenderer`` for this framebuffer size, created on first use.

    Creating an OpenGL context is costly, so one per size is kept for the whole process and freed
    at exit (:func:`close`). Do not call ``delete()`` on it.

    Raises
    ------
    RuntimeError
        When no headless OpenGL context can be created (the message names the fix).
    """
    r = _RENDERERS.get((width, height))
    if r is None:
        pyrender = import_pyrender()
        try:
            r = pyrender.OffscreenRenderer(width, height)
        except Exception as e:
            raise RuntimeError(
                f"geomlib.render: could not create a headless OpenGL context with PYOPENGL_PLATFORM="
                f"{os.environ.get('PYOPENGL_PLATFORM')!r} ({type(e).__name__}: {e}). Fix: {_HEADLESS_FIX}"
            ) from e
        _RENDERERS[(width, height)] = r
    return r


def close() -> None:
    """Free every cached OpenGL context (called automatically at exit)."""
    while _RENDERERS:
        _, r = _RENDERERS.popitem()
        try:
            r.delete()
        except Exception:  # the context may already be gone at interpreter shutdown
            pass


atexit.register(close)


# --------------------------------------------------------------------------------------------
# Small geometry helpers
# --------------------------------------------------------------------------------------------


def _unit(v: np.ndarray, eps: float = 1e-300) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, eps)


def _look_at(eye, target, up, where: str = "render") -> np.ndarray:
    """Camera-to-world pose looking from ``eye`` at ``target`` (camera -z towards the target)."""
    eye, target, up = (np.asarray(a, dtype=np.float64) for a in (eye, target, up))
    back = eye - target
    if np.linalg.norm(back) == 0:
        raise MeshError(f"{where}: camera eye and target coincide")
    back = back / np.linalg.norm(back)
    right = np.cross(up, back)
    if np.linalg.norm(right) < 1e-9 * max(np.linalg.norm(up), 1e-300):
        raise MeshError(f"{where}: camera up vector is parallel to the viewing direction")
    right /= np.linalg.norm(right)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, np.cross(back, right), back, eye
    return pose


def _frame_to_z(z: np.ndarray) -> np.ndarray:
    """A rotation whose third column is the unit vector ``z`` (pose of a light shining along -z)."""
    z = z / np.linalg.norm(z)
    helper = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    R = np.eye(4)
    R[:3, 0], R[:3, 1], R[:3, 2] = x, np.cross(z, x), z
    return R


def _check_size(size, where: str) -> tuple[int, int]:
    if not isinstance(size, Sequence) or len(size) != 2:
        raise MeshError(f"{where}: size must be (width, height) in pixels, got {size!r}")
    w = check_int(size[0], "size[0] (width)", minimum=1, maximum=8192, where=where)
    h = check_int(size[1], "size[1] (height)", minimum=1, maximum=8192, where=where)
    return w, h


def camera_pose(
    V,
    view: str = "three_quarter",
    *,
    fov_deg: float = 35.0,
    size: tuple[int, int] = (640, 480),
    zoom: float = 1.0,
    up_axis: str = "z",
    margin: float = 0.06,
) -> np.ndarray:
    """Camera-to-world pose of a preset view that frames the points ``V``.

    The camera looks at the points from a fixed direction (see :data:`VIEWS`), is centred on
    their projected extent, and is moved back until every point lies inside the image with a
    ``margin``. The result depends only on the arguments (deterministic).

    Parameters
    ----------
    V : (n, 3) array_like
        Points to frame (usually the mesh vertices).
    view : {"front", "three_quarter", "top", "side"}
        With ``up_axis="z"``: ``front`` looks from -y towards +y, ``side`` from +x, ``top`` down
        the -z axis (+y up in the image), ``three_quarter`` from the front right, 35 degrees
        azimuth and 25 degrees elevation. With ``up_axis="y"`` the same views rotated so that
        ``front`` looks from +z.
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

    Returns
    -------
    (4, 4) float64
        Camera-to-world pose (OpenGL convention, camera looks down its -z axis).
    """
    where = "camera_pose"
    P = as_array(V, "V", shape=(None, 3), where=where)
    if len(P) == 0:
        raise MeshError(f"{where}: V is empty, nothing to frame")
    check_choice(view, "view", VIEWS, where=where)
    check_choice(up_axis, "up_axis", ("y", "z"), where=where)
    fov = np.radians(check_float(fov_deg, "fov_deg", minimum=1.0, maximum=170.0, where=where))
    zoom = check_float(zoom, "zoom", minimum=1e-3, where=where)
    margin = check_float(margin, "margin", minimum=0.0, maximum=0.9, where=where)
    w, h = _check_size(size, where)
    back, up = (np.asarray(a, dtype=np.float64) for a in _PRESETS_Y_UP[view])
    if up_axis == "z":
        back, up = _Y_TO_Z @ back, _Y_TO_Z @ up
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


# --------------------------------------------------------------------------------------------
# Input checking
# --------------------------------------------------------------------------------------------


def _as_rgb(c, name: str, where: str, *, n: int | None = None, per: str = "vertex") -> np.ndarray:
    """Colours as float64 in [0, 1]: uint8 (0..255) or floats in [0, 1]; ``n`` rows or one colour."""
    a = np.asarray(c) if c is not None else None
    if a is None or a.dtype == object:
        raise MeshError(f"{where}: {name} must be an array of RGB colours, got {c!r}")
    if n is None:
        if a.shape not in ((3,), (4,)):
            raise MeshError(f"{where}: {name} must be one RGB colour (3 numbers in 0..1), got shape {a.shape}")
    else:
        if a.ndim != 2 or a.shape[1] not in (3, 4):
            raise MeshError(f"{where}: {name} has shape {a.shape}, expected ({n}, 3) RGB or ({n}, 4) RGBA colours")
        if a.shape[0] != n:
            raise MeshError(f"{where}: {name} has {a.shape[0]} rows, expected {n} (one colour per {per})")
    if a.dtype == np.uint8:
        return a[..., :3].astype(np.float64) / 255.0
    f = as_array(a, name, dtype=np.float64, where=where)[..., :3]
    if f.size and (f.min() < -1e-6 or f.max() > 1 + 1e-6):
        bad = np.argwhere((f < -1e-6) | (f > 1 + 1e-6))[0]
        raise MeshError(
            f"{where}: {name} has value {f[tuple(bad)]:.6g} at {tuple(int(i) for i in bad)}; float colours must "
            f"lie in [0, 1] (pass uint8 for 0..255)"
        )
    return np.clip(f, 0.0, 1.0)


def _as_texture(texture, where: str) -> np.ndarray:
    t = as_image(texture, "texture", channels=(1, 3, 4), where=where)
    if t.ndim == 2:
        t = t[:, :, None]
    if t.dtype != np.uint8:
        f = as_array(t, "texture", dtype=np.float64, where=where)
        if f.min() < -1e-6 or f.max() > 1 + 1e-6:
            raise MeshError(f"{where}: texture values span [{f.min():.6g}, {f.max():.6g}]; floats must lie in [0, 1]")
        t = np.round(np.clip(f, 0, 1) * 255).astype(np.uint8)
    if t.shape[2] == 1:
        t = np.repeat(t, 3, axis=2)
    return np.ascontiguousarray(t[:, :, :3])


def _srgb_to_linear(c: np.ndarray) -> np.ndarray:
    # pyrender's lit shader writes pow(linear, 1/2.2); inverting that exactly keeps colours as given.
    return np.asarray(c, dtype=np.float64) ** 2.2


def _light_specs(light, where: str) -> list[dict]:
    """Validate a list of user light specs (world coordinates)."""
    if isinstance(light, dict):
        light = [light]
    if not isinstance(light, Sequence) or isinstance(light, str) or len(light) == 0:
        raise MeshError(
            f"{where}: light must be 'directional', 'spot' or a non-empty list of light dicts, got {light!r}"
        )
    out = []
    for i, s in enumerate(light):
        if not isinstance(s, dict):
            raise MeshError(f"{where}: light[{i}] must be a dict with a 'type', got {s!r}")
        kind = check_choice(s.get("type"), f"light[{i}]['type']", ("directional", "spot", "point"), where=where)
        known = {"type", "direction", "position", "target", "color", "intensity", "inner_cone_deg", "outer_cone_deg"}
        extra = sorted(set(s) - known)
        if extra:
            raise MeshError(f"{where}: light[{i}] has unknown keys {extra}; known keys are {sorted(known)}")
        spec = {
            "type": kind,
            "color": _as_rgb(s.get("color", (1.0, 1.0, 1.0)), f"light[{i}]['color']", where),
            "intensity": check_float(s.get("intensity", 3.0), f"light[{i}]['intensity']", minimum=0.0, where=where),
        }
        if kind == "directional":
            if "direction" not in s:
                raise MeshError(
                    f"{where}: light[{i}] is directional and needs a 'direction' (the way the light travels)"
                )
            d = as_array(s["direction"], f"light[{i}]['direction']", shape=(3,), where=where)
            if np.linalg.norm(d) == 0:
                raise MeshError(f"{where}: light[{i}]['direction'] is the zero vector")
            spec["direction"] = d / np.linalg.norm(d)
        else:
            if "position" not in s:
                raise MeshError(f"{where}: light[{i}] is a {kind} light and needs a 'position'")
            spec["position"] = as_array(s["position"], f"light[{i}]['position']", shape=(3,), where=where)
            if "target" in s:
                spec["target"] = as_array(s["target"], f"light[{i}]['target']", shape=(3,), where=where)
            outer = check_float(
                s.get("outer_cone_deg", 30.0), f"light[{i}]['outer_cone_deg']", minimum=0.1, maximum=89.9, where=where
            )
            inner = check_float(
                s.get("inner_cone_deg", 0.6 * outer),
                f"light[{i}]['inner_cone_deg']",
                minimum=0.0,
                maximum=outer,
                where=where,
            )
            spec["outer"], spec["inner"] = np.radians(outer), np.radians(inner)
        out.append(spec)
    return out


# --------------------------------------------------------------------------------------------
# Wireframe and point overlay
# --------------------------------------------------------------------------------------------


def _project(X: np.ndarray, world_to_cam: np.ndarray, ty: float, tx: float, W: int, H: int):
    """World points -> (pixel x, pixel y, view depth); pixel (0, 0) is the top-left corner."""
    Xc = X @ world_to_cam[:3, :3].T + world_to_cam[:3, 3]
    z = -Xc[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        px = (Xc[:, 0] / (z * tx) + 1.0) * 0.5 * W
        py = (1.0 - Xc[:, 1] / (z * ty)) * 0.5 * H
    return px, py, z


def _visible(px, py, z, dmax: np.ndarray, tol: float):
    """Inside the image and not behind the rendered surface (``dmax``: 3x3 max of the depth buffer)."""
    H, W = dmax.shape
    inside = (px >= 0) & (px < W) & (py >= 0) & (py < H) & (z > 0)
    ix = np.clip(np.floor(np.where(inside, px, 0)).astype(np.int64), 0, W - 1)
    iy = np.clip(np.floor(np.where(inside, py, 0)).astype(np.int64), 0, H - 1)
    ref = dmax[iy, ix]
    return inside & (z <= ref * (1.0 + 2e-3) + tol), ix, iy


def _disk(diameter: float) -> np.ndarray:
    k = max(1, int(round(diameter)))
    c = (k - 1) / 2.0
    yy, xx = np.mgrid[:k, :k]
    return (xx - c) ** 2 + (yy - c) ** 2 <= (k / 2.0) ** 2 + 1e-9


def _edge_mask(X0, X1, world_to_cam, ty, tx, dmax, tol, znear) -> np.ndarray:
    """Boolean (H, W) mask of the visible parts of the 3-D segments ``X0[i] -> X1[i]``."""
    H, W = dmax.shape
    mask = np.zeros((H, W), dtype=bool)
    if len(X0) == 0:
        return mask
    p0x, p0y, z0 = _project(X0, world_to_cam, ty, tx, W, H)
    p1x, p1y, z1 = _project(X1, world_to_cam, ty, tx, W, H)
    keep = (z0 > znear) & (z1 > znear)
    # Skip segments entirely off one side of the image.
    keep &= (
        ~((p0x < 0) & (p1x < 0)) & ~((p0x >= W) & (p1x >= W)) & ~((p0y < 0) & (p1y < 0)) & ~((p0y >= H) & (p1y >= H))
    )
    p0x, p0y, p1x, p1y = p0x[keep], p0y[keep], p1x[keep], p1y[keep]
    iz0, iz1 = 1.0 / z0[keep], 1.0 / z1[keep]
    length = np.minimum(np.hypot(p1x - p0x, p1y - p0y), 2.0 * (W + H))
    step = 0.5
    total = float(np.sum(np.ceil(length / step) + 1))
    if total > 2e7:  # bound memory on huge meshes: thin lines there are a grey haze anyway
        step *= total / 2e7
    n = (np.ceil(length / step) + 1).astype(np.int64)
    seg = np.repeat(np.arange(len(n)), n)
    start = np.repeat(np.cumsum(n) - n, n)
    t = (np.arange(int(n.sum())) - start) / np.repeat(np.maximum(n - 1, 1), n)
    # Screen-space positions interpolate linearly, and so does 1/depth (perspective-correct).
    px = p0x[seg] + t * (p1x - p0x)[seg]
    py = p0y[seg] + t * (p1y - p0y)[seg]
    z = 1.0 / (iz0[seg] + t * (iz1 - iz0)[seg])
    vis, ix, iy = _visible(px, py, z, dmax, tol)
    mask[iy[vis], ix[vis]] = True
    return mask


def _overlay(
    color: np.ndarray,
    depth: np.ndarray,
    pose: np.ndarray,
    fov: float,
    znear: float,
    diag: float,
    *,
    V: np.ndarray,
    edges: np.ndarray | None,
    wire_color: np.ndarray,
    line_px: float,
    wire_opacity: float,
    points: np.ndarray | None,
    point_color: np.ndarray,
    point_px: float,
) -> np.ndarray:
    """Draw depth-tested edges and dots onto the (supersampled) render."""
    from scipy import ndimage

    H, W = depth.shape
    ty = np.tan(fov / 2)
    tx = ty * W / H
    world_to_cam = np.linalg.inv(pose)
    d = np.where(depth > 0, depth, np.inf).astype(np.float64)
    dmax = ndimage.maximum_filter(d, size=3, mode="nearest")
    tol = 2e-3 * diag
    out = color.astype(np.float32)
    if edges is not None and len(edges):
        mask = _edge_mask(V[edges[:, 0]], V[edges[:, 1]], world_to_cam, ty, tx, dmax, tol, znear)
        mask = ndimage.binary_dilation(mask, structure=_disk(line_px))
        wc = (255.0 * wire_color).astype(np.float32)
        out[mask] = out[mask] * (1.0 - wire_opacity) + wc * wire_opacity
    if points is not None and len(points):
        px, py, z = _project(V[points], world_to_cam, ty, tx, W, H)
        vis, ix, iy = _visible(px, py, z, dmax, tol)
        dots = np.zeros((H, W), dtype=bool)
        dots[iy[vis], ix[vis]] = True
        ring = ndimage.binary_dilation(dots, structure=_disk(point_px + 0.3 * point_px + 2))
        core = ndimage.binary_dilation(dots, structure=_disk(point_px))
        out[ring] = 255.0  # white halo keeps dots readable on dark wireframes
        out[core] = (255.0 * point_color).astype(np.float32)
    return out


# --------------------------------------------------------------------------------------------
# Core renderer
# --------------------------------------------------------------------------------------------


def _vertex_normals(n: int, T: np.ndarray, tri_n: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals from unnormalised triangle normals ``tri_n`` (twice the area)."""
    acc = np.zeros((n, 3))
    for k in range(3):
        for c in range(3):
            acc[:, c] += np.bincount(T[:, k], weights=tri_n[:, c], minlength=n)
    return acc


def _crease_normals(T: np.ndarray, tri_n: np.ndarray, vert_n: np.ndarray, crease_deg: float) -> np.ndarray | None:
    """Per-corner normals ``(3m, 3)`` that keep edges sharper than ``crease_deg`` sharp.

    Each corner averages (area-weighted) the faces around its vertex whose normal is within
    ``crease_deg`` of its own face's. Where every face around a vertex lies within half that angle
    of the vertex normal, all pairs pass and the result is the vertex normal, so only the other
    vertices are worked out pair by pair. Returns None when no vertex needs splitting, or when the
    pairs would take too much memory (then plain vertex normals are used).
    """
    vc = T.ravel()
    fc = np.repeat(np.arange(len(T)), 3)
    un = _unit(tri_n)
    close = np.einsum("ij,ij->i", un[fc], _unit(vert_n)[vc]) >= np.cos(np.radians(crease_deg / 2))
    simple = np.ones(len(vert_n), dtype=bool)
    simple[vc[~close]] = False
    cand = np.flatnonzero(~simple[vc])  # corners at vertices that may need split normals
    if len(cand) == 0:
        return None
    order = cand[np.argsort(vc[cand], kind="stable")]
    sorted_v = vc[order]
    first = np.searchsorted(sorted_v, sorted_v)  # where each corner's vertex group starts in `order`
    d = np.bincount(sorted_v)[sorted_v]  # size of that group
    total = int(np.sum(d))
    if total > 3e7:
        return None
    # All ordered pairs (a, b) of corners at the same vertex.
    a = np.repeat(order, d)
    b = order[np.repeat(first, d) + np.arange(total) - np.repeat(np.cumsum(d) - d, d)]
    keep = np.einsum("ij,ij->i", un[fc[a]], un[fc[b]]) >= np.cos(np.radians(crease_deg)) - 1e-9
    a, fb = a[keep], fc[b[keep]]
    out = vert_n[vc].copy()
    for c in range(3):
        out[cand, c] = np.bincount(a, weights=tri_n[fb, c], minlength=len(vc))[cand]
    return out


def _draw(
    V: np.ndarray,
    T: np.ndarray,
    *,
    where: str,
    tri_normals: np.ndarray,
    vert_normals: np.ndarray,
    user_normals: bool,
    crease_deg: float | None,
    edges: np.ndarray | None,
    colors: np.ndarray | None,
    tri_colors: np.ndarray | None,
    uv: np.ndarray | None,
    texture: np.ndarray | None,
    smooth: bool,
    flat: bool,
    wire_color,
    edge_width: float,
    wire_opacity: float,
    highlight_points: np.ndarray | None,
    point_color,
    point_radius: float,
    camera,
    fov_deg: float,
    size,
    zoom: float,
    up_axis: str,
    light,
    ambient: float,
    shadows: bool,
    floor: bool,
    background,
    base_color,
    back_color,
    roughness: float,
    metallic: float,
    supersample: int,
) -> np.ndarray:
    w, h = _check_size(size, where)
    ss = check_int(supersample, "supersample", minimum=1, maximum=4, where=where)
    fov = np.radians(check_float(fov_deg, "fov_deg", minimum=1.0, maximum=170.0, where=where))
    check_choice(up_axis, "up_axis", ("y", "z"), where=where)
    ambient = check_float(ambient, "ambient", minimum=0.0, where=where)
    roughness = check_float(roughness, "roughness", minimum=0.0, maximum=1.0, where=where)
    metallic = check_float(metallic, "metallic", minimum=0.0, maximum=1.0, where=where)
    edge_width = check_float(edge_width, "edge_width", minimum=0.0, maximum=50.0, where=where)
    if wire_opacity is not None:
        wire_opacity = check_float(wire_opacity, "wire_opacity", minimum=0.0, maximum=1.0, where=where)
    point_radius = check_float(point_radius, "point_radius", minimum=0.0, maximum=100.0, where=where)
    if crease_deg is not None:
        crease_deg = check_float(crease_deg, "crease_deg", minimum=0.0, maximum=180.0, where=where)
    bg = _as_rgb(background, "background", where)
    base = _as_rgb(base_color, "base_color", where)
    back = _as_rgb(back_color, "back_color", where) if back_color is not None else None
    wire_rgb = _as_rgb(wire_color, "wire_color", where)
    point_rgb = _as_rgb(point_color, "point_color", where)
    W, H = w * ss, h * ss
    if isinstance(light, str):
        check_choice(light, "light", ("directional", "spot"), where=where)
        specs = None
    else:
        specs = _light_specs(light, where)

    lo, hi = V.min(axis=0), V.max(axis=0)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    center = (lo + hi) / 2
    up_vec = np.array([0.0, 1.0, 0.0]) if up_axis == "y" else np.array([0.0, 0.0, 1.0])

    if isinstance(camera, str):
        check_choice(camera, "camera", VIEWS, where=where)
        pose = camera_pose(V, camera, fov_deg=fov_deg, size=(w, h), zoom=zoom, up_axis=up_axis)
    else:
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
        elif isinstance(camera, Sequence) and len(camera) == 3:
            eye, target, up = (as_array(v, f"camera[{i}]", shape=(3,), where=where) for i, v in enumerate(camera))
            pose = _look_at(eye, target, up, where)
        else:
            raise MeshError(
                f"{where}: camera must be one of {VIEWS}, an (eye, target, up) triple or a 4x4 pose; got {camera!r}"
            )

    # Work in a normalised frame (mesh centred, bounding-box diagonal 1): pyrender's shadow-map bias
    # and clip planes are absolute numbers, so this makes shadows behave the same at every mesh scale.
    c0, s0 = center, diag
    pose = pose.copy()
    pose[:3, 3] = (pose[:3, 3] - c0) / s0
    V = (V - c0) / s0
    lo, hi, center, diag = (lo - c0) / s0, (hi - c0) / s0, np.zeros(3), 1.0

    # Depth range: tight around the mesh (and floor) for depth-buffer precision.
    cam_pos = pose[:3, 3]
    fwd = -pose[:3, 2] / np.linalg.norm(pose[:3, 2])
    depths = (V - cam_pos) @ fwd
    floor_y = float(lo @ up_vec) - 1e-3 * diag
    zfar = float(depths.max()) + 0.05 * diag
    if floor:
        zfar = max(zfar, float(np.linalg.norm(cam_pos - center)) + 6.0 * diag)
    znear = max(float(depths.min()) - 0.05 * diag, 1e-4 * max(zfar, diag))
    zfar = max(zfar, 10.0 * znear)  # the mesh may be behind a user camera: render the empty view

    pyrender = import_pyrender()

    # Per-corner arrays when anything is per face; indexed vertices otherwise.
    corner_n = None
    if not smooth:
        corner_n = np.repeat(tri_normals, 3, axis=0)
    elif not user_normals and crease_deg is not None and crease_deg < 180.0:
        corner_n = _crease_normals(T, tri_normals, vert_normals, crease_deg)
    per_corner = corner_n is not None or tri_colors is not None
    if per_corner:
        idx = T.ravel()
        P = V[idx]
        N = _unit(corner_n) if corner_n is not None else _unit(vert_normals)[idx]
        C = (
            np.repeat(tri_colors, 3, axis=0)
            if tri_colors is not None
            else (colors[idx] if colors is not None else None)
        )
        UV = uv[idx] if uv is not None else None
        I = np.arange(len(idx), dtype=np.uint32).reshape(-1, 3)
    else:
        P, N, C, UV, I = V, _unit(vert_normals), colors, uv, T.astype(np.uint32)
    N = np.where(np.linalg.norm(N, axis=1, keepdims=True) > 0.5, N, -fwd)  # degenerate faces face the camera

    def colour(c):  # lit shading works in linear space; the unlit shader writes colours as given
        return c if flat else _srgb_to_linear(c)

    tex = pyrender.Texture(source=texture, source_channels="RGB") if texture is not None else None

    def material(rgb, tex):
        kw = {} if tex is None else {"baseColorTexture": tex}
        return pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[*map(float, rgb), 1.0],
            metallicFactor=metallic,
            roughnessFactor=roughness,
            doubleSided=False,
            **kw,
        )

    vcol = None
    front_rgb = colour(base)
    if C is not None:
        vcol = np.hstack([colour(C), np.ones((len(C), 1))]).astype(np.float32)
        front_rgb = np.ones(3)
    if texture is not None:
        front_rgb = np.ones(3) if C is None else front_rgb
    P32, N32 = P.astype(np.float32), N.astype(np.float32)
    UV32 = UV.astype(np.float32) if UV is not None else None
    # Back faces get their own reversed copy with flipped normals (culling on), so open surfaces and
    # inconsistently oriented meshes are lit correctly from both sides.
    prims = [
        pyrender.Primitive(
            positions=P32, normals=N32, texcoord_0=UV32, color_0=vcol, indices=I, material=material(front_rgb, tex)
        ),
        pyrender.Primitive(
            positions=P32,
            normals=-N32,
            texcoord_0=UV32,
            color_0=vcol if back is None else None,
            indices=I[:, ::-1].copy(),
            material=material(front_rgb if back is None else colour(back), tex if back is None else None),
        ),
    ]
    scene = pyrender.Scene(bg_color=[*map(float, bg), 1.0], ambient_light=[ambient] * 3)
    scene.add(pyrender.Mesh(primitives=prims))
    if floor:
        e1 = pose[:3, 0] - (pose[:3, 0] @ up_vec) * up_vec
        e1 = e1 / np.linalg.norm(e1) if np.linalg.norm(e1) > 1e-9 else np.cross(up_vec, [1.0, 0.0, 0.0])
        e2 = np.cross(up_vec, e1)
        fc = center - (center @ up_vec - floor_y) * up_vec
        r = 3.0 * diag
        FP = np.array([fc - r * e1 - r * e2, fc + r * e1 - r * e2, fc + r * e1 + r * e2, fc - r * e1 + r * e2])
        FT = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
        if np.dot(np.cross(FP[1] - FP[0], FP[2] - FP[0]), up_vec) < 0:
            FT = FT[:, ::-1].copy()
        floor_mat = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[*colour(np.array([0.93, 0.93, 0.93])), 1.0], metallicFactor=0.0, roughnessFactor=0.9
        )
        scene.add(
            pyrender.Mesh(
                primitives=[
                    pyrender.Primitive(
                        positions=FP.astype(np.float32),
                        normals=np.tile(up_vec, (4, 1)).astype(np.float32),
                        indices=FT,
                        material=floor_mat,
                    )
                ]
            )
        )
    scene.add(pyrender.PerspectiveCamera(yfov=fov, znear=znear, zfar=zfar, aspectRatio=w / h), pose=pose)

    # Lights.
    R = pose[:3, :3]
    flags = pyrender.RenderFlags.NONE
    if specs is None:
        for k, (dcam, inten) in enumerate((_KEY, _FILL, _RIM)):
            towards = R @ _unit(np.asarray(dcam, dtype=np.float64))
            if k == 0 and light == "directional":
                scene.add(pyrender.DirectionalLight(intensity=inten), pose=_frame_to_z(towards))
                if shadows:
                    flags |= pyrender.RenderFlags.SHADOWS_DIRECTIONAL
                continue
            # Fill and rim are far point lights (directional in effect) so only the key casts shadows:
            # pyrender's shadow flags apply to every light of a type, and each shadow costs a lot on llvmpipe.
            dist = 30.0 if k > 0 else 1.5 * float(np.linalg.norm(cam_pos - center)) + 1.0
            node_pose = _frame_to_z(towards)
            node_pose[:3, 3] = center + towards * dist
            if k > 0:
                scene.add(pyrender.PointLight(intensity=inten * dist**2), pose=node_pose)
                continue
            outer = float(min(np.arctan2(0.5, dist) * 1.6, np.radians(80.0)))
            scene.add(
                pyrender.SpotLight(intensity=inten * dist**2, innerConeAngle=0.6 * outer, outerConeAngle=outer),
                pose=node_pose,
            )
            if shadows:
                flags |= pyrender.RenderFlags.SHADOWS_SPOT
    else:
        for s in specs:
            if s["type"] == "directional":
                scene.add(
                    pyrender.DirectionalLight(color=s["color"], intensity=s["intensity"]),
                    pose=_frame_to_z(-s["direction"]),
                )
                if shadows:
                    flags |= pyrender.RenderFlags.SHADOWS_DIRECTIONAL
                continue
            pos = (s["position"] - c0) / s0
            aim = ((s["target"] - c0) / s0 if "target" in s else center) - pos
            if np.linalg.norm(aim) == 0:
                raise MeshError(f"{where}: a {s['type']} light sits exactly at its target")
            node_pose = _frame_to_z(-aim)
            node_pose[:3, 3] = pos
            # Irradiance falls off with squared distance, which the normalised frame divided by s0.
            inten = s["intensity"] / s0**2
            if s["type"] == "spot":
                lt = pyrender.SpotLight(
                    color=s["color"], intensity=inten, innerConeAngle=s["inner"], outerConeAngle=s["outer"]
                )
                if shadows:
                    flags |= pyrender.RenderFlags.SHADOWS_SPOT
            else:
                lt = pyrender.PointLight(color=s["color"], intensity=inten)
            scene.add(lt, pose=node_pose)
    if flat:
        flags |= pyrender.RenderFlags.FLAT

    r = offscreen_renderer(W, H)
    col, depth = r.render(scene, flags=flags)
    col = np.asarray(col[:, :, :3])

    if wire_opacity is None:
        wire_opacity = auto_wire_opacity(V, edges, (w, h), zoom=zoom) if edges is not None else 0.0
    if (edges is not None and edge_width > 0 and wire_opacity > 0) or (
        highlight_points is not None and point_radius > 0
    ):
        img = _overlay(
            col,
            np.asarray(depth),
            pose,
            fov,
            znear,
            diag,
            V=V,
            edges=edges if edge_width > 0 else None,
            wire_color=wire_rgb,
            line_px=edge_width * ss,
            wire_opacity=wire_opacity,
            points=highlight_points,
            point_color=point_rgb,
            point_px=2.0 * point_radius * ss,
        )
    else:
        img = col.astype(np.float32)
    if ss > 1:  # box filter: sum the ss*ss sub-pixel grids
        acc = np.zeros((h, w, 3), dtype=np.float32)
        for i in range(ss):
            for j in range(ss):
                acc += img[i::ss, j::ss]
        img = acc / (ss * ss)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


_OPTIONS_DOC = """
    colors : (n, 3) or (n, 4) array_like, optional
        Per-vertex colours, floats in [0, 1] or uint8 (alpha is ignored). They replace
        ``base_color``; lit shading multiplies them, so use ``flat=True`` to show them exactly.
    face_colors : (m, 3) or (m, 4) array_like, optional
        One colour per face (overrides ``colors``).
    uv : (n, 2) array_like, optional
        Per-vertex texture coordinates, ``(0, 0)`` at the bottom-left of ``texture``.
    texture : (h, w[, c]) array_like, optional
        Image (uint8 or floats in [0, 1]; grey, RGB or RGBA) mapped with ``uv``.
    normals : (n, 3) array_like, optional
        Per-vertex normals for smooth shading (default: area-weighted face normals).
    smooth : bool
        Smooth (per-vertex normal) shading; ``False`` shades each face with its own normal.
    crease_deg : float or None
        With smooth shading, edges whose faces meet at more than this angle stay sharp (the
        normals are split there, as in a cube); None smooths across every edge. Ignored when
        ``normals`` are given.
    flat : bool
        Unlit: show colours and textures exactly as given (no lights, no shadows).
    wireframe : bool
        Draw the mesh edges, depth-tested so hidden edges stay hidden.
    wire_color : RGB in [0, 1]
        Colour of the wireframe.
    edge_width : float
        Wireframe line width in output pixels.
    wire_opacity : float, optional
        Opacity of the wireframe, in [0, 1]. Default: :func:`auto_wire_opacity`, which fades the
        wireframe as edges get short on screen and drops it below about one pixel, so a dense
        mesh is not painted solid black.
    highlight_points : (k,) int array_like, optional
        Vertex indices to mark with dots (e.g. extraordinary vertices); hidden ones are not drawn.
    point_color : RGB in [0, 1]
        Colour of the dots.
    point_radius : float
        Dot radius in output pixels.
    camera : str or (eye, target, up) or (4, 4) array
        A preset of :data:`VIEWS` framing the mesh (see :func:`camera_pose`), a look-at triple, or
        a camera-to-world pose (camera looks down its -z axis).
    fov_deg : float
        Vertical field of view in degrees.
    size : (width, height)
        Output size in pixels.
    zoom : float
        For presets: > 1 moves the camera closer.
    up_axis : {"z", "y"}
        World up axis, for presets and the floor (the course's datasets are z-up).
    light : "directional", "spot" or list of dict
        ``"directional"``: camera-relative three-point lighting (key, fill, rim). ``"spot"``: the
        key light is a spot light. A list gives lights in world coordinates, each a dict with
        ``type`` (``"directional"``, ``"spot"``, ``"point"``), ``direction`` (directional: the way
        the light travels) or ``position`` (and optional ``target``, default the mesh centre),
        ``color``, ``intensity`` (point and spot lights fall off with distance squared) and, for
        spots, ``inner_cone_deg`` / ``outer_cone_deg``.
    ambient : float
        Ambient light intensity.
    shadows : bool
        Shadow-map directional and spot lights.
    floor : bool
        Add a light-grey ground plane under the mesh (to catch shadows).
    background : RGB in [0, 1]
        Background colour (floats; use uint8 arrays for 0..255).
    base_color : RGB in [0, 1]
        Surface colour when neither colours nor a texture are given.
    back_color : RGB in [0, 1], optional
        Colour of back faces (default: same as the front), e.g. to show orientation.
    roughness, metallic : float
        Material parameters (metallic-roughness PBR).
    supersample : int
        Render at this multiple of ``size`` and average down (anti-aliasing), 1..4.

    Returns
    -------
    (height, width, 3) uint8
        The image.

    Raises
    ------
    MeshError
        On invalid meshes, arrays or options.
    RuntimeError
        When no headless OpenGL platform works (the message names the fix).
"""


def auto_wire_opacity(V: np.ndarray, edges: np.ndarray, size: tuple[int, int], zoom: float = 1.0) -> float:
    """Wireframe opacity for a mesh drawn at ``size``: 1 when a typical edge spans >= 7 pixels, fading
    to 0 at about one pixel (the object is assumed to span ~80% of the shorter image side)."""
    if edges is None or len(edges) == 0:
        return 1.0
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) or 1.0
    typical = float(np.median(np.linalg.norm(V[edges[:, 0]] - V[edges[:, 1]], axis=1)))
    px = typical / diag * 0.8 * min(size) * zoom
    return float(np.clip((px - 1.0) / 6.0, 0.0, 1.0))


def render(
    V,
    F,
    *,
    colors=None,
    face_colors=None,
    uv=None,
    texture=None,
    normals=None,
    smooth: bool = True,
    crease_deg: float | None = 60.0,
    flat: bool = False,
    wireframe: bool = False,
    wire_color=DEFAULT_WIRE_COLOR,
    edge_width: float = 1.0,
    wire_opacity: float | None = None,
    highlight_points=None,
    point_color=(0.90, 0.12, 0.10),
    point_radius: float = 3.5,
    camera="three_quarter",
    fov_deg: float = 35.0,
    size: tuple[int, int] = (640, 480),
    zoom: float = 1.0,
    up_axis: str = "z",
    light="directional",
    ambient: float = _AMBIENT,
    shadows: bool = False,
    floor: bool = False,
    background=(1.0, 1.0, 1.0),
    base_color=DEFAULT_BASE_COLOR,
    back_color=None,
    roughness: float = 0.65,
    metallic: float = 0.0,
    supersample: int = 2,
) -> np.ndarray:
    where = "render"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    C, TC, UV, TEX, N, hp = _check_attributes(
        V, len(F), colors, face_colors, uv, texture, normals, highlight_points, where=where
    )
    tri_n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    vn = N if N is not None else _vertex_normals(len(V), F, tri_n)
    return _draw(
        V,
        F,
        where=where,
        tri_normals=tri_n,
        vert_normals=vn,
        user_normals=N is not None,
        crease_deg=crease_deg,
        edges=topology.unique_edges(F) if wireframe else None,
        colors=C,
        tri_colors=TC,
        uv=UV,
        texture=TEX,
        smooth=bool(smooth),
        flat=bool(flat),
        wire_color=wire_color,
        edge_width=edge_width,
        wire_opacity=wire_opacity,
        highlight_points=hp,
        point_color=point_color,
        point_radius=point_radius,
        camera=camera,
        fov_deg=fov_deg,
        size=size,
        zoom=zoom,
        up_axis=up_axis,
        light=light,
        ambient=ambient,
        shadows=bool(shadows),
        floor=bool(floor),
        background=background,
        base_color=base_color,
        back_color=back_color,
        roughness=roughness,
        metallic=metallic,
        supersample=supersample,
    )


render.__doc__ = (
    """Render a triangle mesh to an RGB image (headless, deterministic).

    Parameters
    ----------
    V : (n, 3) array_like
        Vertex positions.
    F : (m, 3) int array_like
        Triangles (degenerate and duplicate faces are drawn as they are)."""
    + _OPTIONS_DOC
    + """
    Examples
    --------
    >>> img = render(V, F, wireframe=True, camera="front", size=(320, 240))  # doctest: +SKIP
    """
)


def render_polygons(V, faces, **options) -> np.ndarray:
    """Render a polygon mesh; shading uses a fan triangulation, the wireframe the true polygon edges.

    Parameters
    ----------
    V : (n, 3) array_like
        Vertex positions.
    faces : (m, k) int array_like, list of index sequences, or ``(indices, offsets)``
        Polygons with at least 3 corners each (see :func:`geomlib.validate.as_polygons`).
    **options
        Every keyword of :func:`render`; ``face_colors`` has one row per polygon and flat shading
        uses one (Newell) normal per polygon.

    Returns
    -------
    (height, width, 3) uint8
    """
    where = "render_polygons"
    unknown = sorted(set(options) - set(render.__kwdefaults__))
    if unknown:
        raise MeshError(f"{where}: unknown option(s) {unknown}")
    opts = dict(render.__kwdefaults__)
    opts.update(options)
    if isinstance(faces, tuple) and len(faces) == 2 and all(isinstance(a, np.ndarray) and a.ndim == 1 for a in faces):
        faces = [faces[0][a:b] for a, b in zip(faces[1][:-1], faces[1][1:], strict=True)]
    V, idx, off = check_polygon_mesh(V, faces, where=where)
    m = len(off) - 1
    C, PC, UV, TEX, N, hp = _check_attributes(
        V,
        m,
        opts["colors"],
        opts["face_colors"],
        opts["uv"],
        opts["texture"],
        opts["normals"],
        opts["highlight_points"],
        where=where,
    )
    T, src = topology.triangulate_polygons((idx, off))
    # Newell normal of each polygon (twice its vector area), robust for non-planar polygons.
    lens = np.diff(off)
    nxt = np.arange(len(idx)) + 1
    nxt[off[1:] - 1] = off[:-1]
    a, b = V[idx], V[idx[nxt]]
    cr = np.cross(a, b)
    poly_n = np.add.reduceat(cr, off[:-1], axis=0) if m else np.zeros((0, 3))
    user_normals = N is not None
    if N is None:
        face_of = np.repeat(np.arange(m), lens)
        N = np.stack([np.bincount(idx, weights=poly_n[face_of, c], minlength=len(V)) for c in range(3)], axis=1)
    return _draw(
        V,
        T,
        where=where,
        tri_normals=poly_n[src] / np.maximum(lens - 2, 1)[src, None],  # each polygon weighs its area once
        vert_normals=N,
        user_normals=user_normals,
        crease_deg=opts["crease_deg"],
        edges=topology.unique_edges((idx, off)) if opts["wireframe"] else None,
        colors=C,
        tri_colors=PC[src] if PC is not None else None,
        uv=UV,
        texture=TEX,
        smooth=bool(opts["smooth"]),
        flat=bool(opts["flat"]),
        wire_color=opts["wire_color"],
        edge_width=opts["edge_width"],
        wire_opacity=opts["wire_opacity"],
        highlight_points=hp,
        point_color=opts["point_color"],
        point_radius=opts["point_radius"],
        camera=opts["camera"],
        fov_deg=opts["fov_deg"],
        size=opts["size"],
        zoom=opts["zoom"],
        up_axis=opts["up_axis"],
        light=opts["light"],
        ambient=opts["ambient"],
        shadows=bool(opts["shadows"]),
        floor=bool(opts["floor"]),
        background=opts["background"],
        base_color=opts["base_color"],
        back_color=opts["back_color"],
        roughness=opts["roughness"],
        metallic=opts["metallic"],
        supersample=opts["supersample"],
    )


def _check_attributes(V, m, colors, face_colors, uv, texture, normals, highlight_points, *, where):
    """Validate the optional per-vertex / per-face arrays shared by render and render_polygons."""
    n = len(V)
    C = _as_rgb(colors, "colors", where, n=n) if colors is not None else None
    FC = _as_rgb(face_colors, "face_colors", where, n=m, per="face") if face_colors is not None else None
    if (uv is None) != (texture is None):
        raise MeshError(f"{where}: uv and texture go together; got {'uv' if uv is not None else 'texture'} only")
    UV = TEX = None
    if uv is not None:
        UV = as_array(uv, "uv", shape=(None, 2), where=where)
        if len(UV) != n:
            raise MeshError(f"{where}: uv has {len(UV)} rows, expected {n} (one texture coordinate per vertex)")
        TEX = _as_texture(texture, where)
    N = None
    if normals is not None:
        N = as_array(normals, "normals", shape=(None, 3), where=where)
        if len(N) != n:
            raise MeshError(f"{where}: normals has {len(N)} rows, expected {n} (one normal per vertex)")
        zero = np.linalg.norm(N, axis=1) == 0
        if zero.any():
            raise MeshError(f"{where}: normals: row {int(np.flatnonzero(zero)[0])} is the zero vector")
    hp = None
    if highlight_points is not None:
        hp = as_array(highlight_points, "highlight_points", dtype=np.int64, where=where).ravel()
        if hp.size and (hp.min() < 0 or hp.max() >= n):
            bad = int(hp[(hp < 0) | (hp >= n)][0])
            raise MeshError(f"{where}: highlight_points has vertex index {bad}, valid indices are 0..{n - 1}")
    return C, FC, UV, TEX, N, hp
