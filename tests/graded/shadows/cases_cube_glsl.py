"""Stored NumPy references for the point light's GLSL route (tasks 11-12), public and hidden.

``shaders/cube_depth.vert`` + ``cube_depth.frag`` (Task 11) are graded against the lab's given NumPy
linear cube pass :func:`cube_distance_maps` (Task 8's window-depth maps turned into distance / far),
drawn through face matrices stored from Task 8's :func:`cube_light_matrices`; ``shaders/cube_shadow.frag``
(Task 12) per pixel of the eye view of ``cases_glsl.py`` against :func:`linear_point_shadow_visibility`
on a stored linear cube map. ``geomlib refs build`` stores every output once (the ``STORED`` entries,
added to ``cases.py``'s and ``cases_hidden.py``'s lists); nothing is computed here.

The lights stand off the planes of the scene's faces: a receiver plane through the light puts its
points exactly on a texel border of its face, where the NumPy route's matrix product and the shader's
cube-map table may round to different texels (the handout's section 1.9).
"""

from __future__ import annotations

import numpy as np

from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input

from .cases_glsl import eye_points
from .support import MapClose, box, concat, small_scene

CUBE_POS = np.array([0.2, -0.3, 2.6])  # the NumPy cube-map cases' light (cases.py)
#: key -> (position, near, far): the point lights of the GLSL cube cases.
LIGHTS = {
    "a": (CUBE_POS, 0.2, 12.0),
    "b": (np.array([-1.1, 0.7, 1.3]), 0.1, 8.0),
    "b-short": (np.array([-1.1, 0.7, 1.3]), 0.1, 3.0),  # its far plane cuts the floor and the boxes
    "c": (np.array([1.3, 1.7, 3.1]), 0.25, 10.0),
    "d": (np.array([-0.3, -1.9, 0.9]), 0.15, 9.0),
    "room": (np.array([0.23, -0.11, 1.52]), 0.1, 6.0),
    "room2": (np.array([-0.37, 0.41, 0.93]), 0.1, 7.0),
}
#: A light and a far plane with few binary digits, so that P - light is exact in float32 and float64 alike.
LIGHTS["ties"] = (np.array([0.25, -0.125, 1.5]), 0.125, 4.0)
#: key -> (centre, half extents): the rooms the "room" lights stand in (room_scene).
ROOMS = {
    "room": (np.array([0.1, -0.2, 1.4]), np.array([2.1, 1.8, 1.5])),
    "room2": (np.array([-0.2, 0.3, 1.1]), np.array([1.7, 2.2, 1.3])),
}
#: Points a side of each wall's grid in room_points.
ROOM_GRID = 24


def room_scene(key: str):
    """A closed box room around light ``key`` and six slabs between the light and its walls, one per cube face
    direction, each off the face's centre and longer one way than the other: every face of the light's cube
    map holds both lit and shadowed wall points, and a mirrored, flipped or transposed face shows."""
    c, h = ROOMS[key]
    parts = [box(2 * h, c, n=2)]
    for a in range(3):
        for s in (1, -1):
            off = np.roll(np.array([0.21, -0.16, 0.12]), a) * h
            off[a] = s * 0.55 * h[a]
            size = np.roll(np.array([0.12, 0.55, 0.3]), a) * h * 0.8
            size[a] = 0.1 * h[a]
            parts.append(box(size, c + off, n=1))
    return concat(*parts)


def room_points(key: str):
    """``(mask, P, N)``: a ROOM_GRID² grid on the inner 90% of each of the room's six walls (+x, -x, +y, -y, +z, -z
    side by side, a ROOM_GRID x 6 ROOM_GRID picture, all covered), off the cube map's texel grid; N into the room."""
    c, h = ROOMS[key]
    n = ROOM_GRID
    g = (np.arange(n) + 0.5) / n * 1.8 - 0.9 + 0.0137
    Ps, Ns = [], []
    for a in range(3):
        for s in (1, -1):
            u, v = (i for i in range(3) if i != a)
            P = np.empty((n, n, 3))
            P[..., a] = c[a] + s * h[a]
            P[..., u] = c[u] + g[None, :] * h[u]
            P[..., v] = c[v] - g[:, None] * h[v]
            N = np.zeros((n, n, 3))
            N[..., a] = -s
            Ps.append(P)
            Ns.append(N)
    P, N = np.concatenate(Ps, axis=1), np.concatenate(Ns, axis=1)
    return np.ones((n, 6 * n), bool), P.reshape(-1, 3), N.reshape(-1, 3)


def _cube_edges():
    """The 12 edges of the cube as (a, sa, b, sb): the faces 2a + (sa < 0) and 2b + (sb < 0), a < b."""
    return [(a, sa, b, sb) for a in range(3) for b in range(a + 1, 3) for sa in (1, -1) for sb in (1, -1)]


def ties_scene():
    """One quad per cube edge of light "ties", half a unit from it, across the edge's diagonal direction and
    only on the side of the edge's first axis a (|d_a| > |d_b|): it covers face a's texels along the edge
    and none of face b's."""
    pos = LIGHTS["ties"][0]
    Vs, Fs = [], []
    for a, sa, b, sb in _cube_edges():
        u, w, k = np.zeros(3), np.zeros(3), np.zeros(3)
        u[a], w[b], k[3 - a - b] = sa, sb, 1.0
        c = pos + 0.5 * (u + w)
        V = np.array([c - 0.3 * k, c + 0.25 * (u - w) - 0.3 * k, c + 0.25 * (u - w) + 0.3 * k, c + 0.3 * k])
        Vs.append(V)
        Fs.append(np.array([[0, 1, 2], [0, 2, 3]]) + 4 * len(Fs))
    return np.vstack(Vs), np.vstack(Fs)


def ties_points():
    """``(mask, P, N)``: 10 points on each cube edge's diagonal (|d_a| = |d_b| to the last bit): 8 behind the
    edge's quad of ties_scene, which the face the first axis gives (cube_face_index's rule on ties) sees in shadow
    and the other face lit, and 2 in front of it (t = 0.3), lit on both faces (a lookup that finds everything in
    shadow fails there). A 12 x 10 picture, one row per edge."""
    pos = LIGHTS["ties"][0]
    P = []
    for a, sa, b, sb in _cube_edges():
        for t in (0.3, 1.0, 1.25, 1.5, 1.75):
            for c in (-0.4, 0.3):
                d = np.zeros(3)
                d[a], d[b], d[3 - a - b] = sa * t, sb * t, c * t
                P.append(pos + d)
    P = np.array(P)
    return np.ones((12, 10), bool), P, np.tile([0.0, 0.0, 1.0], (len(P), 1))


def case_points(key: str):
    """The points a cube_shadow.frag case of light ``key`` shades: the room's walls, the cube edges' diagonals,
    or the eye view's pixels."""
    return room_points(key) if key in ROOMS else ties_points() if key == "ties" else eye_points()


def _prefix(visibility: str) -> str:
    return "hidden-" if visibility == "hidden" else ""


def matrices_entry(key: str, visibility: str = "visible") -> Case:
    """Task 8's face matrices of light ``key``, stored so Task 11's tests do not need Task 8."""
    pos, near, far = LIGHTS[key]
    return Case(id=f"{_prefix(visibility)}glsl-cube-matrices-{key}", function="cube_light_matrices",
                inputs=lambda: {"position": pos, "near": near, "far": far}, outputs=("Ms",),
                check=checks.Allclose(atol=1e-10), part="stored input", points=0, visibility=visibility)  # fmt: skip


def linear_maps_entry(key: str, size: int, cull: str, visibility: str = "visible") -> Case:
    """The NumPy linear cube pass (cube_distance_maps) of the small scene for light ``key``."""
    pos, near, far = LIGHTS[key]

    def make():
        V, F = room_scene(key) if key in ROOMS else ties_scene() if key == "ties" else small_scene()
        return {"V": V, "F": F, "position": pos, "size": size, "near": near, "far": far}

    return Case(id=f"{_prefix(visibility)}glsl-cube-linear-{key}-{size}-{cull}", function="cube_distance_maps",
                inputs=make, params={"cull": cull}, outputs=("maps",), check=MapClose("maps", atol=1e-9),
                part="stored input", points=0, visibility=visibility)  # fmt: skip


def cube_visibility_entry(id: str, maps_id: str, key: str, visibility: str = "visible", **params) -> Case:
    """The NumPy linear lookup per eye pixel (per wall point for a room light) on the stored linear maps
    ``maps_id``, for the cube_shadow.frag tests."""
    pos, near, far = LIGHTS[key]

    def make():
        _, P, N = case_points(key)
        return {"P": P, "N": N, "maps": stored_input("shadows", maps_id)["maps"], "position": pos, "near": near,
                "far": far}  # fmt: skip

    return Case(id=f"{_prefix(visibility)}{id}", function="linear_point_shadow_visibility", inputs=make,
                params=params, outputs=("visibility",), check=checks.Allclose(atol=1e-12), part="stored input",
                points=0, visibility=visibility)  # fmt: skip


H = "hidden"
#: Public: two lights, culling front and none, a far plane that cuts the scene; default and small bias, PCF 3.
STORED = [
    matrices_entry("a"),
    matrices_entry("b"),
    matrices_entry("b-short"),
    linear_maps_entry("a", 64, "front"),
    linear_maps_entry("b", 48, "none"),
    linear_maps_entry("b-short", 48, "front"),
    cube_visibility_entry("glsl-cube-eye-defaults", "glsl-cube-linear-a-64-front", "a"),
    cube_visibility_entry("glsl-cube-eye-small-bias", "glsl-cube-linear-a-64-front", "a", bias=0.004),
    cube_visibility_entry("glsl-cube-eye-pcf3", "glsl-cube-linear-b-48-none", "b", bias=0.02, pcf=3),
    cube_visibility_entry("glsl-cube-eye-short-far", "glsl-cube-linear-b-short-48-front", "b-short"),
]
#: Hidden: two other lights, sizes and culling modes; PCF 5, the default bias, PCF 3 on a back-culled map.
STORED_HIDDEN = [
    matrices_entry("c", H),
    matrices_entry("d", H),
    linear_maps_entry("c", 80, "front", H),
    linear_maps_entry("d", 56, "back", H),
    cube_visibility_entry("glsl-cube-eye-pcf5", "hidden-glsl-cube-linear-c-80-front", "c", H, bias=0.01, pcf=5),
    cube_visibility_entry("glsl-cube-eye-defaults", "hidden-glsl-cube-linear-d-56-back", "d", H),
    cube_visibility_entry("glsl-cube-eye-pcf3", "hidden-glsl-cube-linear-d-56-back", "d", H, pcf=3),
]
#: Every face direction: a light inside a room (room_scene), lit and shadowed wall points on all six faces.
STORED += [
    matrices_entry("room"),
    linear_maps_entry("room", 64, "front"),
    linear_maps_entry("room", 48, "back"),  # from inside, the walls are back faces: back culling drops them
    cube_visibility_entry("glsl-cube-room-defaults", "glsl-cube-linear-room-64-front", "room"),
    cube_visibility_entry("glsl-cube-room-pcf3", "glsl-cube-linear-room-64-front", "room", bias=0.01, pcf=3),
    # points exactly on the cube's edges: the first axis's face on ties
    matrices_entry("ties"),
    linear_maps_entry("ties", 32, "none"),
    cube_visibility_entry("glsl-cube-ties-defaults", "glsl-cube-linear-ties-32-none", "ties"),
]
STORED_HIDDEN += [
    matrices_entry("room2", H),
    linear_maps_entry("room2", 56, "none", H),
    cube_visibility_entry("glsl-cube-room-defaults", "hidden-glsl-cube-linear-room2-56-none", "room2", H),
    cube_visibility_entry("glsl-cube-room-bias", "hidden-glsl-cube-linear-room2-56-none", "room2", H, bias=0.004),
    matrices_entry("ties", H),
    linear_maps_entry("ties", 48, "none", H),
    cube_visibility_entry("glsl-cube-ties-pcf3", "hidden-glsl-cube-linear-ties-48-none", "ties", H, pcf=3),
]
