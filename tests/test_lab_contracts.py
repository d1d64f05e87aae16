"""Per-lab contracts, checked for every lab at once (issue 15, item 7; issue 14, item 5).

- ``make_figures(out_dir, lab=None, quick=False)`` and ``make_view`` (same arguments: the lab's
  interactive 3D page) in ``solutions/<lab>/figures.py`` and its copy in ``labs/<lab>/``; ``lab`` is
  a module of the lab's functions, and passing one is honoured;
- ``__all__`` of every lab package and figures module names things that exist, and the stubs
  export exactly what the solution exports;
- the handout's task list (section "Tasks": numbered items or a table) names the same tasks as
  the stubs' ``NotImplementedError("Task N ...")`` messages;
- ``make_figures`` and ``make_view`` on the untouched stubs finish, and draw one "Task N not implemented yet"
  picture (naming a task the stubs really leave open) for each figure it cannot draw, under the
  figure's own file name (``make_figures`` of a lab with a notebook: on the stubs notebook's run,
  ``tests/test_notebooks.py``);
- every panel of those figures shows what the solution's shows or says what is missing (for a lab
  with a notebook: on its runs, which draw the same figures).
"""

from __future__ import annotations

import contextlib
import importlib
import inspect
import json
import re
import types
from pathlib import Path

import numpy as np
import pytest

from geomlib.grading.course import course
from geomlib.plot import Figure

ROOT = Path(__file__).resolve().parents[1]
LABS = course(ROOT).figure_labs
TASK = re.compile(r"NotImplementedError\(\s*['\"]Task (\d+[a-z]?)\b")


def stub_tasks(lab: str) -> set[str]:
    """Task labels of the stubs' ``NotImplementedError`` messages (``"2"``, ``"1a"``) and of their
    shaders' ``#error Task N`` directives (``shaders/*.frag``, ``*.vert``)."""
    found: set[str] = set()
    for f in (ROOT / "labs" / lab).glob("*.py"):
        found |= set(TASK.findall(f.read_text(encoding="utf-8")))
    for f in (ROOT / "labs" / lab / "shaders").glob("*"):
        found |= set(re.findall(r"^\s*#error Task (\d+[a-z]?)\b", f.read_text(encoding="utf-8"), re.M))
    return found


def handout_tasks(lab: str) -> set[str]:
    """Task labels in the handout's "Tasks" section: ``1. **...**`` items or ``| 1a | ...`` rows."""
    text = (ROOT / "labs" / lab / "README.md").read_text(encoding="utf-8")
    m = re.search(r"^##[^#\n]*\b[Tt]asks\b[^\n]*\n(.*?)(?=^## )", text, re.M | re.S)
    assert m, f"labs/{lab}/README.md has no '## ... Tasks' section"
    section = m.group(1)
    items = re.findall(r"^(\d+)\. ", section, re.M)
    rows = re.findall(r"^\| *(\d+[a-z]?)\b", section, re.M)
    return set(items) | set(rows)


@pytest.mark.parametrize("lab", LABS)
def test_make_figures_and_make_view_have_one_signature(lab):
    for pkg in ("solutions", "labs"):
        for name in ("make_figures", "make_view"):
            fn = getattr(importlib.import_module(f"{pkg}.{lab}.figures"), name)
            params = inspect.signature(fn).parameters
            got = [(p.name, p.default) for p in params.values()]
            assert got == [("out_dir", inspect.Parameter.empty), ("lab", None), ("quick", False)], (
                f"{pkg}/{lab}/figures.py: {name}{inspect.signature(fn)}; expected (out_dir, lab=None, quick=False)"
            )


@pytest.mark.parametrize("lab", LABS)
def test_all_names_exist_and_stubs_export_the_same(lab):
    for module in ("", ".figures"):
        sol = importlib.import_module(f"solutions.{lab}{module}")
        stub = importlib.import_module(f"labs.{lab}{module}")
        names = getattr(sol, "__all__", None)
        assert names, f"solutions/{lab}{module.replace('.', '/')}: no __all__"
        assert len(set(names)) == len(names), f"solutions.{lab}{module}.__all__ repeats a name"
        missing = [n for n in names if not hasattr(sol, n)]
        assert not missing, f"solutions.{lab}{module}.__all__ names missing objects: {missing}"
        assert list(stub.__all__) == list(names), f"labs.{lab}{module}.__all__ differs from the solution's"


@pytest.mark.parametrize("lab", LABS)
def test_handout_task_table_matches_the_stubs(lab):
    stubs, handout = stub_tasks(lab), handout_tasks(lab)
    assert stubs, f"labs/{lab}: no NotImplementedError('Task N ...') in the stubs"
    base = {re.match(r"\d+", t).group() for t in stubs}
    # The handout may list sub-tasks (1a, 1b) or only their number (1 with parts (a), (b)).
    expected = stubs if any(t[-1].isalpha() for t in handout) else base
    assert handout == expected, (
        f"labs/{lab}/README.md lists tasks {sorted(handout)}, the stubs raise for tasks {sorted(stubs)}"
    )


def untouched_stub_figure_problems(lab: str, drawn: list[tuple[str, str, np.ndarray]]) -> list[str]:
    """What is wrong with figures drawn from the untouched stubs of ``lab``, given as ``(file name,
    caption, RGB pixels)``: each must be one of the lab's documented figures and be a "Task N not
    implemented yet" page (a page with text, not an empty file) naming a task the stubs leave open.
    Used here for ``make_view`` and by ``tests/test_notebooks.py`` for ``make_figures``, whose
    figures the stubs notebook's figures cell draws (so the suite draws them once)."""
    open_tasks = stub_tasks(lab)
    documented = {p.stem for p in (ROOT / "docs" / "figures" / lab).glob("*.png")} | {f"{lab}_3d"}
    problems = []
    if not drawn:
        problems.append(f"{lab}: no figures drawn from the stubs")
    for name, caption, img in drawn:
        stem = Path(name).stem
        if stem not in documented:
            problems.append(f"{lab}: figure {name} is not in docs/figures/{lab}/")
        m = re.match(r"Task (\d+[a-z]?) not implemented yet", caption)
        if not m:
            problems.append(f"{lab}: {name} drawn from the stubs without a missing task: {caption[:200]}")
        elif m.group(1) not in open_tasks:
            problems.append(f"{lab}: {name} names Task {m.group(1)}, not a stub task")
        if not (img.shape[0] > 100 and (img < 200).any()):
            problems.append(f"{lab}: {name} is not a page with text ({img.shape})")
    return problems


@pytest.mark.parametrize("lab", LABS)
def test_figures_of_the_untouched_stubs_name_the_missing_tasks(lab, tmp_path):
    """``make_view`` here; ``make_figures`` on the stubs is what the lab notebook's figures cell
    runs, checked with the same rules on that run's output (``tests/test_notebooks.py``), and drawn
    here only for a lab without a notebook."""
    from PIL import Image

    figures = importlib.import_module(f"labs.{lab}.figures")
    out = [figures.make_view(tmp_path, quick=True)]
    if not course(ROOT).lab(lab).notebook.is_file():
        out = [*figures.make_figures(tmp_path, quick=True), *out]
    assert out and all(isinstance(f, Figure) for f in out)
    for f in out:
        assert f.path.is_file() and f.path.parent == tmp_path, f.path
    drawn = [(f.path.name, f.caption, np.asarray(Image.open(f.path).convert("RGB"))) for f in out]
    problems = untouched_stub_figure_problems(lab, drawn)
    assert not problems, "\n".join(problems)


def test_make_figures_draws_the_lab_it_is_given(tmp_path):
    """``lab=`` is honoured: the solution's figures drawn with the stubs' functions show missing tasks."""
    figures = importlib.import_module("solutions.vdm.figures")
    stubs = importlib.import_module("labs.vdm")
    out = figures.make_figures(tmp_path, lab=stubs, quick=True)
    assert all("not implemented yet" in f.caption for f in out)
    with pytest.raises(Exception, match="lab must be a module"):
        figures.make_figures(tmp_path, lab="vdm", quick=True)
    assert isinstance(stubs, types.ModuleType)


@contextlib.contextmanager
def panels_spy():
    """``{(figure title, panel index): [(RGB panel, label), ...]}`` of every ``panels`` call made
    inside the block (the lab's figures and the given placeholders both lay their pictures out with
    ``geomlib.plot.panels``): the modules that hold ``panels`` when the block starts call a spy.
    Used here and in the notebooks' runs around their figures cell (``tests/test_notebooks.py``)."""
    import sys

    from geomlib import plot

    real, drawn = plot.panels, {}

    def spy(images, captions=None, *args, **kwargs):
        title = kwargs.get("title", args[1] if len(args) > 1 else None)
        for i, img in enumerate(images):
            drawn.setdefault((title, i), []).append((plot.to_rgb8(img), captions[i] if captions else ""))
        return real(images, captions, *args, **kwargs)

    users = [m for m in list(sys.modules.values()) if getattr(m, "panels", None) is real and m is not plot]
    for m in users:
        m.panels = spy
    try:
        yield drawn
    finally:
        for m in users:
            m.panels = real


def _panels_drawn(figures_module, out_dir) -> dict:
    """:func:`panels_spy` of ``figures_module.make_figures(out_dir, quick=True)``."""
    with panels_spy() as drawn:
        figures_module.make_figures(out_dir, quick=True)
    return drawn


def _stand_in(img: np.ndarray) -> bool:
    """A ``missing_panel`` (light grey with a line of dark text; a colour bar may sit beside it): it
    says "not implemented yet" itself. A crop of one (all grey, no text) says nothing."""
    return bool((img == 225).all(axis=-1).mean() > 0.5 and (img.max(axis=-1) < 120).any())


def _says_missing(label: str) -> bool:
    """A panel label that says a task is missing: "... (not implemented yet: Task 3)", or a
    placeholder's stub message "Task 3 (height to normals): ..."."""
    from geomlib.taskref import task_at_start

    return "not implemented" in label or task_at_start(label) is not None


def stub_panel_problems(lab: str, stub: dict, solution) -> list[str]:
    """The panels of figures drawn from the untouched stubs (``stub``, :func:`panels_spy`) that
    neither say that a task is missing (a grey stand-in, or "not implemented yet" in the label) nor
    show what the solution's show (``solution()``: the solution's panels, drawn only when needed)."""
    unsaid = [
        (key, i, img, label)
        for key, items in stub.items()
        for i, (img, label) in enumerate(items)
        if not _says_missing(label) and not _stand_in(img)
    ]
    if not unsaid:  # every panel is a stand-in or says what it lacks: no need to draw the solution's
        return []
    drawn = solution()
    problems = []
    for key, i, img, label in unsaid:
        ref = drawn.get(key, [])
        if not (i < len(ref) and ref[i][0].shape == img.shape and np.array_equal(ref[i][0], img)):
            problems.append(f"{lab}: panel {key[1]} of {key[0]!r} ({label!r}) differs from the solution's")
    return problems


def notebook_draws_the_quick_figures(lab: str) -> bool:
    """Whether the lab's notebook has one cell that draws the figures as
    :func:`test_every_panel_drawn_from_the_stubs_is_the_solutions_or_says_what_is_missing` does:
    ``make_figures(out, quick=True)`` of ``<the lab's module>.figures``."""
    notebook = course(ROOT).lab(lab).notebook
    if not notebook.is_file():
        return False
    cells = ["".join(c["source"]) for c in json.loads(notebook.read_text())["cells"] if c["cell_type"] == "code"]
    drawing = [c for c in cells if "make_figures(" in c]
    return (
        len(drawing) == 1
        and re.search(r"^\s*for fig in figures\.make_figures\(out, quick=True\):", drawing[0], re.M) is not None
        and re.search(r'figures = importlib\.import_module\(f"\{\w+\.__name__\}\.figures"\)', drawing[0]) is not None
    )


@pytest.mark.parametrize("lab", LABS)
def test_every_panel_drawn_from_the_stubs_is_the_solutions_or_says_what_is_missing(lab, tmp_path):
    """A panel of a figure drawn from the untouched stubs either shows what the solution's shows, or
    says that a task is missing (a grey stand-in, or "not implemented yet" in its label): no blank
    or wrong panel passes for a result (relief's x3 close-up cropped two stand-ins into a blank
    panel; its silhouette outlines compared the cylinder with itself).

    A lab notebook's figures cell that draws ``make_figures(out, quick=True)`` of the lab's figures
    module draws exactly these figures (on the stubs, then on the solutions), and the notebook's
    runs check their panels (``tests/test_notebooks.py``): the suite draws them once, there. Any
    other lab is drawn here."""
    if notebook_draws_the_quick_figures(lab):
        return
    stub = _panels_drawn(importlib.import_module(f"labs.{lab}.figures"), tmp_path / "labs")
    problems = stub_panel_problems(
        lab, stub, lambda: _panels_drawn(importlib.import_module(f"solutions.{lab}.figures"), tmp_path / "solutions")
    )
    assert not problems, "\n".join(problems)
