"""Texture-space helpers: bilinear map lookups, texel coverage of UV triangles, chart padding, atlases.

These are the given building blocks of the labs that store data in textures (normal maps,
displacement maps, denoising offsets). They fix one convention for the whole course:

* **UV space** is the unit square ``[0, 1]^2`` with ``u`` to the right and ``v`` UP (OpenGL and
  glTF's ``texcoord`` convention as pyrender uses it).
* **Images** are arrays ``(h, w)`` or ``(h, w, c)`` with row 0 at the TOP, so row 0 holds
  ``v`` close to 1 and the last row ``v`` close to 0.
* **Texel centres**: texel ``[row, col]`` covers ``u in [col / w, (col + 1) / w]`` and
  ``v in [1 - (row + 1) / h, 1 - row / h]``; its centre is
  ``(u, v) = ((col + 0.5) / w, 1 - (row + 0.5) / h)``. Continuous texel coordinates are therefore
  ``x = u w - 1/2`` (columns) and ``y = (1 - v) h - 1/2`` (rows), as in ``GL_LINEAR`` filtering.

Functions
---------
:func:`sample_bilinear`
    Bilinear lookup of an image at UV positions, clamp-to-edge or repeat.
:func:`rasterize_uv`
    Which UV triangle covers each texel centre, with barycentric weights (uses
    :func:`geomlib.raster.rasterize_clip`, so shared edges are covered exactly once).
:func:`dilate`
    Pad an image beyond its covered texels (``mask``) so bilinear lookups near chart borders
    do not mix in background values.
:func:`weld_by_position`
    Group vertices that share a position (the copies a UV seam creates).
:func:`triangle_atlas`
    A trivial UV atlas (one chart per triangle) for meshes that have no UVs.

Examples
--------
>>> import numpy as np
>>> from geomlib.textures import sample_bilinear
>>> img = np.array([[0.0, 1.0], [2.0, 3.0]])   # row 0 is the top (v = 1)
>>> float(sample_bilinear(img, [0.25, 0.75]))  # centre of texel [0, 0]
0.0
>>> float(sample_bilinear(img, [0.5, 0.5]))    # middle of the image: mean of all four
1.5
"""

from __future__ import annotations

import numpy as np

from geomlib import portable
from geomlib.validate import MeshError, as_array, as_faces, as_image, as_vertices, check_choice, check_float, check_int

__all__ = ["WRAP_MODES", "sample_bilinear", "rasterize_uv", "dilate", "weld_by_position", "triangle_atlas"]

#: Border handling of :func:`sample_bilinear`.
WRAP_MODES = ("clamp", "repeat")


def _as_uv(uv, where: str, name: str = "uv") -> np.ndarray:
    a = as_array(uv, name, dtype=np.float64, where=where)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise MeshError(f"{where}: {name} has shape {a.shape}; expected (..., 2) texture coordinates (u, v)")
    return a


def _image_size(size, where: str) -> tuple[int, int]:
    """``size`` as ``(h, w)``: an int (square) or a pair."""
    if isinstance(size, int | np.integer) and not isinstance(size, bool):
        s = check_int(size, "size", minimum=1, maximum=2**15, where=where)
        return s, s
    if isinstance(size, tuple | list) and len(size) == 2:
        h = check_int(size[0], "size[0] (height)", minimum=1, maximum=2**15, where=where)
        w = check_int(size[1], "size[1] (width)", minimum=1, maximum=2**15, where=where)
        return h, w
    raise MeshError(f"{where}: size must be an int (square) or (height, width), got {size!r}")


def sample_bilinear(image, uv, wrap: str = "clamp", *, dtype=np.float64) -> np.ndarray:
    """Bilinear lookup of ``image`` at texture coordinates ``uv`` (``GL_LINEAR`` without mipmaps).

    With continuous texel coordinates ``x = u w - 1/2``, ``y = (1 - v) h - 1/2`` (see the module
    docstring: row 0 is ``v = 1``), ``x0 = floor(x)``, ``fx = x - x0`` (same for ``y``)::

        value = (1-fx)(1-fy) I[y0, x0] + fx (1-fy) I[y0, x0+1] + (1-fx) fy I[y0+1, x0] + fx fy I[y0+1, x0+1]

    Parameters
    ----------
    image : array_like (h, w) or (h, w, c)
        Any numeric dtype; values are used as they are (a uint8 image gives values in 0..255).
    uv : array_like (..., 2)
        Texture coordinates, ``u`` right and ``v`` up; finite.
    wrap : {"clamp", "repeat"}
        Texels outside the image: ``"clamp"`` repeats the border texels (clamp-to-edge, so
        ``uv`` outside ``[0, 1]`` reads the border); ``"repeat"`` tiles the image (period 1 in ``u``
        and ``v``).
    dtype : numpy float dtype
        Precision of the arithmetic and the result (``np.float32`` halves memory traffic, as a GPU
        sampler would).

    Returns
    -------
    values : (...) or (..., c) of ``dtype``
        ``uv.shape[:-1]`` plus the channel axis of ``image`` if it has one.

    Raises
    ------
    MeshError
        Not an image, non-finite ``uv``, bad ``wrap``.
    """
    where = "sample_bilinear"
    img = as_image(image, "image", where=where)
    if img.dtype.kind not in "biuf":
        raise MeshError(f"{where}: image has dtype {img.dtype}, expected numbers")
    uv = _as_uv(uv, where)
    check_choice(wrap, "wrap", WRAP_MODES, where=where)
    h, w = img.shape[:2]
    dtype = np.dtype(dtype)
    if dtype.kind != "f":
        raise MeshError(f"{where}: dtype must be a float type, got {dtype}")
    flat = img.reshape(h * w, -1)
    if flat.dtype != dtype:
        flat = flat.astype(dtype)
    q = uv.reshape(-1, 2)
    x = q[:, 0] * w - 0.5
    y = (1.0 - q[:, 1]) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None].astype(dtype), (y - y0)[:, None].astype(dtype)
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    if wrap == "clamp":
        xa, xb = np.clip(x0, 0, w - 1), np.clip(x0 + 1, 0, w - 1)
        ya, yb = np.clip(y0, 0, h - 1), np.clip(y0 + 1, 0, h - 1)
    else:
        xa, xb = x0 % w, (x0 + 1) % w
        ya, yb = y0 % h, (y0 + 1) % h
    ra, rb = ya * w, yb * w
    # np.take gathers whole rows several times faster than fancy indexing.
    t00, t01 = np.take(flat, ra + xa, axis=0), np.take(flat, ra + xb, axis=0)
    t10, t11 = np.take(flat, rb + xa, axis=0), np.take(flat, rb + xb, axis=0)
    top = t00 + (t01 - t00) * fx
    bot = t10 + (t11 - t10) * fx
    out = top + (bot - top) * fy
    return out.reshape(uv.shape[:-1] + img.shape[2:])


def rasterize_uv(F, UV, size) -> tuple[np.ndarray, np.ndarray]:
    """Texel coverage of UV triangles: which triangle holds each texel centre, and where.

    Every texel centre ``(u, v)`` (module docstring) inside a triangle of ``UV[F]`` gets that
    triangle's index and the barycentric weights ``b`` with ``b @ UV[F[f]] = (u, v)``. Coverage is
    decided exactly (fixed point, top-left fill rule of :func:`geomlib.raster.rasterize_clip`), so
    texel centres on an edge shared by two triangles belong to exactly one of them. Where UV
    triangles overlap, the lower face index wins. Triangles may reach outside ``[0, 1]^2``; only
    the part inside the image is drawn.

    Parameters
    ----------
    F : array_like (m, 3) int
        Triangles indexing ``UV`` (degenerate UV triangles cover nothing).
    UV : array_like (n, 2)
        Texture coordinates.
    size : int or (height, width)
        Texture size in texels (an int means square).

    Returns
    -------
    face_id : (h, w) int64
        Index into ``F``; ``-1`` where no triangle covers the texel centre.
    bary : (h, w, 3) float64
        Barycentric weights w.r.t. ``F[face_id]``, non-negative, summing to 1; zero where uncovered.
    """
    from geomlib.raster import rasterize_clip

    where = "rasterize_uv"
    UV = as_array(UV, "UV", shape=(None, 2), where=where)
    F = as_faces(F, len(UV), allow_degenerate=True, allow_duplicate=True, where=where)
    h, w = _image_size(size, where)
    # Orthographic map of UV space onto the image: x_ndc = 2u - 1, y_ndc = 2v - 1 (row 0 = v = 1).
    clip = np.column_stack([2.0 * UV - 1.0, np.zeros(len(UV)), np.ones(len(UV))])
    g = rasterize_clip(clip, F, w, h)
    return g.face_id, g.bary


def _neighbour_sums(A: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sums of ``A`` over the masked 8-neighbours of every texel, and their count."""
    h, w = M.shape
    Ap = np.zeros((h + 2, w + 2) + A.shape[2:])
    Mp = np.zeros((h + 2, w + 2))
    Ap[1:-1, 1:-1] = A * M.reshape(M.shape + (1,) * (A.ndim - 2))
    Mp[1:-1, 1:-1] = M
    S = np.zeros(A.shape)
    C = np.zeros((h, w))
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            if dy == 1 and dx == 1:
                continue
            S += Ap[dy : dy + h, dx : dx + w]
            C += Mp[dy : dy + h, dx : dx + w]
    return S, C


def dilate(image, mask, iterations: int | None = None, *, return_mask: bool = False):
    """Pad an image outward from its covered texels (texture "padding" / "edge padding").

    Each iteration gives every uncovered texel that touches covered texels (8-neighbourhood) the
    mean of those neighbours, then counts it as covered. After ``k`` iterations a band ``k`` texels
    wide around every chart holds copies of the chart's border values, so bilinear lookups (and
    small mipmap levels) near a chart border read chart values, not background. Covered texels are
    never changed. The loop over iterations is sequential by nature; each iteration is vectorised.

    Parameters
    ----------
    image : array_like (h, w) or (h, w, c)
        Values (converted to float64).
    mask : array_like (h, w) bool
        True where ``image`` holds valid (covered) values.
    iterations : int or None
        Width of the band in texels (>= 0); ``None`` pads until every texel connected to a covered
        texel is filled.
    return_mask : bool
        Also return the grown mask.

    Returns
    -------
    padded : (h, w) or (h, w, c) float64
        Uncovered texels out of reach keep their input values.
    grown : (h, w) bool
        Only with ``return_mask=True``.

    Examples
    --------
    >>> import numpy as np
    >>> img = np.zeros((1, 4)); img[0, 0] = 2.0
    >>> dilate(img, img > 0, 2)
    array([[2., 2., 2., 0.]])
    """
    where = "dilate"
    A = as_image(image, "image", dtype=np.float64, where=where)
    M = np.asarray(mask)
    if M.shape != A.shape[:2]:
        raise MeshError(f"{where}: mask has shape {M.shape}, expected {A.shape[:2]} (one flag per texel)")
    if M.dtype != bool:
        raise MeshError(f"{where}: mask has dtype {M.dtype}, expected bool")
    if iterations is not None:
        iterations = check_int(iterations, "iterations", minimum=0, where=where)
    A = A.copy()
    M = M.copy()
    k = 0
    while (iterations is None or k < iterations) and not M.all():
        S, C = _neighbour_sums(A, M)
        new = (C > 0) & ~M
        if not new.any():
            break
        A[new] = S[new] / C[new].reshape(-1, *(1,) * (A.ndim - 2))
        M |= new
        k += 1
    return (A, M) if return_mask else A


def weld_by_position(V, tol: float | None = None) -> tuple[np.ndarray, int]:
    """Group vertices that sit at the same position (the copies a UV seam creates).

    Parameters
    ----------
    V : array_like (n, 3)
    tol : float, optional
        Vertices closer than ``tol`` are joined (transitively). Default: ``1e-9`` times the
        bounding-box diagonal, i.e. only copies.

    Returns
    -------
    group : (n,) int64
        Group label of every vertex, ``0 .. n_groups - 1``, numbered in order of first appearance.
    n_groups : int
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    where = "weld_by_position"
    V = as_vertices(V, where=where)
    n = len(V)
    if n == 0:
        return np.zeros(0, np.int64), 0
    if tol is None:
        diag = portable.norm(V.max(axis=0) - V.min(axis=0))  # not BLAS: the same tolerance on every CPU
        tol = 1e-9 * (diag if diag > 0 else 1.0)
    else:
        tol = check_float(tol, "tol", minimum=0.0, where=where)
    pairs = cKDTree(V).query_pairs(tol, output_type="ndarray")
    A = (
        coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        if len(pairs)
        else coo_matrix((n, n))
    )
    k, lab = connected_components(A, directed=False)
    # Renumber in order of first appearance (deterministic, independent of scipy's numbering).
    _, first = np.unique(lab, return_index=True)
    order = np.argsort(first)
    remap = np.empty(k, np.int64)
    remap[lab[first[order]]] = np.arange(k)
    return remap[lab], int(k)


def triangle_atlas(
    V, F, *, gutter: float = 0.01, mode: str = "uniform"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A trivial UV atlas: every triangle is its own chart, laid out on a grid of cells.

    ``mode="uniform"``: each triangle keeps its shape (a similarity map, no stretch inside a chart)
    and all get the same scale, so texel density is the same all over the surface.
    ``mode="fill"``: each triangle is stretched (an affine map) onto half of its cell, corners at
    ``(0, 0)``, ``(1, 0)`` and ``(x, 1)`` in cell units, so every triangle gets the same number of
    texels however small or thin it is (good for baking decimated meshes, whose triangle sizes
    vary a lot; tangent frames absorb the stretch); the grid then has only ``ceil(m / k)`` rows of
    (non-square) cells, so it fills the square. Degenerate and duplicate faces are accepted (they
    get charts like any other). Triangle ``f`` goes to cell
    ``(f % k, f // k)`` of a ``k x k`` grid (``k = ceil(sqrt(m))``), rotated so its longest edge
    lies along ``u``, with a ``gutter`` of empty UV space around it for padding. The result is a
    triangle soup: vertex ``3 f + i`` is corner ``i`` of face ``f`` (use :func:`weld_by_position`
    or ``src`` to share normals across charts).

    Parameters
    ----------
    V : array_like (n, 3)
    F : array_like (m, 3) int
    gutter : float
        Empty margin inside each cell, as a fraction of the cell size (0 <= gutter < 0.5).
    mode : {"uniform", "fill"}
        One similarity for all triangles, or an affine stretch per triangle.

    Returns
    -------
    V_split : (3m, 3) float64
        ``V[F].reshape(-1, 3)``.
    F_split : (m, 3) int64
        ``arange(3m).reshape(m, 3)`` (same orientation as ``F``).
    UV : (3m, 2) float64
        In ``[0, 1]^2``; counter-clockwise in UV when the face is counter-clockwise in 3-D.
    src : (3m,) int64
        Original vertex of every split vertex, ``F.ravel()``.
    """
    where = "triangle_atlas"
    V = as_vertices(V, where=where)
    F = as_faces(F, len(V), allow_degenerate=True, allow_duplicate=True, where=where)
    gutter = check_float(gutter, "gutter", minimum=0.0, maximum=0.49, where=where)
    check_choice(mode, "mode", ("uniform", "fill"), where=where)
    m = len(F)
    if m == 0:
        raise MeshError(f"{where}: F is empty")
    P = V[F]  # (m, 3, 3)
    E = np.roll(P, -1, axis=1) - P  # edge i runs corner i -> i + 1
    L = np.linalg.norm(E, axis=2)
    # Rotate the corners so the longest edge is edge 0 (corner 0 -> corner 1 along +u).
    r = np.argmax(L, axis=1)
    idx = (r[:, None] + np.arange(3)) % 3
    Q = np.take_along_axis(P, idx[:, :, None], axis=1)
    e0 = Q[:, 1] - Q[:, 0]
    e1 = Q[:, 2] - Q[:, 0]
    l0 = np.linalg.norm(e0, axis=1)
    ok = l0 > 0
    ex = np.where(ok[:, None], e0 / np.where(ok, l0, 1.0)[:, None], 0.0)
    x2 = portable.dot(e1, ex)  # not einsum: no FMA (same bits everywhere)
    y2 = np.linalg.norm(e1 - x2[:, None] * ex, axis=1)
    loc = np.zeros((m, 3, 2))
    loc[:, 1, 0] = l0
    loc[:, 2, 0] = x2
    loc[:, 2, 1] = y2
    # x2 lies in [0, l0] because edge 0 is the longest, so every chart fits in l0 x y2.
    k = int(np.ceil(np.sqrt(m)))
    if mode == "uniform":
        cw = ch = 1.0 / k  # square cells keep the shapes
        ext = max(float(l0.max()), float(y2.max()))
        scale = cw * (1.0 - 2.0 * gutter) / ext if ext > 0 else 0.0
    else:
        # Only as many rows as needed, so the cells (stretched anyway) fill the whole square.
        cw, ch = 1.0 / k, 1.0 / int(np.ceil(m / k))
        # Corner 2 at (x2 / l0, 1) in cell units: its u stays inside [0, 1] because edge 0 is the longest.
        sx = np.where(l0 > 0, cw * (1.0 - 2.0 * gutter) / np.where(l0 > 0, l0, 1.0), 0.0)
        sy = np.where(y2 > 0, ch * (1.0 - 2.0 * gutter) / np.where(y2 > 0, y2, 1.0), 0.0)
        scale = np.stack([sx, sy], axis=1)[:, None, :]
    cx, cy = (np.arange(m) % k) * cw + cw * gutter, (np.arange(m) // k) * ch + ch * gutter
    uv_rot = loc * scale + np.stack([cx, cy], axis=1)[:, None, :]
    # Undo the corner rotation so UV corner i belongs to F[f, i].
    UV = np.empty_like(uv_rot)
    np.put_along_axis(UV, idx[:, :, None], uv_rot, axis=1)
    return P.reshape(-1, 3).copy(), np.arange(3 * m, dtype=np.int64).reshape(m, 3), UV.reshape(-1, 2), F.ravel().copy()
