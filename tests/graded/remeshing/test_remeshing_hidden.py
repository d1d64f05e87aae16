"""Hidden graded cases (not shipped to students): the same rules on other meshes."""

from geomlib.grading import reference_tests

from .cases_hidden import CASES as HIDDEN_CASES

test_hidden_references = reference_tests(HIDDEN_CASES)


# --------------------------------------------------------------------------------------------
# hidden: chains of local operations on realistic meshes, every invariant checked after each

import numpy as np  # noqa: E402

from geomlib import datasets, topology  # noqa: E402
from geomlib.grading import graded  # noqa: E402
from geomlib.grading.errors import Mismatch, StudentError  # noqa: E402

from .support import bumpy_sphere, halfedges, wavy_patch  # noqa: E402


def _chain(lab, op, V, F, picks, label):
    """Apply ``op`` to edge ``pick % n_edges`` repeatedly; every result must pass check_halfedges."""
    H = halfedges(V, F)
    chi = topology.euler_characteristic(F)
    done = 0
    for pick in picks:
        e = int(pick % len(H.E))
        try:
            V, H2 = getattr(lab, op)(V, H, e)
        except StudentError as exc:
            if exc.exc_type == "MeshError" and "cannot be" in exc.exc_message:
                continue  # a refused operation is fine
            raise
        try:
            topology.check_halfedges(H2)
        except Exception as exc:  # noqa: BLE001
            raise Mismatch(f"{op} on {label}, edge {e}: the structure is broken: {exc}") from None
        F2 = np.asarray(H2.idx).reshape(-1, 3)
        if topology.euler_characteristic(F2) != chi:
            raise Mismatch(f"{op} on {label}, edge {e}: the Euler characteristic changed")
        H = topology.halfedge_mesh(F2, len(V), manifold=True)
        done += 1
    if done == 0:
        raise Mismatch(f"{op} on {label}: every operation was refused")


@graded(points=3, part="local operations", visibility="hidden")
def test_hidden_split_chain(lab):
    """eight splits in a row on a bumpy sphere and a wavy patch keep every invariant"""
    rng = np.random.default_rng(11)
    _chain(lab, "split_edge", *bumpy_sphere(2, 3), rng.integers(0, 10**6, 8), "a bumpy sphere")
    _chain(lab, "split_edge", *wavy_patch(6), rng.integers(0, 10**6, 8), "a wavy patch")


@graded(points=3, part="local operations", visibility="hidden")
def test_hidden_flip_chain(lab):
    """eight flips in a row on a torus keep every invariant (refusals allowed)"""
    rng = np.random.default_rng(12)
    _chain(lab, "flip_edge", *datasets.torus(n_major=12, n_minor=8), rng.integers(0, 10**6, 8), "a torus")


@graded(points=4, part="local operations", visibility="hidden")
def test_hidden_collapse_chain(lab):
    """eight collapses in a row on a bumpy sphere and a wavy patch keep every invariant (refusals allowed)"""
    rng = np.random.default_rng(13)
    _chain(lab, "collapse_edge", *bumpy_sphere(2, 3), rng.integers(0, 10**6, 8), "a bumpy sphere")
    _chain(lab, "collapse_edge", *wavy_patch(6), rng.integers(0, 10**6, 8), "a wavy patch")
