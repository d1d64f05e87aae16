"""Depth-tested wireframe and highlighted-point overlays, drawn in NumPy onto the rendered image.

pyrender has no line primitive that is depth-tested against the surface at a fixed pixel width, so
edges are sampled along their screen-space projection (perspective-correct depth) and kept where
they are not behind the depth buffer.
"""

from __future__ import annotations

import numpy as np

__all__ = ["auto_wire_opacity", "overlay"]


def auto_wire_opacity(V: np.ndarray, edges: np.ndarray, size: tuple[int, int], zoom: float = 1.0) -> float:
    """Wireframe opacity for a mesh drawn at ``size``: 1 when a typical edge spans >= 7 pixels, fading
    to 0 at about one pixel (the object is assumed to span ~80% of the shorter image side)."""
    if edges is None or len(edges) == 0:
        return 1.0
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) or 1.0
    typical = float(np.median(np.linalg.norm(V[edges[:, 0]] - V[edges[:, 1]], axis=1)))
    px = typical / diag * 0.8 * min(size) * zoom
    return float(np.clip((px - 1.0) / 6.0, 0.0, 1.0))


def _project(X: np.ndarray, world_to_cam: np.ndarray, ty: float, tx: float, W: int, H: int):
    """World points -> (pixel x, pixel y, view depth); pixel (0, 0) is the top-left corner."""
    Xc = X @ world_to_cam[:3, :3].T + world_to_cam[:3, 3]
    z = -Xc[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        px = (Xc[:, 0] / (z * tx) + 1.0) * 0.5 * W
        py = (1.0 - Xc[:, 1] / (z * ty)) * 0.5 * H
    return px, py, z


def _visible(px, py, z, dmax: np.ndarray, tol: float):
    """Inside the image and not behind the rendered surface (``dmax``: 3x3 max of the depth buffer)."""
    H, W = dmax.shape
    inside = (px >= 0) & (px < W) & (py >= 0) & (py < H) & (z > 0)
    ix = np.clip(np.floor(np.where(inside, px, 0)).astype(np.int64), 0, W - 1)
    iy = np.clip(np.floor(np.where(inside, py, 0)).astype(np.int64), 0, H - 1)
    ref = dmax[iy, ix]
    return inside & (z <= ref * (1.0 + 2e-3) + tol), ix, iy


def _disk(diameter: float) -> np.ndarray:
    k = max(1, int(round(diameter)))
    c = (k - 1) / 2.0
    yy, xx = np.mgrid[:k, :k]
    return (xx - c) ** 2 + (yy - c) ** 2 <= (k / 2.0) ** 2 + 1e-9


def _stamped(iy: np.ndarray, ix: np.ndarray, structure: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The mask with ``structure`` stamped at each pixel ``(iy, ix)``: what ``ndimage.binary_dilation``
    of those pixels gives (same origin, same pixels), in time per dot instead of per image pixel."""
    H, W = shape
    k0, k1 = structure.shape
    oy, ox = np.nonzero(structure)
    yy = (np.asarray(iy)[:, None] + (oy - k0 // 2)[None]).ravel()
    xx = (np.asarray(ix)[:, None] + (ox - k1 // 2)[None]).ravel()
    ok = (yy >= 0) & (yy < H) & (xx >= 0) & (xx < W)
    out = np.zeros((H, W), dtype=bool)
    out[yy[ok], xx[ok]] = True
    return out


def _edge_mask(X0, X1, world_to_cam, ty, tx, dmax, tol, znear) -> np.ndarray:
    """Boolean (H, W) mask of the visible parts of the 3-D segments ``X0[i] -> X1[i]``."""
    H, W = dmax.shape
    mask = np.zeros((H, W), dtype=bool)
    if len(X0) == 0:
        return mask
    p0x, p0y, z0 = _project(X0, world_to_cam, ty, tx, W, H)
    p1x, p1y, z1 = _project(X1, world_to_cam, ty, tx, W, H)
    keep = (z0 > znear) & (z1 > znear)
    # Skip segments entirely off one side of the image.
    keep &= (
        ~((p0x < 0) & (p1x < 0)) & ~((p0x >= W) & (p1x >= W)) & ~((p0y < 0) & (p1y < 0)) & ~((p0y >= H) & (p1y >= H))
    )
    p0x, p0y, p1x, p1y = p0x[keep], p0y[keep], p1x[keep], p1y[keep]
    iz0, iz1 = 1.0 / z0[keep], 1.0 / z1[keep]
    length = np.minimum(np.hypot(p1x - p0x, p1y - p0y), 2.0 * (W + H))
    step = 0.5
    total = float(np.sum(np.ceil(length / step) + 1))
    if total > 2e7:  # bound memory on huge meshes: thin lines there are a grey haze anyway
        step *= total / 2e7
    n = (np.ceil(length / step) + 1).astype(np.int64)
    seg = np.repeat(np.arange(len(n)), n)
    start = np.repeat(np.cumsum(n) - n, n)
    t = (np.arange(int(n.sum())) - start) / np.repeat(np.maximum(n - 1, 1), n)
    # Screen-space positions interpolate linearly, and so does 1/depth (perspective-correct).
    px = p0x[seg] + t * (p1x - p0x)[seg]
    py = p0y[seg] + t * (p1y - p0y)[seg]
    z = 1.0 / (iz0[seg] + t * (iz1 - iz0)[seg])
    vis, ix, iy = _visible(px, py, z, dmax, tol)
    mask[iy[vis], ix[vis]] = True
    return mask


def overlay(
    color: np.ndarray,
    depth: np.ndarray,
    pose: np.ndarray,
    fov: float,
    znear: float,
    diag: float,
    *,
    V: np.ndarray,
    edges: np.ndarray | None,
    wire_color: np.ndarray,
    line_px: float,
    wire_opacity: float,
    points: np.ndarray | None,
    point_color: np.ndarray,
    point_px: float,
) -> np.ndarray:
    """Draw depth-tested edges and dots onto the (supersampled) render.

    ``point_color`` is one RGB colour in [0, 1] (shape ``(3,)``) or one per point (``(k, 3)``).
    """
    from scipy import ndimage

    H, W = depth.shape
    ty = np.tan(fov / 2)
    tx = ty * W / H
    world_to_cam = np.linalg.inv(pose)
    d = np.where(depth > 0, depth, np.inf).astype(np.float64)
    dmax = ndimage.maximum_filter(d, size=3, mode="nearest")
    tol = 2e-3 * diag
    out = color.astype(np.float32)
    if edges is not None and len(edges):
        mask = _edge_mask(V[edges[:, 0]], V[edges[:, 1]], world_to_cam, ty, tx, dmax, tol, znear)
        mask = ndimage.binary_dilation(mask, structure=_disk(line_px))
        wc = (255.0 * wire_color).astype(np.float32)
        out[mask] = out[mask] * (1.0 - wire_opacity) + wc * wire_opacity
    if points is not None and len(points):
        px, py, z = _project(V[points], world_to_cam, ty, tx, W, H)
        vis, ix, iy = _visible(px, py, z, dmax, tol)
        iy, ix = iy[vis], ix[vis]
        ring = _stamped(iy, ix, _disk(point_px + 0.3 * point_px + 2), (H, W))
        out[ring] = 255.0  # white halo keeps dots readable on dark wireframes
        rgb = np.broadcast_to(point_color, (len(points), 3))[vis]
        for c in np.unique(rgb, axis=0):  # one stamp per colour (a handful), not one per dot
            same = (rgb == c).all(axis=1)
            out[_stamped(iy[same], ix[same], _disk(point_px), (H, W))] = (255.0 * c).astype(np.float32)
    return out
