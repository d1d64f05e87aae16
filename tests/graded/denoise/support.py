"""Inputs and comparisons shared by the graded denoise tests (public: shipped with the lab).

Everything here is independent of any implementation of the lab: meshes come from
``geomlib.datasets`` (deterministic, seeded), noisy inputs are made here with geomlib only (the
same recipe as the lab's given ``make_noisy``), and expected values come from hand calculations,
formulas written out below, or the stored references.
"""

from __future__ import annotations

import numpy as np

from geomlib import datasets, portable
from geomlib.geometry import bbox_diagonal, closest_points, mean_edge_length, vertex_normals
from geomlib.grading import checks
from geomlib.grading.checks import format_vec
from geomlib.textures import weld_by_position

# --------------------------------------------------------------------------------------------
# tiny meshes (by hand)

#: A pyramid without its bottom: apex 0 over a diamond of 4 base vertices (base edges are boundary).
PYRAMID_V = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
PYRAMID_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])

#: A right isosceles triangle: 90 degrees at vertex 0, 45 at vertices 1 and 2.
RIGHT_V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
RIGHT_F = np.array([[0, 1, 2]])

#: Regular tetrahedron (all corner angles 60 degrees, so all cotangent weights are equal).
REG_TET_V = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
REG_TET_F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])

#: Two triangles sharing an edge in 3-D, but cut along it in UV: vertices 3 and 4 copy 1 and 2.
SPLIT_V = np.array(
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.3]]
)
SPLIT_F = np.array([[0, 1, 2], [3, 5, 4]])
SPLIT_UV = np.array([[0.0, 0.0], [0.45, 0.0], [0.0, 0.45], [0.55, 0.55], [0.55, 1.0], [1.0, 1.0]])


# --------------------------------------------------------------------------------------------
# noisy inputs (the recipe of the lab's given make_noisy, written with geomlib only)


def noisy(V, F, sigma_rel: float = 0.3, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(V_noisy, N_clean)``: Gaussian noise of ``sigma_rel`` mean edge lengths along random directions.

    Vertices at the same position (UV seam copies) get the same noise and the same normal.
    """
    V, F = np.asarray(V, float), np.asarray(F, np.int64)
    group, k = weld_by_position(V)
    first = np.full(k, len(V), np.int64)
    np.minimum.at(first, group, np.arange(len(V)))
    Vw, Fw = V[first], group[F]
    Vn = datasets.add_noise(Vw, sigma_rel * mean_edge_length(Vw, Fw), seed=seed, direction="random")
    return Vn[group], vertex_normals(Vw, Fw)[group]


def surface_error(V_clean, F_clean, X) -> np.ndarray:
    """Distance of each point of ``X`` to the clean surface, relative to its bbox diagonal."""
    d2, _, _ = closest_points(V_clean, F_clean, X)
    return np.sqrt(d2) / bbox_diagonal(V_clean)


def seam_groups(V) -> np.ndarray:
    """Group label of every vertex: vertices with equal positions share a label."""
    return weld_by_position(np.asarray(V, float))[0]


def copy_spread(X, group) -> float:
    """Largest distance of a vertex from the mean of its copies (0 when every seam stays closed)."""
    X = np.asarray(X, float)
    k = int(group.max()) + 1
    c = np.stack([np.bincount(group, weights=X[:, i], minlength=k) for i in range(3)], 1)
    c /= np.bincount(group, minlength=k)[:, None]
    return float(np.linalg.norm(X - c[group], axis=1).max())


def random_map(size: int, seed: int = 0, dtype=np.uint16) -> np.ndarray:
    """A smooth, seeded offset map (sum of a few waves), quantised to ``dtype``."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:size, 0:size] / size
    H = sum(
        rng.uniform(0.3, 1)
        * portable.sin(2 * np.pi * (rng.integers(1, 5) * c + rng.integers(1, 5) * r) + rng.uniform(0, 6))
        for _ in range(5)
    )
    H = (H - H.min()) / (H.max() - H.min())
    return np.round(H * np.iinfo(dtype).max).astype(dtype)


# --------------------------------------------------------------------------------------------
# comparisons


def _as_float(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def map_check(*, level_tol: int = 1):
    """Compare a baked ``(image, bias, scale)``: dtype, shape, bias and scale, texels within ``level_tol`` levels."""

    def compare(expected: dict, got: dict, ctx) -> str | None:
        e_img = np.asarray(expected["image"])
        img = got.get("image")
        if not isinstance(img, np.ndarray):
            return f"image should be a NumPy array, got {type(img).__name__}"
        if img.dtype != e_img.dtype:
            return (
                f"image has dtype {img.dtype}, expected {e_img.dtype} (quantise: np.round(h * {np.iinfo(e_img.dtype).max})"
                f".astype(np.{e_img.dtype}))"
            )
        if img.shape != e_img.shape:
            return f"image has shape {img.shape}, expected {e_img.shape}"
        for name in ("bias", "scale"):
            v = _as_float(got.get(name))
            if v is None:
                return f"{name} should be a number, got {type(got.get(name)).__name__}"
            ev = float(np.asarray(expected[name]))
            if not abs(v - ev) <= 1e-12 * max(1.0, abs(ev)):
                return f"{name} is {v:.9g}, expected {ev:.9g}"
        diff = np.abs(img.astype(np.int64) - e_img.astype(np.int64))
        bad = diff > level_tol
        if bad.any():
            r, c = (int(i) for i in np.argwhere(bad)[0])
            return (
                f"texel [{r}, {c}] is {int(img[r, c])}, expected {int(e_img[r, c])}; {int(bad.sum())} of {bad.size} texels "
                f"differ by more than {level_tol} level(s)"
            )
        return None

    return checks.Custom(compare)


def weld_check():
    """Compare ``(Vw, Fw, group)`` of a weld up to the numbering of the groups."""

    def compare(expected: dict, got: dict, ctx) -> str | None:
        eg = np.asarray(expected["group"])
        try:
            g = np.asarray(got.get("group"))
            Vw = np.asarray(got.get("Vw"), dtype=float)
            Fw = np.asarray(got.get("Fw"))
        except (TypeError, ValueError):
            return "Vw, Fw and group should be arrays"
        if g.shape != eg.shape or g.dtype.kind not in "iu":
            return f"group should be an int array of shape {eg.shape}, got {g.dtype} {g.shape}"
        k = int(eg.max()) + 1
        if g.min(initial=0) < 0 or len(np.unique(g)) != k or int(g.max()) + 1 != k:
            return f"expected {k} groups labelled 0..{k - 1}, got {len(np.unique(g))} distinct labels from {int(g.min())} to {int(g.max())}"
        pairs = np.unique(np.stack([eg, g], 1), axis=0)
        if len(pairs) != k:
            a = (
                int(pairs[np.flatnonzero(np.diff(pairs[:, 0]) == 0)[0], 0])
                if (np.diff(pairs[:, 0]) == 0).any()
                else None
            )
            i = int(np.flatnonzero(eg == a)[0]) if a is not None else 0
            return (
                f"the groups differ: e.g. vertex {i} at {format_vec(np.asarray(expected['Vw'])[eg[i]])} has copies in "
                f"different groups (vertices with equal positions must share one group)"
            )
        if Vw.shape != (k, 3):
            return f"Vw has shape {Vw.shape}, expected ({k}, 3): one vertex per group"
        Vi = np.asarray(expected["Vw"])[eg]
        off = np.linalg.norm(Vw[g] - Vi, axis=1)
        if off.max() > 1e-12:
            i = int(np.argmax(off))
            return f"Vw[group[{i}]] is {format_vec(Vw[g[i]])}, but vertex {i} is at {format_vec(Vi[i])}"
        eF = np.asarray(expected["Fw"])
        if Fw.ndim != 2 or Fw.shape[1:] != (3,) or Fw.dtype.kind not in "iu":
            return f"Fw should be an (m, 3) int array, got {Fw.dtype} {Fw.shape}"
        if Fw.size and (Fw.min() < 0 or Fw.max() >= k):
            return f"Fw holds index {int(Fw.max() if Fw.max() >= k else Fw.min())}, outside 0..{k - 1} (Fw = group[F])"
        # map the submitted labels onto the expected ones, then compare the faces in order
        to_e = np.empty(k, np.int64)
        to_e[pairs[:, 1]] = pairs[:, 0]
        if Fw.shape != eF.shape or not np.array_equal(to_e[Fw], eF):
            return f"Fw should be group[F] (same faces, same order): expected {len(eF)} faces, got {len(Fw)}, or other indices"
        return None

    return checks.Custom(compare)
