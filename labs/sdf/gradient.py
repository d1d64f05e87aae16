"""Normals of a distance field from its gradient (Task 7).

``grad phi`` is the outward unit normal on the surface. Two finite-difference stencils:

* **central differences**, 6 taps: ``g_x = (phi(p + h e_x) - phi(p - h e_x)) / 2h`` and so on;
  second-order accurate (error ``O(h^2)``).
* **tetrahedral**, 4 taps: ``g = sum_i k_i phi(p + h k_i)`` with
  ``k in {(1,-1,-1), (-1,-1,1), (-1,1,-1), (1,1,1)}``, the corners of a tetrahedron. Taylor
  expansion gives ``g = 4 h grad phi + 4 h^2 (phi_yz, phi_xz, phi_xy) + O(h^3)``: two thirds of
  the lookups, but only first-order accurate where the mixed second derivatives are not zero
  (curved surfaces seen diagonally, and every trilinear cell, whose ``xy``, ``xz``, ``yz`` terms
  are exactly such derivatives). The handout's figure measures both.

Both are normalised (``g / |g|``); a zero gradient (a point equidistant from everything) gives 0.
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import check_float

from .analytic import as_points
from .scene import as_field

__all__ = ["TETRA", "gradient_central", "gradient_tetra"]

TETRA = np.array([[1.0, -1.0, -1.0], [-1.0, -1.0, 1.0], [-1.0, 1.0, -1.0], [1.0, 1.0, 1.0]])


def _h(h, where):
    return check_float(h, "h", positive=True, where=where)


def _unit(G):
    L = np.linalg.norm(G, axis=1, keepdims=True)
    return np.divide(G, L, out=np.zeros_like(G), where=L > 0)


def gradient_central(sdf, P, h: float = 1e-3) -> np.ndarray:
    """Unit normals by 6-tap central differences.

    Parameters
    ----------
    sdf : field (see ``scene.as_field``)
    P : (n, 3) array_like
    h : float
        Step, ``> 0`` (on a grid, about half a voxel).

    Returns
    -------
    N : (n, 3) float64
        ``g / |g|`` with ``g_k = phi(p + h e_k) - phi(p - h e_k)`` (0 where ``g = 0``).
    """
    where = "gradient_central"
    phi = as_field(sdf, where)
    P = as_points(P, where)
    h = _h(h, where)
    raise NotImplementedError('Task 7 (gradients): 6-tap: g_k = phi(p + h e_k) - phi(p - h e_k), k = x, y, z; normalise (0 stays 0)')


def gradient_tetra(sdf, P, h: float = 1e-3) -> np.ndarray:
    """Unit normals by the 4-tap tetrahedral formula ``sum_i k_i phi(p + h k_i)`` (see :data:`TETRA`).

    Returns
    -------
    N : (n, 3) float64 (0 where the sum is 0)
    """
    where = "gradient_tetra"
    phi = as_field(sdf, where)
    P = as_points(P, where)
    h = _h(h, where)
    raise NotImplementedError('Task 7 (gradients): 4-tap: g = sum_i k_i phi(p + h k_i) over the 4 tetrahedron corners; normalise (0 stays 0)')
