"""Hidden graded cases of the remeshing lab (not shipped to students): the same rules on other meshes."""

from __future__ import annotations

import numpy as np

from geomlib import datasets, portable, topology
from geomlib.grading import Case, checks
from geomlib.grading import tolerances as tol

from .cases import LOOP_HINT, QUALITY, bumpy, mesh, projection_points
from .support import adaptive_check, remesh_check, same_vertex_set, spheroid


def torus():
    return datasets.torus(n_major=24, n_minor=12)


def hf():
    return datasets.height_field(16)


def flat_spheroid():
    return spheroid(3, (1.8, 0.7, 0.45))


def box8():
    return datasets.sharp_box((1.0, 0.6, 0.4), n=8)


def box8_with_lines():
    """The box's 12 sharp lines given as feature edges: both ends on two faces of the box.

    The grid is made uneven along each axis (``t + 0.2 a/pi sin(pi t / a)``, monotone, fixing the
    faces ``t = ±a``): on the even grid every vertex already sits at its centroid and relaxation
    would return the input unchanged. Faces stay planar and lines straight.
    """
    V, F = box8()
    a = np.abs(V).max(axis=0)
    on_line = np.isclose(np.abs(V), a).sum(axis=1) >= 2
    V = V + 0.2 * a / np.pi * portable.sin(np.pi * V / a)
    E = topology.unique_edges(F)
    return {"V": V, "F": F, "feature_edges": E[on_line[E].all(axis=1)]}


STORED = [
    Case(
        id="hidden-adaptive-targets-flat-spheroid",
        function="adaptive_target_length",
        inputs=mesh(flat_spheroid, target_length=0.08),
        outputs=("lengths",),
        check=checks.Allclose(atol=1e-9),
        part="stored input",
        points=0,
        visibility="hidden",
    )
]

CASES = [
    Case(
        id="hidden-split-torus",
        function="split_long_edges",
        inputs=mesh(torus, high=0.2),
        outputs=("V", "F"),
        check=checks.Custom(same_vertex_set),
        part="stages",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="hidden-relax-height-field",
        function="tangential_relaxation",
        inputs=mesh(hf, damping=0.8),
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="stages",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="hidden-relax-box-features",
        function="tangential_relaxation",
        inputs=box8_with_lines,
        outputs=("V",),
        check=checks.Allclose(atol=tol.EXACT),
        part="features",
        tasks=(7, 8),  # Task 8's relaxation, with features
        points=1,
        visibility="hidden",
    ),
    Case(
        id="hidden-project-torus",
        function="project_to_surface",
        inputs=projection_points(torus, 3),
        outputs=("P",),
        check=checks.Allclose(atol=1e-9),
        part="stages",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="hidden-sharp-edges-box8",
        function="sharp_edges",
        inputs=mesh(box8, feature_angle=30.0),
        outputs=("E",),
        check=checks.Equal("E"),
        part="features",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="hidden-remesh-torus",
        function="isotropic_remesh",
        inputs=mesh(torus, target_length=0.12),
        outputs=("V", "F"),
        check=remesh_check(mesh(torus), 0.12, hausdorff=0.01, **QUALITY),  # solution: 0.0049
        part="loop",
        points=2,
        visibility="hidden",
        hint=LOOP_HINT,
    ),
    Case(
        id="hidden-remesh-bumpy-fine",
        function="isotropic_remesh",
        inputs=mesh(bumpy(3, 5), target_length=0.09),
        outputs=("V", "F"),
        check=remesh_check(mesh(bumpy(3, 5)), 0.09, hausdorff=0.015, **QUALITY),  # solution: 0.0076
        part="loop",
        points=2,
        visibility="hidden",
        hint=LOOP_HINT,
    ),
    Case(
        id="hidden-remesh-height-field",
        function="isotropic_remesh",
        inputs=mesh(hf, target_length=0.05),
        outputs=("V", "F"),
        check=remesh_check(mesh(hf), 0.05, hausdorff=0.015, **QUALITY),  # solution: 0.007
        part="loop",
        points=2,
        visibility="hidden",
        hint=LOOP_HINT,
    ),
    Case(
        id="hidden-remesh-box8-features",
        function="isotropic_remesh",
        inputs=mesh(box8, target_length=0.07, feature_angle=45.0),
        outputs=("V", "F"),
        check=remesh_check(mesh(box8), 0.07, hausdorff=1e-3, **QUALITY),  # solution: 0
        tasks=(7, 10),  # isotropic_remesh is the loop, Task 10
        part="features",
        points=2,
        visibility="hidden",
    ),
    Case(
        id="hidden-curvature-torus",
        function="max_curvature",
        inputs=mesh(torus),
        outputs=("kappa",),
        check=checks.Allclose(atol=1e-9),
        part="adaptive",
        points=1,
        visibility="hidden",
    ),
    Case(
        id="hidden-adaptive-lengths-height-field",
        function="adaptive_target_length",
        inputs=mesh(hf, target_length=0.05),
        outputs=("lengths",),
        check=checks.Allclose(atol=1e-9),
        part="adaptive",
        points=2,
        visibility="hidden",
        hint="boundary vertices have no curvature (NaN): the smoothing fills them from inside",
    ),
    Case(
        id="hidden-adaptive-lengths-options",
        function="adaptive_target_length",
        inputs=mesh(flat_spheroid, target_length=0.08, error=0.002, min_length=0.05, max_length=0.12, smoothing=1),
        outputs=("lengths",),
        check=checks.Allclose(atol=1e-9),
        part="adaptive",
        points=1,
        visibility="hidden",
    ),
    Case(
        id="hidden-remesh-adaptive-flat-spheroid",
        function="isotropic_remesh",
        inputs=mesh(flat_spheroid, target_length=0.08, adaptive=True),
        outputs=("V", "F"),
        # solution: min angle 32.0°, Hausdorff 0.0021, tips / waist 0.74 (a uniform remesh: 1.0),
        # length / target 1.04 on average (the input unchanged: 2.1)
        check=adaptive_check(
            mesh(flat_spheroid),
            targets="hidden-adaptive-targets-flat-spheroid",
            min_angle=12.0,
            hausdorff=0.006,
            tip_ratio=0.9,
        ),
        part="adaptive",
        tasks=(10, 11),  # adaptive=True runs Task 11's target lengths
        points=2,
        visibility="hidden",
    ),
]
