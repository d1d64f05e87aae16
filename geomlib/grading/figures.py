"""The main job: regenerate every figure from the reference solutions, with an index page.

``geomlib figures`` renders the gallery of built-in datasets and, for every lab that has a
``solutions/<lab>/figures.py`` (in a student bundle, without solutions: ``labs/<lab>/figures.py``), calls its ``make_figures(out_dir, lab=None, quick=False)`` (one
signature in every lab, checked by ``tests/test_lab_contracts.py``); then writes ``index.html``
and ``index.md`` showing every figure with its caption, and each lab's interactive 3D view
(``make_view``: ``<lab>_3d.html``, see :mod:`geomlib.viewer`) in a frame.
"""

from __future__ import annotations

import importlib
import sys
import time
from pathlib import Path

from geomlib.grading.course import course, course_root

__all__ = ["lab_figure_modules", "build_all"]


def lab_figure_modules() -> list[str]:
    """Labs with a ``figures.py`` (the solutions', else in a student bundle the stubs'), in course order."""
    return course().figure_labs


def build_all(out: Path, labs: list[str] | None = None, *, quick: bool = False, progress: bool = True) -> list:
    """Render the gallery and every lab's figures into ``out``; return the list of ``Figure``."""
    from geomlib import gallery, plot

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    wanted = labs or ["gallery", *lab_figure_modules()]
    root = str(course_root())
    if root not in sys.path:
        sys.path.insert(0, root)
    figures = []
    for i, name in enumerate(wanted, 1):
        t = time.time()
        if progress:
            print(f"[{i}/{len(wanted)}] {name} ...", flush=True)
        if name == "gallery":
            figs = gallery.build_gallery(out / "gallery", quick=quick)
        else:
            paths = course().lab(name)
            if not paths.figures.is_file():
                raise FileNotFoundError(
                    f"no figures for lab {name!r} (expected {paths.figures.relative_to(course().root)})"
                )
            mod = importlib.import_module(f"{course().figures_package}.{name}.figures")
            figs = mod.make_figures(out / name, quick=quick)
            if hasattr(mod, "make_view"):  # the lab's interactive 3D page, framed in the index
                figs = [*figs, mod.make_view(out / name, quick=quick)]
        figures.extend(figs)
        if progress:
            print(f"      {len(figs)} figure(s) in {time.time() - t:.1f} s", flush=True)
    plot.write_index(figures, out)
    return figures
