"""Task 5: silhouettes — a relief-mapped polygon keeps its outline; fragments whose uv leaves the texture are discarded."""

from __future__ import annotations

import numpy as np

from .inputs import check_uv_points

__all__ = ["inside_texture"]


def inside_texture(uv) -> np.ndarray:
    """Which shifted texture coordinates still land on the texture: ``0 <= u <= 1`` and ``0 <= v <= 1``.

    On a quad textured once over ``[0, 1]^2``, a fragment whose relief-mapped ``uv`` falls outside
    looks through the side of the relief; discarding it carves the quad's silhouette. On a curved
    mesh the uv leaves the texture almost nowhere, so the silhouette stays the polygon's (fixing
    that needs the relief's volume as geometry: shell mapping, Porumbescu et al. 2005).

    Parameters
    ----------
    uv : (..., 2) float

    Returns
    -------
    (...) bool
        True where the fragment is kept.
    """
    uv = check_uv_points(uv, "inside_texture")
    # BEGIN SOLUTION: Task 5 (silhouette): keep where 0 <= u <= 1 and 0 <= v <= 1
    return np.all((uv >= 0.0) & (uv <= 1.0), axis=-1)
    # END SOLUTION
