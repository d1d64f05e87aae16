"""One grading run's feedback pictures: how many it draws (``--pictures first|all|none``, the
autograder's cap) and drawing each in a forked child under a time limit, beside the next tests.

:mod:`geomlib.grading.feedback` draws the pictures; this module decides whether one is drawn and
runs the drawing, so a picture never costs the run more than its time limit.
"""

from __future__ import annotations

import os


def _relpath(p) -> str:
    try:
        return os.path.relpath(p)
    except ValueError:
        return str(p)


#: Pictures drawn so far in this run (see :func:`_picture_allowed`).
_DRAWN = [0]
#: This run's cap on pictures (None: no cap), set by :func:`pictures_for_run`.
_CAP: list = [None]
#: Pictures this run's cap held back.
_HELD = [0]

#: ``pictures=`` choices of ``geomlib grade --pictures`` and ``check(..., pictures=)``.
PICTURE_CHOICES = ("first", "all", "none")


class pictures_for_run:  # noqa: N801 - used as a function: ``with pictures_for_run("first"):``
    """The pictures of one grading run: ``"first"`` (the first failure's picture only: a picture costs
    about a second, a student fixing one task needs one), ``"all"`` or ``"none"``. None: the cap
    ``GEOMLIB_MAX_FEEDBACK_PICTURES`` if set (the autograder's), else ``"first"``. Counting starts
    at zero for every run (a notebook grades many times in one process)."""

    def __init__(self, pictures: str | None = None):
        if pictures is not None and pictures not in PICTURE_CHOICES:
            raise ValueError(f"pictures={pictures!r}: expected one of {', '.join(map(repr, PICTURE_CHOICES))}")
        from geomlib.grading.settings import GradingSettings

        cap = GradingSettings.build().max_pictures
        if pictures is None and cap is not None:
            self.cap = cap
        else:
            self.cap = {"first": 1, "all": None, "none": 0}[pictures or "first"]

    def __enter__(self):
        self.saved = (_DRAWN[0], _CAP[0], _HELD[0], list(_PENDING), _ASYNC[0], set(_FAILED))
        _DRAWN[0], _CAP[0], _HELD[0], _ASYNC[0] = 0, self.cap, 0, True
        _PENDING.clear()
        _FAILED.clear()
        self.held, self.failed = 0, set()
        return self

    def __exit__(self, *exc):
        #: failures whose picture the cap held back (the report says how to get them)
        self.held = _HELD[0]
        #: pictures named in messages that were not drawn after all (time limit, a drawing error)
        self.failed = _finish_pending()
        _DRAWN[0], _CAP[0], _HELD[0], pending, _ASYNC[0], failed = self.saved
        _PENDING[:] = pending
        _FAILED.clear()
        _FAILED.update(failed)
        return False


#: Within a run, pictures are drawn while the next tests run: ``(pid, path, deadline)`` of each child.
_PENDING: list = []
_ASYNC = [False]


#: Pictures drawn at once while the tests go on (each child holds a plotting library and a mesh:
#: the autograder's memory is limited, and two cores are busy with the tests and one picture).
MAX_DRAWING = 1
#: Pictures of this run that failed or ran out of time (paths as the messages name them).
_FAILED: set = set()


def _finish_pending(keep: int = 0) -> set:
    """Wait for the pictures still being drawn, oldest first, until at most ``keep`` are (each until
    its own deadline); the paths (as the messages name them) of all this run's pictures that failed
    or were too slow."""
    import time

    while len(_PENDING) > keep:
        pid, path, deadline = _PENDING.pop(0)
        ok = False
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                ok = os.waitstatus_to_exitcode(status) == 0 and os.path.exists(path)
                break
            if time.monotonic() > deadline:
                os.kill(pid, 9)
                os.waitpid(pid, 0)
                break
            time.sleep(0.01)
        if not ok:
            _FAILED.add(_relpath(path))
    return set(_FAILED)


def without_pictures(message: str, paths) -> str:
    """``message`` without its ``(see PATH)`` for each of ``paths`` (pictures that were not drawn)."""
    from geomlib.grading.errors import see_picture

    for p in paths:
        message = message.replace(see_picture(p), "")
    return message


def picture_wanted() -> bool:
    """Whether this run draws another picture; False once its cap is reached (the picture is counted
    as held back). Call it before preparing a costly picture (dense matrices, distances)."""
    if _picture_allowed():
        return True
    from geomlib.grading.settings import GradingSettings

    if GradingSettings.build().pictures:
        _HELD[0] += 1
    return False


def _picture_allowed() -> bool:
    """False when pictures are switched off (``GEOMLIB_NO_FEEDBACK_PICTURES`` set) or when this run has
    drawn its cap already (:func:`pictures_for_run`; outside a run, ``GEOMLIB_MAX_FEEDBACK_PICTURES``).
    The autograder sets a cap: a student needs a picture of the first failures of each task, and every
    picture costs a second of the run and ~0.2 MB of results.json."""
    from geomlib.grading.settings import GradingSettings

    run = GradingSettings.build()
    if not run.pictures:
        return False
    if _CAP[0] is not None:
        return _DRAWN[0] < _CAP[0]
    return run.max_pictures is None or _DRAWN[0] < run.max_pictures


def _drawn_in_time(path, draw) -> str | None:
    """Run ``draw()`` (which writes ``path``) in a forked child, stopped after
    ``GradingSettings.picture_time_limit`` or the rest of the run's time budget."""
    import time

    from geomlib.grading import sandbox
    from geomlib.grading.settings import GradingSettings

    if not picture_wanted():
        return None
    limit = GradingSettings.build().picture_time_limit
    left = sandbox.remaining_time()
    if left is not None:
        limit = min(limit, left - 1.0)
    if limit <= 0:
        return None
    if _ASYNC[0]:
        _finish_pending(keep=MAX_DRAWING - 1)  # one picture at a time beside the tests
    pid = os.fork()
    if pid == 0:  # pragma: no cover - child
        code = 1
        try:
            draw()
            code = 0
        finally:
            os._exit(code)
    deadline = time.monotonic() + limit
    if _ASYNC[0]:  # a grading run: the picture is drawn while the next tests run (pictures_for_run waits)
        _PENDING.append((pid, path, deadline))
        _DRAWN[0] += 1
        return _relpath(path)
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            if os.waitstatus_to_exitcode(status) != 0 or not os.path.exists(path):
                return None
            _DRAWN[0] += 1
            return _relpath(path)
        if time.monotonic() > deadline:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            return None
        time.sleep(0.02)
