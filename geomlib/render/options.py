"""Rendering options as one object: :class:`RenderOptions`, and the checks on its values.

Every option of :func:`geomlib.render.render` and :func:`geomlib.render.render_polygons` is a field
here, spelled and documented once; the functions take a ``RenderOptions`` and/or the same names as
keywords (``render(V, F, wireframe=True)`` or ``render(V, F, opts, size=(320, 240))``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field, fields

import numpy as np

from geomlib.camera import AXES, VIEWS
from geomlib.validate import MeshError, as_array, as_image, check_choice, check_float, check_int

__all__ = ["RenderOptions", "DEFAULT_BASE_COLOR", "DEFAULT_WIRE_COLOR", "AMBIENT"]

#: Default surface colour (sRGB, 0..1): a soft light grey-blue.
DEFAULT_BASE_COLOR = (0.74, 0.80, 0.90)
#: Default wireframe colour (sRGB, 0..1).
DEFAULT_WIRE_COLOR = (0.10, 0.11, 0.16)
#: Default ambient light intensity.
AMBIENT = 0.25


@dataclass(frozen=True)
class RenderOptions:
    """Everything about how a mesh is drawn (the mesh itself is passed separately).

    Attributes
    ----------
    colors : (n, 3) or (n, 4) array_like, optional
        Per-vertex colours, floats in [0, 1] or uint8 (alpha is ignored). They replace
        ``base_color``; lit shading multiplies them, so use ``flat=True`` to show them exactly.
    face_colors : (m, 3) or (m, 4) array_like, optional
        One colour per face (overrides ``colors``); for polygon meshes one row per polygon.
    uv : (n, 2) array_like, optional
        Per-vertex texture coordinates, ``(0, 0)`` at the bottom-left of ``texture``.
    texture : (h, w[, c]) array_like, optional
        Image (uint8 or floats in [0, 1]; grey, RGB or RGBA) mapped with ``uv``.
    normals : (n, 3) array_like, optional
        Per-vertex normals for smooth shading (default: area-weighted face normals).
    smooth : bool
        Smooth (per-vertex normal) shading; ``False`` shades each face with its own normal
        (polygon meshes: one Newell normal per polygon).
    crease_deg : float or None
        With smooth shading, edges whose faces meet at more than this angle stay sharp (the
        normals are split there, as in a cube); None smooths across every edge. Ignored when
        ``normals`` are given.
    flat : bool
        Unlit: show colours and textures exactly as given (no lights, no shadows).
    wireframe : bool
        Draw the mesh edges (polygon meshes: the true polygon edges), depth-tested so hidden
        edges stay hidden.
    wire_color : RGB in [0, 1]
        Colour of the wireframe.
    edge_width : float
        Wireframe line width in output pixels.
    wire_opacity : float, optional
        Opacity of the wireframe, in [0, 1]. Default: :func:`geomlib.render.auto_wire_opacity`,
        which fades the wireframe as edges get short on screen and drops it below about one
        pixel, so a dense mesh is not painted solid black.
    highlight_points : (k,) int array_like, optional
        Vertex indices to mark with dots (e.g. extraordinary vertices); hidden ones are not drawn.
    point_color : RGB in [0, 1], or (k, 3) array_like
        Colour of the dots: one for all, or one per entry of ``highlight_points`` (e.g. a dot's
        colour telling its valence).
    point_radius : float
        Dot radius in output pixels.
    highlight_lines : (k, 2, 3) array_like, optional
        Line segments (world positions of their two ends, need not be mesh edges) drawn
        depth-tested on top, e.g. an outline or the sharp edges of another mesh.
    line_color : RGB in [0, 1]
        Colour of ``highlight_lines``.
    line_width : float
        Width of ``highlight_lines`` in pixels.
    camera : str or (eye, target, up) or (4, 4) array
        A view of :data:`geomlib.camera.VIEWS` framing the mesh (see
        :func:`geomlib.render.camera_pose`), a look-at triple, or a camera-to-world pose (camera
        looks down its -z axis; :func:`geomlib.camera.pose_from_view` turns a view matrix into one).
    fov_deg : float
        Vertical field of view in degrees.
    size : (width, height)
        Output size in pixels.
    zoom : float
        For presets: > 1 moves the camera closer.
    up_axis : {"z", "y"}
        World up axis, for presets and the floor (the course's datasets are z-up).
    forward : one of :data:`geomlib.camera.AXES`, optional
        The way the model faces, for presets (default ``-y`` when z is up, ``+z`` when y is up;
        see :func:`geomlib.camera.view_frame`).
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

    Examples
    --------
    >>> from geomlib.render import RenderOptions
    >>> opts = RenderOptions(wireframe=True, size=(320, 240))
    >>> opts.replace(camera="front").camera
    'front'
    """

    colors: object = None
    face_colors: object = None
    uv: object = None
    texture: object = None
    normals: object = None
    smooth: bool = True
    crease_deg: float | None = 60.0
    flat: bool = False
    wireframe: bool = False
    wire_color: object = DEFAULT_WIRE_COLOR
    edge_width: float = 1.0
    wire_opacity: float | None = None
    highlight_points: object = None
    point_color: object = (0.90, 0.12, 0.10)
    point_radius: float = 3.5
    highlight_lines: object = None
    line_color: object = (0.05, 0.55, 0.25)
    line_width: float = 2.5
    camera: object = "three_quarter"
    fov_deg: float = 35.0
    size: tuple[int, int] = (640, 480)
    zoom: float = 1.0
    up_axis: str = "z"
    forward: str | None = None
    light: object = "directional"
    ambient: float = AMBIENT
    shadows: bool = False
    floor: bool = False
    background: object = (1.0, 1.0, 1.0)
    base_color: object = DEFAULT_BASE_COLOR
    back_color: object = None
    roughness: float = 0.65
    metallic: float = 0.0
    supersample: int = 2

    def replace(self, **changes) -> RenderOptions:
        """A copy with some options changed (unknown names raise :class:`MeshError`)."""
        return dataclasses.replace(self, **_known(changes, "RenderOptions.replace"))

    @classmethod
    def build(cls, options: RenderOptions | None, overrides: dict, where: str) -> RenderOptions:
        """``options`` (or the defaults) with keyword ``overrides`` applied, names checked."""
        if options is not None and not isinstance(options, RenderOptions):
            raise MeshError(f"{where}: options must be a RenderOptions, got {type(options).__name__}")
        base = options if options is not None else cls()
        return dataclasses.replace(base, **_known(overrides, where)) if overrides else base


NAMES = tuple(f.name for f in fields(RenderOptions))


def _known(changes: dict, where: str) -> dict:
    unknown = sorted(set(changes) - set(NAMES))
    if unknown:
        raise MeshError(f"{where}: unknown option(s) {unknown}")
    return changes


@dataclass(frozen=True)
class Checked:
    """The scalar and colour options of a :class:`RenderOptions`, validated and converted.

    Per-vertex and per-face arrays are checked against the mesh by the caller; lights by
    :mod:`geomlib.render.lights`.
    """

    width: int
    height: int
    ss: int
    fov: float  # radians
    ambient: float
    roughness: float
    metallic: float
    edge_width: float
    wire_opacity: float | None
    point_radius: float
    crease_deg: float | None
    background: np.ndarray
    base: np.ndarray
    back: np.ndarray | None
    wire_rgb: np.ndarray
    point_rgb: np.ndarray
    up_vec: np.ndarray = field(repr=False, default=None)


def check_options(o: RenderOptions, where: str) -> Checked:
    """Validate the scalar and colour options (clear :class:`MeshError` on the first bad one)."""
    w, h = _check_size(o.size, where)
    ss = check_int(o.supersample, "supersample", minimum=1, maximum=4, where=where)
    fov = np.radians(check_float(o.fov_deg, "fov_deg", minimum=1.0, maximum=170.0, where=where))
    check_choice(o.up_axis, "up_axis", ("y", "z"), where=where)
    if o.forward is not None:
        check_choice(o.forward, "forward", AXES, where=where)
    ambient = check_float(o.ambient, "ambient", minimum=0.0, where=where)
    roughness = check_float(o.roughness, "roughness", minimum=0.0, maximum=1.0, where=where)
    metallic = check_float(o.metallic, "metallic", minimum=0.0, maximum=1.0, where=where)
    edge_width = check_float(o.edge_width, "edge_width", minimum=0.0, maximum=50.0, where=where)
    wire_opacity = o.wire_opacity
    if wire_opacity is not None:
        wire_opacity = check_float(wire_opacity, "wire_opacity", minimum=0.0, maximum=1.0, where=where)
    point_radius = check_float(o.point_radius, "point_radius", minimum=0.0, maximum=100.0, where=where)
    crease_deg = o.crease_deg
    if crease_deg is not None:
        crease_deg = check_float(crease_deg, "crease_deg", minimum=0.0, maximum=180.0, where=where)
    if isinstance(o.camera, str):
        check_choice(o.camera, "camera", tuple(VIEWS), where=where)
    return Checked(
        width=w,
        height=h,
        ss=ss,
        fov=fov,
        ambient=ambient,
        roughness=roughness,
        metallic=metallic,
        edge_width=edge_width,
        wire_opacity=wire_opacity,
        point_radius=point_radius,
        crease_deg=crease_deg,
        background=_as_rgb(o.background, "background", where),
        base=_as_rgb(o.base_color, "base_color", where),
        back=_as_rgb(o.back_color, "back_color", where) if o.back_color is not None else None,
        wire_rgb=_as_rgb(o.wire_color, "wire_color", where),
        point_rgb=_point_rgb(o.point_color, where),
        up_vec=np.array([0.0, 1.0, 0.0]) if o.up_axis == "y" else np.array([0.0, 0.0, 1.0]),
    )


def _check_size(size, where: str) -> tuple[int, int]:
    if not isinstance(size, Sequence) or len(size) != 2:
        raise MeshError(f"{where}: size must be (width, height) in pixels, got {size!r}")
    w = check_int(size[0], "size[0] (width)", minimum=1, maximum=8192, where=where)
    h = check_int(size[1], "size[1] (height)", minimum=1, maximum=8192, where=where)
    return w, h


def _point_rgb(c, where: str) -> np.ndarray:
    """``point_color``: one colour, or one per highlighted point (rows checked against them when drawn)."""
    if np.ndim(c) == 2:
        return _as_rgb(c, "point_color", where, n=np.shape(c)[0], per="highlighted point")
    return _as_rgb(c, "point_color", where)


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
