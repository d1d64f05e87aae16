"""Meshes and comparisons shared by the graded subdivision tests (public: shipped with the lab).

Everything here is independent of any implementation of the lab: inputs come from
``geomlib.datasets`` (deterministic), and expected values come from hand calculations, simple
formulas written out below, or the stored references.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets
from geomlib.grading import tolerances as tol
from geomlib.grading.checks import format_vec, nonfinite_problem

# --------------------------------------------------------------------------------------------
# the handout's rules (labs/subdivision/README.md), in one place

#: Odd vertex of an interior edge (a, b) with opposite vertices c, d: ``3/8 (a + b) + 1/8 (c + d)``.
ODD_ENDS, ODD_OPPOSITE = 3 / 8, 1 / 8
#: Odd vertex of a boundary edge: the midpoint.
ODD_BOUNDARY = 1 / 2
#: Even boundary vertex v with boundary neighbours p, q: ``3/4 v + 1/8 (p + q)``.
EVEN_BOUNDARY_SELF, EVEN_BOUNDARY_NEIGHBOUR = 3 / 4, 1 / 8


def warren_weight(n):
    """Warren's even weight ``u(n) = 3/16 if n == 3 else 3/(8n)``."""
    n = np.asarray(n, dtype=float)
    return np.where(n == 3, 3 / 16, 3 / (8 * n))


def loop_beta(n):
    """Loop's even weight ``β(n) = (1/n) (5/8 - (3/8 + 1/4 cos(2π/n))²)``."""
    n = np.asarray(n, dtype=float)
    return (5 / 8 - (3 / 8 + np.cos(2 * np.pi / n) / 4) ** 2) / n


#: Each rule by the handout's formula: the hand-written tests build their expected weights from the
#: constants above, and ``tests/solutions/test_subdivision.py::test_the_solution_follows_the_rule``
#: checks the reference solution against each, so a deliberate change of a rule fails there, in one
#: test named after it (change the constant here and the handout with it).
RULES = {
    "odd interior edge: 3/8 (a + b) + 1/8 (c + d)": (ODD_ENDS, ODD_OPPOSITE),
    "odd boundary edge: 1/2 (a + b)": (ODD_BOUNDARY,),
    "even boundary vertex: 3/4 v + 1/8 (p + q)": (EVEN_BOUNDARY_SELF, EVEN_BOUNDARY_NEIGHBOUR),
    "even weight, warren: 3/16 if n = 3 else 3/(8n)": ("warren", warren_weight),
    "even weight, loop: (5/8 - (3/8 + cos(2 pi/n)/4)^2)/n": ("loop", loop_beta),
}


# --------------------------------------------------------------------------------------------
# tiny meshes (by hand)

#: One triangle: every vertex and edge is on the boundary.
TRIANGLE_V = np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]])
TRIANGLE_F = np.array([[0, 1, 2]])

#: A unit square split along the diagonal 0-2: one interior edge, four boundary edges.
SQUARE_V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])

#: Corner tetrahedron, outward oriented: every vertex has valence 3, every edge is interior.
TET_V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])

#: Regular tetrahedron centred at the origin (vertex sum 0): nice closed forms for Catmull-Clark.
REG_TET_V = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
REG_TET_F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])

#: Octahedron: vertex 2k and 2k+1 are +-e_k (antipodes); every vertex has valence 4.
OCTA_V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])

#: One quad (all boundary).
QUAD_V = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]])
QUAD_F = np.array([[0, 1, 2, 3]])


# --------------------------------------------------------------------------------------------
# realistic inputs


def airplane() -> tuple[np.ndarray, np.ndarray]:
    """The pyvista airplane made manifold (stray triangle dropped, 6 pinch vertices split)."""
    return datasets.pyvista_mesh("airplane", manifold=True)


def quad_grid(nx: int = 6, ny: int = 5, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """An open (nx x ny)-cell quad patch with random heights, facing +z."""
    x, y = np.meshgrid(np.arange(nx + 1, dtype=float), np.arange(ny + 1, dtype=float), indexing="ij")
    z = 0.3 * np.random.default_rng(seed).normal(size=x.shape)
    V = np.stack([x, y, z], -1).reshape(-1, 3) / max(nx, ny)
    vid = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    Q = np.stack([vid[:-1, :-1], vid[1:, :-1], vid[1:, 1:], vid[:-1, 1:]], -1).reshape(-1, 4)
    return V, Q


def centroids(V, faces) -> np.ndarray:
    """Face centroids, written plainly (so edge/vertex-point tests do not depend on Task 6)."""
    V = np.asarray(V, float)
    return np.array([V[list(f)].mean(axis=0) for f in faces])


def as_dense(S, name: str = "S") -> np.ndarray:
    """A returned matrix (scipy.sparse or dense array) as a dense float array."""
    if hasattr(S, "toarray"):
        S = S.toarray()
    A = np.asarray(S)
    if A.dtype.kind not in "biuf" or A.ndim != 2:
        from geomlib.grading.errors import BadReturn

        raise BadReturn(f"{name} should be a 2-D matrix (scipy.sparse or ndarray), got {type(S).__name__}")
    return A.astype(np.float64)


# --------------------------------------------------------------------------------------------
# comparisons with student-readable messages


def _row_text(row: np.ndarray) -> str:
    nz = np.flatnonzero(np.abs(row) > 1e-15)
    if len(nz) == 0:
        return "{} (an empty row)"
    return "{" + ", ".join(f"{int(c)}: {row[c]:.6g}" for c in nz) + "}"


def matrix_mismatch(name: str, expected, got, *, atol: float = tol.EXACT, what_row: str = "row") -> str | None:
    """None if the matrices agree, else a message naming the first wrong row and its weights."""
    E = as_dense(expected, name)
    G = as_dense(got, name)
    if G.shape != E.shape:
        return f"{name} has shape {G.shape}, expected {E.shape}"
    problem = nonfinite_problem(name, E, G)
    if problem:
        return problem
    bad = (np.abs(G - E) > atol).any(axis=1)
    if not bad.any():
        return None
    r = int(np.flatnonzero(bad)[0])
    msg = (
        f"{name} {what_row} {r}: expected weights {_row_text(E[r])} (column = old vertex), got {_row_text(G[r])}; "
        f"{int(bad.sum())} of {len(E)} rows differ"
    )
    sums = G.sum(axis=1)
    if np.abs(sums - 1).max() > 1e-9:
        # The row shown above when its sum is off too (the largest deviation picked another row
        # for a last-bit difference: "row 0: ... (row 1 sums to 0.85)").
        k = r if abs(sums[r] - 1) > 1e-9 else int(np.argmax(np.abs(sums - 1)))
        msg += f" (row {k} sums to {sums[k]:.6g}; subdivision weights of a row always sum to 1)"
    return msg


def wrong_rows(expected, got, name: str = "S", atol: float = tol.EXACT) -> np.ndarray | None:
    """Indices of the rows of a returned matrix that differ from the expected one (None: shapes differ)."""
    E = as_dense(expected, name)
    G = as_dense(got, name)
    if G.shape != E.shape:
        return None
    return np.flatnonzero(~(np.abs(G - E) <= atol).all(axis=1))  # NaN counts as wrong


def matrix_picture(ctx, V, F, expected, got, name: str) -> str | None:
    """The new vertices of the wrong rows of a subdivision matrix, expected | yours | difference:
    row ``i`` of ``S`` places a new vertex at ``S[i] @ V`` (an edge's odd vertex for ``S_odd``, one
    row per edge; a vertex's new position for ``S_even`` and the other matrices), so the panels show
    where the expected rows put it, where the submitted rows put it, and how far apart they are."""
    from geomlib.grading import feedback

    if ctx is None or ctx.feedback_dir is None or not feedback.picture_wanted():
        return None
    rows = wrong_rows(expected, got, name)
    if rows is None or not len(rows):
        return None
    V = np.asarray(V, float)
    E, G = as_dense(expected, name)[rows], as_dense(got, name)[rows]
    if E.shape[1] != len(V):
        return None
    what = (
        feedback.count(len(rows), "edge", "edges")
        if name == "S_odd"
        else feedback.count(len(rows), "vertex", "vertices")
    )
    err = np.abs(np.nan_to_num(G - E, nan=1.0)).sum(axis=1)  # how much weight is misplaced in the row
    return feedback.rows_picture(
        ctx,
        V,
        F,
        E @ V,
        np.nan_to_num(G) @ V,
        f"expected: the new vertex of each of the {what} whose {name} row is wrong",
        err=err,
        yours=f"yours: where your {name} rows put them",
    )


def matrix_check(name: str, *, atol: float = tol.EXACT, what_row: str = "row"):
    """A ``checks.Custom`` comparison for a matrix output stored dense in the reference."""
    from geomlib.grading import checks

    return checks.Custom(lambda e, g, ctx: matrix_mismatch(name, e[name], g.get(name), atol=atol, what_row=what_row))


def _rotated(F) -> list[tuple]:
    """Each face as an oriented cycle rotated to start at its smallest index."""
    F = np.asarray(F, dtype=np.int64)
    s = np.argmin(F, axis=1)
    k = F.shape[1]
    return list(map(tuple, np.take_along_axis(F, (s[:, None] + np.arange(k)) % k, axis=1).tolist()))


def canonical_faces(F) -> set:
    """Faces as a set of oriented cycles, each rotated to start at its smallest index."""
    return set(_rotated(F))


def faces_mismatch(name: str, expected, got) -> str | None:
    """None if the two face arrays hold the same oriented faces (any order, any rotation)."""
    E = np.asarray(expected)
    try:
        G = np.asarray(got)
    except Exception:
        G = np.zeros((0,))
    if G.dtype == object or G.ndim != 2 or G.shape[1] != E.shape[1]:
        return f"{name} should be an integer array of shape (m, {E.shape[1]}), got shape {getattr(G, 'shape', None)}"
    if len(G) != len(E):
        return f"{name} has {len(G)} faces, expected {len(E)}"
    if G.dtype.kind not in "iu":
        if not np.all(G == np.round(G)):
            return f"{name} holds non-integer values"
        G = G.astype(np.int64)
    ce, cg = canonical_faces(E), canonical_faces(G)
    if ce == cg:
        return None
    missing = sorted(ce - cg)
    # All missing faces reversed in one array operation (a face at a time took seconds on a large mesh).
    flipped = sum(1 for f in _rotated(np.array(missing, dtype=np.int64)[:, ::-1]) if f in cg)
    extra = sorted(cg - ce)
    msg = f"{len(missing)} of {len(E)} expected faces are missing, e.g. {format_vec(np.array(missing[0]))}"
    if extra:
        msg += f"; unexpected faces include {format_vec(np.array(extra[0]))}"
    if flipped:
        msg += f"; {flipped} appear with reversed orientation (keep each child in the corner order of its parent)"
    if len(cg) < len(G):
        msg += f"; {len(G) - len(cg)} faces are repeated"
    return msg


def faces_check(name: str):
    from geomlib.grading import checks

    return checks.Custom(lambda e, g, ctx: faces_mismatch(name, e[name], g.get(name)))
