"""Task 10: the isotropic remeshing loop (Botsch & Kobbelt 2004): split, collapse, flip, relax, project.

The stages are in :mod:`.stages`, the local operations in :mod:`.kernels`, the adaptive target
length in :mod:`.adaptive`.

References
----------
M. Botsch, L. Kobbelt, "A remeshing approach to multiresolution modeling", SGP 2004.
"""

from __future__ import annotations

import numpy as np

from geomlib.errors import MeshError
from geomlib.validate import check_float, check_int

from . import kernels as K
from .adaptive import adaptive_target_length
from .stages import (
    SurfaceProjector,
    _closest_on_segments,
    _collapse_all,
    _relax,
    _split_all,
    clean_slivers,
    manifold_input,
    sharp_edges,
)
from .state import make_state, state_mesh

__all__ = ["isotropic_remesh"]


def _target_field(target_length, n, adaptive, V0, F0, where):
    """``(L, field)``: the scalar target (mean of a field) and the per-vertex field or None."""
    if np.ndim(target_length) == 0:
        L = check_float(target_length, "target_length", positive=True, where=where)
        return L, (adaptive_target_length(V0, F0, L) if adaptive else None)
    if adaptive:
        raise MeshError(f"{where}: adaptive=True computes the lengths itself: give one target_length, not an array")
    field = np.asarray(target_length, dtype=np.float64)
    if field.shape != (n,):
        raise MeshError(
            f"{where}: target_length must be a number or one length per vertex, shape ({n},); got {field.shape}"
        )
    bad = ~(np.isfinite(field) & (field > 0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{where}: target_length must be finite and > 0 at every vertex; vertex {i} has {field[i]}")
    return float(field.mean()), field


def isotropic_remesh(
    V,
    F,
    target_length,
    *,
    iterations=10,
    feature_angle=None,
    preserve_boundary=True,
    damping=0.5,
    relax_steps=3,
    adaptive=False,
):
    """Remesh a triangle mesh toward equilateral triangles with edges of about ``target_length``.

    Each iteration: split edges longer than ``1.4 L``; collapse edges shorter than ``0.7 L`` (none
    touching the preserved boundary); flip edges to bring valences toward 6 (4 on the boundary);
    ``relax_steps`` steps of tangential relaxation; projection of the vertices back onto the input
    (feature-line and boundary vertices onto the input's lines, the others onto its surface). After
    the last iteration, :func:`~.stages.clean_slivers` flips or collapses away the faces with an
    angle below 35° where that raises the smallest angle around them, then moves the vertices of
    faces below 50° toward the centroid of their neighbours (on the surface), and those of faces
    below 40° by short steps in the tangent plane, each where that raises it; last, it pulls the
    nearest free vertex toward each input vertex left farther than a quarter of ``L`` from the
    result (a tip), where the smallest angle around stays at least the result's smallest.

    With a target per vertex (an array, or ``adaptive=True``), an edge's ``L`` is the smaller of its
    two ends'; the loop's vertices take the target of their closest point on the input (linear
    over its triangle) after every projection.

    Parameters
    ----------
    V : (n, 3) float
    F : (m, 3) int
        A manifold, consistently oriented triangle mesh.
    target_length : float or (n,) float
        ``L`` (same units as ``V``), one value or one per input vertex.
    iterations : int
    feature_angle : float, optional
        Edges whose dihedral angle exceeds it (degrees) are kept as feature lines.
    preserve_boundary : bool
        Keep the boundary on the input boundary (boundary vertices slide along it).
    damping : float
        ``λ`` of the relaxation, in [0, 1].
    relax_steps : int
        Relaxation steps per iteration. One damped step does not undo the distortion that the
        iteration's splits, collapses and flips leave (the last iteration's would stay in the
        result); three do, at the cost of two more relaxations (the projection runs once).
    adaptive : bool
        Use :func:`adaptive_target_length` of the input with ``L = target_length``.

    Returns
    -------
    V, F : the remeshed surface (compact: every vertex used).
    """
    where = "isotropic_remesh"
    V0, F0, H0 = manifold_input(V, F, where)  # H0: the half-edge structure of the input, given
    its = check_int(iterations, "iterations", where=where, minimum=0)
    lam = check_float(damping, "damping", where=where, minimum=0.0, maximum=1.0)
    steps = check_int(relax_steps, "relax_steps", where=where, minimum=0)
    L, field = _target_field(target_length, len(V0), bool(adaptive), V0, F0, where)
    fe = None if feature_angle is None else sharp_edges(V0, F0, feature_angle)
    # BEGIN SOLUTION: Task 10 (the loop): split > 1.4 L, collapse < 0.7 L (the given _collapse_all(S)), flip, relax, project; repeat; then the given clean_slivers(S, project=project)
    S = make_state(V0, F0, fe, preserve_boundary=preserve_boundary, where=where, H=H0)
    E0 = S.feature_edges()
    A0, B0 = V0[E0[:, 0]], V0[E0[:, 1]]
    project = SurfaceProjector(V0, F0)
    n0 = len(V0)
    # high = 2 low: the halves of a split edge are not short (with 4/3 and 4/5 they are, 2/3 L)
    S.high[:n0] = 1.4 * (L if field is None else field)
    S.low[:n0] = 0.7 * (L if field is None else field)
    for _ in range(its):
        _split_all(S)
        _collapse_all(S)
        S.compact()  # the collapses left dead rows: the next passes skip them
        for _ in range(3):
            if not K.flip_pass(*S.args()):
                break
        n = S.cnt[0]
        Fl = S.faces()
        cls = S.cls[:n]
        Ef = S.feature_edges() if len(E0) else E0  # no feature edge at the start: none later (splits only copy them)
        Vn = S.V[:n]
        for _ in range(steps):
            Vn = _relax(Vn, Fl, cls, Ef, lam)
        free = cls == 0  # after compact() every vertex is used
        face, Vn[free] = project.closest(Vn[free])
        if field is not None:  # the target where the vertex now is
            h = project.interpolate(field, face, Vn[free])
            S.high[:n][free], S.low[:n][free] = 1.4 * h, 0.7 * h
        line = cls == 1
        if line.any() and len(E0):
            Vn[line] = _closest_on_segments(Vn[line], A0, B0)
        S.V[:n] = Vn
    clean_slivers(S, project=project)
    return state_mesh(S)
    # END SOLUTION
