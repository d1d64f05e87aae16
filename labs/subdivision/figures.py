"""Figures of the subdivision lab, rendered with the lab's own functions.

``make_figures(out_dir)`` writes the PNGs and returns :class:`geomlib.plot.Figure` records. The
file is copied into ``labs/subdivision/`` with the stubs, so there it renders *your* results:
run ``make_figures`` once your functions work and compare with ``docs/figures/subdivision/``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geomlib import datasets, topology
from geomlib.labfigures import Claims, Drawn, MeshView, figure_name, lab_figure_makers
from geomlib.plot import colorbar, heat_colors, line_plot, panels, with_colorbar
from geomlib.render import camera_pose, render, render_polygons

__all__ = ["make_figures", "make_view", "airplane"]

LAB = "subdivision"
CMAP = "YlOrRd"  # light at zero, so the shape stays readable where the difference vanishes


def _ss(quick: bool) -> int:
    """Supersampling factor: anti-aliased figures, faster quick ones."""
    return 1 if quick else 2


def _functions(lab):
    """``(loop_subdivide, catmull_clark)`` of the lab module the figures draw."""
    return lab.loop_subdivide, lab.catmull_clark


def airplane() -> tuple[np.ndarray, np.ndarray]:
    """The pyvista airplane made manifold (stray triangle dropped, 6 pinch vertices split)."""
    return datasets.pyvista_mesh("airplane", manifold=True)


def _levels(subdivide, V, F, levels: int, **kw) -> list[tuple[np.ndarray, np.ndarray]]:
    out = [(np.asarray(V, float), F)]
    for _ in range(levels):  # one level at a time, so every level can be drawn
        V, F = subdivide(V, F, 1, **kw)
        out.append((np.asarray(V), np.asarray(F)))
    return out


@figure_name("loop_levels")
def fig_loop_levels(out: Path, lab, quick: bool) -> Drawn:
    loop_subdivide, _ = _functions(lab)
    size = (240, 200) if quick else (330, 270)
    L = 2 if quick else 3
    row1 = _levels(loop_subdivide, *datasets.icosphere(0), L, weights="warren")
    row2 = _levels(loop_subdivide, *airplane(), L, weights="warren")
    images, captions = [], []
    for name, row in (("icosahedron", row1), ("airplane", row2)):
        pose = camera_pose(row[0][0], "three_quarter", size=size, zoom=1.05)  # one camera per row
        for k, (V, F) in enumerate(row):
            dense = len(F) > 1500
            # The airplane is open: its wings and tail are sheets bounded by boundary loops. Red dots
            # mark the boundary vertices, so the boundary rule can be seen.
            border = np.unique(topology.boundary_edges(F)) if name == "airplane" else None
            images.append(
                render(
                    V,
                    F,
                    camera=pose,
                    size=size,
                    supersample=_ss(quick),
                    wireframe=True,
                    wire_opacity=0.25 if dense else 0.9,
                    smooth=k > 0,
                    highlight_points=border,
                )
            )
            extra = f", {len(border):,} boundary vertices" if border is not None else ""
            captions.append(f"{name}, level {k}: {len(F):,} faces{extra}")
    img = panels(images, captions, ncols=L + 1, title=f"Loop subdivision, Warren weights (levels 0-{L})")
    return Drawn(
        img,
        "Loop subdivision of the icosahedron (top) and of the open airplane mesh (bottom): every level splits each "
        "triangle into four and moves all vertices by fixed weights. The icosahedron shrinks toward a smooth limit "
        "surface inside its control mesh. The airplane is open (red dots: its boundary vertices): the wings and the "
        "tail are sheets whose edges and roots are boundary loops. Boundary vertices follow the curve rule "
        "(midpoints; 3/4, 1/8, 1/8 along the boundary), so these edges stay sharp and straight at every level while "
        "the fuselage is rounded off.",
    )


@figure_name("warren_vs_loop")
def fig_weights(out: Path, lab, quick: bool) -> Drawn:
    loop_subdivide, _ = _functions(lab)
    size = (260, 220) if quick else (360, 300)
    V, F = datasets.pyvista_mesh("ant")
    L = 1 if quick else 2
    Vw, Fw = loop_subdivide(V, F, L, "warren")
    Vl, _ = loop_subdivide(V, F, L, "loop")
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    d = np.linalg.norm(np.asarray(Vw) - np.asarray(Vl), axis=1) / diag
    hi = float(d.max())
    # The ant stands on its legs along +y: a y-up three-quarter view shows all six legs.
    pose = camera_pose(V, "three_quarter", size=size, up_axis="y")
    heat = render(Vw, Fw, camera=pose, size=size, supersample=_ss(quick), colors=heat_colors(d, 0.0, hi, cmap=CMAP))
    k = np.arange(3, 13)
    uw, ul = (np.asarray(lab.loop_weight(k, rule), float) for rule in ("warren", "loop"))
    same = k[np.isclose(uw, ul, rtol=1e-12, atol=0)]
    plot = line_plot(
        [k, k], [uw, ul], ['weights="warren": u = 3/16 (k = 3), 3/(8k)', 'weights="loop": beta(k)'],
        xlabel="valence k", ylabel="weight u of each neighbour", title="The two even-vertex rules",
        size=(size[0] + 120, size[1] + 60),
    )  # fmt: skip
    imgs = [
        plot,
        with_colorbar(heat, colorbar(0.0, hi, CMAP, label="|warren - loop| / diag", height=size[1] - 20)),
    ]
    caps = [
        "u(k) for both rules: equal at k = " + " and k = ".join(str(int(x)) for x in same) + " only",
        f"the pyvista ant subdivided {L} times with each rule: distance between the two",
    ]
    img = panels(imgs, caps, ncols=2, title="Warren's weights vs Loop's beta")
    far = int(k[np.argmax(np.abs(uw - ul))])
    valences = np.bincount(np.asarray(F).ravel(), minlength=len(V))
    return Drawn.claimed(
        img,
        "Warren's simplified weights (as in igl.loop) and Loop's original beta(k) (as in trimesh and VTK) "
        "give each of the k neighbours of an even vertex the weight u plotted on the left: they agree at "
        "valence {same_a} and {same_b} only, and differ most at k = {far} among the valences plotted. On the "
        "ant ({irregular} of its {n} vertices have a valence other than six) the two results differ by at most "
        "{hi:.1e} of the bounding-box diagonal, at vertices of unusual valence.",
        same_a=int(same[0]),
        same_b=int(same[-1]),
        far=far,
        irregular=int(np.sum(valences != 6)),
        n=len(V),
        hi=hi,
    )


@figure_name("catmull_clark_levels")
def fig_catmull_clark(out: Path, lab, quick: bool) -> Drawn:
    _, catmull_clark = _functions(lab)
    size = (240, 200) if quick else (330, 270)
    L = 2 if quick else 3
    images, captions, counts, old = [], [], {}, set()
    for name, (V0, faces0) in (("cube", datasets.quad_cube()), ("polygon cage", datasets.polygon_cage())):
        pose = camera_pose(V0, "three_quarter", size=size, zoom=1.05)
        V, faces = V0, faces0
        for k in range(L + 1):
            if k:
                V, faces = catmull_clark(V, faces, 1)
            ext = topology.extraordinary_vertices(faces, len(V), regular=4)
            counts.setdefault(name, []).append(len(ext))
            if k == 1:  # the extraordinary old corners: their valence (edges at the vertex)
                E = topology.unique_edges(topology.to_ragged(faces))
                valence = np.bincount(E.ravel(), minlength=len(V))
                old |= {int(valence[v]) for v in ext if v < len(V0)}
            images.append(
                render_polygons(
                    V, faces, camera=pose, size=size, supersample=_ss(quick), wireframe=True, wire_opacity=0.8 if k < 3 else 0.35,
                    highlight_points=ext, point_radius=4.0, smooth=k > 0, crease_deg=None,
                )
            )  # fmt: skip
            captions.append(f"{name}, level {k}: {len(faces):,} faces, {len(ext)} extraordinary")
    img = panels(images, captions, ncols=L + 1, title="Catmull-Clark subdivision (red: extraordinary vertices)")
    steady = all(len(set(c[1:])) == 1 for c in counts.values())
    return Drawn.claimed(
        img,
        "Catmull-Clark subdivision of a cube and of a cage of pentagon, quads and triangles. After one level every "
        "face is a quad; the extraordinary vertices (valence != 4, red) are the old corners (valence {lo} "
        + ("or" if len(old) == 2 else "to")
        + " {hi}) "
        "and the face points of non-quad faces, "
        + ("and their number stays the same at every later level: " if steady else "and their number after the "
           "first level (it should stay the same, but here it changes): ")
        + "{cube} on the cube, {cage} on the cage.",
        lo=min(old), hi=max(old), cube=counts["cube"][-1], cage=counts["polygon cage"][-1],
    )  # fmt: skip


@figure_name("boundary")
def fig_boundary(out: Path, lab, quick: bool) -> Drawn:
    loop_subdivide, catmull_clark = _functions(lab)
    import trimesh

    size = (260, 220) if quick else (340, 280)
    V, F = datasets.height_field(n=5, seed=3, amplitude=0.25)
    L = 2
    V2, F2 = loop_subdivide(V, F, L, "loop")
    Vt, Ft = trimesh.remesh.subdivide_loop(V, F, iterations=L)
    # same vertex order in both (old vertices first, then edges): match by position to be safe
    from scipy.spatial import cKDTree

    d = cKDTree(np.asarray(V2)).query(np.asarray(Vt))[0]
    # Corners (Hoppe et al. 1994): boundary vertices where the outline turns by more than 45 degrees.
    Eb = topology.boundary_edges(F)
    nb = [Eb[Eb[:, 0] == v, 1] if (Eb[:, 0] == v).any() else [] for v in range(len(V))]
    pb = [Eb[Eb[:, 1] == v, 0] if (Eb[:, 1] == v).any() else [] for v in range(len(V))]
    corners = []
    for v in np.unique(Eb):
        a, b = V[nb[v][0], :2] - V[v, :2], V[v, :2] - V[pb[v][0], :2]
        if np.dot(a, b) < np.cos(np.radians(45)) * np.linalg.norm(a) * np.linalg.norm(b):
            corners.append(int(v))
    Vc = np.asarray(V, float)
    Fc = F
    for _ in range(L):  # the given corner option of loop_matrix; old vertices keep their indices
        S, Fc = lab.loop_matrix(Vc, Fc, "loop", corners=corners)
        Vc = S @ Vc
    kept = float(np.abs(Vc[corners] - np.asarray(V, float)[corners]).max())
    rounded = float(np.linalg.norm(np.asarray(V2)[corners] - np.asarray(V, float)[corners], axis=1).max())
    pose = camera_pose(V, "three_quarter", size=size)
    imgs = [
        render(V, F, camera=pose, size=size, supersample=_ss(quick), wireframe=True, smooth=False),
        render(V2, F2, camera=pose, size=size, supersample=_ss(quick), wireframe=True, wire_opacity=0.4),
        with_colorbar(
            render(
                Vt,
                Ft,
                camera=pose,
                size=size,
                supersample=_ss(quick),
                colors=heat_colors(d, 0.0, max(float(d.max()), 1e-12), cmap=CMAP),
            ),
            colorbar(0.0, float(d.max()), CMAP, label="distance to ours (model units)", height=size[1] - 20),
        ),
        render(Vc, Fc, camera=pose, size=size, supersample=_ss(quick), wireframe=True, wire_opacity=0.4,
               highlight_points=corners),
    ]  # fmt: skip
    caps = [
        "open height field (control mesh)",
        f"loop_subdivide, {L} levels (same as igl.loop and VTK):\nthe square's corners round off",
        f"trimesh.subdivide_loop, {L} levels",
        f"loop_matrix(..., corners=...), {L} levels: the\n{len(corners)} corners (red) stay fixed",
    ]
    img = panels(imgs, caps, ncols=2, title="Boundary rules: midpoints and 1/8, 3/4, 1/8 along the boundary")
    return Drawn.claimed(
        img,
        "An open grid subdivided {levels} times with Loop's weights. The boundary is refined as a cubic B-spline "
        "curve of its own (odd = edge midpoint, even = 1/8, 3/4, 1/8 along the boundary), as in igl.loop and VTK, "
        "so the square's corners round off: they move by up to {rounded:.3f}. trimesh gives 1/8 to every "
        "neighbour that lies on the boundary, so boundary vertices joined to another boundary vertex by an "
        "interior edge get weights summing to 9/8 and move off (dark red; distances in model units). Last: the "
        "corner rule of Hoppe et al. (1994), a given option (loop_matrix's corners, not a task): the {n_corners} "
        "corner vertices keep their positions (moved by {kept:.1g}) and the outline keeps its right angles.",
        levels=L,
        rounded=rounded,
        n_corners=len(corners),
        kept=kept,
    )


@figure_name("convergence")
def fig_convergence(out: Path, lab, quick: bool) -> Drawn:
    loop_subdivide, catmull_clark = _functions(lab)
    L = 4 if quick else 6
    curves, labels = [], []
    for name, fn, (V, F) in (
        ("Loop, icosahedron", lambda V, F: loop_subdivide(V, F, 1, "loop"), datasets.icosphere(0)),
        ("Catmull-Clark, cube", lambda V, F: catmull_clark(V, F, 1), datasets.quad_cube()),
        ("Catmull-Clark, cage", lambda V, F: catmull_clark(V, F, 1), datasets.polygon_cage()),
    ):
        moves = []
        for _ in range(L):
            V1, F1 = fn(V, F)
            V1 = np.asarray(V1)
            moves.append(float(np.abs(V1[: len(V)] - V).max()))  # how far the old vertices moved
            V, F = V1, F1
        curves.append(np.array(moves))
        labels.append(name)
    xs = [np.arange(1, L + 1)] * len(curves)
    img = line_plot(
        xs, curves, labels, xlabel="level", ylabel="largest move of an old vertex (units)", logy=True,
        title="Subdivision converges: moves shrink geometrically", size=(560, 380),
    )  # fmt: skip
    f = [float(c[-2] / c[-1]) for c in curves]  # how much the moves shrink over the last level
    return Drawn.claimed(
        img,
        "How far the old vertices move at each level (log scale). The moves shrink by a roughly constant factor "
        "per level, so the meshes converge to a limit surface; the limit position of every vertex is a fixed "
        "weighted average of its neighbourhood. Over the last level they shrink {f0:.1f}x (Loop, icosahedron), "
        "{f1:.1f}x (Catmull-Clark, cube) and {f2:.1f}x (Catmull-Clark, cage): the cage converges more slowly, "
        "because next to its valence-five apex the subdivision matrix's second eigenvalue is larger than on a "
        "regular patch.",
        f0=f[0],
        f1=f[1],
        f2=f[2],
    )


@figure_name("subdivision_3d")
def fig_view(lab, quick: bool) -> MeshView:
    loop_subdivide, _ = _functions(lab)
    V, F = airplane()
    levels = 1 if quick else 2
    Vs, Fs = loop_subdivide(V, F, levels=levels)
    return MeshView(
        Vs, Fs, title=f"Loop subdivision of the airplane, {levels} levels", up="z",
        caption=Claims(
            "Turn it: the airplane after {levels} Loop levels ({faces:,} faces); the wings and the tail are "
            "open sheets, and their boundary edges stay sharp and straight.",
            {"levels": levels, "faces": len(Fs)},
        ),
    )  # fmt: skip


make_figures, make_view = lab_figure_makers(
    LAB, __name__, (fig_loop_levels, fig_weights, fig_catmull_clark, fig_boundary, fig_convergence), fig_view,
    quick="Fewer levels and smaller images (for notebooks and smoke tests).",
)  # fmt: skip
