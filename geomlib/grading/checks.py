"""Comparisons between a submission's output and the expected output, with student-readable messages.

A check is called as ``check(expected, got, ctx)`` with two dicts of named outputs and a
:class:`Context`; it returns ``None`` when they agree and raises
:class:`~geomlib.grading.errors.Mismatch` otherwise. Every default tolerance comes from
:mod:`geomlib.grading.tolerances`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geomlib.errors import MeshError
from geomlib.grading import tolerances as tol
from geomlib.grading.context import Context
from geomlib.grading.errors import BadReturn

__all__ = [
    "Context",
    "Allclose",
    "Equal",
    "MeshMatch",
    "SurfaceDistance",
    "ImageMatch",
    "Custom",
    "All",
    "as_output_array",
    "nonfinite_problem",
    "format_vec",
]


def format_vec(x) -> str:
    x = np.atleast_1d(np.asarray(x))
    if x.dtype.kind in "iub":
        return "(" + ", ".join(str(int(v)) for v in x.ravel()) + ")"
    return "(" + ", ".join(f"{v:.6g}" for v in x.ravel()) + ")" if x.size > 1 else f"{x.ravel()[0]:.6g}"


def nonfinite_problem(name: str, expected, got) -> str | None:
    """Why ``got`` cannot match a real, finite ``expected`` (NaN, inf, complex, strings), or None.

    Every comparison calls this first: ``NaN > tol`` is False, so without it an output of NaNs of
    the right shape would pass any tolerance test.
    """
    e = np.asarray(expected)
    try:
        g = np.asarray(got)
    except Exception:  # noqa: BLE001 - odd objects are reported by the shape/type checks
        return None
    if e.dtype.kind not in "biuf":
        return None
    if g.dtype.kind == "c":
        return f"{name} holds complex numbers (dtype {g.dtype}); expected real values"
    if g.dtype.kind not in "biuf":
        return f"{name} is not an array of real numbers (dtype {g.dtype})"
    if g.dtype.kind != "f":
        return None
    bad = ~np.isfinite(g)
    if e.dtype.kind == "f" and e.shape == g.shape:
        bad &= np.isfinite(e)
    if not bad.any():
        return None
    where = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), g.shape) if g.ndim else ()
    at = f" (first at index {tuple(int(i) for i in where)})" if g.ndim else ""
    return (
        f"{name} contains NaN or inf where the expected values are finite{at}; "
        f"{int(bad.sum())} of {g.size} entries are not finite numbers"
    )


def as_output_array(value, name: str, ctx: Context, *, like: np.ndarray | None = None) -> np.ndarray:
    """Convert a submitted output to an array, failing with a message naming ``name``."""
    try:
        a = np.asarray(value)
    except Exception:
        raise BadReturn(f"{ctx.label}: {name} could not be read as an array (got {type(value).__name__})") from None
    if a.dtype == object:
        raise BadReturn(f"{ctx.label}: {name} is not a numeric array (got {type(value).__name__} of mixed objects)")
    if like is not None:
        if a.shape != like.shape:
            raise BadReturn(f"{ctx.label}: {name} has shape {a.shape}, expected {like.shape}")
        problem = nonfinite_problem(name, like, a)
        if problem:
            ctx.fail(problem)
    return a


def _pick(outputs: dict, names: str | tuple | None) -> list[str]:
    if names is None:
        return list(outputs)
    return [names] if isinstance(names, str) else list(names)


@dataclass
class Allclose:
    """Arrays equal element-wise within ``atol + rtol*|expected|``, in the given order.

    The message names the first differing row, both values, and how many rows differ.
    """

    output: str | tuple | None = None
    atol: float = tol.EXACT
    rtol: float = 0.0

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        for name in _pick(expected, self.output):
            e = np.asarray(expected[name])
            g = as_output_array(got.get(name), name, ctx, like=e)
            compare_arrays(name, e, g, ctx, atol=self.atol, rtol=self.rtol)


def compare_arrays(name: str, e: np.ndarray, g: np.ndarray, ctx: Context, *, atol: float, rtol: float = 0.0) -> None:
    if g.shape != e.shape:
        raise BadReturn(f"{ctx.label}: {name} has shape {g.shape}, expected {e.shape}")
    problem = nonfinite_problem(name, e, g)
    if problem:
        ctx.fail(problem)
    if e.size == 0:
        return
    e, g = np.atleast_1d(e), np.atleast_1d(g)  # a scalar output is reported as its one entry
    diff = np.abs(g.astype(np.float64) - e.astype(np.float64))
    bad = diff > atol + rtol * np.abs(e)
    if not bad.any():
        return
    rows = bad.reshape(len(e), -1).any(axis=1) if e.ndim > 1 else bad
    r = int(np.flatnonzero(rows)[0])
    what = "entries" if e.ndim == 1 else "rows"
    ctx.fail(
        f"{name}[{r}] expected {format_vec(e[r])}, got {format_vec(g[r])}; "
        f"{int(rows.sum())} of {len(e)} {what} off by more than {atol:g}"
    )


@dataclass
class Equal:
    """Exact equality (integer and boolean outputs)."""

    output: str | tuple | None = None

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        for name in _pick(expected, self.output):
            e = np.asarray(expected[name])
            g = as_output_array(got.get(name), name, ctx, like=e)
            if not np.array_equal(e, g):
                bad = (e != g).reshape(len(e), -1).any(axis=1) if e.ndim else np.array([True])
                r = int(np.flatnonzero(bad)[0])
                ctx.fail(
                    f"{name}[{r}] expected {format_vec(e[r])}, got {format_vec(g[r])}; {int(bad.sum())} of {len(e)} differ"
                )


def _canonical_faces(F: np.ndarray) -> np.ndarray:
    """Rotate each face so its smallest index comes first (orientation kept)."""
    k = F.shape[1]
    shift = np.argmin(F, axis=1)
    idx = (shift[:, None] + np.arange(k)[None, :]) % k
    return np.take_along_axis(F, idx, axis=1)


def _mesh_outputs(expected: dict, got: dict, vname: str, fname: str, ctx: Context):
    """Expected and submitted (V, F), the submitted ones checked for array shapes (n, 3) and (m, k)."""
    Ve, Fe = np.asarray(expected[vname], float), np.asarray(expected[fname])
    Vg = as_output_array(got.get(vname), vname, ctx)
    Fg = as_output_array(got.get(fname), fname, ctx)
    if Vg.ndim != 2 or Vg.shape[1] != Ve.shape[1]:
        raise BadReturn(f"{ctx.label}: {vname} has shape {Vg.shape}, expected (n, {Ve.shape[1]})")
    if Fg.ndim != 2 or Fg.shape[1] != Fe.shape[1]:
        raise BadReturn(f"{ctx.label}: {fname} has shape {Fg.shape}, expected (m, {Fe.shape[1]})")
    for n, e, g in ((vname, Ve, Vg), (fname, Fe, Fg)):
        problem = nonfinite_problem(n, e, g)
        if problem:
            ctx.fail(problem)
    if Fg.dtype.kind == "f":
        if not np.all(Fg == np.round(Fg)):
            ctx.fail(f"{fname} holds non-integer vertex indices")
        Fg = Fg.astype(np.int64)
    return Ve, Fe, Vg, Fg


@dataclass
class MeshMatch:
    """Same vertices and faces up to the order of vertices and faces (and cyclic order within a face).

    Vertices are matched to the nearest expected vertex (within ``atol``); faces are then compared
    as sets of oriented index cycles. A correct subdivision with another vertex numbering passes.
    """

    vertices: str = "V"
    faces: str = "F"
    atol: float = tol.GEOMETRY

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        from scipy.spatial import cKDTree

        Ve, Fe, Vg, Fg = _mesh_outputs(expected, got, self.vertices, self.faces, ctx)
        if len(Vg) != len(Ve):
            ctx.fail(f"expected {len(Ve)} vertices, got {len(Vg)}", self._picture(Ve, Fe, Vg, Fg, ctx))
        if len(Fg) != len(Fe):
            ctx.fail(f"expected {len(Fe)} faces, got {len(Fg)}", self._picture(Ve, Fe, Vg, Fg, ctx))
        if Fg.size and (Fg.min() < 0 or Fg.max() >= len(Vg)):
            ctx.fail(
                f"{self.faces} holds index {int(Fg.max() if Fg.max() >= len(Vg) else Fg.min())}, out of range for {len(Vg)} vertices"
            )
        if not np.all(np.isfinite(Vg)):
            r = int(np.flatnonzero(~np.isfinite(Vg).all(axis=1))[0])
            ctx.fail(f"{self.vertices}[{r}] is {format_vec(Vg[r])} (NaN or inf)")
        d, j = cKDTree(Vg).query(Ve)
        off = d > self.atol
        if off.any():
            i = int(np.flatnonzero(off)[0])
            ctx.fail(
                f"expected a vertex at {format_vec(Ve[i])}, nearest {ctx.got_name} vertex is {format_vec(Vg[j[i]])} "
                f"(distance {d[i]:.3g}); {int(off.sum())} of {len(Ve)} expected vertices have no match within {self.atol:g}",
                self._picture(Ve, Fe, Vg, Fg, ctx),
            )
        if len(np.unique(j)) != len(j):
            ctx.fail(
                f"several expected vertices match the same {ctx.got_name} vertex: {ctx.got_owner} has duplicate vertices"
            )
        to_expected = np.empty(len(Vg), dtype=np.int64)
        to_expected[j] = np.arange(len(Ve))
        Fm = _canonical_faces(to_expected[Fg.astype(np.int64)])
        Fc = _canonical_faces(Fe.astype(np.int64))
        ke = {tuple(f) for f in Fc.tolist()}
        kg = {tuple(f) for f in Fm.tolist()}
        if ke != kg:
            missing = sorted(ke - kg)
            # One array operation for all missing faces (a face at a time took seconds on a large mesh).
            reversed_faces = _canonical_faces(np.array(missing, dtype=np.int64)[:, ::-1])
            flipped = sum(1 for f in map(tuple, reversed_faces.tolist()) if f in kg)
            detail = f"{len(missing)} of {len(Fe)} expected faces are missing (e.g. vertices {format_vec(Ve[list(missing[0])][0])}, ...)"
            if flipped:
                detail += f"; {flipped} of them appear with reversed orientation (check the corner order)"
            ctx.fail(f"the vertices are right but the faces differ: {detail}", self._picture(Ve, Fe, Vg, Fg, ctx))

    def _picture(self, Ve, Fe, Vg, Fg, ctx: Context) -> str | None:
        from geomlib.grading import feedback

        return feedback.mesh_picture(ctx, Ve, Fe, Vg, Fg)


@dataclass
class SurfaceDistance:
    """Surfaces close as measured by Hausdorff, Chamfer or RMS distance relative to the bbox diagonal."""

    vertices: str = "V"
    faces: str = "F"
    metric: str = "hausdorff"
    rel_tol: float = tol.SURFACE_REL

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        from geomlib import geometry

        Ve, Fe, Vg, Fg = _mesh_outputs(expected, got, self.vertices, self.faces, ctx)
        try:
            dist = geometry.mesh_distance(Ve, Fe, Vg, Fg)
        except ValueError as e:
            ctx.fail(f"the {ctx.got_name} mesh is not valid ({e})")
        value = float(dist[self.metric])
        if value > self.rel_tol:
            ctx.fail(
                f"{self.metric} distance to the expected surface is {value:.3g} of the bbox diagonal, allowed {self.rel_tol:g}",
                self._picture(Ve, Fe, Vg, Fg, ctx),
            )

    def _picture(self, Ve, Fe, Vg, Fg, ctx):
        from geomlib.grading import feedback

        return feedback.mesh_picture(ctx, Ve, Fe, Vg, Fg)


@dataclass
class ImageMatch:
    """Images agree: at most ``max_bad_fraction`` of pixels differ by more than ``pixel_tol``
    (values scaled to [0, 1]); optionally a minimum PSNR."""

    output: str | None = None
    pixel_tol: float = tol.IMAGE_PIXEL
    max_bad_fraction: float = tol.IMAGE_BAD_FRACTION
    psnr: float | None = None

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        for name in _pick(expected, self.output):
            e = np.asarray(expected[name])
            g = as_output_array(got.get(name), name, ctx, like=e)
            scale = {"u": np.iinfo(e.dtype).max if e.dtype.kind == "u" else 1.0}.get(e.dtype.kind, 1.0)
            ef, gf = e.astype(np.float64) / scale, g.astype(np.float64) / scale
            diff = np.abs(ef - gf)
            per_pixel = diff.max(axis=2) if diff.ndim == 3 else diff
            bad = per_pixel > self.pixel_tol
            frac = float(bad.mean())
            if frac > self.max_bad_fraction:
                y, x = np.argwhere(bad)[0]
                from geomlib.grading import feedback

                pic = feedback.image_picture(ctx, ef, gf, per_pixel)
                ctx.fail(
                    f"{name}: {100 * frac:.2f}% of pixels differ by more than {self.pixel_tol:.3g} (allowed "
                    f"{100 * self.max_bad_fraction:.2f}%); first at row {y}, column {x}: expected "
                    f"{format_vec(ef[y, x])}, got {format_vec(gf[y, x])}",
                    pic,
                )
            if self.psnr is not None:
                mse = float(np.mean((ef - gf) ** 2))
                value = np.inf if mse == 0 else 10 * np.log10(1.0 / mse)
                if value < self.psnr:
                    ctx.fail(f"{name}: PSNR {value:.1f} dB, expected at least {self.psnr:g} dB")


@dataclass
class Custom:
    """Any comparison: ``fn(expected, got, ctx)`` raises via ``ctx.fail(...)`` or returns a failure string."""

    fn: Callable

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        try:
            msg = self.fn(expected, got, ctx)
        except MeshError as e:  # a degenerate submitted mesh (e.g. zero area) is the submission's fault
            ctx.fail(f"the submitted output is not a valid mesh ({e})")
        if msg:
            ctx.fail(str(msg))


@dataclass
class All:
    """Several checks in order; the first failure is reported."""

    checks: tuple

    def __init__(self, *checks):
        self.checks = checks

    def __call__(self, expected: dict, got: dict, ctx: Context) -> None:
        for c in self.checks:
            c(expected, got, ctx)
