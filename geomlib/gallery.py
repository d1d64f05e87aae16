"""The dataset gallery: one wireframe render per built-in dataset, plus a contact sheet.

:func:`build_gallery` renders every entry of :data:`geomlib.datasets.DATASETS` and returns the
:class:`~geomlib.plot.Figure` records that ``geomlib figures`` indexes. Polygon meshes are drawn
with their true polygon edges; vertices whose valence differs from the regular one (6 for
triangles, 4 for quads) are marked with red dots when there are few of them.

Run it alone with ``python -m geomlib.gallery OUT_DIR [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from geomlib import topology
from geomlib.plot import Figure, panels, save_png, write_index

__all__ = ["build_gallery", "write_index"]

#: Largest number of extraordinary vertices still marked with dots (more would be clutter).
MAX_MARKED = 60
#: Datasets with texture coordinates: drawn with a UV texture (red = u, green = v, checker), so
#: the mapping and its seams (where red or green jumps) can be seen.
UV_DATASETS = ("uv_sphere", "uv_torus", "uv_grid")
UV_CELLS = 8
#: Views that show what a dataset is about better than the three-quarter view: the cage from
#: below, so its pentagon floor and all six extraordinary vertices (five floor corners, the apex
#: seen past the wall) are visible.
CAMERAS = {"polygon_cage": ((2.4, -2.9, -1.5), (0.0, 0.0, 0.55), (0.0, 0.0, 1.0))}


def uv_texture(size: int = 256, cells: int = UV_CELLS) -> np.ndarray:
    """``(size, size, 3)`` uint8: red grows with u, green with v, and a light/dark checker of ``cells``."""
    t = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(t, t[::-1])  # row 0 is v = 1 (the top of the image)
    check = ((np.floor(u * cells) + np.floor(v * cells)) % 2)[..., None]
    rgb = np.stack([u, v, np.full_like(u, 0.35)], axis=-1)
    return np.round(255 * np.clip(rgb * (0.65 + 0.35 * check), 0, 1)).astype(np.uint8)


def _thumbnail(img: np.ndarray, width: int) -> np.ndarray:
    from PIL import Image

    h, w = img.shape[:2]
    if w <= width:
        return img
    return np.asarray(Image.fromarray(img).resize((width, round(h * width / w)), Image.Resampling.LANCZOS))


def build_gallery(out_dir, quick: bool = False, *, names: list[str] | None = None) -> list[Figure]:
    """Render every built-in dataset with its wireframe; write one PNG each and a contact sheet.

    Parameters
    ----------
    out_dir : str or Path
        Folder for ``<name>.png`` and ``contact_sheet.png`` (created if missing).
    quick : bool
        Smaller images (320 x 240 instead of 640 x 480), for fast checks.
    names : list of str, optional
        Only these datasets (default: all of :data:`geomlib.datasets.DATASETS`, in its order).

    Returns
    -------
    list of Figure
        The contact sheet first, then one figure per dataset, all with ``lab="gallery"``.

    Raises
    ------
    RuntimeError
        When a dataset fails to build or render (the message names it).
    """
    from geomlib.datasets import DATASETS
    from geomlib.render import render, render_polygons

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    chosen = list(DATASETS) if names is None else list(names)
    unknown = [n for n in chosen if n not in DATASETS]
    if unknown:
        raise KeyError(f"build_gallery: unknown dataset(s) {unknown}; known: {', '.join(DATASETS)}")
    size = (320, 240) if quick else (640, 480)
    figures: list[Figure] = []
    thumbs, labels = [], []
    for name in chosen:
        make, description, kind = DATASETS[name]
        try:
            V, faces = make()
            V = np.asarray(V, dtype=np.float64)
            idx, off = topology.to_ragged(faces)
            E = topology.unique_edges((idx, off))
            special = topology.extraordinary_vertices((idx, off), len(V))
            marked = special if 0 < len(special) <= MAX_MARKED else None
            opts = dict(
                wireframe=True,
                highlight_points=marked,
                camera=CAMERAS.get(name, "three_quarter"),
                up_axis="z",  # every built-in dataset is z-up
                size=size,
            )
            if name in UV_DATASETS:
                from geomlib import datasets

                opts.update(uv=getattr(datasets, name)()[2], texture=uv_texture())
            img = render(V, faces, **opts) if kind == "tri" else render_polygons(V, faces, **opts)
        except Exception as e:
            raise RuntimeError(f"build_gallery: dataset {name!r} failed: {type(e).__name__}: {e}") from e
        n_f = len(off) - 1
        what = "triangles" if kind == "tri" else "polygons"
        caption = f"{name}: {description}. {len(V)} vertices, {n_f} {what}, {len(E)} edges."
        if marked is not None:
            caption += f" Red dots: {len(marked)} extraordinary vertices."
        elif len(special):
            caption += f" {len(special)} extraordinary vertices (too many to mark)."
        if name in UV_DATASETS:
            caption += (
                f" Textured by its UVs: red grows with u, green with v, over a {UV_CELLS} x {UV_CELLS} checker; a seam shows "
                "where the colour jumps (u from 1 back to 0, or v)."
            )
        path = save_png(out / f"{name}.png", img)
        figures.append(Figure(path, caption, "gallery"))
        thumbs.append(_thumbnail(img, 320))
        labels.append(f"{name} ({len(V)} v, {n_f} f)")
    sheet = panels(
        thumbs,
        labels,
        title="geomlib built-in datasets (red dots: extraordinary vertices, where there are few)",
        ncols=min(5, max(1, len(thumbs))),
    )
    sheet_path = save_png(out / "contact_sheet.png", sheet)
    return [
        Figure(sheet_path, f"All {len(thumbs)} built-in datasets at a glance (wireframe renders).", "gallery"),
        *figures,
    ]


def main(argv: list[str] | None = None) -> int:
    """``python -m geomlib.gallery OUT_DIR [--quick]``: build the gallery and its index page."""
    args = list(sys.argv[1:] if argv is None else argv)
    quick = "--quick" in args
    rest = [a for a in args if a != "--quick"]
    if len(rest) != 1:
        print("usage: python -m geomlib.gallery OUT_DIR [--quick]", file=sys.stderr)
        return 2
    figs = build_gallery(rest[0], quick=quick)
    index = write_index(figs, rest[0])
    print(f"{len(figs)} figures; open {index}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
