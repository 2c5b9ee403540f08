"""The AHRS kernel's issue-25 stages, each alone (continues ``test_stages.py``).

The accelerometer weight driven by the data (:func:`_motion_power`,
:func:`_motion_variance`, :func:`_lowpass_variance`) and the measurements turned back to the
state's time (:func:`_at_state_time`, then :func:`_delayed_field`), as their plain-Python
twins against closed forms or an independent computation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.signal import lfilter

import strapdown.ahrs._kernel as K
from strapdown.ahrs.filter import AhrsConfig, _params, _Start
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_from_rotvec

G = 9.80665
REF = (48.0, math.radians(60.0), math.radians(80.0))


@pytest.fixture
def k(monkeypatch):
    """The kernel module with every compiled function replaced by its plain-Python twin."""
    from numba.core.registry import CPUDispatcher

    for name, f in list(vars(K).items()):
        if isinstance(f, CPUDispatcher):
            monkeypatch.setattr(K, name, f.py_func)
    return K


def _params_of(h=0.01, te=None, **cfg):
    return _params(AhrsConfig(**cfg), REF, True, h, h if te is None else te,
                   _Start(True, G, True, 0.05))


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


# ------------------------------------------------------------------ the measurement's time
def _body_vector(w, t, v_n):
    """A reference-fixed vector in the body of a sensor turning at a constant rate w from
    the identity: C_b_n(t) v_n, C_n_b(t) = exp(t [w×])."""
    return expm(t * _skew(w)).T @ v_n


@pytest.mark.parametrize("is_rate", [True, False])
def test_at_state_time_turns_the_sample_back_by_the_lead(k, is_rate):
    """A sensor turning at ω sees a fixed vector move as v̇ = −ω × v: the sample at t, taken
    back δ, is the vector at t − δ (here computed exactly, by the matrix exponential) up
    to third order in |ω|δ; bias-corrected; with increments the rate is the interval's
    ending at sample k (never the one after)."""
    h, b = 0.01, np.array([0.05, -0.1, 0.02])
    w = np.array([2.0, -3.0, 6.0])  # 7 rad/s
    v_n = np.array([0.3, 20.0, -40.0])
    x = np.tile(w + b, (6, 1)) if is_rate else np.tile((w + b) * h, (5, 1))
    if not is_rate:
        x[3] = 99.0  # the interval after sample 3: unused
    errs = []
    for lead in (0.005, 0.0025):
        out = np.empty(3)
        k._at_state_time(_body_vector(w, 1.0, v_n), 3, x, h, is_rate, b, lead, out)
        errs.append(np.linalg.norm(out - _body_vector(w, 1.0 - lead, v_n)))
    a = np.linalg.norm(w) * 0.005
    assert errs[0] < a**3 / 6 * np.linalg.norm(v_n)
    assert errs[0] / errs[1] == pytest.approx(8.0, rel=0.05)  # third order


def test_at_state_time_without_lead_or_along_the_axis_is_the_sample(k):
    x = np.tile([1.0, 2.0, 3.0], (4, 1))
    v, out = np.array([0.5, 1.0, 1.5]), np.empty(3)
    k._at_state_time(v, 2, x, 0.01, True, np.zeros(3), 0.0, out)
    assert np.array_equal(out, v)
    k._at_state_time(v, 2, x, 0.01, True, np.zeros(3), 0.005, out)  # v ∥ ω
    assert np.allclose(out, v, rtol=0, atol=1e-15)


def test_meas_lead_is_half_a_period_for_interval_samples():
    """An interval gyro sample is the mean rate over the period: the attitude refers to its
    middle, half a period before the stamp of a field read at an instant."""
    assert _params_of(h=0.004, gyro_sample="interval").meas_lead == 0.002
    assert _params_of(h=0.004, gyro_sample="point").meas_lead == 0.0


def test_acc_lead_is_half_a_period_only_for_point_accelerometer_samples():
    """An interval accelerometer sample (the default) refers where the attitude does; a
    point one is turned back half a period, as a point field sample is."""
    assert _params_of(h=0.004).acc_lead == 0.0
    assert _params_of(h=0.004, acc_sample="point").acc_lead == 0.002
    assert _params_of(h=0.004, gyro_sample="point", acc_sample="point").acc_lead == 0.0
    with pytest.raises(ValueError, match="acc_sample must be 'interval' or 'point'"):
        AhrsConfig(acc_sample="mean")


@pytest.mark.parametrize("recorded,acc_sample,low,high", [
    ("point", "point", 0.0, 0.01), ("point", "interval", 0.1, 0.4),
    ("interval", "interval", 0.0, 0.01), ("interval", "point", 0.1, 0.4)])
def test_accelerometer_sample_convention_on_an_exact_turn(recorded, acc_sample, low, high):
    """The noise-free rests of the generalisation suite (50 Hz, interval gyro; a 2 s quintic
    turn to a new pose at 12 s, at up to 84 °/s, about the sensor), the specific force
    recorded at the stamps or as its mean over each period: told the convention, the filter
    holds the tilt to 0.01°; told the other, gravity is misplaced by half a period of
    rotation during the turn and the low-pass carries it on: 0.2° of tilt after the turn
    (measured 0.197° for point samples taken as means)."""
    import dataclasses

    from strapdown.ahrs.filter import ekf
    from strapdown.rotation.quaternion import quat_conjugate, quat_multiply
    from strapdown.truth.scenarios import record, rests

    sc = rests(duration_s=24.0)
    sc = dataclasses.replace(sc, sensors=dataclasses.replace(sc.sensors, acc_sample=recorded))
    rec = record(sc, 0, noise=False)
    res = ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=AhrsConfig(acc_sample=acc_sample))
    e = quat_multiply(res.q, quat_conjugate(rec.q_n_b))
    tilt = np.degrees(2.0 * np.arcsin(np.minimum(np.hypot(e[:, 1], e[:, 2]), 1.0)))
    assert low <= tilt.max() <= high, tilt.max()
    assert tilt[rec.t < 12.0].max() < 1e-3  # before the turn, both are exact


def test_delayed_field_is_the_stored_attitude_times_the_sample(k):
    ring = dcm_from_quat(quat_from_rotvec(np.array([[0.1, 0.2, 0.3], [0.4, -0.5, 0.6]])))
    m, mn = np.array([10.0, -20.0, 35.0]), np.empty(3)
    nb = k._delayed_field(ring, 1, m, mn)
    assert np.allclose(mn, ring[1] @ m, rtol=0, atol=1e-13)
    assert nb == pytest.approx(np.linalg.norm(m), rel=1e-14)


# ------------------------------------------------------------------ the motion-driven weight
def test_motion_gains_are_the_exact_discretisations():
    """Per epoch te: 1 − e^{−te/τ} for the mean square, 1 − e^{−te/(MOTION_SLOW τ)} for the
    slow mean (τ = acc_lowpass_s)."""
    p = _params_of(h=0.005, te=0.015, acc_lowpass_s=1.5)
    assert p.dyn_k == pytest.approx(1 - math.exp(-0.015 / 1.5), rel=1e-15)
    assert p.dyn_k2 == pytest.approx(1 - math.exp(-0.015 / (K.MOTION_SLOW * 1.5)), rel=1e-15)


def test_motion_power_of_a_horizontal_step(k):
    """While the low-pass still averages, the slow mean copies it and the power stays. Then a
    horizontal step Δ of the low-passed force: the slow mean closes in geometrically,
    d_n = Δ (1 − k₂)^{n}; the power is the exponential mean (gain k) of |d_n|², and the
    mean the exponential mean of d_n — here scipy's lfilter of those closed-form sequences.
    A vertical step adds no power."""
    p = _params_of(acc_lowpass_s=0.05, te=0.01)
    assert p.lp_init_n == 5
    lp, lp2, dmean = np.array([0.1, -0.2, G]), np.zeros(3), np.zeros(3)
    assert k._motion_power(0.25, 3, p, lp, lp2, dmean) == 0.25 and np.array_equal(lp2, lp)
    assert not dmean.any()
    delta = np.array([0.3, -0.4, 0.0])
    k2, n = p.dyn_k2, 200
    for step, expect_zero in ((delta, False), (np.array([0.0, 0.0, 0.5]), True)):
        lp2, dmean = np.array([0.1, -0.2, G]), np.zeros(3)
        lp = lp2 + step
        dyn2, seq, means = 0.0, [], []
        for _ in range(n):
            dyn2 = k._motion_power(dyn2, 5, p, lp, lp2, dmean)
            seq.append(dyn2)
            means.append(dmean.copy())
        d = step[:, None] * (1 - k2) ** np.arange(1, n + 1)
        ref = lfilter([p.dyn_k], [1, p.dyn_k - 1], (d[:2] ** 2).sum(axis=0))
        assert np.allclose(seq, ref, rtol=1e-12, atol=0 if expect_zero else 1e-18)
        ref_mean = lfilter([p.dyn_k], [1, p.dyn_k - 1], d, axis=1).T
        assert np.allclose(means, ref_mean, rtol=0, atol=1e-12)
        assert np.allclose(lp2, lp - step * (1 - k2) ** n, rtol=0, atol=1e-12)
        if expect_zero:
            assert not any(seq)


def test_motion_variance_leaves_out_what_stays(k):
    """The power the weight uses is the variance of d = lp − lp2 over the window. With the
    slow mean held (k₂ = 0) a step Δ that stays gives, after n epochs with r = (1 − k)^n,
    mean square |Δ|² (1 − r) and mean Δ (1 − r): variance |Δ|² r (1 − r), which goes to 0
    — a tilt error left behind is not motion. A horizontal circle d = A (cos ωt, sin ωt)
    keeps in steady state the mean square A² and a mean of A k / |1 − (1 − k) e^{−iωh}|:
    a swing or a turn within the window is motion. Negative round-off is clipped at 0."""
    p = _params_of(acc_lowpass_s=0.5, te=0.01)._replace(dyn_k2=0.0)
    kk = p.dyn_k
    base = np.array([0.1, -0.2, G])
    delta = np.array([0.3, -0.4, 0.2])
    lp2, dmean, dyn2 = base.copy(), np.zeros(3), 0.0
    for n in range(1, 401):
        dyn2 = k._motion_power(dyn2, 50, p, base + delta, lp2, dmean)
        r = (1 - kk) ** n
        assert k._motion_variance(dyn2, dmean) == pytest.approx(0.25 * r * (1 - r),
                                                                rel=1e-9, abs=1e-15)
    assert k._motion_variance(dyn2, dmean) < 1e-3 * 0.25  # eight windows on
    A, w, h = 0.7, 2 * math.pi / 0.8, 0.01
    lp2, dmean, dyn2 = base.copy(), np.zeros(3), 0.0
    for n in range(3000):
        c = A * np.array([math.cos(w * n * h), math.sin(w * n * h), 0.0])
        dyn2 = k._motion_power(dyn2, 50, p, base + c, lp2, dmean)
    m2 = (A * kk / abs(1 - (1 - kk) * np.exp(-1j * w * h))) ** 2
    assert dyn2 == pytest.approx(A * A, rel=1e-9)
    assert k._motion_variance(dyn2, dmean) == pytest.approx(A * A - m2, rel=1e-6)
    assert k._motion_variance(1e-3, np.array([0.1, 0.0, 5.0])) == 0.0


def test_lowpass_variance_adds_the_leaked_motion(k):
    """R = (n² + κ² τ ā²)/T per horizontal axis; κ = 0 gives the plain noise."""
    p = _params_of(acc_lowpass_noise=0.03, acc_lowpass_s=2.0, acc_motion_leak=0.2)
    T, dyn2 = 0.01, 0.7
    assert k._lowpass_variance(p, dyn2, T) == pytest.approx(
        (0.03**2 + 0.04 * 2.0 * 0.7) / T, rel=1e-14)
    assert k._lowpass_variance(p._replace(acc_motion_leak=0.0), dyn2, T) == pytest.approx(
        0.03**2 / T, rel=1e-15)


def test_rest_compares_the_accelerometer_with_gravity_as_measured(k):
    """Quiet needs the mean specific force within rest_acc of the norm measured over the
    initial window (the accelerometer's scale error included), not of the nominal g."""
    g_m = 9.5  # a 3 % scale error: |g_m − g| > rest_acc
    p = _params(AhrsConfig(rest_acc=0.28), REF, True, 0.01, 0.01, _Start(True, g_m, True, 0.05))
    up = np.array([0.0, 0.6, 0.8])
    zero = np.zeros(3)
    for f, quiet in ((0.0, True), (0.98, True), (-0.98, True), (1.02, False), (-1.02, False)):
        am = (g_m + f * 0.28) * up
        assert bool(k._rest_detect(100.0, 0.02, p, zero, zero, am, am**2, g_m)[0]) is quiet, f
