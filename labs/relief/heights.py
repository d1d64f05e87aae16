"""Given: the lab's height maps — smooth bumps (for secant refinement) and bricks (sharp steps, for binary search)."""

from __future__ import annotations

import numpy as np

__all__ = ["bumps", "bricks", "texel_uv"]


def texel_uv(s: int) -> tuple[np.ndarray, np.ndarray]:
    """U, V ``(s, s)`` of the texel centres; row 0 is ``v = 1 - 0.5 / s``."""
    r, c = np.mgrid[0:s, 0:s]
    return (c + 0.5) / s, 1.0 - (r + 0.5) / s


def bumps(s: int = 256, k: int = 3) -> np.ndarray:
    """Smooth bumps ``h = 1/2 + 1/2 sin(2 pi k u) sin(2 pi k v)``: ``k x k`` cells, heights in [0, 1]."""
    u, v = texel_uv(s)
    return 0.5 + 0.5 * np.sin(2 * np.pi * k * u) * np.sin(2 * np.pi * k * v)


def bricks(s: int = 256, rows: int = 4, mortar: float = 0.06, bevel: float = 0.03) -> np.ndarray:
    """Running-bond bricks: flat tops at 1, mortar joints at 0.15, a steep bevel between (sharp steps).

    ``rows`` courses of bricks twice as wide as high, every other course shifted by half a brick;
    ``mortar`` and ``bevel`` are fractions of a course's height.
    """
    u, v = texel_uv(s)
    y = v * rows
    course = np.floor(y)
    x = u * rows / 2 + 0.5 * (course % 2)
    # Distance (in course heights) from the nearest joint, horizontally and vertically.
    dy = np.minimum(y - course, course + 1 - y)
    dx = np.minimum(x - np.floor(x), np.floor(x) + 1 - x) * 2
    dist = np.minimum(dx, dy)
    t = np.clip((dist - mortar / 2) / bevel, 0.0, 1.0)
    return 0.15 + 0.85 * t
