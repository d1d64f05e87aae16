"""Figures of the simplification lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The
file is copied into ``labs/simplification/`` with the stubs, so there it renders *your* results:
run ``make_figures`` once your functions work and compare with ``docs/figures/simplification/``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import datasets, topology
from geomlib.geometry import closest_points, mesh_distance
from geomlib.labfigures import Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import colorbar, heat_colors, line_plot, panels
from geomlib.render import render

__all__ = ["make_figures", "make_view", "airplane", "cracked_sheet"]

LAB = "simplification"
CMAP = "YlOrRd"  # light at zero, so the shape stays readable where the error vanishes


def _simplify(lab):
    """``qem_simplify`` of the lab module the figures draw."""
    return lab.qem_simplify


def _ss(quick: bool) -> int:
    return 1 if quick else 2


def airplane() -> tuple[np.ndarray, np.ndarray]:
    """The pyvista airplane made manifold (stray triangle dropped, pinch vertices split)."""
    return datasets.pyvista_mesh("airplane", manifold=True)


def cracked_sheet(n: int = 12, gap: float = 0.03) -> tuple[np.ndarray, np.ndarray]:
    """Two wavy sheets side by side with a straight crack of width ``gap`` between them."""
    V1, F1 = datasets.grid_patch(n)
    V1[:, 2] = 0.12 * np.sin(3 * V1[:, 0]) * np.cos(2.5 * V1[:, 1])
    V2 = V1.copy()
    V2[:, 0] += 1.0 + gap
    V2[:, 2] = 0.12 * np.sin(3 * V2[:, 0]) * np.cos(2.5 * V2[:, 1])
    return np.r_[V1, V2], np.r_[F1, F1 + len(V1)]


@figure_name("series")
def fig_series(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    V, F = airplane()
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    fractions = (0.5, 0.1, 0.02)
    results = [qem_simplify(V, F, max(4, round(f * len(F)))) for f in fractions]
    # error of every input vertex: its distance to the simplified surface, in % of the diagonal
    errors = [100 * np.sqrt(closest_points(U, G, V)[0]) / diag for U, G in results]
    vmax = float(errors[-1].max())  # the largest error shown anywhere: the bar ends at the stated max
    size = (300, 220) if quick else (420, 300)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), zoom=0.95)
    top = [render(V, F, wireframe=True, edge_width=0.6, **kw)]
    top += [render(np.asarray(U), np.asarray(G), wireframe=True, **kw) for U, G in results]
    bottom = [render(V, F, colors=heat_colors(np.zeros(len(V)), 0, vmax, CMAP), **kw)]
    bottom += [render(V, F, colors=heat_colors(e, 0, vmax, CMAP), **kw) for e in errors]
    caps = [f"input: {len(F)} faces"]
    caps += [f"{f:.0%}: {len(G)} faces" for f, (_, G) in zip(fractions, results)]
    caps += ["error 0 (the input itself)"]
    caps += [f"distance to the {f:.0%} mesh, max {e.max():.2f}%" for f, e in zip(fractions, errors)]
    grid = panels(top + bottom, caps, ncols=4, title="QEM simplification of the airplane (greedy loop)")
    # The bar belongs to the heat maps: beside the bottom row, as tall as its renders.
    bar = colorbar(0, vmax, CMAP, label="distance, % of bbox diagonal", height=size[1] + 40)
    row = panels(bottom, caps[4:], ncols=4)
    img = np.concatenate(
        [
            grid,
            np.pad(
                bar, ((grid.shape[0] - row.shape[0], row.shape[0] - bar.shape[0]), (0, 0), (0, 0)), constant_values=255
            ),
        ],
        axis=1,
    )
    return Drawn(
        img,
        "The lecture's series: the pyvista airplane and its QEM simplifications to 50%, 10% and 2% of the faces "
        "(top, wireframe). Bottom: every input vertex coloured by its distance to the simplified surface, on one "
        "colour scale. At 50% the error is invisible: contractions in flat regions cost nothing. At 2% the error "
        "sits on the rounded nose and along the thin leading and trailing edges of the wings and tail, whose "
        "thickness is lost; the flat parts stay exact.",
    )


def _anchor_runs(V, F, targets):
    """Outputs of igl.qslim, fast-simplification and VTK for each target (None when a library is missing)."""
    runs = {}
    try:
        import igl

        runs["igl.qslim"] = [tuple(igl.qslim(V, F.astype(np.int32), t)[:2]) for t in targets]
    except ImportError:
        pass
    try:
        import fast_simplification

        runs["fast-simplification"] = [fast_simplification.simplify(V, F, 1.0 - t / len(F)) for t in targets]
    except ImportError:
        pass
    try:
        import pyvista as pv

        out = []
        for t in targets:
            d = pv.PolyData.from_regular_faces(V, F).decimate(1.0 - t / len(F))
            out.append((np.asarray(d.points, float), np.asarray(d.faces).reshape(-1, 4)[:, 1:]))
        runs["VTK decimate"] = out
    except ImportError:
        pass
    return runs


@figure_name("error_vs_faces")
def fig_error_curve(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    V, F = datasets.icosphere(3 if quick else 4)
    V = datasets.add_noise(V, 0.01, seed=1, direction="normal", F=F)
    fractions = (0.3, 0.1, 0.03) if quick else (0.5, 0.3, 0.1, 0.05, 0.02)
    targets = [max(8, round(f * len(F))) for f in fractions]
    runs = {"ours (greedy)": [qem_simplify(V, F, t) for t in targets]}
    runs.update(_anchor_runs(V, F, targets))
    samples = 5000 if quick else 20000
    xs, ys, labels = [], [], []
    for name, outs in runs.items():
        faces = [len(G) for _, G in outs]
        rms = [mesh_distance(V, F, np.asarray(U, float), np.asarray(G), n_samples=samples)["rms"] for U, G in outs]
        xs.append(np.array(faces))
        ys.append(100 * np.array(rms))
        labels.append(name)
    w, h = (480, 400) if quick else (620, 520)
    absolute = line_plot(
        xs, ys, labels, xlabel="faces kept", ylabel="RMS distance (% of bbox diagonal)", logx=True, logy=True,
        title=f"Error vs face count, noisy sphere ({len(F)} faces)", size=(w, h),
    )  # fmt: skip
    # Curves that nearly coincide on a log-log plot separate when divided by one of them.
    ref = ys[labels.index("igl.qslim")] if "igl.qslim" in labels else ys[0]
    relative = line_plot(
        xs, [y / ref for y in ys], labels, xlabel="faces kept", ylabel="RMS distance / igl.qslim's", logx=True,
        title="Relative to igl.qslim at the same target", size=(w, h),
    )  # fmt: skip
    img = panels([absolute, relative], ["", ""], ncols=2)
    spread = "; ".join(
        f"{name} {100 * (r.min() - 1):+.1f}% to {100 * (r.max() - 1):+.1f}%"
        for name, r in ((n, y / ref) for n, y in zip(labels, ys, strict=True))
        if name != "igl.qslim"
    )
    return Drawn(
        img,
        "RMS surface distance between a noisy sphere and its simplifications, against the number of faces kept "
        "(both axes logarithmic), for our greedy loop and three libraries: all follow the same power law. Right: "
        "the same errors divided by igl.qslim's, where the curves separate. Our greedy loop places each vertex at "
        f"its quadric minimum like igl.qslim and stays close to it; relative to igl.qslim: {spread}.",
    )


@figure_name("pairs")
def fig_pairs(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    V, F = cracked_sheet(8 if quick else 12)
    target = 24 if quick else 40
    # light boundary quadrics: the outline stays recognisable, and crossing the crack stays affordable
    edges_only = qem_simplify(V, F, target, boundary_weight=0.1)
    with_pairs = qem_simplify(V, F, target, pair_threshold=0.05, boundary_weight=0.1)
    size = (300, 220) if quick else (400, 290)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True, flat=True)
    palette = np.array([[0.55, 0.70, 0.95], [0.98, 0.70, 0.45], [0.6, 0.85, 0.6], [0.85, 0.6, 0.85]])

    def piece_colours(G):
        n, labels = topology.connected_components_faces(np.asarray(G))
        return palette[labels % len(palette)], n

    imgs, caps = [], []
    for title, (U, G) in (
        ("input", (V, F)),
        ("edges only", edges_only),
        ("edges + pairs closer than 0.05", with_pairs),
    ):
        colours, n = piece_colours(G)
        imgs.append(render(np.asarray(U), np.asarray(G), face_colors=colours, **kw))
        caps.append(f"{title}: {len(G)} faces, {n} piece{'s' if n > 1 else ''}")
    img = panels(imgs, caps, title="Valid pairs: edges vs non-edge pairs across a 0.03 crack")
    return Drawn(
        img,
        f"Two sheets separated by a crack of width 0.03 (colour = connected piece), simplified towards the same "
        f"target of {target} faces (a contraction removes two faces, or one on the boundary, so the two runs can "
        f"stop one face apart: {len(edges_only[1])} and {len(with_pairs[1])}). Contracting edges only can never join the pieces: each keeps its own boundary. Adding the non-edge "
        "pairs closer than 0.05 lets vertices on both sides of the crack merge, zipping the sheets into one piece.",
    )


@figure_name("boundary")
def fig_boundary(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    V, F = datasets.height_field(16 if quick else 32)
    target = max(20, len(F) // 25)
    size = (300, 220) if quick else (400, 290)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True)
    imgs = [render(V, F, **kw)]
    caps = [f"input: {len(F)} faces"]
    for keep in (False, True):
        U, G = qem_simplify(V, F, target, preserve_boundary=keep)
        loop = topology.boundary_loops(np.asarray(G))[0]
        imgs.append(render(np.asarray(U), np.asarray(G), highlight_points=loop, **kw))
        caps.append(f"{len(G)} faces, {'with' if keep else 'without'} boundary quadrics")
    img = panels(imgs, caps, title="Boundary penalty quadrics keep the outline")
    return Drawn(
        img,
        "An open height field simplified to 4% of its faces (red dots: boundary vertices). Without penalty "
        "quadrics a boundary vertex only feels the planes of its few faces, so the outline shrinks and cuts the "
        "corners. A plane through each boundary edge, perpendicular to its face and weighted heavily, keeps the "
        "boundary vertices on the square outline.",
    )


@figure_name("simplification_3d")
def fig_view(lab, quick: bool) -> MeshView:
    qem_simplify = _simplify(lab)
    V, F = airplane()
    U, G = qem_simplify(V, F, max(4, round(0.1 * len(F))))
    U, G = np.asarray(U), np.asarray(G)
    err = 100 * np.sqrt(closest_points(V, F, U)[0]) / float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    return MeshView(
        U, G, err, title="QEM: the airplane at 10% of its faces", up="z",
        cmap=CMAP, scalar_name="% of diagonal",
        caption=f"Turn it: the airplane simplified to {len(G):,} faces, each vertex coloured by its distance to the "
        "input surface (% of the bounding-box diagonal).",
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (fig_series, fig_error_curve, fig_pairs, fig_boundary), fig_view,
    quick="Smaller meshes and images (for notebooks and smoke tests).",
)  # fmt: skip
