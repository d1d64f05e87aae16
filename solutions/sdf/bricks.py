"""Sparse bricks with 8-bit quantisation (Task 5) and lookups in them (Task 6).

Far from the surface a distance field is boring: it only has to say "far, and on which side".
Production engines keep it in **bricks** of ``8 x 8 x 8`` samples around the surface only:

* A brick covers 7 grid cells per axis and stores **8** samples per axis: its 7 own samples plus
  one *apron* sample shared with the next brick, so a trilinear lookup inside a brick never needs a
  second brick. Brick ``(I, J, K)`` holds the grid samples ``7 I .. 7 I + 7`` (and so on per axis).
* The field is clamped to the band ``[-r, r]`` (``r = band_voxels * spacing``) and quantised to
  ``uint8``: ``s = round((d + r) / (2 r) * 255)``, decoded as ``d = s / 255 * 2 r - r``. The error
  of a stored sample inside the band is at most half a step, ``r / 255``.
* A brick whose samples are all at least ``r`` outside (or all at least ``r`` inside) is dropped:
  the **brick table** ``(nI, nJ, nK)`` holds, per brick, its row in ``codes`` or a sentinel,
  :data:`EMPTY_OUTSIDE` (``-1``, read as ``+r``) or :data:`EMPTY_INSIDE` (``-2``, read as ``-r``).

A grid whose side is not ``7 k + 1`` samples is padded at its far end by repeating its last
samples (documented behaviour); lookups never read the padding (they stay inside the original box).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.validate import MeshError, as_array, check_float

from .analytic import as_points
from .field import SDFGrid, check_grid, outside_rule

__all__ = ["BRICK", "EMPTY_OUTSIDE", "EMPTY_INSIDE", "BrickSDF", "encode_bricks", "brick_sample", "compress_bricks"]

#: Samples per brick and axis (7 cells + 1 apron sample).
BRICK = 8
#: Table entries of dropped bricks.
EMPTY_OUTSIDE = -1
EMPTY_INSIDE = -2


def _band(band_voxels, spacing, where):
    b = check_float(band_voxels, "band_voxels", where=where)
    if b <= 0:
        raise MeshError(f"{where}: band_voxels (r) must be > 0, got {b}")
    return b * spacing


def encode_bricks(values, spacing: float, band_voxels: float = 4) -> tuple[np.ndarray, np.ndarray]:
    """Split a grid into 8^3 bricks with a shared apron, quantise to uint8 and drop bricks outside the band.

    Parameters
    ----------
    values : (a, b, c) array_like
        Dense samples (each side >= 2).
    spacing : float
        Grid spacing (``r = band_voxels * spacing``).
    band_voxels : float
        Band radius ``> 0`` in voxels.

    Returns
    -------
    codes : (k, 8, 8, 8) uint8
        The kept bricks, in C order of their brick index ``(I, J, K)``.
    table : (nI, nJ, nK) int32
        Row of each brick in ``codes``, or ``-1`` (dropped, outside) / ``-2`` (dropped, inside).
        ``nI = ceil((a - 1) / 7)``.

    Notes
    -----
    Pad the grid to ``7 n + 1`` samples per axis with ``np.pad(mode="edge")``; brick ``(I, J, K)``
    is ``padded[7I : 7I + 8, 7J : 7J + 8, 7K : 7K + 8]``. Clamp to ``[-r, r]``, quantise with
    ``np.rint((d + r) / (2 r) * 255)``. Drop a brick when all its samples are ``>= r`` (outside)
    or all ``<= -r`` (inside).
    """
    where = "encode_bricks"
    values, _, spacing = check_grid(values, np.zeros(3), spacing, where)
    r = _band(band_voxels, spacing, where)
    n = -(-(np.array(values.shape) - 1) // (BRICK - 1))
    # BEGIN SOLUTION: Task 5 (bricks): pad to 7n+1 (mode="edge"); gather all bricks with strided indexing; clamp to [-r, r]; s = rint((d + r)/(2r) * 255); keep a brick unless all d >= r or all d <= -r; table = running index of kept bricks, -1 / -2 for dropped ones
    pad = [(0, int(7 * k + 1 - s)) for k, s in zip(n, values.shape, strict=True)]
    G = np.pad(values, pad, mode="edge")
    starts = [7 * np.arange(k) for k in n]
    off = np.arange(BRICK)
    ix = (starts[0][:, None] + off)[:, None, None, :, None, None]
    iy = (starts[1][:, None] + off)[None, :, None, None, :, None]
    iz = (starts[2][:, None] + off)[None, None, :, None, None, :]
    bricks = G[ix, iy, iz].reshape(-1, BRICK, BRICK, BRICK)  # (nI*nJ*nK, 8, 8, 8)
    flat = bricks.reshape(len(bricks), -1)
    out = flat.min(axis=1) >= r
    inside = flat.max(axis=1) <= -r
    keep = ~(out | inside)
    table = np.where(out, EMPTY_OUTSIDE, EMPTY_INSIDE).astype(np.int32)
    table[keep] = np.arange(int(keep.sum()), dtype=np.int32)
    codes = np.rint((np.clip(bricks[keep], -r, r) + r) / (2 * r) * 255).astype(np.uint8)
    return codes, table.reshape(tuple(int(k) for k in n))
    # END SOLUTION


def brick_sample(codes, table, origin, spacing: float, band_voxels: float, shape, P) -> np.ndarray:
    """Look the bricked field up at points ``P``.

    Parameters
    ----------
    codes, table : from :func:`encode_bricks`
    origin : (3,) array_like
        Position of grid sample ``(0, 0, 0)``.
    spacing : float
    band_voxels : float
    shape : (3,) ints
        Samples per axis of the original grid (its box is ``origin .. origin + spacing (shape - 1)``).
    P : (n, 3) array_like

    Returns
    -------
    d : (n,) float64
        Inside stored bricks: trilinear interpolation of the decoded samples ``s / 255 * 2r - r``;
        in dropped bricks ``+r`` / ``-r``; outside the box the outside rule of
        ``field.outside_rule`` applied to the value at the clamped point.

    Notes
    -----
    With ``u = (Q - origin) / spacing`` (``Q`` = ``P`` clamped to the box), the brick is
    ``B = min(floor(u / 7), nI - 1)`` per axis and the position inside it ``u - 7 B`` in ``[0, 7]``;
    the cell is ``min(floor(u - 7B), 6)``.
    """
    where = "brick_sample"
    codes = as_array(codes, "codes", dtype=np.uint8, shape=(None, BRICK, BRICK, BRICK), where=where)
    table = as_array(table, "table", dtype=np.int64, shape=(None, None, None), where=where)
    if np.any(table >= len(codes)) or np.any(table < EMPTY_INSIDE):
        raise MeshError(f"{where}: table entries must be -2, -1 or a row of codes (0..{len(codes) - 1})")
    origin = as_array(origin, "origin", shape=(3,), where=where)
    spacing = check_float(spacing, "spacing", positive=True, where=where)
    r = _band(band_voxels, spacing, where)
    shape = np.asarray(shape, np.int64).ravel()
    if shape.shape != (3,) or np.any(shape < 2) or np.any(-(-(shape - 1) // 7) != table.shape):
        raise MeshError(f"{where}: shape {shape} does not match a brick table of shape {table.shape}")
    P = as_points(P, where)
    Q = np.clip(P, origin, origin + spacing * (shape - 1))
    # BEGIN SOLUTION: Task 6 (queries): brick lookup: u = (Q - origin)/h; brick B = min(floor(u/7), n-1); local l = u - 7B; cell c = min(floor(l), 6), f = l - c; stored bricks: trilinear of s/255*2r - r; dropped: -1 -> +r, -2 -> -r; then outside_rule
    n = np.array(table.shape)
    u = (Q - origin) / spacing
    Bk = np.minimum(np.floor(u / 7).astype(np.int64), n - 1)
    loc = u - 7 * Bk
    c = np.minimum(np.floor(loc).astype(np.int64), BRICK - 2)
    f = loc - c
    entry = table[Bk[:, 0], Bk[:, 1], Bk[:, 2]]
    stored = entry >= 0
    phi = np.where(entry == EMPTY_INSIDE, -r, r).astype(np.float64)
    e, cs, fs = entry[stored], c[stored], f[stored]
    acc = np.zeros(len(e))
    for dx in (0, 1):
        wx = fs[:, 0] if dx else 1 - fs[:, 0]
        for dy in (0, 1):
            wy = fs[:, 1] if dy else 1 - fs[:, 1]
            for dz in (0, 1):
                wz = fs[:, 2] if dz else 1 - fs[:, 2]
                s = codes[e, cs[:, 0] + dx, cs[:, 1] + dy, cs[:, 2] + dz]
                acc += wx * wy * wz * (s / 255.0 * 2 * r - r)
    phi[stored] = acc
    return outside_rule(P, Q, phi)
    # END SOLUTION


@dataclass(frozen=True)
class BrickSDF:
    """A bricked, quantised distance field (see the module docstring).

    Attributes
    ----------
    codes : (k, 8, 8, 8) uint8
    table : (nI, nJ, nK) int32
    origin : (3,) float64
    spacing : float
    band_voxels : float
    shape : (3,) int
        Samples per axis of the dense grid it came from.
    """

    codes: np.ndarray
    table: np.ndarray
    origin: np.ndarray
    spacing: float
    band_voxels: float
    shape: tuple

    @property
    def r(self) -> float:
        """Band radius in world units."""
        return self.band_voxels * self.spacing

    @property
    def step(self) -> float:
        """One quantisation step, ``2 r / 255``."""
        return 2 * self.r / 255

    @property
    def nbytes(self) -> int:
        """Memory of the codes and the brick table, in bytes."""
        return int(self.codes.nbytes + self.table.nbytes)

    def sample(self, P) -> np.ndarray:
        return brick_sample(self.codes, self.table, self.origin, self.spacing, self.band_voxels, self.shape, P)

    def __call__(self, P) -> np.ndarray:
        return self.sample(P)


def compress_bricks(grid: SDFGrid, band_voxels: float = 4) -> BrickSDF:
    """Compress a dense :class:`SDFGrid` into a :class:`BrickSDF` (Task 5 through :func:`encode_bricks`).

    Parameters
    ----------
    grid : SDFGrid
        Or any object with ``values``, ``origin``, ``spacing``.
    band_voxels : float
        Band radius ``r`` in voxels, ``> 0``.
    """
    where = "compress_bricks"
    values, origin, spacing = check_grid(grid.values, grid.origin, grid.spacing, where)
    codes, table = encode_bricks(values, spacing, band_voxels)
    return BrickSDF(codes, table, origin, spacing, float(band_voxels), tuple(int(s) for s in values.shape))
