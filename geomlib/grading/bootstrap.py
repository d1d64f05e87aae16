"""Find or install uv for ``./run`` and ``setup.sh``, with nothing but the Python standard library.

Run as a script by the system's ``python3`` before any environment exists::

    python3 geomlib/grading/bootstrap.py uv     # prints the path of a uv executable

Why this way. A fresh Debian 12 / Ubuntu 24.04 system Python refuses ``pip install`` (PEP 668,
"externally managed"), often has no pip and no ``venv`` (python3-pip and python3-venv are separate
packages that need root), and an ordinary account has no sudo. uv's standalone installer downloads
from GitHub, which university networks and package-registry-only mirrors often do not reach. uv is
also published on PyPI as a wheel that holds nothing but its static binary: this script downloads
that wheel for a pinned version with ``urllib`` (the system's CA store and ``https_proxy`` apply),
checks the sha256 pinned below, and unpacks the binary into the user's home. No root, no pip, no
venv, no system package touched; the next run finds it there. When PyPI itself is not reachable but
pip is configured for a mirror (``pip.conf``, ``PIP_INDEX_URL``) and ``python3 -m venv`` works, it
falls back to ``pip install uv==VERSION`` into a private virtual environment next to it.

Order: ``$GEOMLIB_UV`` (a uv to use), ``uv`` on the PATH or the ``uv`` Python package of this
interpreter when at least the pinned version, the private copy, then the download
(``$GEOMLIB_UV_WHEEL``: a local copy of the wheel to use instead, still checked against the pin).
The private copy lives in ``$GEOMLIB_UV_DIR``, default ``$XDG_DATA_HOME/geomlib`` or
``~/.local/share/geomlib``.

This file must run on any Python 3.8+ and import nothing from geomlib (nothing is installed yet).
"""

from __future__ import annotations

import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import urllib.request
import zipfile

UV_VERSION = "0.13.9"
_FILES = "https://files.pythonhosted.org/packages/"
#: ``(system, machine)`` -> (wheel file on PyPI, its sha256 as PyPI's simple index gives it).
UV_WHEELS = {
    ("Linux", "x86_64"): (
        "3d/aa/26d64642d808de4a652579ef950d7cd2d37f080a8babf9c67c6b75fc4c3f/"
        "uv-0.13.9-py3-none-manylinux_2_17_x86_64.manylinux2014_x86_64.whl",
        "d7f459fe4fd247d830351c75686d3996ace3c6f3f728eb0e85a30b7ada0cef19",
    ),
    ("Linux", "aarch64"): (
        "57/15/94b6cd62ac3ff6550288328e8035288875197cbc183f51554b266a69877b/"
        "uv-0.13.9-py3-none-manylinux_2_17_aarch64.manylinux2014_aarch64.musllinux_1_1_aarch64.whl",
        "5435c5ce14a56431208ca0996416d310f1598e8c2c8ba707688985a16bb82dbe",
    ),
    ("Darwin", "x86_64"): (
        "1e/db/08e9ef4879bd667e6d7b4705e594e5bd3e4585f10fc63cb16b9fa2fac63e/uv-0.13.9-py3-none-macosx_10_12_x86_64.whl",
        "c16ed11e013557536b3e60065f1b912f6407bd6518e041b961e23ef9e6b4fbf5",
    ),
    ("Darwin", "arm64"): (
        "f3/a7/a8d7b074798c7fb3b26b37584b8fe2e29df2ccdc24ce7902caab2a53edbf/uv-0.13.9-py3-none-macosx_11_0_arm64.whl",
        "66c512266d633bef48384a1f53003f41f2a8e7b36fe6e7fbfd3e0fd52d96fa63",
    ),
}
_ALIASES = {"amd64": "x86_64", "arm64": "arm64", "aarch64": "aarch64"}


class BootstrapError(RuntimeError):
    """uv could not be found or installed; the message says what to do."""


def _say(msg: str) -> None:
    print(f"[setup] {msg}", file=sys.stderr, flush=True)


def _version(exe: str) -> tuple[int, ...] | None:
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=60).stdout.split()
        return tuple(int(x) for x in out[1].split("."))
    except (OSError, subprocess.SubprocessError, IndexError, ValueError):
        return None


def _new_enough(exe: str | None) -> bool:
    v = _version(exe) if exe else None
    return v is not None and v >= tuple(int(x) for x in UV_VERSION.split("."))


def install_dir() -> str:
    """Where the private uv lives (per user; never needs root)."""
    if os.environ.get("GEOMLIB_UV_DIR"):
        return os.environ["GEOMLIB_UV_DIR"]
    data = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return os.path.join(data, "geomlib")


def private_uv() -> str:
    """The path the pinned uv is (or will be) unpacked to."""
    return os.path.join(install_dir(), f"uv-{UV_VERSION}", "uv")


def wheel_for_this_machine() -> tuple[str, str]:
    """``(url, sha256)`` of the pinned uv wheel for this OS and CPU."""
    system, machine = platform.system(), platform.machine()
    key = (system, _ALIASES.get(machine.lower(), machine))
    if key not in UV_WHEELS:
        raise BootstrapError(
            f"no pinned uv wheel for {system} {machine}; install uv yourself "
            f"(https://docs.astral.sh/uv/getting-started/installation/) and run again"
        )
    path, sha = UV_WHEELS[key]
    return _FILES + path, sha


def fetch_wheel(dest_dir: str) -> str:
    """The pinned wheel for this machine in ``dest_dir`` (``$GEOMLIB_UV_WHEEL`` or a download), sha256 checked."""
    url, sha = wheel_for_this_machine()
    name = url.rsplit("/", 1)[1]
    target = os.path.join(dest_dir, name)
    if os.path.isfile(target) and _sha256(target) == sha:
        return target  # kept from an earlier fetch (fetch-wheel DIR)
    local = os.environ.get("GEOMLIB_UV_WHEEL")
    if local:
        shutil.copyfile(local, target)
    else:
        _say(f"downloading uv {UV_VERSION} from PyPI ({name})")
        with urllib.request.urlopen(url, timeout=120) as r, open(target, "wb") as f:
            shutil.copyfileobj(r, f)
    got = _sha256(target)
    if got != sha:
        os.unlink(target)
        raise BootstrapError(f"{name}: sha256 {got} is not the pinned {sha}; not installing it")
    return target


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _unpack(wheel: str, dest: str) -> None:
    member = f"uv-{UV_VERSION}.data/scripts/uv"
    os.makedirs(os.path.dirname(dest), exist_ok=True)
    tmp = f"{dest}.{os.getpid()}.tmp"
    with zipfile.ZipFile(wheel) as z, z.open(member) as src, open(tmp, "wb") as out:
        shutil.copyfileobj(src, out)
    os.chmod(tmp, 0o755)
    os.replace(tmp, dest)  # atomic: two runs at once both end with a whole binary


def _pip_fallback(why: str) -> str:
    """uv from pip's configured index into a private venv (machines that reach PyPI only via a mirror)."""
    venv = os.path.join(install_dir(), f"uv-{UV_VERSION}-venv")
    exe = os.path.join(venv, "bin", "uv")
    if _new_enough(exe):
        return exe
    _say(f"the uv wheel could not be downloaded ({why}); trying pip's configured index in a private venv")
    try:
        subprocess.run([sys.executable, "-m", "venv", "--clear", venv], check=True, capture_output=True)
        subprocess.run(
            [os.path.join(venv, "bin", "python"), "-m", "pip", "install", "--quiet", f"uv=={UV_VERSION}"],
            check=True,
            stdout=sys.stderr,
        )
    except (OSError, subprocess.CalledProcessError) as e:
        raise BootstrapError(
            f"could not install uv: the download failed ({why}) and so did pip in a private venv ({e}). "
            f"Install uv yourself (https://docs.astral.sh/uv/getting-started/installation/), or copy "
            f"uv's wheel onto this machine and set GEOMLIB_UV_WHEEL=/path/to/{wheel_for_this_machine()[0].rsplit('/', 1)[1]}"
        ) from None
    return exe


def find_uv() -> str:
    """A uv of at least the pinned version: found, or installed into the user's home."""
    if os.environ.get("GEOMLIB_UV"):
        return os.environ["GEOMLIB_UV"]
    on_path = shutil.which("uv")
    if _new_enough(on_path):
        return on_path
    try:  # `pip install uv` somewhere (a venv, pipx, a conda env): the binary ships inside the package
        import uv  # type: ignore[import-not-found]

        exe = uv.find_uv_bin()
        if _new_enough(exe):
            return exe
    except Exception:  # noqa: BLE001 - not installed or broken: install our own
        pass
    exe = private_uv()
    if _new_enough(exe):
        return exe
    _say(f"installing uv {UV_VERSION} into {os.path.dirname(exe)} (no root needed)")
    with tempfile.TemporaryDirectory(prefix="geomlib-uv-") as tmp:
        try:
            wheel = fetch_wheel(tmp)
        except OSError as e:  # URLError is an OSError: no network, proxy, DNS, TLS
            return _pip_fallback(str(e))
        _unpack(wheel, exe)
    if not _new_enough(exe):
        raise BootstrapError(f"the unpacked uv at {exe} does not run on this machine")
    return exe


def main(argv: list[str]) -> int:
    if argv[1:] == ["uv"]:
        try:
            print(find_uv())
        except BootstrapError as e:
            print(f"[setup] error: {e}", file=sys.stderr)
            return 1
        return 0
    if argv[1:2] == ["fetch-wheel"] and len(argv) == 3:  # keep one verified copy (for GEOMLIB_UV_WHEEL)
        try:
            print(fetch_wheel(argv[2]))
        except (BootstrapError, OSError) as e:
            print(f"[setup] error: {e}", file=sys.stderr)
            return 1
        return 0
    print("usage: python3 bootstrap.py uv | fetch-wheel DIR", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
