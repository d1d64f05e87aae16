"""Graded cases of the lab "vdm": inputs built from geomlib, never by solution code in this file.

Every task is graded on its own: a task's inputs never come from the student's output of another
task. Where a task needs an earlier task's result (the open box's square parameterization, a
mesh's sharp edges and corners) it is the solution's, stored by ``geomlib refs build`` (``STORED``)
and read back with ``stored_input``; other uv coordinates come from the meshes' own grids, grids
from closed-form warps.

Tolerances: parameterizations 1e-8 (one sparse solve); sampling, naive VDMs, importances and
fields 1e-10 (arithmetic); the transport grid 1e-6 (a few hundred FFTs and Legendre transforms,
whose maxima are continuous in the input, so round-off stays small); aligned grids 1e-9 (exact
crossing points); sharp features and diagonal choices exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib import datasets, portable
from geomlib.grading import Case, checks
from geomlib.grading.cases import stored_input
from geomlib.grading.checks import Context, as_output_array, format_vec

from .. import common

# ------------------------------------------------------------------------------------- checks


@dataclass
class SameRows(common.SameRows):
    """The same set of rows (edges as unordered vertex pairs, corners), in any order."""

    sort_within: bool = True


@dataclass
class TexelClose:
    """Images and grids ``(h, w)`` or ``(h, w, c)`` equal within ``atol``; the message names the first bad ``[i, j]``."""

    output: str
    atol: float

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output], dtype=np.float64)
        g = as_output_array(got.get(self.output), self.output, ctx, like=e).astype(np.float64)
        message = texel_mismatch(self.output, g, e, self.atol)
        if message:
            ctx.fail(message)


def texel_mismatch(name: str, g: np.ndarray, e: np.ndarray, atol: float) -> str | None:
    """None when ``g`` matches ``e`` texel by texel, else a message naming the first bad texel."""
    if g.shape != e.shape:
        return f"{name} has shape {g.shape}, expected {e.shape}"
    diff = np.abs(g - e)
    per = diff.max(axis=tuple(range(2, e.ndim))) if e.ndim > 2 else diff
    bad = ~(per <= atol)  # NaN counts as bad
    if not bad.any():
        return None
    i, j = (int(k) for k in np.argwhere(bad)[0])
    return (
        f"{name}[{i}, {j}] expected {format_vec(e[i, j])}, got {format_vec(g[i, j])}; "
        f"{int(bad.sum())} of {bad.size} entries [i, j] differ by more than {atol:g}"
    )


# ------------------------------------------------------------------------------------- inputs


def open_box(n: int = 4, size=(1.0, 1.0, 0.5)) -> tuple[np.ndarray, np.ndarray]:
    """``datasets.sharp_box`` without its bottom faces, moved to ``[0, sx] x [0, sy] x [0, sz]``."""
    s = np.asarray(size, float)
    V, F = datasets.sharp_box(s, n)
    low = np.isclose(V[:, 2], V[:, 2].min())
    F = F[~low[F].all(axis=1)]
    used = np.unique(F)
    remap = np.full(len(V), -1)
    remap[used] = np.arange(len(used))
    return V[used] + s / 2, remap[F]


def uv_entry(n: int) -> Case:
    """The open box's harmonic square parameterization (Task 1's output), stored for the later tasks' inputs."""
    return Case(id=f"uv-box-{n}", function="parameterize_square", inputs=lambda: dict(zip(("V", "F"), open_box(n), strict=True)),
                params={"method": "harmonic"}, outputs=("UV",), check=checks.Allclose(atol=1e-8), part="stored input",
                points=0)  # fmt: skip


def box_with_uv(n: int = 8) -> dict:
    V, F = open_box(n)
    return {"V": V, "F": F, "UV": stored_input("vdm", f"uv-box-{n}")["UV"]}


def rock_with_uv(n: int = 16, seed: int = 0) -> dict:
    """The rock displaces the vertices of grid_patch(n): the grid's xy is a valid parameterization."""
    V, F = datasets.rock_on_plinth(n, seed=seed)
    Vg, _ = datasets.grid_patch(n)
    return {"V": V, "F": F, "UV": Vg[:, :2].copy()}


def height_field_with_uv(n: int = 12) -> dict:
    V, F = datasets.height_field(n)
    return {"V": V, "F": F, "UV": V[:, :2].copy()}


def uv_points(k: int, seed: int, outside: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    X = rng.random((k, 2))
    if outside:  # a few points outside the square: the nearest point of the domain is sampled
        X = np.r_[X, [[-0.2, 0.37], [1.3, 0.81], [0.44, -0.05], [1.2, 1.4]]]
    return X


def uniform(res: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, res)
    v, u = np.meshgrid(t, t, indexing="ij")
    return np.stack([u, v], axis=-1)


def warped(res: int, amount: float = 0.04) -> np.ndarray:
    """A smooth, unfolded warp of the uniform grid that keeps the boundary on the square's edges."""
    G = uniform(res)
    u, v = G[..., 0], G[..., 1]
    du = amount * portable.sin(np.pi * u) * portable.sin(2 * np.pi * v)
    dv = amount * portable.sin(2 * np.pi * u) * portable.sin(np.pi * v)
    return np.stack([u + du, v + dv], axis=-1)


def pixel_centres(n: int) -> tuple[np.ndarray, np.ndarray]:
    c = np.arange(0.5, n) / n  # pixel centres
    v, u = np.meshgrid(c, c, indexing="ij")
    return u, v


def blob_field(n: int, centre=(0.3, 0.6), width: float = 0.08, background: float = 0.1) -> np.ndarray:
    u, v = pixel_centres(n)
    return background + portable.exp(-((u - centre[0]) ** 2 + (v - centre[1]) ** 2) / (2 * width**2))


def line_field(n: int) -> np.ndarray:
    u, v = pixel_centres(n)
    return 0.05 + 0.5 * portable.exp(-((u + v - 1.2) ** 2 / 2) / (2 * 0.04**2))


def random_splats(k: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    return {"UV": rng.random((k, 2)), "I": np.where(rng.random(k) < 0.3, 0.0, rng.random(k))}


def sharp_inputs(mesh: str) -> dict:
    if mesh == "box":
        d = box_with_uv(8)
    elif mesh == "box4":
        d = box_with_uv(4)
    elif mesh == "rock":
        d = rock_with_uv(16)
    else:
        d = height_field_with_uv(16)
    return d


def features_entry(mesh: str, visibility: str = "visible") -> Case:
    """A mesh's sharp edges and corners (Task 7a's output), stored by `geomlib refs build` for the alignment cases."""
    return Case(id=f"features-{mesh}", function="sharp_features", inputs=lambda: {k: v for k, v in sharp_inputs(mesh).items() if k != "UV"},
                params={"angle": 30.0}, outputs=("edges", "corners"), check=checks.Equal(), part="stored input",
                points=0, visibility=visibility)  # fmt: skip


def align_inputs(mesh: str, grid: np.ndarray) -> dict:
    """Mesh, uv, grid and the mesh's sharp edges and corners (the solution's, stored: see STORED)."""
    features = stored_input("vdm", f"features-{mesh}")
    return {**sharp_inputs(mesh), "grid_uv": grid, "edges": features["edges"], "corners": features["corners"]}


def half_step_inputs(n: int = 16) -> dict:
    """Potentials and densities for one back-and-forth half step (phi convex, rho - target with mean 0)."""
    u, v = pixel_centres(n)
    phi = 0.5 * (u**2 + v**2) + 0.01 * u * v
    target = blob_field(n)
    target *= n * n / target.sum()
    rho = np.ones((n, n))
    return {"phi": phi, "rho": rho, "target": target, "sigma": 0.5}


# ------------------------------------------------------------------------------------- cases

UV_HINT = "map each side of the boundary by arc length, then solve L u = 0 for the interior with the boundary fixed"

# What a case needs from an earlier task (a parameterization, sharp features) is stored by
# `geomlib refs build` from the solution and read back with `stored_input`, never computed here.
STORED = [uv_entry(4), uv_entry(6), uv_entry(8), features_entry("box"), features_entry("rock")]

CASES = [
    # ----------------------------------------------------------------------- Task 1
    Case(
        id="param-harmonic-box",
        function="parameterize_square",
        inputs=lambda: dict(zip(("V", "F"), open_box(4), strict=True)),
        params={"method": "harmonic"},
        outputs=("UV",),
        check=checks.Allclose(atol=1e-8),
        part="parameterization",
        points=2,
        hint=UV_HINT + " (cotangent weights: igl.harmonic with k = 1)",
    ),
    Case(
        id="param-tutte-rock",
        function="parameterize_square",
        inputs=lambda: {k: v for k, v in rock_with_uv(16).items() if k != "UV"},
        params={"method": "tutte"},
        outputs=("UV",),
        check=checks.Allclose(atol=1e-8),
        part="parameterization",
        points=1,
        hint="Tutte: every interior vertex at the plain mean of its neighbours (uniform Laplacian)",
    ),
    Case(
        id="param-lscm-heightfield",
        function="parameterize_square",
        inputs=lambda: {k: v for k, v in height_field_with_uv(8).items() if k != "UV"},
        params={"method": "lscm"},
        outputs=("UV",),
        check=checks.Allclose(atol=1e-8),
        part="parameterization",
        points=1,
        hint="lscm uses the given helper _lscm_sliding with the boundary you computed",
    ),
    # ----------------------------------------------------------------------- Task 2
    Case(
        id="sample-rock",
        function="sample_surface",
        inputs=lambda: {**rock_with_uv(16), "uv_points": uv_points(400, 1)},
        outputs=("P",),
        check=checks.Allclose(atol=1e-10),
        part="sampling",
        points=2,
        hint="find the uv triangle containing each point, then P = sum of barycentric weights times the 3-D corners; "
        "outside the domain use the nearest point of the nearest triangle",
    ),
    Case(
        id="sample-box-grid",
        function="sample_surface",
        inputs=lambda: {**box_with_uv(6), "uv_points": uniform(9)},
        outputs=("P",),
        check=TexelClose("P", atol=1e-10),
        part="sampling",
        points=1,
        hint="uv_points may have any leading shape; return the same leading shape with 3 at the end",
    ),
    # ----------------------------------------------------------------------- Task 3
    Case(
        id="naive-heightfield-9",
        function="naive_vdm",
        inputs=lambda: height_field_with_uv(12),
        params={"res": 9},
        outputs=("D",),
        check=TexelClose("D", atol=1e-10),
        part="naive VDM",
        points=1,
        hint="D[i, j] = p(uv = (j, i) / (res - 1)) - (j / (res - 1), i / (res - 1), 0): row i is v",
    ),
    Case(
        id="naive-box-12",
        function="naive_vdm",
        inputs=lambda: box_with_uv(6),
        params={"res": 12},
        outputs=("D",),
        check=TexelClose("D", atol=1e-10),
        part="naive VDM",
        points=1,
        hint="D[i, j] = p(uv = (j, i) / (res - 1)) - (j / (res - 1), i / (res - 1), 0): row i is v",
    ),
    Case(
        id="naive-rock-warped-grid",
        function="naive_vdm",
        inputs=lambda: {**rock_with_uv(16), "grid_uv": warped(10)},
        params={"res": 10},
        outputs=("D",),
        check=TexelClose("D", atol=1e-10),
        part="naive VDM",
        points=1,
        hint="with grid_uv given, sample there but subtract the *uniform* flat-grid position p_o",
    ),
    # ----------------------------------------------------------------------- Task 4
    Case(
        id="importance-box",
        function="vertex_importance",
        inputs=lambda: dict(zip(("V", "F"), open_box(4), strict=True)),
        outputs=("I",),
        check=checks.Allclose(atol=1e-12),
        part="importance",
        points=1,
        hint="I(v) = max over INTERIOR edges at v of 0.5 - 0.5 n1.n2 (unit face normals); 0 without interior edges",
    ),
    Case(
        id="importance-rock",
        function="vertex_importance",
        inputs=lambda: {k: v for k, v in rock_with_uv(24).items() if k != "UV"},
        outputs=("I",),
        check=checks.Allclose(atol=1e-12),
        part="importance",
        points=1,
        hint="take the maximum over the edges, not the sum or the mean",
    ),
    # ----------------------------------------------------------------------- Task 5
    Case(
        id="field-random-splats",
        function="importance_field",
        inputs=lambda: random_splats(60, 2),
        params={"res": 32, "background": 0.1, "sigma": 0.05},
        outputs=("field",),
        check=TexelClose("field", atol=1e-12),
        part="field",
        points=2,
        hint="pixel (i, j) is centred at ((j + .5) / res, (i + .5) / res); keep the max over vertices, cut at 3 sigma",
    ),
    Case(
        id="field-density",
        function="importance_field",
        inputs=lambda: {**random_splats(25, 3), "density": 0.5 + blob_field(16)},
        params={"res": 16, "background": 0.3},
        outputs=("field",),
        check=TexelClose("field", atol=1e-12),
        part="field",
        points=1,
        hint="the background is multiplied by density; sigma defaults to 1.5 / res",
    ),
    # ----------------------------------------------------------------------- Task 6
    Case(
        id="bfm-half-step",
        function="bfm_half_step",
        inputs=half_step_inputs,
        outputs=("phi", "psi", "grad_sq"),
        check=checks.Allclose(atol=1e-10),
        part="transport grid",
        points=1,
        hint="w = inverse_neg_laplacian(rho - target); phi += sigma w; psi = legendre_transform(phi); "
        "phi = legendre_transform(psi); grad_sq = mean(w (rho - target))",
    ),
    Case(
        id="transport-blob-16",
        function="transport_grid",
        inputs=lambda: {"field": blob_field(32)},
        params={"res": 16},
        outputs=("grid_uv",),
        check=TexelClose("grid_uv", atol=1e-6),
        part="transport grid",
        points=2,
        hint="evaluate soft_legendre_map(phi, t, t, smoothing / n^2) at t = linspace(0, 1, res), subtract the same map "
        "of the identity potential, then pin the boundary",
    ),
    Case(
        id="transport-line-fixed",
        function="transport_grid",
        inputs=lambda: {"field": line_field(32)},
        params={"res": 12, "boundary": "fixed"},
        outputs=("grid_uv",),
        check=TexelClose("grid_uv", atol=1e-6),
        part="transport grid",
        points=1,
        hint="boundary='fixed': subtract the harmonic extension of the boundary offsets (_harmonic_extension)",
    ),
    # ----------------------------------------------------------------------- Task 7
    Case(
        id="sharp-box",
        function="sharp_features",
        inputs=lambda: dict(zip(("V", "F"), open_box(4), strict=True)),
        outputs=("edges", "corners"),
        check=checks.All(SameRows("edges"), SameRows("corners")),
        part="alignment",
        points=1,
        hint="sharp edge: interior edge with dihedral angle > angle (degrees); corner: vertex on MORE than two sharp edges",
    ),
    Case(
        id="sharp-rock-40",
        function="sharp_features",
        inputs=lambda: {k: v for k, v in rock_with_uv(24).items() if k != "UV"},
        params={"angle": 40.0},
        outputs=("edges", "corners"),
        check=checks.All(SameRows("edges"), SameRows("corners")),
        part="alignment",
        points=1,
        hint="compare the angle between the two face normals with the threshold converted to radians",
    ),
    Case(
        id="align-box-warped-16",
        function="align_to_features",
        inputs=lambda: align_inputs("box", warped(16)),
        outputs=("grid_uv",),
        check=TexelClose("grid_uv", atol=1e-9),
        part="alignment",
        points=2,
        hint="corners first (nearest grid vertex), then per colour (i % 2, j % 2) the nearer end of each crossed grid "
        "edge onto the crossing; skip folding moves; move each vertex at most once",
    ),
    Case(
        id="align-rock-uniform-20",
        function="align_to_features",
        inputs=lambda: align_inputs("rock", uniform(20)),
        outputs=("grid_uv",),
        check=TexelClose("grid_uv", atol=1e-9),
        part="alignment",
        points=1,
        hint="boundary grid vertices may only slide along their own edge; the square's corners never move",
    ),
    # ----------------------------------------------------------------------- Task 8
    Case(
        id="diagonals-box-17",
        function="choose_diagonals",
        inputs=lambda: {k: v for k, v in align_inputs("box", uniform(17)).items() if k not in ("corners",)},
        outputs=("diagonals",),
        check=checks.Equal(),
        part="diagonals",
        points=2,
        hint="only cells crossed by a sharp edge change; there pick the split whose flat-triangle samples are closer "
        "to the mesh (sum of squared closest-point distances)",
    ),
    Case(
        id="diagonals-rock-warped-14",
        function="choose_diagonals",
        inputs=lambda: {k: v for k, v in align_inputs("rock", warped(14)).items() if k not in ("corners",)},
        params={"default": False},
        outputs=("diagonals",),
        check=checks.Equal(),
        part="diagonals",
        points=1,
        hint="cells no sharp edge crosses keep `default` (unless only the other split has two positive triangles)",
    ),
    # ----------------------------------------------------------------------- the whole bake (given code)
    Case(
        id="bake-box-6-12",
        function="bake_vdm",
        inputs=lambda: dict(zip(("V", "F"), open_box(6), strict=True)),
        params={"res": 12},
        outputs=("displacement", "grid_uv", "diagonals"),  # fields of the returned VDM
        check=checks.All(
            TexelClose("grid_uv", atol=1e-6), TexelClose("displacement", atol=1e-6), checks.Equal("diagonals")
        ),
        part="whole bake",
        points=0,  # scores nothing of its own (Tasks 1-8 are graded); here to name the wrong task in a wrong bake
        hint="bake_vdm is given: it chains Tasks 1-8, so a wrong bake comes from one of them",
    ),
]
