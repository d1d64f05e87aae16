"""The settings of a grading run, read in one place: CLI, ``GEOMLIB_*`` environment, defaults.

Every ``GEOMLIB_*`` variable the tooling reads is declared once in :data:`VARIABLES` (name and
meaning; docs/autograder.md shows the same table) and read only through :func:`env` here; a test
greps the tree for any other reader. :class:`GradingSettings` is the frozen value one grading run is
made with (``geomlib grade``, ``check()``): it is built at the edge (:meth:`GradingSettings.build`)
and handed to pytest inside a :class:`geomlib.grading.plugin.GradingRun` plugin instance, which
returns that run's records — nothing about a run is kept in module globals or written to the
environment.

The sandbox's zygote and workers are other processes: what the parent decides reaches them through
their environment (``GEOMLIB_SANDBOX_USER``, ...), and they read it through :func:`env` as well.
``geomlib/grading/bootstrap.py`` is the one exception: it runs before any environment exists and
imports nothing from geomlib (its three ``GEOMLIB_UV*`` variables are listed here all the same).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from geomlib.grading.tolerances import PICTURE_TIME_S

__all__ = ["VARIABLES", "GradingSettings", "env", "env_float", "kernel_cache_dir", "markdown_table"]

#: Every ``GEOMLIB_*`` environment variable: what it does (one line each; docs/autograder.md lists them).
VARIABLES: dict[str, str] = {
    "GEOMLIB_ROOT": "the course folder (holding `tests/`, `solutions/`, `labs/`); default: the checkout geomlib is imported from",
    "GEOMLIB_IMPL": "the implementation a notebook's `open_lab` loads and its `check()` grades (`solutions`, `labs` or a folder); default: the solutions where present, else `labs`",
    "GEOMLIB_TIME_BUDGET": "seconds for a whole grading run (`--time-budget`); later tests fail at once with a message",
    "GEOMLIB_TIME_LIMIT": "seconds allowed per call into the implementation (`--time-limit`); default each test's own (the test suite, run without `--impl`, sets 300: a limit for hangs)",
    "GEOMLIB_NO_FEEDBACK_PICTURES": "set (non-empty): draw no feedback pictures",
    "GEOMLIB_MAX_FEEDBACK_PICTURES": "at most this many feedback pictures per run (the autograder sets 8)",
    "GEOMLIB_PICTURE_TIME_LIMIT": "seconds one feedback picture may take before it is given up (a limit for hangs; default 20; the test suite sets 300)",
    "GEOMLIB_SANDBOX_USER": "the user student code runs as (as root; empty: no sandbox user); the autograder sets `nobody`",
    "GEOMLIB_SANDBOX_UIDS": "`FIRST-LAST`: the private uids `grade-all` runs submissions as; `none`: all as the sandbox user",
    "GEOMLIB_SANDBOX_HIDE": "extra folders (os.pathsep-separated) student code may not read",
    "GEOMLIB_LANDLOCK": "`0`: do not use Landlock (to test the protection of a kernel without it)",
    "GEOMLIB_SECCOMP": "`0`: do not install the network filter (to test what it blocks)",
    "GEOMLIB_KERNEL_CACHE": "where the compiled kernels of the course's own `solutions/` and `labs/` are kept between grading runs (default `$XDG_CACHE_HOME/geomlib-kernels`, else `~/.cache/geomlib-kernels`); `off`: nowhere (each run compiles)",
    "GEOMLIB_STUBS": "the folder of the course's stubs (default `labs/` of the course), for shader-task messages",
    "GEOMLIB_AUTOGRADER_PYTHON": "the Python 3.11 `grade-all` builds the autograder's environment with",
    "GEOMLIB_AUTOGRADER_ROOT": "the autograder's folder in `setup.sh`/`run_autograder` (default `/autograder`)",
    "GEOMLIB_SETUP_DEV": "`1`: `setup.sh` also installs the development dependencies",
    "GEOMLIB_DRI_DIR": "where `setup.sh` looks for Mesa's `swrast_dri.so` (default `/usr/lib/*/dri`)",
    "GEOMLIB_PYTHON": "the Python `run_autograder` grades with (default `source/.venv/bin/python`)",
    "GEOMLIB_UV": "a uv executable for `./run` and `setup.sh` (bootstrap.py)",
    "GEOMLIB_UV_WHEEL": "a local copy of the pinned uv wheel (bootstrap.py)",
    "GEOMLIB_UV_DIR": "where bootstrap.py keeps its private uv (default `$XDG_DATA_HOME/geomlib`)",
}


def env(name: str, default: str | None = None) -> str | None:
    """The value of the ``GEOMLIB_*`` variable ``name`` (declared in :data:`VARIABLES`), else ``default``."""
    if name not in VARIABLES:
        raise KeyError(f"{name} is not a declared GEOMLIB_* variable (add it to geomlib.grading.settings.VARIABLES)")
    return os.environ.get(name, default)


def env_float(name: str) -> float | None:
    """A numeric variable: its value as a float, None when unset or empty."""
    value = env(name)
    return float(value) if value else None


def kernel_cache_dir() -> Path | None:
    """Where :mod:`geomlib.grading.kernelcache` keeps trusted compiled kernels (None: ``off``).

    ``GEOMLIB_KERNEL_CACHE``, else ``$XDG_CACHE_HOME/geomlib-kernels``, else ``~/.cache/geomlib-kernels``
    (the XDG base-directory rule; read here, the one place the tooling reads the environment).
    """
    given = (env("GEOMLIB_KERNEL_CACHE") or "").strip()
    if given.lower() in ("off", "0", "no", "none"):
        return None
    if given:
        return Path(given)
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if os.path.isabs(xdg) else Path(os.path.expanduser("~")) / ".cache"
    return base / "geomlib-kernels"


def _picture_cap() -> int | None:
    cap = (env("GEOMLIB_MAX_FEEDBACK_PICTURES") or "").strip()
    return int(cap) if cap.isdigit() else None


@dataclass(frozen=True)
class GradingSettings:
    """What one grading run is made with.

    Attributes
    ----------
    impl : str or None
        ``"solutions"``, ``"labs"`` or a submission path (None: pytest's ``--impl`` or the default).
    feedback_dir : Path or None
        Where failure pictures go (None: no pictures).
    time_budget, time_limit : float or None
        Seconds for the whole run and per call (``GEOMLIB_TIME_BUDGET``, ``GEOMLIB_TIME_LIMIT``).
    pictures : bool
        False when ``GEOMLIB_NO_FEEDBACK_PICTURES`` is set.
    max_pictures : int or None
        ``GEOMLIB_MAX_FEEDBACK_PICTURES``.
    picture_time_limit : float
        Seconds one feedback picture may take (``GEOMLIB_PICTURE_TIME_LIMIT``, default
        :data:`~geomlib.grading.tolerances.PICTURE_TIME_S`): a limit for a drawing that hangs.
    """

    impl: str | None = None
    feedback_dir: Path | None = Path("feedback")
    time_budget: float | None = None
    time_limit: float | None = None
    pictures: bool = True
    max_pictures: int | None = None
    picture_time_limit: float = PICTURE_TIME_S

    @classmethod
    def build(cls, **given) -> GradingSettings:
        """The settings of a run: what the caller (CLI, ``check()``) gives, else the environment, else defaults.

        An argument given as None counts as not given.
        """
        given = {k: v for k, v in given.items() if v is not None}
        if "impl" in given:
            given["impl"] = str(given["impl"])
        if "feedback_dir" in given:
            given["feedback_dir"] = Path(given["feedback_dir"]) if given["feedback_dir"] else None
        values = dict(
            time_budget=env_float("GEOMLIB_TIME_BUDGET"),
            time_limit=env_float("GEOMLIB_TIME_LIMIT"),
            pictures=not env("GEOMLIB_NO_FEEDBACK_PICTURES"),
            max_pictures=_picture_cap(),
            picture_time_limit=env_float("GEOMLIB_PICTURE_TIME_LIMIT") or PICTURE_TIME_S,
        )
        return cls(**{**values, **given})


def markdown_table() -> str:
    """The table of :data:`VARIABLES` as docs/autograder.md shows it."""
    rows = ["| Variable | What it does |", "| --- | --- |"]
    rows += [f"| `{name}` | {what} |" for name, what in VARIABLES.items()]
    return "\n".join(rows)
