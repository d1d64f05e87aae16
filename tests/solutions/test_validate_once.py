"""Public entries validate their mesh once; internal calls receive the checked arrays (issue 25, item 4).

A validation is counted where ``check_mesh`` really checks: its call of ``as_faces`` (a pass-through
of arrays already checked by ``validate.checked`` does not get there).
"""

from __future__ import annotations

import numpy as np
import pytest

import geomlib.validate as validate
from geomlib import datasets
from geomlib.validate import MeshError


@pytest.fixture
def count_validations(monkeypatch):
    calls = []
    real = validate.as_faces

    def counting(*args, **kwargs):
        calls.append(kwargs.get("where"))
        return real(*args, **kwargs)

    monkeypatch.setattr(validate, "as_faces", counting)
    return calls


@pytest.mark.parametrize("method", ["greedy", "fast"])
@pytest.mark.parametrize("mesh", ["closed", "open"])
def test_qem_simplify_validates_once(count_validations, method, mesh):
    from solutions.simplification import qem_simplify

    V, F = datasets.icosphere(2) if mesh == "closed" else datasets.height_field(8)
    U, G = qem_simplify(V, F, len(F) // 2, method=method)
    assert len(G) <= len(F) // 2
    assert count_validations == ["qem_simplify"], f"qem_simplify validated its mesh in {count_validations}"


@pytest.mark.parametrize("sign", ["pseudonormal", "vote", "normal", "winding"])
def test_signed_distance_validates_once(count_validations, sign):
    from solutions.sdf import signed_distance

    V, F = datasets.icosphere(2)
    d = signed_distance(V, F, [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], sign=sign)
    assert d[0] < 0 < d[1]
    assert count_validations == ["signed_distance"], f"signed_distance validated its mesh in {count_validations}"


def test_sdf_grid_validates_once(count_validations):
    from solutions.sdf import sdf_grid

    sdf_grid(*datasets.icosphere(1), 4)
    assert count_validations == ["sdf_grid"], f"sdf_grid validated its mesh in {count_validations}"


def test_checked_arrays_do_not_leak_out_of_the_call():
    """After a public call, its internal helpers validate again: the pass-through ends with the call."""
    from solutions.simplification import qem_simplify
    from solutions.simplification.quadrics import vertex_quadrics

    V, F = datasets.icosphere(1)
    qem_simplify(V, F, 40, method="fast")
    F_bad = F.copy()
    F_bad[0, 0] = len(V)
    with pytest.raises(MeshError, match="vertex_quadrics"):
        vertex_quadrics(V, F_bad)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda f: f(np.zeros((4, 3)), [[0, 1, 9]], 4), "qem_simplify"),
        (lambda f: f([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], 4), "qem_simplify"),
    ],
)
def test_qem_simplify_bad_input_named(call, message):
    from solutions.simplification import qem_simplify

    with pytest.raises(MeshError, match=message):
        call(qem_simplify)
