"""Name the shader a call was stuck in when it runs out of time (issue 23, item 4).

A fragment shader that loops for ever (or for very long) stops a GLSL call at its time limit; the
grader only sees a worker that did not answer. The worker therefore notes, in its private scratch
folder, which shader :mod:`geomlib.gl` is running (:func:`install` sets ``geomlib.gl.on_shader``);
after a time-out the grader reads the note (:func:`read`) and words the message with the shader's
file, its task and the likely cause (:func:`timeout_message`).

The note is written by student code's process, so the grader reads it as untrusted: a regular file
only (no symlink, no FIFO), a few hundred bytes, a plain ``.frag``/``.vert``/``.glsl`` name.
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from geomlib.taskref import find_task

__all__ = ["NOTE", "install", "read", "timeout_message"]

#: File name of the note in the call's scratch folder.
NOTE = ".geomlib-running-shader"

_NAME = re.compile(r"[A-Za-z0-9_./ -]{1,200}\.(?:frag|vert|glsl)")


def install(scratch: str | None) -> None:
    """In the worker, before the student's code runs: note each shader ``geomlib.gl`` runs in ``scratch``."""
    if not scratch:
        return
    import geomlib.gl

    path = os.path.join(scratch, NOTE)

    def note(name) -> None:
        try:
            if name is None:
                os.unlink(path)
            else:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(str(name)[:300])
        except OSError:
            pass

    geomlib.gl.on_shader = note


def read(scratch: str | None) -> str | None:
    """The shader name the worker noted as running (None: no shader was running, or no usable note)."""
    if not scratch:
        return None
    try:
        fd = os.open(os.path.join(scratch, NOTE), os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        name = os.read(fd, 400).decode("utf-8", "replace").strip()
    except OSError:
        return None
    finally:
        os.close(fd)
    return name if _NAME.fullmatch(name) and ".." not in name else None


def _task_of(name: str, folders: list[Path]) -> str | None:
    """``Task N (title)`` from the first of ``folders`` whose copy of the shader names its task."""
    for folder in folders:
        try:
            text = (folder / name).read_text(encoding="utf-8", errors="replace")[:200_000]
        except (OSError, ValueError):
            continue
        m = find_task(text, titled=True) or find_task(text)
        if m:
            return f"Task {m.label}" + (f" ({m.title.strip()})" if m.title else "")
    return None


def timeout_message(function: str, timeout: float, shader: str, folders: list[Path]) -> str:
    """The message of a call stopped at its time limit while ``shader`` was running.

    ``folders`` are searched in order for the shader file to find its task (the course's stubs
    first: the student may have deleted the task's comments).
    """
    task = _task_of(shader, folders)
    what = f"{shader} ({task})" if task else shader
    return (
        f"{function} did not finish within {timeout:g} s (time limit): it was stopped while the GPU was running "
        f"your shader {what}. Look in {shader} for a loop that does not end or a very long one: a counter "
        f"that never reaches its bound (a step of 0, a bound that grows with the loop, a break that is never "
        f"reached), or far more iterations than layers/steps asked for."
    )
