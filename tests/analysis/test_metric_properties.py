"""q ≡ −q: the analysis metrics give the same answer for an estimate q and for −q.

``attitude_errors`` and ``accumulated_drift`` are even in each quaternion (negation is
exact), so they are compared bit for bit (the error vector at ``w == 0`` exactly is
``±π u``, see tests/rotation/test_rotation_properties.py). BROAD's metrics go through the
twist angle ``2 atan2(z, w)``, which moves by 2π under the sign change, so its sine,
cosine and wrapped heading are rounded from a different argument: equal to 1e-12°.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from strapdown import rotation as R
from strapdown.analysis import accumulated_drift, attitude_errors
from strapdown.analysis.broad import broad_errors
from strapdown.truth.motions import ClassicalConing
from strategies import batch_shapes, rotvecs, sign_masks, unit_quaternions

_F = {"allow_nan": False, "allow_infinity": False}


def _flip(q, s):
    return q * s[..., None]


@st.composite
def _estimates_against_coning(draw):
    """(t, q_est, motion, signs): truth ⊗ exp(δφ), δφ tiny, generic, near or beyond π."""
    n = draw(st.integers(1, 12))
    motion = ClassicalConing(draw(st.floats(1e-6, 1.5, **_F)),
                             draw(st.sampled_from([1.0, -1.0])) * draw(st.floats(0.1, 20.0, **_F)))
    t = np.arange(n) * draw(st.floats(1e-4, 0.5, **_F)) + draw(st.floats(-10.0, 10.0, **_F))
    assume(np.all(np.diff(t) > 0))
    dphi = draw(rotvecs((n,), max_angle=2 * math.pi))
    q_est = R.quat_multiply(motion.attitude(t), R.quat_from_rotvec(dphi))
    return t, q_est, motion, draw(sign_masks((n,)))


@given(_estimates_against_coning())
def test_attitude_errors_ignore_the_sign_of_the_estimate(case):
    t, q, motion, s = case
    err, ang = attitude_errors(t, q, motion)
    err_m, ang_m = attitude_errors(t, _flip(q, s), motion)
    assert np.array_equal(ang_m, ang)
    generic = R.attitude_error_quat(q, motion.attitude(t))[:, 0] != 0.0
    assert np.array_equal(err_m[generic], err[generic])
    a, b = err_m[~generic], err[~generic]  # w == 0: ±π u, the same half turn
    assert np.all(np.all(a == b, axis=-1) | np.all(a == -b, axis=-1))


@given(batch_shapes().flatmap(lambda s: st.tuples(unit_quaternions(s), unit_quaternions(s),
                                                    sign_masks(s), sign_masks(s))))
def test_accumulated_drift_ignores_the_signs(case):
    p, q, sp, sq = case
    assert np.array_equal(accumulated_drift(_flip(p, sp), _flip(q, sq)), accumulated_drift(p, q))


@st.composite
def _broad_case(draw):
    n = draw(st.integers(1, 10))
    q_ref = draw(unit_quaternions((n,)))
    q_est = R.quat_multiply(draw(unit_quaternions((n,))), q_ref)
    movement = np.array(draw(st.lists(st.booleans(), min_size=n, max_size=n)))
    assume(movement.any())
    return q_est, q_ref, movement, draw(sign_masks((n,))), draw(sign_masks((n,)))


def _resultant(q_est, q_ref, movement):
    """Length of the mean heading-error phasor: the heading offset is defined when it is > 0."""
    dq = R.quat_multiply(q_est[movement], R.quat_conjugate(q_ref[movement]))
    psi = 2.0 * np.arctan2(dq[:, 3], dq[:, 0])
    return math.hypot(np.mean(np.sin(psi)), np.mean(np.cos(psi)))


@given(_broad_case(), st.booleans())
def test_broad_errors_ignore_the_signs(case, heading_offset):
    q_est, q_ref, movement, se, sr = case
    if heading_offset:  # a phasor mean of ~0 leaves the offset undefined (any answer is right)
        assume(_resultant(q_est, q_ref, movement) > 1e-6)
    a = broad_errors(q_est, q_ref, movement, remove_heading_offset=heading_offset)
    b = broad_errors(_flip(q_est, se), _flip(q_ref, sr), movement,
                     remove_heading_offset=heading_offset)
    assert a.keys() == b.keys() and a["samples"] == b["samples"]
    for k in ("total_deg", "heading_deg", "inclination_deg", "total_offset_removed_deg",
              "heading_offset_removed_deg", "inclination_offset_removed_deg"):
        assert abs(a.get(k, 0.0) - b.get(k, 0.0)) <= 1e-12, k
    if heading_offset:
        d_off = (a["heading_offset_deg"] - b["heading_offset_deg"] + 180.0) % 360.0 - 180.0
        assert abs(d_off) <= 1e-12
