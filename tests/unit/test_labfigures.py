"""Tests for geomlib.labfigures: how a lab's figure builders become its make_figures and make_view.

The builders here draw tiny flat images (no OpenGL); the real labs' figures are checked by
tests/test_lab_contracts.py (signatures, placeholders of the untouched stubs) and
tests/test_figures_reproduce.py (the committed PNGs).
"""

from __future__ import annotations

import inspect
import types

import numpy as np
import pytest

import geomlib
from geomlib.labfigures import (
    Drawn,
    MeshView,
    figure_name,
    figures_or_placeholders,
    lab_figure_makers,
    lab_package,
    partial_figure,
)
from geomlib.plot import Figure, save_png
from geomlib.validate import MeshError

TRIANGLE = (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))


def _png(out, name: str) -> Figure:
    return Figure(save_png(out / f"{name}.png", np.zeros((8, 8, 3), np.uint8)), name, "lab")


def test_a_missing_task_becomes_a_labelled_placeholder(tmp_path):
    def fig_done(out, quick):
        return _png(out, "done")

    @figure_name("todo_figure")
    def fig_todo(out, quick):
        raise NotImplementedError("Task 3b (odd vertices): E = ...")

    assert fig_todo.figure_name == "todo_figure" and fig_todo.__name__ == "fig_todo"
    figs = figures_or_placeholders((fig_done, fig_todo), tmp_path, "lab", True)
    assert [f.path.name for f in figs] == ["done.png", "todo_figure.png"]
    assert figs[1].caption.startswith("Task 3b not implemented yet") and "odd vertices" in figs[1].caption
    assert figs[1].path.is_file()
    with pytest.raises(MeshError, match="lab must be a module"):
        lab_package("subdivision", "solutions.subdivision")


def _makers(seen: list, cache: dict, **kw):
    """make_figures/make_view over two builders (one done, one stopped by Task 2) and a view."""

    @figure_name("first")
    def fig_first(out, L, quick):
        seen.append((L, quick, dict(cache)))
        cache["mesh"] = "computed"  # what a later figure of the same call may reuse
        return _png(out, "first")

    @figure_name("second")
    def fig_second(out, L, quick):
        seen.append((L, quick, dict(cache)))
        raise NotImplementedError("Task 2 (the second thing): not yet")

    @figure_name("toy_3d")
    def fig_view(L, quick):
        return MeshView(*TRIANGLE, np.arange(3.0), caption=f"Turn it: {L.__name__}", title="a triangle")

    return lab_figure_makers("toy", "geomlib.toyfigures", (fig_first, fig_second), fig_view, quick="Tiny.", **kw)


def test_made_functions_have_the_lab_contract_and_full_docstrings():
    make_figures, make_view = _makers([], {})
    for fn in (make_figures, make_view):
        params = [(p.name, p.default) for p in inspect.signature(fn).parameters.values()]
        assert params == [("out_dir", inspect.Parameter.empty), ("lab", None), ("quick", False)]
        assert fn.__module__ == "geomlib.toyfigures" and fn.__qualname__ == fn.__name__
        doc = inspect.getdoc(fn)
        for part in ("Parameters\n----------", "out_dir : str or Path", "lab : module, optional", "``labs.toy``"):
            assert part in doc, (fn.__name__, part)
        assert "quick : bool\n    Tiny." in doc and "Returns\n-------" in doc
    assert "``toy_3d.html``" in make_view.__doc__ and "``toy_3d.png``" in make_view.__doc__


def test_figures_draw_the_given_lab_with_placeholders_and_a_fresh_cache(tmp_path):
    seen, shared = [], {"mesh": "left over from another lab module"}
    make_figures, make_view = _makers(seen, shared, shared=shared)
    figs = make_figures(tmp_path / "out", quick=True)
    assert [f.path.name for f in figs] == ["first.png", "second.png"]
    assert figs[1].caption.startswith("Task 2 not implemented yet") and figs[1].lab == "toy"
    # Default lab: the package the figures module is in (here geomlib); the cache is empty when a call
    # starts, shared between its figures, and emptied when it ends.
    assert [(L, q) for L, q, _ in seen] == [(geomlib, True), (geomlib, True)]
    assert seen[0][2] == {} and seen[1][2] == {"mesh": "computed"} and shared == {}
    other = types.ModuleType("labs.toy")
    make_figures(tmp_path, lab=other)
    assert seen[-1][0] is other and seen[-1][1] is False
    with pytest.raises(MeshError, match="lab must be a module"):
        make_figures(tmp_path, lab="toy")


def test_the_view_is_written_under_its_figure_name(tmp_path):
    make_figures, make_view = _makers([], {})
    fig = make_view(tmp_path / "v", lab=types.ModuleType("labs.toy"))
    assert fig.path == tmp_path / "v" / "toy_3d.html" and fig.caption == "Turn it: labs.toy" and fig.lab == "toy"
    assert "a triangle" in fig.path.read_text(encoding="utf-8")

    def fig_view(L, quick):
        raise NotImplementedError("Task 4 (remesh): ...")

    fig_view.figure_name = "toy_3d"
    _, make_view = lab_figure_makers("toy", "geomlib.toyfigures", (), fig_view, quick="Tiny.")
    fig = make_view(tmp_path)
    assert fig.path.name == "toy_3d.png" and fig.caption.startswith("Task 4 not implemented yet")


def test_figures_that_ignore_lab_get_only_quick_and_say_so(tmp_path):
    calls = []

    @figure_name("only")
    def fig_only(out, quick):
        calls.append(quick)
        return _png(out, "only")

    def fig_view(quick):
        return MeshView(*TRIANGLE, caption="c")

    make_figures, make_view = lab_figure_makers(
        "toy", "geomlib.toyfigures", (fig_only,), fig_view, quick="Tiny.", draws_lab=False
    )
    assert [f.path.name for f in make_figures(tmp_path, quick=True)] == ["only.png"] and calls == [True]
    assert make_view(tmp_path).path.name == "toy_3d.html"
    assert "Not used" in make_figures.__doc__
    with pytest.raises(MeshError, match="lab must be a module"):
        make_figures(tmp_path, lab=3)


def test_a_partial_figure_names_its_first_missing_panel(tmp_path):
    missing: list[str] = []

    @figure_name("panels")
    def fig_panels(out, quick):
        if quick:
            missing.extend(["7", "9"])
        return [_png(out, "a"), _png(out, "b")]

    drawn = partial_figure(fig_panels, missing)
    assert drawn.figure_name == "panels" and drawn.__name__ == "fig_panels"
    figs = drawn(tmp_path, True)
    assert [f.caption for f in figs] == [
        "Task 7 not implemented yet; the other panels show: a",
        "Task 7 not implemented yet; the other panels show: b",
    ]
    missing.append("stale")  # emptied before the next drawing
    assert [f.caption for f in drawn(tmp_path, False)] == ["a", "b"]


def test_a_drawn_picture_is_written_under_its_figure_name_with_its_caption(tmp_path):
    picture = np.zeros((6, 9, 3), np.uint8)
    picture[2:4, 3:7] = (200, 30, 10)

    @figure_name("toy_picture")
    def fig_picture(out, L, quick):
        return Drawn(picture, f"A red bar (quick={quick}).")

    make_figures, _ = lab_figure_makers("toy", "geomlib.toyfigures", (fig_picture,), None, quick="Tiny.")
    (fig,) = make_figures(tmp_path / "out", quick=True)
    assert fig == Figure(tmp_path / "out" / "toy_picture.png", "A red bar (quick=True).", "toy")
    from PIL import Image

    assert np.array_equal(np.asarray(Image.open(fig.path)), picture)
    # The same bytes as writing the picture directly.
    assert fig.path.read_bytes() == save_png(tmp_path / "direct.png", picture).read_bytes()


def test_a_partial_drawn_picture_keeps_its_name_and_names_the_missing_task(tmp_path):
    missing: list[str] = []

    @figure_name("half")
    def fig_half(out, quick):
        missing.append("4")
        return Drawn(np.full((4, 4, 3), 255, np.uint8), "the left panel")

    (fig,) = figures_or_placeholders((partial_figure(fig_half, missing),), tmp_path, "toy", False)
    assert fig.path == tmp_path / "half.png" and fig.path.is_file()
    assert fig.caption == "Task 4 not implemented yet; the other panels show: the left panel"


def test_a_builder_returning_something_else_or_several_drawn_pictures_fails(tmp_path):
    image = np.zeros((4, 4, 3), np.uint8)

    @figure_name("odd")
    def fig_odd(out, quick):
        return image  # forgot the caption

    with pytest.raises(MeshError, match="fig_odd returned ndarray; expected a Drawn"):
        figures_or_placeholders((fig_odd,), tmp_path, "toy", False)

    @figure_name("two")
    def fig_two(out, quick):
        return [Drawn(image, "a"), Drawn(image, "b")]

    with pytest.raises(MeshError, match=r"fig_two returned several pictures as Drawn.*\(two\.png\)"):
        figures_or_placeholders((fig_two,), tmp_path, "toy", False)
    assert not (tmp_path / "two.png").exists()

    @figure_name("bad_image")
    def fig_bad(out, quick):
        return Drawn(np.zeros((4, 4, 7)), "seven channels")

    with pytest.raises(MeshError):
        figures_or_placeholders((fig_bad,), tmp_path, "toy", False)


def test_missing_tasks_note_the_task_and_draw_a_stand_in():
    from geomlib.labfigures import MissingTasks, missing_panel, task_label

    missing = MissingTasks()

    def stub(x):
        raise NotImplementedError("Task 3b (relaxation): not implemented yet")

    assert missing.attempt(lambda x: x + 1, 1) == 2 and missing == [] and missing.caption_head() == ""
    assert missing.attempt(stub, 1) is None and missing == ["3b"]
    assert missing.caption_head() == "Task 3b not implemented yet; the other panels show: "
    assert task_label(NotImplementedError("no task named")) == "?"
    panel = missing_panel(50, 80, "not implemented yet")
    assert panel.shape == (50, 80, 3) and panel.dtype == np.uint8 and (panel < 200).any()
    with pytest.raises(ValueError):  # only a missing task is caught
        missing.attempt(lambda: int("x"))


def test_a_claimed_caption_is_formatted_from_its_numbers(tmp_path):
    from geomlib.labfigures import Claims

    @figure_name("claimed")
    def fig_claimed(out, quick):
        return Drawn.claimed(np.zeros((4, 4, 3), np.uint8), "{n} dots, mean {m:.2f}", n=3, m=0.456)

    (fig,) = figures_or_placeholders((fig_claimed,), tmp_path, "toy", False)
    assert fig.caption == "3 dots, mean 0.46" and fig.claims == Claims("{n} dots, mean {m:.2f}", {"n": 3, "m": 0.456})
    assert fig.claims.problems(fig.caption) == []
