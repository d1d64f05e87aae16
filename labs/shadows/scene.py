"""Scenes, cameras and lights for the shadow-mapping lab (given code).

A :class:`Scene` is several meshes concatenated into one triangle soup ``(V, F)`` (what the depth
pass rasterizes), with one colour per face and one shading normal per vertex. Flat-shaded meshes
(boxes) are *unwelded* first, so each face has its own three vertices and its own normal; smooth
meshes (spheres, tori) keep their shared vertices and get area-weighted vertex normals.

The course's datasets are z-up, and so are the scenes here: the floor is the plane ``z = 0``.

Cameras are ``(eye, target)`` or ``(eye, target, up)`` triples (world coordinates, see
:func:`geomlib.camera.look_at`). Lights are small dicts:

* ``{"type": "directional", "direction": (dx, dy, dz)}``: parallel rays travelling along ``direction``;
* ``{"type": "spot", "position": p, "target": t, "fov_deg": 60}``: a perspective light at ``p``;
* ``{"type": "point", "position": p}``: light in every direction (six-face cube map).

A bare 3-vector is read as a directional light's direction.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from geomlib import datasets
from geomlib.geometry import face_normals, vertex_normals
from geomlib.validate import MeshError, as_array, check_float, check_mesh

__all__ = [
    "Scene",
    "make_scene",
    "as_scene",
    "as_camera",
    "as_light",
    "classic_scene",
    "torus_scene",
    "CLASSIC_CAMERA",
    "CLASSIC_LIGHT",
]


@dataclass(eq=False)
class Scene:
    """Meshes concatenated into one triangle soup, with colours and shading normals.

    Attributes
    ----------
    V : (n, 3) float64
        Vertex positions (world, z up).
    F : (m, 3) int64
        Triangles of all meshes, counter-clockwise seen from outside.
    face_colors : (m, 3) float64
        Albedo of each face, RGB in [0, 1].
    normals : (n, 3) float64
        Unit shading normals per vertex (face normals for flat meshes, which are unwelded).
    mesh_id : (m,) int64
        Which input mesh each face came from.
    """

    V: np.ndarray
    F: np.ndarray
    face_colors: np.ndarray
    normals: np.ndarray
    mesh_id: np.ndarray

    @property
    def bounds(self) -> np.ndarray:
        """``(2, 3)`` array ``[min corner, max corner]`` of the vertices."""
        return np.array([self.V.min(axis=0), self.V.max(axis=0)])

    def __repr__(self) -> str:
        return f"Scene({len(self.V)} vertices, {len(self.F)} faces, {int(self.mesh_id.max()) + 1} meshes)"


def _unweld(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return V[F.ravel()], np.arange(3 * len(F), dtype=np.int64).reshape(-1, 3)


def make_scene(meshes: Sequence) -> Scene:
    """Concatenate meshes into a :class:`Scene`.

    Parameters
    ----------
    meshes : sequence of tuples
        Each ``(V, F)``, ``(V, F, color)`` or ``(V, F, color, smooth)``: a triangle mesh, its RGB
        colour in [0, 1] (default light grey) and whether to shade it smoothly (default False:
        flat faces, right for boxes and floors).

    Returns
    -------
    Scene
    """
    where = "make_scene"
    if isinstance(meshes, tuple) and len(meshes) >= 2 and isinstance(meshes[0], np.ndarray) and meshes[0].ndim == 2:
        meshes = [meshes]  # a single (V, F, ...) tuple
    if not isinstance(meshes, Sequence) or len(meshes) == 0:
        raise MeshError(f"{where}: meshes must be a non-empty list of (V, F[, color[, smooth]]) tuples")
    Vs, Fs, Cs, Ns, ids = [], [], [], [], []
    offset = 0
    for i, item in enumerate(meshes):
        if not isinstance(item, Sequence) or not 2 <= len(item) <= 4:
            raise MeshError(
                f"{where}: meshes[{i}] must be a tuple (V, F[, color[, smooth]]), got {type(item).__name__}"
            )
        V, F = check_mesh(item[0], item[1], where=f"{where}: meshes[{i}]", allow_duplicate=True)
        color = as_array(item[2] if len(item) > 2 else (0.8, 0.8, 0.8), f"meshes[{i}] color", shape=(3,), where=where)
        if color.min() < 0 or color.max() > 1:
            raise MeshError(f"{where}: meshes[{i}] color {tuple(color)} must lie in [0, 1]")
        smooth = bool(item[3]) if len(item) > 3 else False
        if smooth:
            N = vertex_normals(V, F)
        else:
            fn = face_normals(V, F)
            V, F = _unweld(V, F)
            N = np.repeat(fn, 3, axis=0)
        Vs.append(V)
        Fs.append(F + offset)
        Cs.append(np.tile(color, (len(F), 1)))
        Ns.append(N)
        ids.append(np.full(len(F), i, np.int64))
        offset += len(V)
    return Scene(np.vstack(Vs), np.vstack(Fs), np.vstack(Cs), np.vstack(Ns), np.concatenate(ids))


def as_scene(scene, where: str = "as_scene") -> Scene:
    """A :class:`Scene` from a Scene, a list of mesh tuples (see :func:`make_scene`) or a ``(V, F)`` pair."""
    if isinstance(scene, Scene):
        return scene
    if hasattr(scene, "V") and hasattr(scene, "F") and hasattr(scene, "face_colors"):  # a Scene sent by value
        return Scene(
            np.asarray(scene.V, float),
            np.asarray(scene.F, np.int64),
            np.asarray(scene.face_colors, float),
            np.asarray(scene.normals, float),
            np.asarray(scene.mesh_id, np.int64),
        )
    try:
        return make_scene(scene)
    except MeshError as e:
        raise MeshError(f"{where}: scene must be a Scene or a list of (V, F[, color[, smooth]]) meshes ({e})") from None


def as_camera(camera, where: str = "as_camera") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(eye, target, up)`` from an ``(eye, target)`` or ``(eye, target, up)`` triple; default up is +z."""
    if not isinstance(camera, Sequence | np.ndarray) or len(camera) not in (2, 3):
        raise MeshError(f"{where}: camera must be (eye, target) or (eye, target, up), got {camera!r}")
    eye = as_array(camera[0], "camera eye", shape=(3,), where=where)
    target = as_array(camera[1], "camera target", shape=(3,), where=where)
    up = as_array(camera[2], "camera up", shape=(3,), where=where) if len(camera) == 3 else np.array([0.0, 0, 1])
    return eye, target, up


def as_light(light, where: str = "as_light") -> dict:
    """A validated light dict (see the module docstring); a bare 3-vector is a directional light."""
    if not isinstance(light, dict):
        try:
            d = np.asarray(light, dtype=float)
        except (TypeError, ValueError):
            d = None
        if d is None or d.shape != (3,):
            raise MeshError(f"{where}: light must be a dict with a 'type' or a direction 3-vector, got {light!r}")
        light = {"type": "directional", "direction": d}
    kind = light.get("type")
    out: dict = {"type": kind}
    if kind == "directional":
        d = as_array(light.get("direction"), "light['direction']", shape=(3,), where=where)
        if not np.linalg.norm(d) > 0:
            raise MeshError(f"{where}: light['direction'] is the zero vector")
        out["direction"] = d / np.linalg.norm(d)
    elif kind in ("spot", "point"):
        out["position"] = as_array(light.get("position"), "light['position']", shape=(3,), where=where)
        if kind == "spot":
            out["target"] = as_array(light.get("target"), "light['target']", shape=(3,), where=where)
            if np.array_equal(out["target"], out["position"]):
                raise MeshError(f"{where}: the spot light's position and target coincide")
            out["fov_deg"] = check_float(light.get("fov_deg", 60.0), "light['fov_deg']", where=where)
            if not 0 < out["fov_deg"] < 180:
                raise MeshError(f"{where}: light['fov_deg'] must be strictly between 0 and 180, got {out['fov_deg']}")
    else:
        raise MeshError(f"{where}: light['type'] must be 'directional', 'spot' or 'point', got {kind!r}")
    return out


# --------------------------------------------------------------------------------------------
# Built-in scenes


def _box(size, centre, n: int = 2, angle_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    V, F = datasets.sharp_box(size, n=n)
    a = np.radians(angle_deg)
    R = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    return V @ R.T + np.asarray(centre, float), F


def _floor(half: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    V, F = datasets.grid_patch(n, 2 * half)
    return V - np.array([half, half, 0.0]), F


def classic_scene(floor_cells: int = 16, sphere_level: int = 3) -> Scene:
    """The classic shadow-mapping test scene (z up).

    A 6 x 6 floor at ``z = 0`` (single-sided, facing up), two boxes standing on it, a cube floating
    above it and a sphere resting on it (a curved surface, where acne shows first).

    Parameters
    ----------
    floor_cells : int
        Grid cells per side of the floor.
    sphere_level : int
        Subdivision level of the icosphere.
    """
    sphere_V, sphere_F = datasets.icosphere(sphere_level, radius=0.55)
    return make_scene(
        [
            (*_floor(3.0, floor_cells), (0.86, 0.86, 0.82)),
            (*_box((1.0, 1.0, 1.0), (1.1, -0.7, 0.5), angle_deg=20.0), (0.85, 0.45, 0.30)),
            (*_box((0.6, 0.6, 1.6), (-1.2, 0.9, 0.8)), (0.35, 0.55, 0.85)),
            (*_box((0.7, 0.7, 0.7), (-1.5, -1.3, 1.5), angle_deg=35.0), (0.45, 0.75, 0.45)),
            (sphere_V + np.array([0.9, 1.2, 0.55]), sphere_F, (0.90, 0.80, 0.35), True),
        ]
    )


#: Camera ``(eye, target, up)`` that frames :func:`classic_scene`.
CLASSIC_CAMERA = (np.array([3.9, -4.8, 3.4]), np.array([-0.2, 0.3, 0.4]), np.array([0.0, 0.0, 1.0]))

#: Directional light of the classic scene: low enough for long shadows.
CLASSIC_LIGHT = {"type": "directional", "direction": np.array([0.45, 0.55, -0.70])}


def torus_scene(n_major: int = 250, n_minor: int = 100, bumps: float = 0.03) -> Scene:
    """A bumpy torus standing above a floor: a curved, self-shadowing surface (acne test).

    ``2 n_major n_minor + 2`` faces (50,002 with the defaults).
    """
    V, F = datasets.torus(1.0, 0.35, n_major, n_minor)
    j, i = np.divmod(np.arange(len(V)), n_major)
    u, v = 2 * np.pi * i / n_major, 2 * np.pi * j / n_minor
    # Move each vertex along its tube normal: r(u, v) = 0.35 + bumps sin(7u) sin(5v).
    ring = np.stack([np.cos(u), np.sin(u), np.zeros_like(u)], axis=1)
    tube_n = np.cos(v)[:, None] * ring + np.sin(v)[:, None] * np.array([0.0, 0.0, 1.0])
    V = V + (bumps * np.sin(7 * u) * np.sin(5 * v))[:, None] * tube_n
    # Stand it up (tube axis from z to y) and lift it above the floor.
    R = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    V = V @ R.T + np.array([0.0, 0.0, 1.5])
    floor = (np.array([[-3.0, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    return make_scene([(*floor, (0.86, 0.86, 0.82)), (V, F, (0.80, 0.62, 0.45), True)])
