"""Rotation identities across batch shapes, near 0 and near π, and agreement with scipy."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from scipy.spatial.transform import Rotation

from conftest import quat_close
from strapdown import rotation as R
from strategies import rotvecs


@given(rotvecs())
def test_quat_from_rotvec_is_unit_and_round_trips(phi):
    q = R.quat_from_rotvec(phi)
    assert q.shape == (*phi.shape[:-1], 4)
    assert np.allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-15, rtol=0)
    back = R.rotvec_from_quat(q)
    ang = np.linalg.norm(phi, axis=-1, keepdims=True)
    # relative accuracy at small angles, absolute near π
    assert np.all(np.abs(back - phi) <= 4e-16 * np.maximum(ang, 1e-300) + 2e-15 * (ang > 1))


def test_exponential_map_exact_at_tiny_and_large_angles():
    for angle in (1e-20, 1e-8, 3.1):
        phi = np.array([angle, 0.0, 0.0])
        q = R.quat_from_rotvec(phi)
        assert q[0] == pytest.approx(np.cos(angle / 2), rel=1e-16, abs=0)
        assert q[1] == pytest.approx(np.sin(angle / 2), rel=2e-16, abs=0)
        assert R.rotvec_from_quat(q)[0] == pytest.approx(angle, rel=2e-16)
    assert np.array_equal(R.quat_from_rotvec(np.zeros(3)), [1.0, 0, 0, 0])


@given(rotvecs())
def test_q_and_minus_q_give_same_rotation(phi):
    q = R.quat_from_rotvec(phi)
    assert np.allclose(R.dcm_from_quat(q), R.dcm_from_quat(-q), atol=1e-15)
    assert np.allclose(R.rotvec_from_quat(-q), R.rotvec_from_quat(q), atol=1e-15)
    assert np.all(R.attitude_error_angle(q, -q) <= 1e-15)


@given(rotvecs())
def test_group_laws(a):
    b = np.roll(a, 1, axis=-1) * 0.7  # a second batch of the same shape
    p = R.quat_from_rotvec(a)
    q = R.quat_from_rotvec(b)
    # inverse, associativity, homomorphism to DCMs
    ident = R.quat_multiply(p, R.quat_conjugate(p))
    assert quat_close(ident, [1.0, 0, 0, 0], 1e-15)
    r = R.quat_from_rotvec(a[..., ::-1] * 0.5)
    assert np.allclose(R.quat_multiply(R.quat_multiply(p, q), r),
                       R.quat_multiply(p, R.quat_multiply(q, r)), atol=1e-15)
    assert np.allclose(R.dcm_from_quat(R.quat_multiply(p, q)),
                       R.dcm_from_quat(p) @ R.dcm_from_quat(q), atol=2e-15)


@given(rotvecs())
def test_dcm_forms_agree_and_are_orthonormal(phi):
    c1 = R.dcm_from_rotvec(phi)
    c2 = R.dcm_from_quat(R.quat_from_rotvec(phi))
    assert np.allclose(c1, c2, atol=2e-15)
    eye = np.broadcast_to(np.eye(3), c1.shape)
    assert np.allclose(c1 @ np.swapaxes(c1, -1, -2), eye, atol=2e-15)
    assert np.allclose(np.linalg.det(c1), 1.0, atol=2e-15)


@given(rotvecs())
def test_dcm_quat_round_trip(phi):
    q = R.quat_from_rotvec(phi)
    assert quat_close(R.quat_from_dcm(R.dcm_from_quat(q)), q, 2e-15)


@given(rotvecs())
def test_rotate_matches_dcm(phi):
    q = R.quat_from_rotvec(phi)
    v = np.broadcast_to(np.array([0.3, -1.2, 2.0]), phi.shape)
    assert np.allclose(R.quat_rotate(q, v), np.einsum("...ij,...j->...i", R.dcm_from_quat(q), v),
                       atol=5e-15)


@given(rotvecs())
def test_agreement_with_scipy(phi):
    flat = phi.reshape(-1, 3)
    q = R.quat_from_rotvec(flat)
    rot = Rotation.from_rotvec(flat)
    assert quat_close(q, rot.as_quat(scalar_first=True), 1e-14)
    assert np.allclose(R.dcm_from_quat(q), rot.as_matrix(), atol=1e-14)
    assert quat_close(R.quat_from_scipy(R.scipy_from_quat(q)), q, 1e-14)
    assert np.allclose(R.quat_from_dcm(rot.as_matrix()), R.quat_canonical(q), atol=1e-14)


@given(rotvecs(), rotvecs())
def test_error_vector_is_log_of_relative_rotation(a, b):
    b = b.reshape(-1, 3)[: int(np.prod(a.shape[:-1]) or 1)]
    a = a.reshape(-1, 3)[: b.shape[0]]
    qe = R.quat_from_rotvec(a)
    qt = R.quat_from_rotvec(b)
    err = R.attitude_error_vector(qe, qt)
    # exp(err) ⊗ q_true == q_est
    assert quat_close(R.quat_multiply(R.quat_from_rotvec(err), qt), qe, 3e-15)
    ang = R.attitude_error_angle(qe, qt)
    assert np.allclose(np.linalg.norm(err, axis=-1), ang, atol=2e-15)


def test_small_error_angle_resolution():
    q = R.quat_from_rotvec([0.4, -0.2, 1.1])
    tiny = R.quat_multiply(R.quat_from_rotvec([3e-17, 0, 0]), q)
    assert R.attitude_error_angle(tiny, q) < 1e-15


def test_skew_is_cross_product():
    v = np.array([[1.0, 2.0, 3.0], [-0.5, 0.1, 4.0]])
    u = np.array([[0.3, -2.0, 1.0], [1.0, 1.0, 1.0]])
    assert np.allclose(R.skew(v) @ u[..., None], np.cross(v, u)[..., None])


def test_f2_has_no_cancellation():
    f1, f2 = R.f1_f2(np.array([1e-9, 1e-4, 2.0]))
    assert f2[0] == pytest.approx(0.5, rel=1e-16)
    assert f2[1] == pytest.approx(0.5 - 1e-8 / 24, rel=1e-15)
    assert f2[2] == pytest.approx((1 - np.cos(2.0)) / 4.0, rel=1e-15)
    assert f1[2] == pytest.approx(np.sin(2.0) / 2.0, rel=1e-15)


def test_canonical_picks_positive_scalar():
    q = np.array([[-0.5, 0.5, 0.5, 0.5], [0.0, -1.0, 0.0, 0.0]])
    c = R.quat_canonical(q)
    assert np.array_equal(c, [[0.5, -0.5, -0.5, -0.5], [0.0, 1.0, 0.0, 0.0]])


@pytest.mark.parametrize(
    ("fn", "arg", "msg"),
    [
        (R.quat_from_rotvec, np.zeros((2, 4)), r"shape \(\.\.\., 3\)"),
        (R.rotvec_from_quat, np.zeros(3), r"shape \(\.\.\., 4\)"),
        (R.rotvec_from_quat, np.zeros(4), "zero quaternion"),
        (R.quat_from_rotvec, [np.nan, 0, 0], "NaN"),
        (R.dcm_from_quat, [1, 0, np.inf, 0], "NaN or infinity"),
        (R.quat_from_dcm, np.eye(4), r"shape \(\.\.\., 3, 3\)"),
        (R.quat_from_scipy, np.eye(3), "scipy Rotation"),
        (R.scipy_from_quat, np.ones((2, 2, 4)), r"\(n, 4\)"),
        (R.quat_from_rotvec, "abc", "numeric"),
    ],
)
def test_bad_input_names_the_problem(fn, arg, msg):
    with pytest.raises(ValueError, match=msg):
        fn(arg)
