"""Inside or outside: four ways to sign a mesh distance (Task 4).

* **normal** (cheap): the sign of ``(p - q) . n_f`` with ``n_f`` the normal of the closest
  triangle. Wrong when the closest point ``q`` is on an edge or a vertex shared by faces that
  disagree (thin concave regions, sharp edges): there the closest face is not unique and one of
  them sees ``p`` on its front side although ``p`` is inside.
* **pseudonormal** (Baerentzen and Aanaes, 2005): the same dot product, with the normal of the
  closest *feature*: the face normal in a face's interior, the sum of the two face normals on an
  edge, the angle-weighted sum of the face normals around a vertex. Exact for closed, consistently
  oriented meshes.
* **vote**: cast a few rays from ``p`` and count surface crossings; an odd count means inside. The
  majority over rays in different directions survives rays grazing an edge or leaking through a
  hole (the engine's default; it needs no orientation at all).
* **winding**: the generalised winding number ``w(p) = sum_f Omega_f(p) / (4 pi)`` (``Omega_f``
  the signed solid angle of triangle ``f`` seen from ``p``) is 1 inside and 0 outside a closed
  mesh and degrades gracefully on holes; inside when ``w > 1/2``.

On a mesh with a hole, the normal and pseudonormal signs follow the faces near the hole (points
whose closest feature is the hole's rim may flip), the vote is right except where most rays leave
through the hole, and the winding number drifts smoothly from 1 towards 0 near it.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import check_int, check_mesh

from .analytic import as_points

__all__ = [
    "VOTE_DIRECTIONS",
    "face_normals_unit",
    "pseudonormals",
    "sign_normal",
    "sign_pseudonormal",
    "sign_vote",
    "winding_number",
]

#: Ray directions of the vote: three unit vectors, none parallel to an axis or to a grid diagonal
#: (axis-aligned rays through a grid of samples hit axis-aligned meshes exactly on their edges).
VOTE_DIRECTIONS = np.array(
    [[0.8273, 0.3910, 0.4031], [-0.3391, 0.8723, -0.3522], [-0.4150, -0.4489, 0.7913]], dtype=np.float64
)
VOTE_DIRECTIONS /= np.linalg.norm(VOTE_DIRECTIONS, axis=1, keepdims=True)


def face_normals_unit(V, F) -> np.ndarray:
    """Unit face normals ``(m, 3)`` (given); zero for zero-area faces."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    L = np.linalg.norm(N, axis=1, keepdims=True)
    return np.divide(N, L, out=np.zeros_like(N), where=L > 0)


def pseudonormals(V, F) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angle-weighted pseudonormals of faces, edges and vertices.

    Parameters
    ----------
    V : (n, 3) array_like
    F : (m, 3) array_like of int

    Returns
    -------
    face_n : (m, 3) float64
        Unit face normals.
    edge_n : (m, 3, 3) float64
        ``edge_n[f, e]`` the normal of edge ``e`` of face ``f`` (``e = 0, 1, 2`` for ``ab, bc, ca``):
        the sum of the unit normals of all faces sharing that undirected edge.
    vertex_n : (n, 3) float64
        Angle-weighted vertex normals ``sum_f alpha_f n_f`` (``alpha_f`` the corner angle of ``f``
        at the vertex).

    Notes
    -----
    None of them needs to be normalised: only the sign of ``(p - q) . n`` is used.
    """
    where = "pseudonormals"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    # BEGIN SOLUTION: Task 4 (sign): pseudonormal: face normals; edge normals = sum over faces sharing the undirected edge (np.unique on sorted edge keys + np.bincount); vertex normals = sum of corner angle * face normal
    FN = face_normals_unit(V, F)
    m = len(F)
    E = np.stack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]], axis=1).reshape(-1, 2)  # (3m, 2)
    key = np.sort(E, axis=1)
    _, inv = np.unique(key[:, 0] * len(V) + key[:, 1], return_inverse=True)
    rep = np.repeat(FN, 3, axis=0)
    acc = np.stack([np.bincount(inv, weights=rep[:, k]) for k in range(3)], axis=1)  # sum per edge
    EN = acc[inv].reshape(m, 3, 3)
    ang = np.empty((m, 3))
    for k in range(3):  # three corners: a loop over corners, not over faces
        p, q, r = V[F[:, k]], V[F[:, (k + 1) % 3]], V[F[:, (k + 2) % 3]]
        u, v = q - p, r - p
        ang[:, k] = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
    W = (ang[:, :, None] * FN[:, None, :]).reshape(-1, 3)  # (3m, 3) corner contributions
    VN = np.stack([np.bincount(F.ravel(), weights=W[:, k], minlength=len(V)) for k in range(3)], axis=1)
    return FN, EN, VN
    # END SOLUTION


def _signs(x: np.ndarray) -> np.ndarray:
    return np.where(x < 0, -1.0, 1.0)


def sign_normal(V, F, P, face, closest) -> np.ndarray:
    """Sign from the closest face's normal: ``sign((p - q) . n_face)``, ``+1`` on ties.

    Parameters
    ----------
    V, F : the mesh
    P : (n, 3) query points
    face : (n,) int
        Closest triangle of each point.
    closest : (n, 3)
        Closest point ``q`` on it.

    Returns
    -------
    s : (n,) float64 in ``{-1, +1}``
    """
    where = "sign_normal"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    P = as_points(P, where)
    face, closest = _closest_args(face, closest, len(P), len(F), where)
    # BEGIN SOLUTION: Task 4 (sign): normal sign: s = sign((p - q) . n_f), +1 when the dot product is 0
    return _signs(np.einsum("ij,ij->i", P - closest, face_normals_unit(V, F)[face]))
    # END SOLUTION


def sign_pseudonormal(V, F, P, face, closest, region, normals=None) -> np.ndarray:
    """Sign from the pseudonormal of the closest feature (face, edge or vertex).

    Parameters
    ----------
    V, F, P, face, closest : as in :func:`sign_normal`
    region : (n,) int
        Voronoi region of the closest point on ``face`` (0 interior, 1-3 vertices, 4-6 edges).
    normals : tuple, optional
        ``pseudonormals(V, F)`` if already computed.

    Returns
    -------
    s : (n,) float64 in ``{-1, +1}``: ``sign((p - q) . n_feature)``, ``+1`` on ties.
    """
    where = "sign_pseudonormal"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    P = as_points(P, where)
    face, closest = _closest_args(face, closest, len(P), len(F), where)
    region = np.asarray(region, np.int64).reshape(-1)
    if region.shape != (len(P),) or np.any((region < 0) | (region > 6)):
        from geomlib.validate import MeshError

        raise MeshError(f"{where}: region must be ({len(P)},) integers in 0..6")
    FN, EN, VN = pseudonormals(V, F) if normals is None else normals
    # BEGIN SOLUTION: Task 4 (sign): pseudonormal sign: N = face normal (region 0), vertex normal of F[face, region-1] (1-3), edge normal EN[face, region-4] (4-6); s = sign((p - q) . N)
    N = FN[face].copy()
    vert = (region >= 1) & (region <= 3)
    edge = region >= 4
    N[vert] = VN[F[face[vert], region[vert] - 1]]
    N[edge] = EN[face[edge], region[edge] - 4]
    return _signs(np.einsum("ij,ij->i", P - closest, N))
    # END SOLUTION


def _closest_args(face, closest, n: int, m: int, where: str):
    from geomlib.validate import MeshError, as_array

    face = as_array(face, "face", dtype=np.int64, shape=(n,), where=where)
    if n and (face.min() < 0 or face.max() >= m):
        raise MeshError(f"{where}: face indices must be in 0..{m - 1}")
    closest = as_array(closest, "closest", dtype=np.float64, shape=(n, 3), where=where)
    return face, closest


def sign_vote(V, F, P, *, directions=None, bvh=None) -> np.ndarray:
    """Sign by ray parity with a majority vote.

    Parameters
    ----------
    V, F : the mesh (need not be closed or oriented)
    P : (n, 3) query points
    directions : (k, 3) array_like, optional
        Ray directions (default :data:`VOTE_DIRECTIONS`, k = 3); no component may be exactly 0.
    bvh : BVH, optional
        A BVH of the mesh (built if missing).

    Returns
    -------
    s : (n,) float64 in ``{-1, +1}``: ``-1`` when more than half of the rays cross the surface an
    odd number of times.
    """
    where = "sign_vote"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    P = as_points(P, where)
    D = VOTE_DIRECTIONS if directions is None else as_points(directions, where, "directions")
    from geomlib.validate import MeshError

    if len(D) == 0 or np.any(D == 0):
        raise MeshError(f"{where}: directions must be non-empty with no zero component (slab tests divide by them)")
    check_int(len(D), "number of directions", minimum=1, where=where)
    from . import kernels
    from .bvh import build_bvh, bvh_arrays

    B = build_bvh(V, F) if bvh is None else bvh
    # BEGIN SOLUTION: Task 4 (sign): vote: crossings = kernels.crossings_kernel(...); inside when more than half of the rays cross an odd number of times
    odd = kernels.crossings_kernel(P, np.ascontiguousarray(D), V, F, *bvh_arrays(B)) % 2
    return np.where(2 * odd.sum(axis=1) > len(D), -1.0, 1.0)
    # END SOLUTION


def winding_number(V, F, P, *, chunk: int = 1 << 20) -> np.ndarray:
    """Generalised winding number of the mesh at each point (brute force, ``O(n m)``).

    ``w(p) = (1 / 4 pi) sum_f Omega_f(p)``, with the signed solid angle of the triangle
    ``(a, b, c)`` moved so that ``p`` is at the origin (Van Oosterom and Strackee, 1983)::

        tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|)

    Returns
    -------
    w : (n,) float64
        About 1 inside and 0 outside a closed, outward-oriented mesh.
    """
    where = "winding_number"
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    P = as_points(P, where)
    chunk = check_int(chunk, "chunk", minimum=1, where=where)
    T = V[F]
    w = np.zeros(len(P))
    step = max(1, chunk // len(F))
    # BEGIN SOLUTION: Task 4 (sign): winding number: for chunks of `step` points: a, b, c = corners - p; Omega = 2 atan2(a.(b x c), |a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|); w = sum Omega / 4 pi
    for s in range(0, len(P), step):  # bounded memory: step points x all triangles per pass
        X = T[None] - P[s : s + step, None, None, :]  # (k, m, 3, 3)
        a, b, c = X[:, :, 0], X[:, :, 1], X[:, :, 2]
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        num = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("ijk,ijk->ij", a, b) * lc
            + np.einsum("ijk,ijk->ij", b, c) * la
            + np.einsum("ijk,ijk->ij", c, a) * lb
        )
        w[s : s + step] = 2 * np.arctan2(num, den).sum(axis=1) / (4 * np.pi)
    return w
    # END SOLUTION
