"""Meshes and checks shared by the graded remeshing tests (public: shipped with the lab).

Nothing here calls a lab implementation: a remeshed surface is judged by properties measured
here (validity, boundary loops, angles, edge lengths, valences, distance to the input), with
thresholds set from runs of the reference solution with a margin (numbers beside each threshold).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from geomlib import datasets, portable, topology
from geomlib.geometry import mesh_distance, triangle_quality
from geomlib.grading import checks, expect_raises
from geomlib.grading.cases import stored_input

#: Unit square of two triangles, diagonal 0-2, facing +z.
SQUARE_V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])

#: Regular tetrahedron, outward oriented: every edge fails the link condition.
TET_V = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
TET_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])

#: Octahedron of the unit axis points (+x, -x, +y, -y, +z, -z), outward oriented; face 0 is (+x, +y, +z).
OCTA_V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def halfedges(V, F):
    return topology.halfedge_mesh(np.asarray(F), len(V), manifold=True)


def expect_refused(operation, V, F, edge, match: str) -> None:
    """``operation(V, H, e)`` on edge ``edge`` (an index, or its two end vertices) must raise a MeshError."""
    H = halfedges(V, F)
    e = edge_index(H, *edge) if isinstance(edge, tuple) else edge
    expect_raises(lambda: operation(V, H, e), "MeshError", match=match)


def edge_index(H, a, b) -> int:
    a, b = min(a, b), max(a, b)
    return int(np.flatnonzero((H.E[:, 0] == a) & (H.E[:, 1] == b))[0])


def bumpy_sphere(level=3, seed=2):
    V, F = datasets.icosphere(level)
    return datasets.add_noise(V, 0.02, seed=seed, direction="normal", F=F), F


def wavy_patch(n=12, seed=0):
    V, F = datasets.grid_patch(n)
    V[:, 2] = 0.15 * portable.sin(3 * V[:, 0]) * portable.cos(2 * V[:, 1])
    return V, F


def quality(V0, F0, V, F) -> dict:
    """The issue's quality measures of a remeshed surface ``(V, F)`` of ``(V0, F0)``
    (:func:`geomlib.geometry.triangle_quality` and the Hausdorff distance to the input)."""
    return {**triangle_quality(V, F), "hausdorff": mesh_distance(V0, F0, V, F, n_samples=20000)["hausdorff"]}


def validity_problem(V0, F0, V, F) -> str | None:
    """What is wrong with ``(V, F)`` as a remeshing of ``(V0, F0)`` (None: nothing)."""
    V, F = np.asarray(V, float), np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        return f"expected V (n, 3) and F (m, 3), got shapes {V.shape} and {F.shape}"
    if not np.issubdtype(F.dtype, np.integer) or len(F) == 0 or F.min() < 0 or F.max() >= len(V):
        return "F must hold integer indices into V"
    if not np.isfinite(V).all():
        return "V contains NaN or inf"
    if len(np.setdiff1d(np.arange(len(V)), F.ravel())):
        return "some vertices are not used by any face: compact the mesh before returning it"
    try:
        topology.halfedge_mesh(F, len(V), manifold=True)
    except Exception as exc:  # noqa: BLE001 - the message is the feedback
        return f"the result is not a manifold, consistently oriented mesh: {exc}"
    nb0 = len(topology.boundary_loops(F0)) if len(topology.boundary_edges(F0)) else 0
    nb = len(topology.boundary_loops(F)) if len(topology.boundary_edges(F)) else 0
    if nb != nb0:
        return f"the input has {nb0} boundary loop(s), the result {nb}: boundary loops must be kept"
    if topology.euler_characteristic(F) != topology.euler_characteristic(F0):
        return "the Euler characteristic changed: a collapse or flip changed the topology"
    return None


def remesh_check(make, L, *, min_angle, below_30, edge_cv, valence6, hausdorff, length_tol=0.25):
    """A check for ``isotropic_remesh`` outputs: validity plus one threshold per quality measure."""

    def fn(expected, got, ctx):
        d = make()
        problem = validity_problem(d["V"], d["F"], got.get("V"), got.get("F"))
        if problem:
            return problem
        q = quality(d["V"], d["F"], np.asarray(got["V"], float), np.asarray(got["F"]))
        if abs(q["mean_edge"] / L - 1) > length_tol:
            return f"mean edge length {q['mean_edge']:.4g} is not within {length_tol:.0%} of the target {L:.4g}"
        for key, bound, lower in (
            ("min_angle", min_angle, True),
            ("valence6", valence6, True),
            ("below_30", below_30, False),
            ("edge_cv", edge_cv, False),
            ("hausdorff", hausdorff, False),
        ):
            if (q[key] < bound) if lower else (q[key] > bound):
                return (
                    f"{key} = {q[key]:.4g}, needs {'>=' if lower else '<='} {bound:g} (measures: "
                    + ", ".join(f"{k} {v:.3g}" for k, v in q.items())
                    + ")"
                )
        return None

    return checks.Custom(fn)


def same_vertex_set(expected, got, ctx):
    """Split results: the same vertex positions (input vertices plus midpoints), in any order."""
    Ve, Vg = np.asarray(expected["V"]), np.asarray(got.get("V"))
    if Vg.shape != Ve.shape:
        return f"V has shape {Vg.shape}, expected {Ve.shape} (one new vertex per edge longer than high)"
    a, b = Ve[np.lexsort(Ve.T)], Vg[np.lexsort(Vg.T)]
    if not np.allclose(a, b, atol=1e-9):
        return "the new vertices are not the midpoints of the long edges"
    return validity_problem(expected["V"], expected["F"], got["V"], got["F"])


def spheroid(level=3, axes=(1.5, 0.6, 0.6)):
    """An icosphere stretched along x: its tips bend much more than its waist."""
    V, F = datasets.icosphere(level)
    return V * np.asarray(axes), F


def adaptive_check(make, *, targets, min_angle, hausdorff, tip_ratio, length_tol=0.25):
    """A check for adaptive ``isotropic_remesh`` outputs on a shape stretched along x: validity, the
    minimum angle, Hausdorff distance, edges as long as their targets, and edges at the tips
    (|x| > 0.8 max |x|) shorter than at the waist (|x| < 0.2 max |x|) by at least ``tip_ratio`` (a
    uniform remesh gives about 1).

    ``targets`` names the ``STORED`` per-vertex target lengths of the input (``adaptive_target_length``,
    stored by ``geomlib refs build``): an edge's target is the smaller of its ends' targets, a result
    vertex taking the target of the nearest input vertex; the mean of length / target must be within
    ``length_tol`` of 1 (the input itself, unchanged: 1.5 and 2.1)."""

    def fn(expected, got, ctx):
        d = make()
        problem = validity_problem(d["V"], d["F"], got.get("V"), got.get("F"))
        if problem:
            return problem
        V, F = np.asarray(got["V"], float), np.asarray(got["F"])
        q = quality(d["V"], d["F"], V, F)
        ends = topology.unique_edges(F)
        e = np.linalg.norm(V[ends[:, 0]] - V[ends[:, 1]], axis=1)
        x = np.abs(V[ends, 0].mean(axis=1))
        tips, waist = e[x > 0.8 * x.max()].mean(), e[x < 0.2 * x.max()].mean()
        target = stored_input("remeshing", targets)["lengths"][cKDTree(d["V"]).query(V)[1]]
        ratio = float(np.mean(e / np.minimum(target[ends[:, 0]], target[ends[:, 1]])))
        if abs(ratio - 1) > length_tol:
            return (
                f"edges are on average {ratio:.3g} times their target length (the smaller of the "
                f"adaptive_target_length of their ends), needs within {length_tol:.0%} of 1"
            )
        if q["min_angle"] < min_angle:
            return f"min_angle = {q['min_angle']:.3g}, needs >= {min_angle:g}"
        if q["hausdorff"] > hausdorff:
            return f"hausdorff = {q['hausdorff']:.3g}, needs <= {hausdorff:g}"
        if tips / waist > tip_ratio:
            return (
                f"mean edge at the tips {tips:.4g}, at the waist {waist:.4g}: ratio {tips / waist:.3g}, needs <= "
                f"{tip_ratio:g} (shorter edges where the surface bends more)"
            )
        return None

    return checks.Custom(fn)
