"""How a lab's figures are assembled: builders, placeholders for missing tasks, the 3D view.

Every lab's ``figures.py`` holds figure *builders*, one function per figure, named with
:func:`figure_name` and returning what they drew as a :class:`Drawn` (the framework writes it to
``<figure_name>.png``), and a view builder returning a :class:`MeshView`. Its last statement,

    make_figures, make_view = lab_figure_makers(LAB, __name__, (fig_a, fig_b), fig_view, quick="...")

gives every lab the same ``make_figures(out_dir, lab=None, quick=False)`` and
``make_view(out_dir, lab=None, quick=False)`` (``tests/test_lab_contracts.py`` checks them). The
file is copied into ``labs/<lab>/`` with the stubs, so there it draws the student's own functions:
a builder stopped by a task that is not implemented yet leaves a "Task N not implemented yet"
picture under its figure's name (:func:`figures_or_placeholders`), and a figure that can draw
some of its panels draws a grey stand-in (:func:`missing_panel`) for the others, notes their tasks
in a :class:`MissingTasks` and names the first in its caption (:func:`partial_figure`).

A caption's numbers are measured, never typed: a builder formats its caption from a template and
the numbers it computed (:meth:`Claims.caption`, :meth:`Drawn.claimed`), and
``tests/test_figure_captions.py`` checks every caption against them.

The pictures themselves are composed with :mod:`geomlib.plot`; the pages are written with
:mod:`geomlib.viewer`.
"""

from __future__ import annotations

import re
import string
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from geomlib.plot import Figure, _font, panels, save_png
from geomlib.taskref import TASK_RUN, find_task
from geomlib.validate import MeshError

__all__ = [
    "Claims",
    "Drawn",
    "MissingTasks",
    "missing_panel",
    "task_label",
    "MeshView",
    "figure_name",
    "lab_figure_makers",
    "lab_package",
    "figures_or_placeholders",
    "missing_task_figure",
    "partial_figure",
]


@dataclass(frozen=True)
class Claims:
    """A caption's template and the numbers its builder measured, so the caption is never typed.

    ``caption()`` is ``template.format(**numbers)``: every number the caption states is one of
    ``numbers``, computed by the builder (a constant the builder itself uses, like a scale, counts:
    it is what the picture was drawn with). ``tests/test_figure_captions.py`` checks that the
    template's own text holds no digits (:meth:`typed_numbers`).

    Attributes
    ----------
    template : str
        The caption with ``{name}`` / ``{name:.2f}`` fields.
    numbers : dict of str to int or float
        The measured values, by field name.
    """

    template: str
    numbers: dict = field(default_factory=dict)

    #: Digits the template's own text may hold, because they define rather than measure: task
    #: numbers, the texture square [0, 1], a year cited "(1994)", names with a digit (3D, 4-tap,
    #: 8-bit, p99, 2r, 8^3, float32) and
    #: the constants of a formula (``1 - h``, ``v > 1``, ``2r/255``). A measured value (a count, an
    #: error, a threshold the builder uses) is a field.
    ALLOWED = (
        TASK_RUN,
        re.compile(r"\[0, 1\]"),
        re.compile(
            r"\((19|20)\d\d\)|\b[a-z]+\d+\b|\b[23]D\b|\b\d+-(tap|bit|point|ring)s?\b|\bp\d+\b|\b\d+[a-z]\b|\b\d+\^\d+"
        ),
        re.compile(r"\b\d+/\d+\b|[<>=/^*·+−]\s?\d+(\.\d+)?|\d+(\.\d+)?\s?[/^*·+−]|\b\d+ - [A-Za-z(]"),
    )

    @classmethod
    def untyped(cls, text: str) -> list[str]:
        """The numbers in ``text`` once the defining ones (:attr:`ALLOWED`) are taken out."""
        for allowed in cls.ALLOWED:
            text = allowed.sub(" ", text)
        return re.findall(r"\d+(?:[.,]\d+)*", text)

    def caption(self) -> str:
        return self.template.format(**self.numbers)

    def typed_numbers(self) -> list[str]:
        """The numbers written into the template's text instead of measured (should be empty)."""
        return self.untyped("".join(literal for literal, *_ in string.Formatter().parse(self.template)))

    def problems(self, caption: str) -> list[str]:
        """What is wrong with ``caption`` as a figure's caption made from these claims."""
        typed = self.typed_numbers()
        out = [f"numbers {typed} typed into the caption template, not measured"] if typed else []
        fields = {name for _, name, _, _ in string.Formatter().parse(self.template) if name}
        out += [f"caption field {{{name}}} has no measured number" for name in sorted(fields - set(self.numbers))]
        bad = [k for k, v in self.numbers.items() if isinstance(v, bool) or not isinstance(v, (int, float, np.number))]
        out += [f"claim {k!r} is not a number" for k in bad]
        if not out and not caption.endswith(self.caption()):
            out.append("the caption is not the template formatted with the measured numbers")
        return out


@dataclass(frozen=True)
class Drawn:
    """What a figure builder drew: the composed picture and its caption, not yet written.

    A builder named with :func:`figure_name` returns one; :func:`figures_or_placeholders` writes
    ``image`` to ``<figure_name>.png`` with :func:`geomlib.plot.save_png` and records it as a
    :class:`geomlib.plot.Figure` of the lab, so the file name is spelled once, in the decorator.
    A builder that writes several files returns its :class:`~geomlib.plot.Figure` records instead.

    Attributes
    ----------
    image : array_like
        The whole picture, usually :func:`geomlib.plot.panels` (anything ``save_png`` accepts).
    caption : str
        One or two sentences saying what the figure shows.
    """

    image: object
    caption: str
    claims: Claims | None = None

    @classmethod
    def claimed(cls, image, template: str, **numbers) -> Drawn:
        """A picture whose caption is ``template`` formatted with the measured ``numbers``."""
        claims = Claims(template, numbers)
        return cls(image, claims.caption(), claims)


class MeshView:
    """What a lab's interactive 3D page shows: a mesh, optional per-vertex scalars, and the caption.

    A lab's view builder returns one; :func:`lab_figure_makers` writes it with
    :func:`geomlib.viewer.write_html` under the builder's :func:`figure_name` (``<lab>_3d.html``).

    Parameters
    ----------
    V, faces, scalars
        The mesh and its optional per-vertex values, as :func:`geomlib.viewer.html_page` takes them
        (``(n, 3)`` positions, ``(m, 3)`` triangles, ``(n,)`` values coloured with ``cmap``).
    caption : str or Claims
        One or two sentences saying what the page shows (the index prints it under the frame); a
        :class:`Claims` when it states measured numbers.
    **options
        Passed on to :func:`geomlib.viewer.html_page` (``title``, ``up``, ``cmap``, ``scalar_name``, ...).
    """

    def __init__(self, V, faces, scalars=None, *, caption: str | Claims, **options):
        self.claims = caption if isinstance(caption, Claims) else None
        self.caption = caption.caption() if isinstance(caption, Claims) else caption
        self.V, self.faces, self.scalars, self.options = V, faces, scalars, options


def lab_package(lab, package: str):
    """The lab whose functions a ``make_figures`` draws: ``lab`` (a module) or the package ``package``.

    Every lab's ``make_figures(out_dir, lab=None, quick=False)`` takes ``lab`` the same way: a module
    that provides the lab's public functions (``solutions.<lab>``, ``labs.<lab>``, a submission
    loaded as a module); None means the package the figures file lives in.
    """
    import importlib
    import types

    if lab is None:
        return importlib.import_module(package)
    if not isinstance(lab, types.ModuleType):
        raise MeshError(
            f"make_figures: lab must be a module providing the lab's functions (or None), got {type(lab).__name__}"
        )
    return lab


def task_label(error: BaseException) -> str:
    """The task a stub's ``NotImplementedError`` names (``"2"``, ``"1a"``), or ``"?"``."""
    m = find_task(str(error))
    return m.label if m else "?"


class MissingTasks(list):
    """The tasks (labels, ``"3"``) whose panels the figure being drawn had to leave out.

    The one way a figure draws what it can: ``missing.attempt(fn, ...)`` returns ``fn(...)``, or
    None after noting the task a stub's ``NotImplementedError`` names; the figure draws a
    :func:`missing_panel` instead, and :func:`partial_figure` (or :meth:`caption_head`) starts its
    caption with the first missing task.
    """

    def attempt(self, fn, *args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except NotImplementedError as e:
            self.append(task_label(e))
            return None

    def caption_head(self) -> str:
        """``"Task N not implemented yet; the other panels show: "`` (N the first missing), or ``""``."""
        return f"Task {self[0]} not implemented yet; the other panels show: " if self else ""


def missing_panel(height: int, width: int, text: str = "not implemented yet") -> np.ndarray:
    """A light grey ``(height, width, 3)`` uint8 panel with ``text``, standing in for a missing picture."""
    import textwrap

    from PIL import Image, ImageDraw

    im = Image.new("RGB", (int(width), int(height)), (225, 225, 225))
    lines = [line for part in text.splitlines() for line in textwrap.wrap(part, max(20, int(width) // 7)) or [""]]
    ImageDraw.Draw(im).multiline_text((10, 10), "\n".join(lines), fill=(90, 90, 90))
    return np.asarray(im)


def missing_task_figure(path, error: BaseException, lab: str, *, what: str = "") -> Figure:
    """A placeholder figure saying which task is missing, written where the real figure would go.

    Parameters
    ----------
    path : str or Path
        The PNG to write (the name the finished figure will have).
    error : NotImplementedError
        Raised by a stub; its message starts with the task (``"Task 2 (even vertices): ..."``).
    lab : str
        The lab name for the figure record.
    what : str
        What the figure will show once the task is done (goes into the caption).
    """
    msg = str(error).strip() or type(error).__name__
    m = find_task(msg)
    head = f"Task {m.label} not implemented yet" if m else "not implemented yet"
    blank = np.full((160, 560, 3), 244, dtype=np.uint8)
    img = panels([blank], [msg if len(msg) <= 300 else msg[:297] + "..."], title=Path(path).stem, font_size=14)
    # Write the head into the grey box too, so a thumbnail still says it.
    from PIL import Image, ImageDraw

    page = Image.fromarray(img)
    draw = ImageDraw.Draw(page)
    font = _font(22, bold=True)
    w = draw.textlength(head, font=font)
    top = img.shape[0] // 2 - 40
    draw.text(((img.shape[1] - w) / 2, top), head, fill=(150, 40, 30), font=font)
    path = save_png(path, np.asarray(page))
    caption = (
        f"{head}, so {Path(path).name} cannot be drawn yet" + (f" (it will show {what})" if what else "") + f". {msg}"
    )
    return Figure(path, caption, lab)


def figures_or_placeholders(builders, out_dir, lab_name: str, *args) -> list[Figure]:
    """Run figure builders; a builder stopped by a missing task gives a placeholder figure instead.

    Parameters
    ----------
    builders : sequence of callables
        ``build(out_dir, *args)`` returning a :class:`Drawn` (written here to ``out_dir / "<name>.png"``),
        one :class:`Figure` or a list of them. ``<name>`` is the builder's ``figure_name`` attribute or
        its name without the ``fig_`` / ``_fig_`` / ``_`` prefix; a builder stopped by a missing task
        gets its placeholder under the same name.
    out_dir : Path
    lab_name : str
    *args
        Passed on to every builder.

    Returns
    -------
    list of Figure
        In builder order; students see every figure their finished tasks allow, and one
        "Task N not implemented yet" picture for each of the others.
    """
    figures: list[Figure] = []
    for build in builders:
        name = getattr(build, "figure_name", None) or build.__name__.removeprefix("_").removeprefix("fig_")
        path = Path(out_dir) / f"{name}.png"
        try:
            out = build(out_dir, *args)
        except NotImplementedError as e:
            out = missing_task_figure(path, e, lab_name)
        items = out if isinstance(out, list) else [out]
        if len(items) > 1 and any(isinstance(item, Drawn) for item in items):
            raise MeshError(
                f"figure builder {build.__name__} returned several pictures as Drawn; only one can be "
                f"written under its figure_name ({name}.png): return Figure records for the others"
            )
        for item in items:
            if isinstance(item, Drawn):
                item = Figure(save_png(path, item.image), item.caption, lab_name, item.claims)
            elif not isinstance(item, Figure):
                raise MeshError(
                    f"figure builder {build.__name__} returned {type(item).__name__}; "
                    "expected a Drawn (image and caption), a Figure or a list of Figures"
                )
            figures.append(item)
    return figures


def figure_name(name: str):
    """Decorator: the file name (without suffix) a figure builder writes.

    :func:`figures_or_placeholders` writes the :class:`Drawn` picture the builder returns to
    ``<name>.png``, and before its task is done a "Task N not implemented yet" picture under the same
    name, so a student's unfinished figure sits where the finished one will be.

    Examples
    --------
    >>> @figure_name("loop_levels")
    ... def fig_levels(out, lab, quick): ...
    >>> fig_levels.figure_name
    'loop_levels'
    """

    def mark(build):
        build.figure_name = name
        return build

    return mark


def partial_figure(build, missing: MissingTasks):
    """Wrap a figure builder that draws grey panels for missing tasks instead of stopping.

    Some figures still show what they can when one of their panels needs a task that is not
    implemented yet: the builder draws a stand-in panel and appends the task's label (``"3"``,
    ``"1a"``) to ``missing``. The wrapped builder empties ``missing``, draws, and where panels were
    left out starts every caption with ``"Task N not implemented yet; the other panels show: "``
    (``N`` the first missing task), so the figure index says what is missing.

    Parameters
    ----------
    build : callable
        ``build(out_dir, *args)`` returning a :class:`Drawn`, one :class:`Figure` or a list of them.
    missing : MissingTasks
        The list the builder's stand-in panels append to (a plain list of labels works too).

    Returns
    -------
    callable
        ``drawn(out_dir, *args)`` returning what ``build`` returns (as a list), captions amended, with
        ``build``'s ``figure_name`` and name.
    """

    def drawn(out_dir, *args) -> list:
        missing.clear()
        out = build(out_dir, *args)
        figs = out if isinstance(out, list) else [out]
        head = MissingTasks.caption_head(missing)
        if head:
            figs = [replace(f, caption=head + f.caption) for f in figs]
        return figs

    drawn.__name__ = build.__name__
    drawn.figure_name = getattr(build, "figure_name", None)
    return drawn


#: The docstrings of the made functions; ``{args}`` is :data:`_ARGS_DOC` (the same three arguments).
_MAKE_FIGURES_DOC = """Render the lab's figures into ``out_dir`` and return them with their captions.

Parameters
----------
out_dir : str or Path
    Folder for the PNG files (created if missing).
{args}
Returns
-------
list of Figure
    Every figure; one whose tasks are not implemented yet is a picture saying
    "Task N not implemented yet" (under the same file name).
"""

_MAKE_VIEW_DOC = """Write ``{stem}.html``, the lab's interactive 3D view (:mod:`geomlib.viewer`), into ``out_dir``.

Open the page in a browser and turn the result with the mouse; ``geomlib figures`` shows it in
the index.

Parameters
----------
out_dir : str or Path
    Folder for the page (created if missing).
{args}
Returns
-------
Figure
    The page; before the tasks it needs are implemented, a "Task N not implemented yet" picture
    (``{stem}.png``) instead.
"""

_ARGS_DOC = """lab : module, optional
    {lab_doc}
quick : bool
    {quick}
"""


def lab_figure_makers(
    lab_name: str, module: str, builders, view, *, quick: str, shared: dict | None = None, draws_lab: bool = True
):
    """A lab's ``make_figures`` and ``make_view``, built the same way for every lab.

    Every lab's ``figures.py`` ends with::

        make_figures, make_view = lab_figure_makers(LAB, __name__, (fig_a, fig_b), fig_view, quick="...")

    and so offers ``make_figures(out_dir, lab=None, quick=False) -> list[Figure]`` and
    ``make_view(out_dir, lab=None, quick=False) -> Figure`` with full docstrings. Both create
    ``out_dir``, resolve ``lab`` with :func:`lab_package` (a module of the lab's functions; None: the
    package ``module`` is in, so in ``labs/<lab>/`` the student's own code) and run the builders
    through :func:`figures_or_placeholders`, so a figure whose task is missing becomes a
    "Task N not implemented yet" picture under its own name (:func:`figure_name`).

    Parameters
    ----------
    lab_name : str
        The lab (``"subdivision"``): the figures' ``lab`` and the package named in the docstrings.
    module : str
        ``__name__`` of the figures module (``"solutions.subdivision.figures"``): where the made
        functions say they live, and whose package is the default ``lab``.
    builders : sequence of callables
        The figures, in order: ``build(out_dir, L, quick)`` with ``L`` the lab module (or
        ``build(out_dir, quick)`` when ``draws_lab`` is False), returning a :class:`Drawn` (written to
        ``<figure_name>.png``), a :class:`Figure` or a list of Figures.
    view : callable
        The interactive 3D page: ``view(L, quick)`` (or ``view(quick)``) returning a :class:`MeshView`,
        written to ``<figure_name>.html`` (:func:`figure_name`; default ``<lab>_3d``).
    quick : str
        What ``quick=True`` makes smaller (one sentence, for the docstrings).
    shared : dict, optional
        Results the builders share across figures (a mesh several figures draw); emptied before
        and after every call, so no call sees another lab module's results.
    draws_lab : bool
        False for a lab whose figures call the package they sit in directly (``lab`` is then
        checked but not used, and the docstrings say so).

    Returns
    -------
    (make_figures, make_view)
    """
    package = module.rpartition(".")[0]
    if draws_lab:
        lab_doc = (
            f"The lab package whose functions the figures draw (``solutions.{lab_name}``, ``labs.{lab_name}``, a\n"
            f"    submission); default: the package this file is in, so in ``labs/{lab_name}/`` your own code."
        )
    else:
        lab_doc = (
            "Not used: the figures draw the functions of the package this file is in (so in\n"
            f"    ``labs/{lab_name}/`` your own code); a value other than None must still be a module."
        )

    def run(chosen, out_dir, lab, quick_: bool) -> list[Figure]:
        L = lab_package(lab, package)
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        args = (L, quick_) if draws_lab else (quick_,)
        if shared is not None:
            shared.clear()
        try:
            return figures_or_placeholders(chosen, out, lab_name, *args)
        finally:
            if shared is not None:
                shared.clear()

    def make_figures(out_dir, lab=None, quick: bool = False) -> list[Figure]:
        return run(builders, out_dir, lab, quick)

    stem = getattr(view, "figure_name", None) or f"{lab_name}_3d"

    @figure_name(stem)
    def page(out_dir: Path, *args) -> Figure:
        from geomlib.viewer import write_html

        shown = view(*args)
        path = write_html(out_dir / f"{stem}.html", shown.V, shown.faces, shown.scalars, **shown.options)
        return Figure(path, shown.caption, lab_name, shown.claims)

    def make_view(out_dir, lab=None, quick: bool = False) -> Figure:
        return run((page,), out_dir, lab, quick)[0]

    arg_doc = _ARGS_DOC.format(lab_doc=lab_doc, quick=quick)
    make_figures.__doc__ = _MAKE_FIGURES_DOC.format(args=arg_doc)
    make_view.__doc__ = _MAKE_VIEW_DOC.format(args=arg_doc, stem=stem)
    for fn in (make_figures, make_view):
        fn.__module__ = module
        fn.__qualname__ = fn.__name__
    return make_figures, make_view
