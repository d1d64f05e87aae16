"""Where geomlib.jit puts numba's cache: per import name, beside the source when writable, else a
private per-user folder in the temporary directory, ``NUMBA_CACHE_DIR`` first."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from geomlib.jit import cache_folder

ROOT = Path(__file__).resolve().parents[2]


def test_cache_goes_beside_the_source_in_a_folder_per_import_name(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    package = tmp_path / "package"
    package.mkdir()
    first = cache_folder("labs.sdf.kernels", package, tmp_path)
    assert first == package / "__pycache__" / "numba-labs_sdf_kernels" and first.is_dir()
    # The grader imports the same file under another name: its cache must not collide.
    assert cache_folder("lab_sdf.kernels", package, tmp_path) == package / "__pycache__" / "numba-lab_sdf_kernels"


def test_cache_folder_when_the_package_folder_is_not_writable(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    blocked = tmp_path / "a-file"
    blocked.write_text("")  # a folder inside a file cannot be created: not writable for anyone
    chosen = cache_folder("lab.kernels", blocked / "package", tmp_path)
    private = tmp_path / f"geomlib-numba-cache-{os.getuid()}"
    assert chosen == private / "numba-lab_kernels" and chosen.is_dir()
    assert private.stat().st_mode & 0o777 == 0o700
    assert cache_folder("lab.kernels", blocked / "package", tmp_path) == chosen  # the next process reuses it
    private.chmod(0o777)  # someone else could plant pickles there: not used
    other = cache_folder("lab.kernels", blocked / "package", tmp_path).parent
    assert other != private and other.parent == tmp_path and other.stat().st_mode & 0o777 == 0o700
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert cache_folder("lab.kernels", blocked / "package", tmp_path) == tmp_path / "mine" / "numba-lab_kernels"


def test_a_folder_owned_by_someone_else_is_not_used(tmp_path, monkeypatch):
    # A link planted under the expected name (pointing at a folder the planter controls) is not a
    # private folder of ours, even though we can write through it.
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    target = tmp_path / "planted"
    target.mkdir(mode=0o700)
    (tmp_path / f"geomlib-numba-cache-{os.getuid()}").symlink_to(target)
    blocked = tmp_path / "a-file"
    blocked.write_text("")
    chosen = cache_folder("lab.kernels", blocked / "package", tmp_path)
    assert target not in chosen.parents and chosen.parent.parent == tmp_path


def test_importing_geomlib_jit_does_not_import_numba():
    code = "import sys, geomlib.jit; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
