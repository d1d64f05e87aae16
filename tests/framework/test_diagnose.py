"""Hints that diagnose: a single planted error in one task of each lab is named by the message of a
failing composite case ("loop_subdivide is off because loop_even_matrix (Task 2) differs ...").

Each plant wraps one function of a copy of the reference solutions so that it is wrong in a known
way; the composite case is then run through the grader exactly as ``geomlib grade`` runs it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from geomlib.grading import impl as _impl
from geomlib.grading import tasks as _tasks
from geomlib.grading.cases import load_cases, run_case
from geomlib.grading.errors import Mismatch
from geomlib.grading.sandbox import LabProxy

from .course import appended, planted_solution


def _plant(lab: str, module: str, source: str) -> Path:
    """A copy of solutions/<lab> with ``source`` appended to ``module``.py (rebinding a function)."""
    return planted_solution(lab, appended(module, source, "tests/framework/test_diagnose.py"))


def _message(lab: str, folder: Path, case_id: str) -> str:
    case = next(c for c in load_cases(lab) if c.id == case_id)
    with pytest.raises(Mismatch) as e:
        run_case(LabProxy(lab, folder), case, feedback_dir=None)
    shutil.rmtree(folder.parent, ignore_errors=True)
    return str(e.value)


#: A sample_surface 1 % off, planted in the vdm lab (by the naive and the full bake).
SCALED_SAMPLES = """
        _true_sample_surface = sample_surface

        def sample_surface(V, F, UV, uv_points):
            return 1.01 * _true_sample_surface(V, F, UV, uv_points)
        """

# lab, module, planted source, composite case, words the message must contain
PLANTS = {
    "subdivision-even-weight-at-valence-6": (
        "subdivision",
        "loop",
        """
        _true_loop_weight = loop_weight

        def loop_weight(n, weights="warren"):
            u = np.asarray(_true_loop_weight(n, weights), dtype=float)
            return np.where(np.asarray(n) == 6, 1.2 * u, u)
        """,
        "loop-torus-2-loop",
        ["loop_subdivide is off because loop_even_matrix (Task 2:", "valence-6 vertices"],
    ),
    "subdivision-vertex-points": (
        "subdivision",
        "catmullclark",
        """
        _true_cc_vertex_points = cc_vertex_points

        def cc_vertex_points(V, faces, face_points=None, *, topo=None):
            return 1.01 * _true_cc_vertex_points(V, faces, face_points, topo=topo)
        """,
        "cc-cube-2",
        ["catmull_clark is off because cc_vertex_points (Task 8:"],
    ),
    "denoise-normal-offsets": (
        "denoise",
        "laplacian",
        """
        _true_normal_offsets = normal_offsets

        def normal_offsets(delta, N):
            return 0.8 * _true_normal_offsets(delta, N)
        """,
        "denoise-icosphere3-0.7",
        ["denoise_vertices is off because normal_offsets (Task 2:"],
    ),
    "maps-tangent-frames": (
        "maps",
        "tangents",
        """
        _true_tangent_frames = tangent_frames

        def tangent_frames(V, F, UV, N=None, *, eps=1e-12):
            T, B, N, w = _true_tangent_frames(V, F, UV, N, eps=eps)
            return B, T, N, w
        """,
        "bake-height-field-own-frames",
        ["bake_normal_map is off because tangent_frames (Task 1:"],
    ),
    "shadows-depth-comparison": (
        "shadows",
        "lookup",
        """
        _true_light_uvz = light_uvz

        def light_uvz(P, M):
            return np.asarray(_true_light_uvz(P, M)) + [0.05, 0.0, 0.0]
        """,
        "render-small",
        ["render_with_shadows is off because light_uvz (Task 3:"],
    ),
    "simplification-placement": (
        "simplification",
        "placement",
        """
        _true_optimal_contraction = optimal_contraction

        def optimal_contraction(Q, v1, v2):
            p, cost = _true_optimal_contraction(Q, v1, v2)
            return np.asarray(p) + 0.1, cost
        """,
        "simplify-torus-20pct",
        ["qem_simplify is off because optimal_contraction (Task 2:"],
    ),
    "vdm-sampling": (
        "vdm",
        "sampling",
        SCALED_SAMPLES,
        "naive-box-12",
        ["naive_vdm is off because sample_surface (Task 2:"],
    ),
    "vdm-bake-sampling": (
        "vdm",
        "sampling",
        SCALED_SAMPLES,
        "bake-box-6-12",
        ["bake_vdm is off because sample_surface (Task 2:"],
    ),
    "vdm-bake-transport": (
        "vdm",
        "transport",
        """
        _true_transport_grid = transport_grid

        def transport_grid(field, res, *, boundary="fixed", iterations=20, smoothing=1.0, return_info=False):
            return _true_transport_grid(
                field, res, boundary=boundary, iterations=max(1, iterations // 4), smoothing=smoothing,
                return_info=return_info,
            )
        """,
        "bake-box-6-12",
        ["bake_vdm is off because transport_grid (Task 6:"],
    ),
}


def test_error_beyond_the_first_level_is_named():
    """The icosahedron has only valence-5 vertices; valence 6 appears at level 1. The blocks agree on
    the input, so the grader looks at their other cases and still names the wrong rows."""
    src = """
    _true_loop_even_matrix = loop_even_matrix

    def loop_even_matrix(V, F, weights="warren", topo=None):
        S = sp.csr_matrix(_true_loop_even_matrix(V, F, weights, topo=topo))
        per_row = np.diff(S.indptr)  # an interior vertex of valence k has k + 1 weights
        return sp.diags(np.where(per_row == 7, 1.1, 1.0)) @ S
    """
    msg = _message("subdivision", _plant("subdivision", "loop", src), "loop-icosahedron-3-warren")
    assert "agree on this input, but loop_even_matrix (Task 2:" in msg and "valence-6 vertices" in msg, msg


@pytest.mark.parametrize("name", list(PLANTS))
def test_planted_error_is_named(name):
    lab, module, source, case_id, words = PLANTS[name]
    msg = _message(lab, _plant(lab, module, source), case_id)
    for w in words:
        assert w in msg, msg


def test_correct_blocks_point_at_the_composite_itself():
    """Blocks right, composite wrong: the message names the composite's own task, not a block."""
    src = """
    _true_loop_subdivide = loop_subdivide

    def loop_subdivide(V, F, levels=1, weights="warren", *, return_matrix=False):
        out = _true_loop_subdivide(V, F, max(int(levels) - 1, 0), weights, return_matrix=return_matrix)
        return out
    """
    msg = _message("subdivision", _plant("subdivision", "loop", src), "loop-torus-2-loop")
    assert "look at loop_subdivide itself (Task 5:" in msg, msg


@pytest.mark.parametrize("lab", _impl.lab_names())
def test_declared_task_tables_match_the_solutions(lab):
    """Every lab declares its table (without one, ``tasks.table`` derives it from the solutions and this
    test would compare the derived table with itself; a student's copy has no solutions, and the stubs
    lose the composites' calls) and the declaration matches the solutions' markers."""
    module = _tasks._declared(lab)
    assert module is not None and hasattr(module, "TASKS"), (
        f"tests/graded/{lab}/diagnose.py declares no task table (TASKS, TITLES, COMPOSITES): print it with "
        f'geomlib.grading.tasks.derive("solutions/{lab}")'
    )
    declared = _tasks.table(lab)
    derived = _tasks.derive(_impl.course_root() / "solutions" / lab)
    assert declared.tasks == derived.tasks
    assert declared.titles == derived.titles
    for f, blocks in declared.composites.items():
        assert derived.composites.get(f) is not None and set(blocks) == set(derived.composites[f]), f


def test_a_probe_graded_earlier_in_the_run_is_not_called_again(monkeypatch):
    """``--task 3`` of shadows grades light_uvz on "uvz-ortho", then render_with_shadows, whose
    diagnosis probes light_uvz on "uvz-ortho" again: the probe takes the graded call's outputs (one
    sandboxed call less per such probe, same message)."""
    from geomlib.grading import diagnose

    folder = _plant("shadows", "lookup", PLANTS["shadows-depth-comparison"][2])
    monkeypatch.setattr(diagnose, "_CACHE", {})
    monkeypatch.setattr(diagnose, "_OUTPUTS", {})
    calls = []
    lab = LabProxy("shadows", folder)
    real = lab.call
    monkeypatch.setattr(lab, "call", lambda function, *a, **k: (calls.append(function), real(function, *a, **k))[1])
    cases = {c.id: c for c in load_cases("shadows")}
    try:
        for case_id in ("uvz-ortho", "render-small"):
            with pytest.raises(Mismatch) as e:
                run_case(lab, cases[case_id], feedback_dir=None)
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)
    assert "render_with_shadows is off because light_uvz (Task 3:" in str(e.value)
    assert calls.count("light_uvz") == 1, calls
