"""geomlib.portable: elementary functions built from IEEE-754 operations only, close to NumPy's.

That they give the same bits on another CPU is checked where it matters, on every case's inputs
(tests/solutions/test_deterministic.py, against an emulated other machine); here: accuracy against
NumPy on wide samples, and the special values the generators rely on.
"""

from __future__ import annotations

import numpy as np
import pytest

from geomlib import portable


def ulps(got, want) -> float:
    """Largest difference in units of the last place of ``want`` (at least that of 1e-300)."""
    got, want = np.asarray(got), np.asarray(want)
    return float(np.max(np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))))


@pytest.fixture(scope="module")
def rng():
    return np.random.default_rng(24)


def test_sin_cos_tan_are_within_a_few_ulps_of_numpy(rng):
    x = np.r_[rng.uniform(-400, 400, 100_000), np.linspace(-7, 7, 10_001)]
    # Absolute error: near a zero of sin the relative error of any reduction by pi/2 grows.
    assert np.abs(portable.sin(x) - np.sin(x)).max() <= 4e-16
    assert np.abs(portable.cos(x) - np.cos(x)).max() <= 4e-16
    small = rng.uniform(-1.5, 1.5, 100_000)
    assert ulps(portable.tan(small), np.tan(small)) <= 4
    assert ulps(portable.sin(small), np.sin(small)) <= 2
    assert ulps(portable.cos(small), np.cos(small)) <= 2


def test_exp_is_within_two_ulps_of_numpy_and_saturates(rng):
    x = np.r_[rng.uniform(-740, 709, 100_000), rng.uniform(-2, 2, 100_000)]
    assert ulps(portable.exp(x), np.exp(x)) <= 2
    got = portable.exp([0.0, 1.0, -1000.0, 1000.0, np.nan, -np.inf])
    assert got[0] == 1.0 and abs(got[1] - np.e) <= np.spacing(np.e)
    assert got[2] == 0.0 and got[3] == np.inf and np.isnan(got[4]) and got[5] == 0.0


def test_arctan2_is_within_a_few_ulps_of_numpy_in_every_quadrant(rng):
    y, x = rng.normal(size=(2, 100_000)) * 10.0 ** rng.uniform(-4, 4, (2, 100_000))
    assert ulps(portable.arctan2(y, x), np.arctan2(y, x)) <= 6
    axes_y, axes_x = [0.0, 1.0, 0.0, -1.0, 1.0, -1.0, 0.0], [1.0, 0.0, -1.0, 0.0, -1.0, -1.0, 0.0]
    np.testing.assert_allclose(portable.arctan2(axes_y, axes_x), np.arctan2(axes_y, axes_x), rtol=1e-15, atol=0)


def test_dot_norm_hypot_and_matmul_agree_with_numpy(rng):
    A, B, v = rng.normal(size=(7, 4)), rng.normal(size=(4, 3)), rng.normal(size=4)
    np.testing.assert_allclose(portable.matmul(A, B), A @ B, rtol=0, atol=1e-14)
    np.testing.assert_allclose(portable.matmul(A, v), A @ v, rtol=0, atol=1e-14)
    np.testing.assert_allclose(portable.dot(A, A[::-1], axis=1), np.einsum("ij,ij->i", A, A[::-1]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(portable.dot(A, v), A @ v, rtol=0, atol=1e-14)  # broadcast
    np.testing.assert_allclose(portable.dot(A, A, axis=0), np.einsum("ij,ij->j", A, A), rtol=0, atol=1e-14)
    # Index order from the first product (not from +0.0): a single -0.0 product keeps its sign.
    assert np.signbit(portable.dot([-0.0], [1.0])) and np.signbit(portable.dot([-0.0, 0.0], [1.0, -1.0]))
    np.testing.assert_allclose(portable.norm(A, axis=1), np.linalg.norm(A, axis=1), rtol=1e-15)
    assert portable.norm([3.0, 4.0]) == 5.0 and isinstance(portable.norm(v), float)
    np.testing.assert_allclose(portable.hypot(A[:, 0], A[:, 1]), np.hypot(A[:, 0], A[:, 1]), rtol=1e-15)
    with pytest.raises(ValueError, match="do not multiply"):
        portable.matmul(A, A)
    with pytest.raises(ValueError, match="4 and 3 terms"):
        portable.dot(A, B, axis=1)


def test_integer_multiples_of_quarter_turns_are_exact_where_the_meshes_need_it():
    # The torus and sphere seams rely on equal inputs giving equal outputs; sin 0 and cos 0 exact.
    assert portable.sin(0.0) == 0.0 and portable.cos(0.0) == 1.0 and portable.exp(0.0) == 1.0
    t = 2 * np.pi * (np.arange(97) % 48) / 48
    assert np.array_equal(portable.cos(t[:48]), portable.cos(t[48:96]))
