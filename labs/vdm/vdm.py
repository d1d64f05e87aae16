"""Task 3 and the full pipeline: vector displacement maps.

A VDM is a ``res x res`` image of 3-vectors. Texel ``(i, j)`` belongs to the vertex of a flat
grid at ``p_o(i, j) = (j / (res - 1), i / (res - 1), 0)``; adding the texel's vector moves the
vertex onto the surface: ``p_m = p_o + d``. The texel was *sampled* at the grid position
``grid_uv[i, j]`` in the mesh's parameter domain — the uniform position for a naive VDM, an
optimised one after transport and alignment — so ``d(i, j) = p(grid_uv[i, j]) - p_o(i, j)`` with
``p`` the surface point at a uv (Task 2). Whoever renders the VDM only needs ``d`` and the
per-quad diagonal choice; ``grid_uv`` is kept for analysis.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int, check_mesh, checked

from .diagonals import choose_diagonals
from .features import align_to_features, sharp_features
from .grid import grid_faces, uniform_grid, valid_diagonals
from .importance import area_density, importance_field, vertex_importance
from .parameterize import parameterize_square
from .sampling import sample_surface
from .transport import transport_grid

__all__ = ["VDM", "flat_grid", "naive_vdm", "bake_vdm", "vdm_to_mesh", "save_vdm", "load_vdm"]


@dataclass
class VDM:
    """A baked vector displacement map.

    Attributes
    ----------
    displacement : (res, res, 3) float64
        ``d(i, j)``: offset of flat-grid vertex ``(i, j)`` (row i = v, column j = u).
    grid_uv : (res, res, 2) float64
        Where each texel was sampled in the mesh's parameter domain.
    diagonals : (res-1, res-1) bool
        Per-cell split: True along ``(i, j)-(i+1, j+1)``, False along ``(i, j+1)-(i+1, j)``.
    info : dict
        Free-form metadata (stages used, timings).
    """

    displacement: np.ndarray
    grid_uv: np.ndarray
    diagonals: np.ndarray
    info: dict = field(default_factory=dict)

    @property
    def res(self) -> int:
        return int(self.displacement.shape[0])


def flat_grid(res: int) -> np.ndarray:
    """Positions ``p_o`` of the flat grid, ``(res, res, 3)``: ``(j/(res-1), i/(res-1), 0)`` (given helper)."""
    g = uniform_grid(res)
    return np.concatenate([g, np.zeros(g.shape[:2] + (1,))], axis=-1)


def naive_vdm(V, F, UV, res: int, *, grid_uv=None) -> np.ndarray:
    """Displacements ``d(v) = p_m(v) - p_o(v)`` of a ``res x res`` grid.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    UV : (n, 2) float64
        Parameterization onto the unit square.
    res : int
        Texels per side (>= 2).
    grid_uv : (res, res, 2) float64, optional
        Where texel ``(i, j)`` samples the surface. Default: the uniform grid
        ``(j, i) / (res - 1)`` — the *naive* VDM.

    Returns
    -------
    D : (res, res, 3) float64
        ``D[i, j] = p(grid_uv[i, j]) - (j/(res-1), i/(res-1), 0)`` with ``p`` the surface point at a
        uv (:func:`sample_surface`).
    """
    where = "naive_vdm"
    V, F = check_mesh(V, F, where=where)
    UV = as_array(UV, "UV", shape=(len(V), 2), where=where)
    res = check_int(res, "res", minimum=2, maximum=4096, where=where)
    if grid_uv is not None:
        grid_uv = as_array(grid_uv, "grid_uv", shape=(res, res, 2), where=where)
    raise NotImplementedError("Task 3 (naive VDM): D = p_m - p_o, p_m = surface at the grid's uv, p_o = (u, v, 0)")


def vdm_to_mesh(vdm: VDM) -> tuple[np.ndarray, np.ndarray]:
    """Rebuild the surface from a VDM: ``V = p_o + d`` and two triangles per cell (given helper).

    Returns
    -------
    V : (res^2, 3) float64
        Vertex ``(i, j)`` at index ``i * res + j``.
    F : (2 (res-1)^2, 3) int64
        Split along each cell's chosen diagonal.
    """
    where = "vdm_to_mesh"
    D = as_array(getattr(vdm, "displacement", None), "vdm.displacement", shape=(None, None, 3), where=where)
    res = D.shape[0]
    if D.shape[1] != res or res < 2:
        raise MeshError(f"{where}: vdm.displacement has shape {D.shape}; expected (res, res, 3) with res >= 2")
    diag = np.asarray(getattr(vdm, "diagonals", np.ones((res - 1, res - 1), bool)))
    if diag.shape != (res - 1, res - 1):
        raise MeshError(f"{where}: vdm.diagonals has shape {diag.shape}; expected {(res - 1, res - 1)}")
    V = (flat_grid(res) + D).reshape(-1, 3)
    return V, grid_faces(res, diag.astype(bool))


def bake_vdm(
    V,
    F,
    res: int,
    *,
    optimize: bool = True,
    align: bool = True,
    diagonals: bool = True,
    method: str = "harmonic",
    angle: float = 30.0,
    background: float = 0.3,
    sigma: float | None = None,
    field_res: int | None = None,
    boundary: str = "slide",
    area_weighted: bool = True,
    UV=None,
) -> VDM:
    """Bake a VDM of a disk-topology mesh: parameterize, place the samples, sample (given pipeline).

    Stages (each can be switched off to compare): ``optimize`` — importance field + optimal
    transport (Tasks 4-6); ``align`` — snap to sharp corners/edges (Task 7); ``diagonals`` —
    per-cell split along sharp edges (Task 8). All off gives the naive VDM (Task 3).

    Parameters
    ----------
    V, F : disk-topology triangle mesh
    res : int
        Texels per side.
    method : str
        Parameterization (:func:`parameterize_square`).
    angle : float
        Sharp-edge threshold in degrees (:func:`sharp_features`).
    background, sigma : float
        Importance field parameters (:func:`importance_field`); ``field_res`` its pixels per side
        (default ``max(64, res)``).
    boundary : {"slide", "fixed"}
        :func:`transport_grid`'s boundary mode; sliding boundary vertices fit the mesh better, so the
        bake uses it by default.
    area_weighted : bool
        Weight the background importance by the parameterization's area stretch
        (:func:`area_density`), so that feature-free regions are sampled by surface area.
    UV : (n, 2) float64, optional
        A precomputed parameterization (skips ``parameterize_square``).

    Returns
    -------
    VDM
    """
    where = "bake_vdm"
    V, F = check_mesh(V, F, where=where)
    res = check_int(res, "res", minimum=2, maximum=1024, where=where)
    method = check_choice(method, "method", ("harmonic", "tutte", "lscm"), where=where)
    angle = check_float(angle, "angle", minimum=1e-9, maximum=180 - 1e-9, where=where)
    field_res = max(64, res) if field_res is None else check_int(field_res, "field_res", minimum=4, where=where)
    with checked(V, F):  # every call below gets the mesh validated above: no re-validation
        UV = parameterize_square(V, F, method) if UV is None else as_array(UV, "UV", shape=(len(V), 2), where=where)
        G = uniform_grid(res)
        info: dict = {"optimize": optimize, "align": align, "diagonals": diagonals}
        if optimize:
            imp = vertex_importance(V, F)
            dens = area_density(V, F, UV, field_res) if area_weighted else None
            fld = importance_field(UV, imp, field_res, background=background, sigma=sigma, density=dens)
            G = transport_grid(fld, res, boundary=boundary)
        edges, corners = sharp_features(V, F, angle)
        if align:
            G = align_to_features(G, V, F, UV, edges, corners)
        diag = choose_diagonals(G, V, F, UV, edges) if diagonals else valid_diagonals(G)
        D = naive_vdm(V, F, UV, res, grid_uv=G)
        return VDM(displacement=D, grid_uv=G, diagonals=diag, info=info)


def save_vdm(path, vdm: VDM) -> tuple[Path, Path]:
    """Write ``<path>.npz`` (float64 data) and ``<path>.png`` (16-bit RGB preview) (given helper).

    The preview maps each channel's range ``[lo_c, hi_c]`` linearly to ``[0, 65535]`` (the ranges are
    stored in the ``.npz`` as ``preview_lo``/``preview_hi``); image row 0 is v = 1 (texture
    convention: v points up).

    Returns
    -------
    (npz_path, png_path)
    """
    from geomlib.image_io import write_image

    path = Path(path)
    base = path.with_suffix("") if path.suffix in (".npz", ".png") else path
    D = np.asarray(vdm.displacement, np.float64)
    lo, hi = D.reshape(-1, 3).min(0), D.reshape(-1, 3).max(0)
    npz = base.with_suffix(".npz")
    np.savez_compressed(
        npz,
        displacement=D,
        grid_uv=np.asarray(vdm.grid_uv, np.float64),
        diagonals=np.asarray(vdm.diagonals, bool),
        preview_lo=lo,
        preview_hi=hi,
    )
    img = np.round((D - lo) / np.where(hi > lo, hi - lo, 1.0) * 65535).astype(np.uint16)[::-1]
    png = base.with_suffix(".png")
    write_image(png, img)
    return npz, png


def load_vdm(path) -> VDM:
    """Read a VDM written by :func:`save_vdm` (the ``.npz``; given helper)."""
    path = Path(path)
    with np.load(path.with_suffix(".npz")) as z:
        return VDM(displacement=z["displacement"], grid_uv=z["grid_uv"], diagonals=z["diagonals"])
