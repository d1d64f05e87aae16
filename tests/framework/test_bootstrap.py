"""uv's bootstrap (geomlib/grading/bootstrap.py): pinned wheel, checked, unpacked into the user's home.

The wheel comes from one verified copy kept per machine (tests/framework/fresh_machine.py), so
these tests do not download; the download itself is one ``urllib`` call on a pinned URL.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import zipfile

import pytest

from .fresh_machine import BOOTSTRAP, uv_wheel


@pytest.fixture
def bootstrap(monkeypatch, tmp_path):
    spec = importlib.util.spec_from_file_location("geomlib_bootstrap", BOOTSTRAP)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    monkeypatch.setenv("PATH", "/nonexistent")  # no uv on the PATH
    monkeypatch.setitem(sys.modules, "uv", None)  # nor as a Python package
    monkeypatch.setenv("GEOMLIB_UV_DIR", str(tmp_path / "home-share"))
    monkeypatch.delenv("GEOMLIB_UV", raising=False)
    return mod


def test_every_pinned_wheel_is_a_pypi_file_of_the_pinned_version(bootstrap):
    for (system, machine), (path, sha) in bootstrap.UV_WHEELS.items():
        name = path.rsplit("/", 1)[1]
        assert name.startswith(f"uv-{bootstrap.UV_VERSION}-py3-none-") and name.endswith(".whl")
        assert len(sha) == 64 and int(sha, 16) >= 0
        assert {"Linux": "linux", "Darwin": "macosx"}[system] in name and machine in name


def test_the_pinned_uv_is_unpacked_once_into_the_users_home(bootstrap, monkeypatch):
    if (bootstrap.platform.system(), bootstrap.platform.machine()) not in bootstrap.UV_WHEELS:
        pytest.skip("no pinned wheel for this machine")
    monkeypatch.setenv("GEOMLIB_UV_WHEEL", str(uv_wheel()))
    exe = bootstrap.find_uv()
    assert exe == bootstrap.private_uv() and exe.startswith(bootstrap.install_dir())
    out = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.split()[:2] == ["uv", bootstrap.UV_VERSION]
    mtime = os.stat(exe).st_mtime_ns
    monkeypatch.setenv("GEOMLIB_UV_WHEEL", "/nonexistent.whl")  # a second run must not need it
    assert bootstrap.find_uv() == exe and os.stat(exe).st_mtime_ns == mtime


def test_a_wheel_that_is_not_the_pinned_one_is_refused(bootstrap, monkeypatch, tmp_path):
    if (bootstrap.platform.system(), bootstrap.platform.machine()) not in bootstrap.UV_WHEELS:
        pytest.skip("no pinned wheel for this machine")
    fake = tmp_path / "uv.whl"
    with zipfile.ZipFile(fake, "w") as z:
        z.writestr(f"uv-{bootstrap.UV_VERSION}.data/scripts/uv", "#!/bin/sh\necho pwned\n")
    monkeypatch.setenv("GEOMLIB_UV_WHEEL", str(fake))
    with pytest.raises(bootstrap.BootstrapError, match="sha256 .* is not the pinned"):
        bootstrap.find_uv()
    assert not (tmp_path / "home-share").exists() or not list((tmp_path / "home-share").rglob("uv"))


def test_an_unknown_platform_says_what_to_do(bootstrap, monkeypatch):
    monkeypatch.setattr(bootstrap.platform, "machine", lambda: "sparc64")
    with pytest.raises(bootstrap.BootstrapError, match="no pinned uv wheel for .* sparc64.*install uv yourself"):
        bootstrap.wheel_for_this_machine()


def test_without_pypi_it_tries_pips_configured_index_then_says_what_to_do(bootstrap, monkeypatch):
    """No route to files.pythonhosted.org: pip's own configuration (a mirror) in a private venv;
    when that fails too, the message names the two ways out."""
    if (bootstrap.platform.system(), bootstrap.platform.machine()) not in bootstrap.UV_WHEELS:
        pytest.skip("no pinned wheel for this machine")
    monkeypatch.delenv("GEOMLIB_UV_WHEEL", raising=False)

    def no_network(url, timeout=None):
        raise bootstrap.urllib.error.URLError("Name or service not known")

    monkeypatch.setattr(bootstrap.urllib.request, "urlopen", no_network)
    ran = []

    def run(cmd, **kw):
        ran.append(cmd)
        raise subprocess.CalledProcessError(1, cmd, stderr=b"ensurepip is not available")

    monkeypatch.setattr(bootstrap.subprocess, "run", run)
    with pytest.raises(bootstrap.BootstrapError) as e:
        bootstrap.find_uv()
    assert [c for c in ran if c[1:3] == ["-m", "venv"]], ran
    msg = str(e.value)
    assert "Name or service not known" in msg and "GEOMLIB_UV_WHEEL" in msg and "docs.astral.sh/uv" in msg
