"""``qem_simplify``: the entry point that validates, builds quadrics and runs a contraction loop."""

from __future__ import annotations

import warnings

import numpy as np

from geomlib.validate import MeshError, check_choice, check_float, check_mesh, checked

from .contraction import SimplifyState, make_state, state_mesh
from .greedy import candidate_pairs, greedy_collapse
from .quadrics import WEIGHTINGS, crease_quadrics, vertex_quadrics
from .refit import refine_positions

__all__ = ["qem_simplify", "qem_simplify_series", "SimplificationWarning"]

METHODS = ("greedy", "fast")


class SimplificationWarning(UserWarning):
    """The target face count could not be reached (``on_unreachable="warn"``)."""


def _check_target(target_faces, m: int) -> int:
    where = "qem_simplify"
    if isinstance(target_faces, bool) or not isinstance(target_faces, int | np.integer):
        raise MeshError(
            f"{where}: target_faces must be an integer number of faces, got {target_faces!r} ({type(target_faces).__name__})"
        )
    target_faces = int(target_faces)
    if target_faces < 4:
        raise MeshError(
            f"{where}: target_faces must be >= 4 (a closed surface needs at least 4 triangles), got {target_faces}"
        )
    if target_faces > m:
        raise MeshError(
            f"{where}: target_faces = {target_faces} is more than the mesh has (m = {m} faces); simplification only removes faces"
        )
    return target_faces


def qem_simplify(
    V,
    F,
    target_faces: int,
    *,
    pair_threshold: float = 0.0,
    preserve_boundary: bool = True,
    method: str = "greedy",
    weighting: str = "area",
    boundary_weight: float = 2.0,
    crease_angle: float | None = 75.0,
    crease_weight: float = 1.0,
    min_cos: float = 0.0,
    on_unreachable: str = "raise",
    refit: bool | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Simplify a triangle mesh to ``target_faces`` faces with quadric error metrics.

    Garland & Heckbert's algorithm: every vertex gets the quadric of its faces' planes; pairs are
    contracted cheapest first, each to the point that minimises the sum of both quadrics, and the
    survivor keeps that sum. Contractions that would make the mesh non-manifold (link condition)
    or turn a face over are skipped.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        An edge- and vertex-manifold, consistently oriented triangle mesh (boundaries allowed).
    target_faces : int
        Faces wanted, ``4 <= target_faces <= m``. The result has ``target_faces`` or
        ``target_faces - 1`` faces when the target is reachable.
    pair_threshold : float, >= 0
        Also contract non-edge pairs closer than this (joins nearby parts); 0 = edges only.
        Such joins can leave vertices where two surface pieces touch (non-manifold vertices);
        edges always keep at most two faces.
    preserve_boundary : bool
        Add penalty quadrics on boundary edges (see
        :func:`~solutions.simplification.quadrics.boundary_quadrics`) so boundary loops keep their shape.
    method : {"greedy", "fast"}
        ``"greedy"``: the lab's loop, one contraction at a time (a min-heap with lazy
        invalidation), in Python. ``"fast"``: the same loop compiled with numba
        (:mod:`~solutions.simplification.compiled`; edges only, so ``pair_threshold`` must be 0):
        the same result on meshes without cost ties, hundreds of times faster. The first call on
        a machine compiles it (seconds; cached on disk after that).
    weighting : {"area", "uniform"}
        Face quadric weights (see :func:`~solutions.simplification.quadrics.face_quadrics`).
    boundary_weight : float
        Weight ``w`` of the boundary penalty quadrics (``w |b - a|² q qᵀ`` per boundary edge, the
        units of an area like the face quadrics). The default, 2, makes leaving the boundary cost
        about what leaving the surface costs: a boundary vertex's two edges weigh ``2 w |e|²``
        against about ``6 · (√3/4) |e|² ≈ 2.6 |e|²`` of faces around an interior vertex. A much
        heavier penalty (the 10 used before) keeps every outline so stiffly that at 1% of the faces
        a part loses its far end (the airplane's wing tips: 3.9× igl.qslim's Hausdorff distance);
        ``bench/simplification.py`` over the boundary meshes against igl.qslim: w = 1, 1.5, 2
        and 3 stay within the 1.25× bound on every case, 0.5 and 5 do not.
    crease_angle : float in [0, 180] or None
        Edges whose faces meet at a dihedral angle above this (degrees) are sharp features: they
        get constraint-plane quadrics (:func:`~solutions.simplification.quadrics.crease_quadrics`)
        so creases and corners of CAD-like parts keep their place. None: no crease quadrics.
        The default, 75°, was picked over the whole shared test set against igl.qslim
        (``bench/simplification_crease.py``; 45°, 60° and 90° each miss the 1.25× bound on some mesh).
    crease_weight : float
        Weight of the crease quadrics.
    min_cos : float in [-1, 1)
        Flip test threshold: a contraction is refused when a face normal turns so that
        ``cos(angle) <= min_cos`` (0: refuse turns of 90° and more).
    on_unreachable : {"raise", "warn"}
        What to do when no allowed contraction is left before the target: raise a
        :class:`~geomlib.validate.MeshError`, or warn (:class:`SimplificationWarning`) and return
        the mesh reached.
    refit : bool, optional
        Finish with a least-squares fit of the vertex positions to the input surface
        (:func:`~solutions.simplification.refit.refine_positions`, connectivity unchanged; 10-30%
        lower RMS error, at about the cost of a whole igl.qslim run on large meshes). Default
        (None): off for both methods. Skipped when ``pair_threshold > 0`` (joined pieces can meet
        in single vertices, which the fit does not handle).

    Returns
    -------
    V : (n', 3) float64
    F : (m', 3) int64
        Compact: every vertex is used by a face.

    Raises
    ------
    MeshError
        For an invalid mesh or parameter, and when the target cannot be reached without breaking
        manifoldness or flipping faces (``on_unreachable="raise"``).
    """
    return _qem(V, F, target_faces, (), **_options(locals()))[0]


def _options(given: dict) -> dict:
    """The keyword options of :func:`qem_simplify` from its ``locals()``."""
    return {k: given[k] for k in _OPTIONS}


def _qem(V, F, target_faces, passing, *, pair_threshold, preserve_boundary, method, weighting, boundary_weight,
         crease_angle, crease_weight, min_cos, on_unreachable, refit):  # fmt: skip
    """:func:`qem_simplify`, also keeping the meshes of the greedy loop at the face counts ``passing``.

    Returns ``((V, F), {count: (V, F)})``: the result, and the meshes kept on the way (see
    :class:`_Passing`; empty when ``passing`` is, and for ``method="fast"``).
    """
    where = "qem_simplify"
    V, F = check_mesh(V, F, where=where, manifold=True)
    target_faces = _check_target(target_faces, len(F))
    passing = [_check_target(t, len(F)) for t in passing]
    pair_threshold = check_float(pair_threshold, "pair_threshold", minimum=0.0, where=where)
    if not isinstance(preserve_boundary, bool | np.bool_):
        raise MeshError(f"{where}: preserve_boundary must be True or False, got {preserve_boundary!r}")
    check_choice(method, "method", METHODS, where=where)
    check_choice(weighting, "weighting", WEIGHTINGS, where=where)
    boundary_weight = check_float(boundary_weight, "boundary_weight", minimum=0.0, where=where)
    if crease_angle is not None:
        crease_angle = check_float(crease_angle, "crease_angle", minimum=0.0, maximum=180.0, where=where)
    crease_weight = check_float(crease_weight, "crease_weight", minimum=0.0, where=where)
    min_cos = check_float(min_cos, "min_cos", minimum=-1.0, maximum=0.999, where=where)
    check_choice(on_unreachable, "on_unreachable", ("raise", "warn"), where=where)
    if method == "fast" and pair_threshold > 0:
        raise MeshError(f"{where}: method='fast' contracts edges only; use method='greedy' for pair_threshold > 0")

    if refit is None:
        refit = False
    if not isinstance(refit, bool | np.bool_):
        raise MeshError(f"{where}: refit must be True, False or None, got {refit!r}")

    with checked(V, F, manifold=True):  # the quadric and contraction helpers receive the checked mesh
        Q = vertex_quadrics(V, F, weighting, boundary_weight if preserve_boundary else 0.0)
        if crease_angle is not None and crease_weight > 0:
            Q += crease_quadrics(V, F, crease_angle, crease_weight)
        if method == "greedy":
            state = make_state(V, F, Q)
            if passing:
                state = _Passing(state, passing)
            _, others = candidate_pairs(V, F, pair_threshold)
            greedy_collapse(state, others, target_faces, min_cos)
            V_out, F_out = state_mesh(state)
            normals0 = state.face_normal0[state.face_alive]
        else:
            from .compiled import compiled_collapse  # imports numba (0.2-0.5 s): only when asked for

            V_out, F_out, normals0 = compiled_collapse(V, F, Q, target_faces, min_cos)
        if refit and len(F_out) and not pair_threshold > 0:
            V_out = refine_positions(V, F, V_out, F_out, normals0=normals0)

    if len(F_out) > target_faces + 2:
        msg = (
            f"{where}: stopped at {len(F_out)} faces, target {target_faces}: every remaining contraction would "
            f"break manifoldness (link condition) or flip a face. Closed pieces cannot go below 4 faces and "
            f"boundary loops below 3 edges; ask for more faces"
        )
        if on_unreachable == "raise":
            raise MeshError(msg)
        warnings.warn(msg, SimplificationWarning, stacklevel=3)
    return (V_out, F_out), (state.kept if method == "greedy" and passing else {})


#: The keyword options of :func:`qem_simplify` and their defaults.
_OPTIONS: dict = dict(qem_simplify.__kwdefaults__)


class _Passing(SimplifyState):
    """A :class:`SimplifyState` that keeps the compact mesh (:func:`state_mesh`) at given face counts.

    :func:`greedy_collapse` tests ``state.n_faces > target_faces`` before every contraction, the
    previous one complete. The loop is deterministic and its target decides only when it stops, so
    the first test that reads ``t`` faces or fewer sees the mesh a run to the target ``t`` stops
    with: that mesh is kept in ``kept[t]``. A loop that never reads ``n_faces`` there keeps nothing
    (:func:`qem_simplify_series` then runs to that target on its own).
    """

    def __init__(self, state: SimplifyState, counts):
        self.__dict__.update(vars(state))
        self._n = self.__dict__.pop("n_faces")
        self.pending = sorted(set(counts), reverse=True)
        self.kept: dict = {}

    @property
    def n_faces(self) -> int:
        while self.pending and self._n <= self.pending[0]:
            self.kept[self.pending.pop(0)] = state_mesh(self)
        return self._n

    @n_faces.setter
    def n_faces(self, n: int) -> None:
        self._n = n


def qem_simplify_series(V, F, targets, **options) -> list[tuple[np.ndarray, np.ndarray]]:
    """``qem_simplify(V, F, t, **options)`` for every ``t`` of ``targets``, from one run of the loop.

    A series of simplifications (the handout's 50%, 10% and 2% of the faces) need not repeat the
    greedy loop from the input for each: the loop runs once, to the smallest target, and keeps the
    mesh as it passes the others (the mesh a run to that target returns, bit for bit). With
    ``method="fast"`` or ``refit``, and for a target the loop passed without reading its face
    count, ``qem_simplify`` runs to that target on its own.

    Parameters
    ----------
    V, F
        As for :func:`qem_simplify`.
    targets : sequence of int
        Face counts, each as ``target_faces`` of :func:`qem_simplify`; any order, repeats allowed.
    **options
        The keyword options of :func:`qem_simplify`.

    Returns
    -------
    list of (V, F)
        One result per target, in the order of ``targets``.
    """
    unknown = sorted(set(options) - set(_OPTIONS))
    if unknown:
        raise MeshError(f"qem_simplify_series: unknown options {unknown}; qem_simplify takes {list(_OPTIONS)}")
    targets = list(targets)
    if not targets:
        raise MeshError("qem_simplify_series: targets is empty; give at least one face count")
    smallest = min(targets, key=lambda t: _check_target(t, np.iinfo(np.int64).max))  # integers >= 4
    chosen = {**_OPTIONS, **options}
    passing = [t for t in targets if t != smallest] if chosen["method"] == "greedy" and not chosen["refit"] else []
    result, kept = _qem(V, F, smallest, passing, **chosen)
    meshes = {int(smallest): result, **kept}
    for t in targets:
        if int(t) not in meshes:
            meshes[int(t)] = qem_simplify(V, F, t, **options)
    return [meshes[int(t)] for t in targets]
