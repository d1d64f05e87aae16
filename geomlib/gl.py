"""A small headless OpenGL harness: run a fragment shader and read back float buffers.

Real-time labs (relief, ...) let students write GLSL. This module compiles their fragment shader,
binds float textures and uniforms, draws a full-screen quad (or a mesh with per-vertex
attributes) into float32 render targets, and returns the pixels as NumPy arrays, so a test can
compare them with the NumPy reference.

The context lives on the same headless platform as :mod:`geomlib.render` (pyrender):
:func:`geomlib.render.backend` chooses ``PYOPENGL_PLATFORM`` (OSMesa here, Mesa EGL otherwise).
An OSMesa context is created through PyOpenGL directly, with the attributes of pyrender's
``OSMesaPlatform``, so that a process that only runs shaders (a grader's sandboxed worker) never
imports pyrender; an EGL context by pyrender's ``EGLPlatform``. Never mix EGL and OSMesa in one
process (PyOpenGL binds its platform once, at import). Every call makes this module's context
current first, so it coexists with pyrender's own contexts.

Longer than most modules (about 700 lines) on purpose: the context, the shader compiler with
its student-facing error messages, textures, render targets and the two draw calls are one harness
that every GLSL lab uses; split, each part would need the others' private state.

Conventions, those of every texture in geomlib: image row 0 is ``v = 1`` (the top); the
full-screen quad passes ``uv`` in [0, 1]² with ``v`` up, and pixel ``(r, c)`` of a ``(h, w)``
output has its centre at ``uv = ((c + 0.5) / w, 1 - (r + 0.5) / h)``. Textures are uploaded with
``GL_NEAREST`` filtering and ``GL_CLAMP_TO_EDGE`` unless asked otherwise; shaders that need exact
bilinear filtering should interpolate ``texelFetch`` results themselves (GPU filtering weights
have only a few bits of precision on some drivers).

A compile error raises :class:`ShaderError` with the driver's message, with line numbers of the
source as given (the harness inserts ``#line`` after anything it prepends).

Examples
--------
>>> import numpy as np
>>> from geomlib import gl
>>> src = "#version 330 core\\nin vec2 uv; out vec4 color;\\nvoid main() { color = vec4(uv, 0, 1); }"
>>> img = gl.render_quad(src, (4, 2))  # doctest: +SKIP
>>> img.shape, img.dtype  # doctest: +SKIP
((2, 4, 4), dtype('float32'))
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import os
import re
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from geomlib.errors import MeshError

__all__ = [
    "ShaderError",
    "QUAD_VERTEX_SHADER",
    "MOVED_OFFSET_FRAGMENT_SHADER",
    "render_quad",
    "render_mesh",
    "render_points",
    "render_per_vertex",
    "point_grid",
    "renderer_info",
    "close",
    "SHADER_FOLDER",
    "shader_finder",
    "lab_shader_source",
    "naming_task",
]

#: The folder of a lab package that holds the lab's GLSL files (``shaders/<name>.vert``, ``.frag``).
SHADER_FOLDER = "shaders"
_SHADER_SUFFIXES = (".vert", ".frag", ".glsl")

#: Vertex shader of :func:`render_quad`: a full-screen quad passing ``uv`` in [0, 1]² (v up).
QUAD_VERTEX_SHADER = """#version 330 core
layout(location = 0) in vec2 position;
out vec2 uv;
void main() {
    uv = 0.5 * position + 0.5;
    gl_Position = vec4(position, 0.0, 1.0);
}
"""

_FIX = (
    "install OSMesa (`sudo apt-get install libosmesa6` on Debian/Ubuntu), or a Mesa EGL driver "
    "(`sudo apt-get install libegl1 libgl1-mesa-dri`) and set PYOPENGL_PLATFORM=egl before starting Python"
)


class ShaderError(RuntimeError):
    """A shader did not compile or link. ``log`` is the driver's message; ``lines`` the line numbers it names."""

    def __init__(self, message: str, log: str = "", lines: tuple[int, ...] = ()):
        super().__init__(message)
        self.log = log
        self.lines = lines


# --------------------------------------------------------------------------------------------
# Context
# --------------------------------------------------------------------------------------------

_STATE: dict = {}


def shader_finder(package: str | os.PathLike) -> Callable[[str], Path]:
    """The ``shader_path(name)`` function of a lab package: a lab's ``glsl.py`` writes
    ``shader_path = gl.shader_finder(__file__)``, so every lab finds its shaders the same way.

    Parameters
    ----------
    package : path
        The lab package's folder, or a file in it (a module's ``__file__``).

    Returns
    -------
    callable
        ``shader_path(name) -> Path``: ``shaders/<name>`` of the package; ``name`` is a file name
        (``"tbn.vert"``) or the stem of exactly one shader file (``"parallax"`` for ``parallax.frag``).
        A stem no file has, or more than one has, raises ``FileNotFoundError`` naming the files there.
    """
    folder = Path(package).resolve()
    folder = (folder if folder.is_dir() else folder.parent) / SHADER_FOLDER

    def shader_path(name: str) -> Path:
        """``shaders/<name>`` of this lab (``name`` with or without its ``.vert``/``.frag`` suffix)."""
        if Path(name).suffix in _SHADER_SUFFIXES:
            return folder / name
        found = sorted(p for p in folder.glob(f"{name}.*") if p.suffix in _SHADER_SUFFIXES)
        if len(found) != 1:
            have = ", ".join(sorted(p.name for p in folder.glob("*") if p.suffix in _SHADER_SUFFIXES)) or "none"
            raise FileNotFoundError(f"{len(found) or 'no'} shader file(s) named {name!r} in {folder} (it has: {have})")
        return found[0]

    return shader_path


def lab_shader_source(path: str | os.PathLike) -> str:
    """The text of a lab's shader file; a stub's unfilled shader (an ``#error Task N ...`` directive,
    which no driver compiles) raises ``NotImplementedError("shaders/<file>: Task N ...")`` instead, as
    an unfilled Python task does."""
    path = Path(path)
    source = path.read_text()
    todo = [ln.strip()[len("#error") :].strip() for ln in source.splitlines() if ln.strip().startswith("#error")]
    if todo:
        raise NotImplementedError(f"{SHADER_FOLDER}/{path.name}: {todo[0]}")
    return source


@contextlib.contextmanager
def naming_task(label: str, task: str):
    """Re-raise a :class:`ShaderError` of the shader ``label`` (``"shaders/relief.frag"``, the
    ``name`` given to the harness) with its task after the file name, so the message leads with both:
    ``shaders/relief.frag (Task 3: march and refine): line 12: ...``."""
    try:
        yield
    except ShaderError as e:
        msg = str(e).replace(label, f"{label} ({task})", 1)
        raise ShaderError(msg, log=e.log, lines=e.lines) from None


class _OSMesaContext:
    """An OSMesa context with pyrender's ``OSMesaPlatform`` interface and attributes (OpenGL 3.3 core,
    RGBA, 24-bit depth), made without importing pyrender: its import (trimesh, networkx, pyglet) costs
    about 2 s of CPU, which every sandboxed worker running a student's shader paid per call, while
    creating the context costs about 15 ms."""

    def __init__(self, width: int, height: int):
        self.width, self.height = width, height
        self._context = self._buffer = None

    def init_context(self) -> None:
        from OpenGL import arrays, osmesa

        attrs = arrays.GLintArray.asArray(
            [
                osmesa.OSMESA_FORMAT, osmesa.OSMESA_RGBA,
                osmesa.OSMESA_DEPTH_BITS, 24,
                osmesa.OSMESA_PROFILE, osmesa.OSMESA_CORE_PROFILE,
                osmesa.OSMESA_CONTEXT_MAJOR_VERSION, 3,
                osmesa.OSMESA_CONTEXT_MINOR_VERSION, 3,
                0,
            ]
        )  # fmt: skip
        self._context = osmesa.OSMesaCreateContextAttribs(attrs, None)
        if not self._context:
            raise RuntimeError("OSMesaCreateContextAttribs gave no OpenGL 3.3 core context")
        self._buffer = arrays.GLubyteArray.zeros((self.height, self.width, 4))

    def make_current(self) -> None:
        from OpenGL import GL, osmesa

        if not osmesa.OSMesaMakeCurrent(self._context, self._buffer, GL.GL_UNSIGNED_BYTE, self.width, self.height):
            raise RuntimeError("OSMesaMakeCurrent failed")

    def delete_context(self) -> None:
        from OpenGL import osmesa

        if self._context is not None:
            osmesa.OSMesaDestroyContext(self._context)
        self._context = self._buffer = None


def _gl():
    """The OpenGL module, with this module's context current (created on first use)."""
    from geomlib.render.context import note_context_created, require_own_context

    require_own_context("geomlib.gl")
    platform = _STATE.get("platform")
    if platform is None:
        from geomlib.render import backend, import_pyrender

        try:
            chosen = backend()
            if chosen == "osmesa":
                Platform = _OSMesaContext
            elif chosen == "egl":
                import_pyrender()  # the platform choice and pyrender's NumPy shim, in one place
                from pyrender.platforms.egl import EGLPlatform as Platform
            else:
                raise RuntimeError(f"PYOPENGL_PLATFORM={chosen!r} is not a headless platform (osmesa or egl)")
            platform = Platform(1, 1)  # we draw into our own framebuffer objects
            platform.init_context()
            platform.make_current()
        except Exception as e:
            raise RuntimeError(
                f"geomlib.gl: could not create a headless OpenGL context ({type(e).__name__}: {e}). Fix: {_FIX}"
            ) from e
        _STATE["platform"] = platform
        note_context_created()
    else:
        platform.make_current()
    from OpenGL import GL

    return GL


def renderer_info() -> dict:
    """``{"platform", "vendor", "renderer", "version", "glsl"}`` of the harness's context."""
    import os

    GL = _gl()
    return {
        "platform": os.environ.get("PYOPENGL_PLATFORM", ""),
        "vendor": GL.glGetString(GL.GL_VENDOR).decode(),
        "renderer": GL.glGetString(GL.GL_RENDERER).decode(),
        "version": GL.glGetString(GL.GL_VERSION).decode(),
        "glsl": GL.glGetString(GL.GL_SHADING_LANGUAGE_VERSION).decode(),
    }


def close() -> None:
    """Free the harness's OpenGL context (called automatically at exit)."""
    platform = _STATE.pop("platform", None)
    if platform is None:  # no context: not importing geomlib.render at exit saves 0.14 s of CPU
        return
    from geomlib.render.context import inherited_context

    if not inherited_context():  # a parent's context: freeing it would hang
        try:
            platform.delete_context()
        except Exception:  # the context may already be gone at interpreter shutdown
            pass


atexit.register(close)


# --------------------------------------------------------------------------------------------
# Shaders
# --------------------------------------------------------------------------------------------

_LINE_RE = re.compile(r"^\s*\d+:(\d+)\(\d+\)|^ERROR:\s*\d+:(\d+)|^\s*\d+\((\d+)\)", re.M)


#: Called as ``on_shader(name)`` when a shader named ``name`` starts (compile, draw, read-back) and
#: ``on_shader(None)`` when it is done. The grader's worker sets it, so that a call stopped at its time
#: limit can name the shader it was stuck in (a loop that does not end); None otherwise.
on_shader = None


def _note_shader(name) -> None:
    if on_shader is not None:
        on_shader(name)


def _prepare(source: str, version: str) -> str:
    """Add ``#version`` when missing, keeping the driver's line numbers those of ``source``."""
    if re.match(r"\s*#version", source):
        return source
    return f"#version {version}\n#line 1\n{source}"


def _compile(GL, kind, source: str, name: str) -> int:
    shader = GL.glCreateShader(kind)
    GL.glShaderSource(shader, source)
    GL.glCompileShader(shader)
    if not GL.glGetShaderiv(shader, GL.GL_COMPILE_STATUS):
        log = GL.glGetShaderInfoLog(shader)
        log = log.decode(errors="replace") if isinstance(log, bytes) else str(log)
        GL.glDeleteShader(shader)
        lines = tuple(int(next(g for g in m.groups() if g)) for m in _LINE_RE.finditer(log))
        src_lines = source.splitlines()
        if src_lines and src_lines[0].startswith("#version") and len(src_lines) > 1 and src_lines[1] == "#line 1":
            src_lines = src_lines[2:]
        shown = "".join(
            f"\n  line {n}: {src_lines[n - 1].strip()}" for n in dict.fromkeys(lines) if 0 < n <= len(src_lines)
        )
        # Lead with the file and line the student edits and the driver's first complaint there.
        first = next((ln.strip() for ln in log.splitlines() if _LINE_RE.match(ln)), "")
        first = re.sub(r"^(ERROR:\s*)?\d+[:(]\d+\)?(\(\d+\))?:?\s*", "", first)
        head = f"{name} did not compile, line {lines[0]}: {first}" if lines and first else f"{name} did not compile:"
        raise ShaderError(f"{head}{shown}\n{log.strip()}", log=log, lines=lines)
    return shader


def _program(GL, vertex: str, fragment: str, name: str, version: str) -> int:
    key = (vertex, fragment, version)
    cache = _STATE.setdefault("programs", {})
    if key in cache:
        return cache[key]
    vs = _compile(GL, GL.GL_VERTEX_SHADER, _prepare(vertex, version), f"{name} (vertex shader)")
    fs = _compile(GL, GL.GL_FRAGMENT_SHADER, _prepare(fragment, version), name)
    prog = GL.glCreateProgram()
    GL.glAttachShader(prog, vs)
    GL.glAttachShader(prog, fs)
    GL.glLinkProgram(prog)
    GL.glDeleteShader(vs)
    GL.glDeleteShader(fs)
    if not GL.glGetProgramiv(prog, GL.GL_LINK_STATUS):
        log = GL.glGetProgramInfoLog(prog)
        log = log.decode(errors="replace") if isinstance(log, bytes) else str(log)
        GL.glDeleteProgram(prog)
        raise ShaderError(f"{name} did not link:\n{log.strip()}", log=log)
    if len(cache) > 32:  # a grader compiles a few shaders per student; keep memory bounded
        GL.glDeleteProgram(cache.pop(next(iter(cache))))
    cache[key] = prog
    return prog


def _set_uniform(GL, prog: int, name: str, value) -> None:
    loc = GL.glGetUniformLocation(prog, name)
    if loc < 0:  # unused uniforms are optimised away by the compiler; not an error
        return
    if isinstance(value, bool | int | np.integer):
        GL.glUniform1i(loc, int(value))
        return
    a = np.asarray(value)
    if a.dtype.kind in "iub":
        a = a.astype(np.int32).ravel()
        {1: GL.glUniform1i, 2: GL.glUniform2i, 3: GL.glUniform3i, 4: GL.glUniform4i}[a.size](loc, *a.tolist())
        return
    a = a.astype(np.float32)
    if a.shape in ((3, 3), (4, 4)):
        fn = GL.glUniformMatrix3fv if a.shape == (3, 3) else GL.glUniformMatrix4fv
        fn(loc, 1, GL.GL_TRUE, np.ascontiguousarray(a))
        return
    a = a.ravel()
    fns = {1: GL.glUniform1f, 2: GL.glUniform2f, 3: GL.glUniform3f, 4: GL.glUniform4f}
    if a.size not in fns:
        raise MeshError(f"geomlib.gl: uniform {name!r} has {a.size} values; expected 1 to 4, or a 3x3/4x4 matrix")
    fns[a.size](loc, *[float(x) for x in a])


_FORMATS = {
    1: ("GL_R32F", "GL_RED"),
    2: ("GL_RG32F", "GL_RG"),
    3: ("GL_RGB32F", "GL_RGB"),
    4: ("GL_RGBA32F", "GL_RGBA"),
}


def _bind_textures(GL, prog: int, textures: Mapping, filter: str, wrap: str) -> list[int]:
    names = []
    for unit, (name, image) in enumerate(textures.items()):
        a = np.asarray(image, dtype=np.float32)
        if a.ndim == 2:
            a = a[:, :, None]
        if a.ndim != 3 or a.shape[2] not in _FORMATS or min(a.shape[:2]) < 1:
            raise MeshError(
                f"geomlib.gl: texture {name!r} has shape {np.shape(image)}; expected (h, w) or (h, w, c) with c in 1..4"
            )
        internal, fmt = (getattr(GL, n) for n in _FORMATS[a.shape[2]])
        tex = GL.glGenTextures(1)
        names.append(tex)
        GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
        GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
        GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
        # GL's first row is t = 0 (the bottom); geomlib's row 0 is v = 1 (the top).
        data = np.ascontiguousarray(a[::-1])
        GL.glTexImage2D(GL.GL_TEXTURE_2D, 0, internal, a.shape[1], a.shape[0], 0, fmt, GL.GL_FLOAT, data)
        f = GL.GL_LINEAR if filter == "linear" else GL.GL_NEAREST
        w = GL.GL_REPEAT if wrap == "repeat" else GL.GL_CLAMP_TO_EDGE
        GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER, f)
        GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, f)
        GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, w)
        GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, w)
        loc = GL.glGetUniformLocation(prog, name)
        if loc >= 0:
            GL.glUniform1i(loc, unit)
    return names


def _size(size) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in size)
    except (TypeError, ValueError):
        raise MeshError(f"geomlib.gl: size must be (width, height), got {size!r}") from None
    if not (1 <= w <= 8192 and 1 <= h <= 8192):
        raise MeshError(f"geomlib.gl: size must be between 1 and 8192 pixels on each side, got {(w, h)}")
    return w, h


def _draw(GL, prog, size, textures, uniforms, outputs, filter, wrap, draw) -> list[np.ndarray]:
    w, h = size
    if filter not in ("nearest", "linear") or wrap not in ("clamp", "repeat"):
        raise MeshError(
            f"geomlib.gl: filter must be 'nearest' or 'linear' and wrap 'clamp' or 'repeat', got {filter!r}, {wrap!r}"
        )
    fbo = GL.glGenFramebuffers(1)
    GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
    colour = [GL.glGenRenderbuffers(1) for _ in range(outputs)]
    for i, rb in enumerate(colour):
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, rb)
        GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_RGBA32F, w, h)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0 + i, GL.GL_RENDERBUFFER, rb)
    depth = GL.glGenRenderbuffers(1)
    GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, depth)
    GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH_COMPONENT24, w, h)
    GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_RENDERBUFFER, depth)
    texs: list[int] = []
    try:
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError(
                f"geomlib.gl: float framebuffer incomplete (status {status:#x}); the driver lacks RGBA32F targets"
            )
        GL.glDrawBuffers(outputs, [GL.GL_COLOR_ATTACHMENT0 + i for i in range(outputs)])
        GL.glViewport(0, 0, w, h)
        GL.glClearColor(0.0, 0.0, 0.0, 0.0)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
        GL.glUseProgram(prog)
        texs = _bind_textures(GL, prog, textures or {}, filter, wrap)
        for name, value in (uniforms or {}).items():
            _set_uniform(GL, prog, name, value)
        draw()
        GL.glFinish()
        out = []
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        for i in range(outputs):
            GL.glReadBuffer(GL.GL_COLOR_ATTACHMENT0 + i)
            buf = np.empty((h, w, 4), dtype=np.float32)
            GL.glReadPixels(0, 0, w, h, GL.GL_RGBA, GL.GL_FLOAT, buf)
            out.append(buf[::-1].copy())  # GL's first row is the bottom
        return out
    finally:
        GL.glUseProgram(0)
        if texs:
            GL.glDeleteTextures(texs)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        GL.glDeleteRenderbuffers(len(colour) + 1, [*colour, depth])
        GL.glDeleteFramebuffers(1, [fbo])


def _vertex_array(GL, prog, arrays: Mapping[str, np.ndarray]):
    vao = GL.glGenVertexArrays(1)
    GL.glBindVertexArray(vao)
    buffers = []
    for name, a in arrays.items():
        loc = GL.glGetAttribLocation(prog, name)
        if loc < 0:
            continue
        a = np.ascontiguousarray(a, dtype=np.float32)
        vbo = GL.glGenBuffers(1)
        buffers.append(vbo)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, a.nbytes, a, GL.GL_STATIC_DRAW)
        GL.glEnableVertexAttribArray(loc)
        GL.glVertexAttribPointer(loc, a.shape[1], GL.GL_FLOAT, GL.GL_FALSE, 0, ctypes.c_void_p(0))
    return vao, buffers


def render_quad(
    fragment: str,
    size,
    *,
    textures: Mapping[str, np.ndarray] | None = None,
    uniforms: Mapping[str, object] | None = None,
    outputs: int = 1,
    filter: str = "nearest",
    wrap: str = "clamp",
    version: str = "330 core",
    name: str = "fragment shader",
) -> np.ndarray | list[np.ndarray]:
    """Run ``fragment`` once per pixel of a ``size = (width, height)`` float32 image.

    Parameters
    ----------
    fragment : str
        GLSL fragment shader. It receives ``in vec2 uv`` (pixel centre in [0, 1]², v up) and writes
        ``out vec4`` colour(s) (``layout(location = i)`` for ``outputs > 1``). A missing
        ``#version`` line gets ``#version {version}``; line numbers in errors stay those of ``fragment``.
    size : (width, height)
    textures : dict name -> (h, w) or (h, w, c) array, optional
        Bound to the ``sampler2D`` uniforms of those names as 32-bit float textures, row 0 at v = 1.
    uniforms : dict name -> value, optional
        Python ints (and bools) set ``int`` uniforms; floats and 2- to 4-vectors ``float``/``vecN``;
        3x3 and 4x4 arrays ``mat3``/``mat4`` (row-major NumPy order). Names the shader does not use
        are ignored (the compiler removes them).
    outputs : int
        Number of colour outputs read back.
    filter : {"nearest", "linear"}, wrap : {"clamp", "repeat"}
        Texture sampling state for ``texture()`` (``texelFetch`` ignores both).
    name : str
        Names the shader in error messages (e.g. the student's file name).

    Returns
    -------
    (height, width, 4) float32, or a list of ``outputs`` of them
        Row 0 is the top of the image (v = 1).

    Raises
    ------
    ShaderError
        The shader does not compile or link (the driver's message, with line numbers of ``fragment``).
    RuntimeError
        No headless OpenGL context can be created (the message names the fix).
    """
    size = _size(size)
    quad = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1]], dtype=np.float32)

    def draw(GL, vao):
        GL.glBindVertexArray(vao)
        GL.glDrawArrays(GL.GL_TRIANGLE_STRIP, 0, 4)

    return _run_program(
        QUAD_VERTEX_SHADER, fragment, {"position": quad}, None, draw,
        size, textures, uniforms, outputs, filter, wrap, version, name,
    )  # fmt: skip


def _run_program(vertex, fragment, attributes, F, draw, size, textures, uniforms, outputs, filter, wrap, version, name):
    """What :func:`render_quad`, :func:`render_mesh` and :func:`render_points` share: compile and link
    ``vertex`` + ``fragment`` (``name`` noted for the shader watchdog), upload the per-vertex
    ``attributes`` (and the triangles ``F`` as element indices, unless None), call ``draw(GL, vao)``
    into ``outputs`` float targets of ``size`` (:func:`_draw`), free the buffers; one image, or the list."""
    GL = _gl()
    _note_shader(name)
    try:
        prog = _program(GL, vertex, fragment, name, version)
        vao, buffers = _vertex_array(GL, prog, attributes)
        try:
            if F is not None:  # the element buffer is state of the bound vertex array
                idx = np.ascontiguousarray(F, dtype=np.uint32)
                buffers.append(GL.glGenBuffers(1))
                GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, buffers[-1])
                GL.glBufferData(GL.GL_ELEMENT_ARRAY_BUFFER, idx.nbytes, idx, GL.GL_STATIC_DRAW)
            out = _draw(GL, prog, size, textures, uniforms, outputs, filter, wrap, lambda: draw(GL, vao))
        finally:
            GL.glBindVertexArray(0)
            if buffers:
                GL.glDeleteBuffers(len(buffers), buffers)
            GL.glDeleteVertexArrays(1, [vao])
        return out[0] if outputs == 1 else out
    finally:
        _note_shader(None)


def _vertex_count(attributes: Mapping[str, np.ndarray], where: str) -> int | None:
    """The number of vertices ``n`` the per-vertex ``attributes`` (each ``(n, 1..4)``) describe, or
    None when there are none; a mismatched shape raises :class:`MeshError` naming the attribute."""
    n = None
    for key, a in attributes.items():
        a = np.asarray(a)
        if a.ndim != 2 or not 1 <= a.shape[1] <= 4 or (n is not None and len(a) != n):
            raise MeshError(
                f"geomlib.gl.{where}: attribute {key!r} has shape {a.shape}; expected (n, 1..4), same n for all"
            )
        n = len(a)
    return n


def render_mesh(
    vertex: str,
    fragment: str,
    F,
    attributes: Mapping[str, np.ndarray],
    size,
    *,
    textures: Mapping[str, np.ndarray] | None = None,
    uniforms: Mapping[str, object] | None = None,
    outputs: int = 1,
    filter: str = "nearest",
    wrap: str = "clamp",
    version: str = "330 core",
    name: str = "fragment shader",
) -> np.ndarray | list[np.ndarray]:
    """Draw the triangles ``F`` with per-vertex ``attributes`` through ``vertex`` and ``fragment`` (depth-tested).

    Parameters
    ----------
    vertex, fragment : str
        GLSL shaders; the vertex shader writes ``gl_Position`` (clip space) from its ``in`` attributes.
    F : (m, 3) int
        Triangles indexing the rows of the attributes.
    attributes : dict name -> (n, k) float array, k in 1..4
        Bound to the vertex shader's ``in`` variables of those names (unused ones are skipped).
    size, textures, uniforms, outputs, filter, wrap, version, name
        As in :func:`render_quad`.

    Returns
    -------
    (height, width, 4) float32, or a list of them; pixels not covered keep the value 0.
    """
    size = _size(size)
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3 or F.dtype.kind not in "iu":
        raise MeshError(
            f"geomlib.gl.render_mesh: F must be an (m, 3) integer array, got shape {F.shape}, dtype {F.dtype}"
        )
    n = _vertex_count(attributes, "render_mesh")
    if n is None or F.size and (F.min() < 0 or F.max() >= n):
        raise MeshError("geomlib.gl.render_mesh: F indexes vertices that have no attributes")

    def draw(GL, vao):
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glBindVertexArray(vao)
        GL.glDrawElements(GL.GL_TRIANGLES, F.size, GL.GL_UNSIGNED_INT, ctypes.c_void_p(0))
        GL.glDisable(GL.GL_DEPTH_TEST)

    return _run_program(
        vertex, fragment, attributes, F, draw, size, textures, uniforms, outputs, filter, wrap, version, name
    )


#: Fragment shader for :func:`render_points` when a vertex shader moves each vertex: it writes the
#: ``flat`` outputs ``moved`` (the new position) to target 0 and ``offset`` (the scalar it moved by) to
#: target 1, so both read back exactly (maps' ``displace.vert``, denoise's ``denoise.vert``).
MOVED_OFFSET_FRAGMENT_SHADER = """#version 330 core
flat in vec3 moved;
flat in float offset;
layout(location = 0) out vec4 out_moved;
layout(location = 1) out vec4 out_offset;
void main() { out_moved = vec4(moved, 1.0); out_offset = vec4(offset, 0.0, 0.0, 1.0); }
"""


def render_points(
    vertex: str,
    fragment: str,
    attributes: Mapping[str, np.ndarray],
    size,
    *,
    textures: Mapping[str, np.ndarray] | None = None,
    uniforms: Mapping[str, object] | None = None,
    outputs: int = 1,
    filter: str = "nearest",
    wrap: str = "clamp",
    version: str = "330 core",
    name: str = "vertex shader",
) -> np.ndarray | list[np.ndarray]:
    """Draw every vertex as one point (``GL_POINTS``): read a vertex shader's per-vertex results back.

    The vertex shader places vertex ``gl_VertexID`` on a pixel of its own (e.g. ``i % width, i / width``)
    and passes its results as ``flat`` outputs; ``fragment`` writes them to the colour targets.
    Arguments and result as in :func:`render_mesh` (no triangles, no depth test).
    """
    size = _size(size)
    n = _vertex_count(attributes, "render_points")
    if not n:
        raise MeshError("geomlib.gl.render_points: no vertices (give at least one attribute with rows)")

    def draw(GL, vao):
        GL.glBindVertexArray(vao)
        GL.glDrawArrays(GL.GL_POINTS, 0, n)

    return _run_program(
        vertex, fragment, attributes, None, draw, size, textures, uniforms, outputs, filter, wrap, version, name
    )


def point_grid(n: int, width: int = 1024) -> tuple[int, int]:
    """The ``(width, height)`` of the image that holds ``n`` points one per pixel, row by row
    (``min(n, width)`` wide): point ``i`` on pixel ``(i % width, i // width)``."""
    w = int(min(n, width))
    return w, int(-(-n // w))


def render_per_vertex(
    vertex: str,
    fragment: str,
    attributes: Mapping[str, np.ndarray],
    n: int,
    *,
    textures: Mapping[str, np.ndarray] | None = None,
    uniforms: Mapping[str, object] | None = None,
    outputs: int = 1,
    name: str = "vertex shader",
) -> list[np.ndarray]:
    """A vertex shader's per-vertex results, in vertex order: :func:`render_points` on the
    :func:`point_grid` of the ``n`` vertices, whose size the shader gets as the uniform ``ivec2 grid``
    (it places vertex ``gl_VertexID`` on pixel ``(i % grid.x, i / grid.x)``).

    Returns
    -------
    list of ``outputs`` (n, 4) float32 arrays, row ``i`` what vertex ``i`` wrote to that target.
    """
    size = point_grid(n)
    out = render_points(
        vertex,
        fragment,
        attributes,
        size,
        textures=textures,
        uniforms={**(uniforms or {}), "grid": np.array(size, dtype=np.int32)},
        outputs=outputs,
        name=name,
    )
    # Read-back row 0 is the top of the image: GL row size[1] - 1.
    return [o[::-1].reshape(-1, 4)[:n] for o in (out if outputs > 1 else [out])]
