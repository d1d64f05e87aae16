"""A software triangle rasterizer in vectorised NumPy: depth buffer, face ids and barycentrics.

This is the engine of the shading and shadow-mapping labs. It follows what GPUs do, in the
conventions of :mod:`geomlib.camera` (OpenGL; ``docs/cameras.md``):

1. **Clipping** in homogeneous clip space. Triangles entirely outside one plane of the view
   frustum are dropped. Triangles that cross the near plane ``z = -w`` are cut (a triangle with one
   vertex behind becomes two, with two behind one); so are the rare triangles that reach beyond a
   guard band of ``2**19`` pixels around the image, which keeps the fixed-point arithmetic below
   exact. Every piece remembers its barycentric weights with respect to the ORIGINAL triangle.
2. **Snapping** of window coordinates to fixed point with 8 sub-pixel bits (1/256 pixel), as GPUs do.
   Coverage is then decided in exact ``int64`` arithmetic.
3. **Coverage** is tested at pixel centres with the top-left fill rule: a pixel centre exactly on an
   edge belongs to the triangle for which that edge is a *top* edge (horizontal, interior below it
   in the picture) or a *left* edge (interior to its right). Triangles that share an edge therefore
   cover every pixel along it exactly once: no cracks, no double coverage. Each triangle is scanned
   row by row; the span of covered pixels in a row is solved exactly from the three edge functions,
   so a thin diagonal triangle costs its rows and covered pixels, not its bounding box.
4. **Depth test**: window depth ``(z_ndc + 1) / 2`` is interpolated linearly in screen space;
   fragments beyond the far plane (depth > 1) are discarded; the nearest fragment wins and ties go
   to the lower face id.
5. **Barycentrics** of the winning fragment are computed perspective-correctly (screen-space
   weights divided by clip ``w``, renormalised) and mapped back to the original triangle's vertices.

Everything is vectorised over triangles, triangle rows and pixels; the only Python loops run over
chunks (bounded memory) and over the few clip planes.

Examples
--------
>>> import numpy as np
>>> from geomlib.camera import look_at, perspective
>>> from geomlib.raster import rasterize
>>> V = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0.0]])
>>> M = perspective(60, 1.0, 0.1, 10) @ look_at((0, 0, 3), (0, 0, 0))
>>> g = rasterize(V, [[0, 1, 2]], M, 32, 32, attributes={"position": V})
>>> g.depth.shape, int(g.face_id[16, 16]), float(g.bary[16, 16].sum().round(12))
((32, 32), 0, 1.0)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from geomlib import portable
from geomlib.validate import MeshError, as_array, as_faces, check_choice, check_int

__all__ = ["GBuffer", "rasterize", "rasterize_clip", "SUBPIXEL_BITS", "MAX_SIZE", "GUARD_BAND_PX"]

#: Fixed-point precision of snapped window coordinates (1/256 pixel).
SUBPIXEL_BITS = 8
#: Largest accepted image width or height.
MAX_SIZE = 2**15
#: Triangles reaching further than this many pixels outside the image are clipped geometrically.
GUARD_BAND_PX = 2**19

_SUB = 1 << SUBPIXEL_BITS
_HALF = _SUB // 2
_PAIR_BUDGET = 1 << 16  # (triangle, row) pairs per chunk
_FRAG_BUDGET = 1 << 17  # fragments per chunk
_PIX_BLOCK = 1 << 16  # pixels per block when computing barycentrics and attributes
_NO_TRI = np.iinfo(np.int64).max


@dataclass(eq=False)
class GBuffer:
    """Per-pixel output of :func:`rasterize`, in image layout ``(height, width)``, row 0 = TOP.

    Pixel ``[row, col]`` was sampled at its centre, image coordinates ``(col + 0.5, row + 0.5)``
    (see :func:`geomlib.camera.project`).

    Attributes
    ----------
    depth : (h, w) float64
        Window depth ``(z_ndc + 1) / 2`` in ``[0, 1]`` (0 = near plane) of the visible surface;
        ``np.inf`` where no triangle covers the pixel (background).
    face_id : (h, w) int64
        Index into ``F`` of the visible triangle, -1 for background.
    bary : (h, w, 3) float64 or None
        Perspective-correct barycentric coordinates of the pixel centre with respect to the
        vertices ``F[face_id]`` of the ORIGINAL (unclipped) triangle; non-negative, summing to 1.
        Zero for background. ``None`` when rasterized with ``depth_only=True``.
    mask : (h, w) bool
        True where a triangle covers the pixel.
    attributes : dict of str -> (h, w, k) or (h, w) float64
        The ``attributes`` passed to :func:`rasterize`, interpolated perspective-correctly
        (a per-vertex array ``(n,)`` gives ``(h, w)``). Zero for background.
    faces : (m, 3) int64
        The triangles that were rasterized (needed by :meth:`interpolate`).
    n_vertices : int
        Number of vertices, the expected length of per-vertex arrays.
    """

    depth: np.ndarray
    face_id: np.ndarray
    bary: np.ndarray | None
    mask: np.ndarray
    attributes: dict[str, np.ndarray] = field(default_factory=dict)
    faces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))
    n_vertices: int = 0

    def __repr__(self) -> str:
        kind = "depth only" if self.bary is None else f"attributes {sorted(self.attributes)}"
        return f"GBuffer({self.height}x{self.width} pixels, {int(self.mask.sum())} covered, {kind})"

    @property
    def height(self) -> int:
        return self.depth.shape[0]

    @property
    def width(self) -> int:
        return self.depth.shape[1]

    def interpolate(self, values, *, name: str = "values") -> np.ndarray:
        """Interpolate a per-vertex array over the image with the stored barycentrics.

        Parameters
        ----------
        values : array_like (n,) or (n, k)
            One value (or row) per vertex of the rasterized mesh.
        name : str
            Name used in error messages.

        Returns
        -------
        (h, w) or (h, w, k) float64
            ``sum_i bary[..., i] * values[F[face_id, i]]``; zero for background pixels.
        """
        where = "GBuffer.interpolate"
        if self.bary is None:
            raise MeshError(f"{where}: this G-buffer was rasterized with depth_only=True and has no barycentrics")
        A = _vertex_values(values, self.n_vertices, name, where)
        return _interpolate(A, self.faces, self.face_id, self.bary, self.mask)


def _vertex_values(values, n: int, name: str, where: str) -> np.ndarray:
    A = as_array(values, name, dtype=np.float64, where=where)
    if A.ndim not in (1, 2) or A.shape[0] != n:
        raise MeshError(
            f"{where}: {name} has shape {A.shape}, expected ({n},) or ({n}, k): one value or row per vertex"
        )
    return A


def _interpolate(A: np.ndarray, F: np.ndarray, face_id: np.ndarray, bary: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``sum_i bary[..., i] * A[F[face_id, i]]`` on covered pixels, zero elsewhere; blockwise for memory."""
    out = np.zeros((mask.size,) + A.shape[1:])
    pix = np.flatnonzero(mask)
    fid, b = face_id.reshape(-1), bary.reshape(-1, 3)
    for a in range(0, len(pix), _PIX_BLOCK):
        p = pix[a : a + _PIX_BLOCK]
        w = b[p].reshape((len(p), 3) + (1,) * (A.ndim - 1))  # corner weights against (p, 3, k) corner values
        out[p] = portable.dot(w, A[F[fid[p]]], axis=1)  # not einsum: no FMA (same bits on every CPU)
    return out.reshape(mask.shape + A.shape[1:])


def rasterize(
    V,
    F,
    M,
    width: int,
    height: int,
    *,
    attributes: Mapping[str, np.ndarray] | None = None,
    cull: str = "none",
    depth_only: bool = False,
) -> GBuffer:
    """Rasterize a triangle mesh seen through a camera into a :class:`GBuffer`.

    Parameters
    ----------
    V : array_like (n, 3)
        World positions.
    F : array_like (m, 3)
        Triangle indices into ``V`` (degenerate and duplicate faces are allowed; they draw nothing
        or lose the depth tie to the earlier copy).
    M : array_like (4, 4)
        Clip-from-world matrix, ``projection @ view`` (column vectors; :mod:`geomlib.camera`). Its
        visible side must have clip ``w > 0``, as every perspective or orthographic matrix has.
    width, height : int
        Image size in pixels, each in ``1..MAX_SIZE``.
    attributes : dict of str -> array_like (n, k) or (n,), optional
        Per-vertex values (e.g. ``"position"``, ``"normal"``, ``"uv"``, ``"tangent"``) to interpolate
        perspective-correctly into ``GBuffer.attributes``.
    cull : {"none", "back", "front"}
        Drop back- or front-facing triangles. A triangle is front-facing when its vertices run
        counter-clockwise in NDC (x right, y up), OpenGL's default ``glFrontFace(GL_CCW)``.
    depth_only : bool
        Compute only ``depth``, ``face_id`` and ``mask`` (``bary`` is None): faster and lighter, for
        shadow maps.

    Returns
    -------
    GBuffer
        Arrays of shape ``(height, width, ...)`` with row 0 at the top of the picture.

    Raises
    ------
    MeshError
        Bad shapes, non-finite values, out-of-range indices, bad ``cull`` or image size.
    """
    where = "rasterize"
    V = as_array(V, "V", shape=(None, 3), where=where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    C = portable.matmul(V, M[:, :3].T) + M[:, 3]  # not BLAS: the same bits on every CPU (geomlib.portable)
    if not np.all(np.isfinite(C)):
        r = int(np.flatnonzero(~np.isfinite(C).all(axis=1))[0])
        raise MeshError(f"{where}: M @ V overflows at vertex {r} (clip coordinates {tuple(C[r])})")
    return _rasterize(C, F, width, height, attributes, cull, depth_only, where)


def rasterize_clip(
    Vclip,
    F,
    width: int,
    height: int,
    *,
    attributes: Mapping[str, np.ndarray] | None = None,
    cull: str = "none",
    depth_only: bool = False,
) -> GBuffer:
    """Rasterize triangles given directly in homogeneous clip coordinates.

    Same as :func:`rasterize` with ``Vclip = [V, 1] @ M.T``; use it when vertices were transformed by
    a vertex shader of your own (e.g. skinning or displacement).

    Parameters
    ----------
    Vclip : array_like (n, 4)
        Clip-space positions ``(x, y, z, w)``; the visible volume is ``-w <= x, y, z <= w``.
    F, width, height, attributes, cull, depth_only
        As in :func:`rasterize`.
    """
    where = "rasterize_clip"
    C = as_array(Vclip, "Vclip", shape=(None, 4), where=where)
    return _rasterize(C, F, width, height, attributes, cull, depth_only, where)


def _rasterize(C, F, width, height, attributes, cull, depth_only, where) -> GBuffer:
    n = len(C)
    F = as_faces(F, n, allow_degenerate=True, allow_duplicate=True, where=where)
    width = check_int(width, "width", minimum=1, maximum=MAX_SIZE, where=where)
    height = check_int(height, "height", minimum=1, maximum=MAX_SIZE, where=where)
    check_choice(cull, "cull", ("none", "back", "front"), where=where)
    if not isinstance(depth_only, bool | np.bool_):
        raise MeshError(f"{where}: depth_only must be True or False, got {depth_only!r}")
    attrs: dict[str, np.ndarray] = {}
    if attributes is not None:
        if not isinstance(attributes, Mapping):
            raise MeshError(
                f"{where}: attributes must be a dict name -> per-vertex array, got {type(attributes).__name__}"
            )
        if depth_only and len(attributes):
            raise MeshError(f"{where}: attributes need barycentrics; they cannot be combined with depth_only=True")
        for key, val in attributes.items():
            if not isinstance(key, str):
                raise MeshError(f"{where}: attribute names must be strings, got {key!r}")
            attrs[key] = _vertex_values(val, n, f"attributes[{key!r}]", where)

    S = _setup(C, F, width, height, cull)
    face_id, depth = _scan(S, width, height)  # face_id holds the winning setup triangle for now
    mask = face_id >= 0
    shape = (height, width)
    bary = None
    if depth_only:
        face_id[mask] = S["orig"][face_id[mask]]
    else:
        pix = np.flatnonzero(mask)
        tri = face_id[pix]
        face_id[pix] = S["orig"][tri]
        bary = np.zeros((width * height, 3))
        for a in range(0, len(pix), _PIX_BLOCK):
            sl = slice(a, a + _PIX_BLOCK)
            bary[pix[sl]] = _barycentrics(pix[sl], tri[sl], S, width)
    g = GBuffer(
        depth=depth.reshape(shape),
        face_id=face_id.reshape(shape),
        bary=None if bary is None else bary.reshape(shape + (3,)),
        mask=mask.reshape(shape),
        faces=F,
        n_vertices=n,
    )
    for key, A in attrs.items():
        g.attributes[key] = _interpolate(A, F, g.face_id, g.bary, g.mask)
    return g


# ----------------------------------------------------------------------------------------------
# Clipping


_N_PLANES = 5


def _plane_distance(P: np.ndarray, plane: int, gx: float, gy: float) -> np.ndarray:
    """Signed distance (>= 0 inside) of clip-space points ``(..., 4)`` to clip plane 0..4.

    Plane 0 is the near plane ``z = -w``, planes 1-4 the guard band ``x = +-gx w``, ``y = +-gy w``.
    Written elementwise (no BLAS) so that a vertex shared by two triangles gets bitwise identical
    values in both.
    """
    x, y, z, w = P[..., 0], P[..., 1], P[..., 2], P[..., 3]
    if plane == 0:
        return z + w
    if plane == 1:
        return gx * w - x
    if plane == 2:
        return gx * w + x
    if plane == 3:
        return gy * w - y
    return gy * w + y


def _clip_polygons(T: np.ndarray, gx: float, gy: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sutherland-Hodgman clipping of triangles ``T (k, 3, 4)`` against the planes of :func:`_plane_distance`.

    Returns polygons ``P (k, 8, 4)``, their barycentric weights w.r.t. the input triangle
    ``B (k, 8, 3)`` and vertex counts ``(k,)`` (0 when nothing is left). A cut point is always
    computed from the edge's inside vertex towards its outside vertex, so two triangles sharing the
    edge produce the same point bit for bit: watertightness survives clipping.
    """
    k = len(T)
    K = 3 + _N_PLANES  # each plane adds at most one vertex to a convex polygon
    P = np.zeros((k, K, 4))
    P[:, :3] = T
    B = np.zeros((k, K, 3))
    B[:, :3] = np.eye(3)
    cnt = np.full(k, 3, np.int64)
    slots = np.arange(K)
    rows = np.arange(k)[:, None]
    for plane in range(_N_PLANES):
        d = _plane_distance(P, plane, gx, gy)
        valid = slots < cnt[:, None]
        inside = d >= 0
        prev = np.maximum(np.where(slots == 0, cnt[:, None] - 1, slots - 1), 0)
        in_prev = inside[rows, prev]
        # Edge prev -> cur emits the cut point if it crosses the plane, then cur if cur is inside.
        emit_cut = valid & (inside != in_prev)
        emit_cur = valid & inside
        n_out = emit_cut.astype(np.int64) + emit_cur
        start = np.cumsum(n_out, axis=1) - n_out
        Pn, Bn = np.zeros_like(P), np.zeros_like(B)
        r, c = np.nonzero(emit_cut)
        if len(r):
            pc = prev[r, c]
            cur_in = inside[r, c]
            ia = np.where(cur_in, c, pc)  # the edge's inside end
            ib = np.where(cur_in, pc, c)
            da, db = d[r, ia], d[r, ib]
            t = (da / (da - db))[:, None]
            Pa, Pb, Ba, Bb = P[r, ia], P[r, ib], B[r, ia], B[r, ib]
            Pn[r, start[r, c]] = Pa + t * (Pb - Pa)
            Bn[r, start[r, c]] = Ba + t * (Bb - Ba)
        r, c = np.nonzero(emit_cur)
        dst = start[r, c] + emit_cut[r, c]
        Pn[r, dst] = P[r, c]
        Bn[r, dst] = B[r, c]
        P, B, cnt = Pn, Bn, n_out.sum(axis=1)
    return P, B, cnt


def _clip_faces(T: np.ndarray, faces: np.ndarray, gx: float, gy: float):
    """Clip triangles ``T (k, 3, 4)`` of the given face ids; return fan-triangulated pieces ``(T, B, orig)``."""
    P, B, cnt = _clip_polygons(T, gx, gy)
    Ts, Bs, orig = [], [], []
    for j in range(1, P.shape[1] - 1):  # fan (0, j, j + 1) over at most 6 triangles
        sel = np.flatnonzero(cnt > j + 1)
        idx = np.array([0, j, j + 1])
        Ts.append(P[sel][:, idx])
        Bs.append(B[sel][:, idx])
        orig.append(faces[sel])
    return np.concatenate(Ts), np.concatenate(Bs), np.concatenate(orig)


# ----------------------------------------------------------------------------------------------
# Setup: clip, project, snap, cull


def _window(x, y, z, w, width: int, height: int):
    """Image coordinates (x right, y DOWN, pixels) and window depth; elementwise and deterministic."""
    return (x / w + 1.0) * (0.5 * width), (1.0 - y / w) * (0.5 * height), (z / w + 1.0) * 0.5


def _snap(x: np.ndarray) -> np.ndarray:
    return np.rint(x * _SUB).astype(np.int64)


def _setup(C: np.ndarray, F: np.ndarray, width: int, height: int, cull: str) -> dict[str, np.ndarray]:
    """Per-triangle data for scan conversion, for the triangles (or clipped pieces) that may cover a pixel.

    Arrays are laid out ``(3, t)`` (one row per triangle corner), which keeps NumPy's loops long.
    Pieces are ordered by original face index, so a lower index here means a lower face id.
    """
    gx = 1.0 + 2.0 * GUARD_BAND_PX / width
    gy = 1.0 + 2.0 * GUARD_BAND_PX / height
    x, y, z, w = (np.ascontiguousarray(C[:, i]) for i in range(4))
    # Per vertex: outcodes against the view frustum, and whether it lies outside a clip plane.
    oc = np.zeros(len(C), np.uint8)
    for bit, out in enumerate((x > w, x < -w, y > w, y < -w, z < -w, z > w)):
        oc |= out.astype(np.uint8) << bit
    needs_clip = w <= 0
    for plane in range(_N_PLANES):
        needs_clip |= _plane_distance(C, plane, gx, gy) < 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        xi, yi, zi = _window(x, y, z, np.where(needs_clip, 1.0, w), width, height)
    xi[needs_clip] = yi[needs_clip] = zi[needs_clip] = 0.0  # never used: such faces are clipped or rejected
    Xv, Yv = _snap(xi), _snap(yi)

    Ft = F.T
    reject = (oc[Ft[0]] & oc[Ft[1]] & oc[Ft[2]]) != 0  # all three corners outside one frustum plane
    nc = needs_clip[Ft]
    hard = (nc[0] | nc[1] | nc[2]) & ~reject
    easy = np.flatnonzero(~reject & ~hard)
    Fe = Ft[:, easy]
    X, Y, Z, Wc, orig, Bw = Xv[Fe], Yv[Fe], zi[Fe], w[Fe], easy, None
    hard = np.flatnonzero(hard)
    if len(hard):
        Th, Bh, oh = _clip_faces(C[F[hard]], hard, gx, gy)
        ok = (Th[..., 3] > 0).all(axis=1)  # the guard band implies w >= 0; w == 0 only at a point at infinity
        Th, Bh, oh = Th[ok].transpose(2, 1, 0), Bh[ok], oh[ok]  # Th: (4, 3, k)
        xh, yh, zh = _window(Th[0], Th[1], Th[2], Th[3], width, height)
        order = np.argsort(np.concatenate([orig, oh]), kind="stable")
        X = np.concatenate([X, _snap(xh)], axis=1)[:, order]
        Y = np.concatenate([Y, _snap(yh)], axis=1)[:, order]
        Z = np.concatenate([Z, zh], axis=1)[:, order]
        Wc = np.concatenate([Wc, Th[3]], axis=1)[:, order]
        Bw = np.concatenate([np.broadcast_to(np.eye(3), (len(orig), 3, 3)), Bh])[order]
        orig = np.concatenate([orig, oh])[order]

    # Twice the signed area in image coordinates (y down): < 0 means counter-clockwise in NDC = front-facing.
    A = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0])
    keep = A != 0
    if cull == "back":
        keep &= A < 0
    elif cull == "front":
        keep &= A > 0
    # Pixel-centre bounding box; the centre of column c is at 256 c + 128 in fixed point.
    c0 = np.maximum(-((_HALF - np.minimum(np.minimum(X[0], X[1]), X[2])) // _SUB), 0)
    c1 = np.minimum((np.maximum(np.maximum(X[0], X[1]), X[2]) - _HALF) // _SUB, width - 1)
    r0 = np.maximum(-((_HALF - np.minimum(np.minimum(Y[0], Y[1]), Y[2])) // _SUB), 0)
    r1 = np.minimum((np.maximum(np.maximum(Y[0], Y[1]), Y[2]) - _HALF) // _SUB, height - 1)
    keep &= (c0 <= c1) & (r0 <= r1)
    k = np.flatnonzero(keep)
    X, Y, Z, Wc, A, orig = X[:, k], Y[:, k], Z[:, k], Wc[:, k], A[k], orig[k]
    s = np.where(A > 0, 1, -1)
    # Edge i -> i+1: E(P) = s ((X[i+1] - X[i]) (PY - Y[i]) - (Y[i+1] - Y[i]) (PX - X[i])) = alpha PX + gamma PY + delta0.
    # A pixel centre is covered when E > 0 for all three edges, or E == 0 on a top or left edge
    # (the top-left rule: exactly one of two triangles sharing an edge owns the edge). In integers,
    # "E > 0 or (E == 0 and owner)" is "E + owner - 1 >= 0", so owner - 1 is folded into delta.
    Xn, Yn = np.roll(X, -1, axis=0), np.roll(Y, -1, axis=0)
    alpha = s * (Y - Yn)
    gamma = s * (Xn - X)
    owner = (alpha > 0) | ((alpha == 0) & (gamma > 0))
    delta = owner - 1 - (alpha * X + gamma * Y)
    ints = np.concatenate([alpha, gamma, delta, r0[None, k], c0[None, k], c1[None, k]])
    # Window depth is affine in screen space: z = z0 + zx (PX - X0) + zy (PY - Y0), fixed-point units.
    Xf, Yf, Af = X.astype(np.float64), Y.astype(np.float64), A.astype(np.float64)
    dX1, dX2, dY1, dY2 = Xf[1] - Xf[0], Xf[2] - Xf[0], Yf[1] - Yf[0], Yf[2] - Yf[0]
    dz1, dz2 = Z[1] - Z[0], Z[2] - Z[0]
    zx = (dz1 * dY2 - dz2 * dY1) / Af
    zy = (dz2 * dX1 - dz1 * dX2) / Af
    return {
        "orig": orig,  # (t,) original face of each triangle, non-decreasing
        "B": None if Bw is None else Bw[k],  # (t, 3, 3) weights of its corners over the original face's, or identity
        "ints": ints,  # (12, t) int64: alpha, gamma, delta (3 rows each), first row, first and last column
        "nrows": r1[k] - r0[k] + 1,  # (t,)
        "plane": np.stack([Z[0], zx, zy, Xf[0], Yf[0]]),  # (5, t)
        "X": Xf,  # (3, t) snapped image coordinates, fixed-point units
        "Y": Yf,
        "w": Wc,  # (3, t) clip w
        "A": Af,  # (t,) twice the signed area, fixed-point units squared
    }


# ----------------------------------------------------------------------------------------------
# Scan conversion and depth test


def _expand(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For consecutive runs of the given lengths: the run of each element and its position in the run."""
    run = np.repeat(np.arange(len(counts)), counts)
    start = np.cumsum(counts) - counts
    return run, np.arange(len(run)) - start[run]


def _chunks(sizes: np.ndarray, budget: int):
    """Split ``range(len(sizes))`` into consecutive ``(begin, end)`` with sum of sizes <= budget (or one item)."""
    cum = np.cumsum(sizes)
    b = 0
    while b < len(sizes):
        base = cum[b - 1] if b else 0
        e = max(int(np.searchsorted(cum, base + budget, side="right")), b + 1)
        yield b, e
        b = e


def _scan(S: dict, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Z-buffer all triangles; return per pixel (flat, row-major) the winning triangle (-1: none) and depth."""
    npix = width * height
    # Slightly beyond the far plane: a fragment wins only with depth <= 1, with no extra test.
    far = np.nextafter(1.0, 2.0)
    zbuf = np.full(npix, far)
    tbuf = np.full(npix, _NO_TRI, np.int64)
    # Chunks bound the memory of (triangle, row) pairs and fragments and keep them cache-sized.
    for t0, t1 in _chunks(S["nrows"], _PAIR_BUDGET):
        _scan_chunk(S, t0, t1, width, zbuf, tbuf)
    empty = tbuf == _NO_TRI
    tbuf[empty] = -1
    np.maximum(zbuf, 0.0, out=zbuf)
    zbuf[empty] = np.inf
    return tbuf, zbuf


def _scan_chunk(S: dict, t0: int, t1: int, width: int, zbuf: np.ndarray, tbuf: np.ndarray) -> None:
    """Scan-convert triangles ``t0:t1`` row by row and merge their fragments into the z-buffer."""
    run, k = _expand(S["nrows"][t0:t1])
    tri = run + t0
    e = np.take(S["ints"], tri, axis=1)
    r = e[9] + k
    PY = r * _SUB + _HALF
    # Solve alpha (256 c + 128) + beta >= 0 for the column c exactly, per edge: with
    # Q = floor((beta + 128 alpha) / (256 |alpha|)), c >= -Q if alpha > 0 and c <= Q if alpha < 0;
    # alpha == 0 (a horizontal edge) keeps all or nothing of the row.
    lo, hi = e[10], e[11]
    empty = np.zeros(len(tri), bool)
    for i in range(3):
        alpha = e[i]
        beta = e[3 + i] * PY + e[6 + i]
        Q = (beta + _HALF * alpha) // np.where(alpha == 0, 1, _SUB * np.abs(alpha))
        lo = np.maximum(lo, np.where(alpha > 0, -Q, 0))
        hi = np.minimum(hi, np.where(alpha < 0, Q, width))
        empty |= (alpha == 0) & (beta < 0)
    counts = np.maximum(hi - lo + 1, 0)
    counts[empty] = 0
    nz = np.flatnonzero(counts)
    tri, r, lo, counts = tri[nz], r[nz], lo[nz], counts[nz]
    z0, zx, zy, X0, Y0 = np.take(S["plane"], tri, axis=1)
    z_start = z0 + zx * (lo * _SUB + _HALF - X0) + zy * (r * _SUB + _HALF - Y0)
    dz = zx * _SUB
    pix_start = r * width + lo
    for p0, p1 in _chunks(counts, _FRAG_BUDGET):
        c = counts[p0:p1]
        j = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
        pix = np.repeat(pix_start[p0:p1], c) + j
        z = np.repeat(z_start[p0:p1], c) + np.repeat(dz[p0:p1], c) * j
        _merge(zbuf, tbuf, pix, z, np.repeat(tri[p0:p1], c))


def _merge(zbuf: np.ndarray, tbuf: np.ndarray, pix: np.ndarray, z: np.ndarray, t: np.ndarray) -> None:
    """Depth test: nearest wins; ties go to the lower triangle index (earlier chunks hold lower indices)."""
    better = z < zbuf[pix]
    if not better.all():
        pix, z, t = pix[better], z[better], t[better]
    np.minimum.at(zbuf, pix, z)
    win = z == zbuf[pix]
    pix = pix[win]
    tbuf[pix] = _NO_TRI
    np.minimum.at(tbuf, pix, t[win])


# ----------------------------------------------------------------------------------------------
# Barycentrics and interpolation


def _barycentrics(pix: np.ndarray, tri: np.ndarray, S: dict, width: int) -> np.ndarray:
    """Perspective-correct barycentrics ``(p, 3)`` w.r.t. the original triangles, at the centres of pixels ``pix``."""
    X, Y, w, A = np.take(S["X"], tri, axis=1), np.take(S["Y"], tri, axis=1), np.take(S["w"], tri, axis=1), S["A"][tri]
    PX = (pix % width) * _SUB + _HALF - X[0]
    PY = (pix // width) * _SUB + _HALF - Y[0]
    dX1, dX2, dY1, dY2 = X[1] - X[0], X[2] - X[0], Y[1] - Y[0], Y[2] - Y[0]
    l1 = (PX * dY2 - PY * dX2) / A
    l2 = (PY * dX1 - PX * dY1) / A
    # Screen-space weights -> perspective-correct: divide by clip w and renormalise. The pixel centre
    # is inside the snapped triangle, so the weights are >= 0 up to rounding, which the clip removes.
    q = np.clip(np.stack([1.0 - l1 - l2, l1, l2], axis=1), 0.0, None) / w.T
    q /= q.sum(axis=1, keepdims=True)
    if S["B"] is None:
        return q
    b = portable.dot(q[:, :, None], S["B"][tri], axis=1)  # clipped corners' weights; same bits on every CPU
    np.clip(b, 0.0, None, out=b)
    return b / b.sum(axis=1, keepdims=True)
