"""The fresh process's side of :mod:`geomlib.render.fresh`: read pickled calls, draw, send images back.

Its own module so that data flows one way: ``draw`` sends calls through ``fresh``, and this
server (started by ``fresh`` as ``python -c "from geomlib.render.fresh_server import serve; serve()"``)
is the only module above both.
"""

from __future__ import annotations

import sys

from geomlib.render import draw
from geomlib.render.fresh import _pickled, _receive, _send

__all__ = ["serve"]


def serve() -> None:  # pragma: no cover - runs in the fresh process (tested through render)
    """Answer pickled calls from stdin with ``("ok", image)`` or ``("error", exc)`` until stdin closes."""
    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    while True:
        try:
            entry, V, F, options, overrides = _receive(stdin)
        except EOFError:
            return
        try:
            out = ("ok", getattr(draw, entry)(V, F, options, **overrides))
        except Exception as e:
            out = ("error", e)
        try:
            data = _pickled(out)
        except Exception:  # an exception that does not pickle: keep its type's name and message
            data = _pickled(("error", RuntimeError(f"{type(out[1]).__name__}: {out[1]}")))
        _send(stdout, data)
