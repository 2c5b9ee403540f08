"""Analysis helpers: drift estimation, predictions, update periods."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.analysis import accuracy as A
from strapdown.truth.motions import ClassicalConing


def test_drift_at_whole_periods_removes_periodic_part_exactly():
    p = 0.5
    t = np.arange(0, 2001) * (p / 100)
    e = 3e-9 + 2e-12 * t + 1e-6 * np.sin(2 * np.pi * t / p + 0.3)
    d = A.drift_rate(t, e, period=p)
    assert d.method == "whole-periods" and d.points == 21
    assert d.rate == pytest.approx(2e-12, rel=1e-6)
    # without the period, the periodic part biases the slope
    biased = A.drift_rate(t, e)
    assert biased.method == "all-samples"
    assert abs(biased.rate - 2e-12) > 1e-10


def test_drift_falls_back_when_no_whole_periods():
    t = np.linspace(0, 0.3, 31)
    d = A.drift_rate(t, np.c_[t, 2 * t, -t], period=1.0)
    assert d.method == "all-samples"
    assert np.allclose(d.rate, [1, 2, -1])


def test_chain_drift_each_chain_at_own_phase():
    p, n = 1.0, 3
    t = np.arange(0, 601) / 120
    chain = np.arange(t.size) % n
    e = 5e-10 * t + 1e-7 * np.cos(2 * np.pi * t / p) + 1e-8 * chain  # per-chain offsets
    out = A.chain_drift_rate(t, e, chain, period=p)
    assert len(out) == 3
    assert all(d.method == "whole-periods" for d in out)
    assert np.allclose([d.rate for d in out], 5e-10, rtol=1e-6)


def test_table1_prediction_sign_and_value():
    v = A.table1_prediction(0.01, 2.0, 1e-3, 2)
    assert v == pytest.approx(-(0.01**2) * 2.0 * (2e-3) ** 4 / 60)


def test_update_period_and_rotation_per_update():
    assert A.update_period("conventional", 4, 1e-4) == pytest.approx(4e-4)
    assert A.update_period("realtime", 4, 1e-4) == 1e-4
    assert math.degrees(A.rotation_per_update(math.radians(9000), "conventional", 5, 1e-4)) == \
        pytest.approx(4.5)
    with pytest.raises(ValueError, match="unknown structure"):
        A.update_period("fancy", 2, 1e-3)


def test_attitude_errors_against_truth():
    m = ClassicalConing(0.1, 1.0)
    t = np.linspace(0, 1, 5)
    err, ang = A.attitude_errors(t, m.attitude(t), m)
    assert np.all(ang <= 1e-15) and np.all(np.abs(err) <= 1e-15)
    with pytest.raises(ValueError, match="match t"):
        A.attitude_errors(t, m.attitude(t)[:3], m)


@pytest.mark.parametrize(
    ("call", "msg"),
    [
        (lambda: A.drift_rate([0.0, 0.0, 1.0], [1.0, 2.0, 3.0]), "strictly increasing"),
        (lambda: A.drift_rate([0.0], [1.0]), "at least 2"),
        (lambda: A.drift_rate([0.0, 1.0], [[1.0, 2.0, 3.0]]), "2 rows"),
        (lambda: A.drift_rate([0.0, np.nan], [1.0, 2.0]), "NaN"),
        (lambda: A.table1_prediction(0.1, 1.0, 0.0, 2), "positive"),
        (lambda: A.table1_prediction(np.nan, 1.0, 1e-3, 2), "NaN"),
        (lambda: A.rotation_per_update(np.nan, "realtime", 2, 1e-3), "NaN"),
        (lambda: A.chain_drift_rate([0.0, 1.0, 2.0], [1.0, 2.0, 3.0], [0, 1]), "match t"),
        (lambda: A.integrate_attitude_ode(ClassicalConing(0.1, 1.0), [0, 1], rtol=1e-6),
         "rtol"),
    ],
)
def test_bad_input(call, msg):
    with pytest.raises(ValueError, match=msg):
        call()
