"""Figures of the remeshing lab, rendered with the lab's own functions.

``make_figures(out_dir, lab=None, quick=False)`` writes the PNGs and returns
:class:`geomlib.plot.Figure` records; in ``labs/remeshing/`` it renders *your* results.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import numpy as np

from geomlib import datasets, topology
from geomlib.plot import Figure, figures_or_placeholders, line_plot, panels, save_png
from geomlib.render import render
from geomlib.viewer import write_html

__all__ = ["make_figures", "make_view"]

LAB = "remeshing"
#: valence colours: blue below 6, grey at 6, red above (4 on the boundary counts as regular)
LOW, SIX, HIGH = np.array([0.25, 0.45, 0.95]), np.array([0.82, 0.82, 0.82]), np.array([0.95, 0.3, 0.25])


def _lab(lab):
    if lab is not None:
        return lab
    return importlib.import_module(__package__)  # this package: the solution, or your lab in labs/


def valence_colors(V, F) -> np.ndarray:
    H = topology.halfedge_mesh(np.asarray(F), len(V))
    target = np.where(H.boundary_vertex, 4, 6)
    d = H.valence - target
    return np.where(d[:, None] < 0, LOW, np.where(d[:, None] > 0, HIGH, SIX))


def angles(V, F) -> np.ndarray:
    out = []
    for k in range(3):
        a, b = V[F[:, (k + 1) % 3]] - V[F[:, k]], V[F[:, (k + 2) % 3]] - V[F[:, k]]
        c = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        out.append(np.degrees(np.arccos(np.clip(c, -1, 1))))
    return np.concatenate(out)


def irregular_sphere():
    """A noisy icosphere made irregular by random vertex jitter in the tangent plane."""
    V, F = datasets.icosphere(3)
    rng = np.random.default_rng(0)
    V = V + 0.04 * rng.normal(size=V.shape)
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def fig_before_after(out: Path, lab, quick: bool) -> Figure:
    R = _lab(lab)
    V, F = irregular_sphere()
    L = 0.12
    U, G = R.isotropic_remesh(V, F, L, iterations=5 if quick else 10)
    U, G = np.asarray(U), np.asarray(G)
    size = (260, 220) if quick else (360, 300)
    kw = dict(camera="three_quarter", size=size, supersample=1 if quick else 2, wireframe=True, flat=True)
    imgs, caps = [], []
    hx, hy, labels = [], [], []
    for title, (X, T) in (("input", (V, F)), (f"remeshed, L = {L}", (U, G))):
        a = angles(X, T)
        h = np.mean(valence_colors(X, T) == SIX, axis=1).mean()
        imgs.append(render(X, T, colors=valence_colors(X, T), **kw))
        caps.append(f"{title}: {len(T)} faces, min angle {a.min():.1f}°, valence 6: {h:.0%}")
        counts, edges = np.histogram(a, bins=36, range=(0, 180))
        hx.append(0.5 * (edges[1:] + edges[:-1]))
        hy.append(counts / counts.sum())
        labels.append(title)
    imgs.append(
        line_plot(
            hx,
            hy,
            labels,
            xlabel="corner angle (degrees)",
            ylabel="share of angles",
            title="angle histograms (60° = equilateral)",
            size=(size[0] + 80, size[1]),
            markers=False,
        )
    )
    caps.append("angles cluster at 60° after remeshing")
    img = panels(imgs, caps, title="Isotropic remeshing: valence blue < 6, grey = 6, red > 6")
    path = save_png(out / "before_after.png", img)
    return Figure(
        path,
        "An irregular sphere before and after isotropic_remesh, vertices coloured by valence (blue below 6, grey 6, "
        "red above); the captions print the minimum angle and the valence-6 share, the plot the angle histograms.",
        LAB,
    )


def fig_operations(out: Path, lab, quick: bool) -> Figure:
    R = _lab(lab)
    V, F = datasets.grid_patch(3)
    H = topology.halfedge_mesh(F, len(V), manifold=True)
    inner = np.flatnonzero(~H.boundary_edge)
    e = int(inner[len(inner) // 2])
    size = (200, 200) if quick else (260, 260)
    kw = dict(camera="top", size=size, supersample=1 if quick else 2, wireframe=True, flat=True)
    missing: list[NotImplementedError] = []  # tasks whose panels are left blank
    imgs, caps = (
        [render(V, F, highlight_points=H.E[e], **kw)],
        [f"patch, edge ({int(H.E[e, 0])}, {int(H.E[e, 1])}) marked"],
    )
    for name, op in (("split_edge", R.split_edge), ("collapse_edge", R.collapse_edge), ("flip_edge", R.flip_edge)):
        try:
            U, H2 = op(V, H, e)
            G = np.asarray(H2.idx).reshape(-1, 3)
            imgs.append(render(np.asarray(U), G, **kw))
            caps.append(f"{name}: {len(G)} faces")
        except NotImplementedError as err:
            missing.append(err)
            imgs.append(np.full((size[1], size[0], 3), 255, np.uint8))
            caps.append(f"{name}: not implemented yet")
    try:
        J = V + 0.08 * np.random.default_rng(1).normal(size=V.shape) * [1, 1, 0] * ~H.boundary_vertex[:, None]
        W = np.asarray(R.tangential_relaxation(J, F))
        imgs[-1:-1] = []
        imgs.append(render(J, F, **kw))
        caps.append("interior vertices jittered")
        imgs.append(render(W, F, **kw))
        caps.append("after tangential_relaxation")
    except NotImplementedError as err:
        missing.append(err)
        imgs.append(np.full((size[1], size[0], 3), 255, np.uint8))
        caps.append("tangential_relaxation: not implemented yet")
    img = panels(imgs, caps, title="The local operations on a 4 x 4 patch", ncols=3)
    path = save_png(out / "operations.png", img)
    first = re.search(r"Task \d+[a-z]?", str(missing[0])) if missing else None
    todo = f"{first.group(0) if first else 'A task'} not implemented yet; the other panels show: " if missing else ""
    return Figure(
        path,
        todo
        + "One interior edge of a grid patch (marked) split, collapsed and flipped; a patch with jittered interior "
        "vertices before and after one tangential relaxation step (damping 0.5).",
        LAB,
    )


def make_figures(out_dir, lab=None, quick: bool = False) -> list[Figure]:
    """Render the lab's figures into ``out_dir`` (``lab``: a lab module, default this package).

    A figure whose task is not implemented yet becomes a "Task N not implemented yet" picture.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return figures_or_placeholders((fig_before_after, fig_operations), out, LAB, lab, quick)


def fig_view(out: Path, lab, quick: bool) -> Figure:
    R = _lab(lab)
    V, F = irregular_sphere()
    U, G = R.isotropic_remesh(V, F, 0.12, iterations=5 if quick else 10)
    U, G = np.asarray(U, float), np.asarray(G)
    H = topology.halfedge_mesh(G, len(U))
    dev = np.abs(H.valence - np.where(H.boundary_vertex, 4, 6)).astype(float)
    path = write_html(
        out / "remeshing_3d.html", U, G, dev, title="Remeshed sphere (L = 0.12)",
        cmap="viridis", scalar_name="|valence - 6|",
    )  # fmt: skip
    return Figure(
        path,
        "Turn it: the jittered sphere after isotropic remeshing to L = 0.12, each vertex coloured by how far its "
        "valence is from 6 (0: regular).",
        LAB,
    )


fig_before_after.figure_name = "before_after"
fig_operations.figure_name = "operations"
fig_view.figure_name = "remeshing_3d"


def make_view(out_dir, lab=None, quick: bool = False) -> Figure:
    """Write the lab's interactive 3D view, ``remeshing_3d.html`` (:mod:`geomlib.viewer`), into ``out_dir``.

    Same arguments as :func:`make_figures`; before the loop (Task 10) is implemented, the returned
    figure is a "Task N not implemented yet" picture instead.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return figures_or_placeholders((fig_view,), out, LAB, lab, quick)[0]
