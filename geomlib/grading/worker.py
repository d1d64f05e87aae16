"""The worker side of the sandbox: finds and runs one function of a submission in a sandboxed child.

A worker is forked by the zygote (:mod:`geomlib.grading.zygote`) for every call. It confines itself
(:func:`confine`), imports only the module that defines the requested function (so a syntax error
elsewhere in the lab costs only the functions in that file), calls it, and sends back either the
encoded result or a description of what went wrong. Nothing it sends is unpickled by the grader
(see :mod:`geomlib.grading.wire`).

Given code is the course's. When the course's stubs of the lab are known (``labs/<lab>/``), each
module of the lab is assembled from the stub and the submission (:func:`merge_module`):

- *task functions* (those whose body the stub replaces by ``raise NotImplementedError``) come from
  the submission, but run the stub's statements that precede the task (input validation) first
  when the submission changed or dropped them;
- everything else the stub defines (given helpers, constants, imports) is the stub's: a submission
  that rewrites a given helper or deletes validation gains nothing;
- names the submission adds (its own helpers, imports) and its other top-level statements are
  kept; files the stub does not have are the submission's own.

Longer than most modules (about 890 lines) on purpose: the parsed stubs and their compiled given
statements (``_TREES``, ``_STUB_CODE``) and the submission's modules merged ahead (``_MERGED``, used
only for the bytes the zygote merged), filled in the zygote before it forks, are read by the merge,
by the OpenGL preload decision, by the function lookup and by a kernel zygote's import of trusted
code (:func:`preload_lab`); one module owns those caches, so no
other module reaches into another's private state.
"""

from __future__ import annotations
import __future__

import ast
import copy
import dataclasses
import hashlib
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import json
import os
import re
import resource
import stat
import struct
import sys
import traceback
import types
import warnings
from pathlib import Path

from geomlib.grading import blacklist, wire

__all__ = ["find_function", "merge_module", "task_names", "run_call", "describe_exception"]

#: Longest exception message a worker sends (the grader cuts again on its side).
MESSAGE_CHARS = 4000


# ---------------------------------------------------------------------------------- reading files


def _read_source(path: Path) -> str:
    """A submission file's text, never following a symbolic link."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    with os.fdopen(fd, "rb") as f:
        return f.read(4 << 20).decode("utf-8", errors="replace")


#: Syntax trees parsed in this worker, by path: ``find_function`` looks for the function in every
#: file of the lab, then the import merges the stub and the submission's file; each file is read and
#: parsed once per call (a worker serves one call). Trees are never changed (merging copies).
_TREES: dict = {}


def _parsed(path: Path, *, student: bool) -> ast.Module:
    """``path``'s syntax tree (a submission's file read without following links); raises SyntaxError.

    A submission's file whose bytes are those the zygote merged (:func:`prepare_merged`) gets the
    zygote's tree."""
    key = (str(path), student)
    if key not in _TREES:
        try:
            text = _read_source(path) if student else path.read_text(encoding="utf-8")
            ahead = _MERGED.get(str(path)) if student else None
            if ahead is not None and ahead.digest == hashlib.sha256(text.encode("utf-8", "surrogatepass")).digest():
                _TREES[key] = ahead.tree
            else:
                _TREES[key] = ast.parse(text, filename=str(path))
        except SyntaxError as e:
            _TREES[key] = e
    tree = _TREES[key]
    if isinstance(tree, SyntaxError):
        raise tree
    return tree


#: The course's stubs, parsed and compiled once in the zygote (:func:`prepare_stubs`) and inherited by
#: every worker it forks: ``path -> sha256`` of the bytes ``_TREES`` holds (a size and mtime kept
#: across an edit must not keep the old code), and the code of each top-level stub statement by
#: ``id`` of the statement.
_STUB_STAT: dict = {}
_STUB_CODE: dict = {}
#: ``id(stub tree) -> (task names, given names)`` (:func:`merge_module`), for the trees in ``_TREES``.
_STUB_NAMES: dict = {}
#: ``id(stub tree) -> (tree, names it defines)`` (:func:`_defines`, asked of every stub file at every
#: call) and ``id(stub task function) -> (function, its validation prefix)`` (:func:`_merged_task`);
#: worked out in the zygote too (:func:`prepare_stubs`).
_STUB_DEFINES: dict = {}
_STUB_PREFIX: dict = {}


def prepare_stubs(stubs_dir: str | None) -> None:
    """Parse and compile the course's stub files of a lab ahead of the calls (run by the zygote, which
    forks the workers: each call then starts with them, ~40 ms of CPU less per call). Only the course's
    stubs, never a submission's file; a stub that changed on disk is parsed again."""
    if not stubs_dir:
        return
    flags = __future__.annotations.compiler_flag
    for path in sorted(Path(stubs_dir).glob("*.py")):
        try:
            data = path.read_bytes()
        except OSError:
            continue
        digest = hashlib.sha256(data).hexdigest()
        if _STUB_STAT.get(str(path)) == digest:
            continue
        old = _TREES.pop((str(path), False), None)
        for stmt in getattr(old, "body", ()):  # their ids may be reused once the old tree is freed
            _STUB_CODE.pop(id(stmt), None)
            _STUB_PREFIX.pop(id(stmt), None)
        _STUB_NAMES.pop(id(old), None)
        _STUB_DEFINES.pop(id(old), None)
        _STUB_STAT[str(path)] = digest
        try:
            tree = _TREES[(str(path), False)] = ast.parse(data.decode("utf-8"), filename=str(path))
        except (SyntaxError, ValueError):
            continue
        tasks = task_names(tree)
        _STUB_NAMES[id(tree)] = (
            tasks,
            set().union(*(_bound_names(s) for s in tree.body)) - tasks if tree.body else set(),
        )
        _stub_defines(tree)
        for stmt in tree.body:
            if isinstance(stmt, ast.FunctionDef | ast.AsyncFunctionDef) and stmt.name in tasks:
                _stub_prefix(stmt)
            try:
                _STUB_CODE[id(stmt)] = compile(
                    ast.Module(body=[stmt], type_ignores=[]), str(path), "exec", flags=flags, dont_inherit=True
                )
            except (SyntaxError, ValueError):
                pass


def prepare_gl(*lab_folders: str | None, function: str | None = None) -> None:
    """Import PyOpenGL on the headless platform, in the zygote, when the lab runs shaders (it has a
    ``shaders/`` folder): every worker of a GLSL call imported it (0.4 s of CPU) before this. No
    OpenGL context is created here: Mesa's rasteriser threads do not survive a fork (see
    :func:`geomlib.render.context.inherited_context`), so each worker creates its own (about 15 ms).

    With ``function`` (the call's) and the lab's stubs first among ``lab_folders``: not before a
    call whose stub module may use OpenGL (:func:`_may_use_gl`), so ``--task 3`` of shadows, which
    runs no shader, does not pay the import (0.2 s of CPU at every start of the grader)."""
    from geomlib.gl import SHADER_FOLDER

    if "OpenGL.GL" in sys.modules or not any(f and os.path.isdir(os.path.join(f, SHADER_FOLDER)) for f in lab_folders):
        return
    if function and lab_folders[0] and not _may_use_gl(lab_folders[0], function):
        return
    from geomlib.render.context import backend

    platform = backend()  # PYOPENGL_PLATFORM before PyOpenGL's import (inherited by the workers)
    importlib.import_module("OpenGL.GL")
    importlib.import_module("OpenGL.arrays")
    # PyOpenGL's array handlers, which it imports at a worker's first GL call (numpy arrays,
    # ctypes arrays and pointers, lists, bytes): ~17 ms of CPU per GLSL call otherwise.
    for handler in ("numpymodule", "ctypesarrays", "ctypespointers", "lists", "strings"):
        importlib.import_module(f"OpenGL.arrays.{handler}")
    if platform == "osmesa":
        importlib.import_module("OpenGL.osmesa")


#: Modules whose import in a stub means OpenGL (shaders, or pyrender's renderer).
_GL_MODULES = ("geomlib.gl", "geomlib.render", "OpenGL", "pyrender")


def _may_use_gl(stubs_dir: str, function: str) -> bool:
    """Whether the course's stub module that defines ``function`` imports one of :data:`_GL_MODULES`,
    itself or through the lab's other stub modules it imports (relative imports, at any depth of
    the file); True when that is not known (no parsed stub defines it: a submission's own file)."""
    return may_import(stubs_dir, function, _GL_MODULES)


def may_import(stubs_dir: str, function: str, modules: tuple[str, ...]) -> bool:
    """:func:`_may_use_gl` for any ``modules`` (names or prefixes of dotted names): whether a call of
    ``function`` may import one of them, from the stubs the zygote parsed (:func:`prepare_stubs`)."""
    trees = {p.stem: _TREES.get((str(p), False)) for p in sorted(Path(stubs_dir).glob("*.py"))}
    key = (stubs_dir, function, modules)
    version = tuple(map(id, trees.values()))  # the trees of this version of the stubs (prepare_stubs)
    known = _GL_USE.get(key)
    if known is not None and known[0] == version and all(t is not None for t in trees.values()):
        return known[1]  # asked at every call until OpenGL is loaded: 4-12 ms of walking the stubs each
    _GL_USE[key] = (version, _walk_for(trees, function, modules))
    return _GL_USE[key][1]


#: :func:`may_import` by (stubs folder, function, modules): (ids of the stub trees, the answer).
_GL_USE: dict = {}


def _walk_for(trees: dict, function: str, modules: tuple[str, ...]) -> bool:
    todo = [stem for stem, t in trees.items() if isinstance(t, ast.Module) and function in _stub_defines(t)]
    if not todo:
        return True

    def gl(name: str) -> bool:
        return any(name == m or name.startswith(m + ".") for m in modules)

    seen = set()
    while todo:
        stem = todo.pop()
        if stem in seen:
            continue
        seen.add(stem)
        tree = trees.get(stem)
        if not isinstance(tree, ast.Module):
            return True
        for node in ast.walk(tree):
            if isinstance(node, ast.Import) and any(gl(a.name) for a in node.names):
                return True
            if isinstance(node, ast.ImportFrom):
                if node.level:  # the lab's own modules: from .glsl import ..., from . import glsl
                    todo += [node.module.split(".")[0]] if node.module else [a.name for a in node.names]
                elif gl(node.module or "") or any(gl(f"{node.module}.{a.name}") for a in node.names):
                    return True
    return False


def _is_plain_file(path: Path) -> bool:
    return path.is_file() and not path.is_symlink()


# ---------------------------------------------------------------------------------- which names


def task_names(tree: ast.Module) -> set[str]:
    """Top-level functions of a stub whose body raises ``NotImplementedError`` (the student's tasks)."""
    out = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            for sub in ast.walk(node):
                if isinstance(sub, ast.Raise) and sub.exc is not None:
                    exc = sub.exc.func if isinstance(sub.exc, ast.Call) else sub.exc
                    if isinstance(exc, ast.Name) and exc.id == "NotImplementedError":
                        out.add(node.name)
                        break
    return out


def _bound_names(stmt: ast.stmt) -> set[str]:
    """Names a top-level statement binds in the module namespace."""
    if isinstance(stmt, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
        return {stmt.name}
    if isinstance(stmt, ast.Import | ast.ImportFrom):
        return {(a.asname or a.name).split(".")[0] for a in stmt.names}
    names = set()
    todo = [stmt]
    while todo:
        node = todo.pop()
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                names.add(child.name)
            elif isinstance(child, ast.Lambda):
                continue
            else:
                if isinstance(child, ast.Name) and isinstance(child.ctx, ast.Store):
                    names.add(child.id)
                elif isinstance(child, ast.Import | ast.ImportFrom):
                    names |= _bound_names(child)
                todo.append(child)
    return names


def _defines(tree: ast.Module, name: str) -> bool:
    """Whether the module *defines* ``name`` (def, class or assignment; an import does not count)."""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) and node.name == name:
            return True
        if isinstance(node, ast.Assign | ast.AnnAssign) and name in _bound_names(node):
            return True
    return False


def _stub_defines(tree: ast.Module) -> frozenset:
    """The names a course stub defines (as :func:`_defines` counts them), worked out once per tree."""
    known = _STUB_DEFINES.get(id(tree))
    if known is None or known[0] is not tree:
        names = frozenset(
            n
            for node in tree.body
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef | ast.Assign | ast.AnnAssign)
            for n in ({node.name} if hasattr(node, "name") else _bound_names(node))
        )
        known = _STUB_DEFINES[id(tree)] = (tree, names)
    return known[1]


def _imports(tree: ast.Module, name: str) -> bool:
    return any(isinstance(n, ast.Import | ast.ImportFrom) and name in _bound_names(n) for n in tree.body)


# ---------------------------------------------------------------------------------- merging


def _relocate(node, line: int):
    """A copy of ``node`` with every position at ``line``, column 0 (the stub's code merged into a
    student's function reports that function's line). A plain recursive copy: ``copy.deepcopy``
    of a syntax tree costs a few times more, and a worker merges every task of a module per call."""
    if isinstance(node, list):
        return [_relocate(x, line) for x in node]
    if not isinstance(node, ast.AST):
        return node  # str, int, None, a constant's value: not changed by anyone
    new = node.__class__.__new__(node.__class__)
    for name in node._fields:
        try:
            setattr(new, name, _relocate(getattr(node, name), line))
        except AttributeError:  # an optional field left unset
            pass
    if "lineno" in node._attributes:
        new.lineno = new.end_lineno = line
        new.col_offset = new.end_col_offset = 0
    else:
        for name in node._attributes:
            if hasattr(node, name):
                setattr(new, name, getattr(node, name))
    return new


def _task_prefix(stub_fn: ast.FunctionDef) -> list[ast.stmt]:
    """The stub's statements before the one holding ``raise NotImplementedError`` (validation)."""
    for i, stmt in enumerate(stub_fn.body):
        if any(isinstance(s, ast.Raise) for s in ast.walk(stmt)):
            return stub_fn.body[:i]
    return []


def _stub_prefix(stub_fn: ast.FunctionDef) -> list[ast.stmt]:
    """:func:`_task_prefix`, once per stub function."""
    known = _STUB_PREFIX.get(id(stub_fn))
    if known is None or known[0] is not stub_fn:
        known = _STUB_PREFIX[id(stub_fn)] = (stub_fn, _task_prefix(stub_fn))
    return known[1]


def _same(a, b) -> bool:
    """Whether two syntax trees are the same code (``ast.dump(a) == ast.dump(b)``: fields compared,
    positions not), stopping at the first difference instead of writing both trees out."""
    if type(a) is not type(b):
        return False
    if isinstance(a, ast.AST):
        return all(_same(getattr(a, f, None), getattr(b, f, None)) for f in a._fields)
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a is b or repr(a) == repr(b)  # a constant, compared as ast.dump writes it (1 is not 1.0)


def _merged_task(stub_fn: ast.FunctionDef, student_fn: ast.FunctionDef) -> ast.FunctionDef:
    """The student's task function with the stub's signature and the stub's leading validation."""
    line = student_fn.lineno
    prefix = _stub_prefix(stub_fn)
    body = list(student_fn.body)
    common = 0
    while common < min(len(prefix), len(body)) and _same(prefix[common], body[common]):
        common += 1
    missing = [_relocate(s, line) for s in prefix[common:]]
    fn = copy.copy(student_fn)
    fn.args = _relocate(stub_fn.args, line)
    fn.decorator_list = [_relocate(d, line) for d in stub_fn.decorator_list]
    fn.returns = _relocate(stub_fn.returns, line) if stub_fn.returns is not None else None
    fn.body = body[:common] + missing + body[common:] if missing else body
    return fn


def _syntax_stub(stub_fn: ast.FunctionDef, message: str) -> ast.FunctionDef:
    fn = copy.copy(stub_fn)
    fn.body = [_relocate(ast.parse(f"raise SyntaxError({message!r})").body[0], stub_fn.lineno)]
    return fn


def merge_module(stub_path: Path, student_path: Path | None) -> list[tuple[ast.stmt, str]]:
    """The statements of one lab module, each with the file it comes from (see the module docstring).

    Returns a list of ``(statement, filename)`` to execute in order in the module's namespace.
    """
    stub = _parsed(stub_path, student=False)
    if id(stub) not in _STUB_NAMES:  # the zygote's stubs come with them (prepare_stubs)
        tasks = task_names(stub)
        _STUB_NAMES[id(stub)] = (
            tasks,
            set().union(*(_bound_names(s) for s in stub.body)) - tasks if stub.body else set(),
        )
    tasks, given = _STUB_NAMES[id(stub)]
    sfile = str(stub_path)
    if student_path is None or not _is_plain_file(student_path):
        return [(s, sfile) for s in stub.body]
    pfile = str(student_path)
    try:
        student = _parsed(student_path, student=True)
    except SyntaxError as e:
        where = f"{student_path.parent.name}/{student_path.name} line {e.lineno}: {e.msg}"
        text = (e.text or "").strip()
        msg = f"{where}" + (f" (`{text[:200]}`)" if text else "")
        return [(_syntax_stub(s, msg) if getattr(s, "name", None) in tasks else s, sfile) for s in stub.body]
    pieces: list[tuple[ast.stmt, str]] = [(s, sfile) for s in stub.body]
    stub_defs = {s.name: s for s in stub.body if isinstance(s, ast.FunctionDef | ast.AsyncFunctionDef)}
    # The submission's statements follow the stub's, in the submission's order, so that they keep
    # their meaning (a task defined twice, a name bound to an earlier version of a task).
    for i, s in enumerate(student.body):
        if i == 0 and isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
            continue  # the module docstring
        if isinstance(s, ast.ImportFrom) and s.module == "__future__":
            continue
        if isinstance(s, ast.FunctionDef | ast.AsyncFunctionDef) and s.name in tasks:
            pieces.append((_merged_task(stub_defs[s.name], s), pfile))
            continue
        bound = _bound_names(s)
        if isinstance(s, ast.ImportFrom | ast.Import) and bound & given:
            keep = [a for a in s.names if (a.asname or a.name).split(".")[0] not in given]
            if not keep:
                continue
            s = copy.copy(s)
            s.names = keep
        elif bound & given:
            continue  # the student's version of a given helper or constant: the course's stays
        pieces.append((s, pfile))
    return pieces


def merged_code(stub_path: Path, student_path: Path | None) -> list[tuple[types.CodeType, bool]]:
    """``(code, given)`` of each statement of the merged module (:func:`merge_module`), in order: the
    given statements are the zygote's compiled stub statements, the submission's are compiled here,
    or were compiled by the zygote for these very bytes (:func:`prepare_merged`).

    Never kept by a worker, nor in any file a worker can write: the submission could forge that,
    and a forged list of pieces could leave out a given helper and put the submission's own
    version in its place (the merge drops such redefinitions).
    """
    if student_path is not None and _is_plain_file(student_path):
        ahead = _MERGED.get(str(student_path))
        try:
            tree = _parsed(student_path, student=True)  # the worker's own read of the bytes
        except SyntaxError:
            tree = None
        if (
            ahead is not None
            and tree is not None
            and tree is ahead.tree  # the bytes the zygote merged (_parsed compared their digest)
            and ahead.stub == str(stub_path)
            and _TREES.get((str(stub_path), False)) is ahead.stub_tree  # and the stubs it merged them with
        ):
            return list(ahead.code)
    return _compile_merged(stub_path, student_path)


def _compile_merged(stub_path: Path, student_path: Path | None) -> list[tuple[types.CodeType, bool]]:
    flags = __future__.annotations.compiler_flag
    out = []
    for stmt, filename in merge_module(stub_path, student_path):
        given = filename == str(stub_path)
        code = _STUB_CODE.get(id(stmt)) if given else None
        if code is None:
            code = compile(ast.Module(body=[stmt], type_ignores=[]), filename, "exec", flags=flags, dont_inherit=True)
        out.append((code, given))
    return out


@dataclasses.dataclass(frozen=True)
class _Ahead:
    """A submission's module as the zygote merged it: the sha256 of the file's text, its tree, and
    the merged module's code (the stub ``stub``, parsed as ``stub_tree``). A module of the
    submission's own (no stub of that name: ``stub`` is ``""``, ``stub_tree`` None) is compiled
    whole, as Python's import would, into ``code[0]``, from the bytes whose sha256 is ``raw``."""

    digest: bytes
    tree: ast.Module
    stub: str
    stub_tree: ast.Module | None
    code: tuple
    raw: bytes = b""


#: ``submission file -> _Ahead``, filled by :func:`prepare_merged` in the zygote only, read by its
#: workers (each checks the bytes it reads against ``digest``). No worker writes it, and what a
#: worker writes stays in that worker (a fork's copy): a submission cannot forge an entry.
_MERGED: dict[str, _Ahead] = {}
#: Largest submission file the zygote parses and compiles ahead (larger ones: each worker does).
MERGE_AHEAD_BYTES = 1 << 20
#: Submission files kept merged in the zygote (the most recent).
MERGE_AHEAD_FILES = 200


def prepare_merged(stubs_dir: str | None, lab_dir: str | None) -> None:
    """Merge and compile the submission's modules of a call's snapshot with the course's stubs, in
    the zygote, before it forks the call's worker (:func:`prepare_stubs` first): each worker of the
    snapshot starts with them instead of merging and compiling again (~25 ms of CPU per call).
    The submission's own modules (no stub of that name) are compiled whole here too: a worker
    cannot keep bytecode (the snapshot is read-only to it), so each call compiled them again
    (measured: a 360-line helper module, 7.5 ms per call, 0.6 s of a whole subdivision grading).

    The zygote only parses and compiles the submission's text (nothing of it runs here); a file
    it cannot read, too large, or that the compiler refuses is left to the workers, which report
    what is wrong as before."""
    if not lab_dir:
        return
    for path in sorted(Path(lab_dir).glob("*.py")):
        stub = Path(stubs_dir) / path.name if stubs_dir else None
        own = stub is None or not stub.exists()  # as _LabFinder decides: no stub, the file is imported whole
        stub_tree = None if own else _TREES.get((str(stub), False))
        if path.name == "__init__.py" or not (own or isinstance(stub_tree, ast.Module)):
            continue
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
            with os.fdopen(fd, "rb") as f:
                if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                    continue
                data = f.read(MERGE_AHEAD_BYTES + 1)
        except OSError:
            continue
        if len(data) > MERGE_AHEAD_BYTES:
            _MERGED.pop(str(path), None)
            continue
        text = data.decode("utf-8", errors="replace")  # as _read_source reads it
        digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).digest()
        raw = hashlib.sha256(data).digest() if own else b""
        known = _MERGED.get(str(path))
        if known is not None and known.digest == digest and known.raw == raw and known.stub_tree is stub_tree:
            continue
        _MERGED.pop(str(path), None)
        key = (str(path), True)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # a worker compiling it shows them to the student
                _TREES[key] = tree = ast.parse(text, filename=str(path))
                if own:
                    code = (compile(data, str(path), "exec", dont_inherit=True),)
                else:
                    code = tuple(_compile_merged(stub, path))
        except Exception:  # noqa: BLE001 - a syntax error, too deep a nesting: the worker reports it
            continue
        finally:
            _TREES.pop(key, None)  # a zygote's tree of a submission file is only ever read through _MERGED
        _MERGED[str(path)] = _Ahead(digest, tree, "" if own else str(stub), stub_tree, code, raw)
        while len(_MERGED) > MERGE_AHEAD_FILES:  # an audit grades hundreds of copies: the oldest go
            del _MERGED[next(iter(_MERGED))]


class _OwnLoader(importlib.machinery.SourceFileLoader):
    """A submission's own module (no stub of that name), imported whole as Python's import does, but
    never through a ``__pycache__``: its bytes are read here (links not followed) and run as the
    code the zygote compiled from these very bytes (:func:`prepare_merged`), else compiled here.
    Nothing is written: bytecode a worker wrote could be loaded by a later call."""

    def get_code(self, fullname):
        fd = os.open(self.path, os.O_RDONLY | os.O_NOFOLLOW)
        with os.fdopen(fd, "rb") as f:
            data = f.read()
        ahead = _MERGED.get(self.path)
        if ahead is not None and not ahead.stub and ahead.raw == hashlib.sha256(data).digest():
            return ahead.code[0]
        return compile(data, self.path, "exec", dont_inherit=True)


class _MergedLoader(importlib.abc.Loader):
    def __init__(self, stub_path: Path, student_path: Path | None):
        self.stub_path, self.student_path = stub_path, student_path

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        pieces = merged_code(self.stub_path, self.student_path)
        module.__file__ = str(self.student_path if self.student_path is not None else self.stub_path)
        for code, given in pieces:
            if given:
                blacklist.given(code)  # given code may call what the lab forbids the student
            exec(code, module.__dict__)


class _LabFinder(importlib.abc.MetaPathFinder):
    """Imports ``_graded_<lab>.<module>`` as the merge of the stub and the submission's file."""

    def __init__(self, package: str, lab_dir: Path, stubs_dir: Path | None):
        self.package, self.lab_dir, self.stubs_dir = package, lab_dir, stubs_dir

    def find_spec(self, fullname, path=None, target=None):
        prefix = self.package + "."
        if not fullname.startswith(prefix) or "." in fullname[len(prefix) :]:
            return None
        stem = fullname[len(prefix) :]
        student = self.lab_dir / f"{stem}.py"
        stub = self.stubs_dir / f"{stem}.py" if self.stubs_dir is not None else None
        if stub is not None and stub.is_file():
            loader = _MergedLoader(stub, student if student.exists() else None)
            return importlib.util.spec_from_loader(fullname, loader, origin=str(student))
        if student.is_symlink():
            raise ImportError(f"{self.lab_dir.name}/{stem}.py is a symbolic link; the grader reads only plain files")
        if student.is_file():
            return importlib.util.spec_from_file_location(fullname, student, loader=_OwnLoader(fullname, str(student)))
        return None


def _student_defines(path: Path, name: str) -> bool:
    if not _is_plain_file(path):
        return False
    try:
        tree = _parsed(path, student=True)
        return _defines(tree, name) or _imports(tree, name)
    except SyntaxError:
        text = _read_source(path)
        return re.search(rf"^\s*(async\s+)?def\s+{re.escape(name)}\b", text, re.M) is not None


def _lab_package(lab_dir: Path, lab: str, stubs_dir: Path | None) -> str:
    """Make ``_graded_<lab>`` the package of ``lab_dir`` (merged with ``stubs_dir``) and return its name.

    Kept when it is already that folder's: the modules a kernel zygote imported for a trusted
    snapshot (:func:`preload_lab`) are the ones its workers find. Any other ``_graded_<lab>``
    module is dropped first (none in a worker of the plain zygote, which imports no lab)."""
    name, origin = f"_graded_{lab}", (str(lab_dir), str(stubs_dir))
    if getattr(sys.modules.get(name), "__graded_origin__", None) == origin:
        return name
    for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
        del sys.modules[key]
    pkg = types.ModuleType(name)
    pkg.__path__ = [str(lab_dir)]
    pkg.__package__ = name
    pkg.__graded_origin__ = origin
    sys.modules[name] = pkg
    sys.meta_path.insert(0, _LabFinder(name, lab_dir, stubs_dir))
    return name


#: Calls a module may make at its top level, in an assignment, to be imported by a kernel zygote:
#: NumPy's and math's (the course's constant tables, ``TETRA = np.array(...)``).
_PRELOAD_CALLS = ("np", "numpy", "math")


def _plain_top_level(tree: ast.Module) -> bool:
    """Whether a module's top level only defines things: imports, functions, classes, docstrings,
    assignments whose calls are NumPy's or math's, ``use_cache_folder(__name__, __file__)`` and an
    ``if __name__ == "__main__":`` block. A module that does more (prints, runs a test of its
    own) is imported by each worker, as any submission's, so what it prints or raises is the call's."""
    for node in tree.body:
        if isinstance(node, ast.Import | ast.ImportFrom | ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            continue
        if isinstance(node, ast.Expr) and ast.unparse(node) == "use_cache_folder(__name__, __file__)":
            continue
        if isinstance(node, ast.If) and ast.unparse(node.test) in ("__name__ == '__main__'", '__name__ == "__main__"'):
            continue
        if isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign):
            calls = [n.func for n in ast.walk(node) if isinstance(n, ast.Call)]
            if all(
                isinstance(f, ast.Attribute)
                and isinstance(f.value, ast.Name | ast.Attribute)
                and ast.unparse(f.value).split(".")[0] in _PRELOAD_CALLS
                for f in calls
            ):
                continue
        return False
    return True


def _preload_deps(tree: ast.Module) -> set[str] | None:
    """The lab modules a module imports at its top level (relative imports), or None when a kernel
    zygote may not import it: its top level does more than define things (:func:`_plain_top_level`)
    or imports a library this process has not loaded (figures' matplotlib, say)."""
    if not _plain_top_level(tree):
        return None
    deps = set()
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.level:
            deps |= {node.module.split(".")[0]} if node.module else {a.name for a in node.names}
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            if any(n not in sys.modules and n.split(".")[0] not in sys.stdlib_module_names for n in names):
                return None
    return deps


def preload_lab(lab_dir: Path, lab: str, stubs_dir: Path | None) -> list[types.ModuleType]:
    """Import the modules of a **trusted** lab snapshot (the course's own code, see
    :mod:`geomlib.grading.kernelcache`) that a kernel zygote keeps for its workers: those whose stub
    and own file pass :func:`_preload_deps`, with the lab modules they import. Never called for a
    submission. Returns the modules imported (one that fails is left to the workers)."""
    stems = {p.stem for p in lab_dir.glob("*.py")} | ({p.stem for p in stubs_dir.glob("*.py")} if stubs_dir else set())
    stems.discard("__init__")
    deps: dict[str, set[str]] = {}
    for stem in sorted(stems):
        found = [(stubs_dir / f"{stem}.py", False)] if stubs_dir else []
        found = [(f, student) for f, student in [*found, (lab_dir / f"{stem}.py", True)] if _is_plain_file(f)]
        try:
            mine = [_preload_deps(_parsed(f, student=student)) for f, student in found]
        except SyntaxError:
            continue
        if None not in mine:
            deps[stem] = set().union(*mine)
    ok = set(deps)
    while (keep := {s for s in ok if deps[s] <= ok}) != ok:
        ok = keep
    pkg = _lab_package(lab_dir, lab, stubs_dir)
    modules = []
    for stem in sorted(ok):
        try:
            modules.append(importlib.import_module(f"{pkg}.{stem}"))
        except Exception:  # noqa: BLE001 - each worker imports it itself and reports what fails
            pass
    return modules


def find_function(lab_dir: Path, lab: str, function: str, stubs_dir: Path | None = None):
    """Import the module of the lab that defines ``function`` and return the function.

    With ``stubs_dir`` (the course's stubs of this lab), modules are merged as the module docstring
    says. The lab's ``__init__.py`` is not executed (it usually imports every module, which would
    let a syntax error in one file break them all); it is searched last.
    """
    pkg_name = _lab_package(lab_dir, lab, stubs_dir)
    broken = []
    stub_files = sorted(p for p in stubs_dir.glob("*.py") if p.name != "__init__.py") if stubs_dir else []
    stub_stems = {p.stem for p in stub_files}
    own_files = sorted(p for p in lab_dir.glob("*.py") if p.name != "__init__.py" and p.stem not in stub_stems)
    stub_trees = [(p.stem, _parsed(p, student=False)) for p in stub_files]
    own_trees = []
    for path in own_files:
        if not _is_plain_file(path):
            continue
        try:
            own_trees.append((path.stem, _parsed(path, student=True)))
        except SyntaxError as e:
            broken.append(f"{path.name} line {e.lineno}: {e.msg}")

    def load(stem):
        return getattr(importlib.import_module(f"{pkg_name}.{stem}"), function, None)

    for stem, tree in stub_trees:
        if function in _stub_defines(tree):
            tasks = _STUB_NAMES[id(tree)][0] if id(tree) in _STUB_NAMES else task_names(tree)  # the zygote's
            if function in tasks and not _student_defines(lab_dir / f"{stem}.py", function):
                # The student moved the task to a file of their own.
                for own, own_tree in own_trees:
                    if _defines(own_tree, function) and (fn := load(own)) is not None:
                        return fn
                own_trees = stub_trees = []  # not in the submission: report it missing, not "not implemented"
                break
            if (fn := load(stem)) is not None:
                return fn
    for test in (_defines, _imports):
        for stem, tree in own_trees + stub_trees:
            if test(tree, function) and (fn := load(stem)) is not None:
                return fn
    init = lab_dir / "__init__.py"
    if not stubs_dir and _is_plain_file(init):
        try:
            tree = ast.parse(_read_source(init))
        except SyntaxError as e:
            broken.append(f"__init__.py line {e.lineno}: {e.msg}")
        else:
            if _defines(tree, function) or _imports(tree, function):
                spec = importlib.util.spec_from_file_location(pkg_name, init, submodule_search_locations=[str(lab_dir)])
                mod = importlib.util.module_from_spec(spec)
                sys.modules[pkg_name] = mod
                spec.loader.exec_module(mod)
                fn = getattr(mod, function, None)
                if fn is not None:
                    return fn
    hint = f"; these files have syntax errors: {'; '.join(broken)}" if broken else ""
    raise LookupError(f"could not find a function named {function!r} in {lab_dir.name}/{hint}")


# ---------------------------------------------------------------------------------- reporting


def _student_frames(tb, lab_dir: Path) -> list[dict]:
    frames = []
    for fs in traceback.extract_tb(tb):
        try:
            inside = Path(fs.filename).resolve().is_relative_to(lab_dir.resolve())
        except (OSError, ValueError):
            inside = False
        if inside:
            frames.append(
                {
                    "file": f"{lab_dir.name}/{Path(fs.filename).name}",
                    "line": fs.lineno,
                    "function": fs.name,
                    "code": (fs.line or "")[:300],
                }
            )
    return frames


def describe_exception(e: BaseException, lab_dir: Path) -> dict:
    if isinstance(e, SyntaxError) and e.filename:
        frames = [
            {
                "file": f"{lab_dir.name}/{Path(e.filename).name}",
                "line": e.lineno,
                "function": "<module>",
                "code": (e.text or "").strip()[:300],
            }
        ]
    else:
        frames = _student_frames(e.__traceback__, lab_dir)
    try:
        message = str(e)[:MESSAGE_CHARS]
    except Exception:  # noqa: BLE001 - a __str__ that raises
        message = "<the exception's message could not be printed>"
    return {
        "kind": "exception",
        "type": type(e).__name__[:200],
        "mro": [c.__name__[:200] for c in type(e).__mro__][:20],
        "message": message,
        "frames": frames[-3:],
    }


def send(fd: int, payload: bytes) -> None:
    """Write one framed message (``<Q`` length + payload) to the result pipe."""
    data = struct.pack("<Q", len(payload)) + payload
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


def send_json(fd: int, tag: bytes, obj: dict) -> None:
    send(fd, tag + json.dumps(obj, ensure_ascii=True).encode())


def run_call(
    fd: int, lab_dir: str, lab: str, function: str, args, kwargs, stubs_dir: str | None = None, not_allowed=None
) -> None:
    """Find and call ``function`` in an already confined worker, send the outcome to ``fd``, exit.

    ``not_allowed``: the lab's blacklist (:mod:`geomlib.grading.blacklist`), guarded before the
    submission is imported.
    """
    lab_path = Path(lab_dir)
    try:
        blacklist.install(lab, lab_dir, not_allowed)
    except Exception as e:  # noqa: BLE001 - the grader's problem, not the student's
        send_json(fd, b"E", {"kind": "internal", "message": f"blacklist set-up failed: {e!r}"[:2000]})
        os._exit(0)
    try:
        from geomlib.grading import shader_watch

        shader_watch.install(os.environ.get("TMPDIR"))  # the call's scratch folder (zygote.confine)
        try:
            fn = find_function(lab_path, lab, function, Path(stubs_dir) if stubs_dir else None)
        except LookupError as e:
            payload = {"kind": "missing", "message": str(e)[:MESSAGE_CHARS]}
        else:
            result = fn(*args, **kwargs)
            try:
                data = wire.encode(result)
            except wire.WireError as e:
                payload = {"kind": "bad_return", "message": f"{function} returned {e}, which the grader cannot read"}
            else:
                sys.stdout.flush()
                send(fd, b"R" + data)
                os._exit(0)
    except MemoryError:
        payload = {"kind": "memory", "message": "ran out of memory"}
    except SystemExit as e:
        payload = {"kind": "exit", "message": f"called sys.exit({repr(e.code)[:100]})"}
    except BaseException as e:  # noqa: BLE001 - anything the student raises is reported
        payload = describe_exception(e, lab_path)
    try:
        sys.stdout.flush()
    except BaseException:  # noqa: BLE001
        pass
    try:
        send_json(fd, b"E", payload)
    finally:
        os._exit(0)


# ---------------------------------------------------------------------------------- confinement


def vm_size_bytes() -> int:
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * resource.getpagesize()
    except OSError:
        return 0


def tasks_of_user(uid: int) -> int | None:
    """Threads currently running as ``uid`` (what RLIMIT_NPROC counts); None without /proc (macOS)."""
    n = 0
    try:
        names = os.listdir("/proc")
    except OSError:
        return None
    for name in names:
        if name.isdigit():
            try:
                if os.stat(f"/proc/{name}").st_uid == uid:
                    with open(f"/proc/{name}/stat", "rb") as f:
                        n += int(f.read().rsplit(b")", 1)[1].split()[17])
            except (OSError, ValueError, IndexError):
                pass
    return n
