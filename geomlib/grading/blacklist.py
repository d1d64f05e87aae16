"""Per-lab blacklists: library functions a lab's student code may not call.

Each lab declares, in one place, the library functions that would do its tasks for the student
(``NOT_ALLOWED`` in ``tests/graded/<lab>/__init__.py``: ``{"igl.signed_distance": "Task 4 asks you
to write it", ...}``); its handout lists the same names under "Not allowed" (a test checks that).

Grader side, :func:`declared` reads the declaration and :mod:`geomlib.grading.sandbox` sends it with
every call. Worker side, :func:`install` (run in the forked worker, before the submission is
imported) replaces each named function by a *guard* that raises :class:`NotAllowedError` ("not
allowed in the sdf lab: igl.signed_distance — Task 4 asks you to write it") when the call comes from
the student's code and calls the real function otherwise. The guard replaces the function

- in every loaded module that holds it (so ``igl.signed_distance``, ``from igl import
  signed_distance``, ``importlib.import_module("igl")``, ``getattr`` and the compiled extension
  module ``igl.pyigl_core`` all give the guard), and in the class that defines a method;
- in modules imported later (an import hook patches a watched package as soon as it is executed);
- in an extension module loaded again (``_imp.create_dynamic`` re-applies the guards to what it
  returns: reloading ``pyigl_core.so`` would otherwise restore the raw functions).

Who is calling: the guard walks the Python stack outwards from its caller. Library frames (NumPy,
trimesh, geomlib, ...) are skipped; the first frame that is either *given code* (a statement of the
course's stub, compiled by :class:`geomlib.grading.worker._MergedLoader` and recorded by
:func:`given`, matched by code-object identity so a file name cannot impersonate it) or *student
code* (a code object whose file is inside the submission's folder) decides: given code may call the
function, student code may not, and a stack with neither (a thread the student started) may not.
So a given helper that uses the function keeps working when the student calls the helper, and a
library function that calls it for the student (``trimesh.Trimesh.subdivide_loop`` calling
``trimesh.remesh.subdivide_loop``) is caught too.

Not covered (an in-process guard cannot be): digging the raw function out of the guard's closure or
with ``gc``, switching the guard off through its own state (it is Python objects in the student's
process, like everything else there), calling into the shared library with ``ctypes``, or passing
the function itself as a callback to a given helper that calls whatever it receives. Each of these
is deliberate tampering that shows in the submitted code; every ordinary way of calling the
function (what the handout forbids) is caught. The grader's own checks run in the
grader's process, where nothing is replaced.
"""

from __future__ import annotations

import ast
import importlib.abc
import os
import sys
from pathlib import Path

__all__ = ["NotAllowedError", "declared", "install", "given", "handout_section", "handout_sections"]

#: The title of the handout's section that lists a lab's blacklist (``labs/<lab>/README.md``), at
#: heading level 2 or 3.
HANDOUT_TITLE = "Not allowed"


class NotAllowedError(RuntimeError):
    """A student's code called a library function its lab forbids."""


# ---------------------------------------------------------------------------------- grader side


def declared(lab: str, tests_dir: Path | None = None) -> dict[str, str]:
    """The lab's ``NOT_ALLOWED`` (``{"module.function": why}``) from ``tests/graded/<lab>/__init__.py``.

    Read as a literal (nothing of the file is executed); ``{}`` when the lab declares none.

    Raises
    ------
    ValueError
        The declaration is not a literal ``dict`` of strings (naming the file).
    """
    from geomlib.grading.course import course

    c = course()
    path = c.lab(lab).package
    if tests_dir is not None:  # another tests folder, laid out as the course's
        path = Path(tests_dir) / path.relative_to(c.tests_dir)
    if not path.is_file():
        return {}
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in tree.body:
        targets = (
            node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        )
        if any(isinstance(t, ast.Name) and t.id == "NOT_ALLOWED" for t in targets):
            try:
                value = ast.literal_eval(node.value)
            except ValueError:
                value = None
            if not isinstance(value, dict) or not all(
                isinstance(k, str) and isinstance(v, str) for k, v in value.items()
            ):
                raise ValueError(f"{path}: NOT_ALLOWED must be a literal dict {{'module.function': 'why'}}")
            bad = [k for k in value if not all(part.isidentifier() for part in k.split(".")) or "." not in k]
            if bad:
                raise ValueError(f"{path}: NOT_ALLOWED names must be dotted Python names (module.function): {bad}")
            return dict(value)
    return {}


def handout_section(entries: dict[str, str], level: int = 3) -> str:
    """The Markdown of the handout's "Not allowed" section for ``entries`` (what the handout must hold)."""
    lines = [
        "#" * level + " " + HANDOUT_TITLE,
        "",
        "The grader makes these functions raise an error when your code calls them, directly or through",
        "another library function (use them freely in a notebook to check your results):",
        "",
    ]
    lines += [f"- `{name}` — {why}" for name, why in entries.items()]
    return "\n".join(lines) + "\n"


def handout_sections(readme_text: str) -> list[str]:
    """Every "Not allowed" section of a handout, each from its heading to the next heading."""
    lines = readme_text.splitlines()
    out = []
    for i, line in enumerate(lines):
        level = len(line) - len(line.lstrip("#"))
        if level in (2, 3) and line[level:].strip() == HANDOUT_TITLE:
            end = next((k for k in range(i + 1, len(lines)) if lines[k].startswith("#")), len(lines))
            out.append("\n".join(lines[i:end]).rstrip("\n") + "\n")
    return out


# ---------------------------------------------------------------------------------- worker side

_GIVEN: set[int] = set()  # ids of the given code objects (kept alive by _GIVEN_CODE)
_GIVEN_CODE: list = []


def given(code) -> None:
    """Record a code object (and those nested in it) compiled from the course's stub: given code."""
    todo = [code]
    while todo:
        c = todo.pop()
        if id(c) in _GIVEN:
            continue
        _GIVEN.add(id(c))
        _GIVEN_CODE.append(c)
        todo.extend(k for k in c.co_consts if hasattr(k, "co_code"))


#: Built by the zygote before it forks (:func:`prepare`), per lab's entries: ``(loaded, where)``,
#: ``loaded`` the module objects loaded then (``name -> id``), ``where`` the id of each declared
#: function loaded then -> the names of the modules whose namespace referenced it. A worker's search
#: for references then reads only those modules and the ones loaded after the fork, instead of the
#: namespace of every loaded module (about 1000; a fifth of a short call's CPU, copy-on-write pages).
_INDEX: dict = {}


def _index_key(entries: dict[str, str]) -> tuple:
    return tuple(sorted(entries))


def prepare(entries: dict[str, str] | None) -> None:
    """In the zygote (nothing of a submission loaded): index where the declared functions are referenced."""
    if not entries:
        return
    resolver = _Guards("", os.sep, entries)
    raw = [found[2] for name in entries if (found := resolver._resolve(name)) is not None]  # may import
    loaded = {name: id(mod) for name, mod in list(sys.modules.items())}
    key = _index_key(entries)
    if key in _INDEX and _INDEX[key][0] == loaded:
        return
    where: dict[int, set[str]] = {id(fn): set() for fn in raw}
    for name, mod in list(sys.modules.items()):
        try:
            d = vars(mod)
        except TypeError:
            continue
        for i in where.keys() & set(map(id, list(d.values()))):
            where[i].add(name)
    _INDEX[key] = (loaded, where, raw)  # raw keeps the ids valid


class _Guards:
    """The installed guards of one worker (one lab, one submission)."""

    def __init__(self, lab: str, lab_dir: str, entries: dict[str, str]):
        self.lab = lab
        self.prefix = os.path.realpath(lab_dir).rstrip(os.sep) + os.sep
        self.raw_prefix = os.path.abspath(lab_dir).rstrip(os.sep) + os.sep
        self.pending = dict(entries)
        self.guard_of: dict[int, object] = {}  # id(raw function) -> guard
        self.raw: list = []  # keeps the raw functions alive (their ids stay valid)
        self.roots = {name.split(".")[0] for name in entries}
        self.index = _INDEX.get(_index_key(entries))

    # -- who is calling

    def _student_frame(self, code) -> bool:
        f = code.co_filename
        return f.startswith(self.prefix) or f.startswith(self.raw_prefix)

    def forbidden_here(self, frame) -> bool:
        while frame is not None:
            code = frame.f_code
            if id(code) in _GIVEN:
                return False
            if self._student_frame(code):
                return True
            frame = frame.f_back
        return True

    # -- the guard

    def make_guard(self, name: str, why: str, fn):
        guards = self
        message = f"not allowed in the {self.lab} lab: {name} — {why}"

        def guard(*args, **kwargs):
            if guards.forbidden_here(sys._getframe(1)):
                raise NotAllowedError(message)
            return fn(*args, **kwargs)

        guard.__name__ = getattr(fn, "__name__", name.rsplit(".", 1)[-1])
        guard.__qualname__ = getattr(fn, "__qualname__", guard.__name__)
        guard.__doc__ = getattr(fn, "__doc__", None)
        guard.__module__ = getattr(fn, "__module__", None)
        return guard

    # -- finding and replacing

    def _resolve(self, name: str):
        """``(owner, attribute, raw)`` for a loaded ``name``, or None (its module is not loaded yet)."""
        parts = name.split(".")
        obj = sys.modules.get(parts[0])
        if obj is None:
            return None
        owner = obj
        for i, part in enumerate(parts[1:], start=1):
            sub = sys.modules.get(".".join(parts[: i + 1]))
            owner = obj
            if sub is not None and i < len(parts) - 1:
                obj = sub
                continue
            try:
                obj = getattr(obj, part)
            except Exception:  # noqa: BLE001 - not there (yet): a submodule not imported
                return None
        attr = parts[-1]
        if isinstance(owner, type):
            for klass in owner.__mro__:
                if attr in vars(klass):
                    raw = vars(klass)[attr]
                    if isinstance(raw, staticmethod | classmethod):
                        return None  # not used by any declaration; left alone rather than half-guarded
                    return klass, attr, raw
            return None
        return owner, attr, obj

    def apply(self, module=None) -> None:
        """Guard every declared function whose module is loaded, everywhere it is referenced.

        After the import of ``module`` only that module is searched unless a declared function
        was found for the first time (then every loaded module is).
        """
        new = []
        for name in list(self.pending):
            found = self._resolve(name)
            if found is None:
                continue
            owner, attr, raw = found
            why = self.pending.pop(name)
            guard = self.guard_of.get(id(raw))
            if guard is None:
                guard = self.guard_of[id(raw)] = self.make_guard(name, why, raw)
                self.raw.append(raw)
            try:
                setattr(owner, attr, guard)
            except (AttributeError, TypeError):
                pass
            new.append(id(raw))
        if new:
            for mod in self._may_refer(new):
                self.patch_module(mod)
        elif module is not None and self.guard_of:
            self.patch_module(module)

    def _may_refer(self, new: list[int]) -> list:
        """The loaded modules that may reference a function of ``new`` (ids): every module, unless the
        zygote's index saw every guarded function; then the modules it lists for ``new`` and those
        loaded or replaced after the fork (the references to functions guarded before are patched)."""
        modules = list(sys.modules.items())
        if self.index is None or any(i not in self.index[1] for i in self.guard_of):
            return [mod for _, mod in modules]  # no index, or a function the zygote did not see
        loaded, where, _ = self.index
        listed = set().union(*(where[i] for i in new))
        return [mod for name, mod in modules if loaded.get(name) != id(mod) or name in listed]

    def patch_module(self, mod) -> None:
        try:
            d = vars(mod)
        except TypeError:
            return
        if self.guard_of.keys().isdisjoint(map(id, list(d.values()))):
            return  # the common case, at C speed (every loaded module is searched once per worker)
        for key, value in list(d.items()):
            g = self.guard_of.get(id(value))
            if g is not None:
                try:
                    d[key] = g
                except TypeError:
                    pass


class _Watch(importlib.abc.MetaPathFinder):
    """Patches a watched package's modules right after they are executed (imported after install)."""

    def __init__(self, guards: _Guards):
        self.guards = guards
        self.busy = False

    def find_spec(self, fullname, path=None, target=None):
        if self.busy or fullname.split(".")[0] not in self.guards.roots:
            return None
        self.busy = True
        try:
            for finder in sys.meta_path:
                if finder is self or not hasattr(finder, "find_spec"):
                    continue
                spec = finder.find_spec(fullname, path, target)
                if spec is not None:
                    break
            else:
                return None
        finally:
            self.busy = False
        if spec.loader is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = _PatchingLoader(spec.loader, self.guards)
        return spec


class _PatchingLoader(importlib.abc.Loader):
    def __init__(self, inner, guards: _Guards):
        self._inner, self._guards = inner, guards

    def create_module(self, spec):
        return self._inner.create_module(spec)

    def exec_module(self, module):
        self._inner.exec_module(module)
        self._guards.apply(module)

    def __getattr__(self, name):
        return getattr(self._inner, name)


def install(lab: str, lab_dir: str, entries: dict[str, str] | None) -> None:
    """Guard the lab's declared functions in this (worker) process (see the module docstring)."""
    if not entries:
        return
    guards = _Guards(lab, lab_dir, entries)
    guards.apply()
    sys.meta_path.insert(0, _Watch(guards))
    import _imp

    create = _imp.create_dynamic

    def create_dynamic(*args, **kwargs):
        module = create(*args, **kwargs)
        guards.patch_module(module)
        return module

    _imp.create_dynamic = create_dynamic
