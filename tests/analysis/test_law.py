"""The measured/law judgement: the round-off floor, the statuses, and what they claim.

Each status is checked against what it asserts: "below float64 floor" — mpmath resolves
the drift the float64 run could not; "higher order in a dominates" — mpmath measures the
same drift (so it is not round-off), and a smaller half angle brings the ratio to 1.
"""

from __future__ import annotations

import math

import pytest

from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.analysis.law import (
    BELOW_FLOOR,
    FLOOR_FACTOR,
    GYRO_ERRORS,
    HIGHER_ORDER,
    RESOLVED,
    judge_law,
    roundoff_floor,
)
from strapdown.truth.sensors import GyroErrors

EPS = 2.0**-52


def test_floor_formula_and_bad_input():
    a, T, n = math.radians(1.0), 20.0, 12_000
    assert roundoff_floor(a, T, n) == pytest.approx(FLOOR_FACTOR * a**2 * EPS * math.sqrt(n) / T,
                                                    rel=1e-15)
    assert roundoff_floor(a, T, n, digits=30) == pytest.approx(
        FLOOR_FACTOR * a**2 * 1e-29 * math.sqrt(n) / T, rel=1e-12)
    with pytest.raises(ValueError, match="duration must be positive"):
        roundoff_floor(a, 0.0, n)
    with pytest.raises(ValueError, match="updates must be at least 1"):
        roundoff_floor(a, T, 0)


@pytest.mark.parametrize(("measured", "predicted", "status"), [
    (-0.9997e-12, -1e-12, RESOLVED),       # law far above the floor, ratio ≈ 1
    (3.5e-17, -9e-18, HIGHER_ORDER),       # measured resolved, ratio −3.9
    (1e-20, 1e-12, HIGHER_ORDER),          # law resolved but absent from the measurement
    (1.9e-19, -4.2e-25, BELOW_FLOOR),      # both below the floor (~1.5e-18 here)
    (5e-19, 4.9e-19, BELOW_FLOOR),         # ratio ≈ 1 by chance: still not resolved
])
def test_statuses(measured, predicted, status):
    res = judge_law(measured, predicted, half_angle=math.radians(1.0), duration=20.0,
                    updates=12_000)
    assert res.status == status
    assert res.ratio == measured / predicted
    assert (res.note == "") == (status == RESOLVED)


def test_no_ratio_and_gyro_errors():
    kw = dict(half_angle=0.01, duration=2.0, updates=100)
    assert judge_law(None, 1e-12, **kw).status is None
    assert judge_law(1e-12, None, **kw).status is None
    assert judge_law(math.nan, 1e-12, **kw).status is None
    assert judge_law(1e-12, 1e-12, ideal_gyro=False, **kw).status == GYRO_ERRORS


def _law(**kw):
    return evaluate(EvaluationConfig.of(**kw)).to_dict()


def test_resolved_law_in_float64():
    d = _law(sample_rate_hz=600.0, duration=20.0, subsamples=2)
    assert d["law_status"] == RESOLVED and d["law_note"] is None
    assert d["measured_over_law"] == pytest.approx(1.0, abs=1e-3)
    assert d["measured_over_law"] == d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"]


def test_below_floor_is_resolved_by_precision():
    cfg = dict(algorithm="rk4", sample_rate_hz=10_000.0, duration=2.0)
    d = _law(**cfg)
    assert d["law_status"] == BELOW_FLOOR
    assert "--precision" in d["law_note"]
    mp = _law(**cfg, precision=30)
    assert mp["law_status"] == RESOLVED
    assert mp["measured_over_law"] == pytest.approx(1.0, abs=1e-3)


def test_higher_order_is_real_and_shrinks_with_the_half_angle():
    """The README's first command: measured/law −3.84 is the a⁴ terms, not round-off."""
    cfg = dict(sample_rate_hz=600.0, duration=20.0, subsamples=3, structure="realtime")
    d = _law(**cfg)
    assert d["law_status"] == HIGHER_ORDER
    assert d["measured_over_law"] == pytest.approx(-3.84, abs=0.01)
    assert "--half-angle-deg" in d["law_note"]
    mp = _law(**cfg, precision=25)  # the same drift in 25 digits: it is not round-off
    assert mp["cone_axis_drift_rad_s"] == pytest.approx(d["cone_axis_drift_rad_s"], rel=1e-3)
    small = _law(**cfg, half_angle_deg=0.01)  # a⁴/a² falls as a²: the law takes over
    assert small["law_status"] == RESOLVED
    assert small["measured_over_law"] == pytest.approx(1.0, abs=1e-2)


@pytest.mark.parametrize("cfg", [
    dict(algorithm="rate-single", half_angle_deg=10.0, sample_rate_hz=2000.0, duration=2.0),
    dict(subsamples=3, structure="realtime", half_angle_deg=3.0, sample_rate_hz=1000.0,
         duration=3.0),
    dict(algorithm="rk4", half_angle_deg=20.0, sample_rate_hz=1000.0, duration=3.0),
])
def test_floor_bounds_the_float64_roundoff(cfg):
    """|float64 − mpmath| of the cone-axis drift stays below the floor (the calibration)."""
    d, mp = _law(**cfg), _law(**cfg, precision=25)
    assert abs(d["cone_axis_drift_rad_s"] - mp["cone_axis_drift_rad_s"]) < d["law_floor_rad_s"]


def test_noisy_gyro_is_flagged():
    d = evaluate(EvaluationConfig.of(sample_rate_hz=600.0, duration=4.0, subsamples=2,
                                     gyro=GyroErrors(white_noise=1e-5), seed=3)).to_dict()
    assert d["law_status"] == GYRO_ERRORS
