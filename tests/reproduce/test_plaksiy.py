"""Krylov-angle motion, Plaksiy's A1–A3, accumulated drift, reproduction numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _reference
from strapdown.algorithms.quaternion import QuaternionAlgorithm, quaternion_attitude
from strapdown.analysis import accumulated_drift, integrate_attitude_ode
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.reproduce.plaksiy2024 import (
    K2,
    PRINTED_T1,
    PRINTED_T2,
    PRINTED_T3,
    REPRODUCING_A1,
    STATED,
    DriftRun,
    K,
)
from strapdown.rotation import attitude_error_angle
from strapdown.truth.motions import KrylovMotion, RotationSequenceMotion

KS = [(0.15, 0.25, 0.05), (0.3, 0.5, 0.1), (0.4, 0.4, 0.0), (0.0, 0.7, 0.7), (1.3, -0.2, 2.1)]


@pytest.mark.parametrize("k", KS)
def test_krylov_attitude_matches_ode_and_rotation_sequence(k):
    m = KrylovMotion(*k)
    t = np.linspace(0, 20, 21)
    assert np.max(attitude_error_angle(integrate_attitude_ode(m, t), m.attitude(t))) <= 1e-12
    seq = RotationSequenceMotion("zyx", lambda s: np.asarray(s)[..., None] * np.array(k),
                                 lambda s: np.broadcast_to(np.array(k), (*np.shape(s), 3)))
    assert np.allclose(m.attitude(t), seq.attitude(t), atol=1e-15)
    assert np.allclose(m.rate(t), seq.rate(t), atol=1e-15)


def test_krylov_rates_are_eq4():
    k1, k2, k3 = 0.15, 0.25, 0.05
    t = np.array([0.0, 3.3, 17.0])
    w = KrylovMotion(k1, k2, k3).rate(t)
    assert np.allclose(w[:, 0], k3 - k1 * np.sin(k2 * t))
    assert np.allclose(w[:, 1], k1 * np.cos(k2 * t) * np.sin(k3 * t) + k2 * np.cos(k3 * t))
    assert np.allclose(w[:, 2], k1 * np.cos(k2 * t) * np.cos(k3 * t) - k2 * np.sin(k3 * t))


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")  # quad at round-off
@pytest.mark.parametrize("k", KS)
@pytest.mark.parametrize("frac", [1.0, 1 / 2, 1 / 3])  # steps, halves, thirds
def test_quasi_coordinates_match_adaptive_quadrature(k, frac):
    m = KrylovMotion(*k)
    dt = 0.1 * frac
    for t0 in (0.0, 7.3, 123.4, 399.9):
        exact = m.increments([t0, t0 + dt])[0]
        for i in range(3):
            q, _ = quad(lambda s, i=i: m.rate(np.array(s))[i], t0, t0 + dt, epsabs=1e-18,
                        epsrel=1e-15, limit=200)
            assert abs(exact[i] - q) <= 1e-15


def test_krylov_mp_matches_float():
    import mpmath

    m = KrylovMotion(0.3, 0.5, 0.1)
    with mpmath.workdps(40):
        th = m.increment_mp(5.0, 5.1)
        q = m.attitude_mp(5.1)
    assert np.allclose([float(x) for x in th], m.increments([5.0, 5.1])[0], atol=1e-17)
    assert np.allclose([float(x) for x in q], m.attitude(5.1), atol=1e-16)


@pytest.mark.parametrize("name", ["miller", "panov", "power"])
@pytest.mark.parametrize("exact", [False, True])
def test_kernel_matches_reference(name, exact):
    rng = np.random.default_rng(1)
    sub = 3 if name == "miller" else 2
    theta = rng.normal(size=(sub * 50, 3)) * 0.05
    alg = QuaternionAlgorithm(name, 0.4, 0.7 if name == "miller" else 0.0, exact)
    sol = quaternion_attitude(theta, alg, step=0.1)
    mode = {"miller": 1, "panov": 2, "power": 3}[name]
    ref = _reference.quaternion_increment([tuple(r) for r in theta], mode, 0.4,
                                          0.7 if name == "miller" else 0.0, exact,
                                          (1.0, 0.0, 0.0, 0.0), NUMPY)
    assert np.max(np.abs(sol.q - np.array(ref))) <= 1e-15


def test_truncated_increment_is_eq7():
    theta = np.array([[0.01, 0.02, -0.01], [0.02, 0.0, 0.01]])
    sol = quaternion_attitude(theta, QuaternionAlgorithm("panov", 0.0), step=0.1)
    s = theta.sum(0)
    th2 = s @ s
    assert np.allclose(sol.q[1], [1 - th2 / 8 + th2**2 / 384, *(0.5 * s * (1 - th2 / 24))],
                       atol=1e-18)


def test_panov_equals_two_sample_rotation_vector_with_exact_exp():
    from strapdown.algorithms.coning import coefficient_set
    from strapdown.algorithms.structures import conventional

    rng = np.random.default_rng(3)
    theta = rng.normal(size=(40, 3)) * 0.05
    a = quaternion_attitude(theta, QuaternionAlgorithm("panov", 2 / 3, exact_exp=True), step=0.1)
    b = conventional(theta, coefficient_set("table3", 2), h=0.05)
    assert np.max(np.abs(a.q - b.q)) <= 1e-14


def _first(n):
    return REPRODUCING_A1 if n == "miller" else STATED[n][:1]


def _t2(n):
    return PRINTED_T2[n] if n == "miller" else PRINTED_T2[n][:1]


@pytest.mark.parametrize("name", ["miller", "panov", "power"])
def test_table1_and_table3_reproduce(name):
    run = DriftRun(KrylovMotion(*K2), name)
    assert run.max_drift(_first(name)) / PRINTED_T1[name] == pytest.approx(1, abs=0.005)
    assert run.max_drift(_t2(name)) / PRINTED_T3[name] == pytest.approx(1, abs=0.01)
    stated = DriftRun(KrylovMotion(*K), name).max_drift(
        STATED[name] if name == "miller" else STATED[name][:1])
    assert PRINTED_T1[name] / stated == pytest.approx(32, rel=0.02)


@pytest.mark.parametrize("name", ["miller", "panov", "power"])
def test_our_optimiser_is_at_least_as_good(name):
    from strapdown.design.optimize import optimize

    run = DriftRun(KrylovMotion(*K2), name)
    res = optimize(run.max_drift, np.array(_t2(name)), maxiter=200)
    assert res.fun <= run.max_drift(_t2(name))


def test_accumulated_drift_metric():
    q = np.array([[1.0, 0.0, 0.0, 0.0], [math.cos(0.1), math.sin(0.1), 0.0, 0.0]])
    assert np.allclose(accumulated_drift(q, np.array([[1.0, 0, 0, 0]] * 2)),
                       [0.0, 2 * math.sin(0.1)])
    assert np.allclose(accumulated_drift(-q, q), 0.0, atol=1e-16)


def test_evaluate_krylov_json():
    cfg = EvaluationConfig.of(motion="krylov", krylov_rates=K2, algorithm="miller",
                              alpha=9 / 20, beta=27 / 40, step=0.1, duration=200.0)
    d = evaluate(cfg).to_dict()
    assert d["accumulated_drift_rad"] == pytest.approx(PRINTED_T1["miller"], rel=0.005)
    assert d["update_period_s"] == 0.1 and d["alpha"] == 9 / 20


@pytest.mark.parametrize(
    ("kw", "msg"),
    [
        (dict(algorithm="panov"), "needs --step"),
        (dict(algorithm="panov", step=0.1, beta=1.0), "one coefficient"),
        (dict(algorithm="rotvec", alpha=1.0), "belong to miller"),
        (dict(algorithm="power", step=0.1, precision=40), "float64 only"),
        (dict(motion="krylov", krylov_rates=(0.1, np.nan, 0.2), algorithm="power", step=0.1),
         "three finite"),
    ],
)
def test_bad_configuration(kw, msg):
    with pytest.raises(ValueError, match=msg):
        evaluate(EvaluationConfig.of(**kw))


def test_bad_algorithm_input():
    with pytest.raises(ValueError, match="whole steps of 3"):
        quaternion_attitude(np.zeros((4, 3)), QuaternionAlgorithm("miller", 0.4, 0.7), step=0.1)
    with pytest.raises(ValueError, match="beta must be 0"):
        QuaternionAlgorithm("power", 0.3, 0.1)
    with pytest.raises(ValueError, match="unknown algorithm"):
        QuaternionAlgorithm("euler", 0.3)
