"""Which task of a lab each function, case and graded test belongs to.

A lab's tasks are marked in its source: ``# BEGIN SOLUTION: Task 2 (even vertices): ...`` in the
solutions, ``raise NotImplementedError("Task 2 (even vertices): ...")`` in the stubs. A function's
tasks are the markers inside it, the first one being its main task (``loop_odd_matrix`` is Task 1,
with Task 4's boundary rule inside). A function without markers that calls task functions (a
*composite*, such as ``catmull_clark``) belongs to the tasks of what it calls.

Students edit the stubs, so the markers disappear as they work: each lab therefore *declares* its
table in ``tests/graded/<lab>/diagnose.py`` (``TASKS``, ``TITLES``, ``COMPOSITES``), and a framework
test checks that the declaration matches what :func:`derive` reads from the solutions.

A graded test's tasks: those it declares (``Case(tasks=...)``, ``graded(tasks=...)``: where a
parameter runs a later task), else the task whose title is the test's part ("boundary rules" is
Task 4), else the main tasks of the lab functions it calls (``Case.function``, or
``lab.<name>(...)`` in a hand-written test). ``--task N`` runs the tests whose latest task is N
(:func:`selects`).
"""

from __future__ import annotations

import ast
import inspect
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.gl import SHADER_FOLDER
from geomlib.grading.course import course
from geomlib.grading.registry import graded_module
from geomlib.taskref import find_task

__all__ = [
    "TaskTable",
    "derive",
    "table",
    "lab_calls",
    "named_functions",
    "test_functions",
    "test_tasks",
    "test_runs",
    "selects",
]

#: A shader named in a lab function: ``"parallax"`` (``shaders/parallax.frag``) or ``"tbn.vert"``.
_SHADER = re.compile(r"[A-Za-z_]\w*(\.(?:frag|vert))?")


@dataclass
class TaskTable:
    """A lab's tasks.

    Attributes
    ----------
    tasks : dict
        ``{function: (main task, other tasks...)}`` for functions that hold a student part.
    titles : dict
        ``{task number: title}`` (the first title a task is marked with).
    composites : dict
        ``{function: (building-block functions...)}``, blocks in task order, for functions that call
        task functions (whether or not they hold a part themselves).
    """

    tasks: dict = field(default_factory=dict)
    titles: dict = field(default_factory=dict)
    composites: dict = field(default_factory=dict)

    def of_function(self, name: str) -> tuple[int, ...]:
        """The tasks a call of ``name`` exercises: its main task, else its blocks' main tasks."""
        if name in self.tasks:
            return self.tasks[name][:1]
        out = []
        for b in self.composites.get(name, ()):
            for t in self.tasks.get(b, ())[:1]:
                if t not in out:
                    out.append(t)
        return tuple(sorted(out))

    def runs(self, name: str) -> tuple[int, ...]:
        """Every task a call of ``name`` runs: its own and all its blocks' main tasks."""
        out = set(self.of_function(name))
        for b in self.composites.get(name, ()):
            out |= set(self.tasks.get(b, ())[:1])
        return tuple(sorted(out))

    def of_part(self, part: str) -> int | None:
        """The task whose title is ``part`` (case and a leading "the" ignored), else None."""
        key = _norm(part)
        for n, title in self.titles.items():
            if _norm(title) == key:
                return n
        return None

    def describe(self, n: int) -> str:
        return f"Task {n}: {self.titles[n]}" if n in self.titles else f"Task {n}"


def _norm(s: str) -> str:
    s = s.strip().lower()
    return s[4:] if s.startswith("the ") else s


def derive(lab_dir: str | Path) -> TaskTable:
    """Read the task table from a lab's source (solutions or untouched stubs)."""
    funcs: dict[str, tuple[list, set]] = {}
    shader_marks: list[tuple[int, str, str]] = []  # (task, title, function running the shader)
    for path in sorted(Path(lab_dir).glob("*.py")):
        if path.name == "figures.py":
            continue
        src = path.read_text()
        lines = src.splitlines()
        tree = ast.parse(src)
        modules = _lab_module_aliases(tree)
        for node in tree.body:
            if not isinstance(node, ast.FunctionDef):
                continue
            marks = _marks(lines[node.lineno - 1 : node.end_lineno])
            # A function that runs one of the lab's shaders (``_run("parallax", ...)``) holds the
            # shader's tasks: the student writes them in ``shaders/parallax.frag``.
            for n in ast.walk(node):
                if isinstance(n, ast.Constant) and isinstance(n.value, str) and _SHADER.fullmatch(n.value):
                    shader = Path(lab_dir) / SHADER_FOLDER / (n.value if "." in n.value else f"{n.value}.frag")
                    if shader.is_file():
                        shader_marks += [(n, t, node.name) for n, t in _marks(shader.read_text().splitlines())]
            calls = set()
            for n in ast.walk(node):
                if not isinstance(n, ast.Call):
                    continue
                if isinstance(n.func, ast.Name):
                    calls.add(n.func.id)
                elif (  # ``K.split(...)`` after ``from . import kernels as K``
                    isinstance(n.func, ast.Attribute)
                    and isinstance(n.func.value, ast.Name)
                    and n.func.value.id in modules
                ):
                    calls.add(n.func.attr)
            funcs[node.name] = (marks, calls)
    t = TaskTable()
    for name, (marks, _) in funcs.items():
        if marks:
            nums = []
            for n, title in marks:
                if n not in nums:
                    nums.append(n)
                t.titles.setdefault(n, title)
            t.tasks[name] = tuple(nums)
    for n, title, name in shader_marks:  # after the Python markers: those name the tasks
        t.titles.setdefault(n, title)
        if n not in t.tasks.get(name, ()):
            t.tasks[name] = (*t.tasks.get(name, ()), n)

    def blocks(name, seen):
        out = set()
        for c in funcs.get(name, ((), set()))[1]:
            if c in seen or c not in funcs:
                continue
            seen.add(c)
            if c in t.tasks:
                out.add(c)
            out |= blocks(c, seen)
        return out

    for name in funcs:
        b = blocks(name, {name})
        if b:
            t.composites[name] = tuple(sorted(b, key=lambda f: (t.tasks[f][0], f)))
    t.titles = dict(sorted(t.titles.items()))
    return t


def _marks(lines) -> list[tuple[int, str]]:
    """``(task, title)`` of the task markers among ``lines`` (Python or GLSL, solution or stub)."""
    out = []
    for line in lines:
        m = find_task(line, titled=True)
        if m and ("BEGIN SOLUTION" in line or "NotImplementedError" in line or "#error" in line):
            out.append((m.number, m.title.strip()))
    return out


def _lab_module_aliases(tree) -> set[str]:
    """Names under which a lab file imports the lab's own modules (``from . import kernels as K``)."""
    out = set()
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.level >= 1 and not node.module:
            out |= {a.asname or a.name for a in node.names}
    return out


def _declared(lab: str):
    return graded_module(lab, "diagnose")


def table(lab: str) -> TaskTable:
    """The lab's declared task table, else the one derived from its solutions or stubs."""
    mod = _declared(lab)
    if mod is not None and hasattr(mod, "TASKS"):
        return TaskTable(dict(mod.TASKS), dict(mod.TITLES), dict(getattr(mod, "COMPOSITES", {})))
    paths = course().lab(lab)
    for d in (paths.solution, paths.stubs):
        if d.is_dir():
            return derive(d)
    return TaskTable()


def lab_calls(fn) -> list[str]:
    """Lab functions a hand-written test uses: ``lab.name(...)``, ``lab.call("name", ...)`` and
    ``lab.name`` passed on (``applied(lab.split_edge, ...)``), directly or through a helper defined
    in the same test module.

    Parameters
    ----------
    fn : function
        The test function (its source is read; none readable: ``[]``).

    Returns
    -------
    list of str
        The function names, in order of first use.
    """
    key = _key(fn)
    if key in _CALLS:  # every check() cell of a notebook collects the same tests again
        return list(_CALLS[key])
    tree = _tree(fn)
    if tree is None:
        return []
    out = _direct_lab_calls(fn, tree)
    module = sys.modules.get(getattr(fn, "__module__", ""), None)
    for n in ast.walk(tree):
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name):
            g = getattr(module, n.func.id, None)
            if inspect.isfunction(g) and g.__module__ == fn.__module__ and g is not fn:
                for name in _direct_lab_calls(g):
                    if name not in out:
                        out.append(name)
    _CALLS[key] = tuple(out)
    return out


#: :func:`lab_calls` by function (the same key as :data:`_TREES`).
_CALLS: dict = {}


def _key(fn) -> tuple:
    """A function's key in the caches below: module, name and code object (a reloaded test module
    parses again)."""
    return (getattr(fn, "__module__", None), getattr(fn, "__qualname__", None), getattr(fn, "__code__", None))


def _dedent(fn) -> str:
    import textwrap

    return textwrap.dedent(inspect.getsource(fn))


def _tree(fn):
    """The syntax tree of ``fn``'s source, or None where it has no readable source (parsed once
    per function: a ``--task N`` run asks for every collected test's tasks)."""
    key = _key(fn)
    if key not in _TREES:
        try:
            _TREES[key] = ast.parse(_dedent(fn))
        except (OSError, TypeError, SyntaxError):
            _TREES[key] = None
    return _TREES[key]


#: :func:`_tree` by function (module, name and code object: a reloaded test module parses again).
_TREES: dict = {}


def _direct_lab_calls(fn, tree=None) -> list[str]:
    key = _key(fn)
    if tree is None and key in _DIRECT:  # a helper asked for by every test that calls it
        return list(_DIRECT[key])
    tree = _tree(fn) if tree is None else tree
    if tree is None:
        return []
    out = []
    for n in ast.walk(tree):
        name = None
        if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id == "lab":
            name = n.attr if n.attr != "call" else None
        elif (
            isinstance(n, ast.Call)
            and isinstance(n.func, ast.Attribute)
            and isinstance(n.func.value, ast.Name)
            and n.func.value.id == "lab"
            and n.func.attr == "call"
            and n.args
            and isinstance(n.args[0], ast.Constant)
        ):
            name = str(n.args[0].value)
        if name is not None and name not in out:
            out.append(name)
    _DIRECT[key] = tuple(out)
    return out


#: :func:`_direct_lab_calls` by function (the same key as :data:`_TREES`).
_DIRECT: dict = {}


def named_functions(fn, tab: TaskTable) -> list[str]:
    """Lab functions a test names in a string (``check_glsl_case(lab, case, "glsl_parallax_uv")``):
    the string constants of ``fn``'s source that are functions of the task table ``tab``, in order."""
    key = _key(fn)
    if key not in _STRINGS:
        tree = _tree(fn)
        found = (
            []
            if tree is None
            else [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
        )
        _STRINGS[key] = tuple(dict.fromkeys(found))
    return [s for s in _STRINGS[key] if s in tab.tasks or s in tab.composites]


#: The string constants of a function's source, in order, once each (the same key as :data:`_TREES`).
_STRINGS: dict = {}


def test_functions(item, tab: TaskTable) -> list[str]:
    """The lab functions a collected graded pytest item calls, as the grader reads them: a reference
    case's ``Case.function``, else :func:`lab_calls` and then :func:`named_functions` of the test."""
    callspec = getattr(item, "callspec", None)
    case = callspec.params.get("case") if callspec is not None else None
    if case is not None and hasattr(case, "function"):
        return [case.function]
    names = lab_calls(item.function)
    return names + [n for n in named_functions(item.function, tab) if n not in names]


def test_tasks(item, tab: TaskTable, part: str) -> tuple[int, ...]:
    """The tasks of a collected graded pytest item (see the module docstring)."""
    marker = item.get_closest_marker("graded")
    callspec = getattr(item, "callspec", None)
    case = callspec.params.get("case") if callspec is not None else None
    declared = getattr(case, "tasks", ()) or (marker.kwargs.get("tasks", ()) if marker is not None else ())
    if declared:
        return tuple(sorted(int(t) for t in declared))
    n = tab.of_part(part)
    if n is not None:
        return (n,)
    out: list[int] = []
    for name in test_functions(item, tab):
        for t in tab.of_function(name):
            if t not in out:
                out.append(t)
    return tuple(sorted(out))


def selects(tasks: tuple[int, ...], n: int, every_test: bool = False) -> bool:
    """Whether ``--task n`` selects a graded test of ``tasks`` (:func:`test_tasks`): the tests whose
    latest task is ``n``, the ones a student who does the tasks in order can pass once Task ``n`` is
    done. A test that needs a later task too is that task's (remeshing's ``split_long_edges`` case runs
    Task 1's ``split`` through Task 4's pass: Task 4's), so ``--task 1`` on the stubs names no later
    task's "not implemented". ``every_test``: every test that needs ``n`` (the mutation audit)."""
    return n in tasks if every_test else bool(tasks) and max(tasks) == n


def test_runs(item, tab: TaskTable) -> tuple[int, ...]:
    """Every task a collected graded test runs (its functions and their building blocks): what
    ``--task N`` falls back to for a task that has no test of its own (remeshing's collapse pass,
    graded through the loop)."""
    return tuple(sorted({t for name in test_functions(item, tab) for t in tab.runs(name)}))


test_tasks.__test__ = False  # not a pytest test, despite the name
test_runs.__test__ = False
test_functions.__test__ = False
