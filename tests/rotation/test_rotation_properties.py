"""q ≡ −q: every rotation function that reads an attitude gives the same answer for q and −q.

Negation is exact in IEEE arithmetic and each formula below is even in q (products
of two components, ``|w|``, norms) or odd where its output is a quaternion, so the
answers are compared bit for bit. The one exception is a 180° rotation with
``w == 0`` exactly: there ``rotvec_from_quat`` cannot tell q from −q and returns
``±π u`` — the same rotation, checked as such.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from strapdown import rotation as R
from strategies import batch_shapes, rotvecs, sign_masks, unit_quaternions


def _pairs():
    """(p, q, sp, sq): two quaternion batches of one shape and a ±1 mask for each."""
    return batch_shapes().flatmap(lambda s: st.tuples(
        unit_quaternions(s), unit_quaternions(s), sign_masks(s), sign_masks(s)))


def _flip(q, s):
    return q * s[..., None]


def _not_a_half_turn(w):
    """Rows whose ``w`` is a normal number: the functions first scale their quaternions by
    a power of two (a largest component in [0.5, 1): by 1/2 for a unit one with a component
    ±1, 1/4 for a product of two), so a subnormal ``w`` may become 0 there — a half turn —
    and the sign of the logarithm is then a convention (a run found w = 5e-324 → 0)."""
    return np.abs(w) >= np.finfo(float).tiny


def _half_turns_agree(a, b):
    """At ``w == 0`` the logarithm of q and of −q are ``±π u``: each row of ``a`` is the row
    of ``b`` or its negative, exactly, and has length π (to the rounding of scale·v)."""
    same = np.all(a == b, axis=-1) | np.all(a == -b, axis=-1)
    half_turn = np.abs(np.linalg.norm(a, axis=-1) - np.pi) <= 2 * np.spacing(np.pi)
    return bool(np.all(same & half_turn))


@given(_pairs())
def test_dcm_and_derived_angles_ignore_the_sign(case):
    _, q, _, s = case
    mq = _flip(q, s)
    assert np.array_equal(R.dcm_from_quat(mq), R.dcm_from_quat(q))
    assert np.array_equal(R.quat_canonical(mq), R.quat_canonical(q))
    v = np.broadcast_to(np.array([0.3, -1.2, 2.0]), (*q.shape[:-1], 3))
    assert np.array_equal(R.quat_rotate(mq, v), R.quat_rotate(q, v))
    for a, b in zip(R.cone_angles_from_quat(mq), R.cone_angles_from_quat(q), strict=True):
        assert np.array_equal(a, b)


@given(_pairs())
def test_rotvec_from_quat_ignores_the_sign(case):
    _, q, _, s = case
    a = R.rotvec_from_quat(_flip(q, s))
    b = R.rotvec_from_quat(q)
    generic = _not_a_half_turn(q[..., 0])
    assert np.array_equal(a[generic], b[generic])
    assert _half_turns_agree(a[~generic], b[~generic])
    # principal: |φ| ≤ π up to the roundings of scale·v and of its norm taken again
    # (nextafter(π) seen at w = 0; a run found more at w = 6e-17, as in the test above)
    assert np.all(np.linalg.norm(a, axis=-1) <= np.pi * (1.0 + 4.0 * np.finfo(float).eps))


@given(_pairs())
def test_error_functions_ignore_the_sign_of_either_argument(case):
    p, q, sp, sq = case
    mp, mq = _flip(p, sp), _flip(q, sq)
    ang = R.attitude_error_angle(p, q)
    assert np.array_equal(R.attitude_error_angle(mp, mq), ang)
    assert np.all((ang >= 0.0) & (ang <= np.pi))
    dq = R.attitude_error_quat(p, q)
    assert np.array_equal(R.attitude_error_quat(mp, mq), _flip(dq, sp * sq))
    a = R.attitude_error_vector(mp, mq)
    b = R.attitude_error_vector(p, q)
    generic = _not_a_half_turn(dq[..., 0])
    assert np.array_equal(a[generic], b[generic])
    assert _half_turns_agree(a[~generic], b[~generic])


@given(_pairs())
def test_q_against_minus_q_is_no_error(case):
    # q ⊗ (±q)* = ±[1, 0, 0, 0] up to the rounding of its vector part (sums such as
    # −c + d + c − d are not exactly 0), so the error is round-off, never ~2π
    _, q, _, s = case
    assert np.all(R.attitude_error_angle(_flip(q, s), q) <= 1e-15)
    assert np.all(np.linalg.norm(R.attitude_error_vector(_flip(q, s), q), axis=-1) <= 1e-15)


@settings(max_examples=40)
@given(rotvecs(max_angle=2 * np.pi), st.sampled_from([1.0, -1.0]))
def test_exp_of_phi_beyond_pi_is_the_principal_rotation(phi, sign):
    # |φ| ∈ (π, 2π] gives w < 0; the logarithm must return the principal vector of the same
    # rotation, i.e. of q and of −q alike. Its angle 2 atan2(|v|, |w|) is at most π; the
    # vector (angle/|v|) v and the norm taken of it again add a few roundings (a fresh
    # clone's hypothesis run found |back| = π + 2 ulp; 1 ulp was allowed before)
    q = sign * R.quat_from_rotvec(phi)
    back = R.rotvec_from_quat(q)
    assert np.all(np.linalg.norm(back, axis=-1) <= np.pi * (1.0 + 4.0 * np.finfo(float).eps))
    assert np.allclose(R.dcm_from_rotvec(back), R.dcm_from_rotvec(phi), rtol=0, atol=2e-15)
