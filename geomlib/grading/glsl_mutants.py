"""Mutants of the GLSL solution blocks (``// BEGIN SOLUTION`` in ``.vert``/``.frag``), for ``geomlib audit``.

The Python mutants (:mod:`geomlib.grading.audit`) come from :mod:`ast`; GLSL has no parser in the
course's dependencies, so these come from a small tokenizer and the shapes the course's shaders use:
a solution block sits inside one function whose header is one line (``vec2 parallax_uv(vec2 uv,
vec3 view) {``), and its results are either the function's ``return`` value or the names it assigns
that were declared before it (locals read after the block, ``out`` parameters, global ``out``
variables). A shader that does not fit gets no mutant and a note saying why.

- *does nothing*: the block returns (or leaves in its result names) zeros of the result's type
  (``zeros``), the function's input of the same type (``input``: ``uv`` for ``parallax_uv``, ``p``
  for ``denoise``, ``n_interp`` for ``shading_normal``; a larger vector input is cut with a swizzle,
  ``t.xyz``; zeros when none fits) or a constant (``constant``: ones, true; a visibility of 1 is
  "all lit");
- *operators* inside the block: numeric literals (0↔1, ×2, ½, +1), binary ``+``↔``-``, ``*``↔``/``
  (also ``+=``…), ``<``↔``<=``, ``>``↔``>=``, ``a[i]`` → ``a[i + 1]``, ``true``↔``false``, the
  first two arguments of a call swapped (not for calls that commute: ``max``, ``min``, ``dot``…).
  A mutant that does not compile is dropped, as Python mutants with a syntax error are: GLSL's type
  errors (``mat3 / vec3``, ``cross`` of a swapped ``vec2``) show only when the driver compiles it, so
  :func:`compiles` asks the driver, in a child process (the audit's own process must stay free of a
  GL context: its workers are forked from it).
- *probe* (which tests run the block): the block's results become NaN (an int: -1000000). GLSL
  cannot raise; a compile error would fail every test of the shader, also those that never reach
  the block (``normalmap.frag``'s ``shading_normal`` with the normal map off).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys

#: GLSL types the generator knows how to fill, with their zero, constant and probe values.
_SCALARS = {
    "float": ("0.0", "1.0", "uintBitsToFloat(0x7fc00000u)"),
    "int": ("0", "1", "-1000000"),
    "uint": ("0u", "1u", "1000000u"),
    "bool": ("false", "true", "true"),
}
_VECTOR = re.compile(r"^(vec|ivec|uvec|bvec|mat)([234])$")
_TYPES = r"(?:float|int|uint|bool|[iub]?vec[234]|mat[234])"
_HEADER = re.compile(r"^([A-Za-z_]\w*)\s+([A-Za-z_]\w*)\s*\(([^)]*)\)\s*\{", re.M)
_PARAM = re.compile(r"^\s*(?:const\s+)?(?:(in|out|inout)\s+)?(?:(?:highp|mediump|lowp)\s+)?(\w+)\s+(\w+)\s*$")
_ASSIGN = re.compile(r"(?<![\w.])([A-Za-z_]\w*)\s*(?:\.[xyzwrgbastpq]+|\[[^\]]*\])?\s*(?:[-+*/]?=)(?!=)")
_TOKEN = re.compile(
    r"(?P<num>(?:\d+\.\d*|\.\d+)(?:[eE][-+]?\d+)?[fF]?|\d+[eE][-+]?\d+[fF]?|0[xX][0-9a-fA-F]+[uU]?|\d+[uU]?)"
    r"|(?P<id>[A-Za-z_]\w*)"
    r"|(?P<op>\+\+|--|\+=|-=|\*=|/=|<=|>=|==|!=|&&|\|\||<<|>>|[-+*/<>=!?:;,.()\[\]{}%&|^~])"
    r"|(?P<ws>\s+)"
    r"|(?P<other>.)",
    re.S,
)
#: Calls whose first two arguments commute: swapping them is an equivalent mutant, never generated.
_COMMUTATIVE = {"max", "min", "dot", "distance", "equal", "notEqual"}
_KEYWORDS = {"if", "for", "while", "switch", "return"}
MODES = ("zeros", "input", "constant")


def code_only(text: str) -> str:
    """``text`` with its comments blanked (same length, same line breaks)."""

    def blank(m):
        return re.sub(r"[^\n]", " ", m.group(0))

    return re.sub(r"//[^\n]*|/\*.*?\*/", blank, text, flags=re.S)


def _line_offsets(text: str) -> list[int]:
    starts, k = [0], 0
    for line in text.split("\n"):
        k += len(line) + 1
        starts.append(k)
    return starts


def value(typ: str, mode: str) -> str | None:
    """A GLSL expression of type ``typ`` for ``mode`` (zeros, constant, probe); None for unknown types."""
    k = {"zeros": 0, "constant": 1, "probe": 2}[mode]
    if typ in _SCALARS:
        return _SCALARS[typ][k]
    m = _VECTOR.match(typ)
    if not m:
        return None
    base = {"vec": "float", "mat": "float", "ivec": "int", "uvec": "uint", "bvec": "bool"}[m.group(1)]
    inner = _SCALARS[base][k]
    return f"{typ}({inner})"


def _size(typ: str) -> tuple[str, int] | None:
    if typ in _SCALARS:
        return typ, 1
    m = _VECTOR.match(typ)
    if not m or m.group(1) == "mat":
        return None
    return {"vec": "float", "ivec": "int", "uvec": "uint", "bvec": "bool"}[m.group(1)], int(m.group(2))


def _input_for(typ: str, params: list[tuple[str, str, str]], used: set[str]) -> str | None:
    """The first unused input parameter of type ``typ``, or a larger vector input cut to its size."""
    for q, t, name in params:
        if q in ("", "in", "inout") and t == typ and name not in used:
            used.add(name)
            return name
    want = _size(typ)
    if want and want[1] > 1:
        for q, t, name in params:
            have = _size(t)
            if q in ("", "in", "inout") and have and have[0] == want[0] and have[1] > want[1] and name not in used:
                used.add(name)
                return f"{name}.{'xyzw'[: want[1]]}"
    return None


#: GLSL's built-in outputs a block may leave as its result.
_BUILTIN_OUTPUTS = {"gl_Position": "vec4", "gl_PointSize": "float", "gl_FragDepth": "float"}


class Shape:
    """Where a block sits: its function, the function's parameters and the block's results."""

    def __init__(self, text: str, start: int, end: int):
        self.text, self.start, self.end = text, start, end
        self.code = code_only(text)
        self.lines = self.code.split("\n")
        self.offsets = _line_offsets(text)
        self.why = ""
        self.fn = self.ret = ""
        self.params: list[tuple[str, str, str]] = []
        self.returns = False
        self.results: list[tuple[str, str]] = []  # (name, type) the block leaves for the rest to read
        self._find()

    def _find(self) -> None:
        begin = self.offsets[self.start - 1]
        headers = [m for m in _HEADER.finditer(self.code) if m.start() < begin]
        if not headers:
            self.why = "the block is not inside a function (no one-line GLSL function header above it)"
            return
        h = headers[-1]
        depth, k = 0, h.end() - 1
        while k < len(self.code):
            depth += {"{": 1, "}": -1}.get(self.code[k], 0)
            if depth == 0:
                break
            k += 1
        if k < self.offsets[self.end - 1]:
            self.why = "the block is not inside one function (its header's braces close before the block ends)"
            return
        self.ret, self.fn = h.group(1), h.group(2)
        for p in filter(str.strip, h.group(3).split(",")):
            m = _PARAM.match(p)
            if m:
                self.params.append((m.group(1) or "", m.group(2), m.group(3)))
        block = "\n".join(self.lines[self.start : self.end - 1])
        before = self.code[h.end() : begin]
        after = self.code[self.offsets[self.end] : k]
        self.returns = self.ret != "void" and re.search(r"\breturn\b", block) is not None
        declared = {n: t for t, n in re.findall(rf"\b({_TYPES})\s+([A-Za-z_]\w*)", before)}
        outs = {n: t for q, t, n in self.params if q in ("out", "inout")}
        globals_out = {
            n: t for t, n in re.findall(rf"^\s*(?:flat\s+|smooth\s+)?out\s+({_TYPES})\s+(\w+)\s*;", self.code, re.M)
        }
        globals_out.update(_BUILTIN_OUTPUTS)  # a vertex stage's result is gl_Position (shadows' depth.vert)
        inside = set(re.findall(rf"\b{_TYPES}\s+([A-Za-z_]\w*)", block))
        for name in dict.fromkeys(_ASSIGN.findall(block)):
            if name in inside:
                continue
            if name in outs or name in globals_out:
                self.results.append((name, outs.get(name) or globals_out[name]))
            elif name in declared and re.search(rf"(?<![\w.]){name}\b", after):
                self.results.append((name, declared[name]))
        if not self.returns and not self.results:
            self.why = "the block has no result the function uses"

    def nothing(self, mode: str) -> str | None:
        """The shader with the block's results replaced (``zeros``, ``input``, ``constant``, ``probe``)."""
        if self.why:
            return None
        indent = re.match(r"\s*", self.text.split("\n")[self.start - 1]).group(0)
        used: set[str] = set()

        def fill(typ):
            got = _input_for(typ, self.params, used) if mode == "input" else None
            return got or value(typ, "zeros" if mode == "input" else mode)

        lines = self.text.split("\n")
        if self.returns:
            v = fill(self.ret)
            if v is None:
                return None
            new = [*lines[: self.start], f"{indent}return {v};  // geomlib audit", *lines[self.start :]]
        else:
            sets = []
            for name, typ in self.results:
                v = fill(typ)
                if v is None:
                    return None
                sets.append(f"{indent}{name} = {v};  // geomlib audit")
            new = [*lines[: self.end - 1], *sets, *lines[self.end - 1 :]]
        return "\n".join(new)

    def operators(self) -> list[tuple[int, int, str, str, int, int]]:
        """(start, end, replacement, label, line, column) text edits inside the block."""
        lo, hi = self.offsets[self.start], self.offsets[self.end - 1]
        toks = [(m.lastgroup, m.group(0), m.start()) for m in _TOKEN.finditer(self.code, lo, hi)]
        toks = [t for t in toks if t[0] != "ws"]
        edits = []

        def at(pos):
            line = next(i for i in range(len(self.offsets)) if self.offsets[i + 1] > pos)
            return line + 1, pos - self.offsets[line]

        def add(pos, old, new, label):
            edits.append((pos, pos + len(old), new, label, *at(pos)))

        for i, (kind, tok, pos) in enumerate(toks):
            prev = toks[i - 1] if i else ("op", ";", lo)
            operand_before = prev[0] in ("id", "num") or prev[1] in (")", "]")
            if kind == "num" and not re.search(r"[xXuU]", tok):
                is_float = re.search(r"[.eE]", tok) is not None
                v = float(tok.rstrip("fF")) if is_float else int(tok)
                cands = [1 if v == 0 else 0, v * 2, v // 2 if not is_float else v / 2, v + 1]
                seen = {v}
                for c in cands:
                    c = float(c) if is_float else int(c)
                    if c in seen:
                        continue
                    seen.add(c)
                    add(pos, tok, repr(c), f"{tok} → {c!r}")
            elif kind == "id" and tok in ("true", "false"):
                new = "false" if tok == "true" else "true"
                add(pos, tok, new, f"{tok} → {new}")
            elif kind == "op" and tok in ("+", "-", "*", "/") and operand_before:
                new = {"+": "-", "-": "+", "*": "/", "/": "*"}[tok]
                add(pos, tok, new, f"{tok} → {new}")
            elif kind == "op" and tok in ("+=", "-=", "*=", "/="):
                new = {"+=": "-=", "-=": "+=", "*=": "/=", "/=": "*="}[tok]
                add(pos, tok, new, f"{tok} → {new}")
            elif kind == "op" and tok in ("<", "<=", ">", ">="):
                new = {"<": "<=", "<=": "<", ">": ">=", ">=": ">"}[tok]
                add(pos, tok, new, f"{tok} → {new}")
            elif (
                kind == "id"
                and prev[1] == "["
                and i + 1 < len(toks)
                and toks[i + 1][1] == "]"
                and i >= 2
                and toks[i - 2][0] == "id"
            ):
                add(pos, tok, f"({tok} + 1)", f"[{tok}] → [{tok} + 1]")
            elif kind == "id" and i + 1 < len(toks) and toks[i + 1][1] == "(" and tok not in _COMMUTATIVE | _KEYWORDS:
                args = self._args(toks, i + 1)
                if args and len(args) >= 2:
                    (s0, e0), (s1, e1) = args[0], args[1]
                    a0, a1 = self.text[s0:e0], self.text[s1:e1]
                    if a0.strip() != a1.strip():
                        new = a1 + self.text[e0:s1] + a0
                        edits.append((s0, e1, new, f"{tok}(a, b) → {tok}(b, a)", *at(pos)))
        return edits

    def _args(self, toks, k) -> list[tuple[int, int]] | None:
        """Spans of the top-level arguments of the call whose ``(`` is token ``k`` (whitespace trimmed)."""
        depth, spans, first = 0, [], None
        last = None
        for _kind, tok, pos in toks[k:]:
            if tok in ("(", "["):
                depth += 1
                if depth == 1:
                    continue
            elif tok in (")", "]"):
                depth -= 1
                if depth == 0:
                    if first is not None:
                        spans.append((first, last))
                    return spans
            if depth == 1 and tok == ",":
                if first is None:
                    return None
                spans.append((first, last))
                first = None
                continue
            if first is None:
                first = pos
            last = pos + len(tok)
        return None


def compiles(sources: list[tuple[str, str]]) -> list[bool] | None:
    """Whether each ``(suffix, source)`` shader compiles, asked of the driver in a child process;
    None when no GL context can be made there (then no mutant is dropped)."""
    if not sources:
        return []
    code = (
        "import json, sys\n"
        "from geomlib import gl\n"
        "GL = gl._gl()\n"
        "out = []\n"
        "for suffix, src in json.load(sys.stdin):\n"
        "    kind = GL.GL_VERTEX_SHADER if suffix == '.vert' else GL.GL_FRAGMENT_SHADER\n"
        "    try:\n"
        "        GL.glDeleteShader(gl._compile(GL, kind, gl._prepare(src, '330 core'), 'mutant'))\n"
        "        out.append(True)\n"
        "    except gl.ShaderError:\n"
        "        out.append(False)\n"
        "print(json.dumps(out))\n"
    )
    try:
        r = subprocess.run(
            [sys.executable, "-c", code], input=json.dumps(sources), capture_output=True, text=True, timeout=600
        )
        got = json.loads(r.stdout.strip().splitlines()[-1]) if r.returncode == 0 and r.stdout.strip() else None
    except (OSError, ValueError, subprocess.TimeoutExpired):
        return None
    return got if isinstance(got, list) and len(got) == len(sources) else None
