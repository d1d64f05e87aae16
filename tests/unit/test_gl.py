"""The headless GL harness (geomlib.gl): exact read-back, texture orientation, compile errors with line numbers."""

from __future__ import annotations

import numpy as np
import pytest

from geomlib import gl
from geomlib.errors import MeshError


def test_trivial_shader_reads_back_pixel_centres_exactly():
    # uv of pixel (r, c) of a (h, w) image is ((c + 0.5) / w, 1 - (r + 0.5) / h): exact in float32 for w = 4, h = 2.
    src = "in vec2 uv; out vec4 color;\nvoid main() { color = vec4(uv, 0.25, 1.0); }"
    img = gl.render_quad(src, (4, 2))
    assert img.shape == (2, 4, 4) and img.dtype == np.float32
    r, c = np.mgrid[0:2, 0:4]
    assert np.array_equal(img[..., 0], (c + 0.5) / 4)
    assert np.array_equal(img[..., 1], 1 - (r + 0.5) / 2)
    assert np.all(img[..., 2] == 0.25) and np.all(img[..., 3] == 1.0)


def test_texture_lookup_keeps_row_zero_on_top_and_uniforms_reach_the_shader():
    tex = (np.arange(12, dtype=np.float32).reshape(3, 4) + 0.5) / 7
    src = (
        "uniform sampler2D h; uniform float k; uniform vec2 shift; in vec2 uv; out vec4 color;\n"
        "void main() { color = vec4(texelFetch(h, ivec2(gl_FragCoord.xy), 0).r * k, texture(h, uv).r, shift); }"
    )
    out = gl.render_quad(src, (4, 3), textures={"h": tex}, uniforms={"k": 2.0, "shift": (3.0, -1.0)})
    assert np.array_equal(out[..., 0], 2 * tex)  # texelFetch at the pixel = the same texel
    assert np.array_equal(out[..., 1], tex)  # texture() at texel centres (nearest) = the same texel
    assert np.all(out[..., 2] == 3.0) and np.all(out[..., 3] == -1.0)


def test_multiple_outputs_and_a_mesh_with_per_vertex_attributes():
    src = "in vec2 uv; layout(location = 0) out vec4 a; layout(location = 1) out vec4 b;\nvoid main() { a = vec4(1); b = vec4(2); }"
    a, b = gl.render_quad(src, (2, 2), outputs=2)
    assert np.all(a == 1) and np.all(b == 2)
    # One triangle covering the lower-left half of clip space, colour = its vertex attribute (constant here).
    P = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1.0]])
    vs = "in vec4 p; in float c; out float col; void main() { gl_Position = p; col = c; }"
    fs = "in float col; out vec4 o; void main() { o = vec4(col, 0, 0, 1); }"
    img = gl.render_mesh(vs, fs, [[0, 1, 2]], {"p": P, "c": np.full((3, 1), 0.5)}, (4, 4))
    covered = img[..., 3] == 1
    # Pixel centres strictly below the diagonal x + y < 0 (in image rows: r > c) are covered, above are not.
    r, c = np.mgrid[0:4, 0:4]
    assert np.array_equal(covered[r != c], (r > c)[r != c])
    assert np.all(img[covered, 0] == 0.5)


def test_syntax_error_names_the_students_line():
    src = "in vec2 uv; out vec4 color;\nvoid main() {\n  color = vec4(1.0)\n}\n"  # missing ';' on line 3
    with pytest.raises(gl.ShaderError) as e:
        gl.render_quad(src, (2, 2), name="parallax.frag")
    assert e.value.lines and e.value.lines[0] in (3, 4)  # the driver reports the token after the missing ';'
    assert "parallax.frag did not compile" in str(e.value) and "error" in e.value.log
    # With an explicit #version line the numbers are those of the file too.
    with pytest.raises(gl.ShaderError) as e2:
        gl.render_quad("#version 330 core\n" + src, (2, 2))
    assert e2.value.lines[0] == e.value.lines[0] + 1


def test_undeclared_name_error_points_at_its_line():
    src = "in vec2 uv; out vec4 color;\n\nvoid main() {\n  color = vec4(undeclared_thing);\n}\n"
    with pytest.raises(gl.ShaderError, match="undeclared_thing") as e:
        gl.render_quad(src, (2, 2))
    assert e.value.lines[0] == 4


def test_bad_arguments_name_the_problem():
    src = "in vec2 uv; out vec4 color; void main() { color = vec4(0); }"
    with pytest.raises(MeshError, match="size must be"):
        gl.render_quad(src, (0, 2))
    with pytest.raises(MeshError, match="texture 'h' has shape"):
        gl.render_quad(src, (2, 2), textures={"h": np.zeros((2, 2, 5))})
    with pytest.raises(MeshError, match="uniform 'k' has 5 values"):
        gl.render_quad(
            "uniform float k[5]; in vec2 uv; out vec4 color; void main() { color = vec4(k[1]); }",
            (2, 2),
            uniforms={"k": np.zeros(5)},
        )


def test_no_usable_platform_names_the_fix():
    import os
    import subprocess
    import sys

    code = "from geomlib import gl\ngl.render_quad('in vec2 uv; out vec4 c; void main() { c = vec4(0); }', (1, 1))"
    env = {**os.environ, "PYOPENGL_PLATFORM": "nonsense"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
    assert "could not create a headless OpenGL context" in out.stderr and "apt-get install libosmesa6" in out.stderr


def test_points_read_back_every_vertex_s_own_result():
    """render_points: vertex i on pixel (i % w, i // w) of a (w, h) target; its flat output read back exactly."""
    vs = (
        "in vec3 p; uniform ivec2 grid; flat out vec4 r;\n"
        "void main() {\n"
        "    r = vec4(2.0 * p, float(gl_VertexID));\n"
        "    vec2 px = vec2(float(gl_VertexID % grid.x), float(gl_VertexID / grid.x)) + 0.5;\n"
        "    gl_Position = vec4(px * 2.0 / vec2(grid) - 1.0, 0.0, 1.0);\n"
        "}\n"
    )
    fs = "flat in vec4 r; out vec4 o;\nvoid main() { o = r; }"
    P = np.arange(21, dtype=np.float64).reshape(7, 3) / 8
    out = gl.render_points(vs, fs, {"p": P}, (3, 3), uniforms={"grid": np.array([3, 3], np.int32)})
    rows = out[::-1].reshape(-1, 4)  # read-back row 0 is the top: GL row 2
    assert np.array_equal(rows[:7, :3], 2 * P) and np.array_equal(rows[:7, 3], np.arange(7))
    assert np.all(rows[7:] == 0)  # no vertex there
    with pytest.raises(MeshError, match="no vertices"):
        gl.render_points(vs, fs, {}, (1, 1))
