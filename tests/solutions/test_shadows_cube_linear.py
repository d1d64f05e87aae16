"""The point light in linear depth (the NumPy twins of the shadows lab's tasks 11-12, ``cube_glsl.py``)
against an independent computation: geomlib's watertight ray caster, not the rasterizer."""

from __future__ import annotations

import numpy as np
import pytest

from geomlib.geometry import ray_cast
from solutions.shadows import (
    CUBE_DIRECTIONS,
    CUBE_UPS,
    cube_depth_maps,
    cube_distance_maps,
    cube_linear_depth,
    linear_point_shadow_visibility,
)
from tests.graded.shadows.support import small_scene, surface_points

LIGHT, NEAR, FAR = np.array([0.2, -0.3, 2.6]), 0.2, 12.0


def _texel_rays(size: int) -> np.ndarray:
    """(6, size, size, 3) world directions through the texel centres of the six 90-degree faces (row 0 at the top)."""
    c = (2.0 * np.arange(size) + 1.0) / size - 1.0
    x, y = np.meshgrid(c, c[::-1])
    out = []
    for d, up in zip(CUBE_DIRECTIONS, CUBE_UPS):
        right = np.cross(d, up)
        out.append(d + x[..., None] * right + y[..., None] * up)
    return np.stack(out)


def test_linear_cube_maps_are_the_ray_cast_distances():
    """Every texel holds the distance / far of the first surface along its centre's ray (no culling)."""
    V, F = small_scene()
    size = 32
    D = cube_distance_maps(V, F, LIGHT, size, NEAR, FAR, cull="none")
    dirs = _texel_rays(size).reshape(-1, 3)
    _, t, *_ = ray_cast(V, F, np.tile(LIGHT, (len(dirs), 1)), dirs)
    truth = (t * np.linalg.norm(dirs, axis=1) / FAR).reshape(D.shape)
    empty = np.isinf(truth)
    far_plane = np.linalg.norm(dirs, axis=1).reshape(D.shape)  # the far plane along the ray, over far
    assert np.abs(D[empty] - far_plane[empty]).max() < 1e-12
    err = np.abs(D[~empty] - truth[~empty])
    # the rasterizer snaps vertices to 1/256 texel (an error of the depth slope / 256), and texel centres
    # on an edge between two surfaces may pick either: a few may differ more
    assert np.median(err) < 1e-4 and (err > 1e-3).mean() < 2e-3, (np.median(err), int((err > 1e-3).sum()), err.size)


def test_linear_depth_of_window_depth_by_hand():
    """A texel at the face centre with window depth z_w: eye depth 2 n f / (f + n - (2 z_w - 1)(f - n))."""
    maps = np.full((6, 2, 2), 0.5)
    t = 2 * NEAR * FAR / (FAR + NEAR)  # z_ndc = 0
    # texel centres of a 2 x 2 face are at NDC (+-0.5, +-0.5): sqrt(1 + 0.25 + 0.25)
    assert np.allclose(cube_linear_depth(maps, NEAR, FAR), t * np.sqrt(1.5) / FAR, atol=1e-15)
    assert np.allclose(cube_linear_depth(np.ones((6, 2, 2)), NEAR, FAR), np.sqrt(1.5), atol=1e-15)


# Measured: 99.6% with front faces culled; 98.0% without culling, where the constant bias leaves acne on
# surfaces the light grazes (linear depth takes no slope-scaled bias).
@pytest.mark.parametrize(("cull", "least"), [("front", 0.99), ("none", 0.97)])
def test_linear_lookup_agrees_with_ray_casting(cull, least):
    """Hard shadows of the surface points facing the light (of 4,000) through a 256² linear cube against rays."""
    V, F = small_scene()
    P, N = surface_points(V, F, 4000, seed=21)
    facing = np.einsum("ij,ij->i", N, LIGHT - P) > 0  # the others are dark by N . L whatever the map says
    P, N = P[facing], N[facing]
    maps = cube_distance_maps(V, F, LIGHT, 256, NEAR, FAR, cull=cull)
    vis = linear_point_shadow_visibility(P, N, maps, LIGHT, NEAR, FAR, bias=0.004)
    d = LIGHT - P
    _, t, *_ = ray_cast(V, F, P, d, t_min=1e-6, t_max=1.0 - 1e-6)
    lit = np.isinf(t)
    agree = (vis >= 0.5) == lit
    assert agree.mean() > least, agree.mean()


def test_window_and_linear_routes_pick_the_same_surfaces():
    """Task 8's window-depth maps and the linear ones cover the same texels (the same nearest surface)."""
    V, F = small_scene()
    W = cube_depth_maps(V, F, LIGHT, 48, NEAR, FAR, cull="front")
    D = cube_distance_maps(V, F, LIGHT, 48, NEAR, FAR, cull="front")
    far_plane = np.linalg.norm(_texel_rays(48), axis=-1)
    assert np.array_equal(W < 1.0, np.abs(D - far_plane) > 1e-12)
