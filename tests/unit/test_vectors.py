"""Tests for geomlib.vectors and the top-level package (lazy re-exports, version)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import geomlib
from geomlib.errors import MeshError
from geomlib.vectors import as_unit_vectors, normalize_rows


def test_normalize_rows_keeps_zero_rows_finite():
    X = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -2.0]])
    np.testing.assert_allclose(normalize_rows(X), [[0.6, 0.8, 0], [0, 0, 0], [0, 0, -1]])
    np.testing.assert_allclose(normalize_rows(X, fallback=(0, 0, 1))[1], [0, 0, 1])
    assert normalize_rows(X.astype(np.float32)).dtype == np.float32
    assert normalize_rows([[0, 2]]).tolist() == [[0.0, 1.0]]  # ints become float64
    np.testing.assert_allclose(normalize_rows(np.ones((2, 2, 4))), np.full((2, 2, 4), 0.5))  # any leading shape


def test_as_unit_vectors_names_the_problem():
    N = as_unit_vectors([[0, 0, 2.0], [1, 0, 0]], 2)
    np.testing.assert_allclose(N, [[0, 0, 1], [1, 0, 0]])
    with pytest.raises(MeshError, match="f: N has 2 rows but V has 3; expected one normal per vertex"):
        as_unit_vectors(N, 3, "f")
    with pytest.raises(MeshError, match="f: N has 2 rows but delta has 3"):
        as_unit_vectors(N, 3, "f", ref="delta")
    with pytest.raises(MeshError, match=r"f: N_hi row 1 is the zero vector \(1 zero rows\)"):
        as_unit_vectors([[0, 0, 1.0], [0, 0, 0]], 2, "f", name="N_hi")


def test_package_exposes_its_api_lazily_with_a_version():
    assert geomlib.__version__.count(".") >= 1
    assert geomlib.MeshError is geomlib.validate.MeshError
    assert geomlib.halfedge_mesh is geomlib.topology.halfedge_mesh
    assert "check_mesh" in dir(geomlib)
    with pytest.raises(AttributeError, match="no attribute 'no_such_thing'"):
        geomlib.no_such_thing  # noqa: B018
    code = "import sys, geomlib; print(sorted(m for m in sys.modules if m.startswith('geomlib')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "['geomlib']"  # nothing is imported before it is used
