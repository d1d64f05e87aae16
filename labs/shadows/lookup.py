"""The second pass: is a surface point lit? (Tasks 3, 4, 6 and 7; :func:`shadow_visibility` is given.)

For a point ``P`` seen by the eye, transform it into light space with the light-space matrix ``M``,
divide by ``w`` and map NDC ``[-1, 1]`` to ``[0, 1]``::

    (x, y, z, w) = M @ (P, 1)        u = (x/w + 1) / 2,  v = (y/w + 1) / 2,  z_P = (z/w + 1) / 2

``(u, v)`` says where ``P`` lands in the shadow map ``D`` and ``z_P`` how far it is from the light,
in the same window-depth units as ``D``. The point is lit when nothing closer to the light was
stored there: ``z_P <= D(u, v)``.

Comparing a surface with its own stored depth is fragile: the map stores depth only at texel
centres, so a slanted surface is, within each texel, partly in front of and partly behind what is
stored. Half of it then shadows itself (*shadow acne*, a moire of dark stripes). The cure is a
bias ``b`` (Task 4), ``z_P - b <= D(u, v)``, made of a constant part and a part proportional to how
fast the surface's depth changes across a texel (the slope). Too much bias detaches shadows from
their casters (*peter-panning*). Points outside the light's frustum (Task 6) have no texel: they
must count as lit. Percentage-closer filtering (Task 7) averages the comparison over a
``k x k`` block of texels, which turns jagged 0/1 edges into soft ones.
"""

from __future__ import annotations

import numpy as np

from geomlib.raster import MAX_SIZE
from geomlib.validate import MeshError, as_array, check_float, check_int

from .options import (
    DEFAULT_BIAS_TEXELS,
    DEFAULT_MAX_SLOPE,
    DEFAULT_SLOPE_BIAS,
    PCF_SAMPLINGS,
    ShadowOptions,
    keyword_defaults,
)

__all__ = [
    "DEFAULT_BIAS_TEXELS",
    "DEFAULT_SLOPE_BIAS",
    "DEFAULT_MAX_SLOPE",
    "check_shadow_map",
    "light_uvz",
    "compare_depth",
    "receiver_depth_gradient",
    "shadow_bias",
    "outside_frustum",
    "pcf_visibility",
    "PCF_SAMPLINGS",
    "poisson_disk",
    "poisson_pcf_visibility",
    "shadow_visibility",
]

# --------------------------------------------------------------------------------------------
# input checks (given)


def check_shadow_map(D, where: str) -> np.ndarray:
    """A square float64 depth map ``(size, size)`` with finite values (given)."""
    D = as_array(D, "D", dtype=np.float64, finite=False, where=where)
    if D.ndim != 2 or D.shape[0] != D.shape[1] or D.shape[0] == 0 or D.shape[0] > MAX_SIZE:
        raise MeshError(f"{where}: D has shape {D.shape}; a shadow map is a square (size, size) array of depths")
    bad = ~np.isfinite(D)
    if bad.any():
        r, c = (int(i) for i in np.argwhere(bad)[0])
        raise MeshError(
            f"{where}: D[{r}, {c}] is {D[r, c]} ({int(bad.sum())} texels are not finite); empty texels of a "
            f"shadow map hold 1.0, the far plane"
        )
    return D


def _uvz(uvz, where: str) -> np.ndarray:
    return as_array(uvz, "uvz", shape=(None, 3), where=where)


def _bias_array(bias, n: int, where: str) -> np.ndarray:
    if np.ndim(bias) == 0:
        return np.full(n, check_float(bias, "bias", where=where))
    b = as_array(bias, "bias", where=where)
    if b.shape != (n,):
        raise MeshError(f"{where}: bias has shape {b.shape}, expected a number or one value per point ({n},)")
    return b


def _gradient_array(gradient, n: int, where: str) -> np.ndarray:
    """``(n, 2)`` receiver depth gradient, zeros when ``gradient`` is None (a flat receiver)."""
    return np.zeros((n, 2)) if gradient is None else as_array(gradient, "gradient", shape=(n, 2), where=where)


def _pcf_size(pcf, where: str) -> int:
    k = check_int(pcf, "pcf", minimum=1, maximum=15, where=where)
    if k % 2 == 0:
        raise MeshError(f"{where}: pcf must be odd (a k x k block centred on the texel), got {k}")
    return k


# --------------------------------------------------------------------------------------------
# Task 3: project and compare


def light_uvz(P, M) -> np.ndarray:
    """Shadow-map coordinates of world points: ``(u, v)`` in the map and depth ``z`` from the light.

    Parameters
    ----------
    P : (n, 3) array_like
        World positions.
    M : (4, 4) array_like
        Light-space matrix (clip from world).

    Returns
    -------
    uvz : (n, 3) float64
        ``(u, v, z) = ((x/w + 1) / 2, (y/w + 1) / 2, (z/w + 1) / 2)`` with ``(x, y, z, w) = M @ (P, 1)``.
        Inside the light's frustum all three lie in ``[0, 1]``; ``u`` grows to the right of the map
        and ``v`` upwards. Rows are NaN where ``w <= 0`` (the point is level with or behind a
        perspective light, where the projection is undefined).
    """
    where = "light_uvz"
    P = as_array(P, "P", shape=(None, 3), where=where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    raise NotImplementedError('Task 3 (the comparison): (x, y, z, w) = M @ (P, 1); uvz = (xyz / w + 1) / 2; NaN where w <= 0')


def compare_depth(D, uvz, bias=0.0) -> np.ndarray:
    """Shadow test of points against the map, one texel each: 1 where lit, 0 where in shadow.

    Parameters
    ----------
    D : (size, size) array_like
        Shadow map from :func:`depth_map` (row 0 = top of the map, ``v = 1``).
    uvz : (n, 3) array_like
        Map coordinates from :func:`light_uvz` (finite).
    bias : float or (n,) array_like
        Subtracted from the point's depth before comparing.

    Returns
    -------
    lit : (n,) float64
        ``1.0`` where ``z - bias <= D[row, col]``, else ``0.0``, with the texel that contains ``(u, v)``::

            col = floor(u * size),   row = size - 1 - floor(v * size)

        both clamped to ``0 .. size - 1`` (as OpenGL's ``GL_CLAMP_TO_EDGE``: points outside the map
        read its border).
    """
    where = "compare_depth"
    D = check_shadow_map(D, where)
    uvz = _uvz(uvz, where)
    b = _bias_array(bias, len(uvz), where)
    raise NotImplementedError('Task 3 (the comparison): col = floor(u size), row = size - 1 - floor(v size), clamped; lit = z - bias <= D[row, col]')


# --------------------------------------------------------------------------------------------
# Task 4: bias


def receiver_depth_gradient(P, N, M, size: int, max_slope: float = DEFAULT_MAX_SLOPE) -> np.ndarray:
    """How fast the depth of each point's tangent plane changes from one texel to the next.

    Parameters
    ----------
    P : (n, 3) array_like
        World positions.
    N : (n, 3) array_like
        Geometric normals at ``P`` (any length, any sign; zero rows give a zero gradient).
    M : (4, 4) array_like
        Light-space matrix; must be invertible (every perspective or orthographic light is).
    size : int
        Map size in texels.
    max_slope : float
        Largest NDC slope ``|dz/dx|``, ``|dz/dy|`` kept: planes seen edge-on by the light have an
        infinite slope, which is clamped to this.

    Returns
    -------
    g : (n, 2) float64
        ``(dz/du, dz/dv)``: change of window depth per texel step to the right (``+u``) and up
        (``+v``) along the plane through ``P`` with normal ``N``.

    Notes
    -----
    A plane is the 4-vector ``pi = (N, -N . P)`` (``pi . (X, 1) = 0`` on the plane). Projective
    maps take planes to planes: in clip space it is ``(a, b, c, d) = M^{-T} pi``, and because NDC
    points are clip points divided by ``w``, the plane in NDC is ``a x + b y + c z + d = 0``. So
    ``dz/dx = -a / c`` and ``dz/dy = -b / c`` in NDC. One texel is ``2 / size`` in NDC and window
    depth is ``(z + 1) / 2``, hence (after clamping the NDC slopes to ``[-max_slope, max_slope]``)::

        g = (-a / c, -b / c) / size

    This is the receiver-plane depth bias of Isidoro (GDC 2006), the receiver-side counterpart of
    OpenGL's ``glPolygonOffset`` slope factor; it is exact for orthographic and perspective lights.
    """
    where = "receiver_depth_gradient"
    P = as_array(P, "P", shape=(None, 3), where=where)
    N = as_array(N, "N", shape=(len(P), 3), where=where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    size = check_int(size, "size", minimum=1, maximum=MAX_SIZE, where=where)
    max_slope = check_float(max_slope, "max_slope", minimum=0.0, where=where)
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise MeshError(f"{where}: M is singular; a light-space matrix must be invertible") from None
    raise NotImplementedError('Task 4 (bias): (a, b, c, d) = M^{-T} (N, -N.P); g = clip((-a/c, -b/c), -max_slope, max_slope) / size')


def shadow_bias(gradient, bias: float, slope_bias: float) -> np.ndarray:
    """Per-point depth bias: a constant part plus a slope-scaled part.

    Parameters
    ----------
    gradient : (n, 2) array_like
        ``(dz/du, dz/dv)`` per texel, from :func:`receiver_depth_gradient`.
    bias : float
        Constant part, in window-depth units (``>= 0``).
    slope_bias : float
        Factor on the slope part (``>= 0``); 1 exactly covers a flat surface.

    Returns
    -------
    b : (n,) float64
        ``b = bias + slope_bias * (|dz/du| + |dz/dv|) / 2``.

    Notes
    -----
    A point may lie anywhere in its texel, up to half a texel from the centre in ``u`` and in ``v``,
    where the map sampled the depth. Along its tangent plane the depth there differs by at most
    ``(|dz/du| + |dz/dv|) / 2``: that much bias (``slope_bias = 1``) is what a flat surface needs
    not to shadow itself; the constant part covers curvature and round-off.
    """
    where = "shadow_bias"
    g = as_array(gradient, "gradient", shape=(None, 2), where=where)
    bias = check_float(bias, "bias", minimum=0.0, where=where)
    slope_bias = check_float(slope_bias, "slope_bias", minimum=0.0, where=where)
    raise NotImplementedError('Task 4 (bias): b = bias + slope_bias (|g_u| + |g_v|) / 2')


# --------------------------------------------------------------------------------------------
# Task 6: frustum


def outside_frustum(uvz) -> np.ndarray:
    """Points the shadow map does not cover: they must count as lit.

    Parameters
    ----------
    uvz : (n, 3) array_like
        Finite map coordinates from :func:`light_uvz`.

    Returns
    -------
    outside : (n,) bool
        True where ``u`` or ``v`` is outside ``[0, 1]`` (beside the map) or ``z > 1`` (beyond the far
        plane). ``z < 0`` (nearer than the near plane) is not outside: nothing can be in front of such
        a point, and the comparison already finds it lit.
    """
    where = "outside_frustum"
    uvz = _uvz(uvz, where)
    raise NotImplementedError('Task 6 (frustum handling): outside = u < 0 or u > 1 or v < 0 or v > 1 or z > 1')


# --------------------------------------------------------------------------------------------
# Task 7: percentage-closer filtering


def pcf_visibility(D, uvz, bias=0.0, pcf: int = 3, gradient=None) -> np.ndarray:
    """Percentage-closer filtering: the fraction of a ``pcf x pcf`` block of texels that finds the point lit.

    Parameters
    ----------
    D : (size, size) array_like
        Shadow map (row 0 = top, ``v = 1``).
    uvz : (n, 3) array_like
        Finite map coordinates from :func:`light_uvz`.
    bias : float or (n,) array_like
        Depth bias, as in :func:`compare_depth`.
    pcf : int
        Odd block size ``k``; ``k = 1`` is :func:`compare_depth`.
    gradient : (n, 2) array_like, optional
        ``(dz/du, dz/dv)`` per texel (:func:`receiver_depth_gradient`). When given, each neighbour
        is compared with the point's tangent plane extended to that texel, so a slanted surface does
        not shadow itself through the wider block.

    Returns
    -------
    visibility : (n,) float64 in [0, 1]
        Mean over the offsets ``(i, j)`` in ``{-(k-1)/2, ..., (k-1)/2}^2`` (``i`` texels to the right,
        ``j`` texels up) of::

            z + g_u i + g_v j - bias <= D[clamp(row - j), clamp(col + i)]

        with ``row``, ``col`` the point's own texel as in :func:`compare_depth` (and ``g = 0`` when no
        gradient is given).
    """
    where = "pcf_visibility"
    D = check_shadow_map(D, where)
    uvz = _uvz(uvz, where)
    b = _bias_array(bias, len(uvz), where)
    k = _pcf_size(pcf, where)
    g = _gradient_array(gradient, len(uvz), where)
    raise NotImplementedError('Task 7 (PCF): mean over i, j in -(k-1)/2..(k-1)/2 of [z + g_u i + g_v j - bias <= D[clamp(row - j), clamp(col + i)]]')


# --------------------------------------------------------------------------------------------
# Poisson-disk PCF (given; an extension of Task 7)


def poisson_disk(samples: int = 16, *, seed: int = 0, candidates: int = 32) -> np.ndarray:
    """Well-spread points in the unit disk: Mitchell's best-candidate sampling (given).

    Each new point is the one of ``candidates`` uniform random points in the disk that lies
    farthest from the points chosen so far, so no two points come close (a Poisson-disk
    distribution) while the disk is covered evenly. The same ``seed`` gives the same points.

    Parameters
    ----------
    samples : int, 1..256
    seed : int
    candidates : int
        Candidates per point; more spreads the points more evenly.

    Returns
    -------
    (samples, 2) float64
        Offsets ``(x, y)`` with ``x² + y² <= 1``.

    Examples
    --------
    >>> d = poisson_disk(16)
    >>> d.shape, bool((np.hypot(d[:, 0], d[:, 1]) <= 1).all())
    ((16, 2), True)
    """
    where = "poisson_disk"
    samples = check_int(samples, "samples", minimum=1, maximum=256, where=where)
    candidates = check_int(candidates, "candidates", minimum=1, maximum=4096, where=where)
    rng = np.random.default_rng(check_int(seed, "seed", minimum=0, where=where))

    def uniform_in_disk(k: int) -> np.ndarray:
        r, t = np.sqrt(rng.random(k)), 2 * np.pi * rng.random(k)
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)

    pts = uniform_in_disk(1)
    for _ in range(samples - 1):
        c = uniform_in_disk(candidates)
        gap = ((c[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2).min(axis=1)
        pts = np.vstack([pts, c[np.argmax(gap)]])
    return pts


def _texel_angle(row: np.ndarray, col: np.ndarray) -> np.ndarray:
    """A rotation angle per texel from an integer hash: fixed on the map, so the noise does not crawl."""
    h = (row.astype(np.uint64) * np.uint64(73856093)) ^ (col.astype(np.uint64) * np.uint64(19349663))
    h = (h * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(40)
    return (h.astype(np.float64) / 2.0**24) * (2 * np.pi)


def poisson_pcf_visibility(
    D, uvz, bias=0.0, radius: float = 1.5, samples: int = 16, gradient=None, *, rotate: bool = True
) -> np.ndarray:
    """PCF with the samples on a rotated Poisson disk instead of a k x k block of texels (given).

    The k x k block gives only ``k² + 1`` visibility levels, and its square footprint shows as
    stair-stepped bands along a soft edge. Samples spread evenly over a *disk* of ``radius`` texels,
    rotated by a different angle at every texel, turn the bands into fine noise (which the eye
    forgives) at the same or lower cost: 16 disk samples against 25 for a 5 x 5 block.

    Parameters
    ----------
    D, uvz, bias
        Shadow map, map coordinates and depth bias, as in :func:`pcf_visibility`.
    radius : float, > 0
        Disk radius in texels; ``k / 2`` covers about the area of a k x k block.
    samples : int
        Number of disk samples (:func:`poisson_disk`).
    gradient : (n, 2) array_like, optional
        ``(dz/du, dz/dv)`` per texel, as in :func:`pcf_visibility`: each sample is compared with
        the point's tangent plane extended to the sample.
    rotate : bool
        Rotate the disk per texel (noise instead of bands); ``False`` uses the same disk everywhere.

    Returns
    -------
    visibility : (n,) float64 in [0, 1]
        Mean over the disk offsets ``(dx, dy)`` (texels, ``dy`` up) of
        ``z + g_u dx + g_v dy - bias <= D[texel containing (u size + dx, v size + dy)]``.
    """
    where = "poisson_pcf_visibility"
    D = check_shadow_map(D, where)
    uvz = _uvz(uvz, where)
    b = _bias_array(bias, len(uvz), where)
    radius = check_float(radius, "radius", minimum=0.0, where=where)
    if radius <= 0:
        raise MeshError(f"{where}: radius must be > 0 texels, got {radius}")
    if not isinstance(rotate, bool | np.bool_):
        raise MeshError(f"{where}: rotate must be True or False, got {rotate!r}")
    g = _gradient_array(gradient, len(uvz), where)
    disk = poisson_disk(samples) * radius
    size = D.shape[0]
    x, y = uvz[:, 0] * size, uvz[:, 1] * size  # continuous texel coordinates, y up
    z = uvz[:, 2] - b
    if rotate:
        t = _texel_angle(np.floor(y).astype(np.int64), np.floor(x).astype(np.int64))
        cos, sin = np.cos(t), np.sin(t)
    lit = np.zeros(len(uvz))
    for ox, oy in disk:  # a few offsets, each vectorised over all points
        dx, dy = (cos * ox - sin * oy, sin * ox + cos * oy) if rotate else (ox, oy)
        col = np.clip(np.floor(x + dx), 0, size - 1).astype(np.int64)
        row = np.clip(size - 1 - np.floor(y + dy), 0, size - 1).astype(np.int64)
        lit += z + g[:, 0] * dx + g[:, 1] * dy <= D[row, col]
    return lit / len(disk)


# --------------------------------------------------------------------------------------------
# Everything together (given)


def shadow_visibility(
    P,
    N,
    D,
    M,
    bias: float | None = None,
    slope_bias: float | None = None,
    pcf: int = 1,
    *,
    frustum_fix: bool = True,
    max_slope: float = DEFAULT_MAX_SLOPE,
    pcf_sampling: str = "grid",
    pcf_samples: int = 16,
    options: ShadowOptions | None = None,
) -> np.ndarray:
    """How much of the light reaches each point: 1 lit, 0 in shadow, fractions at soft PCF edges (given).

    Parameters
    ----------
    P : (n, 3) array_like
        World positions of surface points (e.g. what the eye sees, one per pixel).
    N : (n, 3) array_like
        Geometric (face) normals at ``P``, used for the slope-scaled bias. Interpolated vertex normals
        of a coarse mesh do not match the actual facets and give acne.
    D : (size, size) array_like
        Shadow map from :func:`depth_map`.
    M : (4, 4) array_like
        The light-space matrix the map was rendered with.
    bias : float, optional
        Constant bias in window-depth units; default ``DEFAULT_BIAS_TEXELS / size``.
    slope_bias : float, optional
        Slope factor (see :func:`shadow_bias`); default ``DEFAULT_SLOPE_BIAS``.
    pcf : int
        Odd PCF block size; 1 gives hard 0/1 shadows.
    frustum_fix : bool
        Treat points outside the light frustum as lit (Task 6). ``False`` shows what happens without:
        they read clamped border texels and, beyond the far plane, are always dark.
    max_slope : float
        Clamp of the NDC depth slope (see :func:`receiver_depth_gradient`).
    pcf_sampling : {"grid", "poisson"}
        ``"grid"``: the ``pcf x pcf`` block of :func:`pcf_visibility`. ``"poisson"``:
        ``pcf_samples`` samples on a rotated Poisson disk of radius ``pcf / 2`` texels
        (:func:`poisson_pcf_visibility`); noise instead of bands along soft edges. ``pcf = 1`` is
        the hard 0/1 test either way.
    pcf_samples : int
        Disk samples for ``pcf_sampling="poisson"``.
    options : ShadowOptions, optional
        All of the above at once, checked when made (then leave the keywords at their defaults);
        ``cull`` and ``bounds`` in it are not used here.

    Returns
    -------
    visibility : (n,) float64 in [0, 1]

    Notes
    -----
    Points behind a perspective light (NaN in :func:`light_uvz`) are returned lit: no map can hold
    them; a spot light's cone leaves them dark anyway, and a point light uses a cube map.
    """
    where = "shadow_visibility"
    P = as_array(P, "P", shape=(None, 3), where=where)
    N = as_array(N, "N", shape=(None, 3), where=where)
    if len(N) != len(P):
        raise MeshError(f"{where}: N has {len(N)} rows but P has {len(P)}; expected one normal per point")
    D = check_shadow_map(D, where)
    M = as_array(M, "M", shape=(4, 4), where=where)
    size = D.shape[0]
    keywords = dict(
        bias=bias, slope_bias=slope_bias, pcf=pcf, frustum_fix=frustum_fix, max_slope=max_slope,
        pcf_sampling=pcf_sampling, pcf_samples=pcf_samples,
    )  # fmt: skip
    opts = ShadowOptions.of(options, where, keywords, _SHADOW_VISIBILITY_DEFAULTS)
    bias = DEFAULT_BIAS_TEXELS / size if opts.bias is None else opts.bias
    slope_bias = DEFAULT_SLOPE_BIAS if opts.slope_bias is None else opts.slope_bias
    k, max_slope, pcf_sampling, pcf_samples = opts.pcf, opts.max_slope, opts.pcf_sampling, opts.pcf_samples

    vis = np.ones(len(P))
    uvz = light_uvz(P, M)
    ok = np.isfinite(uvz).all(axis=1)
    if opts.frustum_fix:
        ok[ok] = ~outside_frustum(uvz[ok])
    idx = np.flatnonzero(ok)
    if len(idx) == 0:
        return vis
    uvz = uvz[idx]
    if slope_bias == 0 and k == 1:
        g, b = None, np.full(len(idx), bias)  # a constant bias needs no gradient
    else:
        g = receiver_depth_gradient(P[idx], N[idx], M, size, max_slope)
        b = shadow_bias(g, bias, slope_bias)
    if k == 1:
        vis[idx] = compare_depth(D, uvz, b)
    elif pcf_sampling == "poisson":
        vis[idx] = poisson_pcf_visibility(D, uvz, b, k / 2, pcf_samples, gradient=g)
    else:
        vis[idx] = pcf_visibility(D, uvz, b, k, gradient=g)
    return vis


_SHADOW_VISIBILITY_DEFAULTS = keyword_defaults(shadow_visibility)
