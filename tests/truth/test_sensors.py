"""Gyro models: ideal output, seeded error models, pre-averaging (Li & Zhang eq. 11)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.truth import sensors as S
from strapdown.truth.motions import ClassicalConing, PureSpin

CONE = ClassicalConing(math.radians(1.0), 2 * math.pi)


def test_ideal_increments_are_exact():
    rec = S.increments(CONE, 1e-3, 50, t0=0.2)
    assert rec.kind == "increment" and rec.data.shape == (50, 3) and rec.t.shape == (51,)
    assert np.array_equal(rec.data, CONE.increments(rec.t))


def test_rate_samples_at_sample_times():
    rec = S.rate_samples(CONE, 1e-2, 10)
    assert np.allclose(rec.data, CONE.rate(np.arange(10) * 1e-2))


def test_same_seed_same_bytes_and_generator_accepted():
    e = S.GyroErrors(white_noise=1e-3, gm_sigma=1e-4, gm_tau=5.0)
    a = S.increments(CONE, 1e-3, 200, errors=e, rng=7).data
    b = S.increments(CONE, 1e-3, 200, errors=e, rng=np.random.default_rng(7)).data
    c = S.increments(CONE, 1e-3, 200, errors=e, rng=8).data
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)


def test_white_noise_statistics():
    sd = 2e-3  # rad/s/√Hz
    h = 1e-3
    e = S.GyroErrors(white_noise=sd)
    rec = S.increments(PureSpin(0.0), h, 200_000, errors=e, rng=1)
    emp = rec.data.std(axis=0)
    assert np.allclose(emp, sd * math.sqrt(h), rtol=0.01)  # 200k samples: ~0.16 % sampling error
    rates = S.rate_samples(PureSpin(0.0), h, 200_000, errors=e, rng=1).data
    assert np.allclose(rates.std(axis=0), sd / math.sqrt(h), rtol=0.01)


def test_bias_scale_factor_misalignment():
    mis = np.array([[0, 1e-3, 0], [0, 0, -2e-3], [5e-4, 0, 0]])
    e = S.GyroErrors(bias=[1e-3, 0, -1e-3], scale_factor=[1e-4, 0, 0], misalignment=mis)
    h = 1e-2
    truth = S.increments(PureSpin(2.0), h, 10).data
    meas = S.increments(PureSpin(2.0), h, 10, errors=e).data
    expected = (truth + np.array([1e-3, 0, -1e-3]) * h) @ (np.eye(3) + np.diag([1e-4, 0, 0])
                                                            + mis).T
    assert np.allclose(meas, expected, atol=1e-16)


def test_gauss_markov_bias_stationary_variance():
    e = S.GyroErrors(gm_sigma=1e-3, gm_tau=0.05)
    r = S.rate_samples(PureSpin(0.0), 1e-3, 400_000, errors=e, rng=3).data
    # 400 s / 0.05 s = 8000 correlation times: ~1.6 % error on the variance
    assert np.allclose(r.std(axis=0), 1e-3, rtol=0.05)
    lag = int(0.05 / 1e-3)
    rho = np.mean(r[:-lag, 0] * r[lag:, 0]) / np.var(r[:, 0])
    assert rho == pytest.approx(math.exp(-1.0), abs=0.05)


def test_quantisation_carries_residual():
    e = S.GyroErrors(quantization=1e-4)
    truth = S.increments(CONE, 1e-3, 1000).data
    q = S.increments(CONE, 1e-3, 1000, errors=e).data
    assert np.allclose(q / 1e-4, np.round(q / 1e-4), atol=1e-9)
    # the running sum never drifts by more than half an LSB
    assert np.max(np.abs(np.cumsum(q - truth, axis=0))) <= 0.5e-4 + 1e-15


def test_saturation_clips_rate():
    e = S.GyroErrors(saturation=1.0)
    rec = S.increments(PureSpin(3.0), 1e-2, 5, errors=e)
    assert np.allclose(rec.data[:, 0], 1e-2)
    r = S.rate_samples(PureSpin(-3.0), 1e-2, 5, errors=e)
    assert np.allclose(r.data[:, 0], -1.0)


def test_preaveraging_is_mean_not_divided_by_h():
    h = 1e-3
    # m = 1: one midpoint sample; increment = ω(mid) h
    one = S.preaveraged_increments(CONE, h, 10, 1).data
    assert np.allclose(one, CONE.rate(np.arange(10) * h + h / 2) * h, atol=1e-18)
    # many raw samples: the mean converges to the exact increment (midpoint rule, O(1/m²))
    exact = CONE.increments(np.arange(11) * h)
    many = S.preaveraged_increments(CONE, h, 10, 64).data
    assert np.max(np.abs(many - exact)) < 1e-3 * np.max(np.abs(exact - one))


@pytest.mark.parametrize(
    ("kwargs", "msg"),
    [
        ({"white_noise": -1.0}, "non-negative"),
        ({"saturation": 0.0}, "saturation"),
        ({"gm_tau": -1.0}, "gm_tau"),
        ({"misalignment": np.eye(3)}, "zero diagonal"),
        ({"misalignment": np.zeros(3)}, r"shape \(3, 3\)"),
        ({"bias": [1, 2]}, r"shape \(3,\)"),
    ],
)
def test_bad_error_model(kwargs, msg):
    with pytest.raises(ValueError, match=msg):
        S.GyroErrors(**kwargs)


@pytest.mark.parametrize(("h", "n", "msg"), [(0.0, 5, "positive"), (1e-3, 0, "positive integer"),
                                             (-1.0, 5, "positive"), (1e-3, 2.5, "integer")])
def test_bad_sampling(h, n, msg):
    with pytest.raises(ValueError, match=msg):
        S.increments(CONE, h, n)
