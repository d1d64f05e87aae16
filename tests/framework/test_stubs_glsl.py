"""Stubs of GLSL shaders: the same markers as // comments; a stub block becomes #error naming the task."""

from __future__ import annotations

from geomlib.grading.stubs import make_stub, solution_lines

SHADER = """#version 330 core
out vec4 result;
float f(float x) {
    // BEGIN SOLUTION: Task 2 (f): f(x) = 2 x
    return 2.0 * x;
    // END SOLUTION
}
void main() {
    // BEGIN PROMPT
    // float y = f(1.0);
    // END PROMPT
    result = vec4(f(1.0));
}
"""


def test_glsl_blocks_become_error_directives_and_prompts_are_uncommented():
    stub = make_stub(SHADER, "shaders/x.frag")
    assert "    #error Task 2 (f): f(x) = 2 x\n" in stub
    assert "return 2.0 * x;" not in stub and "BEGIN" not in stub and "END" not in stub
    assert "    float y = f(1.0);\n" in stub
    assert solution_lines(SHADER, "shaders/x.frag") == ["return 2.0 * x;"]


def test_python_files_are_unchanged_by_the_glsl_rules():
    py = "def f(x):\n    # BEGIN SOLUTION: Task 1\n    return 2 * x  // 1\n    # END SOLUTION\n"
    assert make_stub(py, "f.py") == "def f(x):\n    raise NotImplementedError('Task 1')\n"
    # In a .py file a // comment is not a marker.
    assert make_stub(SHADER, "x.py") == SHADER
