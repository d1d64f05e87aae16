"""The headless OpenGL context: platform choice (OSMesa or Mesa EGL), pyrender import, renderer cache.

Importing this module imports neither pyrender nor OpenGL; :func:`import_pyrender` does, after
:func:`backend` has chosen a headless platform. One ``OffscreenRenderer`` is kept per image size.
"""

from __future__ import annotations

import atexit
import ctypes.util
import os
import sys

import numpy as np

__all__ = [
    "backend",
    "import_pyrender",
    "offscreen_renderer",
    "close",
    "note_context_created",
    "inherited_context",
    "require_own_context",
]

_HEADLESS_FIX = (
    "install OSMesa (`sudo apt-get install libosmesa6` on Debian/Ubuntu), or a Mesa EGL driver "
    "(`sudo apt-get install libegl1 libgl1-mesa-dri`) and set PYOPENGL_PLATFORM=egl"
)


def backend() -> str:
    """The headless OpenGL platform used for rendering: ``"osmesa"``, ``"egl"``, or the user's choice.

    A ``PYOPENGL_PLATFORM`` already set in the environment is respected. Otherwise OSMesa is used
    when ``libOSMesa`` is found, else Mesa EGL when ``libEGL`` is found, and the choice is written
    to ``os.environ["PYOPENGL_PLATFORM"]`` (PyOpenGL reads it once, at import).

    Returns
    -------
    str
        The value of ``PYOPENGL_PLATFORM``.

    Raises
    ------
    RuntimeError
        When no headless OpenGL library is installed, or OpenGL was imported before a platform
        was chosen. The message names the fix.
    """
    chosen = os.environ.get("PYOPENGL_PLATFORM")
    if chosen:
        return chosen
    if "OpenGL.platform" in sys.modules:
        # PyOpenGL chose its platform at import. A headless one (OSMesa or EGL) is what we would
        # choose, so record it; an on-screen one (GLX) cannot render here.
        current = type(getattr(sys.modules["OpenGL.platform"], "PLATFORM", None)).__name__.lower()
        for name in ("osmesa", "egl"):
            if current.startswith(name):
                os.environ["PYOPENGL_PLATFORM"] = name
                return name
        raise RuntimeError(
            "geomlib.render: PyOpenGL was imported before a headless platform was chosen, so it uses an "
            "on-screen platform. Set the environment variable PYOPENGL_PLATFORM=osmesa (or egl) before "
            "starting Python, or import geomlib.render before anything that imports OpenGL."
        )
    if ctypes.util.find_library("OSMesa"):
        chosen = "osmesa"
    elif ctypes.util.find_library("EGL"):
        chosen = "egl"
    else:
        raise RuntimeError(
            f"geomlib.render: no headless OpenGL library found (neither libOSMesa nor libEGL). Fix: {_HEADLESS_FIX}"
        )
    os.environ["PYOPENGL_PLATFORM"] = chosen
    return chosen


def import_pyrender():
    """Import and return the ``pyrender`` module, after choosing the headless platform (see :func:`backend`).

    Use this (never a bare ``import pyrender``) in code that builds its own pyrender scenes, e.g.
    cross-checks against pyrender's shadow maps, so the platform and the NumPy shim are in place.
    """
    backend()
    if not hasattr(np, "infty"):
        # Compatibility shim, the only one in the project: pyrender 0.1.45 (its latest release) still
        # uses np.infty in Mesh.bounds, an alias removed in NumPy 2.0.
        np.infty = np.inf  # noqa: NPY201 (setting the alias, not using it)
    import pyrender

    return pyrender


_RENDERERS: dict[tuple[int, int], object] = {}

#: The process that created this process's first OpenGL context (empty until one is created).
_CONTEXT_OWNER: list[int] = []


def note_context_created() -> None:
    """Record that this process has created an OpenGL context (see :func:`inherited_context`)."""
    if not _CONTEXT_OWNER:
        _CONTEXT_OWNER.append(os.getpid())


def inherited_context() -> bool:
    """True in a process forked from one that had already created an OpenGL context.

    Mesa's software rasteriser (llvmpipe, under OSMesa and EGL alike) draws with worker threads that
    a fork does not copy: in the child, the inherited context and any new one wait for them forever
    (measured: a 64x64 render that takes 0.06 s hangs). Such a process must not touch OpenGL;
    :func:`geomlib.render.render` then draws in a fresh interpreter (:mod:`.fresh`).
    """
    return bool(_CONTEXT_OWNER) and _CONTEXT_OWNER[0] != os.getpid()


def require_own_context(where: str) -> None:
    """Raise a clear ``RuntimeError`` (naming ``where``) instead of hanging in an :func:`inherited_context`."""
    if inherited_context():
        raise RuntimeError(
            f"{where}: this process was forked from one that had already rendered, and Mesa's OpenGL "
            "does not survive a fork (its rasteriser threads stay behind, so any drawing would hang). "
            "Render before forking, in a fresh process (multiprocessing's 'spawn'), or through "
            "geomlib.render.render, which does that by itself."
        )


def offscreen_renderer(width: int, height: int):
    """The shared ``pyrender.OffscreenRenderer`` for this framebuffer size, created on first use.

    Creating an OpenGL context is costly, so one per size is kept for the whole process and freed
    at exit (:func:`close`). Do not call ``delete()`` on it.

    Raises
    ------
    RuntimeError
        When no headless OpenGL context can be created (the message names the fix), or in a process
        forked after OpenGL was used (:func:`inherited_context`).
    """
    require_own_context("geomlib.render.offscreen_renderer")
    r = _RENDERERS.get((width, height))
    if r is None:
        pyrender = import_pyrender()
        try:
            r = pyrender.OffscreenRenderer(width, height)
        except Exception as e:
            raise RuntimeError(
                f"geomlib.render: could not create a headless OpenGL context with PYOPENGL_PLATFORM="
                f"{os.environ.get('PYOPENGL_PLATFORM')!r} ({type(e).__name__}: {e}). Fix: {_HEADLESS_FIX}"
            ) from e
        _RENDERERS[(width, height)] = r
        note_context_created()
    return r


def close() -> None:
    """Free every cached OpenGL context (called automatically at exit)."""
    if inherited_context():  # the parent's contexts: freeing them here would hang
        _RENDERERS.clear()
    while _RENDERERS:
        _, r = _RENDERERS.popitem()
        try:
            r.delete()
        except Exception:  # the context may already be gone at interpreter shutdown
            pass


atexit.register(close)
