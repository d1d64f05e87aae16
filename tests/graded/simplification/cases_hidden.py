"""Hidden graded cases of the simplification lab (not shipped to students): the same rules on other meshes."""

from __future__ import annotations

from geomlib import datasets
from geomlib.grading import Case, checks
from geomlib.grading import tolerances as tol

from .cases import edge_pairs, edge_quadrics, ico_noisy, quadrics_entry, simplify
from .support import random_quadrics, simplification_check


def ant():
    V, F = datasets.pyvista_mesh("ant")
    return {"V": V, "F": F}


def airplane():
    V, F = datasets.pyvista_mesh("airplane", manifold=True)  # 10 boundary loops, thin wings
    return {"V": V, "F": F}


def rock():
    return dict(zip(("V", "F"), datasets.rock_on_plinth(16), strict=True))


def torus_fine():
    return dict(zip(("V", "F"), datasets.torus(n_major=32, n_minor=16), strict=True))


def ant_chain():
    d = ant()
    pairs = [[0, 1], [10, 11], [100, 101]]
    return {**d, "Q": random_quadrics(len(d["V"]), seed=9), "pairs": pairs, "positions": d["V"][[0, 10, 100]] * 1.01}


STORED = [quadrics_entry("quadrics-torus-fine", torus_fine, visibility="hidden")]

CASES = [
    Case(
        id="hidden-face-quadrics-ant",
        function="face_quadrics",
        inputs=ant,
        outputs=("K",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=6,
        visibility="hidden",
    ),
    Case(
        id="hidden-vertex-quadrics-rock",
        function="vertex_quadrics",
        inputs=rock,
        params={"boundary_weight": 5.0},
        outputs=("Q",),
        check=checks.Allclose(atol=tol.EXACT),
        part="quadrics",
        points=6,
        visibility="hidden",
    ),
    Case(
        id="hidden-placement-torus-edges",
        function="optimal_contraction",
        inputs=edge_quadrics(torus_fine, "quadrics-torus-fine"),
        outputs=("position", "cost"),
        check=checks.All(checks.Allclose("position", atol=tol.GEOMETRY), checks.Allclose("cost", atol=tol.EXACT)),
        part="placement",
        points=12,
        visibility="hidden",
    ),
    Case(
        id="hidden-check-contractions-airplane",
        function="check_contractions",
        inputs=edge_pairs(airplane, push=5.0),
        outputs=("link_ok", "flips"),
        check=checks.Equal(),
        part="contraction",
        points=8,
        visibility="hidden",
    ),
    Case(
        id="hidden-contract-chain-ant",
        function="contract_pairs",
        inputs=ant_chain,
        outputs=("V", "F", "Q", "removed"),
        check=checks.All(
            checks.Equal(("F", "removed")), checks.Allclose("V", atol=tol.EXACT), checks.Allclose("Q", atol=tol.EXACT)
        ),
        part="contraction",
        points=7,
        visibility="hidden",
        trivial_outputs={
            "removed": "a closed mesh: every contraction removes its edge's two faces (the boundary case has 1)"
        },
    ),
    Case(
        id="hidden-simplify-ant-20pct",
        function="qem_simplify",
        inputs=simplify(ant, 180),
        outputs=("V", "F"),
        check=simplification_check(simplify(ant, 180), 180, flips=False),  # thin legs: see validity_problem
        part="greedy loop",
        points=6,
        visibility="hidden",
    ),
    Case(
        id="hidden-simplify-rock-20pct",
        function="qem_simplify",
        inputs=simplify(rock, 100),
        outputs=("V", "F"),
        check=simplification_check(simplify(rock, 100), 100),
        part="greedy loop",
        points=6,
        visibility="hidden",
    ),
    Case(
        id="hidden-simplify-noisy-ico3-5pct",
        function="qem_simplify",
        inputs=simplify(ico_noisy(3, 0.02, 11), 64),
        outputs=("V", "F"),
        check=simplification_check(simplify(ico_noisy(3, 0.02, 11), 64), 64),
        part="greedy loop",
        points=5,
        visibility="hidden",
    ),
]
