"""Lab "simplification": quadric error metrics (Garland & Heckbert 1997).

Tasks, in order:

1. quadrics: :func:`face_quadrics`, :func:`boundary_quadrics`, :func:`vertex_quadrics`;
2. placement: :func:`optimal_contraction` (incl. singular systems);
3. contraction: :func:`link_condition`, :func:`flips_normal`, :func:`contract_pair`;
4. the greedy loop: :func:`greedy_collapse`, used by :func:`qem_simplify`.
"""

from .contraction import (
    SimplifyState,
    check_contractions,
    contract_pair,
    contract_pairs,
    edge_faces,
    flips_normal,
    link_condition,
    make_state,
    neighbors,
    state_mesh,
)
from .greedy import candidate_pairs, greedy_collapse, pair_costs
from .placement import optimal_contraction
from .quadrics import boundary_quadrics, face_planes, face_quadrics, quadric_error, vertex_quadrics
from .simplify import SimplificationWarning, qem_simplify

__all__ = [
    "face_planes",
    "face_quadrics",
    "boundary_quadrics",
    "vertex_quadrics",
    "quadric_error",
    "optimal_contraction",
    "SimplifyState",
    "make_state",
    "neighbors",
    "edge_faces",
    "state_mesh",
    "link_condition",
    "flips_normal",
    "contract_pair",
    "check_contractions",
    "contract_pairs",
    "candidate_pairs",
    "pair_costs",
    "greedy_collapse",
    "qem_simplify",
    "SimplificationWarning",
]
