"""Public graded cases of the simplification lab: realistic meshes compared with stored references.

Each case calls one lab function on a deterministic input; ``geomlib refs build --lab
simplification`` stored the reference solution's output. Quadrics, placements and single
contractions have exact answers (compared entry by entry). The full greedy loop is judged by
validity and error metrics (``support.simplification_check``), not by vertex positions: equal
costs can be popped in a different order by a correct implementation.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, topology
from geomlib.grading import Case, checks
from geomlib.grading import tolerances as tol
from geomlib.grading.cases import stored_input

from .support import noisy_icosphere, random_quadrics, simplification_check

# --------------------------------------------------------------------------------------------
# inputs (functions: built when the case runs, identical every time)


def ico_noisy(level=2, sigma=0.01, seed=4):
    return lambda: dict(zip(("V", "F"), noisy_icosphere(level, sigma, seed), strict=True))


def ant():
    V, F = datasets.pyvista_mesh("ant")  # valence-3 vertices: some edges fail the link condition
    return {"V": V, "F": F}


def torus():
    return dict(zip(("V", "F"), datasets.torus(n_major=24, n_minor=12), strict=True))


def height_field():
    return dict(zip(("V", "F"), datasets.height_field(16), strict=True))


def sharp_box():
    return dict(zip(("V", "F"), datasets.sharp_box(n=6), strict=True))


def edge_pairs(make, push: float = 0.0):
    """Every edge of a mesh with the midpoint as position; ``push`` moves it along a fixed direction."""

    def inputs():
        d = make()
        E = topology.unique_edges(d["F"])
        mid = 0.5 * (d["V"][E[:, 0]] + d["V"][E[:, 1]])
        return {**d, "pairs": E, "positions": mid + push * np.array([0.6, -0.3, 0.2])}

    return inputs


def quadrics_entry(id: str, make, visibility: str = "visible") -> Case:
    """Area-weighted vertex quadrics (Task 1's output), stored by `geomlib refs build` for the placement cases."""
    return Case(id=id, function="vertex_quadrics", inputs=lambda: {k: make()[k] for k in ("V", "F")},
                params={"weighting": "area"}, outputs=("Q",), check=checks.Allclose(atol=tol.EXACT),
                part="stored input", points=0, visibility=visibility)  # fmt: skip


def edge_quadrics(make, id: str):
    """Summed quadrics ``Q_i + Q_j`` of every edge, from the stored vertex quadrics ``id`` (see STORED)."""

    def inputs():
        d = make()
        V, F = d["V"], d["F"]
        Q = stored_input("simplification", id)["Q"]
        E = topology.unique_edges(F)
        return {"Q": Q[E[:, 0]] + Q[E[:, 1]], "v1": V[E[:, 0]], "v2": V[E[:, 1]]}

    return inputs


def torus_chain():
    """Five contractions in a row on the torus, each using the survivor of the one before."""
    d = torus()
    pairs = np.array([[0, 1], [0, 25], [0, 2], [40, 41], [40, 64]])
    positions = np.array([d["V"][i] for i, _ in pairs]) + 0.01
    return {**d, "Q": random_quadrics(len(d["V"]), seed=5), "pairs": pairs, "positions": positions}


def height_field_boundary_pairs():
    """Contractions along the boundary and into the interior of an open mesh.

    The new positions are off the survivors' own (at them, the returned V would equal the input V).
    """
    d = height_field()
    pairs = np.array([[0, 1], [2, 19], [272, 273]])  # boundary edge, boundary-interior edge, boundary edge
    positions = d["V"][pairs[:, 0]] + np.array([0.01, -0.02, 0.005])
    return {**d, "Q": random_quadrics(len(d["V"]), seed=6), "pairs": pairs, "positions": positions}


def simplify(make, target):
    return lambda: {**make(), "target_faces": target}


QUAD_HINT = "K_f = area * p pᵀ with p = (n, -n·v0) and n the unit normal; Q_v sums K_f over the faces around v"
PLACE_HINT = "solve A x = -b with A = Q[:3, :3], b = Q[:3, 3]; the cost is xᵀ A x + 2 bᵀ x + c"
LINK_HINT = "common neighbours must be exactly the vertices opposite the edge (count the virtual boundary vertex)"
CONTRACT_HINT = "kill the faces that use both vertices, rename j to i in the others, V[i] = position, Q[i] += Q[j]"

# What a case needs from an earlier task is stored by `geomlib refs build` from the solution and
# read back with `stored_input`, never computed here.
STORED = [quadrics_entry("quadrics-noisy-ico2", ico_noisy(2)), quadrics_entry("quadrics-sharp-box", sharp_box)]

CASES = [
    # ---------------------------------------------------------------- Task 1: quadrics
    Case(
        id="face-quadrics-noisy-ico2",
        function="face_quadrics",
        inputs=ico_noisy(2),
        outputs=("K",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=1,
        hint=QUAD_HINT,
    ),
    Case(
        id="face-quadrics-torus-uniform",
        function="face_quadrics",
        inputs=torus,
        params={"weighting": "uniform"},
        outputs=("K",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=1,
        hint="uniform weighting: K_f = p pᵀ (no area factor)",
    ),
    Case(
        id="boundary-quadrics-height-field",
        function="boundary_quadrics",
        inputs=height_field,
        params={"weight": 10.0},
        outputs=("Q",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=1,
        hint="plane through the boundary edge a→b containing the face normal: m = (b - a) × n_f, weight |b - a|²",
    ),
    Case(
        id="vertex-quadrics-height-field",
        function="vertex_quadrics",
        inputs=height_field,
        params={"boundary_weight": 10.0},
        outputs=("Q",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=1,
        hint=QUAD_HINT + "; add boundary_quadrics when boundary_weight > 0",
    ),
    # ---------------------------------------------------------------- Task 2: placement
    Case(
        id="placement-noisy-ico2-edges",
        function="optimal_contraction",
        inputs=edge_quadrics(ico_noisy(2), "quadrics-noisy-ico2"),
        outputs=("position", "cost"),
        check=checks.All(checks.Allclose("position", atol=tol.GEOMETRY), checks.Allclose("cost", atol=tol.EXACT)),
        part="placement",
        points=2,
        hint=PLACE_HINT,
    ),
    Case(
        id="placement-sharp-box-edges",
        function="optimal_contraction",
        inputs=edge_quadrics(sharp_box, "quadrics-sharp-box"),
        outputs=("position", "cost"),
        check=checks.All(checks.Allclose("position", atol=tol.GEOMETRY), checks.Allclose("cost", atol=tol.EXACT)),
        part="placement",
        points=2,
        hint="flat faces and creases make A singular: minimise along the segment, and when the cost is the same "
        "everywhere on it take the midpoint",
        trivial_outputs={
            "cost": "every edge of a box contracts onto its faces and creases exactly (cost 0); the point "
            "here is the placement on singular quadrics, costs are graded on the noisy icosphere"
        },
    ),
    # ---------------------------------------------------------------- Task 3: contraction
    Case(
        id="check-contractions-ant-pushed",
        function="check_contractions",
        inputs=edge_pairs(ant, push=0.3),
        outputs=("link_ok", "flips"),
        check=checks.Equal(),
        part="contraction",
        points=1,
        hint=LINK_HINT + "; flips: n' · n <= 0 against the normal before the move or in the input, or degenerate",
    ),
    Case(
        id="check-contractions-height-field-pushed",
        function="check_contractions",
        inputs=edge_pairs(height_field, push=0.08),
        outputs=("link_ok", "flips"),
        check=checks.Equal(),
        part="contraction",
        points=1,
        hint=LINK_HINT + "; flips: n' · n <= 0 against the normal before the move or in the input, or degenerate",
    ),
    Case(
        id="contract-chain-torus",
        function="contract_pairs",
        inputs=torus_chain,
        outputs=("V", "F", "Q", "removed"),
        check=checks.All(
            checks.Equal(("F", "removed")), checks.Allclose("V", atol=tol.EXACT), checks.Allclose("Q", atol=tol.EXACT)
        ),
        part="contraction",
        points=2,
        hint=CONTRACT_HINT + "; update vertex_faces so the next contraction sees the new faces of i",
        trivial_outputs={
            "removed": "a closed mesh: every contraction removes its edge's two faces (the boundary case has 1)"
        },
    ),
    Case(
        id="contract-boundary-height-field",
        function="contract_pairs",
        inputs=height_field_boundary_pairs,
        outputs=("V", "F", "Q", "removed"),
        check=checks.All(
            checks.Equal(("F", "removed")), checks.Allclose("V", atol=tol.EXACT), checks.Allclose("Q", atol=tol.EXACT)
        ),
        part="contraction",
        points=1,
        hint=CONTRACT_HINT + "; a boundary edge has only one face",
    ),
    # ---------------------------------------------------------------- Task 4: the greedy loop
    Case(
        id="simplify-noisy-ico3-10pct",
        function="qem_simplify",
        inputs=simplify(ico_noisy(3), 128),
        outputs=("V", "F"),
        check=simplification_check(simplify(ico_noisy(3), 128), 128),
        part="greedy loop",
        points=2,
    ),
    Case(
        id="simplify-torus-20pct",
        function="qem_simplify",
        inputs=simplify(torus, 115),
        outputs=("V", "F"),
        check=simplification_check(simplify(torus, 115), 115),
        part="greedy loop",
        points=1,
    ),
    Case(
        id="simplify-height-field-10pct",
        function="qem_simplify",
        inputs=simplify(height_field, 51),
        outputs=("V", "F"),
        check=simplification_check(simplify(height_field, 51), 51),
        part="greedy loop",
        points=2,
        hint="boundary vertices carry penalty quadrics; the boundary loop must survive",
    ),
    Case(
        id="simplify-sharp-box-10pct",
        function="qem_simplify",
        inputs=simplify(sharp_box, 43),
        outputs=("V", "F"),
        check=simplification_check(simplify(sharp_box, 43), 43),
        part="greedy loop",
        points=1,
        hint="a box needs only 12 triangles: flat regions must be simplified without error",
    ),
]
