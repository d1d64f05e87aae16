"""Lab "simplification": quadric error metrics (Garland & Heckbert 1997).

Tasks, in order:

1. quadrics: :func:`face_quadrics`, :func:`boundary_quadrics`, :func:`vertex_quadrics`;
2. placement: :func:`optimal_contraction` (incl. singular systems);
3. contraction: :func:`link_condition`, :func:`flips_normal`, :func:`contract_pair`;
4. the greedy loop: :func:`greedy_collapse`, used by :func:`qem_simplify`.
"""

# ruff: noqa: F403 (the package re-exports what its modules export)
from . import contraction, greedy, placement, quadrics, simplify
from .contraction import *
from .greedy import *
from .placement import *
from .quadrics import *
from .simplify import *

#: Exported by their modules for the lab's other modules (input checks and the like), not by the lab.
_MODULE_ONLY = {"SINGULAR_RCOND", "refresh_boundary"}
__all__ = [
    name
    for module in (quadrics, placement, contraction, greedy, simplify)
    for name in module.__all__
    if name not in _MODULE_ONLY
]
