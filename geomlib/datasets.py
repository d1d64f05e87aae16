"""Procedural test meshes: deterministic, built in code (no downloads).

A catalogue (about 750 lines): one short builder per mesh, which would only be scattered by
splitting; each builder stands alone.

Triangle meshes are ``(V, F)`` with ``V`` float64 ``(n, 3)`` and ``F`` int64 ``(m, 3)``; quad
meshes ``(V, Q)`` with ``Q`` int64 ``(m, 4)``; mixed polygon meshes ``(V, faces)`` with a list of
index lists. Closed meshes are outward oriented (counter-clockwise seen from outside), open ones
face +z. Meshes with texture coordinates return ``(V, F, UV)`` with ``UV`` float64 ``(n, 2)`` per
vertex: vertices on a UV seam are duplicated (same position, different UV), so as triangle meshes
they are cut open along the seams.

Random shapes take a ``seed`` for ``numpy.random.default_rng``: the same seed gives the same mesh.

:data:`DATASETS` lists every mesh by name for the figures gallery.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import numpy as np

from geomlib import portable, topology
from geomlib.validate import MeshError, as_array, as_vertices, check_choice, check_float, check_int, check_mesh

__all__ = [
    "icosphere",
    "torus",
    "sharp_box",
    "grid_patch",
    "height_field",
    "quad_cube",
    "quad_torus",
    "polygon_cage",
    "rock_on_plinth",
    "uv_sphere",
    "uv_torus",
    "uv_grid",
    "pyvista_mesh",
    "add_noise",
    "Dataset",
    "DATASETS",
]


# --------------------------------------------------------------------------------------------
# closed triangle meshes


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    p = (1.0 + np.sqrt(5.0)) / 2.0
    V = np.array(
        [[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
         [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]],
        dtype=np.float64,
    )  # fmt: skip
    F = np.array(
        [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]],
        dtype=np.int64,
    )  # fmt: skip
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def _midpoint_subdivide(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split every triangle into four at its edge midpoints (orientation kept)."""
    H = topology.halfedge_mesh(F, len(V), checked=True)  # half-edge 3f + i runs corner i -> i + 1
    E = H.E
    mid = len(V) + H.he_edge.reshape(-1, 3)  # new vertex on edges (0,1), (1,2), (2,0)
    a, b, c = F.T
    m01, m12, m20 = mid.T
    F2 = np.concatenate([np.stack(t, axis=1) for t in ((a, m01, m20), (m01, b, m12), (m20, m12, c), (m01, m12, m20))])
    return np.vstack([V, 0.5 * (V[E[:, 0]] + V[E[:, 1]])]), F2


def icosphere(level: int = 2, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Sphere from a subdivided icosahedron.

    Level 0 is the icosahedron (12 vertices, 20 faces); each level splits every triangle into
    four at its edge midpoints and pushes the new vertices onto the sphere. Level ``l`` has
    ``10 * 4**l + 2`` vertices and ``20 * 4**l`` faces; every vertex lies on the sphere.

    Parameters
    ----------
    level : int
        Subdivision level, 0..8.
    radius : float
        Sphere radius (> 0).

    Returns
    -------
    V : (10 * 4**level + 2, 3) float64
    F : (20 * 4**level, 3) int64
        Closed, genus 0, outward oriented.
    """
    level = check_int(level, "level", minimum=0, maximum=8, where="icosphere")
    radius = check_float(radius, "radius", positive=True, where="icosphere")
    V, F = _icosahedron()
    for _ in range(level):
        V, F = _midpoint_subdivide(V, F)
        V /= np.linalg.norm(V, axis=1, keepdims=True)
    return radius * V, F


def _torus_points(major: float, minor: float, i: np.ndarray, j: np.ndarray, n_major: int, n_minor: int) -> np.ndarray:
    th = 2.0 * np.pi * (i % n_major) / n_major  # modulo: seam copies get bit-identical positions
    ph = 2.0 * np.pi * (j % n_minor) / n_minor
    rr = major + minor * portable.cos(ph)
    return np.stack([rr * portable.cos(th), rr * portable.sin(th), minor * portable.sin(ph)], axis=-1)


def _grid_quads(nu: int, nv: int, wrap_u: bool, wrap_v: bool) -> np.ndarray:
    """Quads ``(a, b, c, d)`` of an index grid ``u + (nu + !wrap_u) * v``, counter-clockwise in (u, v)."""
    cu, cv = (nu if wrap_u else nu - 1), (nv if wrap_v else nv - 1)
    iu, iv = np.meshgrid(np.arange(cu), np.arange(cv), indexing="xy")
    iu, iv = iu.ravel(), iv.ravel()

    def idx(u, v):
        return (u % nu) + nu * (v % nv)

    return np.stack([idx(iu, iv), idx(iu + 1, iv), idx(iu + 1, iv + 1), idx(iu, iv + 1)], axis=1)


def _split_quads(Q: np.ndarray, anti: np.ndarray | None = None) -> np.ndarray:
    """Two triangles per quad ``(a, b, c, d)``: along a-c, or along b-d where ``anti``."""
    a, b, c, d = Q.T
    F = np.stack([np.stack([a, b, c], 1), np.stack([a, c, d], 1)], axis=1)
    if anti is not None:
        G = np.stack([np.stack([a, b, d], 1), np.stack([b, c, d], 1)], axis=1)
        F = np.where(anti[:, None, None], G, F)
    return F.reshape(-1, 3)


def _check_torus(major, minor, n_major, n_minor, where):
    major = check_float(major, "major", minimum=0.0, where=where)
    minor = check_float(minor, "minor", minimum=0.0, where=where)
    if not 0 < minor < major:
        raise MeshError(f"{where}: need 0 < minor < major (a ring torus); got major={major}, minor={minor}")
    n_major = check_int(n_major, "n_major", minimum=3, where=where)
    n_minor = check_int(n_minor, "n_minor", minimum=3, where=where)
    return major, minor, n_major, n_minor


def torus(
    major: float = 1.0, minor: float = 0.35, n_major: int = 48, n_minor: int = 24
) -> tuple[np.ndarray, np.ndarray]:
    """Ring torus around the z axis, triangulated.

    Vertex ``i + n_major * j`` sits at angle ``2 pi i / n_major`` around the z axis and
    ``2 pi j / n_minor`` around the tube:
    ``((R + r cos phi) cos theta, (R + r cos phi) sin theta, r sin phi)``.

    Parameters
    ----------
    major, minor : float
        Radius ``R`` of the centre circle and radius ``r`` of the tube, ``0 < r < R``.
    n_major, n_minor : int
        Segments around the z axis and around the tube (>= 3).

    Returns
    -------
    V : (n_major * n_minor, 3) float64
    F : (2 * n_major * n_minor, 3) int64
        Closed, genus 1, outward oriented.
    """
    major, minor, n_major, n_minor = _check_torus(major, minor, n_major, n_minor, "torus")
    j, i = np.divmod(np.arange(n_major * n_minor), n_major)
    V = _torus_points(major, minor, i, j, n_major, n_minor)
    return V, _split_quads(_grid_quads(n_major, n_minor, True, True))


def _weld_exact(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices with bit-identical positions; drop unreferenced ones (order of first use)."""
    _, first, inv = np.unique(V, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    rank = np.argsort(np.argsort(first))  # keep the order in which vertices first appear
    keep = np.sort(first)
    return V[keep], rank[inv][F]


def sharp_box(size: float | tuple[float, float, float] = (1.0, 1.0, 1.0), n: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Closed axis-aligned box centred at the origin, each side an ``n x n`` grid of split quads.

    The sides share their border vertices (welded), so the box is one closed manifold with
    sharp 90-degree edges: ``6 n**2 + 2`` vertices, ``12 n**2`` triangles.

    Parameters
    ----------
    size : float or (3,) float
        Edge lengths along x, y, z (> 0).
    n : int
        Grid cells per side edge (>= 1).

    Returns
    -------
    V : (6 n**2 + 2, 3) float64
    F : (12 n**2, 3) int64
        Closed, genus 0, outward oriented.
    """
    where = "sharp_box"
    n = check_int(n, "n", minimum=1, where=where)
    s = np.broadcast_to(as_array(size, "size", dtype=np.float64, where=where), (3,)).copy()
    if (s <= 0).any():
        raise MeshError(f"{where}: size must be positive, got {tuple(s)}")
    # Integer lattice points of the 6 sides; welding on integers is exact.
    g = np.arange(n + 1)
    u, v = np.meshgrid(g, g, indexing="xy")
    u, v = u.ravel(), v.ravel()
    cells = _grid_quads(n + 1, n + 1, False, False)
    P, Fs = [], []
    for a in range(3):
        for side in (0, 1):
            b, c = (a + 1) % 3, (a + 2) % 3  # e_b x e_c = e_a: the quads face +a
            if side == 0:
                b, c = c, b  # ... and -a here
            L = np.zeros((len(u), 3), np.int64)
            L[:, a], L[:, b], L[:, c] = side * n, u, v
            Fs.append(cells + sum(len(p) for p in P))
            P.append(L)
    L = np.vstack(P)
    Q = np.vstack(Fs)
    Lw, Qw = _weld_exact(L, Q)
    return (Lw / n - 0.5) * s, _split_quads(Qw)


# --------------------------------------------------------------------------------------------
# open grids


def _grid_xy(n: int, size: float) -> np.ndarray:
    j, i = np.divmod(np.arange((n + 1) ** 2), n + 1)
    return np.stack([i * size / n, j * size / n, np.zeros(len(i))], axis=1)


def _grid_faces(n: int, diagonals: str) -> np.ndarray:
    Q = _grid_quads(n + 1, n + 1, False, False)
    if diagonals == "uniform":
        return _split_quads(Q)
    # "radial": each cell is split along the diagonal that points away from the grid centre,
    # so the pattern is symmetric under the square's rotations and reflections.
    j, i = np.divmod(np.arange(n * n), n)
    cx, cy = i + 0.5 - n / 2, j + 0.5 - n / 2
    return _split_quads(Q, anti=cx * cy < 0)


def grid_patch(n: int = 16, size: float = 1.0, *, diagonals: str = "uniform") -> tuple[np.ndarray, np.ndarray]:
    """Flat square grid ``[0, size]^2`` in the plane z = 0, facing +z.

    Vertex ``i + (n + 1) * j`` sits at ``(i, j) * size / n``.

    Parameters
    ----------
    n : int
        Cells per side (>= 1).
    size : float
        Side length (> 0).
    diagonals : {"uniform", "radial"}
        How cells are split: all along the same diagonal ``(i, j)-(i+1, j+1)``, or along the
        diagonal pointing away from the centre (symmetric pattern; used by
        :func:`rock_on_plinth`).

    Returns
    -------
    V : ((n + 1)**2, 3) float64
    F : (2 n**2, 3) int64
        An open disk with one boundary loop.
    """
    where = "grid_patch"
    n = check_int(n, "n", minimum=1, where=where)
    size = check_float(size, "size", positive=True, where=where)
    check_choice(diagonals, "diagonals", ("uniform", "radial"), where=where)
    return _grid_xy(n, size), _grid_faces(n, diagonals)


def _bumps(x: np.ndarray, y: np.ndarray, rng: np.random.Generator, count: int = 7) -> np.ndarray:
    """Sum of Gaussian bumps of random sign, centre and width over the unit square."""
    c = rng.uniform(0.15, 0.85, size=(count, 2))
    s = rng.uniform(0.08, 0.2, size=count)
    w = rng.uniform(0.5, 1.0, size=count) * rng.choice([-1.0, 1.0], size=count)
    d2 = (x[:, None] - c[:, 0]) ** 2 + (y[:, None] - c[:, 1]) ** 2
    return (w * portable.exp(-d2 / (2 * s**2))).sum(axis=1)


def height_field(
    n: int = 32,
    fn: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    seed: int = 0,
    amplitude: float = 0.15,
    size: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The grid of :func:`grid_patch` lifted to ``z = fn(x, y)``.

    Parameters
    ----------
    n : int
        Cells per side.
    fn : callable, optional
        ``fn(x, y) -> z`` on arrays of vertex coordinates (units of ``size``). Default: a smooth
        sum of seeded Gaussian bumps scaled so that ``max |z| = amplitude``.
    seed : int
        Seed of the default bumps.
    amplitude : float
        Largest ``|z|`` of the default bumps (ignored when ``fn`` is given).
    size : float
        Side length of the square.

    Returns
    -------
    V : ((n + 1)**2, 3) float64
    F : (2 n**2, 3) int64
    """
    where = "height_field"
    n = check_int(n, "n", minimum=1, where=where)
    size = check_float(size, "size", positive=True, where=where)
    V = _grid_xy(n, size)
    if fn is None:
        seed = check_int(seed, "seed", minimum=0, where=where)
        amplitude = check_float(amplitude, "amplitude", where=where)
        z = _bumps(V[:, 0] / size, V[:, 1] / size, np.random.default_rng(seed))
        z *= amplitude / np.abs(z).max()
    else:
        if not callable(fn):
            raise MeshError(f"{where}: fn must be a function fn(x, y) -> z, got {type(fn).__name__}")
        z = as_array(fn(V[:, 0], V[:, 1]), "fn(x, y)", where=where)
        if z.shape not in ((len(V),), ()):
            raise MeshError(f"{where}: fn(x, y) returned shape {z.shape}; expected ({len(V)},), one height per vertex")
    V[:, 2] = z
    return V, _grid_faces(n, "uniform")


# --------------------------------------------------------------------------------------------
# quad and polygon meshes


def quad_cube() -> tuple[np.ndarray, np.ndarray]:
    """Unit cube ``[-0.5, 0.5]^3`` as 8 vertices and 6 outward quads.

    Returns
    -------
    V : (8, 3) float64
        Vertex ``x + 2 y + 4 z`` is at ``(x, y, z) - 0.5`` for x, y, z in {0, 1}.
    Q : (6, 4) int64
    """
    b = np.arange(8)
    V = np.stack([b & 1, (b >> 1) & 1, (b >> 2) & 1], axis=1).astype(np.float64) - 0.5
    Q = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]], dtype=np.int64)
    return V, Q


def quad_torus(
    n_major: int = 16, n_minor: int = 8, major: float = 1.0, minor: float = 0.35
) -> tuple[np.ndarray, np.ndarray]:
    """The torus of :func:`torus` as an all-quad mesh (genus 1, every vertex of valence 4).

    Returns
    -------
    V : (n_major * n_minor, 3) float64
    Q : (n_major * n_minor, 4) int64
        Outward quads.
    """
    major, minor, n_major, n_minor = _check_torus(major, minor, n_major, n_minor, "quad_torus")
    j, i = np.divmod(np.arange(n_major * n_minor), n_major)
    return _torus_points(major, minor, i, j, n_major, n_minor), _grid_quads(n_major, n_minor, True, True)


def polygon_cage() -> tuple[np.ndarray, list[list[int]]]:
    """A small closed cage mixing pentagons, quads and triangles (for Catmull-Clark).

    A pentagonal tower: a regular pentagon floor (radius 1, z = 0), five quad walls up to
    z = 1, and a roof of five triangles meeting at an apex (1.6 high, shifted off-centre so the
    shape has no rotational symmetry). 11 vertices, 20 edges, 11 faces: closed, manifold,
    genus 0 (chi = 2), outward oriented; the apex has valence 5.

    Returns
    -------
    V : (11, 3) float64
    faces : list of 11 lists of int
        ``[pentagon] + 5 quads + 5 triangles``.
    """
    a = 2.0 * np.pi * np.arange(5) / 5 + np.pi / 2
    ring = np.stack([portable.cos(a), portable.sin(a), np.zeros(5)], axis=1)
    V = np.vstack([ring, ring + [0.0, 0.0, 1.0], [[0.25, 0.0, 1.6]]])
    floor = [[4, 3, 2, 1, 0]]  # clockwise seen from above = outward (down)
    walls = [[i, (i + 1) % 5, 5 + (i + 1) % 5, 5 + i] for i in range(5)]
    roof = [[5 + i, 5 + (i + 1) % 5, 10] for i in range(5)]
    return V, floor + walls + roof


# --------------------------------------------------------------------------------------------
# rock on a plinth (vector-displacement lab)


def rock_on_plinth(n: int = 48, seed: int = 0, size: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """A bumpy rock on a square plinth: a disk-topology mesh with sharp 90-degree creases.

    Built by displacing the grid of ``grid_patch(n, size, diagonals="radial")``: vertex ``i`` is
    grid vertex ``i`` moved, and the faces are the same, so ``V - grid_V`` is an exact vector
    displacement of the flat square. The grid's square rings around the centre (Chebyshev
    distance ``k`` in cells) are mapped to

    * the flat base plate ``z = 0`` (outer rings, out to the unchanged square boundary),
    * the plinth's walls: a few rings stacked *vertically* at the plinth's half-width, giving
      exactly vertical walls with a 90-degree crease at their foot and at their top,
    * the plinth's flat top ``z = 0.12 size`` (inner rings, a uniformly scaled grid),

    and the centre of the top carries a seeded rock: a dome of height about ``0.28 size`` over a
    lumpy outline, modulated by seeded Gaussian bumps and ridges (``|cos|`` waves, which crease
    the surface); its flanks are steep where it meets the plinth. The rock stays inside 85% of
    the plinth's half-width, so the rim remains a sharp, straight crease.

    Parameters
    ----------
    n : int
        Cells per side of the grid; even, >= 8.
    seed : int
        Seed of the rock's noise.
    size : float
        Side of the square footprint ``[0, size]^2``.

    Returns
    -------
    V : ((n + 1)**2, 3) float64
    F : (2 n**2, 3) int64
        One boundary loop (the square's border), genus 0, chi = 1, facing +z.
    """
    where = "rock_on_plinth"
    n = check_int(n, "n", minimum=8, where=where)
    if n % 2:
        raise MeshError(f"{where}: n must be even (the plinth is centred on a grid vertex), got {n}")
    seed = check_int(seed, "seed", minimum=0, where=where)
    size = check_float(size, "size", positive=True, where=where)
    h = n // 2
    k_top = max(2, round(0.5 * h))  # rings 0..k_top: plinth top
    k_foot = k_top + max(1, round(0.125 * h))  # rings k_top..k_foot: vertical walls
    rho_w, height = 0.55, 0.12  # plinth half-width (fraction of half the size) and height (of size)

    j, i = np.divmod(np.arange((n + 1) ** 2), n + 1)
    di, dj = (i - h).astype(np.float64), (j - h).astype(np.float64)
    k = np.maximum(np.abs(di), np.abs(dj))
    rho = np.where(
        k <= k_top, rho_w * k / k_top, np.where(k <= k_foot, rho_w, rho_w + (1 - rho_w) * (k - k_foot) / (h - k_foot))
    )
    z = np.where(k <= k_top, height, np.where(k <= k_foot, height * (k_foot - k) / (k_foot - k_top), 0.0))
    scale = np.divide(rho, k, out=np.zeros_like(rho), where=k > 0) * (size / 2)
    x, y = di * scale, dj * scale  # relative to the centre

    # The rock (units of size): a dome over a lumpy outline, modulated by bumps and ridges.
    rng = np.random.default_rng(seed)
    xs, ys = x / size, y / size
    ang = portable.arctan2(ys, xs)
    outline = 1 + sum(
        rng.uniform(0.06, 0.14) * portable.cos(m * ang + rng.uniform(0, 2 * np.pi))
        for m in rng.choice([2, 3, 4, 5], 3, replace=False)
    )
    r0 = 0.85 * rho_w / 2  # the rock stays inside 85% of the plinth's half-width
    s = portable.hypot(xs, ys) / (r0 * outline / outline.max())
    dome = np.sqrt(np.clip(1 - s**2, 0, None))  # steep flanks: a crease where it meets the plinth
    bumps = _bumps(xs / (2 * r0) + 0.5, ys / (2 * r0) + 0.5, rng, count=12)
    bumps /= np.abs(bumps).max()
    d = rng.normal(size=(3, 2))
    ridges = (
        sum(np.abs(portable.cos(rng.uniform(12, 20) * (u[0] * xs + u[1] * ys) / portable.hypot(*u))) for u in d) / 3
    )
    z = z + 0.28 * dome * (1 + 0.35 * bumps + 0.3 * (ridges - 0.5))
    V = np.stack([x + size / 2, y + size / 2, z * size], axis=1)
    V[k == h, 0:2] = _grid_xy(n, size)[k == h, 0:2]  # the border exactly on the grid's border
    return V, _grid_faces(n, "radial")


# --------------------------------------------------------------------------------------------
# meshes with texture coordinates


def uv_sphere(n_lat: int = 16, n_lon: int = 32, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Latitude-longitude sphere with UV coordinates ``u = longitude / 2 pi``, ``v = 1 - colatitude / pi``.

    The seam (longitude 0 = 2 pi, in the plane y = 0, x > 0) is duplicated: column ``n_lon``
    repeats the positions of column 0 with ``u = 1`` instead of 0. Each pole is split into
    ``n_lon`` copies, one per cap triangle, with ``u`` at the middle of that triangle's
    longitude range (``v = 1`` at the north pole z = +r, 0 at the south pole). As a triangle
    mesh it is therefore an open disk; merging equal positions closes it into a sphere.

    Parameters
    ----------
    n_lat : int
        Rings of triangles from pole to pole (>= 2).
    n_lon : int
        Segments around the z axis (>= 3).
    radius : float

    Returns
    -------
    V : (2 n_lon + (n_lat - 1)(n_lon + 1), 3) float64
        North-pole copies first, then rows of ``n_lon + 1`` vertices north to south, then the
        south-pole copies.
    F : (2 n_lon (n_lat - 1), 3) int64
        Outward oriented; counter-clockwise in UV as well.
    UV : (len(V), 2) float64
    """
    where = "uv_sphere"
    n_lat = check_int(n_lat, "n_lat", minimum=2, where=where)
    n_lon = check_int(n_lon, "n_lon", minimum=3, where=where)
    radius = check_float(radius, "radius", positive=True, where=where)
    c = np.arange(n_lon + 1)
    phi = 2 * np.pi * (c % n_lon) / n_lon  # modulo: the seam copies get identical positions
    rows = np.arange(1, n_lat)
    th = np.pi * rows / n_lat
    mid = np.stack(
        [
            np.outer(portable.sin(th), portable.cos(phi)),
            np.outer(portable.sin(th), portable.sin(phi)),
            np.repeat(portable.cos(th), n_lon + 1).reshape(-1, n_lon + 1),
        ],
        axis=-1,
    ).reshape(-1, 3)
    north = np.tile([0.0, 0.0, 1.0], (n_lon, 1))
    south = np.tile([0.0, 0.0, -1.0], (n_lon, 1))
    V = radius * np.vstack([north, mid, south])
    u_pole = (np.arange(n_lon) + 0.5) / n_lon
    uv_mid = np.stack(np.meshgrid(c / n_lon, 1.0 - rows / n_lat, indexing="xy"), axis=-1).reshape(-1, 2)
    UV = np.vstack([np.stack([u_pole, np.ones(n_lon)], 1), uv_mid, np.stack([u_pole, np.zeros(n_lon)], 1)])

    def m(r, col):  # vertex of the middle row r (1..n_lat-1) and column col
        return n_lon + (r - 1) * (n_lon + 1) + col

    cl = np.arange(n_lon)
    caps_n = np.stack([cl, m(1, cl), m(1, cl + 1)], axis=1)
    south0 = n_lon + (n_lat - 1) * (n_lon + 1)
    caps_s = np.stack([m(n_lat - 1, cl), south0 + cl, m(n_lat - 1, cl + 1)], axis=1)
    Q = _grid_quads(n_lon + 1, n_lat - 1, False, False)  # (col, row) grid of the middle rows
    # a quad (a, b, c, d) runs east then south here; reorder to (a, d, c, b) = south then east
    Q = n_lon + Q[:, [0, 3, 2, 1]]
    F = np.vstack([caps_n, _split_quads(Q), caps_s])
    return V, F, UV


def uv_torus(
    n_major: int = 48, n_minor: int = 24, major: float = 1.0, minor: float = 0.35
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The torus of :func:`torus` with UV coordinates ``u = i / n_major``, ``v = j / n_minor``.

    Two seams (``u = 0 = 1`` and ``v = 0 = 1``) are duplicated, so there are
    ``(n_major + 1)(n_minor + 1)`` vertices; as a triangle mesh it is a disk (a torus cut open
    twice). Vertex ``i + (n_major + 1) j`` is at the torus point of angles
    ``(2 pi i / n_major, 2 pi j / n_minor)``.

    Returns
    -------
    V : ((n_major + 1)(n_minor + 1), 3) float64
    F : (2 n_major n_minor, 3) int64
        Outward oriented, counter-clockwise in UV.
    UV : (len(V), 2) float64
    """
    major, minor, n_major, n_minor = _check_torus(major, minor, n_major, n_minor, "uv_torus")
    j, i = np.divmod(np.arange((n_major + 1) * (n_minor + 1)), n_major + 1)
    V = _torus_points(major, minor, i, j, n_major, n_minor)
    UV = np.stack([i / n_major, j / n_minor], axis=1)
    return V, _split_quads(_grid_quads(n_major + 1, n_minor + 1, False, False)), UV


def uv_grid(n: int = 16, size: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`grid_patch` with ``UV = (x, y) / size`` (so ``UV = xy`` for the unit square).

    Returns
    -------
    V : ((n + 1)**2, 3) float64
    F : (2 n**2, 3) int64
    UV : ((n + 1)**2, 2) float64
    """
    where = "uv_grid"
    n = check_int(n, "n", minimum=1, where=where)
    size = check_float(size, "size", positive=True, where=where)
    V = _grid_xy(n, size)
    return V, _grid_faces(n, "uniform"), V[:, :2] / size


# --------------------------------------------------------------------------------------------
# meshes shipped with pyvista


_PYVISTA_MESHES = ("airplane", "ant", "nut")


def pyvista_mesh(name: str, manifold: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh from the PLY files inside the pyvista package (no download).

    The file is read with :func:`geomlib.mesh_io.read_mesh` (the same arrays as ``pyvista.read``
    and ``triangulate``, without importing pyvista and VTK: a grading run loads the ant in half a
    second less), and vertices with identical positions are welded; faces that become degenerate or duplicate are dropped, and so are unused vertices.
    The airplane is not manifold as shipped (a stray triangle on a wing edge makes an edge with
    three faces, and six vertices are pinch points where separate parts touch):
    ``manifold=True`` drops components of fewer than three faces and gives each fan of faces
    around a pinch vertex its own copy of the vertex (see :func:`split_nonmanifold_vertices`).

    Parameters
    ----------
    name : {"airplane", "ant", "nut"}
    manifold : bool
        Repair as described above (a no-op for the ant and the nut, which are manifold).

    Returns
    -------
    V : (n, 3) float64
    F : (m, 3) int64
    """
    where = "pyvista_mesh"
    check_choice(name, "name", _PYVISTA_MESHES, where=where)
    from importlib.util import find_spec

    from geomlib import mesh_io

    spec = find_spec("pyvista")  # the package's folder, without importing it (and VTK)
    path = Path(spec.origin if spec and spec.origin else ".").parent / "examples" / f"{name}.ply"
    if not path.is_file():
        raise MeshError(f"{where}: {path} is missing from the installed pyvista package")
    V, F = mesh_io.read_mesh(path, triangulate=True)
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    V, F = _weld_exact(V, F)
    S = np.sort(F, axis=1)
    ok = (S[:, 1:] != S[:, :-1]).all(axis=1)
    F, S = F[ok], S[ok]
    _, first = np.unique(S, axis=0, return_index=True)
    F = F[np.sort(first)]
    used = np.flatnonzero(np.bincount(F.ravel(), minlength=len(V)))
    remap = np.full(len(V), -1, np.int64)
    remap[used] = np.arange(len(used))
    V, F = np.ascontiguousarray(V[used]), remap[F]
    if manifold:
        _, comp = topology.connected_components_faces(F)
        F = F[np.bincount(comp)[comp] >= 3]
        V, F = split_nonmanifold_vertices(V, F)
    return V, F


def split_nonmanifold_vertices(V, F) -> tuple[np.ndarray, np.ndarray]:
    """Give every fan of faces around a vertex its own copy of that vertex.

    A consistently oriented, edge-manifold triangle mesh whose vertices are pinch points (several
    fans meeting at one vertex) becomes vertex-manifold; positions are unchanged, so the surface
    is the same. Unreferenced vertices are dropped.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int

    Returns
    -------
    V2 : (n2, 3) float64
        ``n2 >= n`` (one row per fan).
    F2 : (m, 3) int64
        The same faces, re-indexed.
    """
    V, F = check_mesh(V, F, where="split_nonmanifold_vertices")
    # Every fan of the half-edge structure becomes one vertex.
    label, owner = topology.halfedge_mesh(F, len(V), checked=True).fans()
    return V[owner], label.reshape(-1, 3)


# --------------------------------------------------------------------------------------------
# noise


def add_noise(
    V,
    sigma: float,
    seed: int = 0,
    direction: str = "random",
    N: np.ndarray | None = None,
    *,
    F: np.ndarray | None = None,
) -> np.ndarray:
    """Displace every vertex by Gaussian noise of standard deviation ``sigma``.

    ``V'_i = V_i + g_i d_i`` with ``g_i ~ N(0, sigma^2)`` and ``d_i`` a unit direction: uniformly
    random (``"random"``) or the vertex normal ``N_i`` (``"normal"``).

    Parameters
    ----------
    V : (n, 3) float
    sigma : float
        Standard deviation in units of ``V`` (>= 0).
    seed : int
        Seed of ``numpy.random.default_rng``.
    direction : {"random", "normal"}
    N : (n, 3) float, optional
        Normals for ``"normal"`` (normalised here; zero rows give no displacement).
    F : (m, 3) int, optional
        Faces, to compute area-weighted vertex normals when ``N`` is not given.

    Returns
    -------
    V_noisy : (n, 3) float64
    """
    where = "add_noise"
    V = as_vertices(V, where=where)
    sigma = check_float(sigma, "sigma", minimum=0.0, where=where)
    seed = check_int(seed, "seed", minimum=0, where=where)
    check_choice(direction, "direction", ("random", "normal"), where=where)
    rng = np.random.default_rng(seed)
    g = rng.normal(0.0, sigma, size=len(V)) if sigma > 0 else np.zeros(len(V))
    if direction == "random":
        d = rng.normal(size=(len(V), 3))
    else:
        if N is None:
            if F is None:
                raise MeshError(f"{where}: direction='normal' needs the normals N (or the faces F to compute them)")
            from geomlib.geometry import vertex_normals

            d = vertex_normals(V, F)
        else:
            d = as_vertices(N, name="N", where=where)
            if len(d) != len(V):
                raise MeshError(f"{where}: N has {len(d)} rows but V has {len(V)}; expected one normal per vertex")
    nrm = np.linalg.norm(d, axis=1, keepdims=True)
    d = np.divide(d, nrm, out=np.zeros_like(d), where=nrm > 0)
    return V + g[:, None] * d


# --------------------------------------------------------------------------------------------
# registry


class Dataset(NamedTuple):
    """A registry entry: ``make()`` returns ``(V, F)`` for ``kind == "tri"``, ``(V, faces)`` for ``"poly"``."""

    make: Callable[[], tuple]
    description: str
    kind: str


def _vf(fn: Callable[[], tuple]) -> Callable[[], tuple]:
    def make():
        return fn()[:2]

    make.__name__ = getattr(fn, "__name__", "make")
    return make


DATASETS: dict[str, Dataset] = {
    "icosphere": Dataset(lambda: icosphere(3), "unit sphere, subdivided icosahedron, level 3 (642 vertices)", "tri"),
    "torus": Dataset(torus, "ring torus R = 1, r = 0.35, 48 x 24 segments (genus 1)", "tri"),
    "sharp_box": Dataset(sharp_box, "unit box, 4 x 4 grid per side, sharp 90-degree edges", "tri"),
    "grid_patch": Dataset(grid_patch, "flat 16 x 16 grid on the unit square (open, one boundary loop)", "tri"),
    "height_field": Dataset(height_field, "32 x 32 grid with seeded smooth bumps (open)", "tri"),
    "rock_on_plinth": Dataset(
        rock_on_plinth, "seeded rock on a square plinth with vertical walls (disk, sharp creases)", "tri"
    ),
    "uv_sphere": Dataset(_vf(uv_sphere), "latitude-longitude sphere with UVs, seam and poles split", "tri"),
    "uv_torus": Dataset(_vf(uv_torus), "torus with UVs, cut along both seams", "tri"),
    "uv_grid": Dataset(_vf(uv_grid), "flat 16 x 16 grid with UV = xy", "tri"),
    "quad_cube": Dataset(quad_cube, "cube as 6 quads", "poly"),
    "quad_torus": Dataset(quad_torus, "torus as 16 x 8 quads", "poly"),
    "polygon_cage": Dataset(polygon_cage, "pentagonal tower: pentagon floor, quad walls, triangle roof", "poly"),
    "airplane": Dataset(lambda: pyvista_mesh("airplane"), "pyvista's airplane.ply", "tri"),
    "ant": Dataset(lambda: pyvista_mesh("ant"), "pyvista's ant.ply", "tri"),
    "nut": Dataset(lambda: pyvista_mesh("nut"), "pyvista's nut.ply", "tri"),
}
"""Every dataset by name: ``(make, description, kind)``, ``make()`` with default arguments."""
