"""Rendering in a fresh interpreter, for a process forked after OpenGL was used.

A forked child of a process that has rendered cannot use OpenGL (Mesa's rasteriser threads stay
behind in the parent; see :func:`geomlib.render.context.inherited_context`). The grader draws its
feedback pictures in forked children (to bound their time), and a notebook often renders figures
before it grades, so :func:`geomlib.render.render` sends the call to a new Python process instead:
the arrays and options go over a pipe (pickled), the image comes back. That costs the start of an
interpreter and a context (about 2 s) per call, paid only in such a child.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys

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


def render_in_fresh_process(entry: str, V, F, options, overrides: dict) -> np.ndarray:
    """Call ``geomlib.render.<entry>(V, F, options, **overrides)`` in a new Python process.

    Parameters
    ----------
    entry : {"render", "render_polygons"}
        The entry point to call.
    V, F, options, overrides
        Its arguments, as given to it (they must pickle: arrays, lists, option objects do).

    Returns and raises what the entry point does there (the image; a ``MeshError`` for a bad mesh,
    ...), or a ``RuntimeError`` naming the failure when the fresh process itself failed.
    """
    payload = pickle.dumps((entry, V, F, options, overrides), protocol=pickle.HIGHEST_PROTOCOL)
    # The fresh interpreter sees the modules this one sees (a course root added to sys.path, ...).
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run(
        [sys.executable, "-c", "from geomlib.render.fresh import _serve; _serve()"],
        input=payload,
        capture_output=True,
        env=env,
        preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
    )
    if proc.returncode != 0 or not proc.stdout:
        tail = proc.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["no message"]
        raise RuntimeError(
            f"geomlib.render.{entry}: the fresh process drawing for this forked one failed "
            f"(exit code {proc.returncode}: {tail[0]})"
        )
    status, value = pickle.loads(proc.stdout)
    if status == "error":
        raise value
    return value


def _serve() -> None:  # pragma: no cover - runs in the fresh process (tested through render)
    """Read one pickled call from stdin, run it, write the pickled ``("ok", image)`` or ``("error", exc)``."""
    from geomlib.render import draw

    entry, V, F, options, overrides = pickle.load(sys.stdin.buffer)
    try:
        out = ("ok", getattr(draw, entry)(V, F, options, **overrides))
    except Exception as e:
        out = ("error", e)
    try:
        data = pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # an exception that does not pickle: keep its type's name and message
        data = pickle.dumps(("error", RuntimeError(f"{type(out[1]).__name__}: {out[1]}")))
    sys.stdout.buffer.write(data)
    sys.stdout.flush()
