"""Meshes and checks shared by the graded simplification tests (public: shipped with the lab).

Everything here is independent of any implementation of the lab: inputs come from
``geomlib.datasets`` (deterministic) or are written out by hand, and a simplified mesh is judged
by what the handout promises (face count, manifoldness, no flipped faces, boundary loops kept)
and by its distance to the input compared with the stored reference output's distance.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, portable, topology
from geomlib.geometry import closest_points, face_normals, mesh_distance
from geomlib.grading import checks

# --------------------------------------------------------------------------------------------
# tiny meshes (by hand)

#: Regular tetrahedron, outward oriented: every edge fails the link condition (the pair sits in a
#: tetrahedron, which would collapse into two copies of one triangle).
TET_V = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
TET_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])

#: Octahedron: vertices +-e_k; every vertex has valence 4, every edge passes the link condition.
OCTA_V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])

#: A fan of four triangles around vertex 0 in the plane z = 0, facing +z.
FAN_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])
FAN_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])

#: 3 x 3 grid of the unit square (``grid_patch(2)``): vertex 4 is the only interior vertex.
GRID_V, GRID_F = datasets.grid_patch(2)


def two_tetrahedra() -> tuple[np.ndarray, np.ndarray]:
    """Two disjoint tetrahedra (8 faces): no contraction keeps them manifold."""
    return np.r_[TET_V, TET_V + 3.0], np.r_[TET_F, TET_F + 4]


def cracked_sheet(n: int = 8, gap: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """Two wavy n x n sheets side by side, ``gap`` apart along x (a straight crack)."""
    V1, F1 = datasets.grid_patch(n)
    V1[:, 2] = 0.1 * portable.sin(3 * V1[:, 0]) * portable.cos(2 * V1[:, 1])
    V2 = V1.copy()
    V2[:, 0] += 1.0 + gap
    return np.r_[V1, V2], np.r_[F1, F1 + len(V1)]


def noisy_icosphere(level: int, sigma: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    V, F = datasets.icosphere(level)
    return datasets.add_noise(V, sigma, seed=seed, direction="normal", F=F), F


def random_quadrics(n: int, seed: int) -> np.ndarray:
    """``n`` symmetric positive semi-definite 4x4 matrices (sums of two random plane quadrics)."""
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(n, 2, 4))
    return P[:, 0, :, None] * P[:, 0, None, :] + P[:, 1, :, None] * P[:, 1, None, :]  # not einsum: no FMA


def rename_and_drop(F: np.ndarray, pairs) -> np.ndarray:
    """Naive reference for a sequence of contractions: rename j -> i, drop faces that repeat a vertex."""
    G = np.array(F, dtype=np.int64)
    for i, j in pairs:
        G[G == j] = i
        G = G[(G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])]
    return G


# --------------------------------------------------------------------------------------------
# judging a simplified mesh


def validity_problem(V0, F0, V, F, target: int, *, flips: bool = True) -> str | None:
    """What is wrong with ``(V, F)`` as a simplification of ``(V0, F0)`` to ``target`` faces (None: nothing).

    ``flips``: also look for faces that point against the input surface at the closest point to
    their centroid. That test assumes parts thicker than the output's triangles; on thin parts
    (an ant's legs at 20%) the closest point can lie on the far side, so it is switched off there.
    """
    V, F = np.asarray(V, float), np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        return f"expected V (n, 3) and F (m, 3), got shapes {V.shape} and {F.shape}"
    if not np.issubdtype(F.dtype, np.integer):
        return f"F has dtype {F.dtype}, expected integers"
    if len(F) == 0 or F.min() < 0 or F.max() >= len(V):
        return "F is empty or holds indices outside 0..len(V)-1"
    if not np.isfinite(V).all():
        return "V contains NaN or inf"
    if abs(len(F) - target) > 2:
        return f"returned {len(F)} faces for target_faces = {target} (allowed {target - 2}..{target + 2})"
    unused = np.setdiff1d(np.arange(len(V)), F.ravel())
    if len(unused):
        return f"vertex {int(unused[0])} is not used by any face ({len(unused)} unused): compact the mesh before returning it"
    S = np.sort(F, axis=1)
    if (S[:, 1:] == S[:, :-1]).any():
        return f"face {int(np.flatnonzero((S[:, 1:] == S[:, :-1]).any(axis=1))[0])} repeats a vertex (degenerate)"
    if len(np.unique(S, axis=0)) != len(F):
        return "two faces use the same three vertices (duplicate faces): a contraction broke the link condition"
    if not topology.is_edge_manifold(F):
        return "an edge is shared by more than two faces: a contraction broke the link condition"
    fans = topology.vertex_fan_counts(F, None, len(V))
    if (fans > 1).any():
        return f"vertex {int(np.flatnonzero(fans > 1)[0])} joins separate fans of faces (non-manifold vertex)"
    loops0, loops = len(topology.boundary_edges(F0)) and len(topology.boundary_loops(F0)), None
    try:
        loops = len(topology.boundary_loops(F)) if len(topology.boundary_edges(F)) else 0
    except ValueError:
        return "the boundary is pinched (a boundary vertex has two outgoing boundary edges)"
    if loops != loops0:
        return f"the input has {loops0} boundary loop(s), the output {loops}: boundary loops must be kept"
    if topology.euler_characteristic(F) != topology.euler_characteristic(F0):
        return (
            f"the Euler characteristic changed from {topology.euler_characteristic(F0)} to "
            f"{topology.euler_characteristic(F)}: the topology of the surface changed"
        )
    if not flips:
        return None
    bad = flipped_faces(V0, F0, V, F)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        return (
            f"{int(bad.sum())} output face(s) point against the input surface (e.g. face {k}): reject contractions "
            f"that flip a face, comparing with the face's normal before the move and in the input mesh"
        )
    return None


def flipped_faces(V0, F0, V, F) -> np.ndarray:
    """Output faces turned against the input surface, judged at the closest input point to their centroid.

    A face counts when its normal is more than 120° from the input normal there, or more than 90°
    for a well-shaped face (quality ``4√3 area / Σ edge² > 0.3``; 1 for an equilateral triangle):
    a sliver's normal is ill-defined, so a sliver standing on edge is not called flipped.
    """
    centroids = V[F].mean(axis=1)
    _, face, _ = closest_points(V0, F0, centroids)
    cos = np.einsum("ij,ij->i", face_normals(V, F), face_normals(V0, F0)[face])
    area2 = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    quality = 2 * np.sqrt(3) * area2 / ((V[F] - V[F[:, [1, 2, 0]]]) ** 2).sum(axis=(1, 2))
    return (cos < -0.5) | ((cos < 0) & (quality > 0.3))


def simplification_check(
    make, target: int, *, rms_slack: float = 1.5, hausdorff_slack: float = 2.0, floor: float = 1e-4, flips: bool = True
):
    """A check for ``qem_simplify`` outputs ``(V, F)`` judged by validity and error metrics.

    Passes when the output is a valid simplification (:func:`validity_problem`) and its RMS and
    Hausdorff distances to the input (relative to the bbox diagonal) are at most
    ``slack x`` the reference output's distances, plus ``floor``. Equal costs are broken in
    different orders by different correct implementations, so the vertices themselves are not
    compared; the slack covers those differences (measured on several correct variants).
    """

    def fn(expected: dict, got: dict, ctx):
        d0 = make()
        V0, F0 = d0["V"], d0["F"]
        problem = validity_problem(V0, F0, got.get("V"), got.get("F"), target, flips=flips)
        if problem:
            return problem
        ours = mesh_distance(V0, F0, got["V"], got["F"], n_samples=20000)
        ref = mesh_distance(V0, F0, expected["V"], expected["F"], n_samples=20000)
        for metric, slack in (("rms", rms_slack), ("hausdorff", hausdorff_slack)):
            allowed = slack * ref[metric] + floor
            if ours[metric] > allowed:
                return (
                    f"{metric} distance to the input is {ours[metric]:.3g} of the bbox diagonal; the reference reaches "
                    f"{ref[metric]:.3g}, allowed {allowed:.3g} ({slack:g}x + {floor:g}). Check the costs and the "
                    f"placement, and that the heap pops the cheapest pair"
                )
        return None

    return checks.Custom(fn)
