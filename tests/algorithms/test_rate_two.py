"""rate-two, the designer's two-period rate algorithm: a family added in one module
(algorithms/rate.py) shows up in the registry, evaluate, the filter and export-c."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.design import classical_coning_drift, derive, rate_structure
from strapdown.truth import sensors
from strapdown.truth.motions import SpinConing


def test_coefficients_and_law_are_the_designers():
    alg = derive(rate_structure(2)).algorithm()
    w = AlgorithmSpec("rate-two").family.windowed(AlgorithmSpec("rate-two"))
    assert (w.offsets, w.weights, w.pairs, w.pair_coefficients) == (
        alg.offsets, alg.weights, alg.pairs, alg.pair_coefficients)
    law = AlgorithmSpec("rate-two").drift_law()
    assert (law.order, law.constant) == classical_coning_drift(rate_structure(2),
                                                               alg.pair_coefficients)


@pytest.mark.parametrize("spp", [120, 60])
def test_measured_drift_follows_the_law_in_arbitrary_precision(spp):
    d = evaluate(EvaluationConfig.of(algorithm="rate-two", sample_rate_hz=spp, duration=4.0,
                                     precision=40, half_angle_deg=0.01)).to_dict()
    assert d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"] == pytest.approx(1, abs=2e-3)


def test_facts_and_registry():
    s = AlgorithmSpec.parse("rate-two")
    assert "rate-two" in REGISTRY and s.input_kind == "rate"
    assert (s.min_samples, s.update_period(1e-3)) == (3, 2e-3)
    with pytest.raises(ValueError, match="supports the structures"):
        AlgorithmSpec.parse("rate-two:structure=sliding")
    with pytest.raises(ValueError, match="takes coefficients derived"):
        AlgorithmSpec.parse("rate-two:coefficients=paper")


def test_float64_run_against_exact_truth():
    m = SpinConing(math.radians(1.0), 2 * math.pi * 2, math.radians(360.0))
    h = 1e-3
    rec = sensors.rate_samples(m, h, 2001)
    sol = AlgorithmSpec.parse("rate-two").run(rec, q0=m.attitude(0.0))
    from strapdown.analysis import attitude_errors

    _, ang = attitude_errors(sol.t, sol.q, m)
    assert sol.t.size == 1001 and np.max(ang) < 1e-8


def test_the_filter_propagates_with_it():
    from strapdown.ahrs import ekf

    n = 400
    t = np.arange(n) / 100.0
    res = ekf(t, np.zeros((n, 3)), np.tile([0.0, 0.0, 9.80665], (n, 1)),
              np.tile([0.0, 20.0, -40.0], (n, 1)), algorithm="rate-two")
    assert np.all(np.isfinite(res.q))


def test_exported_c_matches_the_library(tmp_path):
    from c_harness import build, drive

    h = 1e-4
    t = np.arange(2001) * h
    m = SpinConing(math.radians(2.0), 2 * math.pi * 5, math.radians(3600.0))
    w = m.rate(t)
    q0 = m.attitude(0.0)
    e, lib = build(tmp_path, algorithm="rate-two", h=h)
    c = drive(e, lib, w, q0)
    py = AlgorithmSpec.parse("rate-two").run_rates(t, w, q0=q0).q
    assert c.shape == py.shape
    assert np.max(np.abs(c - py)) <= 1e-13
