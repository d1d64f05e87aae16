"""`geomlib audit` on GLSL solution blocks: does-nothing, operator and probe mutants of shaders."""

from __future__ import annotations

import pytest

from geomlib.grading import audit, glsl_mutants, stubs
from geomlib.grading import impl as _impl

SHADER = """#version 330 core
uniform float lam;
uniform vec3 light_vec[4];
flat out vec3 moved;

vec3 shade(vec3 p, vec3 n, float s) {
    // BEGIN SOLUTION: Task 7 (shade): p - lam s n
    vec3 l = light_vec[k];
    return p - lam * s / n + vec3(2.0) * cross(n, l);  // a comment: 3.0 + x
    // END SOLUTION
}

void frame(vec3 n, vec4 t, out vec3 T, out vec3 B) {
    // BEGIN SOLUTION: Task 8 (frame): T = t.xyz, B = n x T
    T = t.xyz;
    B = cross(n, T) * (t.w < 0.0 ? -1.0 : 1.0);
    // END SOLUTION
}

vec4 march(vec2 uv, int n) {
    float d = 0.0;
    int hit = 0;
    // BEGIN SOLUTION: Task 9 (march): first i with i >= n / 2
    for (int i = 0; i <= n; ++i) {
        if (i >= n / 2 && true) { hit = i; d += 0.5; break; }
    }
    // END SOLUTION
    return vec4(uv, d, float(hit));
}
"""


def _shapes():
    blocks, _ = stubs._scan(SHADER, "x.frag")
    return [glsl_mutants.Shape(SHADER, b.start, b.end) for b in blocks]


def test_does_nothing_replaces_the_results_of_each_block_form():
    """A returning block returns trivial values; a block with out parameters or locals read after it
    leaves trivial values in them; 'input' takes the function's input of the same type (a larger
    vector cut to size), else zeros."""
    ret, outs, loop = _shapes()
    assert (ret.fn, ret.returns, ret.why) == ("shade", True, "")
    assert "return vec3(0.0);  // geomlib audit" in ret.nothing("zeros")
    assert "return p;  // geomlib audit" in ret.nothing("input")
    assert "return vec3(1.0);  // geomlib audit" in ret.nothing("constant")
    assert "return vec3(uintBitsToFloat(0x7fc00000u));" in ret.nothing("probe")
    assert sorted(outs.results) == [("B", "vec3"), ("T", "vec3")]
    # each input once, in order: T takes n (same type), B the vec4 t cut to vec3
    assert "T = n;  // geomlib audit" in outs.nothing("input")
    assert "B = t.xyz;  // geomlib audit" in outs.nothing("input")
    assert sorted(loop.results) == [("d", "float"), ("hit", "int")]
    assert "hit = 0;  // geomlib audit" in loop.nothing("zeros")
    assert "d = 1.0;  // geomlib audit" in loop.nothing("constant")
    assert "hit = -1000000;" in loop.nothing("probe")
    for shape in (ret, outs, loop):
        for mode in (*glsl_mutants.MODES, "probe"):
            new = shape.nothing(mode)
            # the change stays inside the block: the stubs of mutant and solution agree
            assert stubs.make_stub(new, "x.frag") == stubs.make_stub(SHADER, "x.frag"), mode


def test_glsl_operator_mutants_cover_every_listed_operator_and_stay_in_blocks():
    labels = set()
    for shape in _shapes():
        for a, z, new, label, line, _col in shape.operators():
            labels.add(label)
            src = SHADER[:a] + new + SHADER[z:]
            assert stubs.make_stub(src, "x.frag") == stubs.make_stub(SHADER, "x.frag"), label
            assert shape.start < line < shape.end, label
    for want in ["- → +", "* → /", "/ → *", "+ → -", "+= → -=", "< → <=", "<= → <", ">= → >", "2.0 → 0.0",
                 "2.0 → 4.0", "2.0 → 1.0", "2.0 → 3.0", "0 → 1", "2 → 1", "true → false", "[k] → [k + 1]",
                 "cross(a, b) → cross(b, a)", "0.5 → 1.0"]:  # fmt: skip
        assert want in labels, f"{want!r} not among {sorted(labels)}"
    assert "3.0 → 6.0" not in labels, "a number in a comment is not code"
    assert not any(lab.startswith(("for(", "if(")) for lab in labels)
    # unary minus is not a binary operator: `-1.0` gives number mutants only
    unary = SHADER.index("-1.0")
    assert not [e for shape in _shapes() for e in shape.operators() if e[0] == unary], "unary minus mutated"


@pytest.mark.parametrize("lab", ["relief", "maps", "denoise"])
def test_every_glsl_block_of_the_course_has_does_nothing_and_operator_mutants(lab):
    root = _impl.course_root() / "solutions" / lab
    mutants, notes = audit.generate(lab, check_glsl=False)
    blocks = [b for b in audit._blocks(root)[0] if not b.file.endswith(".py")]
    assert blocks, f"{lab} has GLSL blocks"
    for b in blocks:
        mine = [m for m in mutants if m.file == b.file and b.start <= m.line < b.end]
        assert {m.op for m in mine if m.kind == "nothing"} >= {"zeros", "constant"}, f"{b.file}:{b.start}"
        assert any(m.kind == "operator" for m in mine), f"{b.file}:{b.start}"
        probe = audit._probe_source((root / b.file).read_text(), b.start, b.file)
        assert "uintBitsToFloat(0x7fc00000u)" in probe, f"{b.file}:{b.start}: the probe sets no result to NaN"
    assert not [n for n in notes if "GLSL" in n], notes


def test_glsl_compile_check_drops_mutants_that_do_not_compile():
    """The driver tells a type error (``mat3 / vec3``) from a mutant that compiles."""
    src = (_impl.course_root() / "solutions" / "maps" / "shaders" / "tbn.vert").read_text()
    bad = src.replace("transpose(inverse(m)) * n", "transpose(inverse(m)) / n")
    assert bad != src
    assert glsl_mutants.compiles([(".vert", src), (".vert", bad)]) == [True, False]
