"""Helpers of the fresh-machine tests (issue 28): a clean environment, the shared uv cache, uv's wheel.

A "fresh machine" here is ``env -i`` with the system PATH (no pyenv, no ~/.local/bin, no uv on it),
an empty HOME and the system ``python3`` (``/usr/bin/python3``: PEP 668, maybe without pip or venv).
Two things are shared with the machine so that the tests check the set-up and not the network:

- the uv package cache (``UV_CACHE_DIR``), which ``./run`` uses like any uv cache;
- one verified copy of uv's wheel (``GEOMLIB_UV_WHEEL``), fetched once per machine by the
  bootstrap's own ``fetch-wheel`` into ``~/.cache/geomlib-test/`` and checked against the same
  pinned sha256 every time it is used.

The machine's network settings (proxy, CA bundle, package index) are passed through: they are how
this machine reaches a registry, not set-up.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SYSTEM_PATH = "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"
BOOTSTRAP = ROOT / "geomlib" / "grading" / "bootstrap.py"
_NETWORK = re.compile(
    r"^(SSL_CERT_(FILE|DIR)|REQUESTS_CA_BUNDLE|CURL_CA_BUNDLE|PIP_(CERT|INDEX_URL|EXTRA_INDEX_URL|DEFAULT_TIMEOUT)"
    r"|UV_(INDEX_URL|EXTRA_INDEX_URL|DEFAULT_INDEX|INDEX|NATIVE_TLS|SYSTEM_CERTS)|(https?|no|all)_proxy)$",
    re.IGNORECASE,
)


def system_python() -> str:
    """The system's python3 (what a fresh machine has), or skip."""
    found = shutil.which("python3", path=SYSTEM_PATH)
    if not found:
        pytest.skip("no python3 on the system PATH")
    return found


def uv_cache_dir() -> Path:
    """The machine's uv package cache (where uv itself looks for it), or skip when it is empty."""
    if os.environ.get("UV_CACHE_DIR"):
        d = Path(os.environ["UV_CACHE_DIR"])
    else:
        d = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "uv"
    if not (d / "archive-v0").is_dir():
        pytest.skip(f"no warm uv cache at {d}: the fresh-machine test would download every package")
    return d


def uv_wheel() -> Path:
    """One copy of the pinned uv wheel for this machine, sha256-checked by the bootstrap (fetched once)."""
    keep = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "geomlib-test"
    keep.mkdir(parents=True, exist_ok=True)
    p = subprocess.run(
        [sys.executable, str(BOOTSTRAP), "fetch-wheel", str(keep)],
        env={**os.environ, "GEOMLIB_UV_WHEEL": ""},
        capture_output=True,
        text=True,
        timeout=600,
    )
    if p.returncode != 0:
        pytest.skip(f"uv's wheel could not be fetched from PyPI: {p.stderr.strip()[-500:]}")
    return Path(p.stdout.strip())


def clean_env(home: Path, **extra: str) -> dict[str, str]:
    """``env -i`` plus the system PATH, ``home`` as HOME and the machine's network settings."""
    env = {k: v for k, v in os.environ.items() if _NETWORK.match(k)}
    env.update(PATH=SYSTEM_PATH, HOME=str(home), LANG="C.UTF-8")
    env.update(extra)
    return env


def env_i(env: dict[str, str]) -> list[str]:
    """The ``env -i`` prefix of a command run in exactly ``env``."""
    return ["env", "-i", *(f"{k}={v}" for k, v in env.items())]
