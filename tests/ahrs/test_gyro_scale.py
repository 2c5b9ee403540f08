"""An uncalibrated gyro: the suite's spinning body (1.5 Hz about a near-vertical axis) with
scale-factor and cross-axis errors drawn with standard deviations of 1 % and 0.5 % (seed 6:
−1.4 % on the spin axis, 7.7 °/s of heading drift that the gyro model without heading rate
noise cannot follow); the swinging 0.3 m pendulum with the same errors.

- :func:`offline_ekf` runs its passes again with the causal filter's heading rate noise when
  its forward pass's gate rejects most of an undisturbed field
  (:func:`strapdown.ahrs.filter._clean_field_rejected`, ``HEADING_ESCAPED_SHARE``);
- ``AhrsConfig.gyro_scale_sigma`` (off by default) lets the bias follow the scale error of a
  sustained rotation."""

from __future__ import annotations

import dataclasses
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
from strapdown.ahrs.filter import HEADING_ESCAPED_SHARE, _clean_field_rejected, _pass_config
from strapdown.ahrs.flags import MeasurementFlag as F
from strapdown.analysis.broad import broad_errors
from strapdown.truth.scenarios import record, suite

SEED = 6
ON = AhrsConfig(gyro_scale_sigma=0.01)


def _recording(kind: str, scale_sd: float = 0.01, seed: int = SEED):
    k, sc = next((i, s) for i, s in enumerate(suite(seed)) if s.kind == kind)
    sc = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, gyro_scale_sd=scale_sd, gyro_misalignment_sd=scale_sd / 2))
    return record(sc, np.random.SeedSequence([seed, k]))


def _total(result, rec) -> float:
    return broad_errors(result.q, rec.q_n_b, rec.t >= 5.0)["total_deg"]


@pytest.fixture(scope="module")
def spin():
    """The spinning body with the 1 % error: the recording, the causal filter without and
    with the floor, the offline filter, and the offline filter without the rerun's rule
    (no heading rate noise to fall back on)."""
    rec = _recording("spin-coning")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return SimpleNamespace(
            rec=rec, causal=ekf(rec.t, rec.gyro, rec.acc, rec.mag),
            causal_on=ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=ON),
            offline=offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag),
            no_rule=offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag,
                                config=AhrsConfig(heading_rate_noise=0.0,
                                                  offline_heading_rate_noise=0.0)))


def test_the_bias_follows_the_scale_error_of_the_spin_and_holds_the_heading(spin):
    """Without the floor the heading lags the drift by 15°; with it the bias learns the
    spin's scale error (2.4°, most of it while the averaged rate builds up)."""
    rec, off, on = spin.rec, spin.causal, spin.causal_on
    assert _total(off, rec) > 12.0
    assert _total(on, rec) < 3.0


def test_the_learned_bias_is_the_scale_error_times_the_spin(spin):
    """Over the last ten seconds the x bias (the spin axis) is the true bias plus the
    first row of M − I times the mean rate, within 10 % of that scale part."""
    rec, on = spin.rec, spin.causal_on
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


# --- offline_ekf's rerun when the heading escaped its covariance


def test_the_drawn_scale_error_drifts_the_heading_by_degrees_per_second(spin):
    rec = spin.rec
    spin = np.abs(rec.gyro[rec.t > 5.0, 0]).mean()
    drift = np.degrees(abs(rec.gyro_matrix[0, 0] - 1.0) * spin)
    assert 6.0 < drift < 9.0


def test_offline_passes_rerun_with_the_rate_noise_and_beat_the_causal_filter(spin):
    """With the rule, offline is better than causal (5–8° against 10–15° over seeds);
    its result's config says the passes used the causal heading rate noise."""
    rec, causal, offline = spin.rec, spin.causal, spin.offline
    assert offline.config.offline_heading_rate_noise == AhrsConfig().heading_rate_noise
    assert _total(offline, rec) < 0.8 * _total(causal, rec)
    assert _total(offline, rec) < 12.0


def test_the_rerun_sees_through_the_adapted_heading_variance():
    """Seed 18: the widened heading variance (``mag_adapt_s``) lets part of the
    contradicting field through the gate, so the forward pass rejects less than a quarter
    of the clean field while its heading runs away; counted against the unadapted variance
    (``Outputs.mag_nis0``) the share is over it and the passes run again (43.5° without
    that count, 4.5° with it)."""
    rec = _recording("spin-coning", seed=18)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag)
        fwd = ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=_pass_config(AhrsConfig()))
    assert _clean_field_rejected(fwd.flags) < HEADING_ESCAPED_SHARE  # rejections alone
    assert out.config.offline_heading_rate_noise == AhrsConfig().heading_rate_noise
    assert _total(out, rec) < 6.0


def test_without_the_rule_the_offline_heading_runs_away(spin):
    """The failure the rule exists for: with no heading rate noise to fall back on (the rule
    then does not apply), the offline passes lose the field and their heading runs away."""
    rec, no_rule = spin.rec, spin.no_rule
    assert no_rule.config.offline_heading_rate_noise == 0.0
    assert _total(no_rule, rec) > 45.0


def test_a_calibrated_gyro_keeps_the_offline_passes_as_they_were():
    rec = _recording("spin-coning", 0.0)
    out = offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag)
    assert out.config.offline_heading_rate_noise == AhrsConfig().offline_heading_rate_noise
    assert _clean_field_rejected(out.flags) < 0.05
    assert _total(out, rec) < 0.5


def test_clean_field_rejected_counts_only_undisturbed_field_epochs():
    used, rej, dist = int(F.MAG_USED), int(F.MAG_REJECTED), int(F.MAG_DISTURBED)
    flags = np.array([0, used, used, rej, rej | dist, dist, rej, 0])
    assert _clean_field_rejected(flags) == pytest.approx(2 / 4)
    assert _clean_field_rejected(np.array([0, dist, rej | dist])) == 0.0
    # an update the gate let through only at the widened variance counts; no NIS (NaN) or
    # one within the gate does not
    nis0 = np.array([np.nan, 9.0, 1.0, np.nan, 9.0, 9.0, np.nan, np.nan])
    assert _clean_field_rejected(flags, nis0, 4.0) == pytest.approx(3 / 4)
    assert _clean_field_rejected(flags, nis0, 10.0) == pytest.approx(2 / 4)
    assert 0.0 < HEADING_ESCAPED_SHARE < 1.0
