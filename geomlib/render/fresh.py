"""Rendering in a fresh interpreter, for a process forked after OpenGL was used.

A forked child of a process that has rendered cannot use OpenGL (Mesa's rasteriser threads stay
behind in the parent; see :func:`geomlib.render.context.inherited_context`). The grader draws its
feedback pictures in forked children (to bound their time), and a notebook often renders figures
before it grades, so :func:`geomlib.render.render` sends the call to a new Python process instead:
the arrays and options go over a pipe (pickled), the image comes back. That costs the start of an
interpreter and a context (about 1 s) once per child, then a render as usual; paid only in such a child.
"""

from __future__ import annotations

import os
import pickle
import struct
import subprocess
import sys
import tempfile

import numpy as np

__all__ = ["render_in_fresh_process"]


def _die_with_parent() -> None:  # pragma: no cover - runs in the child between fork and exec
    """Linux: the fresh process is killed with the process that asked for it (a feedback picture
    past its time limit is killed with SIGKILL, which its helpers must not outlive)."""
    try:
        import ctypes

        ctypes.CDLL(None).prctl(1, 9)  # PR_SET_PDEATHSIG, SIGKILL
    except Exception:
        pass


#: The fresh process serving this process's calls: ``(owner pid, Popen, stderr file)``, started on the
#: first call and reused (a feedback picture renders three images: one start instead of three).
_SERVER: list = []


def _server():
    if _SERVER and _SERVER[0][0] == os.getpid() and _SERVER[0][1].poll() is None:
        return _SERVER[0]
    _SERVER.clear()  # none yet, a parent's (inherited through a fork: its pipes are not ours), or dead
    # The fresh interpreter sees the modules this one sees (a course root added to sys.path, ...).
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    err = tempfile.TemporaryFile()  # a file, not a pipe: a chatty stderr cannot block the server
    proc = subprocess.Popen(
        [sys.executable, "-c", "from geomlib.render.fresh_server import serve; serve()"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=err,
        env=env,
        preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
    )
    _SERVER.append((os.getpid(), proc, err))
    return _SERVER[0]


def _pickled(obj) -> bytes:
    return pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)


def _send(stream, data: bytes) -> None:
    """Write one message: its length (8 bytes), then the pickled bytes."""
    stream.write(struct.pack("<Q", len(data)))
    stream.write(data)
    stream.flush()


def _receive(stream):
    head = stream.read(8)
    if len(head) < 8:
        raise EOFError("the fresh process closed its pipe")
    (n,) = struct.unpack("<Q", head)
    data = stream.read(n)
    if len(data) < n:
        raise EOFError("the fresh process closed its pipe")
    return pickle.loads(data)


def render_in_fresh_process(entry: str, V, F, options, overrides: dict) -> np.ndarray:
    """Call ``geomlib.render.<entry>(V, F, options, **overrides)`` in a fresh Python process.

    Parameters
    ----------
    entry : {"render", "render_polygons"}
        The entry point to call.
    V, F, options, overrides
        Its arguments, as given to it (they must pickle: arrays, lists, option objects do).

    Returns and raises what the entry point does there (the image; a ``MeshError`` for a bad mesh,
    ...), or a ``RuntimeError`` naming the failure when the fresh process itself failed.
    """
    _, proc, err = _server()
    try:
        _send(proc.stdin, _pickled((entry, V, F, options, overrides)))
        status, value = _receive(proc.stdout)
    except (OSError, EOFError) as e:
        proc.kill()
        proc.wait()
        err.seek(0)
        tail = err.read().decode(errors="replace").strip().splitlines()[-1:] or [str(e)]
        raise RuntimeError(
            f"geomlib.render.{entry}: the fresh process drawing for this forked one failed "
            f"(exit code {proc.returncode}: {tail[0]})"
        ) from None
    if status == "error":
        raise value
    return value
