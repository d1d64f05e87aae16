"""Figures of the remeshing lab, rendered with the lab's own functions.

``make_figures(out_dir, lab=None, quick=False)`` writes the PNGs and returns
:class:`geomlib.plot.Figure` records; in ``labs/remeshing/`` it renders *your* results.

The usual remeshing test meshes (the Stanford bunny, the fandisk, the camel head) are not part of the course,
so the figures use built-in stand-ins made here: a bunny of metaballs extracted by marching cubes
(:func:`metaball_bunny`; like a scan, it has slivers and irregular valences), the same bunny
decimated by QEM (:func:`decimated_bunny`), a block with a curved top and sharp edges
(:func:`curved_block`) and the bunny's head cut off at the neck, an open surface with one
boundary loop (:func:`bunny_head`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import datasets, topology
from geomlib.geometry import bbox_diagonal, closest_points, corner_angles, triangle_quality
from geomlib.labfigures import (
    Drawn,
    MeshView,
    MissingTasks,
    figure_name,
    lab_figure_makers,
    missing_panel,
    partial_figure,
)
from geomlib.plot import colorbar, heat_colors, line_plot, panels
from geomlib.render import render

__all__ = [
    "make_figures",
    "make_view",
    "metaball_bunny",
    "decimated_bunny",
    "curved_block",
    "bunny_head",
    "quality",
    "valence_colors",
    "valence_dots",
]

LAB = "remeshing"
#: valence colours: blue below the target, grey at it, red above (target 6 inside, 4 on the boundary)
LOW, SIX, HIGH = np.array([0.25, 0.45, 0.95]), np.array([0.82, 0.82, 0.82]), np.array([0.95, 0.3, 0.25])
VALENCE_TITLE = "vertices coloured by valence: blue below 6, grey 6, red above"
DOTS_TITLE = "dots mark irregular vertices: blue below valence 6, red above"
#: the target valences: inside and on the boundary
TARGET_INSIDE, TARGET_BOUNDARY = 6, 4
#: boundary vertices (black, apart from the valence colours) and feature lines (green)
BOUNDARY, FEATURE = (0.05, 0.05, 0.05), (0.05, 0.6, 0.2)
CMAP = "YlOrRd"  # light at zero, so the shape stays readable where the error vanishes
#: The tasks whose panels the figure being drawn left out (:func:`~geomlib.labfigures.partial_figure`).
_MISSING = MissingTasks()


def _ss(quick: bool) -> int:
    return 1 if quick else 2


# --------------------------------------------------------------------------------------------
# the meshes


#: metaballs of the bunny: (centre, radii) of Gaussian ellipsoids; it faces +x, z up
_BUNNY_BALLS = (
    ((0.0, 0.0, 0.0), (0.55, 0.42, 0.42)),  # body
    ((0.35, 0.0, 0.22), (0.35, 0.32, 0.32)),  # chest
    ((0.62, 0.0, 0.48), (0.26, 0.22, 0.22)),  # head
    ((0.82, 0.0, 0.42), (0.12, 0.11, 0.11)),  # snout
    ((0.55, 0.11, 0.90), (0.09, 0.065, 0.30)),  # ears
    ((0.52, -0.11, 0.88), (0.09, 0.065, 0.30)),
    ((-0.55, 0.0, 0.1), (0.13, 0.13, 0.13)),  # tail
    ((0.25, 0.22, -0.35), (0.22, 0.1, 0.1)),  # fore paws
    ((0.25, -0.22, -0.35), (0.22, 0.1, 0.1)),
    ((-0.2, 0.3, -0.3), (0.3, 0.12, 0.16)),  # haunches
    ((-0.2, -0.3, -0.3), (0.3, 0.12, 0.16)),
)


def metaball_bunny(n: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """A bunny of metaballs: the 0.5 level set of a sum of Gaussian ellipsoids, by marching cubes.

    Stands in for the Stanford bunny: a closed genus-0 surface about 2.2 units long (facing +x,
    z up) whose marching-cubes triangles have the flaws of a scan (slivers, valences from 3 to 9).

    Parameters
    ----------
    n : int
        Grid samples per axis (the mesh has about ``1.5 n**2`` faces).

    Returns
    -------
    V : (k, 3) float64
    F : (m, 3) int64
    """
    import pyvista as pv  # slow import: only when asked for

    g = np.linspace(-1.2, 1.4, n)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    f = np.zeros_like(X)
    for c, r in _BUNNY_BALLS:
        f += np.exp(-(((X - c[0]) / r[0]) ** 2) - ((Y - c[1]) / r[1]) ** 2 - ((Z - c[2]) / r[2]) ** 2)
    grid = pv.ImageData(dimensions=(n, n, n), spacing=(g[1] - g[0],) * 3, origin=(g[0],) * 3)
    grid.point_data["f"] = f.ravel(order="F")
    mesh = grid.contour([0.5], scalars="f", method="marching_cubes").triangulate().clean()
    F = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    return np.asarray(mesh.points, dtype=np.float64), F


def decimated_bunny(faces: int = 1200, n: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """:func:`metaball_bunny` decimated by QEM (fast-simplification) to about ``faces`` faces.

    An irregular input, as a decimated scan is: long thin triangles where the surface is flat
    in one direction, valences far from 6.
    """
    import fast_simplification

    V, F = metaball_bunny(n)
    U, G = fast_simplification.simplify(V.astype(np.float32), F.astype(np.int32), target_count=faces)
    return np.asarray(U, dtype=np.float64), np.asarray(G, dtype=np.int64)


def curved_block(n: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """A block with a curved top and waist: :func:`geomlib.datasets.sharp_box` 1.6 x 1 x 0.8, bent.

    Stands in for the fandisk: smooth curved parts (the top) meeting flat ones along sharp edges
    (dihedral angles of 60-90 degrees) with corners where three of them meet.
    """
    V, F = datasets.sharp_box((1.6, 1.0, 0.8), n)
    bump = np.cos(np.pi * V[:, 0] / 1.6)  # 1 in the middle, 0 at the ends
    V[:, 2] = -0.4 + (V[:, 2] + 0.4) * (1.0 + 0.6 * bump)
    V[:, 1] *= 1.0 - 0.3 * bump  # a waist: the front and back are curved too
    return V, F


def bunny_head(n: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """The head and ears of :func:`metaball_bunny`, cut off at the neck (the faces with ``x + z > 0.9`` at every vertex).

    Stands in for the camel head: an open surface with one jagged boundary loop.
    """
    V, F = metaball_bunny(n)
    F = F[(V[F, 0] + V[F, 2] > 0.9).all(axis=1)]
    _, label = topology.connected_components_faces(F)
    F = F[label == np.argmax(np.bincount(label))]
    used = np.unique(F)
    new = np.full(len(V), -1, np.int64)
    new[used] = np.arange(len(used))
    return V[used], new[F]


# --------------------------------------------------------------------------------------------
# measures


def angles(V, F) -> np.ndarray:
    """Every corner angle of every face, in degrees, ``(3 m,)``."""
    return np.degrees(corner_angles(V, F)).ravel()


def quality(V, F) -> dict:
    """The mesh quality measures (those the graded tests use, without the distance to the input):
    :func:`geomlib.geometry.triangle_quality`."""
    return triangle_quality(np.asarray(V, dtype=np.float64), np.asarray(F))


def _summary(q: dict) -> str:
    return (
        f"{q['faces']} faces, min angle {q['min_angle']:.1f}°, {q['below_30']:.2%} of angles < 30°, "
        f"valence 6: {q['valence6']:.0%}"
    )


def valence_colors(V, F) -> np.ndarray:
    """Per-vertex colours: :data:`LOW` below the target valence, :data:`SIX` at it, :data:`HIGH` above."""
    H = topology.halfedge_mesh(np.asarray(F), len(V))
    d = H.valence - np.where(H.boundary_vertex, TARGET_BOUNDARY, TARGET_INSIDE)
    return np.where(d[:, None] < 0, LOW, np.where(d[:, None] > 0, HIGH, SIX))


def valence_dots(V, F, radius: float = 1.6) -> dict:
    """Render options marking each irregular vertex with a dot: :data:`LOW` below the target, :data:`HIGH` above.

    Dots, not blended vertex colours (:func:`valence_colors`): on a mesh of long thin triangles the
    blend smears one vertex's colour over its fan, and one cannot tell which vertex is irregular.
    Regular vertices get no dot. Returns ``highlight_points``, ``point_color`` and ``point_radius``.
    """
    H = topology.halfedge_mesh(np.asarray(F), len(V))
    d = H.valence - np.where(H.boundary_vertex, TARGET_BOUNDARY, TARGET_INSIDE)
    off = np.flatnonzero(d != 0)
    return dict(highlight_points=off, point_color=np.where(d[off, None] < 0, LOW, HIGH), point_radius=radius)


def _histogram(meshes, labels, size, title) -> np.ndarray:
    xs, ys = [], []
    for V, F in meshes:
        counts, edges = np.histogram(angles(V, F), bins=36, range=(0, 180))
        xs.append(0.5 * (edges[1:] + edges[:-1]))
        ys.append(counts / counts.sum())
    return line_plot(
        xs, ys, labels, xlabel="corner angle (degrees)", ylabel="share of angles", title=title, size=size, markers=False
    )


def _blank(size) -> np.ndarray:
    """The grey stand-in for a panel whose task is not implemented yet (``size`` = (width, height))."""
    return missing_panel(size[1], size[0])


def _mesh(result):
    return None if result is None else (np.asarray(result[0], dtype=np.float64), np.asarray(result[1]))


# --------------------------------------------------------------------------------------------
# the figures


@figure_name("before_after")
def fig_before_after(out: Path, R, quick: bool) -> Drawn:
    n = 48 if quick else 64
    bunny, decimated = metaball_bunny(n), decimated_bunny(800 if quick else 1200, n)
    L = 0.08 if quick else 0.06
    its = 5 if quick else 10
    size = (260, 220) if quick else (380, 300)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True, zoom=0.95)
    missing = _MISSING  # tasks whose panels are left blank (emptied by partial_figure)
    imgs, caps = [], []
    for name, (V, F) in (("bunny (marching cubes)", bunny), ("bunny decimated by QEM", decimated)):
        imgs.append(render(V, F, **valence_dots(V, F), **kw))
        caps.append(f"{name}: {_summary(quality(V, F))}")
        result = _mesh(missing.attempt(R.isotropic_remesh, V, F, L, iterations=its))
        if result is None:
            imgs.append(_blank(size))
            caps.append(f"isotropic_remesh: not implemented yet (Task {missing[-1]})")
        else:
            imgs.append(render(*result, **valence_dots(*result), **kw))
            caps.append(f"remeshed, L = {L}: {_summary(quality(*result))}")
        meshes = [(V, F)] + ([result] if result is not None else [])
        hist_size = (max(size[0] + 40, 360), max(size[1], 280))
        imgs.append(_histogram(meshes, ["input", "remeshed"][: len(meshes)], hist_size, "angles (60° = equilateral)"))
        caps.append(
            f"corner angles of the {name.split(' (')[0]}"
            + ("" if result is not None else f" (remeshed: not implemented yet, Task {missing[-1]})")
        )
    img = panels(imgs, caps, ncols=3, title=f"Isotropic remeshing, {its} iterations; {DOTS_TITLE}")
    return Drawn(
        img,
        f"Top: a scan-like bunny (metaballs extracted by marching cubes, {len(bunny[1])} faces) before and after "
        f"isotropic_remesh to L = {L} ({its} iterations); bottom: the same bunny decimated by QEM "
        f"(fast-simplification, {len(decimated[1])} faces: long thin triangles) before and after the same call. "
        "A dot marks each vertex whose valence is not 6 (blue below, red above; 4 on the boundary); the captions "
        "give the faces, the smallest angle, the share of angles below 30° and the share of interior vertices of valence 6; the "
        "plots show the distribution of the corner angles, which remeshing gathers around 60°.",
    )


@figure_name("iterations")
def fig_iterations(out: Path, R, quick: bool) -> Drawn:
    n = 48 if quick else 64
    V, F = decimated_bunny(800 if quick else 1200, n)
    L = 0.08 if quick else 0.06
    size = (240, 200) if quick else (340, 270)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True, zoom=0.95)
    imgs, caps = [], []
    for its in range(6):
        U, G = R.isotropic_remesh(V, F, L, iterations=its)
        U, G = np.asarray(U, dtype=np.float64), np.asarray(G)
        imgs.append(render(U, G, **valence_dots(U, G), **kw))
        caps.append(f"{its} iteration{'' if its == 1 else 's'}: {_summary(quality(U, G))}")
    img = panels(imgs, caps, ncols=3, title=f"The decimated bunny after 0 to 5 iterations (L = {L}); {DOTS_TITLE}")
    return Drawn(
        img,
        f"isotropic_remesh(V, F, {L}, iterations=k) of the QEM-decimated bunny for k = 0 to 5 (k = 0 is not "
        "the input: the sliver clean-up that ends the loop still runs), a dot on each vertex whose valence "
        "is not 6 (blue below, red above); each caption gives the faces, the smallest angle, the share of "
        "angles below 30° and the share of interior vertices of valence 6.",
    )


def _bar_beside_row(grid: np.ndarray, bar: np.ndarray, row: np.ndarray, pad: int = 12) -> np.ndarray:
    """Put ``bar`` right of the one-row panel page ``grid``, level with its pictures.

    ``row`` is the same row laid out without the title, to find where the pictures start.
    """
    top = grid.shape[0] - row.shape[0] + pad
    bar = np.pad(bar, ((top, grid.shape[0] - top - bar.shape[0]), (0, pad), (0, 0)), constant_values=255)
    return np.concatenate([grid, bar], axis=1)


@figure_name("features")
def fig_features(out: Path, R, quick: bool) -> Drawn:
    V, F = curved_block(4)
    L, angle = (0.14, 45.0) if quick else (0.1, 45.0)
    its = 5 if quick else 10
    size = (280, 220) if quick else (380, 300)
    kw = dict(camera="three_quarter", size=size, supersample=_ss(quick), wireframe=True)
    diag = bbox_diagonal(V)
    missing = _MISSING  # tasks whose panels are left blank (emptied by partial_figure)
    sharp = missing.attempt(R.sharp_edges, V, F, angle)
    results = [
        _mesh(missing.attempt(R.isotropic_remesh, V, F, L, iterations=its, feature_angle=fa)) for fa in (angle, None)
    ]
    # how far each face leaves the input: the distance of its centroid, in % of the diagonal
    errs = [
        None if r is None else 100 * np.sqrt(closest_points(V, F, r[0][r[1]].mean(axis=1))[0]) / diag for r in results
    ]
    vmax = max([float(e.max()) for e in errs if e is not None] + [1e-3])
    if sharp is None:
        imgs, caps = [render(V, F, **kw)], [f"input: {len(F)} faces; sharp_edges: not implemented yet"]
    else:
        sharp = np.asarray(sharp)
        imgs = [render(V, F, highlight_lines=V[sharp], line_color=FEATURE, **kw)]
        caps = [f"input: {len(F)} faces; the {len(sharp)} edges sharper than {angle:.0f}° in green"]
    lines = None if sharp is None else V[sharp]  # the input's sharp edges, over both results
    for r, e, what in zip(results, errs, (f"feature_angle={angle:.0f}", "feature_angle=None"), strict=True):
        if r is None:
            imgs.append(_blank(size))
            caps.append(f"{what}: not implemented yet")
            continue
        imgs.append(render(*r, face_colors=heat_colors(e, 0, vmax, CMAP), highlight_lines=lines, line_color=FEATURE,
                           line_width=1.5, **kw))  # fmt: skip
        caps.append(
            f"{what}: {len(r[1])} faces, min angle {quality(*r)['min_angle']:.1f}°; "
            f"faces off the input by up to {e.max():.2f}%"
        )
    grid = panels(imgs, caps, ncols=3, title=f"Sharp edges kept (feature_angle = {angle:.0f}°) or not, L = {L}")
    if any(e is not None for e in errs):  # the bar of the heat maps, when there are any
        bar = colorbar(0, vmax, CMAP, label="distance, % of diagonal", height=size[1])
        grid = _bar_beside_row(grid, bar, panels(imgs, caps, ncols=3))
    if missing or sharp is None:
        return Drawn(grid, "A block with sharp edges remeshed with and without them kept.")
    return Drawn.claimed(
        grid,
        "A block with a curved top and waist and sharp edges (a built-in stand-in for the fandisk); its {n_sharp} "
        "edges sharper than {angle:.0f} degrees (sharp_edges) drawn in green, on the input and over both results. "
        "Then isotropic_remesh to L = {L} ({its} iterations) with feature_angle = {angle:.0f} and without: each face "
        "is coloured by the distance of its centroid from the input surface, in % of the bounding-box diagonal "
        "(one scale for both, the bar on the right; at most {kept:.2f}% and {free:.2f}%). With the features kept, "
        "the corners stay put and the vertices of the sharp edges on the input's edges, so what is left is the "
        "sag of flat faces under the curved top; without, the faces cut across the green lines and round the "
        "corners.",
        n_sharp=len(sharp), angle=angle, L=L, its=its, kept=float(errs[0].max()), free=float(errs[1].max()),
    )  # fmt: skip


def _boundary_offset(U, G, A, B) -> tuple[int, float, float]:
    """Boundary of ``(U, G)``: vertex count, largest distance of a vertex to the segments ``A[i]B[i]``, length."""
    E = topology.boundary_edges(G)
    P = U[np.unique(E)]
    AB = B - A
    t = np.clip(np.einsum("pij,ij->pi", P[:, None] - A[None], AB) / np.einsum("ij,ij->i", AB, AB), 0, 1)
    d = np.linalg.norm(A[None] + t[:, :, None] * AB[None] - P[:, None], axis=2).min(axis=1)
    return len(P), float(d.max()), float(np.linalg.norm(U[E[:, 1]] - U[E[:, 0]], axis=1).sum())


@figure_name("boundary")
def fig_boundary(out: Path, R, quick: bool) -> Drawn:
    V, F = bunny_head(48 if quick else 64)
    L = 0.06 if quick else 0.045
    its = 5 if quick else 10
    size = (260, 260) if quick else (360, 340)
    c = V.mean(axis=0)
    view = c + 1.9 * np.array([-0.61, -0.73, -0.3])  # from behind, left and below: into the opening
    kw = dict(camera=(view, c, (0.0, 0.0, 1.0)), size=size, supersample=_ss(quick), wireframe=True)
    diag = bbox_diagonal(V)
    E = topology.boundary_edges(F)
    A, B = V[E[:, 0]], V[E[:, 1]]
    length = float(np.linalg.norm(B - A, axis=1).sum())
    kw["point_color"] = BOUNDARY  # not the valence red
    imgs = [render(V, F, colors=valence_colors(V, F), highlight_points=np.unique(E), **kw)]
    caps = [f"input: {len(F)} faces, {len(np.unique(E))} boundary vertices (black dots), boundary length {length:.2f}"]
    offsets = {}
    missing = _MISSING  # tasks whose panels are left blank (emptied by partial_figure)
    for keep in (True, False):
        r = _mesh(missing.attempt(R.isotropic_remesh, V, F, L, iterations=its, preserve_boundary=keep))
        if r is None:
            imgs.append(_blank(size))
            caps.append(f"preserve_boundary={keep}: not implemented yet")
            continue
        nb, off, ln = _boundary_offset(*r, A, B)
        offsets[keep] = (off, ln)
        dots = np.unique(topology.boundary_edges(r[1]))
        imgs.append(render(*r, colors=valence_colors(*r), highlight_points=dots, **kw))
        caps.append(
            f"preserve_boundary={keep}: {len(r[1])} faces, {nb} boundary vertices, at most {off:.2g} "
            f"({100 * off / diag:.2g}% of the diagonal) from the input boundary; length {ln:.2f}"
        )
    title = f"An open surface remeshed to L = {L}; valence: blue below the target (6, on the boundary 4), grey at it, red above"
    img = panels(imgs, caps, ncols=3, title=title)
    if missing:
        return Drawn(img, "An open surface remeshed with its boundary preserved or not.")
    return Drawn.claimed(
        img,
        "The bunny's head cut off at the neck (a built-in stand-in for the camel head: an open surface with one "
        "jagged boundary loop), seen from behind into the opening, and isotropic_remesh to L = {L} ({its} "
        "iterations) with preserve_boundary True and False. Boundary vertices are black dots, every vertex "
        "coloured by valence against its target ({inside} inside, {boundary} on the boundary: blue below, grey at, red "
        "above). "
        "Preserved, the boundary stays on the input's boundary line (its vertices at most {off_kept:.2g} from it, "
        "the model being {diag:.2f} across) and is only respaced (length {len_kept:.2f} against {length:.2f}); not "
        "preserved, it is relaxed like the interior and leaves the line (up to {off_free:.2g}), and the opening "
        "shrinks (length {len_free:.2f}).",
        L=L, its=its, off_kept=offsets[True][0], off_free=offsets[False][0], diag=diag, len_kept=offsets[True][1],
        len_free=offsets[False][1], length=length, inside=TARGET_INSIDE, boundary=TARGET_BOUNDARY,
    )  # fmt: skip


def _patch_drawing(U, G, size, *, thick=(), labels=(), dots=()) -> np.ndarray:
    """A flat patch drawn from above with matplotlib: its edges, ``thick`` edges in red, named points.

    ``thick`` is a list of ``(p, q)`` position pairs, ``labels`` of ``(name, position)``, ``dots`` of
    positions (drawn as red dots). The patches of the operations figure are planar, so a 2-D drawing
    shows the letters of the handout's formulas exactly where the vertices are.
    """
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    dpi = 100
    with matplotlib.rc_context({"font.family": "DejaVu Sans", "svg.hashsalt": "geomlib", "path.simplify": False}):
        fig = MplFigure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi, facecolor="white")
        canvas = FigureCanvasAgg(fig)
        ax = fig.add_axes((0.04, 0.04, 0.92, 0.92))
        ax.triplot(U[:, 0], U[:, 1], G, color=(0.25, 0.3, 0.45), linewidth=0.9)
        ax.fill(*U[np.unique(G)][:, :2].T, alpha=0)  # keeps the axes limits on the patch
        for p, q in thick:
            ax.plot([p[0], q[0]], [p[1], q[1]], color=(0.85, 0.15, 0.1), linewidth=3.2, zorder=3)
        for p in dots:
            ax.plot([p[0]], [p[1]], "o", color=(0.85, 0.15, 0.1), markersize=7, zorder=4)
        for name, p in labels:
            ax.annotate(name, (p[0], p[1]), xytext=(6, 5), textcoords="offset points", fontsize=15,
                        fontweight="bold", color=(0.1, 0.1, 0.1), zorder=5)  # fmt: skip
        lo, hi = U[:, :2].min(axis=0), U[:, :2].max(axis=0)
        pad = 0.06 * float((hi - lo).max())
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.axis("off")
        canvas.draw()
        return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


@figure_name("operations")
def fig_operations(out: Path, R, quick: bool) -> Drawn:
    V, F = datasets.grid_patch(3)
    H = topology.halfedge_mesh(F, len(V), manifold=True)
    # the diagonal of the middle cell: both ends inside the patch
    inside = (~H.boundary_vertex[H.E]).all(axis=1)
    diagonal = (V[H.E[:, 0], :2] != V[H.E[:, 1], :2]).all(axis=1)
    e = int(np.flatnonzero(inside & diagonal)[0])
    a, b = (int(i) for i in H.E[e])
    # c: opposite the edge in the face (a, b, c), d: in the face (b, a, d), as in the flip's docstring
    c = d = None
    for f in F[(F == a).any(axis=1) & (F == b).any(axis=1)]:
        k = int(np.flatnonzero(f == a)[0])
        if f[(k + 1) % 3] == b:
            c = int(f[(k + 2) % 3])
        else:
            d = int(f[(k + 1) % 3])
    pa, pb, pc, pd = V[a], V[b], V[c], V[d]
    mid = 0.5 * (pa + pb)
    size = (240, 240) if quick else (300, 300)
    missing = _MISSING  # tasks whose panels are left blank (emptied by partial_figure)
    names = [("a", pa), ("b", pb), ("c", pc), ("d", pd)]
    imgs = [_patch_drawing(V, F, size, thick=[(pa, pb)], labels=names)]
    caps = [f"{len(F)} faces; the edge a-b in red, c and d opposite it"]
    faces = {}
    for name, op in (("split_edge", R.split_edge), ("collapse_edge", R.collapse_edge), ("flip_edge", R.flip_edge)):
        r = missing.attempt(op, V, H, e)
        if r is None:
            imgs.append(_blank(size))
            caps.append(f"{name}: not implemented yet")
            continue
        U, G = np.asarray(r[0], dtype=np.float64), np.asarray(r[1].idx).reshape(-1, 3)
        faces[name] = len(G)
        if name == "split_edge":
            draw = dict(thick=[(mid, p) for p in (pa, pb, pc, pd)], dots=[mid], labels=[*names, ("m", mid)])
            caps.append(f"split_edge: {len(G)} faces; m, the midpoint of a-b, joined to a, b, c, d")
        elif name == "collapse_edge":
            draw = dict(dots=[mid], labels=[("m", mid), ("c", pc), ("d", pd)])
            caps.append(f"collapse_edge: {len(G)} faces; a and b merged at m, faces a-b-c and b-a-d gone")
        else:
            draw = dict(thick=[(pc, pd)], labels=names)
            caps.append(f"flip_edge: {len(G)} faces; a-b replaced by c-d")
        imgs.append(_patch_drawing(U, G, size, **draw))
    J = V + 0.08 * np.random.default_rng(1).normal(size=V.shape) * [1, 1, 0] * ~H.boundary_vertex[:, None]
    imgs.append(_patch_drawing(J, F, size))
    caps.append("interior vertices jittered")
    damping = 0.5
    W = missing.attempt(R.tangential_relaxation, J, F, damping=damping)
    imgs.append(_blank(size) if W is None else _patch_drawing(np.asarray(W, dtype=np.float64), F, size))
    caps.append("tangential_relaxation: not implemented yet" if W is None else "after tangential_relaxation")
    img = panels(imgs, caps, title="The local operations on a 4 x 4 patch", ncols=3)
    if missing:
        return Drawn(img, "The local operations on the diagonal a-b of a grid patch.")
    return Drawn.claimed(
        img,
        "The diagonal a-b of the middle cell of a grid patch ({faces} faces; c and d are the vertices opposite "
        "it, in the faces (a, b, c) and (b, a, d), as in the Task 1-3 docstrings) split at its midpoint m "
        "({split} faces: m joins a, b, c and d), collapsed (a and b meet at m, the two faces of the edge go: "
        "{collapse} faces) and flipped to the other diagonal c-d ({flip} faces); a patch with jittered interior "
        "vertices before and after one tangential relaxation step (damping {damping}).",
        faces=len(F), split=faces["split_edge"], collapse=faces["collapse_edge"], flip=faces["flip_edge"],
        damping=damping,
    )  # fmt: skip


@figure_name("remeshing_3d")
def fig_view(R, quick: bool) -> MeshView:
    V, F = metaball_bunny(48 if quick else 64)
    L = 0.08 if quick else 0.06
    U, G = R.isotropic_remesh(V, F, L, iterations=5 if quick else 10)
    U, G = np.asarray(U, float), np.asarray(G)
    H = topology.halfedge_mesh(G, len(U))
    # signed, as in the PNGs (blue below the target, grey at it, red above), not |valence - 6|
    dev = (H.valence - np.where(H.boundary_vertex, TARGET_BOUNDARY, TARGET_INSIDE)).astype(float)
    return MeshView(
        U, G, dev, title=f"Remeshed bunny (L = {L})", up="z",
        cmap="coolwarm", clim=(-3.0, 3.0), scalar_name="valence - target (6 inside, 4 on the boundary)",
        caption=f"Turn it: the metaball bunny after isotropic remeshing to L = {L}, each vertex coloured by its "
        "valence minus the target, as in the pictures: blue below 6, grey at 6 (regular), red above.",
    )  # fmt: skip


#: The figures in order; one drawn without some of its panels names the first missing task in its caption.
FIGURES = [
    partial_figure(build, _MISSING)
    for build in (fig_before_after, fig_operations, fig_iterations, fig_features, fig_boundary)
]

make_figures, make_view = lab_figure_makers(
    LAB, __name__, FIGURES, fig_view,
    quick="Smaller meshes, fewer iterations and smaller images (for notebooks and smoke tests).",
)  # fmt: skip
