"""Drift predicted from the cross-spectrum of the body rates against simulated pseudo-coning
with exact truth (tone vibration, 20 seeds)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.analysis.accuracy import attitude_errors
from strapdown.analysis.spectrum import (
    coning_kernel,
    coning_spectrum,
    cross_spectra,
    predict_drift,
    predict_drift_lines,
)
from strapdown.truth import sensors
from strapdown.truth.vibration import ToneVibration, random_tone_vibration

FS = 200.0
H = 1 / FS
N = 4000
SPECS = ["rotvec:N=1", "rotvec:N=2", "rotvec:N=3:structure=single-chain", "rate-single", "rk4"]
AMP, REL = (2e-3, 5e-3, 5e-3), (0.3, 1.2, 0.0)  # per axis x, y, z: the chosen cross-spectrum


def _drift(spec, motion, inc, t, rates):
    if spec.input_kind == "increment":
        sol = spec.run_increments(inc, h=H, q0=motion.attitude(0.0))
    else:
        sol = spec.run_rates(t, rates, q0=motion.attitude(0.0))
    err, _ = attitude_errors(sol.t, sol.q, motion)
    k = sol.startup
    return np.polyfit(sol.t[k:], err[k:], 1)[0]


@pytest.fixture(scope="module")
def measured():
    out = {s: [] for s in SPECS}
    vib = None
    for seed in range(20):
        vib = random_tone_vibration((4.0, 24.0), 6, AMP, REL, np.random.default_rng(seed))
        motion = vib.motion()
        inc = sensors.increments(motion, H, N).data
        t = np.arange(N + 1) * H
        rates = motion.rate(t)
        for s in SPECS:
            out[s].append(_drift(AlgorithmSpec.parse(s), motion, inc, t, rates))
    return vib, rates, {s: np.mean(v, axis=0) for s, v in out.items()}


@pytest.mark.parametrize("text", SPECS)
def test_line_spectrum_prediction_is_the_mean_measured_drift(measured, text):
    vib, _, mean = measured
    pred = predict_drift_lines(AlgorithmSpec.parse(text), vib.omega, vib.coning_power(), H)
    assert np.all(np.abs(mean[text] / pred - 1) < 0.02)  # every axis, 2 %


@pytest.mark.parametrize("text", SPECS)
def test_welch_estimate_from_the_gyro_log_predicts_the_same(measured, text):
    vib, rates, mean = measured
    f, g = cross_spectra(rates, FS, nperseg=512)
    pred = predict_drift(AlgorithmSpec.parse(text), f, g, H)
    assert np.all(np.abs(mean[text] / pred - 1) < 0.02)
    assert np.trapezoid(coning_spectrum(g), f, axis=0) == pytest.approx(
        vib.coning_power().sum(axis=0), rel=0.02)


def test_kernel_is_table1_at_small_omega_h():
    spec = AlgorithmSpec.parse("rotvec:N=2")
    w = np.array([1.0, 2.0])
    k = coning_kernel(spec, w, 1e-3)
    assert np.allclose(k, -2 * (w * 1e-3) ** 4 / 60 / w, rtol=1e-5)


def test_bad_input():
    spec = AlgorithmSpec.parse("rotvec:N=2")
    with pytest.raises(ValueError, match="Nyquist"):
        coning_kernel(spec, [4000.0], 1e-3)
    with pytest.raises(ValueError, match=r"\(n ≥ 16, 3\)"):
        cross_spectra(np.zeros((10, 3)), 100.0)
    with pytest.raises(ValueError, match="shape"):
        ToneVibration(np.array([1.0]), np.zeros((2, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="one entry per spectral bin"):
        predict_drift(spec, [1.0, 2.0, 3.0], np.zeros((2, 3, 3)), 1e-3)


def test_vibration_rate_is_the_attitudes_derivative():
    vib = random_tone_vibration((1.0, 3.0), 3, (0.3, 0.2, 0.4), (0.0, 1.0, 2.0),
                                np.random.default_rng(1))
    t, dt = 0.37, 1e-6
    q0, q1 = vib.attitude(t - dt), vib.attitude(t + dt)
    w, x, y, z = q0
    qd = (q1 - q0) / (2 * dt)
    # ω_b = 2 vec(q* ⊗ q̇)
    wb = 2 * np.array([w * qd[1] - x * qd[0] - y * qd[3] + z * qd[2],
                       w * qd[2] + x * qd[3] - y * qd[0] - z * qd[1],
                       w * qd[3] - x * qd[2] + y * qd[1] - z * qd[0]])
    assert np.allclose(vib.rate(t), wb, atol=1e-8)
    assert math.isclose(np.linalg.norm(vib.attitude(t)), 1.0, rel_tol=1e-15)
