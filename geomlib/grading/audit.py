"""``geomlib audit``: mutation analysis of the graded tests.

A *mutant* is a copy of ``solutions/<lab>/`` with one change inside one ``# BEGIN SOLUTION`` block.
Each mutant is graded through the real grading path (``geomlib grade --impl COPY --lab LAB --task N``:
sandboxed workers, the course's stubs merged in, public and hidden tests) on the graded tests of the
block's task, and it is

- *killed* when it loses points there (a *does-nothing* mutant is only counted killed when the
  tests that run its block score 0; one that keeps some of their points is reported as *partly
  killed*). The tests that run a block are measured: a *probe* copy raises at the block's first
  line, and the tests it fails are the block's (without a probe result: the tests that call the
  block's function or a composite of it). The row keeps the per-task verdict as ``task_status``;
- *survived* otherwise: the tests cannot tell it from the reference solution;
- *equivalent* when ``tests/graded/<lab>/equivalent_mutants.toml`` declares it so, with a reason
  (an equivalent mutant that a test kills is an error of the declaration).

Two kinds of mutants, both generated from the solution's syntax tree (:mod:`ast`) and applied as
text at the node's position, so that each is a one-line diff of the source:

- *does nothing* (``nothing``): the block's results (its ``return`` values and the names it binds or
  changes that the rest of the function reads) are replaced, after the block ran, by zeros of the
  same shape and dtype (``zeros``), by the function's input of the same kind (``input``: ``V`` for
  a new ``V``, ``(V, F)`` for a remeshed ``(V, F)``), or by a constant of the right shape
  (``constant``: the mean value for floats, ones for integers, True for booleans). Blocks inside
  numba-compiled kernels get no does-nothing mutant (the helper that builds the replacement is
  Python); they are listed in the report;
- *operators* inside the block: numeric constants (0↔1, ×2, ½, +1), ``+``↔``-``, ``*``↔``/``
  (also in ``+=`` and friends), ``<``↔``<=``, ``>``↔``>=``, an index ``a[i]`` → ``a[i + 1]``,
  ``True``↔``False``, the first two positional arguments of a call swapped.

Why not mutmut or cosmic-ray: both mutate a package in place and run a test command per mutant
against that one tree, and both pick mutation sites over whole modules. Here a mutant must be a
*separate folder* graded with ``--impl FOLDER`` (the sandbox snapshots the folder and merges it
with the course's stubs), only code inside solution blocks may change, and each mutant must be
traced to its task; with either tool the copy, the restriction to blocks and the task mapping
would all be rewritten around it. Blocks in GLSL shaders (``.vert``/``.frag``: relief, maps 7-9,
denoise 7) get the same two kinds from :mod:`geomlib.grading.glsl_mutants` (a tokenizer, no
``ast``); their probe sets the block's results to NaN, since GLSL cannot raise.

Grading many mutants: ``--jobs`` worker processes each grade mutants one after another in one
interpreter (the sandbox's zygote and pytest's imports are reused: about 1.5 s per task instead of
8 s for a fresh ``geomlib grade``). A mutant's run gets a time budget of five times the solution's
(at least 60 s): a mutant that loops forever is killed by the budget, and the report says so.

``--in-order`` (:func:`in_order`) uses the same copies and workers for another question: a copy with
Tasks 1..N done and the later tasks stubbed (as ``geomlib stubs build`` stubs them) must get full
marks from ``--task N``, for every N: a student doing the tasks in order meets no later task.

Longer than most modules (about 860 lines) on purpose: generating mutants, grading them and
reporting are one pipeline over one data type (``Mutant``); split, each part would import the
others' internals.
"""

from __future__ import annotations

import ast
import json
import os
import queue
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import zlib
from dataclasses import asdict, dataclass, field
from pathlib import Path

from geomlib.grading import glsl_mutants
from geomlib.grading import impl as _impl
from geomlib.grading.course import course
from geomlib.taskref import find_task, task_at_start

__all__ = ["Mutant", "generate", "audit", "markdown", "AuditError", "in_order", "in_order_copy", "in_order_markdown"]

_HELPER = "_geomlib_audit_nothing"
NOTHING_MODES = ("zeros", "input", "constant")
#: How many mutants per lab ``--quick`` grades (a fixed, seeded sample).
QUICK_PER_LAB = 3


class AuditError(ValueError):
    """A lab that cannot be audited (unknown, no blocks, solution not at full marks, bad declaration)."""


@dataclass
class Mutant:
    id: str  # "<file>:<line>:<col>:<op>" (stable while the solution's line does not move)
    lab: str
    file: str  # relative to solutions/<lab>/
    line: int
    task: int
    title: str
    kind: str  # "nothing" or "operator"
    op: str  # "zeros", "+ → -", "3 → 6", ...
    diff: str  # "- old line" / "+ new line", one line each
    function: str = ""  # the module-level function that holds the block
    source: str = field(repr=False, default="")


# ---------------------------------------------------------------------------------- finding the blocks


@dataclass
class _Block:
    file: str
    start: int  # line of BEGIN (1-based)
    end: int  # line of END
    task: int
    title: str


def _blocks(lab_dir: Path) -> tuple[list[_Block], list[str]]:
    """The solution blocks of a lab (Python and GLSL) and the names of the shader files with blocks."""
    from geomlib.grading import stubs

    out, shaders = [], []
    for f in sorted(lab_dir.rglob("*")):
        if "__pycache__" in f.parts or f.suffix not in stubs.STUB_SUFFIXES:
            continue
        rel = str(f.relative_to(lab_dir))
        blocks, _ = stubs._scan(f.read_text(), rel)
        if not blocks:
            continue
        if f.suffix != ".py":
            shaders.append(f"{rel} ({len(blocks)} block{'s' if len(blocks) != 1 else ''})")
        for b in blocks:
            m = find_task(b.task, titled=True)
            if not m:
                raise AuditError(f"{rel}, line {b.start}: a solution block without 'Task N (title)' in its marker")
            out.append(_Block(rel, b.start, b.end, m.number, m.title.strip()))
    return out, shaders


# ---------------------------------------------------------------------------------- text edits


def _offset(lines: list[str], line: int, col: int) -> int:
    """Character offset in the joined text of (1-based line, UTF-8 byte column)."""
    before = sum(len(s) + 1 for s in lines[: line - 1])
    return before + len(lines[line - 1].encode("utf-8")[:col].decode("utf-8", errors="replace"))


def _span(lines, node) -> tuple[int, int]:
    return _offset(lines, node.lineno, node.col_offset), _offset(lines, node.end_lineno, node.end_col_offset)


def _diff(old: str, new: str) -> str:
    """The first changed line of two texts, as ``- old`` / ``+ new`` (stripped)."""
    a, b = old.splitlines(), new.splitlines()
    for i, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            j = len(b) - (len(a) - i)  # a change that adds lines: show the added ones
            added = " ⏎ ".join(s.strip() for s in b[i : max(i + 1, j + 1)])
            return f"- {x.strip()}\n+ {added}"
    return "(no change)"


# ---------------------------------------------------------------------------------- operator mutants

_BINOPS = {
    ast.Add: (ast.Sub, "+", "-"),
    ast.Sub: (ast.Add, "-", "+"),
    ast.Mult: (ast.Div, "*", "/"),
    ast.Div: (ast.Mult, "/", "*"),
}
_CMPOPS = {ast.Lt: "<=", ast.LtE: "<", ast.Gt: ">=", ast.GtE: ">"}
_CMPSYM = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}
#: Calls whose first two arguments commute: swapping them is an equivalent mutant, never generated.
_COMMUTATIVE = {
    "max", "min", "maximum", "minimum", "fmax", "fmin", "hypot", "add", "multiply", "logical_and",
    "logical_or", "logical_xor", "bitwise_and", "bitwise_or", "bitwise_xor", "union1d", "intersect1d",
    "array_equal", "isclose", "allclose", "equal", "not_equal",
}  # fmt: skip


def _number_variants(v) -> list[tuple[str, str]]:
    """(new literal, label) for a numeric constant: 0↔1, ×2, ½, +1 (distinct values only)."""
    out = []
    if isinstance(v, int):
        cands = [1 if v == 0 else 0, v * 2, v // 2, v + 1]
    else:
        cands = [1.0 if v == 0 else 0.0, v * 2, v / 2, v + 1]
    seen = {v}
    for c in cands:
        if c in seen:
            continue
        seen.add(c)
        out.append((repr(c), f"{v!r} → {c!r}"))
    return out


def _in_block(node, b: _Block) -> bool:
    return hasattr(node, "lineno") and b.start < node.lineno and node.end_lineno < b.end


def _operator_edits(text: str, tree: ast.AST, b: _Block) -> list[tuple[int, int, str, str, int, int]]:
    """(start, end, replacement, label, line, col) text edits for the operator mutants of one block."""
    lines = text.split("\n")
    seg = lambda n: text[slice(*_span(lines, n))]  # noqa: E731
    edits = []

    def gap_edit(left, right, sym, new, label, node):
        a, z = _span(lines, left)[1], _span(lines, right)[0]
        gap = text[a:z]
        k = gap.find(sym)
        if k < 0:
            return
        edits.append((a + k, a + k + len(sym), new, label, node.lineno, node.col_offset))

    for node in ast.walk(tree):
        if not _in_block(node, b):
            continue
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            s, e = _span(lines, node)
            for new, label in _number_variants(node.value):
                edits.append((s, e, new, label, node.lineno, node.col_offset))
        elif isinstance(node, ast.Constant) and isinstance(node.value, bool):
            s, e = _span(lines, node)
            new = "False" if node.value else "True"
            edits.append((s, e, new, f"{node.value} → {new}", node.lineno, node.col_offset))
        elif isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
            _, old, new = _BINOPS[type(node.op)]
            gap_edit(node.left, node.right, old, new, f"{old} → {new}", node)
        elif isinstance(node, ast.AugAssign) and type(node.op) in _BINOPS:
            _, old, new = _BINOPS[type(node.op)]
            gap_edit(node.target, node.value, old + "=", new + "=", f"{old}= → {new}=", node)
        elif isinstance(node, ast.Compare):
            left = node.left
            for op, right in zip(node.ops, node.comparators, strict=True):
                if type(op) in _CMPOPS:
                    old, new = _CMPSYM[type(op)], _CMPOPS[type(op)]
                    a, z = _span(lines, left)[1], _span(lines, right)[0]
                    gap = text[a:z]
                    m = re.search(re.escape(old) + r"(?![=<>])", gap)
                    if m:
                        edits.append((a + m.start(), a + m.end(), new, f"{old} → {new}", node.lineno, node.col_offset))
                left = right
        elif isinstance(node, ast.Subscript):
            idx = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
            for i in idx:
                if isinstance(i, ast.Name):
                    s, e = _span(lines, i)
                    edits.append((s, e, f"({i.id} + 1)", f"[{i.id}] → [{i.id} + 1]", i.lineno, i.col_offset))
        elif (
            isinstance(node, ast.Call)
            and len(node.args) >= 2
            and not any(isinstance(a, ast.Starred) for a in node.args[:2])
        ):
            a0, a1 = node.args[0], node.args[1]
            s0, e0 = _span(lines, a0)
            s1, e1 = _span(lines, a1)
            fname = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if seg(a0) != seg(a1) and fname not in _COMMUTATIVE:
                new = text[s1:e1] + text[e0:s1] + text[s0:e0]
                name = ast.unparse(node.func)
                label = f"{name}(a, b) → {name}(b, a)"
                edits.append((s0, e1, new, label, node.lineno, node.col_offset))
    return edits


# ---------------------------------------------------------------------------------- does-nothing mutants

_HELPER_SOURCE = f'''

def {_HELPER}_keep(objs):
    """geomlib audit: copies of the objects (dataclass instances) a block changes, taken at its start."""
    import copy as _copy
    import dataclasses as _dc

    return tuple((o, _copy.deepcopy(o)) for o in objs if _dc.is_dataclass(o) and not isinstance(o, type))


def {_HELPER}(x, mode, inputs=(), inplace=False, restore=()):
    """geomlib audit: a does-nothing replacement for a task's result ``x`` (zeros, an input, a constant)."""
    import numpy as _np
    import scipy.sparse as _sp

    for o, c in restore:  # the objects the block changed, back as the block found them
        o.__dict__.update(c.__dict__)

    if isinstance(x, tuple | list):
        if mode == "input":
            like = [a for a in inputs if isinstance(a, _np.ndarray)]
            out = []
            for v in x:
                same = [a for a in like if isinstance(v, _np.ndarray) and a.ndim == v.ndim and a.dtype.kind == v.dtype.kind and a.shape[1:] == v.shape[1:]]
                out.append(same[0].copy() if same else {_HELPER}(v, "zeros"))
                if same:
                    like.remove(same[0])
        else:
            out = [{_HELPER}(v, mode, inputs) for v in x]
        if inplace and isinstance(x, list):
            x[:] = out
            return x
        return type(x)(out) if isinstance(x, tuple) else out
    if isinstance(x, dict):
        return {{k: {_HELPER}(v, mode, inputs) for k, v in x.items()}}
    if _sp.issparse(x):
        return x * 0 if mode != "constant" else _sp.csr_matrix(_np.full(x.shape, 1.0 / max(1, x.shape[1]), dtype=x.dtype)) if x.shape[0] * x.shape[1] < 1 << 22 else x * 0
    if isinstance(x, _np.ndarray):
        new = None
        if mode == "input":
            for a in inputs:
                if isinstance(a, _np.ndarray) and a.ndim == x.ndim and a.dtype.kind == x.dtype.kind and a.shape[1:] == x.shape[1:]:
                    new = a.copy() if a.shape == x.shape or not inplace else None
                    break
        if new is None and mode == "constant":
            if x.dtype.kind == "b":
                new = _np.ones_like(x)
            elif x.dtype.kind in "iu":
                new = _np.ones_like(x)
            elif x.dtype.kind in "fc":
                fin = x[_np.isfinite(x)] if x.size else x
                new = _np.full_like(x, fin.mean() if fin.size else 0)
        if new is None:
            new = _np.zeros_like(x)
        if inplace and new.shape == x.shape and x.flags.writeable:
            x[...] = new
            return x
        return new
    if isinstance(x, bool | _np.bool_):
        return mode == "constant"
    if isinstance(x, int | float | _np.number):
        if mode == "input":
            for a in inputs:
                if type(a) is type(x):
                    return a
        return type(x)(1 if mode == "constant" else 0)
    return x
'''


def _is_compiled(fn: ast.AST) -> bool:
    for d in getattr(fn, "decorator_list", []):
        target = d.func if isinstance(d, ast.Call) else d
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit", "vectorize", "guvectorize", "stencil"):
            return True
    return False


def _enclosing(tree: ast.Module, b: _Block) -> list[ast.AST]:
    """The function definitions that contain the block, outermost first."""
    chain = []
    node = tree
    while True:
        inner = [
            n
            for n in ast.iter_child_nodes(node)
            if n.__class__.__name__ != "ClassDef"
            and hasattr(n, "lineno")
            and n.lineno < b.start
            and n.end_lineno > b.start
        ]
        if not inner:
            return chain
        node = inner[0]
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            chain.append(node)


def _walk_no_defs(node):
    """Nodes under ``node`` without entering nested functions, lambdas or comprehensions."""
    todo = list(ast.iter_child_nodes(node))
    while todo:
        n = todo.pop()
        yield n
        if isinstance(
            n,
            ast.FunctionDef
            | ast.AsyncFunctionDef
            | ast.Lambda
            | ast.ListComp
            | ast.SetComp
            | ast.DictComp
            | ast.GeneratorExp,
        ):
            continue
        todo.extend(ast.iter_child_nodes(n))


def _stored_bases(nodes) -> list[str]:
    """Names whose attributes or items the nodes assign to (``state.V[i] = p`` gives ``state``)."""
    out = []
    for n in nodes:
        name = _stored_base(n)
        if name is not None and name not in out:
            out.append(name)
    return out


def _stored_base(n) -> str | None:
    """The name an item or attribute store writes into (``state.V[i] = p`` gives ``state``), else None."""
    if not (isinstance(n, ast.Subscript | ast.Attribute) and isinstance(n.ctx, ast.Store)):
        return None
    base = n.value
    while isinstance(base, ast.Subscript | ast.Attribute):
        base = base.value
    return base.id if isinstance(base, ast.Name) else None


def _changed_through_calls(stmts, params: list[str], defs: dict) -> list[str]:
    """The parameters the block hands to one of the lab's functions that assigns into that argument
    (``greedy_collapse`` calls ``contract_pair(state, ...)``, which sets ``state.V[i]``)."""
    out = []
    for s in stmts:
        for n in [s, *_walk_no_defs(s)]:
            if not (isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id in defs):
                continue
            g = defs[n.func.id]
            names = [a.arg for a in (*g.args.posonlyargs, *g.args.args)]
            stored = _stored_bases(ast.walk(g))
            for k, arg in enumerate(n.args):
                if isinstance(arg, ast.Name) and arg.id in params and k < len(names) and names[k] in stored:
                    out.append(arg.id)
    return out


def _nothing_edits(text: str, tree: ast.Module, b: _Block, defs: dict | None = None) -> tuple[list, str]:
    """Text edits that make a block's results trivial, with ``{mode}`` left to fill in; or ([], why not).

    ``defs``: the lab's module-level functions by name, to find the objects the block changes through
    them."""
    chain = _enclosing(tree, b)
    if not chain:
        return [], "the block is not inside a function"
    fn = chain[-1]
    if any(_is_compiled(f) for f in chain):
        return [], "compiled kernel (numba): no does-nothing mutant"
    lines = text.split("\n")
    stmts = [s for s in _walk_no_defs(fn) if isinstance(s, ast.stmt) and _in_block(s, b)]
    params = [a.arg for a in (*fn.args.posonlyargs, *fn.args.args) if a.arg not in ("self", "cls")]
    # The inputs as the block sees them at its start (the block may rebind V or F): held in a name
    # set on the block's first line, inside the block.
    inputs = f"{_HELPER}_in"
    indent = re.match(r"\s*", lines[b.start - 1]).group(0)
    at_start = _offset(lines, b.start + 1, 0)
    # Copies (of what has a .copy()): the block may change an input in place (push_out's P), and the "input"
    # mutant must return the input as it was, not the block's work.
    copies = "".join(f"{p}, " for p in params)
    capture = (
        at_start,
        at_start,
        f"{indent}{inputs} = tuple(getattr(a, 'copy', lambda a=a: a)() for a in ({copies}))\n",
    )
    edits = []
    # Objects (dataclass instances such as simplification's SimplifyState) that the block changes, directly or
    # through the lab's functions, are results too: a block that does nothing leaves them as it found them.
    changed_params = [p for p in params if p in _stored_bases(n for s in stmts for n in [s, *_walk_no_defs(s)])]
    kept = list(dict.fromkeys(changed_params + _changed_through_calls(stmts, params, defs or {})))
    objs = f"{_HELPER}_obj"
    restore = f", restore={objs}" if kept else ""
    if kept:
        capture = (
            at_start,
            at_start,
            capture[2] + f"{indent}{objs} = {_HELPER}_keep(({''.join(f'{p}, ' for p in kept)}))\n",
        )
    # Returns inside the block give trivial values.
    for s in stmts:
        if isinstance(s, ast.Return) and s.value is not None:
            a, z = _span(lines, s.value)
            edits.append((a, z, f"{_HELPER}(({text[a:z]}), {{mode!r}}, {inputs}{restore})"))
    # Names the block binds or changes in place, read elsewhere in the function, become trivial after it.
    bound, changed = [], []
    for s in stmts:
        for n in _walk_no_defs(s) if not isinstance(s, ast.Return) else ():
            if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store) and n.id not in bound:
                bound.append(n.id)
            elif _stored_base(n) is not None:
                if _stored_base(n) not in changed:
                    changed.append(_stored_base(n))
            elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and isinstance(n.func.value, ast.Name):
                if (
                    n.func.attr in ("append", "extend", "insert", "update", "add", "fill", "sort")
                    and n.func.value.id not in changed
                ):
                    changed.append(n.func.value.id)
    read_outside = {
        n.id
        for n in _walk_no_defs(fn)
        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load) and not (b.start < n.lineno < b.end)
    }
    # Closures read names too (relief's f(k, d)): count loads in nested functions as well.
    read_outside |= {n.id for n in ast.walk(fn) if isinstance(n, ast.Name) and not (b.start < n.lineno < b.end)}
    resets = []
    for name in bound:
        if name in read_outside and name not in changed:
            resets.append(f"{indent}{name} = {_HELPER}({name}, {{mode!r}}, {inputs})")
    for name in changed:
        resets.append(f"{indent}{name} = {_HELPER}({name}, {{mode!r}}, {inputs}, inplace=True{restore})")
        restore = ""
    if restore:
        resets.append(f"{indent}{_HELPER}(None, {{mode!r}}{restore})")
    last = stmts and max(s.end_lineno for s in stmts)
    if resets and not (
        stmts and any(isinstance(s, ast.Return) for s in stmts if s.end_lineno == last and s.col_offset == len(indent))
    ):
        at = _offset(lines, b.end, 0)
        edits.append((at, at, "\n".join(resets) + "\n"))
    if not edits:
        return [], "the block has no result the function uses"
    return [capture, *edits], ""


def _apply(text: str, edits: list[tuple[int, int, str]]) -> str:
    for a, z, new in sorted(edits, key=lambda e: e[0], reverse=True):
        text = text[:a] + new + text[z:]
    return text


# ---------------------------------------------------------------------------------- generation


def _unique_id(out: list[Mutant], base: str) -> str:
    """``base``, or ``base#2``, ``base#3``, ... when a mutant of ``out`` already has that id (two
    edits of the same kind at one place)."""
    ids = {m.id for m in out}
    mid, k = base, 2
    while mid in ids:
        mid, k = f"{base}#{k}", k + 1
    return mid


def _compiles(text: str, tree: ast.Module, a: int, z: int, new: str, filename: str) -> bool:
    """Whether ``text`` with ``text[a:z]`` replaced by ``new`` compiles, judged on the top-level
    statement that holds the edit only (its decorators to its last line): the rest of the file is
    the solution's, which compiles, and nothing outside a statement changes what compiles inside it.
    A lab file has hundreds of operator mutants: compiling each whole file took most of ``generate``."""
    lines = text.splitlines(keepends=True)
    starts = [0]
    for line in lines:
        starts.append(starts[-1] + len(line))
    for node in tree.body:
        first = min([node.lineno, *(d.lineno for d in getattr(node, "decorator_list", ()))])
        s, e = starts[first - 1], starts[node.end_lineno]
        if s <= a and z <= e:
            src = text[s:a] + new + text[z:e]
            break
    else:  # not inside one statement: the whole file
        src = text[:a] + new + text[z:]
    try:
        compile(src, filename, "exec", dont_inherit=True)
    except SyntaxError:
        return False
    return True


def generate(lab: str, lab_dir: Path | None = None, *, check_glsl: bool = True) -> tuple[list[Mutant], list[str]]:
    """Every mutant of a lab's solution, in file and line order, and notes on what was not mutated.

    ``check_glsl``: drop the GLSL operator mutants that do not compile (asks the driver in a child
    process; a few seconds for its GL context)."""
    lab_dir = Path(lab_dir or course().lab(lab).solution)
    if not lab_dir.is_dir():
        raise AuditError(f"no solution folder {lab_dir}")
    blocks, shaders = _blocks(lab_dir)
    notes = []
    out: list[Mutant] = []
    seen: set[str] = set()
    texts: dict[str, tuple[str, ast.Module]] = {}
    glsl: list[Mutant] = []
    defs = {}  # the lab's module-level functions by name (objects changed through them, see _nothing_edits)
    for f in sorted(lab_dir.rglob("*.py")):
        if "__pycache__" not in f.parts:
            defs |= {n.name: n for n in ast.parse(f.read_text()).body if isinstance(n, ast.FunctionDef)}
    for b in blocks:
        if not b.file.endswith(".py"):
            glsl += _glsl_mutants(lab, lab_dir, b, notes)
            continue
        if b.file not in texts:
            text = (lab_dir / b.file).read_text()
            texts[b.file] = (text, ast.parse(text))
        text, tree = texts[b.file]
        edits, why = _nothing_edits(text, tree, b, defs)
        chain = _enclosing(tree, b)
        fname = chain[0].name if chain else ""
        if not edits:
            notes.append(f"{b.file}:{b.start} (Task {b.task}): {why}")
        for mode in NOTHING_MODES if edits else ():
            filled = [(a, z, new.format(mode=mode)) for a, z, new in edits]
            src = _apply(text, filled).rstrip("\n") + "\n" + _HELPER_SOURCE
            diff = f"- (block at line {b.start + 1}: its results)\n+ {mode} of the same shape and dtype"
            if mode == "input":
                diff = f"- (block at line {b.start + 1}: its results)\n+ the function's input of the same kind (else zeros)"
            mid = f"{b.file}:{b.start}:nothing-{mode}"
            out.append(Mutant(mid, lab, b.file, b.start, b.task, b.title, "nothing", mode, diff, fname, src))
        for a, z, new, label, line, col in _operator_edits(text, tree, b):
            src = _apply(text, [(a, z, new)])
            if src in seen or src == text:
                continue
            if not _compiles(text, tree, a, z, new, b.file):
                continue
            seen.add(src)
            mid = _unique_id(out, f"{b.file}:{line}:{col}:{label}")
            out.append(Mutant(mid, lab, b.file, line, b.task, b.title, "operator", label, _diff(text, src), fname, src))
    ok = (
        glsl_mutants.compiles([(Path(m.file).suffix, m.source) for m in glsl if m.kind == "operator"])
        if check_glsl
        else []
    )
    if ok is None and glsl:
        notes.append(
            "GLSL operator mutants not compile-checked (no GL context): the ones that do not compile count as killed"
        )
    ok = iter(ok or [])
    dropped = [m for m in glsl if m.kind == "operator" and not next(ok, True)]
    if dropped:
        notes.append(f"GLSL: {len(dropped)} operator mutant(s) dropped because they do not compile (type errors)")
    out += [m for m in glsl if m not in dropped]
    return out, notes


def _glsl_mutants(lab: str, lab_dir: Path, b: _Block, notes: list[str]) -> list[Mutant]:
    """The mutants of one GLSL block (:mod:`geomlib.grading.glsl_mutants`), before the compile check."""
    text = (lab_dir / b.file).read_text()
    shape = glsl_mutants.Shape(text, b.start, b.end)
    out: list[Mutant] = []
    if shape.why:
        notes.append(f"{b.file}:{b.start} (Task {b.task}): {shape.why}")
    seen = {text}
    for mode in glsl_mutants.MODES:
        src = shape.nothing(mode)
        if src is None or src in seen:
            continue
        seen.add(src)
        diff = f"- (block at line {b.start + 1}: its results)\n+ {mode} of the same type"
        if mode == "input":
            diff = f"- (block at line {b.start + 1}: its results)\n+ the function's input of the same type (else zeros)"
        mid = f"{b.file}:{b.start}:nothing-{mode}"
        out.append(Mutant(mid, lab, b.file, b.start, b.task, b.title, "nothing", mode, diff, shape.fn, src))
    for a, z, new, label, line, col in shape.operators() if not shape.why else ():
        src = _apply(text, [(a, z, new)])
        if src in seen:
            continue
        seen.add(src)
        mid = _unique_id(out, f"{b.file}:{line}:{col}:{label}")
        out.append(Mutant(mid, lab, b.file, line, b.task, b.title, "operator", label, _diff(text, src), shape.fn, src))
    return out


def quick_sample(mutants: list[Mutant], lab: str, n: int = QUICK_PER_LAB) -> list[Mutant]:
    """A fixed sample (seeded by the lab's name): does-nothing mutants (half, rounded up), then operators."""
    rng = random.Random(zlib.crc32(lab.encode()))
    nothing = [m for m in mutants if m.kind == "nothing" and m.op == "zeros"]
    ops = [m for m in mutants if m.kind == "operator"]
    pick = rng.sample(nothing, min(len(nothing), max(1, (n + 1) // 2)))
    pick += rng.sample(ops, min(len(ops), n - len(pick)))
    order = {m.id: i for i, m in enumerate(mutants)}
    return sorted(pick, key=lambda m: order[m.id])


def sample_mutants(mutants: list[Mutant], lab: str, n: int) -> list[Mutant]:
    """A fixed sample of ``n`` of ``mutants`` (seeded by the lab's name: the same ones every run), in order."""
    if n >= len(mutants):
        return list(mutants)
    rng = random.Random(zlib.crc32(f"sample:{lab}".encode()))
    pick = {m.id for m in rng.sample(mutants, n)}
    return [m for m in mutants if m.id in pick]


# ---------------------------------------------------------------------------------- equivalent mutants


def equivalents(lab: str) -> dict[str, str]:
    """``{mutant id: reason}`` from ``tests/graded/<lab>/equivalent_mutants.toml``::

    [[equivalent]]
    id = "loop.py:168:20:3 → 6"
    reason = "why no test can tell it from the solution"
    """
    import tomllib

    path = course().lab(lab).mutants
    if not path.is_file():
        return {}
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as e:
        raise AuditError(f"{path}: {e}") from None
    out = {}
    for i, entry in enumerate(data.get("equivalent", []), start=1):
        if not isinstance(entry, dict) or not entry.get("id") or not str(entry.get("reason", "")).strip():
            raise AuditError(f"{path}: entry {i} needs an id and a reason")
        out[str(entry["id"])] = str(entry["reason"]).strip()
    return out


# ---------------------------------------------------------------------------------- grading


#: ``{pytest node id: lab functions the test calls}``, filled by the hook below while the worker grades.
_CALLS: dict[str, list[str]] = {}


def pytest_collection_modifyitems(session, config, items):
    """Pytest hook (the worker passes ``-p geomlib.grading.audit``): which lab functions each graded
    test calls, as the grader reads them (``Case.function``, ``lab.name(...)`` in a hand-written test)."""
    from geomlib.grading import plugin, tasks

    tables: dict = {}
    for item in items:
        lab = plugin.lab_of(item.path)
        if lab is None:
            continue
        if lab not in tables:
            tables[lab] = tasks.table(lab)
        _CALLS[item.nodeid] = tasks.test_functions(item, tables[lab])


def _worker_main() -> int:
    """``python -m geomlib.grading.audit --worker``: grade requests (JSON lines on stdin), one per line out."""
    reply = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # anything else written to stdout goes to the log, not into the replies
    from geomlib.grading import audit as registered  # the module pytest loads with -p (this one is __main__)
    from geomlib.grading.grade import grade
    from geomlib.grading.settings import env

    user_limit = env("GEOMLIB_TIME_LIMIT")
    for line in sys.stdin:
        req = json.loads(line)
        t = time.time()
        os.environ["GEOMLIB_TIME_BUDGET"] = str(req.get("budget") or "")
        if not user_limit:  # GEOMLIB_TIME_LIMIT set by the user wins
            os.environ["GEOMLIB_TIME_LIMIT"] = str(req.get("time_limit") or "")
        try:
            registered._CALLS.clear()
            records: list = []
            data = grade(
                req["impl"], [req["lab"]], task=req["task"], feedback_dir="", extra_args=["-p", "geomlib.grading.audit"],
                records_out=records, every_test=req.get("every_test", True),
            )  # fmt: skip
            ids = [r.nodeid for r in records]
            ids = ids if len(ids) == len(data["tests"]) else [""] * len(data["tests"])
            tests = [
                {"name": x["name"], "score": x["score"], "max": x["max_score"], "passed": x["status"] == "passed",
                 "output": x.get("output", "")[:300], "calls": registered._CALLS.get(nid, [])}
                for x, nid in zip(data["tests"], ids, strict=True)
            ]  # fmt: skip
            out = {"ok": True, "tests": tests, "note": data.get("output", "")[:1000]}
        except BaseException as e:  # noqa: BLE001  (the audit keeps going; the mutant's row says what happened)
            out = {"ok": False, "error": f"{type(e).__name__}: {e}"}
        out["seconds"] = time.time() - t
        reply.write(json.dumps(out) + "\n")
    return 0


class _Pool:
    """``jobs`` worker processes that grade one request at a time each."""

    def __init__(self, jobs: int, log_dir: Path):
        self.jobs, self.log_dir = jobs, log_dir
        self.procs: dict[int, subprocess.Popen] = {}

    def _start(self, k: int) -> subprocess.Popen:
        env = {**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
        log = open(self.log_dir / f"worker-{k}.log", "ab")  # noqa: SIM115
        return subprocess.Popen(
            [sys.executable, "-m", "geomlib.grading.audit", "--worker"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, text=True, env=env,
            start_new_session=True, cwd=str(_impl.course_root()),
        )  # fmt: skip

    def run(self, requests: list[dict], on_done) -> None:
        """Grade ``requests`` (a request may hold ``prepare``: a function that returns the real one);
        ``on_done(index, request, reply)`` is called from the worker threads as replies arrive."""
        todo: queue.Queue = queue.Queue()
        for i, r in enumerate(requests):
            todo.put((i, r))

        def serve(k):
            while True:
                try:
                    i, r = todo.get_nowait()
                except queue.Empty:
                    return
                if "prepare" in r:
                    r = r["prepare"]()
                p = self.procs.get(k)
                if p is None or p.poll() is not None:
                    p = self.procs[k] = self._start(k)
                try:
                    p.stdin.write(json.dumps(r) + "\n")
                    p.stdin.flush()
                    line = p.stdout.readline()
                    res = json.loads(line) if line else {"ok": False, "error": "the audit worker stopped"}
                except (OSError, ValueError) as e:
                    res = {"ok": False, "error": f"the audit worker failed: {e}"}
                on_done(i, r, res)

        threads = [threading.Thread(target=serve, args=(k,), daemon=True) for k in range(self.jobs)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    def close(self):
        for p in self.procs.values():
            try:
                p.stdin.close()
                p.wait(30)
            except (OSError, subprocess.TimeoutExpired):
                p.kill()
                p.wait()


class _Progress:
    def __init__(self, total: int, stream=sys.stderr, *, what: str = "mutants", bad: str = "survived"):
        self.total, self.done, self.survived, self.t0, self.stream = total, 0, 0, time.time(), stream
        self.what, self.bad = what, bad

    def step(self, survived: bool, what: str = "") -> None:
        self.done += 1
        self.survived += survived
        width = 30
        fill = int(width * self.done / max(1, self.total))
        el = time.time() - self.t0
        eta = el / self.done * (self.total - self.done)
        line = (
            f"\r[{'#' * fill}{'.' * (width - fill)}] {self.done}/{self.total} {self.what}, "
            f"{self.survived} {self.bad}, {el:.0f} s (about {eta:.0f} s left) {what[:40]:<40}"
        )
        self.stream.write(line)
        self.stream.flush()

    def end(self) -> None:
        self.stream.write("\n")
        self.stream.flush()


#: Seconds per call for a lab with numba kernels (unless GEOMLIB_TIME_LIMIT is set): each mutant is
#: a new folder, so its first call compiles every kernel again (remeshing: 20 s of CPU, over 150 s
#: of wall time at load 20), which the grader's own limit (a warm cache) does not allow for.
COMPILED_CALL_LIMIT = 600.0


def _jit_request(solution: Path) -> dict:
    """For a lab with ``@njit`` kernels: :data:`COMPILED_CALL_LIMIT` per call.

    No new zygote per mutant: each mutant is a new folder, so the sandbox gives it a new snapshot
    with its own numba cache (:meth:`geomlib.grading.sandbox._Zygote.snapshot`), and a given kernel
    that calls a task kernel (remeshing's ``clean_pass`` calls ``flip``) is compiled again with that
    mutant's task kernel, never loaded with another mutant's.
    """
    compiled = any("@njit" in p.read_text(encoding="utf-8") for p in sorted(solution.rglob("*.py")))
    return {"time_limit": COMPILED_CALL_LIMIT} if compiled else {}


def _copy_lab(src: Path, dest: Path) -> None:
    shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))


def _score(res: dict) -> tuple[float, float]:
    tests = res.get("tests", [])
    return sum(t["score"] for t in tests), sum(t["max"] for t in tests)


def _first_failure(res: dict) -> str:
    if not res.get("ok"):
        return res.get("error", "")
    for t in res.get("tests", []):
        if not t["passed"]:
            return f"{t['name']}: {' '.join(t['output'].split())}"[:200]
    return ""


def select_mutants(muts: list, *, kind: str | None = None, tasks=None, files=None) -> list:
    """The mutants ``geomlib audit --kind/--task/--file`` keep: of that kind, of one of those task
    numbers, of a solution file whose path contains one of the strings (all given filters apply)."""
    if kind:
        muts = [m for m in muts if m.kind == kind]
    if tasks:
        muts = [m for m in muts if m.task in tasks]
    if files:
        muts = [m for m in muts if any(f in m.file for f in files)]
    return muts


def _labs_and_work(labs: list[str] | None, prefix: str) -> tuple[list[str], Path]:
    """The labs asked for (all by default; an unknown one is an :class:`AuditError`) and a new work
    folder the sandbox user can read (the copies are graded from there)."""
    names = labs or _impl.lab_names()
    known = _impl.lab_names()
    unknown = [n for n in names if n not in known]
    if unknown:
        raise AuditError(f"unknown lab(s): {', '.join(unknown)}; known: {', '.join(known)}")
    work = Path(tempfile.mkdtemp(prefix=prefix))
    os.chmod(work, 0o755)
    return names, work


def audit(
    labs: list[str] | None = None,
    *,
    quick: bool = False,
    jobs: int = 1,
    progress: bool = True,
    log=print,
    kind: str | None = None,
    sample: int | None = None,
    tasks: list[int] | None = None,
    files: list[str] | None = None,
) -> dict:
    """Grade the mutants of each lab; returns the report as a dict (see :func:`markdown`).

    ``kind`` (``"nothing"`` or ``"operator"``) keeps one kind of mutant; ``sample`` grades a fixed,
    seeded sample of that many mutants per lab (after ``kind``); ``tasks`` keeps the mutants of those
    task numbers, ``files`` those whose solution file (``shaders/cube_shadow.frag``) contains one of
    the strings (``shaders/``: the GLSL part)."""
    from geomlib.grading import tasks as _tasks

    names, work = _labs_and_work(labs, "geomlib-audit-")
    t_start = time.time()
    report: dict = {"labs": {}, "quick": quick, "jobs": jobs, "kind": kind, "sample": sample}
    if tasks or files:
        report["only"] = {"tasks": tasks or [], "files": files or []}
    if kind not in (None, "nothing", "operator"):
        raise AuditError(f"unknown mutant kind {kind!r}: 'nothing' or 'operator'")
    runs_of: dict[str, dict] = {}  # lab -> {function: every lab function a call of it runs}
    jit: dict[str, dict] = {}  # lab -> what its requests add when it has compiled kernels (_jit_request)
    tabs: dict = {}  # lab -> its TaskTable
    pool = _Pool(max(1, jobs), work)
    try:
        plan = []  # (lab, mutant)
        for lab in names:
            muts, notes = generate(lab)
            eq = equivalents(lab)
            ids = {m.id for m in muts}
            stale = [i for i in eq if i not in ids]
            total = len(muts)
            muts = select_mutants(muts, kind=kind, tasks=tasks, files=files)
            if quick:
                muts = quick_sample(muts, lab)
            elif sample:
                muts = sample_mutants(muts, lab, sample)
            tab = _tasks.derive(course().lab(lab).solution)
            runs_of[lab] = {f: {f, *tab.composites.get(f, ())} for f in {*tab.tasks, *tab.composites}}
            tabs[lab] = tab
            tasks = sorted({m.task for m in muts})
            report["labs"][lab] = {
                "notes": notes,
                "stale_equivalents": stale,
                "equivalent_declared": eq,
                "tasks": {},
                "mutants": [],
                "baseline": {},
                "errors": [],
                "generated": total,
            }
            plan.append((lab, muts, tasks))
            jit[lab] = _jit_request(course().lab(lab).solution)
        # Baseline: the unchanged solution, graded task by task the same way. --quick skips it (the
        # test suite already checks that the solutions score full marks): a mutant is killed when it
        # scores less than the maximum.
        base_reqs = []
        for lab, _muts, tasks in [] if quick else plan:
            d = work / "baseline"
            if not (d / lab).exists():
                _copy_lab(course().lab(lab).solution, d / lab)
            base_reqs += [{"impl": str(d), "lab": lab, "task": t, "budget": None, **jit[lab]} for t in tasks]
        base: dict = {}

        def base_done(i, r, res):
            base[(r["lab"], r["task"])] = res

        if progress and base_reqs:
            sys.stderr.write(f"grading the solution ({len(base_reqs)} task runs)...\n")
        pool.run(base_reqs, base_done)
        reqs = []
        for lab, muts, tasks in plan:
            lr = report["labs"][lab]
            for t in [] if quick else tasks:
                res = base.get((lab, t), {})
                got, top = _score(res)
                lr["baseline"][t] = {"score": got, "max": top, "seconds": round(res.get("seconds", 0.0), 2)}
                if not res.get("ok") or got < top:
                    lr["errors"].append(
                        f"Task {t}: the solution itself scores {got:g}/{top:g} ({_first_failure(res)}); its mutants are not graded"
                    )
            for k, m in enumerate(muts):
                b = lr["baseline"].get(m.task, {})
                if not quick and (b.get("score", 0) < b.get("max", 0) or not base[(lab, m.task)].get("ok")):
                    continue
                budget = max(60.0, 5 * b.get("seconds", 0.0)) if not quick else 120.0
                d = work / f"{lab}-{k}"

                def prepare(m=m, d=d, budget=budget):
                    _copy_lab(course().lab(m.lab).solution, d / m.lab)
                    (d / m.lab / m.file).write_text(m.source)
                    return {
                        "impl": str(d),
                        "lab": m.lab,
                        "task": m.task,
                        "budget": budget,
                        "mutant": m.id,
                        **jit[m.lab],
                    }

                reqs.append({"prepare": prepare, "mutant": m})
        # Which tests run each block: a probe copy raises at the block's first line; the tests it
        # fails are the ones that reach the block (measured through the same grading path).
        probes, covered = [], {}  # covered: (lab, file, line) -> names of the tests that run the block
        for key in dict.fromkeys((r["mutant"].lab, r["mutant"].file, r["mutant"].line, r["mutant"].task)
                                 for r in reqs if r["mutant"].kind == "nothing"):  # fmt: skip
            d = work / f"probe-{len(probes)}"

            def prepare_probe(key=key, d=d):
                lab, file, line, task = key
                _copy_lab(course().lab(lab).solution, d / lab)
                (d / lab / file).write_text(_probe_source((course().lab(lab).solution / file).read_text(), line, file))
                return {"impl": str(d), "lab": lab, "task": task, "budget": None if jit[lab] else 120.0, **jit[lab]}

            probes.append({"prepare": prepare_probe, "key": key})

        def probe_done(i, r, res):
            shutil.rmtree(r["impl"], ignore_errors=True) if "impl" in r else None
            if res.get("ok"):
                # A test the probe failed only by a time limit (a loaded machine) does not show that it runs the block.
                covered[probes[i]["key"][:3]] = {
                    t["name"]
                    for t in res["tests"]
                    if not t["passed"]
                    and ("geomlib audit: probe" in t.get("output", "") or not _TIMED_OUT.search(t.get("output", "")))
                }

        if progress and probes:
            sys.stderr.write(f"finding the tests that run each block ({len(probes)} probe runs)...\n")
        pool.run(probes, probe_done)
        prog = _Progress(len(reqs)) if progress else None
        rows: dict[int, dict] = {}

        def done(i, r, res):
            m: Mutant = reqs[i]["mutant"]
            shutil.rmtree(r["impl"], ignore_errors=True) if "impl" in r else None
            lr = report["labs"][m.lab]
            got, top = _score(res)
            own: list[dict] = []  # a does-nothing mutant's tests that run the block's function
            task_status = None  # the old rule for does-nothing mutants: killed when the whole task scores 0
            full = lr["baseline"][m.task]["score"] if m.task in lr["baseline"] else top
            if not res.get("ok"):
                status = "error"
            elif top == 0:
                status = "survived"  # no graded test of the task at all
            elif m.kind == "nothing":
                status = "killed" if got == 0 else ("partly killed" if got < full else "survived")
                task_status = status
                own = _own_tests(res, m.function, runs_of[m.lab], covered.get((m.lab, m.file, m.line)))
                if own:  # the rule: the tests that run the block's function score 0
                    own_got, own_top = sum(t["score"] for t in own), sum(t["max"] for t in own)
                    status = "killed" if own_got == 0 else ("partly killed" if own_got < own_top else "survived")
            else:
                status = "killed" if got < full else "survived"
            task_status = task_status or status
            eq = lr["equivalent_declared"].get(m.id)
            if eq is not None:
                status = "equivalent" if status == "survived" else f"ERROR: declared equivalent but {status}"
            failure = _first_failure(res)
            timeout = bool(_TIMED_OUT.search(failure))
            row = {
                **{k: v for k, v in asdict(m).items() if k != "source"},
                "status": status,
                "score": got,
                "max": top,
                "seconds": round(res.get("seconds", 0.0), 2),
                "why": failure,
                "by_time": timeout,
            }
            if m.kind == "nothing":
                row["task_status"] = task_status
                row["own_tests"] = len(own) if own else 0
                row["own_score"] = sum(t["score"] for t in own) if own else None
                row["own_max"] = sum(t["max"] for t in own) if own else None
                row["kept_points"] = [
                    f"{t['name']} ({t['score']:g}/{t['max']:g})"
                    for t in (own or res.get("tests", []))
                    if t["score"] > 0
                ]
            if eq is not None:
                row["reason"] = eq
            rows[i] = row
            if prog:
                prog.step(status in ("survived", "partly killed"), m.id)

        pool.run(reqs, done)
        if prog:
            prog.end()
        _grade_elsewhere(pool, reqs, rows, report, tabs, jit, work, quick, progress)
        for i in sorted(rows):
            report["labs"][rows[i]["lab"]]["mutants"].append(rows[i])
        for lr in report["labs"].values():
            lr["tasks"] = _task_summary(lr)
            for s in lr["stale_equivalents"]:
                lr["errors"].append(f"equivalent_mutants.toml names {s!r}, which is not a mutant of the solution")
            for r in lr["mutants"]:
                if r["status"].startswith("ERROR"):
                    lr["errors"].append(f"{r['id']}: {r['status']} ({r['why']})")
                elif r["status"] == "error":
                    lr["errors"].append(f"{r['id']}: could not be graded ({r['why']})")
    finally:
        pool.close()
        shutil.rmtree(work, ignore_errors=True)
    report["seconds"] = round(time.time() - t_start, 1)
    return report


def _grade_elsewhere(pool, reqs, rows, report, tabs, jit, work, quick, progress) -> None:
    """An operator mutant its own task's tests do not catch is graded on the tests of the other tasks
    whose functions run its block (remeshing's ``split`` kernel, Task 1, is graded through
    ``split_long_edges`` and the loop, Tasks 4 and 10): a student with that bug loses points there.
    It is killed when it scores less than the solution on one of them (``killed_by``)."""
    todo = []  # (row index, task)
    for i, row in rows.items():
        if row["kind"] != "operator" or row["status"] not in ("survived", "equivalent"):
            continue
        tab = tabs[row["lab"]]
        others = sorted(
            {t[0] for f, t in tab.tasks.items() if row["function"] in tab.composites.get(f, ()) and t[0] != row["task"]}
        )
        todo += [(i, t) for t in others]
    if not todo:
        return
    need = sorted({(rows[i]["lab"], t) for i, t in todo if t not in report["labs"][rows[i]["lab"]]["baseline"]})
    base: dict = {}
    if not quick:
        for lab, _t in need:
            if not (work / "baseline" / lab).exists():
                _copy_lab(course().lab(lab).solution, work / "baseline" / lab)
        pool.run(
            [{"impl": str(work / "baseline"), "lab": lab, "task": t, "budget": None, **jit[lab]} for lab, t in need],
            lambda k, r, res: base.__setitem__((r["lab"], r["task"]), res),
        )
        for (lab, t), res in base.items():
            got, top = _score(res)
            full = res.get("ok") and got >= top
            report["labs"][lab]["baseline"][t] = {
                "score": got,
                "max": top,
                "seconds": round(res.get("seconds", 0.0), 2),
            }
            if not full:
                report["labs"][lab]["errors"].append(
                    f"Task {t}: the solution itself scores {got:g}/{top:g} ({_first_failure(res)}); "
                    "mutants of other tasks are not graded on it"
                )
    again = []
    for i, t in todo:
        row = rows[i]
        b = report["labs"][row["lab"]]["baseline"].get(t)
        if not quick and (not b or b["score"] < b["max"]):
            continue
        m: Mutant = reqs[i]["mutant"]
        d = work / f"{m.lab}-again-{len(again)}"

        def prepare(m=m, d=d, t=t):
            _copy_lab(course().lab(m.lab).solution, d / m.lab)
            (d / m.lab / m.file).write_text(m.source)
            return {"impl": str(d), "lab": m.lab, "task": t, "budget": None, "mutant": m.id, **jit[m.lab]}

        again.append({"prepare": prepare, "row": i, "task": t})
    if progress and again:
        n = len({a["row"] for a in again})
        sys.stderr.write(
            f"grading {n} surviving operator mutant(s) on the other tasks that run their block ({len(again)} runs)...\n"
        )

    def again_done(k, r, res):
        shutil.rmtree(r["impl"], ignore_errors=True) if "impl" in r else None
        row, t = rows[again[k]["row"]], again[k]["task"]
        got, top = _score(res)
        full = report["labs"][row["lab"]]["baseline"].get(t, {}).get("score", top)
        if not res.get("ok") or got >= full or row["status"] not in ("survived", "equivalent"):
            return
        why = _first_failure(res)
        row["status"] = (
            "killed" if row["status"] == "survived" else f"ERROR: declared equivalent but killed by Task {t}'s tests"
        )
        row["killed_by"] = f"Task {t}"
        row["why"] = why
        row["by_time"] = bool(_TIMED_OUT.search(why))

    pool.run(again, again_done)


_TIMED_OUT = re.compile(r"time budget|timed out|took longer|time limit", re.I)


def _probe_source(text: str, line: int, file: str = ".py") -> str:
    """``text`` with a ``raise`` as the first statement of the block whose BEGIN marker is on ``line``
    (a GLSL block, which cannot raise, gives NaN: see :mod:`geomlib.grading.glsl_mutants`)."""
    if not file.endswith(".py"):
        from geomlib.grading import stubs

        end = next(b.end for b in stubs._scan(text, file)[0] if b.start == line)
        return glsl_mutants.Shape(text, line, end).nothing("probe") or text
    lines = text.split("\n")
    indent = re.match(r"\s*", lines[line - 1]).group(0)
    lines.insert(line, f'{indent}raise RuntimeError("geomlib audit: probe (this block runs)")')
    return "\n".join(lines)


def _own_tests(res: dict, function: str, runs: dict, covered: set | None = None) -> list[dict]:
    """The point-carrying tests of a mutant's run that run its block: the ones its block's probe
    failed (``covered``), else (no probe result) the ones that call ``function``, directly or
    through a composite."""
    if covered is not None:
        return [t for t in res.get("tests", []) if t["max"] > 0 and t["name"] in covered]
    if not function:
        return []
    return [
        t
        for t in res.get("tests", [])
        if t["max"] > 0 and any(function in runs.get(c, {c}) for c in t.get("calls", []))
    ]


def _task_summary(lr: dict) -> dict:
    out: dict = {}
    for r in lr["mutants"]:
        t = out.setdefault(
            str(r["task"]),
            {"title": r["title"], "mutants": 0, "killed": 0, "survived": 0, "equivalent": 0, "nothing": 0,
             "nothing_killed": 0, "nothing_task_zero": 0, "operators": 0, "operators_killed": 0, "by_time": 0},
        )  # fmt: skip
        t["mutants"] += 1
        t["nothing_task_zero"] += r.get("task_status") == "killed"
        kind = "nothing" if r["kind"] == "nothing" else "operators"
        t[kind] += 1
        if r["status"] == "killed":
            t["killed"] += 1
            t[kind + "_killed"] += 1
            t["by_time"] += r["by_time"]
        elif r["status"] == "equivalent":
            t["equivalent"] += 1
        elif r["status"] in ("survived", "partly killed"):
            t["survived"] += 1
    return dict(sorted(out.items(), key=lambda kv: int(kv[0])))


def _pct(k: int, n: int) -> str:
    return f"{100 * k / n:.0f}%" if n else "–"


def markdown(report: dict) -> str:
    """The report as Markdown: one table per lab (a row per task), then every survivor with its diff."""
    what = " (quick sample)" if report.get("quick") else ""
    if report.get("sample") and not report.get("quick"):
        what = f" (a seeded sample of {report['sample']} mutants per lab)"
    if report.get("kind"):
        what += f", {report['kind']} mutants only"
    out = [f"# Mutation audit{what}", ""]
    out.append(f"{report.get('seconds', 0):.0f} s with {report.get('jobs', 1)} job(s).")
    out.append("")
    out.append(
        "A does-nothing mutant is killed when the tests that run its block's function score 0; "
        "*whole task 0* counts the ones whose whole task scores 0."
    )
    out.append("")
    out.append(
        "| lab | task | mutants | killed | survived | equivalent | does-nothing killed | whole task 0 "
        "| operators killed | operator score |"
    )
    out.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for lab, lr in report["labs"].items():
        for t, s in lr["tasks"].items():
            ops_n = s["operators"] - sum(
                1
                for r in lr["mutants"]
                if str(r["task"]) == t and r["kind"] == "operator" and r["status"] == "equivalent"
            )
            out.append(
                f"| {lab} | {t} ({s['title']}) | {s['mutants']} | {s['killed']} | {s['survived']} | {s['equivalent']} "
                f"| {s['nothing_killed']}/{s['nothing']} | {s['nothing_task_zero']}/{s['nothing']} "
                f"| {s['operators_killed']}/{s['operators']} "
                f"| {_pct(s['operators_killed'], ops_n)} |"
            )
        ops = [r for r in lr["mutants"] if r["kind"] == "operator" and r["status"] != "equivalent"]
        k = sum(r["status"] == "killed" for r in ops)
        nothing = [r for r in lr["mutants"] if r["kind"] == "nothing"]
        kn = sum(r["status"] == "killed" for r in nothing)
        kt = sum(r.get("task_status") == "killed" for r in nothing)
        out.append(
            f"| **{lab}** | **all** | **{len(lr['mutants'])}** | | | | **{kn}/{len(nothing)}** | {kt}/{len(nothing)} "
            f"| **{k}/{len(ops)}** "
            f"| **{_pct(k, len(ops))}** |"
        )
    for lab, lr in report["labs"].items():
        surv = [r for r in lr["mutants"] if r["status"] in ("survived", "partly killed")]
        if lr["errors"]:
            out += ["", f"## {lab}: errors", ""]
            out += [f"- {e}" for e in lr["errors"]]
        if surv:
            out += ["", f"## {lab}: {len(surv)} survivor(s)", ""]
            for r in surv:
                d = r["diff"].replace("\n", " ⟶ ")
                what = f" ({r['score']:g}/{r['max']:g} points kept)" if r["status"] == "partly killed" else ""
                if r["kind"] == "nothing" and r.get("own_max"):
                    what = f" ({r['own_score']:g}/{r['own_max']:g} points kept by the tests of `{r['function']}`)"
                out.append(f"- Task {r['task']} `{r['id']}`{what}: `{d}`")
                if r.get("kept_points"):
                    out.append(f"  kept by: {'; '.join(r['kept_points'][:4])}")
        elsewhere = [r for r in lr["mutants"] if r.get("killed_by")]
        if elsewhere:
            out += ["", f"## {lab}: killed only by the tests of another task that runs the block", ""]
            out += [
                f"- Task {r['task']} `{r['id']}`: by {r['killed_by']}'s tests ({r['why'][:120]})" for r in elsewhere
            ]
        if lr["notes"]:
            out += ["", f"## {lab}: not mutated", ""]
            out += [f"- {n}" for n in lr["notes"]]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------- tasks done in order


def in_order_copy(lab: str, n: int, dest: Path) -> None:
    """``dest`` becomes the lab of a student who has done Tasks 1..``n`` and nothing else: a copy of
    ``solutions/<lab>/`` whose blocks of later tasks are stubbed exactly as ``geomlib stubs build``
    stubs them (:func:`geomlib.grading.stubs.make_stub` with ``keep``), prompts included."""
    from geomlib.grading import stubs

    src = course().lab(lab).solution
    _copy_lab(src, dest)

    def keep(task: str) -> bool:
        m = find_task(task, titled=True)
        return m is not None and m.number <= n

    for f in sorted(dest.rglob("*")):
        if f.suffix in stubs.STUB_SUFFIXES and "__pycache__" not in f.parts:
            text = f.read_text()
            new = stubs.make_stub(text, str(f.relative_to(dest)), keep=keep)
            if new != text:
                f.write_text(new)


#: "not implemented yet (Task 6 ...", "NotImplementedError: Task 6 (...", "#error Task 6 (...": a stub's words,
#: up to the task reference they lead to (read by :func:`geomlib.taskref.task_at_start`).
_NOT_DONE = re.compile(r"(?:not implemented(?: yet)?|NotImplementedError|#error)[^\w]{0,20}", re.I)


def later_tasks_named(text: str, n: int) -> list[int]:
    """The task numbers above ``n`` that ``text`` (a failed test's message) names as not implemented."""
    out = []
    for m in _NOT_DONE.finditer(text):
        ref = task_at_start(text[m.end() :])
        if ref and ref.number > n and ref.number not in out:
            out.append(ref.number)
    return out


def in_order(
    labs: list[str] | None = None, *, jobs: int = 1, progress: bool = True, tasks: list[int] | None = None
) -> dict:
    """``geomlib audit --in-order``: for every lab and task N, grade (``--task N``, as a student runs
    it: public and hidden tests, sandboxed, the tests whose latest task is N) a copy of the solution
    with Tasks 1..N done and the later ones stubbed (:func:`in_order_copy`). A student who did the
    tasks in order must get full marks there, and no test may stop at a later task's stub.

    Returns ``{"labs": {lab: [row per task]}, "seconds": ...}``; a row has ``task``, ``status``
    (``ok``; ``later``: a test stopped at a later task's stub; ``lost``: points lost otherwise;
    ``no tests``: nothing graded; ``error``: the grading failed), ``score``, ``max``, ``later``
    (the later task numbers named), ``failures`` (``name: message`` of each failed test),
    ``seconds`` and ``note`` (the grader's note, e.g. a task graded through a composite)."""
    from geomlib.grading import tasks as _tasks

    names, work = _labs_and_work(labs, "geomlib-in-order-")
    t_start = time.time()
    report: dict = {"in_order": True, "jobs": jobs, "labs": {x: [] for x in names}}
    reqs = []
    for lab in names:
        numbers = sorted(_tasks.derive(course().lab(lab).solution).titles)
        jit = _jit_request(course().lab(lab).solution)
        for n in numbers if not tasks else [t for t in numbers if t in tasks]:
            d = work / f"{lab}-{n}"

            def prepare(lab=lab, n=n, d=d, jit=jit):
                in_order_copy(lab, n, d / lab)
                return {"impl": str(d), "lab": lab, "task": n, "budget": None, "every_test": False, **jit}

            reqs.append({"prepare": prepare, "lab": lab, "task": n})
    prog = _Progress(len(reqs), what="tasks", bad="not at full marks") if progress else None
    pool = _Pool(max(1, jobs), work)
    rows: dict[int, dict] = {}

    def done(i, r, res):
        shutil.rmtree(r["impl"], ignore_errors=True) if "impl" in r else None
        lab, n = reqs[i]["lab"], reqs[i]["task"]
        got, top = _score(res)
        failures = [f"{t['name']}: {' '.join(t['output'].split())}" for t in res.get("tests", []) if not t["passed"]]
        later = sorted({k for f in failures for k in later_tasks_named(f, n)})
        if not res.get("ok"):
            status, failures = "error", [res.get("error", "")]
        elif not res["tests"]:
            status = "no tests"
        elif later:
            status = "later"
        elif got < top or failures:
            status = "lost"
        else:
            status = "ok"
        rows[i] = {"lab": lab, "task": n, "status": status, "score": got, "max": top, "later": later,
                   "failures": failures, "seconds": round(res.get("seconds", 0.0), 2),
                   "note": _through(res.get("note", ""))}  # fmt: skip
        if prog:
            prog.step(status != "ok", f"{lab} Task {n}")

    try:
        pool.run(reqs, done)
    finally:
        pool.close()
        shutil.rmtree(work, ignore_errors=True)
    if prog:
        prog.end()
    for i in sorted(rows):
        report["labs"][rows[i]["lab"]].append({k: v for k, v in rows[i].items() if k != "lab"})
    report["seconds"] = round(time.time() - t_start, 1)
    return report


def _through(output: str) -> str:
    """The grader's note that a task without a test of its own was graded through later tasks' tests."""
    return next((line.strip() for line in str(output).splitlines() if "no test of its own" in line), "")


def in_order_markdown(report: dict) -> str:
    """The ``--in-order`` report: a row per lab and task, then each failure's tests and messages."""
    out = ["# Tasks done in order", ""]
    out.append(
        f"{report.get('seconds', 0):.0f} s with {report.get('jobs', 1)} job(s). Each row grades `--task N` on a copy "
        "of the solution with Tasks 1..N done and the later tasks stubbed as `geomlib stubs build` stubs them."
    )
    out += ["", "| lab | task | status | score | later task named | seconds |", "|---|---:|---|---:|---|---:|"]
    for lab, rows in report["labs"].items():
        for r in rows:
            later = ", ".join(f"Task {k}" for k in r["later"]) or ""
            out.append(
                f"| {lab} | {r['task']} | {r['status']} | {r['score']:g}/{r['max']:g} | {later} | {r['seconds']:.1f} |"
            )
    for lab, rows in report["labs"].items():
        for r in rows:
            if r["status"] == "ok":
                continue
            out += ["", f"## {lab}, Task {r['task']}: {r['status']}", ""]
            if r.get("note"):
                out.append(f"- grader's note: {r['note']}")
            out += [f"- {f[:400]}" for f in r["failures"]]
    return "\n".join(out) + "\n"


def in_order_failed(report: dict) -> bool:
    """True when some lab's task, done in order, does not get full marks (or names a later task)."""
    return any(r["status"] not in ("ok",) for rows in report["labs"].values() for r in rows)


def failed(report: dict) -> bool:
    """True when the audit itself found errors (a bad declaration, a solution not at full marks)."""
    return any(lr["errors"] for lr in report["labs"].values())


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--worker"]:
        return _worker_main()
    raise SystemExit("use `geomlib audit`")


if __name__ == "__main__":
    sys.exit(main())
