"""Inputs and checks shared by the graded tests of the lab "shadows" (built from geomlib only).

The scenes and light matrices here never call the lab: light matrices are made directly with
:mod:`geomlib.camera`, so a case about the depth pass does not depend on Task 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib import camera, datasets, portable
from geomlib.grading.checks import Context, as_output_array, format_vec
from geomlib.grading.errors import Mismatch
from geomlib.grading.feedback import failure_picture

from .. import common

# --------------------------------------------------------------------------------- scenes


def box(size, centre, n: int = 1):
    V, F = datasets.sharp_box(size, n=n)
    return V + np.asarray(centre, float), F


def floor(half: float = 3.0, n: int = 4):
    V, F = datasets.grid_patch(n, 2 * half)
    return V - np.array([half, half, 0.0]), F


def concat(*meshes):
    Vs, Fs, off = [], [], 0
    for V, F in meshes:
        Vs.append(V)
        Fs.append(F + off)
        off += len(V)
    return np.vstack(Vs), np.vstack(Fs)


def small_scene():
    """A floor, a box standing on it, a floating box and a sphere resting on it (z up), 376 faces."""
    S, SF = datasets.icosphere(2, radius=0.5)
    return concat(
        floor(),
        box((1.0, 1.0, 1.0), (1.0, -0.6, 0.5)),
        box((0.6, 0.6, 0.6), (-1.2, -0.8, 1.6)),
        (S + np.array([-0.4, 1.0, 0.5]), SF),
    )


def scene_meshes():
    """The same scene as the list of ``(V, F, color[, smooth])`` meshes that ``render_with_shadows`` takes."""
    S, SF = datasets.icosphere(2, radius=0.5)
    return [
        (*floor(), (0.86, 0.86, 0.82)),
        (*box((1.0, 1.0, 1.0), (1.0, -0.6, 0.5)), (0.85, 0.45, 0.30)),
        (*box((0.6, 0.6, 0.6), (-1.2, -0.8, 1.6)), (0.45, 0.75, 0.45)),
        (S + np.array([-0.4, 1.0, 0.5]), SF, (0.90, 0.80, 0.35), True),
    ]


SCENE_BOUNDS = np.array([[-3.0, -3.0, 0.0], [3.0, 3.0, 1.9]])
CAMERA = (np.array([3.9, -4.8, 3.4]), np.array([-0.2, 0.3, 0.4]), np.array([0.0, 0.0, 1.0]))


def ortho_light(direction=(0.4, 0.5, -0.75), bounds=SCENE_BOUNDS, up=None) -> np.ndarray:
    """An orthographic light-space matrix made with geomlib.camera (not with the lab): a loose box."""
    d = np.asarray(direction, float) / portable.norm(direction)  # portable: no BLAS in case inputs
    B = np.asarray(bounds, float)
    c, R = B.mean(0), 0.5 * portable.norm(B[1] - B[0])
    up = np.eye(3)[np.argmin(np.abs(d))] if up is None else up
    return portable.matmul(camera.orthographic(-R, R, -R, R, 0.0, 2 * R), camera.look_at(c - R * d, c, up))


def spot_light(position=(-3.0, -3.5, 5.0), target=(0.0, 0.0, 0.0), fov=70.0, near=2.0, far=12.0) -> np.ndarray:
    p, t = np.asarray(position, float), np.asarray(target, float)
    return portable.matmul(
        camera.perspective(fov, 1.0, near, far), camera.look_at(p, t, np.eye(3)[np.argmin(np.abs(t - p))])
    )


def surface_points(V, F, n: int, seed: int):
    """Random points on the faces that face +z or the light, with their unit face normals."""
    rng = np.random.default_rng(seed)
    f = rng.integers(0, len(F), n)
    b = rng.dirichlet(np.ones(3), n)
    T = V[F[f]]
    P = b[:, 0, None] * T[:, 0] + b[:, 1, None] * T[:, 1] + b[:, 2, None] * T[:, 2]  # not einsum: no FMA
    N = np.cross(V[F[f, 1]] - V[F[f, 0]], V[F[f, 2]] - V[F[f, 0]])
    return P, N / np.linalg.norm(N, axis=1, keepdims=True)


# --------------------------------------------------------------------------------- checks


@dataclass
class MapClose:
    """Depth maps or images equal within ``atol`` per texel (at most ``max_bad`` texels may differ).

    The message names the first bad texel by (row, column); the feedback picture shows expected,
    submitted and their difference.
    """

    output: str
    atol: float = 1e-9
    max_bad: float = 0.0

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output], float)
        g = as_output_array(got.get(self.output), self.output, ctx, like=e).astype(float)
        per = np.abs(g - e)
        if per.ndim == 3:
            per = per.max(axis=2)
        bad = per > self.atol
        if bad.mean() <= self.max_bad:
            return
        r, c = (int(i) for i in np.argwhere(bad)[0])
        hint = ""
        if np.allclose(g, e[::-1], atol=self.atol):
            hint = " (your map is upside down: row 0 is the TOP of the map, v = 1)"
        elif e.ndim == 2 and np.allclose(g, e.T, atol=self.atol):
            hint = " (your map is transposed: rows go with v, columns with u)"
        ctx.fail(
            f"{self.output}[{r}, {c}] expected {format_vec(e[r, c])}, got {format_vec(g[r, c])}; "
            f"{int(bad.sum())} of {bad.size} texels differ by more than {self.atol:g}{hint}",
            self._picture(e, g, per, ctx),
        )

    def _picture(self, e, g, per, ctx):
        from geomlib.grading import feedback

        k = max(1, 160 // min(per.shape))

        def show(x):
            return np.repeat(np.repeat(np.clip(x, 0, 1), k, axis=0), k, axis=1)

        return feedback.image_picture(ctx, show(e), show(g), np.repeat(np.repeat(per, k, axis=0), k, axis=1))


@dataclass
class SameRows(common.SameRows):
    """The same set of faces as expected, in any order (each face's corner order counts)."""

    missing: str = "expected faces are missing"
    extra: str = "faces should have been culled"


@dataclass
class NanClose:
    """Arrays equal within ``atol`` where finite, with NaN in exactly the same places."""

    output: str
    atol: float = 1e-10

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        e = np.asarray(expected[self.output], float)
        try:
            g = np.asarray(got.get(self.output), float)
        except (TypeError, ValueError):
            ctx.fail(f"{self.output} is not a numeric array")
        if g.shape != e.shape:
            ctx.fail(f"{self.output} has shape {g.shape}, expected {e.shape}")
        ne, ng = np.isnan(e).any(axis=-1), np.isnan(g).any(axis=-1)
        if (ne != ng).any():
            r = int(np.flatnonzero(ne != ng)[0])
            ctx.fail(
                f"{self.output}[{r}] expected {format_vec(e[r])}, got {format_vec(g[r])} (NaN exactly where w <= 0)"
            )
        ok = ~ne
        diff = np.abs(g[ok] - e[ok]).max(axis=-1) if ok.any() else np.zeros(0)
        if (diff > self.atol).any():
            r = int(np.flatnonzero(ok)[np.flatnonzero(diff > self.atol)[0]])
            ctx.fail(
                f"{self.output}[{r}] expected {format_vec(e[r])}, got {format_vec(g[r])}; "
                f"{int((diff > self.atol).sum())} of {len(e)} rows off by more than {self.atol:g}"
            )


# --------------------------------------------------------------------------------- GLSL routes


#: What :func:`gpu_array` says when per-point visibilities come back in another shape.
VISIBILITY_SHAPES = "the result has shape {got}, expected one visibility per point {expected}"


def gpu_array(label: str, got, expected: np.ndarray, shapes: str) -> np.ndarray:
    """A GLSL route's result ``got`` as a float array shaped like ``expected``; otherwise a
    :class:`Mismatch` that starts with ``label`` and says ``shapes`` (formatted with the shapes
    ``got`` and ``expected``)."""
    try:
        g = np.asarray(got, float)
    except (TypeError, ValueError):
        raise Mismatch(f"{label}: the result is not a numeric array") from None
    if g.shape != expected.shape:
        raise Mismatch(f"{label}: " + shapes.format(got=g.shape, expected=expected.shape))
    return g


def visibility_picture(label: str, mask: np.ndarray, got: np.ndarray, expected: np.ndarray, atol: float):
    """The failure picture of per-point visibilities laid out on the pixels ``mask`` (1, lit, elsewhere)."""
    img_e, img_g = np.ones(mask.shape), np.ones(mask.shape)
    img_e[mask], img_g[mask] = expected, got
    return failure_picture(label, img_g, img_e, name="visibility", atol=atol)
