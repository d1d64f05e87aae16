"""How a GLSL call runs in the sandbox (issue 26, item 4: feedback speed), and that what makes it fast
keeps the relief route's guarantees.

A GLSL call forks a fresh worker from the zygote, as every call does. The zygote imports PyOpenGL once
for a lab with a ``shaders/`` folder (``worker.prepare_gl``) and never creates an OpenGL context (Mesa's
rasteriser threads do not survive a fork); ``geomlib.gl`` creates its OSMesa context without importing
pyrender (~2 s of CPU per call before). The zygote is shared by every call of a run, so a shader that
hangs or does not compile must leave it able to grade the next call.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest

from geomlib.grading import sandbox
from geomlib.grading.errors import GradingFailure, StudentTimeout
from geomlib.grading.sandbox import LabProxy

from .course import planted_solution, replace_once

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

PROBE = """
import sys

import numpy as np

PRELOADED = "OpenGL.GL" in sys.modules  # what the worker inherited from the zygote


def gl_probe():
    from geomlib import gl

    src = "#version 330 core\\nin vec2 uv; out vec4 color;\\nvoid main() { color = vec4(uv, 0.25, 1.0); }"
    img = gl.render_quad(src, (2, 1))
    return np.array([PRELOADED, "pyrender" in sys.modules, *img[0, 0]], dtype=float)
"""


def _with_probe(dest: Path) -> None:
    (dest / "probe.py").write_text(PROBE)


def test_a_glsl_worker_inherits_pyopengl_and_never_imports_pyrender():
    dest = planted_solution("shadows", _with_probe)
    try:
        got = LabProxy("shadows", dest, timeout=180).gl_probe()
    finally:
        shutil.rmtree(dest.parent, ignore_errors=True)
    preloaded, pyrender, *pixel = got.tolist()
    assert pixel == [0.25, 0.5, 0.25, 1.0], pixel  # the worker's own context rendered
    assert preloaded == 1.0, "the zygote did not import PyOpenGL for a lab with shaders/"
    assert pyrender == 0.0, "geomlib.gl imported pyrender (about 2 s of CPU in every GLSL call)"


def _hanging_shadow_shader(dest: Path) -> None:
    """A loop in shadow.frag that runs for minutes (llvmpipe stops a fragment after 65535 turns in all,
    so each turn makes 1024 dependent texture reads: see test_planted_labs' relief shader)."""
    reads = "".join(
        f"        spin += texelFetch(shadow_map, ivec2(int(spin * 1e9) & 7, {i % 8}), 0).r * 1e-9;\n"
        for i in range(1024)
    )
    old = "    float size = float(textureSize(shadow_map, 0).x);\n    bool behind;\n"
    new = f"    float spin = 0.0;\n    while (spin >= 0.0) {{\n{reads}    }}\n" + old.replace(".x);", ".x) + spin;")
    replace_once(dest / "shaders" / "shadow.frag", old, new)


def _zygote_threads() -> int:
    return len(os.listdir(f"/proc/{sandbox._STATE['zygote'].proc.pid}/task"))


def test_after_a_hung_and_a_broken_shader_the_next_glsl_call_is_graded_correctly():
    from tests.graded.shadows import test_shadows_glsl as t

    hung = planted_solution("shadows", _hanging_shadow_shader)
    broken = planted_solution(
        "shadows", lambda d: replace_once(d / "shaders" / "depth.frag", "result = vec4(", "result = vec5(")
    )
    good = planted_solution("shadows", lambda d: None)
    try:
        lab = LabProxy("shadows", good, timeout=180)
        t.check_glsl_depth(lab, "depth-ortho-64")  # the zygote has imported PyOpenGL
        # The hung call waits out its whole limit with llvmpipe spinning (CPU, not sleep): what the
        # message needs is only that the worker reached its shader first. Forked from this warm zygote
        # it does in under 0.5 s of wall clock (the message named shadow.frag at a 0.5 s limit at a
        # load of 6 on 2 cores; the whole good call takes 1 s): 5 s (x10), not the 10 s it was.
        with pytest.raises(StudentTimeout, match=r"shaders/shadow\.frag \(Task 10"):
            t.check_glsl_shadow(LabProxy("shadows", hung, timeout=5), "glsl-eye-ortho-defaults")
        t.check_glsl_shadow(lab, "glsl-eye-ortho-defaults")
        t.check_glsl_depth(LabProxy("shadows", hung, timeout=180), "depth-ortho-64")  # its other shaders count
        with pytest.raises(GradingFailure, match=r"shaders/depth\.frag \(Task 9: light pass\) did not compile"):
            t.check_glsl_depth(LabProxy("shadows", broken, timeout=180), "depth-ortho-64")
        t.check_glsl_depth(lab, "depth-spot-48")
        t.check_glsl_shadow(lab, "glsl-eye-spot-pcf3")
        assert _zygote_threads() == 1, "the zygote started threads (an OpenGL context?): its forks could hang"
    finally:
        for d in (hung, broken, good):
            shutil.rmtree(d.parent, ignore_errors=True)


CACHE_PROBE = """
import os

import numpy as np


def gl_cached():
    from geomlib import gl

    folder = os.environ.get("MESA_SHADER_CACHE_DIR")
    before = sum(len(files) for _, _, files in os.walk(folder)) if folder else -1
    src = "#version 330 core\\nin vec2 uv; out vec4 color;\\nvoid main() { color = vec4(uv, 0.75, 1.0); }"
    gl.render_quad(src, (2, 1))
    gl.close()
    return np.array([folder == os.environ.get("NUMBA_CACHE_DIR"), before], dtype=float)
"""


def test_glsl_workers_of_one_submission_share_mesas_shader_cache():
    """llvmpipe compiles a shader at its first draw (~0.3 s of CPU, most of a GLSL call): the workers of
    one snapshot keep Mesa's disk cache in their numba cache folder, which they may write, so the second
    call of a shader finds it compiled."""
    dest = planted_solution("shadows", lambda d: (d / "probe.py").write_text(CACHE_PROBE))
    try:
        lab = LabProxy("shadows", dest, timeout=180)
        same, first = lab.gl_cached().tolist()
        _, second = lab.gl_cached().tolist()
    finally:
        shutil.rmtree(dest.parent, ignore_errors=True)
    assert same == 1.0, "MESA_SHADER_CACHE_DIR is not the snapshot's cache folder"
    assert first == 0, "the first call of a new snapshot found another snapshot's shader cache"
    assert second > 0, "the first call's compiled shader was not written to Mesa's cache"
