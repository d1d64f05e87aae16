"""Benchmark: lab "relief" — a NumPy parallax-occlusion-mapping frame next to the same GLSL shader, in one run.

Run: ``uv run python bench/relief.py [--quick]``

Targets of the issue (this 2-core machine):

- A 512 x 512 POM frame with refinement (5 secant steps) and self-shadowing (32 layers) on a
  256 x 256 height map, in NumPy (``relief_uv`` + ``relief_shadow``), within 3x of the same
  shaders (``shaders/relief.frag`` + ``shaders/shadow.frag``) on llvmpipe through ``geomlib.gl``
  (context and programs warm; texture upload and float read-back included), i.e. about <= 0.25 s.
- uv error against the exact intersection (fine march + bisection), p99 in texels, per method
  and view angle (30/60/75 degrees from the normal), on smooth bumps and on bricks.

Times are the best of a few runs, the contenders interleaved (the machine is shared and noisy);
the NumPy CPU time (``time.process_time``) is printed next to its wall time. Peak memory is the
tracemalloc peak of one NumPy frame (NumPy allocations), in MiB.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bench.measure import peak_mib
from geomlib import gl
from solutions.relief import (
    REFINEMENTS,
    bricks,
    bumps,
    exact_uv,
    glsl_relief_shadow,
    glsl_relief_uv,
    parallax_uv,
    relief_shadow,
    relief_uv,
    uv_error_texels,
)

SCALE = 0.08
LIGHT = np.array([-0.5, 0.35, 0.6])


def pixel_uv(p: int) -> np.ndarray:
    t = (np.arange(p) + 0.5) / p
    return np.stack(np.meshgrid(t, t[::-1]), axis=-1)


def perspective_views(p: int, eye=(0.2, -0.9, 0.7)) -> np.ndarray:
    """Per-pixel view vectors towards an eye close to the quad: 35 to 75 degrees from the normal."""
    uv = pixel_uv(p)
    d = np.asarray(eye) - np.concatenate([uv, np.zeros((p, p, 1))], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def numpy_frame(H, uv, V):
    hit, depth, _ = relief_uv(H, uv, V, scale=SCALE, refine="secant", refine_steps=5)
    return hit, relief_shadow(H, hit, depth, LIGHT, scale=SCALE, layers=32)


def glsl_frame(H, uv, V):
    hit, depth, _ = glsl_relief_uv(H, uv, V, scale=SCALE, refine="secant", refine_steps=5)
    return hit, glsl_relief_shadow(H, hit, depth, LIGHT, scale=SCALE, layers=32)


def timing(p: int, repeat: int) -> None:
    H = bricks(256)
    uv, V = pixel_uv(p), perspective_views(p)
    info = gl.renderer_info()
    print(
        f"POM frame {p} x {p}, height map 256 x 256, secant x5 + shadow x32; GL: {info['renderer']} ({info['platform']})"
    )
    glsl_frame(H, uv, V)  # warm: context, shader compilation
    t_np, t_gl, cpu_np = [], [], []
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        hit_n, vis_n = numpy_frame(H, uv, V)
        t_np.append(time.perf_counter() - t0)
        cpu_np.append(time.process_time() - c0)
        t0 = time.perf_counter()
        hit_g, vis_g = glsl_frame(H, uv, V)
        t_gl.append(time.perf_counter() - t0)
    peak = peak_mib(lambda: numpy_frame(H, uv, V))
    i = int(np.argmin(t_np))
    err = uv_error_texels(hit_n, hit_g, 256)
    print(f"  NumPy  {min(t_np) * 1e3:7.1f} ms (CPU {cpu_np[i] * 1e3:.1f} ms), peak {peak:.0f} MiB")
    print(f"  GLSL   {min(t_gl) * 1e3:7.1f} ms (llvmpipe, upload + read-back included)")
    print(f"  ratio NumPy / GLSL = {min(t_np) / min(t_gl):.2f} (target <= 3)")
    print(
        f"  agreement: uv p99.9 {np.percentile(err, 99.9):.2g} texel, max {err.max():.2g}; "
        f"shadow pixels equal {100 * np.mean(vis_n == vis_g):.3f}%"
    )


def accuracy(p: int) -> None:
    uv = pixel_uv(p)
    print(f"\np99 uv error in texels against the exact intersection ({p} x {p} pixels, 256 x 256 map, scale {SCALE})")
    methods = ["parallax", "offset-limited", *REFINEMENTS]
    print(f"  {'map':7s} {'deg':>3s} " + " ".join(f"{m:>14s}" for m in methods))
    for name, H in (("bumps", bumps(256)), ("bricks", bricks(256))):
        for deg in (30, 60, 75):
            t = np.radians(deg)
            V = np.array([np.sin(t) * np.cos(0.3), np.sin(t) * np.sin(0.3), np.cos(t)])
            truth, _ = exact_uv(H, uv, V, scale=SCALE)
            res = [parallax_uv(H, uv, V, scale=SCALE), parallax_uv(H, uv, V, scale=SCALE, offset_limit=True)]
            res += [relief_uv(H, uv, V, scale=SCALE, refine=m)[0] for m in REFINEMENTS]
            errs = [np.percentile(uv_error_texels(x, truth, 256), 99) for x in res]
            print(f"  {name:7s} {deg:3d} " + " ".join(f"{e:14.3g}" for e in errs))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller frame and fewer repeats")
    args = ap.parse_args()
    timing(256 if args.quick else 512, 2 if args.quick else 5)
    accuracy(96 if args.quick else 256)


if __name__ == "__main__":
    main()
