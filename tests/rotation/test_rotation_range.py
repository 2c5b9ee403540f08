"""Rotation functions across the whole float64 range (issue 16): norms taken after an exact
power-of-two scaling, so 1e308-rad rotation vectors and quaternions scaled to 1e300 or
1e-320 give the right attitude, and no branch of a np.where overflows. References are
closed forms evaluated in mpmath; unit inputs are unchanged to the bit (scaling by 2⁰)."""

from __future__ import annotations

import math
import warnings

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from strapdown.rotation import (
    attitude_error_angle,
    dcm_from_quat,
    dcm_from_rotvec,
    quat_from_rotvec,
    quat_normalize,
    quat_rotate,
    rotvec_from_quat,
    scipy_from_quat,
)


@pytest.fixture(autouse=True)
def _no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an overflow in either branch of a np.where fails
        yield


def test_exponential_map_of_a_1e308_rad_rotation_vector():
    q = quat_from_rotvec([1e308, 0.0, 0.0])
    with mp.workprec(2000):  # exact argument reduction of 5e307
        half = mp.mpf(1e308) / 2
        ref = [float(mp.cos(half)), float(mp.sin(half))]
    assert q[0] == pytest.approx(ref[0], abs=1e-15) and q[1] == pytest.approx(ref[1], abs=1e-15)
    assert q[2] == q[3] == 0.0 and abs(np.linalg.norm(q) - 1.0) < 1e-15
    # |φ| = √3·1e308 is not a float: the attitude is that of the float norm (one ulp is
    # 2e292 rad), so check the structure: unit, equal components, w² + 3s² = 1
    diag = quat_from_rotvec([1e308, 1e308, 1e308])
    assert abs(np.linalg.norm(diag) - 1.0) < 1e-15 and diag[1] == diag[2] == diag[3]


def test_logarithm_of_huge_and_tiny_quaternions_is_120_degrees():
    for scale in (1e300, 1.0, 1e-160, 1e-300, 1e-320):
        phi = rotvec_from_quat([scale] * 4)
        assert np.linalg.norm(phi) == pytest.approx(2 * math.pi / 3, rel=1e-15), scale
        assert np.allclose(phi / np.linalg.norm(phi), np.full(3, 3 ** -0.5), rtol=1e-15)


def test_normalising_huge_and_tiny_quaternions():
    for scale in (1e300, 1e-160, 1e-300):
        assert np.allclose(quat_normalize(np.array([3.0, 4.0, 0.0, 0.0]) * scale),
                           [0.6, 0.8, 0.0, 0.0], rtol=1e-15, atol=0)
        assert np.allclose(dcm_from_quat(np.array([1.0, 0.0, 0.0, 1.0]) * scale),
                           [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=3e-16)
    sub = quat_normalize([5e-324, 0.0, 0.0, 0.0])  # the smallest subnormal is not zero
    assert np.array_equal(sub, [1.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="zero quaternion"):
        quat_normalize([0.0, 0.0, 0.0, 0.0])


def test_tiny_w_takes_no_branch_that_overflows():
    assert np.allclose(rotvec_from_quat([1e-320, 1.0, 0.0, 0.0]), [math.pi, 0, 0], rtol=1e-15)
    assert np.allclose(rotvec_from_quat([0.0, 0.0, 1.0, 0.0]), [0, math.pi, 0], rtol=1e-15)
    assert np.array_equal(rotvec_from_quat([1.0, 1e-300, 0.0, 0.0]), [2e-300, 0.0, 0.0])


def test_rotation_matrix_of_a_huge_rotation_vector_matches_the_quaternion():
    phi = np.array([[1e200, -3e199, 2e199], [0.0, 0.0, 0.0], [0.3, 0.2, 0.1]])
    assert np.allclose(dcm_from_rotvec(phi), dcm_from_quat(quat_from_rotvec(phi)), atol=1e-14)


def test_errors_rotation_and_scipy_of_scaled_quaternions():
    q = np.array([1.0, 0.0, 0.0, 1.0])
    assert attitude_error_angle(q * 1e300, q * 1e-300) == 0.0
    assert attitude_error_angle(np.array([1.0, 1.0, 0, 0]) * 1e200, [1.0, 0, 0, 0]) == (
        pytest.approx(math.pi / 2, rel=1e-15))
    assert np.allclose(quat_rotate(q * 1e300, [1e308, 0.0, 0.0]), [0.0, 1e308, 0.0],
                       rtol=1e-15, atol=1e293)
    assert np.allclose(scipy_from_quat(np.full(4, 1e300)).as_rotvec(),
                       np.full(3, 2 * math.pi / 3 / math.sqrt(3)), rtol=1e-15)


_unit = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda v: 0.1 < sum(x * x for x in v)).map(lambda v: np.array(v) / np.linalg.norm(v))


@given(q=_unit, k=st.integers(-1070, 1020))
def test_power_of_two_scale_changes_nothing(q, k):
    s = math.ldexp(1.0, k)
    qs = q * s
    if not np.array_equal(qs / s, q):  # under- or overflow on input: digits are lost
        # the largest component (≥ 1/2) keeps k + 1073 bits down at the subnormal floor
        # (2⁻¹⁰⁷⁴): the normalised quaternion is good to a few units of the last one kept
        # (k = −1067 keeps 6 bits; 1e-3, the tolerance once used here, needs 10)
        bits = min(k + 1073, 52)
        assert np.allclose(quat_normalize(qs), q, atol=max(1e-3, 2.0 ** (2 - bits)))
        return
    assert np.array_equal(quat_normalize(qs), quat_normalize(q))
    assert np.array_equal(rotvec_from_quat(qs), rotvec_from_quat(q))
    assert np.array_equal(dcm_from_quat(qs), dcm_from_quat(q))


@given(phi=st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array),
       k=st.integers(-300, 300))
def test_exponential_map_is_a_unit_quaternion_for_any_magnitude(phi, k):
    q = quat_from_rotvec(phi * 10.0**k)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-14
