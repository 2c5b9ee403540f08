"""The aligned error metric: the fit finds a known world and body rotation, and the RMSE left
is the error that was injected.

Construction: a reference ``q_ref`` whose samples come in equal pairs, a known ``q_W`` and
``q_B``, and an error ``e_k`` in the estimate's world frame, ``q_est = e ⊗ q_W ⊗ q_ref ⊗ q_B``,
with ``e`` and ``e*`` on the two samples of each pair. The chordal cost's gradient then
vanishes at the true ``q_W``, ``q_B`` (each pair's residuals cancel), so the least-squares fit
must return them, and the error left is ``e_k`` itself: its angle (total), its twist about
the vertical (heading) and its tilt (inclination) are known by construction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import quat_close
from strapdown.analysis.alignment import (
    AlignmentWarning,
    aligned_errors,
    fit_alignment,
)
from strapdown.rotation.quaternion import quat_from_rotvec, quat_multiply
from strategies import unit_quaternions


def _random_quats(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1)[:, None]


def _case(rng, q_w, q_b, n_pairs=300, tilt=0.03, heading=0.05, ref=None):
    """``(q_est, q_ref, expected)``: pairs of equal reference samples, errors ±φ about x
    (tilt) on the first half of the pairs and about z (heading) on the second."""
    ref = _random_quats(rng, n_pairs) if ref is None else ref
    q_ref = np.repeat(ref, 2, axis=0)
    half = n_pairs // 2
    ang = np.concatenate([tilt * (0.5 + rng.random(half)), heading * (0.5 + rng.random(
        n_pairs - half))])
    axis = np.zeros((n_pairs, 3))
    axis[:half, 0] = 1.0
    axis[half:, 2] = 1.0
    phi = np.repeat(ang[:, None] * axis, 2, axis=0) * np.tile([1.0, -1.0], n_pairs)[:, None]
    q_est = quat_multiply(quat_from_rotvec(phi), quat_multiply(quat_multiply(q_w, q_ref), q_b))
    rms = lambda a: math.degrees(math.sqrt(np.sum(a**2) / (2 * n_pairs)))  # noqa: E731
    expected = {"total_deg": rms(np.repeat(ang, 2)),
                "inclination_deg": rms(np.repeat(ang[:half], 2)),
                "heading_deg": rms(np.repeat(ang[half:], 2))}
    return q_est, q_ref, expected


Q_W = quat_from_rotvec([0.4, -1.9, 0.7])
Q_B = quat_from_rotvec([-2.2, 0.3, 1.1])


def test_fit_recovers_the_rotations_and_the_injected_error():
    q_est, q_ref, expected = _case(np.random.default_rng(1), Q_W, Q_B)
    fit = fit_alignment(q_est, q_ref)
    assert fit.converged
    assert quat_close(fit.q_world, Q_W, 1e-9) and quat_close(fit.q_body, Q_B, 1e-9)
    e = aligned_errors(q_est, q_ref)
    for key, value in expected.items():
        assert e[key] == pytest.approx(value, abs=1e-9), key
    assert e["samples"] == q_ref.shape[0] and e["total_deg"] > 2.0  # an error, not noise


def test_the_mask_selects_the_fitted_and_scored_samples():
    """Samples outside the mask (here 90° off, as a filter's start-up) change nothing."""
    rng = np.random.default_rng(2)
    q_est, q_ref, expected = _case(rng, Q_W, Q_B)
    junk = _random_quats(rng, 50)
    q_est = np.concatenate([junk, q_est])
    q_ref = np.concatenate([_random_quats(rng, 50), q_ref])
    mask = np.arange(q_ref.shape[0]) >= 50
    fit = fit_alignment(q_est, q_ref, mask)
    assert quat_close(fit.q_world, Q_W, 1e-9) and quat_close(fit.q_body, Q_B, 1e-9)
    e = aligned_errors(q_est, q_ref, mask)
    assert e["samples"] == q_ref.shape[0] - 50
    assert e["total_deg"] == pytest.approx(expected["total_deg"], abs=1e-9)
    assert aligned_errors(q_est, q_ref)["total_deg"] > 10 * expected["total_deg"]


def test_every_sign_flip_gives_the_same_fit_and_errors():
    rng = np.random.default_rng(3)
    q_est, q_ref, _ = _case(rng, Q_W, Q_B)
    base = aligned_errors(q_est, q_ref)
    fit = fit_alignment(q_est, q_ref)
    s_est = np.where(rng.random(q_est.shape[0]) < 0.5, -1.0, 1.0)[:, None]
    s_ref = np.where(rng.random(q_est.shape[0]) < 0.5, -1.0, 1.0)[:, None]
    flipped = aligned_errors(s_est * q_est, s_ref * q_ref)
    for key in ("total_deg", "heading_deg", "inclination_deg"):
        assert flipped[key] == pytest.approx(base[key], abs=1e-10), key
    fit2 = fit_alignment(s_est * q_est, s_ref * q_ref)
    assert quat_close(fit2.q_world, fit.q_world, 1e-10)
    assert quat_close(fit2.q_body, fit.q_body, 1e-10)


def test_a_reference_turning_about_one_axis_still_gives_the_injected_error():
    """Then q_B about the axis trades for q_W at no cost (the OpenAXES carpus link turns
    about one axis): the fitted attitudes, not the two rotations, are determined."""
    rng = np.random.default_rng(4)
    ref = quat_from_rotvec(np.linspace(0.0, 0.6, 200)[:, None] * np.array([0.0, 0.6, 0.8]))
    q_est, q_ref, expected = _case(rng, Q_W, Q_B, n_pairs=200, ref=ref)
    fit = fit_alignment(q_est, q_ref)
    assert fit.converged
    fitted = quat_multiply(quat_multiply(fit.q_world, q_ref), fit.q_body)
    truth = quat_multiply(quat_multiply(Q_W, q_ref), Q_B)
    assert quat_close(fitted, truth, 1e-9)
    e = aligned_errors(q_est, q_ref)
    for key, value in expected.items():
        assert e[key] == pytest.approx(value, abs=1e-9), key


@settings(max_examples=25)
@given(q_w=unit_quaternions(()), q_b=unit_quaternions(()), seed=st.integers(0, 2**32 - 1),
       tilt=st.floats(0.0, 0.2), heading=st.floats(0.0, 0.2))
def test_fit_recovers_any_world_and_body_rotation(q_w, q_b, seed, tilt, heading):
    q_est, q_ref, expected = _case(np.random.default_rng(seed), q_w, q_b, n_pairs=60,
                                   tilt=tilt, heading=heading)
    fit = fit_alignment(q_est, q_ref)
    assert fit.converged
    assert quat_close(fit.q_world, q_w, 1e-9) and quat_close(fit.q_body, q_b, 1e-9)
    e = aligned_errors(q_est, q_ref)
    for key, value in expected.items():  # within the rotations' 1e-9 (an angle of 2e-9 rad):
        # an error part that is zero in truth (hypothesis tries heading = 0) is the RMS of
        # that residual, not its square (2.1e-8 deg seen; 1e-8 failed on seed 5637211)
        assert e[key] == pytest.approx(value, abs=float(np.degrees(2e-9))), key


def test_the_fit_stops_on_its_tolerance_and_warns_when_it_cannot():
    q_est, q_ref, _ = _case(np.random.default_rng(5), Q_W, Q_B)
    with pytest.warns(AlignmentWarning, match="1 Newton steps"):
        fit = fit_alignment(q_est, q_ref, tol=0.0, max_iter=1)
    assert not fit.converged and fit.iterations == 1


def test_bad_input_is_refused():
    q = np.tile([1.0, 0.0, 0.0, 0.0], (10, 1))
    with pytest.raises(ValueError, match=r"\(n, 4\)"):
        aligned_errors(q, q[:9])
    with pytest.raises(ValueError, match="at least 2"):
        aligned_errors(q, q, np.arange(10) == 3)
    bad = q.copy()
    bad[4] = np.nan
    with pytest.raises(ValueError, match="not finite at sample 4"):
        aligned_errors(bad, q)
    ref = q.copy()
    ref[4] = np.nan  # a lost reference sample is skipped, as in BROAD's metric
    assert aligned_errors(q, ref)["samples"] == 9
