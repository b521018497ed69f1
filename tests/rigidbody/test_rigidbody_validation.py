"""Validation of rigid-body inputs (dirac.rigidbody.inertia): errors name the value and
the fix; the triangle-inequality warning (docs/conventions.md) is issued once and is not fatal."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dirac.errors import DiracWarning, InputError
from dirac.rigidbody.inertia import validate_inertia, validate_momentum, validate_rotation


def test_valid_inertia_is_returned_as_float_array_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = validate_inertia([1, 2, 2.5])
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [1.0, 2.0, 2.5])


@pytest.mark.parametrize(
    "bad, fragment",
    [
        ([1.0, 2.0], "shape"),
        ([1.0, 0.0, 1.0], "non-positive"),
        ([1.0, -2.0, 1.5], "non-positive"),
        ([1.0, float("nan"), 1.0], "non-finite"),
        ([1.0, float("inf"), 1.0], "non-finite"),
        (["a", 1.0, 1.0], "not numeric"),
    ],
)
def test_bad_inertia_raises_input_error_naming_it(bad, fragment):
    with pytest.raises(InputError, match=fragment) as info:
        validate_inertia(bad)
    assert "inertia" in str(info.value)


def test_triangle_inequality_violation_warns_once_and_continues():
    # the standard test case: I = (2, 1, 2/3) has 1 + 2/3 < 2 -- no physical body.
    with pytest.warns(DiracWarning, match="triangle inequality") as record:
        out = validate_inertia([2.0, 1.0, 2.0 / 3.0])
    assert len(record) == 1
    assert "no physical body" in str(record[0].message)
    np.testing.assert_allclose(out, [2.0, 1.0, 2.0 / 3.0])


def test_plane_body_equality_is_physical_and_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        validate_inertia([1.0, 2.0, 3.0])  # I1 + I2 = I3: a plane body


def test_rotation_accepts_a_proper_rotation():
    c, s = np.cos(0.3), np.sin(0.3)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_array_equal(validate_rotation(R), R)


def test_rotation_rejects_left_handed_matrix():
    with pytest.raises(InputError, match="left-handed.*det R = -1"):
        validate_rotation(np.diag([1.0, 1.0, -1.0]))


def test_rotation_rejects_non_orthogonal_matrix_and_says_how_far_off():
    R = np.eye(3)
    R[0, 1] = 1e-6
    with pytest.raises(InputError, match=r"not orthogonal: max \|R\^T R - 1\| = 1e-06"):
        validate_rotation(R)


def test_rotation_rejects_wrong_shape_and_nan():
    with pytest.raises(InputError, match="shape"):
        validate_rotation(np.eye(2))
    R = np.eye(3)
    R[2, 2] = np.nan
    with pytest.raises(InputError, match="non-finite"):
        validate_rotation(R)


def test_momentum_validation():
    np.testing.assert_array_equal(validate_momentum([1, 2, 3]), [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="M has shape"):
        validate_momentum([1.0, 2.0, 3.0, 4.0])
    with pytest.raises(InputError, match="non-finite"):
        validate_momentum([1.0, np.inf, 0.0])
