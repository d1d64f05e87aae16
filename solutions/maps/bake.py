"""Task 6: baking a tangent-space normal map from a high-resolution mesh onto a low-resolution one."""

from __future__ import annotations

import numpy as np

from geomlib.geometry import bbox_diagonal, closest_points
from geomlib.textures import dilate, rasterize_uv
from geomlib.validate import MeshError, check_float, check_int, check_mesh

from .displacement import welded_vertex_normals
from .inputs import as_tangents, as_unit_vectors, check_uv, normalize_rows
from .shading import surface_frames
from .tangents import tangent_frames

__all__ = ["bake_normal_map", "project_to_surface", "barycentric"]


def barycentric(X: np.ndarray, A: np.ndarray, B: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Given: barycentric weights ``(k, 3)`` of points ``X`` in triangles ``(A, B, C)`` (all ``(k, 3)``).

    Solves ``X - A = b1 (B - A) + b2 (C - A)`` in the least-squares sense (exact for points in the
    plane); degenerate triangles give ``(1, 0, 0)``.
    """
    e1, e2, d = B - A, C - A, X - A
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    r1, r2 = (d * e1).sum(1), (d * e2).sum(1)
    den = d11 * d22 - d12 * d12
    ok = den > 1e-300
    den = np.where(ok, den, 1.0)
    b1 = np.where(ok, (d22 * r1 - d12 * r2) / den, 0.0)
    b2 = np.where(ok, (d11 * r2 - d12 * r1) / den, 0.0)
    return np.stack([1.0 - b1 - b2, b1, b2], axis=1)


def project_to_surface(V, F, P, D, max_distance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Given: where the lines ``P + t D`` first meet the mesh ``(V, F)``, in either direction.

    Casts a ray along ``D`` and one along ``-D`` from every point and keeps the nearer hit
    (libigl's Embree ``line_mesh_intersection``; Embree works in single precision, so the hit is
    recomputed in double precision on the triangle it found). Hits farther than
    ``max_distance`` and rays that miss fall back to the closest point of the surface
    (:func:`geomlib.geometry.closest_points`).

    Returns
    -------
    face : (k,) int64
        Triangle of ``F`` holding the surface point.
    bary : (k, 3) float64
        Its barycentric weights, so the point is ``bary @ V[F[face]]``.
    hit : (k,) bool
        True where the ray found it, False where the closest point was used.
    """
    from igl.embree import line_mesh_intersection

    k = len(P)
    if k == 0:
        return np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0, bool)
    R = np.asarray(line_mesh_intersection(np.ascontiguousarray(P), np.ascontiguousarray(D), V, F))
    face = R[:, 0].astype(np.int64)
    hit = face >= 0
    bary = np.zeros((k, 3))
    bary[:, 1], bary[:, 2] = R[:, 1], R[:, 2]
    bary[:, 0] = 1.0 - bary[:, 1] - bary[:, 2]
    # Embree traverses in single precision: redo the hit on the triangle it found in float64 (the
    # plane of the triangle along the line), so the surface point is exact to round-off.
    fh = np.where(hit, face, 0)
    A, B, C = (V[F[fh, i]] for i in range(3))
    nf = np.cross(B - A, C - A)
    den = np.einsum("ij,ij->i", D, nf)
    ok = hit & (np.abs(den) > 1e-300)
    t = np.einsum("ij,ij->i", A - P, nf) / np.where(ok, den, 1.0)
    X = P + t[:, None] * D
    bary = np.where(ok[:, None], barycentric(X, A, B, C), bary)
    hit &= np.abs(t) * np.linalg.norm(D, axis=1) <= max_distance
    miss = np.flatnonzero(~hit)
    if len(miss):
        _, f, C = closest_points(V, F, P[miss])
        face[miss] = f
        T = V[F[f]]
        bary[miss] = barycentric(C, T[:, 0], T[:, 1], T[:, 2])
    face[~hit & (face < 0)] = 0
    return face, bary, hit


def bake_normal_map(
    V_hi,
    F_hi,
    V_lo,
    F_lo,
    UV_lo,
    size: int,
    *,
    N_lo=None,
    tangents=None,
    N_hi=None,
    max_distance: float | None = None,
    padding: int | None = 8,
    return_mask: bool = False,
):
    """Bake the normals of a detailed mesh into a tangent-space normal map of a simple mesh.

    For every texel centre ``(u, v)`` of an ``size x size`` map that lies inside a UV triangle of
    the low mesh (:func:`geomlib.textures.rasterize_uv` gives the triangle and barycentrics ``b``):

    1. Interpolate on the low mesh: position ``P = b @ V_lo[f]``, normal and ``[T, w]`` tangent,
       and build the orthonormal frame ``(T', B', N')`` with :func:`surface_frames` (the same
       convention :func:`shade` uses to read the map back).
    2. Cast the line ``P + t N'`` in both directions onto the high mesh and keep the nearest hit
       (:func:`project_to_surface`; when nothing is hit within ``max_distance``, the closest point
       of the high mesh is used instead).
    3. Take the high mesh's smooth normal there (its vertex normals interpolated with the hit's
       barycentrics), ``n``, and express it in the low frame::

           m = normalize(n . T', n . B', n . N')

    Texels outside every UV triangle are then filled by :func:`geomlib.textures.dilate`
    (``padding`` texels around each chart), so bilinear lookups at chart borders and seams read
    chart values instead of background; texels beyond the padding hold the flat normal ``(0, 0, 1)``.

    Parameters
    ----------
    V_hi, F_hi : mesh
        The detailed surface.
    V_lo, F_lo : mesh
        The simple surface that will carry the map (close to the detailed one).
    UV_lo : (n_lo, 2) float in [0, 1]
        Texture coordinates of the low mesh (non-overlapping charts).
    size : int
        The map is ``size x size`` texels.
    N_lo : (n_lo, 3) float, optional
        Low-mesh normals. Default: area-weighted normals welded across UV seams
        (:func:`welded_vertex_normals`), so charts cut apart in UV still shade smoothly.
    tangents : (n_lo, 4) float, optional
        Low-mesh ``[T, w]``. Default: :func:`tangent_frames` of the low mesh with ``N_lo``.
    N_hi : (n_hi, 3) float, optional
        High-mesh normals. Default: area-weighted normals welded across seams, as for ``N_lo``.
    max_distance : float, optional
        Longest accepted ray hit; default 10% of the low mesh's bounding-box diagonal.
    padding : int or None
        Texels of padding around the charts (``None``: fill the whole map).
    return_mask : bool
        Also return the ``(size, size)`` bool mask of texels covered by a UV triangle.

    Returns
    -------
    normal_map : (size, size, 3) float64
        Unit tangent-space normals (encode them with :func:`encode_normal_map` to store them).
    mask : (size, size) bool
        Only with ``return_mask=True``.

    Raises
    ------
    MeshError
        Invalid meshes, missing or out-of-range UVs, bad parameters.
    """
    where = "bake_normal_map"
    V_hi, F_hi = check_mesh(V_hi, F_hi, where=where)
    V_lo, F_lo = check_mesh(V_lo, F_lo, where=where)
    UV_lo = check_uv(UV_lo, len(V_lo), where, in_range=True, name="UV_lo")
    size = check_int(size, "size", minimum=1, maximum=8192, where=where)
    if padding is not None:
        padding = check_int(padding, "padding", minimum=0, where=where)
    N_lo = welded_vertex_normals(V_lo, F_lo) if N_lo is None else as_unit_vectors(N_lo, len(V_lo), where, name="N_lo")
    if tangents is None:
        T, _, _, w = tangent_frames(V_lo, F_lo, UV_lo, N_lo)
        tangents = np.column_stack([T, w])
    else:
        tangents = as_tangents(tangents, len(V_lo), where)
    if N_hi is None:
        N_hi = welded_vertex_normals(V_hi, F_hi)
    else:
        N_hi = as_unit_vectors(N_hi, len(V_hi), where, name="N_hi")
    if max_distance is None:
        max_distance = 0.1 * bbox_diagonal(V_lo)
    else:
        max_distance = check_float(max_distance, "max_distance", minimum=0.0, where=where)
        if max_distance == 0:
            raise MeshError(f"{where}: max_distance must be > 0")
    face_id, bary = rasterize_uv(F_lo, UV_lo, size)
    covered = face_id >= 0
    f = face_id[covered]
    b = bary[covered]
    # BEGIN PROMPT
    # P = ...  # (k, 3) points of the low mesh at the k covered texel centres
    # Ti = ...  # (k, 3) T' there; likewise Bi and Ni (use surface_frames)
    # END PROMPT
    # BEGIN SOLUTION: Task 6 (low-mesh frames): P = b @ V_lo[f]; frame (T', B', N') from interpolated normal and [T, w]
    corners = F_lo[f]
    P = np.einsum("ki,kij->kj", b, V_lo[corners])
    Ti, Bi, Ni = surface_frames(
        np.einsum("ki,kij->kj", b, N_lo[corners]), np.einsum("ki,kij->kj", b, tangents[corners])
    )
    # END SOLUTION
    # BEGIN PROMPT
    # m = ...  # (k, 3) unit tangent-space normals of the covered texels
    # END PROMPT
    # BEGIN SOLUTION: Task 6 (sample the high mesh): nearest hit along +-N', high normal n, m = normalize(n.T', n.B', n.N')
    hf, hb, _ = project_to_surface(V_hi, F_hi, P, Ni, max_distance)
    n = normalize_rows(np.einsum("ki,kij->kj", hb, N_hi[F_hi[hf]]), fallback=(0.0, 0.0, 1.0))
    m = np.stack([(n * Ti).sum(1), (n * Bi).sum(1), (n * Ni).sum(1)], axis=1)
    m = normalize_rows(m, fallback=(0.0, 0.0, 1.0))
    # END SOLUTION
    img = np.zeros((size, size, 3))
    img[..., 2] = 1.0
    img[covered] = m
    img = dilate(img, covered, padding)
    img = normalize_rows(img, fallback=(0.0, 0.0, 1.0))
    return (img, covered) if return_mask else img
