"""``AhrsConfig.gyro_scale_sigma``: an uncalibrated gyro on a body that keeps turning one
way. The suite's spinning body (1.5 Hz about a near-vertical axis) with scale-factor and
cross-axis errors drawn with standard deviations of 1 % and 0.5 % (seed 6: −1.4 % on the
spin axis, 7.7 °/s of heading drift); the swinging 0.3 m pendulum with the same errors."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
from strapdown.analysis.broad import broad_errors
from strapdown.truth.scenarios import record, suite

SEED = 6
ON = AhrsConfig(gyro_scale_sigma=0.01)


def _recording(kind: str, scale_sd: float = 0.01):
    k, sc = next((i, s) for i, s in enumerate(suite(SEED)) if s.kind == kind)
    sc = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, gyro_scale_sd=scale_sd, gyro_misalignment_sd=scale_sd / 2))
    return record(sc, np.random.SeedSequence([SEED, k]))


def _total(result, rec) -> float:
    return broad_errors(result.q, rec.q_n_b, rec.t >= 5.0)["total_deg"]


@pytest.fixture(scope="module")
def spin():
    rec = _recording("spin-coning")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rec, ekf(rec.t, rec.gyro, rec.acc, rec.mag), ekf(rec.t, rec.gyro, rec.acc,
                                                                  rec.mag, config=ON)


def test_the_bias_follows_the_scale_error_of_the_spin_and_holds_the_heading(spin):
    """Without the floor the heading lags the drift by 15°; with it the bias learns the
    spin's scale error (2.4°, most of it while the averaged rate builds up)."""
    rec, off, on = spin
    assert _total(off, rec) > 12.0
    assert _total(on, rec) < 3.0


def test_the_learned_bias_is_the_scale_error_times_the_spin(spin):
    """Over the last ten seconds the x bias (the spin axis) is the true bias plus the
    first row of M − I times the mean rate, within 10 % of that scale part."""
    rec, _, on = spin
    last = rec.t > rec.t[-1] - 10.0
    w = rec.gyro[last].mean(axis=0)  # ≈ M ω: the scale part is (M − I) ω to first order
    expected = rec.gyro_bias[last, 0].mean() + (rec.gyro_matrix[0] - np.eye(3)[0]) @ w
    scale_part = expected - rec.gyro_bias[last, 0].mean()
    assert abs(scale_part) > np.radians(5.0)
    assert on.gyro_bias[last, 0].mean() == pytest.approx(expected, abs=0.1 * abs(scale_part))


def test_offline_too():
    """A 2 % error: the offline passes run away without the floor (94°), 5.5° with it."""
    rec = _recording("spin-coning", 0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert _total(offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag), rec) > 45.0
        assert _total(offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=ON), rec) < 7.0


def test_a_swing_averages_out_of_the_rate_and_keeps_its_accuracy():
    """A pendulum's rate averages to zero over gyro_scale_tau: the floor hardly moves."""
    rec = _recording("pendulum")
    base = _total(ekf(rec.t, rec.gyro, rec.acc, rec.mag), rec)
    assert _total(ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=ON), rec) < 1.2 * base


def test_options_are_checked():
    with pytest.raises(ValueError, match="gyro_scale_sigma"):
        AhrsConfig(gyro_scale_sigma=-0.01)
    with pytest.raises(ValueError, match="gyro_scale_tau"):
        AhrsConfig(gyro_scale_tau=0.0)
