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
from geomlib.labfigures import Claims, Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import colorbar, heat_colors, line_plot, panels
from geomlib.render import render

__all__ = ["make_figures", "make_view", "airplane", "cracked_sheet", "shortest_edge_decimate"]

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
    V, F = airplane()
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    fractions = (0.5, 0.1, 0.02)
    # one run of the greedy loop to 2%, keeping the mesh as it passes 50% and 10% (the same meshes as three runs)
    results = lab.qem_simplify_series(V, F, [max(4, round(f * len(F))) for f in fractions])
    # error of every input vertex: its distance to the simplified surface, in % of the diagonal
    errors = [100 * np.sqrt(closest_points(U, G, V)[0]) / diag for U, G in results]
    # A log scale: the errors span decades, and on a linear one the 50% and 10% maps are blank.
    hi = float(np.ceil(np.log10(max(float(e.max()) for e in errors))))
    lo = hi - 4.0
    size = (300, 220) if quick else (420, 300)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), zoom=0.95)
    top = [render(V, F, wireframe=True, edge_width=0.6, **kw)]
    top += [render(np.asarray(U), np.asarray(G), wireframe=True, **kw) for U, G in results]

    def log_colours(e):
        return heat_colors(np.log10(np.maximum(e, 10**lo)), lo, hi, CMAP)

    bottom = [render(V, F, colors=log_colours(e), **kw) for e in errors]
    bar = colorbar(lo, hi, CMAP, label="log10 of the distance, % of bbox diagonal", height=size[1])
    caps = [f"input: {len(F)} faces"]
    caps += [f"{f:.0%}: {len(G)} faces" for f, (_, G) in zip(fractions, results)]
    caps += [f"colour scale: 10^{lo:.0f} % (lightest) to 10^{hi:.0f} %"]
    caps += [f"distance to the {f:.0%} mesh, max {e.max():.2f}%" for f, e in zip(fractions, errors)]
    img = panels(top + [bar] + bottom, caps, ncols=4, title="QEM simplification of the airplane (greedy loop)")
    # where the error starts: the share of input vertices more than a thousandth of the scale's top off
    start = 10.0 ** (hi - 3)
    shares = [float(np.mean(e > start)) for e in errors]
    return Drawn.claimed(
        img,
        "The lecture's series: the pyvista airplane and its QEM simplifications to {f0:.0%}, {f1:.0%} and {f2:.0%} "
        "of the faces (top, wireframe). Bottom: every input vertex coloured by its distance to the simplified "
        "surface on one logarithmic colour scale (bottom left), maxima {m0:.2f}%, {m1:.2f}% and {m2:.2f}% of the "
        "diagonal. At {f0:.0%} contractions in flat regions cost nothing: only {s0:.0%} of the vertices are more "
        "than {start:.2f}% off, at the tip of the nose and along the thin edges of the tail and wings, where the "
        "error starts. At {f1:.0%} ({s1:.0%} of the vertices) it has spread over the curved fuselage and the wings, "
        "except at the vertices that survived (the light spots); at {f2:.0%} ({s2:.0%}) it covers the whole "
        "airplane, darkest on the nose and on the trailing edges of the wings and tail, whose thickness is lost.",
        f0=fractions[0], f1=fractions[1], f2=fractions[2], m0=float(errors[0].max()), m1=float(errors[1].max()),
        m2=float(errors[2].max()), s0=shares[0], s1=shares[1], s2=shares[2], start=start,
    )  # fmt: skip


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
    V, F = datasets.icosphere(3 if quick else 4)
    V = datasets.add_noise(V, 0.01, seed=1, direction="normal", F=F)
    fractions = (0.3, 0.1, 0.03) if quick else (0.5, 0.3, 0.1, 0.05, 0.02)
    targets = [max(8, round(f * len(F))) for f in fractions]
    runs = {"ours (greedy)": lab.qem_simplify_series(V, F, targets)}  # one run of the loop, kept at each target
    runs.update(_anchor_runs(V, F, targets))
    baseline = "shortest edge, midpoint"
    runs[baseline] = shortest_edge_decimate(V, F, targets)
    samples = 5000 if quick else 20000
    xs, ys, labels = [], [], []
    for name, outs in runs.items():
        faces = [len(G) for _, G in outs]
        rms = [mesh_distance(V, F, np.asarray(U, float), np.asarray(G), n_samples=samples)["rms"] for U, G in outs]
        xs.append(np.array(faces))
        ys.append(100 * np.array(rms))
        labels.append(name)
    w, h = (480, 360) if quick else (620, 440)
    absolute = line_plot(
        xs, ys, labels, xlabel="faces kept", ylabel="RMS distance (% of bbox diagonal)", logx=True, logy=True,
        title=f"Error vs face count, noisy sphere ({len(F)} faces)", size=(w, h),
    )  # fmt: skip
    # Curves that nearly coincide on a log-log plot separate when divided by one of them; the
    # baseline, many times higher, stays on the left only.
    ref = ys[labels.index("igl.qslim")] if "igl.qslim" in labels else ys[0]
    qem = [i for i, name in enumerate(labels) if name != baseline]
    relative = line_plot(
        [xs[i] for i in qem], [ys[i] / ref for i in qem], [labels[i] for i in qem], xlabel="faces kept",
        ylabel="RMS distance / igl.qslim's", logx=True, title="The QEM implementations, relative to igl.qslim",
        size=(w, h),
    )  # fmt: skip
    img = panels([absolute, relative], None, ncols=2)
    spread = {}
    for name, y in zip(labels, ys, strict=True):
        if name not in ("igl.qslim", baseline):
            key = {"ours (greedy)": "ours", "fast-simplification": "fs", "VTK decimate": "vtk"}[name]
            spread[f"{key}_lo"], spread[f"{key}_hi"] = (
                100 * float((y / ref).min() - 1),
                100 * float((y / ref).max() - 1),
            )
    times = ys[labels.index(baseline)] / ys[0]
    others = "; ".join(
        f"{name} {{{key}_lo:+.1f}}% to {{{key}_hi:+.1f}}%"
        for name, key in (("fast-simplification", "fs"), ("VTK decimate", "vtk"))
        if f"{key}_lo" in spread
    )
    return Drawn.claimed(
        img,
        "RMS surface distance between a noisy sphere and its simplifications, against the number of faces kept "
        "(both axes logarithmic). The baseline contracts the shortest edge to its midpoint, with no quadric: its "
        "error is {b_lo:.1f} to {b_hi:.1f} times ours at the same face count, because midpoints sink below a "
        "curved surface and the shortest edge is not the cheapest one to lose. That gap is what the quadric buys: "
        "its order (the contraction that moves the surface least goes first) and its placement (the point closest "
        "to the planes of both ends' faces). Our greedy loop and three libraries, all QEM, follow the same lower "
        "curve. Right: their errors divided by igl.qslim's, where they separate; relative to igl.qslim, ours "
        "{ours_lo:+.1f}% to {ours_hi:+.1f}%" + ("; " + others if others else "") + ".",
        b_lo=float(times.min()), b_hi=float(times.max()), **spread,
    )  # fmt: skip


def shortest_edge_decimate(V, F, targets) -> list[tuple[np.ndarray, np.ndarray]]:
    """The baseline QEM is measured against: contract the shortest edge to its midpoint, repeatedly.

    No quadric: the order is the edge length and the new vertex the midpoint (the naive decimator of
    Garland and Heckbert's and Botsch et al.'s comparisons). Contractions keep the mesh a manifold
    (the link condition: the ends share exactly the vertices opposite the edge) and turn no face over.
    A figure helper, not a lab task: one Python heap, a few milliseconds a contraction.

    Returns the mesh at each of ``targets`` (face counts, any order), compacted.
    """
    import heapq

    V = np.array(V, dtype=np.float64)
    F = np.array(F, dtype=np.int64)
    alive = np.ones(len(F), bool)
    faces_of = [set() for _ in range(len(V))]
    for f, tri in enumerate(F.tolist()):
        for v in tri:
            faces_of[v].add(f)
    version = np.zeros(len(V), np.int64)

    def ring(v):
        return {u for f in faces_of[v] for u in F[f].tolist()} - {v}

    def push(heap, i, j):
        a, b = min(i, j), max(i, j)
        heapq.heappush(heap, (float(np.sum((V[a] - V[b]) ** 2)), a, b, int(version[a]), int(version[b])))

    heap = []
    for i, j in topology.unique_edges(F).tolist():
        push(heap, i, j)
    out, left = {}, int(alive.sum())
    for target in sorted(set(int(t) for t in targets), reverse=True):
        while left > target and heap:
            _, i, j, vi, vj = heapq.heappop(heap)
            if version[i] != vi or version[j] != vj:
                continue
            shared = faces_of[i] & faces_of[j]
            opposite = {u for f in shared for u in F[f].tolist()} - {i, j}
            if not shared or ring(i) & ring(j) != opposite or len(ring(i) | ring(j)) <= 3:
                continue
            m = 0.5 * (V[i] + V[j])
            moved = [f for f in (faces_of[i] | faces_of[j]) - shared]
            T = F[moved]
            before = np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]])
            W = V.copy()
            W[[i, j]] = m
            after = np.cross(W[T[:, 1]] - W[T[:, 0]], W[T[:, 2]] - W[T[:, 0]])
            if (np.sum(before * after, axis=1) <= 0).any():
                continue
            V[i] = m
            for f in shared:
                alive[f] = False
                for u in F[f].tolist():
                    faces_of[u].discard(f)
            for f in list(faces_of[j]):
                F[f][F[f] == j] = i
                faces_of[i].add(f)
            faces_of[j] = set()
            left -= len(shared)
            version[i] += 1
            version[j] += 1
            for u in ring(i):
                push(heap, i, u)
        G = F[alive]
        used = np.unique(G)
        new = np.full(len(V), -1, np.int64)
        new[used] = np.arange(len(used))
        out[target] = (V[used].copy(), new[G])
    return [out[int(t)] for t in targets]


@figure_name("pairs")
def fig_pairs(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    gap, threshold = 0.03, 0.05
    V, F = cracked_sheet(8 if quick else 12, gap)
    target = 24 if quick else 40
    # light boundary quadrics: the outline stays recognisable, and crossing the crack stays affordable
    edges_only = qem_simplify(V, F, target, boundary_weight=0.1)
    with_pairs = qem_simplify(V, F, target, pair_threshold=threshold, boundary_weight=0.1)
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
        (f"edges + pairs closer than {threshold}", with_pairs),
    ):
        colours, n = piece_colours(G)
        imgs.append(render(np.asarray(U), np.asarray(G), face_colors=colours, **kw))
        caps.append(f"{title}: {len(G)} faces, {n} piece{'s' if n > 1 else ''}")
    img = panels(imgs, caps, title=f"Valid pairs: edges vs non-edge pairs across a {gap} crack")
    return Drawn.claimed(
        img,
        "Two sheets separated by a crack of width {gap} (colour = connected piece), simplified towards the same "
        "target of {target} faces (a contraction removes two faces, or one on the boundary, so the two runs can "
        "stop one face apart: {edges_faces} and {pairs_faces}). Contracting edges only can never join the pieces: "
        "each keeps its own boundary. Adding the non-edge pairs closer than {threshold} lets vertices on both "
        "sides of the crack merge, zipping the sheets into {pieces} piece.",
        gap=gap,
        target=target,
        edges_faces=len(edges_only[1]),
        pairs_faces=len(with_pairs[1]),
        threshold=threshold,
        pieces=topology.connected_components_faces(np.asarray(with_pairs[1]))[0],
    )


def _outline_distance(P, A, B) -> np.ndarray:
    """Distance of each point ``P`` to the nearest of the segments ``A[i]B[i]``."""
    AB = B - A
    t = np.clip(np.einsum("pij,ij->pi", P[:, None] - A[None], AB) / np.einsum("ij,ij->i", AB, AB), 0, 1)
    return np.linalg.norm(A[None] + t[:, :, None] * AB[None] - P[:, None], axis=2).min(axis=1)


@figure_name("boundary")
def fig_boundary(out: Path, lab, quick: bool) -> Drawn:
    qem_simplify = _simplify(lab)
    V, F = datasets.height_field(16 if quick else 32)
    target = max(20, len(F) // 25)
    size = (300, 220) if quick else (400, 290)
    E = topology.boundary_edges(F)
    A, B = V[E[:, 0]], V[E[:, 1]]
    outline = np.stack([A, B], axis=1)  # the input's outline, drawn over both results
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True)
    imgs = [render(V, F, highlight_lines=outline, **kw)]
    caps = [f"input: {len(F)} faces, its outline in green"]
    off, faces = {}, {}
    for keep in (False, True):
        U, G = qem_simplify(V, F, target, preserve_boundary=keep)
        U, G = np.asarray(U), np.asarray(G)
        faces[keep] = len(G)
        loop = topology.boundary_loops(G)[0]
        off[keep] = 100 * float(_outline_distance(U[loop], A, B).max()) / diag
        imgs.append(render(U, G, highlight_points=loop, highlight_lines=outline, **kw))
        caps.append(
            f"{len(G)} faces, {'with' if keep else 'without'} boundary quadrics: boundary vertices up to "
            f"{off[keep]:.2f}% of the diagonal off the outline"
        )
    img = panels(imgs, caps, title="Boundary penalty quadrics keep the outline")
    return Drawn.claimed(
        img,
        "An open height field simplified to {share:.0%} of its faces (a target of {target}: {faces} faces come out, "
        "each collapse removing two; red dots: the result's "
        "boundary vertices, green line: the input's outline). Without penalty quadrics a boundary vertex only "
        "feels the planes of its few faces, so it slides off the outline at little cost and the result cuts the "
        "corners: its boundary vertices lie up to {off_free:.2f}% of the bounding-box diagonal from the input's "
        "outline. A plane through each boundary edge, perpendicular to its face and weighted like the faces, keeps them "
        "within {off_kept:.2f}% of it.",
        share=target / len(F), target=target, faces=faces[True], off_free=off[False], off_kept=off[True],
    )  # fmt: skip


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
        caption=Claims(
            "Turn it: the airplane simplified to {faces:,} faces, each vertex coloured by its distance to the "
            "input surface (% of the bounding-box diagonal), up to {max_err:.2f}%.",
            {"faces": len(G), "max_err": float(err.max())},
        ),
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (fig_series, fig_error_curve, fig_pairs, fig_boundary), fig_view,
    quick="Smaller meshes and images (for notebooks and smoke tests).",
)  # fmt: skip
