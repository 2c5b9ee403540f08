"""The offline filter on an uncalibrated gyro: when its forward pass's gate rejects most of
an undisturbed field, its passes run again with the causal filter's heading rate noise
(:func:`strapdown.ahrs.filter._clean_field_rejected`, ``HEADING_ESCAPED_SHARE``).

The case is the suite's spin-coning body (1.5 Hz spin about a near-vertical axis) with a
gyro whose scale-factor and cross-axis errors are drawn with standard deviations of 1 % and
0.5 % (``Sensors.gyro_scale_sd``): seed 6 draws −1.4 % on the spin axis, a heading drift of
7.7 °/s that the gyro model without heading rate noise cannot follow."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
from strapdown.ahrs.filter import HEADING_ESCAPED_SHARE, _clean_field_rejected
from strapdown.ahrs.flags import MeasurementFlag as F
from strapdown.analysis.broad import broad_errors
from strapdown.truth.scenarios import record, suite

SEED = 6


def _spin(scale_sd: float):
    k, sc = next((i, s) for i, s in enumerate(suite(SEED)) if s.kind == "spin-coning")
    sc = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, gyro_scale_sd=scale_sd, gyro_misalignment_sd=scale_sd / 2))
    return record(sc, np.random.SeedSequence([SEED, k]))


def _total(result, rec) -> float:
    return broad_errors(result.q, rec.q_n_b, rec.t >= 5.0)["total_deg"]


@pytest.fixture(scope="module")
def uncalibrated():
    rec = _spin(0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return (rec, ekf(rec.t, rec.gyro, rec.acc, rec.mag),
                offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag),
                offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag,
                            config=AhrsConfig(heading_rate_noise=0.0)))


def test_the_drawn_scale_error_drifts_the_heading_by_degrees_per_second(uncalibrated):
    rec = uncalibrated[0]
    spin = np.abs(rec.gyro[rec.t > 5.0, 0]).mean()
    drift = np.degrees(abs(rec.gyro_matrix[0, 0] - 1.0) * spin)
    assert 6.0 < drift < 9.0


def test_offline_passes_rerun_with_the_rate_noise_and_beat_the_causal_filter(uncalibrated):
    """With the rule, offline is better than causal (5–8° against 10–15° over seeds);
    its result's config says the passes used the causal heading rate noise."""
    rec, causal, offline, _ = uncalibrated
    assert offline.config.offline_heading_rate_noise == AhrsConfig().heading_rate_noise
    assert _total(offline, rec) < 0.8 * _total(causal, rec)
    assert _total(offline, rec) < 12.0


def test_without_the_rule_the_offline_heading_runs_away(uncalibrated):
    """The failure the rule exists for: with no heading rate noise to fall back on (the rule
    then does not apply), the offline passes lose the field and their heading runs away."""
    rec, _, _, no_rule = uncalibrated
    assert no_rule.config.offline_heading_rate_noise == 0.0
    assert _total(no_rule, rec) > 45.0


def test_a_calibrated_gyro_keeps_the_offline_passes_as_they_were():
    rec = _spin(0.0)
    out = offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag)
    assert out.config.offline_heading_rate_noise == 0.0
    assert _clean_field_rejected(out.flags) < 0.05
    assert _total(out, rec) < 0.5


def test_clean_field_rejected_counts_only_undisturbed_field_epochs():
    used, rej, dist = int(F.MAG_USED), int(F.MAG_REJECTED), int(F.MAG_DISTURBED)
    flags = np.array([0, used, used, rej, rej | dist, dist, rej, 0])
    assert _clean_field_rejected(flags) == pytest.approx(2 / 4)
    assert _clean_field_rejected(np.array([0, dist, rej | dist])) == 0.0
    assert 0.0 < HEADING_ESCAPED_SHARE < 1.0
