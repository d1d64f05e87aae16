"""Anchor libraries set up once: the benchmarks time them, the solution cross-checks compare with them.

``tests/solutions`` imports these (pytest's ``pythonpath`` puts the project root on ``sys.path``), so a
benchmark and a cross-check of the same lab measure against the same set-up.
"""

from __future__ import annotations

import numpy as np


def pixel_centres(n: int) -> np.ndarray:
    """``(n * n, 2)`` centres ``(x, y)`` of an ``n x n`` pixel grid on the unit square, row by row."""
    c = (np.arange(n) + 0.5) / n
    y, x = np.meshgrid(c, c, indexing="ij")
    return np.c_[x.ravel(), y.ravel()]


def pot_transport_map(field: np.ndarray) -> tuple[np.ndarray, float]:
    """POT's exact optimal transport (``ot.emd``) from uniform mass on the pixel centres to ``field``.

    Parameters
    ----------
    field : (n, n) array of float >= 0
        Target density per pixel (normalised here), row 0 at y = 0.5 / n.

    Returns
    -------
    T : (n * n, 2) float64
        The barycentric projection of the exact plan: where each pixel centre of
        :func:`pixel_centres` goes.
    cost : float
        The transport cost, the squared Wasserstein distance W2^2.
    """
    import ot

    n = field.shape[0]
    X = pixel_centres(n)
    a = np.full(n * n, 1.0 / n**2)
    b = field.ravel() / field.sum()
    M = ot.dist(X, X)
    plan = ot.emd(a, b, M, numItermax=10**7)
    return plan @ X / a[:, None], float((plan * M).sum())


def pyrender_normal_mapped_mesh(V, F, UV, N, tangents, normal_map, *, base_color, roughness: float):
    """A pyrender mesh shaded through a tangent-space normal map (glTF's route to what the maps lab does).

    Parameters
    ----------
    V, F, UV, N : (n, 3), (m, 3), (n, 2), (n, 3) arrays
        Positions, triangles, texture coordinates and vertex normals.
    tangents : (n, 4) array
        Tangent ``xyz`` and handedness ``w``, glTF's ``TANGENT``.
    normal_map : (h, w, 3) uint8 array
        The encoded normal map.
    base_color : (r, g, b) floats in [0, 1]
    roughness : float
        Metallic 0, this roughness (pyrender's PBR model).
    """
    from geomlib.render import import_pyrender  # headless platform + the project's one NumPy-2 shim

    pyrender = import_pyrender()
    material = pyrender.MetallicRoughnessMaterial(
        baseColorFactor=[*map(float, base_color), 1.0],
        metallicFactor=0.0,
        roughnessFactor=roughness,
        normalTexture=pyrender.Texture(source=normal_map, source_channels="RGB"),
    )
    primitive = pyrender.Primitive(
        positions=np.asarray(V, np.float32),
        normals=np.asarray(N, np.float32),
        texcoord_0=np.asarray(UV, np.float32),
        tangents=np.asarray(tangents, np.float32),
        indices=np.asarray(F, np.uint32),
        material=material,
    )
    return pyrender.Mesh([primitive])


def pyrender_mesh_frame(V, F, pose, size: int):
    """A call that draws the mesh ``(V, F)`` with pyrender at ``size`` x ``size`` from ``pose = (eye, target)``
    (z up, 40 degrees, one directional light), building and uploading the mesh in the call: its vertices
    change every frame, as a displaced or denoised mesh's do. Returns the function (``color, depth``)."""
    import trimesh

    from geomlib import camera
    from geomlib import render as grender

    pyrender = grender.import_pyrender()
    renderer = grender.offscreen_renderer(size, size)
    view = camera.look_at(pose[0], pose[1], (0, 0, 1))
    light = np.linalg.inv(camera.look_at((1.0, -1.0, 2.0), (0, 0, 0), (0, 0, 1)))
    cam = pyrender.PerspectiveCamera(yfov=np.radians(40), aspectRatio=1.0, znear=0.5, zfar=10.0)

    def frame():
        scene = pyrender.Scene(bg_color=[1.0, 1.0, 1.0, 1.0], ambient_light=[0.1] * 3)
        scene.add(pyrender.Mesh.from_trimesh(trimesh.Trimesh(V, F, process=False), smooth=True))
        scene.add(cam, pose=np.linalg.inv(view))
        scene.add(pyrender.DirectionalLight(intensity=3.0), pose=light)
        return renderer.render(scene)

    return frame
