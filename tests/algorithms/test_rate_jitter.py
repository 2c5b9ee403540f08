"""Jittered time stamps: the nominal period, the jitter seen, the grid and resampling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.rate import (
    JITTER_TOLERANCE,
    check_rate_record,
    rate_attitude,
    resample_uniform,
)
from strapdown.truth.motions import SpinConing

T = 1e-3
N = 2001
MOTION = SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(720.0))


def _jittered(amplitude: float, seed: int = 7) -> np.ndarray:
    """Stamps k·T + e_k, e_k uniform in ±amplitude·T (independent per stamp)."""
    rng = np.random.default_rng(seed)
    return np.arange(N) * T + rng.uniform(-amplitude, amplitude, N) * T


def test_uniform_stamps_are_used_as_given():
    t = np.arange(N) / 1000.0
    w = MOTION.rate(t)
    rec = check_rate_record(t, w)
    assert rec.t is t and rec.stamps is None and not rec.resampled
    assert rec.td == (t[-1] - t[0]) / (N - 1)  # today's estimate, bit for bit
    assert rec.jitter < 1e-9


def test_jittered_stamps_give_the_nominal_period_and_the_jitter():
    t = _jittered(0.005)
    rec = check_rate_record(t, MOTION.rate(t))
    # least squares over 2001 stamps: σ_e √12 / n^1.5 ≈ 1e-10 of T; the median interval
    # would be off by ~1e-4 of T
    assert rec.td == pytest.approx(T, rel=1e-7)
    assert 0.004 < rec.jitter <= 0.0055  # the stamps' ±0.5 % about the fitted grid
    assert np.array_equal(rec.stamps, t)
    assert np.array_equal(rec.t, t[0] + np.arange(N) * rec.td)
    assert np.array_equal(rec.omega, MOTION.rate(t))  # not resampled: taken to lie on the grid


def test_stamps_beyond_the_tolerance_are_non_uniform():
    t = np.arange(50) * T
    t[20:] += 0.3 * T  # a step of 0.3 periods between samples 20 and 21 (1-based)
    with pytest.raises(ValueError, match="non-uniform sampling between samples 20 and 21"):
        check_rate_record(t, np.zeros((50, 3)))
    assert JITTER_TOLERANCE == 0.1
    t = _jittered(0.09)
    assert check_rate_record(t, np.zeros((N, 3))).jitter < JITTER_TOLERANCE
    with pytest.raises(ValueError, match=r"jitter tolerance 0\.05 period"):
        check_rate_record(t, np.zeros((N, 3)), jitter_tolerance=0.05)


def test_given_period_is_used_and_checked_against_the_stamps():
    t = _jittered(0.005)
    rec = check_rate_record(t, np.zeros((N, 3)), td=1e-3)
    assert rec.td == 1e-3 and np.array_equal(rec.t, t[0] + np.arange(N) * 1e-3)
    # 1 % off: after 2000 samples the stamps are 20 periods from the given grid
    with pytest.raises(ValueError, match=r"not at the given sample period 0\.00101 s"):
        check_rate_record(t, np.zeros((N, 3)), td=1.01e-3)
    with pytest.raises(ValueError, match="positive and finite"):
        check_rate_record(t, np.zeros((N, 3)), td=0.0)


def test_resampling_interpolates_onto_the_grid_ending_at_the_last_stamp():
    t = _jittered(0.005)
    rec = check_rate_record(t, MOTION.rate(t), resample=True)
    assert rec.resampled and rec.t[-1] <= t[-1] and rec.t.size >= N - 1
    assert np.array_equal(rec.t, t[0] + np.arange(rec.t.size) * rec.td)
    # the rates at the grid: the cubic spline's error is δ·T³·|ω⁗|/12 ~ 4e-13 rad/s here
    assert np.max(np.abs(rec.omega - MOTION.rate(rec.t))) < 2e-12


def test_resample_reproduces_a_cubic_exactly():
    t = np.sort(np.random.default_rng(3).uniform(0.0, 1.0, 40))
    f = np.column_stack([1 + 2 * t - t**2 + 0.5 * t**3, t**3, -t])
    g = np.linspace(t[0], t[-1], 17)
    ref = np.column_stack([1 + 2 * g - g**2 + 0.5 * g**3, g**3, -g])
    assert np.allclose(resample_uniform(t, f, g), ref, rtol=0, atol=1e-13)


@pytest.mark.parametrize("algorithm", ["rate-single", "rate-three", "rk4"])
def test_library_runs_accept_jitter_on_the_nominal_grid(algorithm):
    t = _jittered(0.005)
    sol = rate_attitude(t, MOTION.rate(t), algorithm=algorithm, q0=MOTION.attitude(0.0))
    td = check_rate_record(t, MOTION.rate(t)).td
    stride = round((sol.t[1] - sol.t[0]) / td)
    assert np.allclose(sol.t, t[0] + np.arange(sol.t.size) * stride * td, rtol=0, atol=1e-15)
