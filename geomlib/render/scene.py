"""The pyrender scene of one render: the normalised frame, depth range, surface, floor and camera.

Everything happens in a normalised frame (mesh centred, bounding-box diagonal 1): pyrender's
shadow-map bias and clip planes are absolute numbers, so this makes shadows behave the same at
every mesh scale.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.render.shading import crease_normals, srgb_to_linear, unit

__all__ = ["Surface", "Frame", "normalised_frame", "add_surface", "add_floor"]


@dataclass(frozen=True)
class Surface:
    """A checked triangle mesh and its attributes, ready to draw (built by render / render_polygons).

    ``T`` are the triangles drawn (a fan triangulation for polygon meshes), ``tri_normals`` their
    unnormalised normals (twice the area, or the polygon's Newell normal share), ``edges`` the
    wireframe edges (the true polygon edges) or None, ``tri_colors`` one colour per triangle.
    """

    V: np.ndarray
    T: np.ndarray
    tri_normals: np.ndarray
    vert_normals: np.ndarray
    user_normals: bool
    edges: np.ndarray | None
    colors: np.ndarray | None
    tri_colors: np.ndarray | None
    uv: np.ndarray | None
    texture: np.ndarray | None
    highlight_points: np.ndarray | None


@dataclass(frozen=True)
class Frame:
    """The normalised frame ``x -> (x - c0) / s0`` and the camera's depth range in it."""

    V: np.ndarray  # vertices in the normalised frame
    pose: np.ndarray  # camera-to-world pose in the normalised frame
    c0: np.ndarray
    s0: float
    lo: np.ndarray
    center: np.ndarray
    diag: float
    fwd: np.ndarray  # unit viewing direction
    znear: float
    zfar: float
    floor_y: float


def normalised_frame(V: np.ndarray, pose: np.ndarray, *, floor: bool, up_vec: np.ndarray) -> Frame:
    """Move the mesh and camera into the normalised frame; choose tight near/far planes."""
    lo, hi = V.min(axis=0), V.max(axis=0)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    center = (lo + hi) / 2
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
    return Frame(V, pose, c0, s0, lo, center, diag, fwd, znear, zfar, floor_y)


def add_surface(scene, pyrender, s: Surface, V: np.ndarray, fwd: np.ndarray, *, smooth, flat, crease_deg, chk) -> None:
    """Add the mesh (front faces and a reversed back-face copy) with its material to the scene."""
    # Per-corner arrays when anything is per face; indexed vertices otherwise.
    T = s.T
    corner_n = None
    if not smooth:
        corner_n = np.repeat(s.tri_normals, 3, axis=0)
    elif not s.user_normals and crease_deg is not None and crease_deg < 180.0:
        corner_n = crease_normals(T, s.tri_normals, s.vert_normals, crease_deg)
    per_corner = corner_n is not None or s.tri_colors is not None
    if per_corner:
        idx = T.ravel()
        P = V[idx]
        N = unit(corner_n) if corner_n is not None else unit(s.vert_normals)[idx]
        C = (
            np.repeat(s.tri_colors, 3, axis=0)
            if s.tri_colors is not None
            else (s.colors[idx] if s.colors is not None else None)
        )
        UV = s.uv[idx] if s.uv is not None else None
        I = np.arange(len(idx), dtype=np.uint32).reshape(-1, 3)
    else:
        P, N, C, UV, I = V, unit(s.vert_normals), s.colors, s.uv, T.astype(np.uint32)
    N = np.where(np.linalg.norm(N, axis=1, keepdims=True) > 0.5, N, -fwd)  # degenerate faces face the camera

    def colour(c):  # lit shading works in linear space; the unlit shader writes colours as given
        return c if flat else srgb_to_linear(c)

    tex = pyrender.Texture(source=s.texture, source_channels="RGB") if s.texture is not None else None

    def material(rgb, tex):
        kw = {} if tex is None else {"baseColorTexture": tex}
        return pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[*map(float, rgb), 1.0],
            metallicFactor=chk.metallic,
            roughnessFactor=chk.roughness,
            doubleSided=False,
            **kw,
        )

    back = chk.back
    vcol = None
    front_rgb = colour(chk.base)
    if C is not None:
        vcol = np.hstack([colour(C), np.ones((len(C), 1))]).astype(np.float32)
        front_rgb = np.ones(3)
    if s.texture is not None:
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
    scene.add(pyrender.Mesh(primitives=prims))


def add_floor(scene, pyrender, fr: Frame, up_vec: np.ndarray, *, flat: bool) -> None:
    """A light-grey square ground plane under the mesh, facing up, to catch shadows."""
    pose, center, diag = fr.pose, fr.center, fr.diag
    e1 = pose[:3, 0] - (pose[:3, 0] @ up_vec) * up_vec
    e1 = e1 / np.linalg.norm(e1) if np.linalg.norm(e1) > 1e-9 else np.cross(up_vec, [1.0, 0.0, 0.0])
    e2 = np.cross(up_vec, e1)
    fc = center - (center @ up_vec - fr.floor_y) * up_vec
    r = 3.0 * diag
    FP = np.array([fc - r * e1 - r * e2, fc + r * e1 - r * e2, fc + r * e1 + r * e2, fc - r * e1 + r * e2])
    FT = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    if np.dot(np.cross(FP[1] - FP[0], FP[2] - FP[0]), up_vec) < 0:
        FT = FT[:, ::-1].copy()
    grey = np.array([0.93, 0.93, 0.93])
    floor_mat = pyrender.MetallicRoughnessMaterial(
        baseColorFactor=[*(grey if flat else srgb_to_linear(grey)), 1.0], metallicFactor=0.0, roughnessFactor=0.9
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
