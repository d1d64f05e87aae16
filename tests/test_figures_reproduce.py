"""The committed handout figures (``docs/figures/<lab>/``) are what the solutions draw today.

Every lab's figures are regenerated at full size (about 10-30 s a lab) and compared with the
committed PNGs, picture by picture. Tolerance: same size, and at most 0.2% of the pixels differ by
more than 32 levels (of 255) in some channel. That absorbs what differs between machines (Mesa's
OSMesa vs EGL rasterization and anti-aliasing along edges, and the 256-colour palette of the VDM
figures shifting with it) but not a changed mesh, a moved colour bar or a new caption number drawn
into the picture: the two stale figures this test was written for differed in 53,893
(``series.png``) and 80,852 (``vdm_pipeline.png``) pixels.

Every figure also keeps a white margin: nothing (a label, a legend) runs past the image edge.

When it fails after an intended change, regenerate and commit the lab's figures:
``uv run geomlib figures --lab <lab> --out docs/figures``.

The same build is checked for its captions (the rule and its waivers: ``tests/test_figure_captions.py``):
each lab's figures are drawn once per run, not once per check.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.test_figure_captions import NOT_YET, caption_problems

ROOT = Path(__file__).resolve().parents[1]
LABS = sorted(p.name for p in (ROOT / "docs" / "figures").iterdir() if p.is_dir() and p.name != "gallery")
DRAWN = sorted(p.parent.name for p in (ROOT / "solutions").glob("*/figures.py"))
LEVELS = 32
MAX_FRACTION = 0.002


def differing_pixels(a: np.ndarray, b: np.ndarray) -> int:
    """Pixels where some channel differs by more than :data:`LEVELS`."""
    return int((np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2) > LEVELS).sum())


@pytest.fixture(scope="module")
def drawn(tmp_path_factory) -> Callable[[str], list]:
    """``drawn(lab)``: the lab's ``make_figures`` records at full size, drawn on the first call only."""
    made: dict[str, list] = {}

    def draw(lab: str) -> list:
        if lab not in made:
            figures = importlib.import_module(f"solutions.{lab}.figures")
            made[lab] = figures.make_figures(tmp_path_factory.mktemp(f"figures-{lab}"))
        return made[lab]

    return draw


@pytest.mark.slow
@pytest.mark.render
@pytest.mark.parametrize("lab", LABS)
def test_regenerated_figures_equal_the_committed_ones(lab, drawn):
    made = {f.path.name: f.path for f in drawn(lab) if f.path.suffix == ".png"}
    committed = {p.name: p for p in (ROOT / "docs" / "figures" / lab).glob("*.png")}
    assert set(made) == set(committed), (
        f"{lab}: make_figures writes {sorted(made)}, docs/figures/{lab}/ holds {sorted(committed)}"
    )
    stale = []
    for name, path in sorted(committed.items()):
        old = np.asarray(Image.open(path).convert("RGB"))
        new = np.asarray(Image.open(made[name]).convert("RGB"))
        border = np.concatenate([new[:2].reshape(-1, 3), new[-2:].reshape(-1, 3),
                                 new[:, :2].reshape(-1, 3), new[:, -2:].reshape(-1, 3)])  # fmt: skip
        if (border.min(axis=1) < 200).any():
            stale.append(f"{name}: something is drawn on the image edge (a label or legend cut off)")
        if old.shape != new.shape:
            stale.append(f"{name}: size {old.shape[1]}x{old.shape[0]} committed, {new.shape[1]}x{new.shape[0]} now")
            continue
        n = differing_pixels(old, new)
        if n > MAX_FRACTION * old.shape[0] * old.shape[1]:
            stale.append(f"{name}: {n:,} of {old.shape[0] * old.shape[1]:,} pixels differ by more than {LEVELS} levels")
    assert not stale, (
        f"docs/figures/{lab}/ is stale (regenerate: uv run geomlib figures --lab {lab} --out docs/figures):\n"
        + "\n".join(stale)
    )


@pytest.mark.slow
@pytest.mark.render
@pytest.mark.parametrize("lab", DRAWN)
def test_every_caption_states_measured_numbers(lab, drawn, tmp_path):
    figures = importlib.import_module(f"solutions.{lab}.figures")
    made = [*drawn(lab), figures.make_view(tmp_path, quick=True)]
    waived = NOT_YET.get(lab, set())
    wrong, converted = [], []
    for fig in made:
        problems = caption_problems(fig)
        if fig.path.name in waived:
            if not problems:
                converted.append(fig.path.name)
            continue
        wrong += [f"{fig.path.name}: {p}" for p in problems]
    assert not wrong, f"{lab}: captions with numbers not measured by their builder:\n" + "\n".join(wrong)
    assert not converted, (
        f"{lab}: remove {converted} from NOT_YET in tests/test_figure_captions.py: their captions are measured now"
    )


#: What a caption's words say about its measured numbers, per lab and figure: the words are typed,
#: so each claim in them is checked here against the numbers the builder measured (Claims.numbers).
PROSE: dict[str, dict[str, Callable[[dict], bool]]] = {
    "sdf": {
        # the legend's three brick states all occur on this mesh
        "sdf_bricks.png": lambda n: n["inside"] > 0 and n["outside"] > 0 and n["kept"] > 0 and n["max_err"] <= 0.5,
        # "the improved variant cuts that overestimate", "the streaks are small next to the error against the truth"
        "sdf_soft_shadows.png": lambda n: n["ib_mean"] < n["pb_mean"] and n["ib_max"] < n["pb_max"]
        and n["prof_err"] > 2 * n["pb_max"] and n["better"] == sum(n[f"i{i}"] < n[f"e{i}"] for i in range(3)),
        "sdf_normals.png": lambda n: n["mean4"] > 10 * n["mean6"],  # "first- against second-order"
    },
    "simplification": {
        "error_vs_faces.png": lambda n: n["b_lo"] > 1.0,  # the shortest-edge baseline is worse everywhere
        "boundary.png": lambda n: n["off_kept"] < 0.1 * n["off_free"],  # the outline is kept, not cut
        "series.png": lambda n: n["m0"] < n["m1"] < n["m2"] and n["s0"] < n["s1"] < n["s2"],
    },
    "remeshing": {
        "operations.png": lambda n: (n["split"], n["collapse"], n["flip"]) == (n["faces"] + 2, n["faces"] - 2, n["faces"]),
        "features.png": lambda n: n["kept"] < n["free"],  # keeping the features keeps the surface closer
        # preserved: on the line and respaced; not preserved: off the line and the opening shrinks
        "boundary.png": lambda n: n["off_kept"] < 1e-6 * n["diag"] < n["off_free"] and n["len_free"] < n["length"],
    },
}  # fmt: skip


@pytest.mark.slow
@pytest.mark.render
@pytest.mark.parametrize("lab", sorted(PROSE))
def test_caption_words_agree_with_the_measured_numbers(lab, drawn):
    made = {f.path.name: f for f in drawn(lab)}
    wrong = []
    for name, holds in PROSE[lab].items():
        claims = made[name].claims
        if claims is None:
            wrong.append(f"{name}: the caption has no measured numbers")
        elif not holds(claims.numbers):
            wrong.append(f"{name}: the caption's words do not hold for its numbers {claims.numbers}")
    assert not wrong, f"{lab}:\n" + "\n".join(wrong)
