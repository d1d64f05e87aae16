"""Generate the student stubs ``labs/<lab>/`` from the reference solutions ``solutions/<lab>/``.

In a solution file, each student part sits between two marker comments::

    # BEGIN SOLUTION: Task 2 (even vertices): v' = (1 - n u) v + u * sum(neighbours)
    ...reference code...
    # END SOLUTION

The stub gets, at the block's indentation, ``raise NotImplementedError("Task 2 (even vertices): ...")``.
Optional prompt lines, commented out in the solution, are uncommented in the stub::

    # BEGIN PROMPT
    # odd = ...  # (e, 3) positions of the edge points
    # END PROMPT

Everything else (imports, docstrings, validation, given helpers) is copied unchanged.

GLSL shaders (``.frag``, ``.vert``, ``.glsl``) use the same markers as ``//`` comments; a stub
block becomes ``#error Task ...``, so the stub shader does not compile and names its task.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass
from pathlib import Path

from geomlib.grading import impl as _impl
from geomlib.grading.course import course as _course

__all__ = ["make_stub", "build", "check", "solution_lines", "solution_blocks", "StubError"]

_BEGIN = re.compile(r"^(?P<indent>\s*)# BEGIN SOLUTION(?::\s*(?P<task>.*?))?\s*$")
_END = re.compile(r"^\s*# END SOLUTION\s*$")
_PBEGIN = re.compile(r"^\s*# BEGIN PROMPT\s*$")
_PEND = re.compile(r"^\s*# END PROMPT\s*$")
#: Shader files stubbed like the Python ones, with ``//`` markers.
GLSL_SUFFIXES = (".frag", ".vert", ".glsl")
STUB_SUFFIXES = (".py", *GLSL_SUFFIXES)


def _glsl(name: str) -> bool:
    return str(name).endswith(GLSL_SUFFIXES)


def _comments(text: str, name: str) -> str:
    """GLSL text with its ``//`` marker lines spelled as ``#`` ones (same line count)."""
    if not _glsl(name):
        return text
    marker = re.compile(r"^(\s*)// ?((?:BEGIN|END) (?:SOLUTION|PROMPT)\b.*)$")
    return "\n".join(marker.sub(r"\1# \2", line) for line in text.split("\n"))


class StubError(ValueError):
    """Unbalanced or misplaced solution/prompt markers (the message names file and line)."""


@dataclass
class _Block:
    start: int
    end: int
    indent: str
    task: str


def _scan(text: str, name: str) -> tuple[list[_Block], list[tuple[int, int]]]:
    lines = _comments(text, name).splitlines()
    blocks, prompts = [], []
    open_block = open_prompt = None
    for i, line in enumerate(lines, start=1):
        m = _BEGIN.match(line)
        if m:
            if open_block or open_prompt:
                raise StubError(f"{name}, line {i}: BEGIN SOLUTION inside another block")
            open_block = _Block(i, -1, m.group("indent"), m.group("task") or "")
        elif _END.match(line):
            if not open_block:
                raise StubError(f"{name}, line {i}: END SOLUTION without BEGIN SOLUTION")
            open_block.end = i
            blocks.append(open_block)
            open_block = None
        elif _PBEGIN.match(line):
            if open_block or open_prompt:
                raise StubError(f"{name}, line {i}: BEGIN PROMPT inside another block")
            open_prompt = i
        elif _PEND.match(line):
            if not open_prompt:
                raise StubError(f"{name}, line {i}: END PROMPT without BEGIN PROMPT")
            prompts.append((open_prompt, i))
            open_prompt = None
    if open_block:
        raise StubError(f"{name}, line {open_block.start}: BEGIN SOLUTION is never closed")
    if open_prompt:
        raise StubError(f"{name}, line {open_prompt}: BEGIN PROMPT is never closed")
    return blocks, prompts


def make_stub(text: str, name: str = "<solution>", keep=None) -> str:
    """The stub version of one solution file's text.

    ``keep``: a function of a block's task text (``"Task 2 (even vertices): ..."``) that says which
    blocks stay as the solution wrote them, with the prompt just before each (``geomlib audit
    --in-order``: the lab of a student who has done Tasks 1..N); the others are stubbed as always."""
    blocks, prompts = _scan(text, name)
    if keep is not None:
        kept = {b.start for b in blocks if keep(b.task)}
        # A prompt belongs to the block after it: it stays commented out when that block stays.
        prompts = [(s, e) for s, e in prompts if next((b.start for b in blocks if b.start > e), None) not in kept]
        blocks = [b for b in blocks if b.start not in kept]
    lines = text.splitlines()  # marker lines (the only ones _comments changes) are all dropped below
    out: list[str] = []
    starts = {b.start: b for b in blocks}
    in_prompt = {i for s, e in prompts for i in range(s, e + 1)}
    i = 1
    while i <= len(lines):
        if i in starts:
            b = starts[i]
            task = b.task or "this part of the lab"
            if _glsl(name):
                out.append(f"{b.indent}#error {task}")
            else:
                out.append(f"{b.indent}raise NotImplementedError({task!r})")
            i = b.end + 1
            continue
        line = lines[i - 1]
        if i in in_prompt:
            if i in (s for s, _ in prompts) or i in (e for _, e in prompts):
                i += 1
                continue
            out.append(re.sub(r"^(\s*)// ?" if _glsl(name) else r"^(\s*)# ?", r"\1", line, count=1))
        else:
            out.append(line)
        i += 1
    return "\n".join(out) + ("\n" if text.endswith("\n") else "")


def solution_lines(text: str, name: str = "<solution>") -> list[str]:
    """The stripped lines inside solution blocks (what must never reach students)."""
    blocks, _ = _scan(text, name)
    lines = text.splitlines()
    return [lines[k - 1].strip() for b in blocks for k in range(b.start + 1, b.end) if lines[k - 1].strip()]


def solution_blocks(text: str, name: str = "<solution>") -> list[tuple[str, list[str]]]:
    """``(task, stripped lines)`` of every solution block, in file order (the task as its BEGIN marker names it)."""
    blocks, _ = _scan(text, name)
    lines = text.splitlines()
    out = []
    for b in blocks:
        body = [lines[k - 1].strip() for k in range(b.start + 1, b.end) if lines[k - 1].strip()]
        out.append((b.task or f"line {b.start}", body))
    return out


def _pairs(labs: list[str] | None):
    c = _course()
    for lab in labs or c.solution_labs:
        src, dst = c.lab(lab).solution, c.lab(lab).stubs
        if not src.is_dir():
            raise StubError(f"no solution folder {src}")
        for f in sorted(f for f in src.rglob("*") if f.suffix in STUB_SUFFIXES):
            if "__pycache__" in f.parts:
                continue
            yield lab, f, dst / f.relative_to(src)


class Written(list):
    """The files a ``build`` wrote (those whose content changed); ``unchanged`` counts the files that
    already held what it would write (left untouched, so git and timestamps do not move)."""

    unchanged: int = 0


def build(labs: list[str] | None = None, *, log=print) -> Written:
    """Regenerate the ``.py`` files of ``labs/<lab>/`` from ``solutions/<lab>/``; returns the files
    written (changed), their ``unchanged`` count as an attribute.

    Stub ``.py`` files with no solution counterpart are removed; other files in ``labs/`` (the
    handout README, data) are left alone.
    """
    written = Written()
    expected: dict[str, set[Path]] = {}
    for lab, src, dst in _pairs(labs):
        stub = make_stub(src.read_text(), str(src.relative_to(_impl.course_root())))
        dst.parent.mkdir(parents=True, exist_ok=True)
        if not dst.is_file() or dst.read_text() != stub:
            dst.write_text(stub)
            log(f"  wrote {dst.relative_to(_impl.course_root())}")
            written.append(dst)
        else:
            written.unchanged += 1
        expected.setdefault(lab, set()).add(dst)
    for lab, files in expected.items():
        for f in _course().lab(lab).stubs.rglob("*"):
            if f.suffix in STUB_SUFFIXES and f not in files and "__pycache__" not in f.parts:
                f.unlink()
                log(f"  removed {f.relative_to(_impl.course_root())} (no solution counterpart)")
    return written


def check(labs: list[str] | None = None, *, diff: bool = False) -> list[str]:
    """Problems that make ``labs/`` stale: missing, differing or extra stub files. With ``diff``, a
    differing file's problem is followed by the unified diff from ``labs/`` to the generated stub."""
    problems = []
    seen: dict[str, set[Path]] = {}
    for lab, src, dst in _pairs(labs):
        seen.setdefault(lab, set()).add(dst)
        rel = dst.relative_to(_impl.course_root())
        if not dst.is_file():
            problems.append(f"{rel} is missing")
            continue
        have, want = dst.read_text(), make_stub(src.read_text(), str(src))
        if have != want:
            problem = f"{rel} differs from the stub generated from {src.relative_to(_impl.course_root())}"
            if diff:
                lines = difflib.unified_diff(
                    have.splitlines(keepends=True),
                    want.splitlines(keepends=True),
                    f"{rel} (in labs/)",
                    f"{rel} (generated from solutions/)",
                )
                problem += "\n" + "".join(ln if ln.endswith("\n") else ln + "\n" for ln in lines).rstrip("\n")
            problems.append(problem)
    for lab, files in seen.items():
        for f in _course().lab(lab).stubs.rglob("*"):
            if f.suffix in STUB_SUFFIXES and f not in files and "__pycache__" not in f.parts:
                problems.append(f"{f.relative_to(_impl.course_root())} has no solution counterpart")
    return problems
