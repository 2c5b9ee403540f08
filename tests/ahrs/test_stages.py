"""The AHRS kernel stage by stage, each against a closed form or an independent computation.

Like VQF's tests, which compare one stage at a time, every test here calls one stage of
:mod:`strapdown.ahrs._kernel` on its own: propagation (attitude and covariance), the rest
detector and zero-rate update, the low-pass and the raw accelerometer models, the
magnetometer's heading update and disturbance detection, the reset, gating and recovery.

The stages run as their plain-Python twins (``py_func``, through the ``k`` fixture: every
compiled function of the kernel replaced by its twin), which compiles nothing;
``test_ahrs.py::test_kernel_matches_its_plain_python_execution`` ties the compiled loop to
those twins. The few loop-level rules (``rest_min_s``, the rejection budget) are checked on
the compiled filter at the end.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.signal import butter, lfilter, lfilter_zi

import strapdown.ahrs._kernel as K
from strapdown.ahrs import MeasurementFlag as Flag
from strapdown.ahrs.filter import (
    AhrsConfig,
    _algorithm,
    _params,
    _propagation,
    _Start,
    butterworth,
    ekf,
)
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_from_rotvec, quat_multiply

G = 9.80665
G_UP = np.array([0.0, 0.0, G])
#: reference field of the stage tests: norm (µT), dip 60° down, heading 80° (from east)
REF = (48.0, math.radians(60.0), math.radians(80.0))
M_REF = REF[0] * np.array([math.cos(REF[1]) * math.cos(REF[2]),
                           math.cos(REF[1]) * math.sin(REF[2]), -math.sin(REF[1])])


@pytest.fixture
def k(monkeypatch):
    """The kernel module with every compiled function (stages, helpers, the quaternion
    update) replaced by its plain-Python twin."""
    from numba.core.registry import CPUDispatcher

    for name, f in list(vars(K).items()):
        if isinstance(f, CPUDispatcher):
            monkeypatch.setattr(K, name, f.py_func)
    return K


def _params_of(h=0.01, te=None, g_measured=G, **cfg):
    """The kernel's parameter record for ``AhrsConfig(**cfg)``, sample period h, epoch te."""
    return _params(AhrsConfig(**cfg), REF, True, h, h if te is None else te,
                   _Start(True, g_measured, True, 0.05))


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _spd(rng, n, scale=1e-3):
    a = rng.standard_normal((n, n))
    return scale * (a @ a.T + n * np.eye(n)) / n


def _q(rotvec):
    return quat_from_rotvec(np.asarray(rotvec, float))


Q_HAT = _q([0.4, -0.7, 1.9])  # an attitude far from level
C_HAT = dcm_from_quat(Q_HAT)


def _fd_jacobian(f, n, d=1e-6):
    """Central differences of f: R^n → R^m at 0."""
    cols = []
    for i in range(n):
        e = np.zeros(n)
        e[i] = d
        cols.append((f(e) - f(-e)) / (2 * d))
    return np.column_stack(cols)


# ------------------------------------------------------------------ 1. attitude propagation
@pytest.mark.parametrize("spec", ["rate-single", "rate-three", "rotvec:N=3"])
def test_window_step_turns_a_constant_rate_by_the_exponential_map(k, spec):
    """For a constant rate the window's cross-products vanish and its weights sum to one
    period: each epoch's φ is ω T exactly and the attitude q0 ⊗ q(ω t), through the bias
    correction (the gyro reads ω + b, the estimate holds b)."""
    prop, win = _propagation(_algorithm(spec))
    h, w, b = 0.01, np.array([0.9, -1.3, 0.4]), np.array([0.02, -0.01, 0.03])
    n = 61
    x = np.tile(w + b, (n, 1)) if prop.is_rate else np.tile((w + b) * h, (n - 1, 1))
    q0 = _q([0.3, 0.2, -1.0])
    q, ring = q0.copy(), q0[None].copy()
    phi, tmp, base, bias_x = (np.empty(s) for s in (3, 4, 4, 3))
    nodes = np.empty((win.offsets.size, 3))
    for e in range(k._n_epochs(prop, win.offsets, x.shape[0], n)):
        kk, T = k._window_step(e, x, h, prop, *win, ring, q, b, phi, tmp, base, nodes, bias_x)
        ring[0] = q
        assert T == prop.stride * h and kk == (e + 1) * prop.stride
        assert np.allclose(phi, w * T, rtol=0, atol=1e-15)
    assert kk == 60
    assert np.allclose(q, quat_multiply(q0, _q(w * kk * h)), rtol=0, atol=2e-14)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-15


def test_rk4_step_is_the_fourth_order_taylor_polynomial_normalised(k):
    """Quaternion RK4 on a constant rate: one step of length T is exactly
    normalise(Σ_{j≤4} (Ω T/2)^j/j! q), Ω the rate's quaternion-product matrix, and its φ
    the mid rate times T."""
    h, w, b = 0.02, np.array([2.0, -1.5, 3.0]), np.array([0.1, 0.0, -0.2])
    x = np.tile(w + b, (5, 1))
    q = _q([1.0, 0.5, -0.3])
    q_start = q.copy()
    phi, tmp, ry = np.empty(3), np.empty(4), np.empty(4)
    kk, T = k._rk4_step(0, x, h, q, b, phi, tmp, np.empty((3, 3)), np.empty((4, 4)), ry)
    om = np.array([[0, -w[0], -w[1], -w[2]], [w[0], 0, w[2], -w[1]],
                   [w[1], -w[2], 0, w[0]], [w[2], w[1], -w[0], 0]])  # q ⊗ [0, ω] = Ω q
    a = 0.5 * T * om
    taylor = sum(np.linalg.matrix_power(a, j) / math.factorial(j) for j in range(5)) @ q_start
    assert (kk, T) == (2, 2 * h)
    assert np.allclose(q, taylor / np.linalg.norm(taylor), rtol=0, atol=1e-15)
    assert np.allclose(phi, w * T, rtol=0, atol=1e-16)
    # and within the fifth-order term of the exact rotation (|ω|T = 0.16 rad)
    err = np.linalg.norm(q - quat_multiply(q_start, _q(w * T)))
    assert 1e-9 < err < (np.linalg.norm(w) * T / 2) ** 5 / 120


def test_startup_step_rotation_vector(k):
    """The sliding scheme's single-period step: φ = h/2 (ω₀ + ω₁) + c h² ω₀ × ω₁ on the
    bias-corrected rates, applied by the exact exponential map."""
    h, c = 0.005, 1.0 / 6.0
    x = np.array([[0.5, -2.0, 1.0], [1.5, 0.5, -1.0], [9.0, 9.0, 9.0]])
    b = np.array([0.1, 0.2, -0.1])
    q0 = _q([0.2, 0.1, 0.0])
    q, phi, tmp = q0.copy(), np.empty(3), np.empty(4)
    assert k._startup_step(1, x, h, c, q, b, phi, tmp) == h
    w0, w1 = x[0] - b, x[1] - b
    expect = 0.5 * h * (w0 + w1) + c * h * h * np.cross(w0, w1)
    assert np.allclose(phi, expect, rtol=0, atol=1e-17)
    assert np.allclose(q, quat_multiply(q0, _q(expect)), rtol=0, atol=1e-15)


# ------------------------------------------------------------------ 3. covariance propagation
def _phi_matrix(phi, T, nx, singer, decay):
    """Φ = [[I − [φ×] + ½[φ×]², −T I], [0, I]] (decay I on the Singer rows), built whole."""
    s = _skew(phi)
    F = np.eye(nx)
    F[:3, :3] = np.eye(3) - s + 0.5 * s @ s
    F[:3, 3:6] = -T * np.eye(3)
    if singer:
        F[6:9, 6:9] = decay * np.eye(3)
    return F


@pytest.mark.parametrize("nx, singer", [(6, False), (9, False), (9, True), (12, True)])
def test_propagate_covariance_is_phi_p_phi_transposed(k, nx, singer):
    rng = np.random.default_rng(nx + singer)
    P = _spd(rng, nx)
    phi, T, decay = np.array([0.03, -0.05, 0.02]), 0.01, 0.95
    F = _phi_matrix(phi, T, nx, singer, decay)
    expect = F @ P @ F.T
    k._propagate_covariance(P, phi, T, decay, singer, np.empty((3, 3)), np.empty((nx, nx)))
    assert np.allclose(P, expect, rtol=1e-13, atol=1e-18)
    assert np.array_equal(P, P.T)


def test_attitude_transition_is_exp_of_minus_phi_to_second_order():
    """The attitude block of Φ against exp(−[φ×]): the omitted terms start at |φ|³/6."""
    for mag in (1e-3, 1e-2, 5e-2):
        phi = mag * np.array([0.6, -0.48, 0.64])
        F = _phi_matrix(phi, 0.01, 6, False, 1.0)
        err = np.abs(F[:3, :3] - expm(-_skew(phi))).max()
        assert 0.1 * mag**3 / 6 < err < mag**3 / 6


def test_covariance_of_a_constant_rate_converges_to_the_closed_form(k):
    """A constant rate ω over t: the error-state transition is exp(−[ω×]t) on the attitude
    and −∫₀ᵗ exp(−[ω×]s) ds on the bias (Rodrigues, integrated). The kernel's product of
    steps (the bias column by the rectangle rule) reaches it at first order in T."""
    w, t = np.array([0.3, -0.5, 0.8]), 2.0
    W, a = _skew(w), np.linalg.norm(w)
    F = np.eye(6)
    F[:3, :3] = expm(-W * t)
    F[:3, 3:] = -(t * np.eye(3) - (1 - math.cos(a * t)) / a**2 * W
                  + (t - math.sin(a * t) / a) / a**2 * W @ W)
    P0 = np.diag([1e-4, 2e-4, 3e-4, 1e-4, 1e-4, 2e-4])
    expect = F @ P0 @ F.T
    errs = []
    for T in (0.01, 0.005):
        P = P0.copy()
        for _ in range(round(t / T)):
            k._propagate_covariance(P, w * T, T, 1.0, False, np.empty((3, 3)), np.empty((6, 6)))
        errs.append(np.abs(P - expect).max() / np.abs(expect).max())
    assert errs[0] < 0.5 * 0.01 * a * t  # the rectangle rule's bound, ½ T |ω| t
    assert errs[0] / errs[1] == pytest.approx(2.0, rel=0.02)  # first order


def test_process_noise_terms(k):
    """Q over T: gyro white noise σ_g² T, bias random walk σ_b² T, the Singer process's
    exact discretisation (decay e^{−T/τ}, variance σ²(1 − e^{−2T/τ}), whose fixed point is
    σ²) and the accelerometer bias's random walk."""
    p = _params_of(gyro_noise=2e-3, gyro_bias_rw=3e-5, singer_sigma=1.5, singer_tau=0.3,
                   acc_bias_rw=2e-4)
    T = 0.02
    decay, qg, qb, qa, qab = k._process_noise(T, p)
    assert decay == pytest.approx(math.exp(-T / 0.3), rel=1e-15)
    assert qg == pytest.approx(4e-6 * T, rel=1e-15)
    assert qb == pytest.approx(9e-10 * T, rel=1e-15)
    assert qab == pytest.approx(4e-8 * T, rel=1e-15)
    # the Gauss–Markov variance added over T: ∫₀ᵀ e^{−2s/τ} (2σ²/τ) ds
    s = np.linspace(0, T, 20001)
    integrand = np.exp(-2 * s / 0.3) * 2 * 1.5**2 / 0.3
    assert qa == pytest.approx(np.trapezoid(integrand, s), rel=1e-8)
    v = 0.0
    for _ in range(2000):
        v = decay**2 * v + qa
    assert v == pytest.approx(1.5**2, rel=1e-12)


@pytest.mark.parametrize("nx, singer", [(6, False), (9, True), (12, True), (9, False)])
def test_add_process_noise_splits_tilt_and_heading(k, nx, singer):
    """The attitude noise is σ_g² T plus tilt_rate_noise² |ω|² T across the reference
    vertical (the body-frame c = C₃ᵀ) and heading_rate_noise² |ω|² T along it (none
    after a disturbed field; at least the tilt's while a bridging pass rejects one)."""
    p = _params_of(gyro_noise=2e-3, tilt_rate_noise=4e-3, heading_rate_noise=1e-2)
    T, phi = 0.01, np.array([0.02, 0.01, -0.03])
    qg, qb, qa, qab = 4e-6 * T, 1e-10, 3e-3, 2e-9
    P = np.zeros((nx, nx))
    k._add_process_noise(P, C_HAT, phi, T, qg, qb, qa, qab, p, singer, False, False, 1.0)
    w2 = phi @ phi / T**2
    c = C_HAT[2]
    assert P[:3, :3] @ c == pytest.approx((qg + 1e-4 * w2 * T) * c, rel=1e-12)
    horiz = np.cross(c, [1.0, 0.0, 0.0])
    assert P[:3, :3] @ horiz == pytest.approx((qg + 1.6e-5 * w2 * T) * horiz, rel=1e-12)
    # the last epoch found the field disturbed: no heading rate noise; a rejected one in
    # a bridging pass (heading_bridge_noise): at least the tilt's
    for unobserved, disturbed, hv in ((False, True, 0.0), (True, True, 1e-4)):
        Pd = np.zeros((nx, nx))
        k._add_process_noise(Pd, C_HAT, phi, T, qg, qb, qa, qab, p, singer, unobserved,
                             disturbed, 1.0)
        assert Pd[:3, :3] @ c == pytest.approx((qg + hv * w2 * T) * c, rel=1e-12, abs=1e-20)
        assert Pd[:3, :3] @ horiz == pytest.approx((qg + 1.6e-5 * w2 * T) * horiz, rel=1e-12)
    pb = _params_of(gyro_noise=2e-3, tilt_rate_noise=4e-3, heading_rate_noise=0.0)
    Pb = np.zeros((nx, nx))
    k._add_process_noise(Pb, C_HAT, phi, T, qg, qb, qa, qab, pb, singer, True, True, 1.0)
    assert Pb[:3, :3] @ c == pytest.approx((qg + 1.6e-5 * w2 * T) * c, rel=1e-12)
    # the adaptation's factor m multiplies the tilt's rate noise only
    Pm = np.zeros((nx, nx))
    k._add_process_noise(Pm, C_HAT, phi, T, qg, qb, qa, qab, p, singer, False, False, 7.0)
    assert Pm[:3, :3] @ c == pytest.approx((qg + 1e-4 * w2 * T) * c, rel=1e-12)
    assert Pm[:3, :3] @ horiz == pytest.approx((qg + 7.0 * 1.6e-5 * w2 * T) * horiz,
                                               rel=1e-12)
    diag = np.diag(P)
    assert np.all(diag[3:6] == qb)
    assert np.all(diag[6:9] == (qa if singer else (qab if nx == 9 else 0)))
    if nx == 12:
        assert np.all(diag[9:] == qab)
    assert np.count_nonzero(P - np.diag(diag) - np.pad(P[:3, :3] - np.diag(diag[:3]),
                                                      (0, nx - 3))) == 0


def test_tilt_adapt_factor_is_one_below_the_level_then_proportional_and_capped(k):
    """``m`` is 1 up to ``tilt_adapt_level``, the innovation power over the level above it,
    at most ``tilt_adapt_max``; +∞ as the level never adapts."""
    p = _params_of(tilt_adapt_level=5.0, tilt_adapt_max=25.0)
    assert k._tilt_adapt(0.0, p) == 1.0
    assert k._tilt_adapt(5.0, p) == 1.0
    assert k._tilt_adapt(15.0, p) == pytest.approx(3.0, rel=1e-15)
    assert k._tilt_adapt(1e6, p) == 25.0
    assert k._tilt_adapt(1e300, _params_of(tilt_adapt_level=math.inf)) == 1.0


def test_heading_adapt_factor_is_the_mean_nis_above_one_and_one_near_a_clip(k):
    """``m`` is 1 up to a mean NIS of 1 (a consistent filter's), the mean above it; 1
    within ``gyro_clip_s`` of a clipped gyro sample whatever the mean."""
    assert k._heading_adapt(0.0, False) == 1.0
    assert k._heading_adapt(1.0, False) == 1.0
    assert k._heading_adapt(7.5, False) == 7.5
    assert k._heading_adapt(7.5, True) == 1.0
    assert k._heading_adapt(math.nan, False) == 1.0


@pytest.mark.parametrize("h", [0.002, 0.01, 0.04])
def test_heading_power_is_a_moving_mean_of_the_capped_nis(k, h):
    """A constant NIS reaches 1 − 1/e of itself after ``mag_adapt_s`` and itself after
    many, at every sample rate; NaN leaves the mean; an NIS above the gate
    (``mag_gate``) counts as the gate."""
    p = _params_of(h=h, mag_adapt_s=2.0)
    assert p.mag_adapt_k == pytest.approx(1.0 - math.exp(-h / 2.0), rel=1e-15)
    assert p.mag_gate == 4.0
    x, n = 0.0, round(2.0 / h)
    for _ in range(n):
        x = k._heading_power(x, 3.0, p)
    assert x == pytest.approx(3.0 * (1 - math.exp(-1.0)), rel=1e-9)
    for _ in range(20 * n):
        x = k._heading_power(x, 3.0, p)
    assert x == pytest.approx(3.0, rel=1e-9)
    assert k._heading_power(x, math.nan, p) == x
    assert k._heading_power(0.0, 1e6, p) == pytest.approx(p.mag_adapt_k * 4.0, rel=1e-12)
    assert _params_of(h=h, mag_adapt_s=0.0).mag_adapt_k == 0.0


@pytest.mark.parametrize("h", [0.002, 0.01, 0.04])
def test_innovation_power_is_a_moving_mean_of_nis_per_second_whatever_the_rate(k, h):
    """A constant innovation of power ``y²/density²`` (R = density²/T, P negligible) gives
    NIS = T y²/density²: the moving mean of NIS/T reaches y²/density² at every sample rate,
    after ``tilt_adapt_s`` to 1 − 1/e; NaN (no update) leaves it; an NIS above the gate
    counts as the gate."""
    p = _params_of(h=h, tilt_adapt_s=1.0)
    power = 8.0  # 1/s
    x, n = 0.0, round(1.0 / h)
    for _ in range(n):
        x = k._innovation_power(x, power * h, h, p)
    assert x == pytest.approx(power * (1 - math.exp(-1.0)), rel=1e-9)
    for _ in range(20 * n):
        x = k._innovation_power(x, power * h, h, p)
    assert x == pytest.approx(power, rel=1e-9)
    assert k._innovation_power(x, math.nan, h, p) == x
    big = k._innovation_power(0.0, 1e6, h, p)
    assert big == pytest.approx(p.adapt_k * p.acc_gate_lowpass / h, rel=1e-12)


# ------------------------------------------------------------------ 2, 4. rest
def test_rest_averages_are_the_running_mean_then_an_exponential_one(k):
    """The detector's averages over the first rest_tau/h samples are the plain mean (and
    mean square); then an exponential moving average of gain h/rest_tau (scipy's lfilter
    from that mean). Rates are sample k's; increments give interval k's mean rate."""
    rng = np.random.default_rng(3)
    h, tau, n = 1 / 128, 0.25, 200
    alpha = h / tau  # 1/32
    w = rng.standard_normal((n, 3))
    acc = G_UP + rng.standard_normal((n, 3))
    for is_rate in (True, False):
        x = w if is_rate else w[1:] * h
        gm, g2, am, a2 = (np.zeros(3) for _ in range(4))
        last, ema_n = k._fold_rest_samples(0, 32, 0.0, alpha, x, acc, h, is_rate, gm, g2, am, a2)
        assert (last, ema_n) == (32, 32.0)
        assert np.allclose(gm, w[1:33].mean(0), rtol=0, atol=1e-15)
        assert np.allclose(g2, (w[1:33] ** 2).mean(0), rtol=0, atol=1e-15)
        assert np.allclose(a2 - am**2, acc[1:33].var(0), rtol=1e-12)
        k._fold_rest_samples(32, n - 1, 32.0, alpha, x, acc, h, is_rate, gm, g2, am, a2)
        ref = lfilter([alpha], [1, alpha - 1], w[33:], axis=0,
                      zi=(1 - alpha) * w[1:33].mean(0)[None])[0][-1]
        assert np.allclose(gm, ref, rtol=0, atol=1e-14)


def _rest_stats(gyro_mean, gyro_var, acc_mean, acc_var):
    """The averages of signals with these per-axis means and variances."""
    gm, am = np.asarray(gyro_mean, float), np.asarray(acc_mean, float)
    return gm, np.asarray(gyro_var) + gm**2, am, np.asarray(acc_var) + am**2


def test_rest_detection_thresholds(k):
    """At rest: settled (ema_n · h/rest_tau > 1), accelerometer quiet (its variance summed
    over axes below rest_acc², its mean's norm within rest_acc of g), gyro variance below
    rest_gyro², gyro mean below rest_gyro_mean; each threshold crossed by 2 % flips it."""
    p = _params_of(rest_gyro=0.04, rest_gyro_mean=0.035, rest_acc=0.28, rest_tau=0.5)
    alpha = 0.01 / 0.5

    def detect(f_gv=0.0, f_gm=0.0, f_av=0.0, d_an=0.0, ema_n=100.0):
        gv = np.full(3, f_gv * 0.04**2 / 3)
        av = np.full(3, f_av * 0.28**2 / 3)
        up = np.array([0.36, -0.48, 0.8])  # any direction
        stats = _rest_stats(f_gm * 0.035 * up, gv, (G + d_an * 0.28) * up, av)
        return k._rest_detect(ema_n, alpha, p, *stats, p.gravity_measured)

    assert detect() == (True, True)
    assert detect(f_gv=0.98) == (True, True) and detect(f_gv=1.02) == (True, False)
    assert detect(f_gm=0.98) == (True, True) and detect(f_gm=1.02) == (True, False)
    assert detect(f_av=0.98) == (True, True) and detect(f_av=1.02) == (False, False)
    assert detect(d_an=0.98) == (True, True) and detect(d_an=1.02) == (False, False)
    assert detect(d_an=-0.98) == (True, True) and detect(d_an=-1.02) == (False, False)
    assert detect(ema_n=51.0) == (True, True) and detect(ema_n=49.0) == (False, False)


def test_rest_detection_on_a_synthetic_signal(k):
    """A gyro alternating ±a about a bias: its averaged variance is a²(1 − (α/(2 − α))²)
    (the EMA of a ±a alternation swings by ±a α/(2 − α)); at rest just below rest_gyro,
    in motion just above."""
    h, tau = 1 / 100, 0.5
    p = _params_of(h=h, rest_tau=tau)
    alpha = h / tau
    n = 400
    sign = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)[:, None]
    acc = np.tile(G_UP, (n, 1))
    factor = 1 - (alpha / (2 - alpha)) ** 2
    for f, rest in ((0.97, True), (1.03, False)):
        a = f * p.rest_gyro / math.sqrt(factor)
        w = np.array([0.01, -0.02, 0.005]) + a * sign * np.array([1.0, 0.0, 0.0])
        gm, g2, am, a2 = (np.zeros(3) for _ in range(4))
        _, ema_n = k._fold_rest_samples(0, n - 1, 0.0, alpha, w, acc, h, True, gm, g2, am, a2)
        assert k._rest_detect(ema_n, alpha, p, gm, g2, am, a2, p.gravity_measured) == (True, rest)


def test_zero_rate_update_is_the_kalman_filter_of_a_constant(k):
    """At rest the gyro's mean is its bias: H = [0, I], R = rest_noise²/T. Repeated on a
    constant mean b from a zero estimate, the bias variance follows 1/P_n = 1/P_0 + n T/σ²
    and the estimate b (1 − P_n/P_0) — the Kalman filter of a constant, in closed form."""
    p = _params_of(rest_noise=1e-3)
    T, n, p0 = 0.01, 50, 1e-4
    b_true = np.array([0.01, -0.02, 0.015])
    P = np.diag([1e-3] * 3 + [p0] * 3)
    bias, H = np.zeros(3), np.hstack([np.zeros((3, 3)), np.eye(3)])
    y = np.empty(3)
    for _ in range(n):
        dx = np.zeros(6)
        k._rest_model(p, bias, b_true, dx, y)
        assert np.array_equal(y, b_true - bias)
        k._gated_update(P, H, 6, 1e-6 / T, y, 0.0, False, True, False, dx,
                        np.empty((6, 3)), np.empty((3, 3)), np.empty((3, 3)))
        bias += dx[3:]
    pn = 1.0 / (1.0 / p0 + n * T / 1e-6)
    dx = np.array([0.0, 0.0, 0.0, 1e-3, 2e-3, -1e-3])  # an earlier update this epoch
    k._rest_model(p, bias, b_true, dx, y)
    assert np.array_equal(y, b_true - (bias + dx[3:]))
    assert np.diag(P)[3:] == pytest.approx([pn] * 3, rel=1e-12)
    assert bias == pytest.approx(b_true * (1 - pn / p0), rel=1e-12)
    assert np.diag(P)[:3] == pytest.approx([1e-3] * 3, rel=1e-15)  # no attitude coupling


# ------------------------------------------------------------------ 5a. low-pass accelerometer
@pytest.mark.parametrize("tau, ts", [(2.1, 0.01), (0.05, 1 / 286), (3.0, 1 / 51)])
def test_butterworth_coefficients_are_scipys(tau, ts):
    """Second order, cut-off √2/(2π τ), bilinear transform prewarped at the cut-off."""
    b, a = butter(2, math.sqrt(2) / (2 * math.pi * tau), fs=1 / ts)
    assert np.allclose(butterworth(tau, ts), [*b, *a[1:]], rtol=1e-11, atol=0)


def test_butterworth_passes_through_above_ninety_percent_of_nyquist():
    assert butterworth(0.004, 0.01) == (1.0, 0.0, 0.0, 0.0, 0.0)
    assert butterworth(0.006, 0.01) != (1.0, 0.0, 0.0, 0.0, 0.0)


def test_lowpass_averages_then_filters_from_that_steady_state(k):
    """The first n_init outputs are running means; then the Butterworth filter (scipy's
    lfilter) started in the steady state of their mean."""
    rng = np.random.default_rng(5)
    b0, b1, b2, a1, a2 = butterworth(0.3, 0.01)
    x = rng.standard_normal((120, 3)) + np.array([1.0, -2.0, 9.8])
    n_init = 30
    s0, s1, out = np.zeros(3), np.zeros(3), np.empty(3)
    outs, n = [], 0
    for row in x:
        n = k._lowpass(row, n, n_init, b0, b1, b2, a1, a2, s0, s1, out)
        outs.append(out.copy())
    outs = np.array(outs)
    assert n == n_init
    assert np.allclose(outs[:n_init], np.cumsum(x[:n_init], 0) / np.arange(1, 31)[:, None],
                       rtol=1e-15)
    zi = lfilter_zi([b0, b1, b2], [1, a1, a2])[:, None] * outs[n_init - 1][None]
    ref, _ = lfilter([b0, b1, b2], [1, a1, a2], x[n_init:], axis=0, zi=zi)
    # the two starting states differ by rounding (scipy solves for its own), which the
    # poles (|p| ≈ 0.93) carry on for a while: 1e-12 on values of 10
    assert np.allclose(outs[n_init:], ref, rtol=0, atol=5e-12)


def test_lowpass_states_follow_a_reset_rotation(k):
    """The states rotated by (I + [ε×]) (what the reset does, ε the correction in the
    reference frame) continue as if the whole input history had been rotated by ε: the
    filter is linear, so only the second-order remainder of the rotation is left."""
    rng = np.random.default_rng(6)
    coeffs = butterworth(0.5, 0.01)
    x = rng.standard_normal((300, 3)) + G_UP
    eps = np.array([1e-3, -2e-3, 1.5e-3])
    R = expm(_skew(eps))
    v = np.array([1.0, 2.0, 3.0])
    k._rotate_small(eps, v)
    assert np.allclose(v, (np.eye(3) + _skew(eps)) @ [1.0, 2.0, 3.0], rtol=0, atol=1e-15)

    def run(rows, states=None):
        s0, s1, out = states or (np.zeros(3), np.zeros(3), np.empty(3))
        n = 10 if states else 0
        for row in rows:
            n = k._lowpass(row, n, 10, *coeffs, s0, s1, out)
        return s0, s1, out

    whole = run(x @ R.T)[2]
    s0, s1, out = run(x[:150])
    for s in (s0, s1, out):
        k._rotate_small(eps, s)
    followed = run(x[150:] @ R.T, (s0, s1, out))[2]
    s0, s1, out = run(x[:150])
    unrotated = run(x[150:] @ R.T, (s0, s1, out))[2]
    e2 = eps @ eps
    assert np.linalg.norm(followed - whole) < e2 * G
    assert np.linalg.norm(unrotated - whole) > 1e-3 * np.linalg.norm(eps) * G


def _lowpass_measurement(dtheta, dba):
    """Horizontal part of what the estimate C_HAT sees, for the truth q̂ ⊗ q(δθ) at rest and
    an accelerometer bias error δb_a: C_HAT (C_trueᵀ g_up + δb_a)."""
    c_true = dcm_from_quat(quat_multiply(Q_HAT, _q(dtheta)))
    return (C_HAT @ (c_true.T @ G_UP + dba))[:2]


@pytest.mark.parametrize("nx", [6, 9])
def test_lowpass_model_jacobian_and_innovation(k, nx):
    """H against finite differences of the horizontal reference-frame specific force in the
    attitude error (and the accelerometer bias's, nx = 9); the innovation lp − H dx, lp the
    low-pass of C f (one epoch averaged: lp = C f)."""
    p = _params_of(acc_lowpass_s=0.01)
    assert p.lp_init_n == 1
    H, y, lp = np.zeros((2, nx)), np.empty(2), np.empty(3)
    dx = np.zeros(nx)
    dx[:3], dx[3:6] = [1e-3, -2e-3, 5e-4], [1.0, 1.0, 1.0]
    if nx == 9:
        dx[6:] = [0.01, 0.02, -0.03]
    fk = C_HAT.T @ G_UP + np.array([0.05, -0.1, 0.02])  # not exactly gravity
    n = k._acc_lowpass_model(0, p, C_HAT, fk, np.empty(3), lp, np.zeros(3), np.zeros(3), dx,
                             H, y)
    assert n == 1 and np.allclose(lp, C_HAT @ fk, rtol=0, atol=1e-15)
    fd = _fd_jacobian(lambda e: _lowpass_measurement(e[:3], e[3:]), 6)
    assert np.allclose(H[:, :3], fd[:, :3], rtol=0, atol=1e-8)
    assert np.all(H[:, 3:6] == 0)
    if nx == 9:
        assert np.allclose(H[:, 6:], fd[:, 3:], rtol=0, atol=1e-9)
    assert np.allclose(y, lp[:2] - H @ dx, rtol=0, atol=1e-15)


def test_lowpass_plausibility_is_relative_to_measured_gravity(k):
    """Used while |‖lp‖ − g_m| ≤ tol · g_m, g_m the norm measured over the initial window."""
    gm = 9.7
    p = _params_of(acc_lowpass_norm_tol=0.015, g_measured=gm)
    up = np.array([0.6, 0.0, 0.8])
    for f, ok in ((0.99, True), (1.01, False), (-0.99, True), (-1.01, False)):
        assert bool(k._lowpass_plausible(gm * (1 + f * 0.015) * up, p, gm)) is ok


def test_learned_gravity_is_a_running_mean_then_a_moving_one_within_the_scale_band(k):
    """While no rest measured gravity: the low-passed force's norm averaged, 1/n until the
    average spans MOTION_SLOW × acc_lowpass_s (gain dyn_k2), the nominal g in use until
    then; after it the average when within acc_scale_tol of g, else the nominal."""
    p = _params_of(acc_scale_tol=0.02)
    n_slow = math.ceil(1.0 / p.dyn_k2)
    norms = G * (1.018 + 0.004 * np.sin(np.arange(3 * n_slow)))
    g, n, ref = G, 0.0, G
    for i, x in enumerate(norms):
        g, n, used = k._learn_gravity(np.array([0.0, 0.6, 0.8]) * x, p, g, n)
        ref += max(p.dyn_k2, 1.0 / (i + 1)) * (x - ref)
        assert g == pytest.approx(ref, rel=1e-14) and n == i + 1
        assert used == (G if 1.0 / (i + 1) > p.dyn_k2 else g)
    assert used == pytest.approx(1.018 * G, rel=2e-3)
    # a norm further off than the band is not taken for gravity's
    for off, in_use in ((0.019, True), (0.021, False), (-0.019, True), (-0.021, False)):
        assert k._gravity_in_use(G * (1 + off), p) == (G * (1 + off) if in_use else G)


# ------------------------------------------------------------------ 5b. raw accelerometer
@pytest.mark.parametrize("nx", [9, 12])
def test_raw_model_jacobian_and_innovation(k, nx):
    """``f = C_b_n g_up + a_b (+ δb_a)``: H = [[v̂×], 0, I (, I)] against finite differences
    of that model in the attitude error, the manoeuvre and bias states; the innovation
    f − (v̂ + â) − H dx."""
    p = _params_of(acc_model="raw")
    H, y, v = np.zeros((3, nx)), np.empty(3), np.empty(3)
    accel = np.array([0.3, -0.2, 0.1])
    dx = np.arange(1, nx + 1) * 1e-3
    fk = np.array([1.0, 2.0, 9.0])

    def model(e):
        c_true = dcm_from_quat(quat_multiply(Q_HAT, _q(e[:3])))
        return c_true.T @ G_UP + accel + e[3:6] + (e[6:] if nx == 12 else 0)

    k._acc_raw_model(p, accel, C_HAT, fk, v, dx, H, y)
    fd = _fd_jacobian(model, nx - 3)
    assert np.allclose(v, C_HAT.T @ G_UP, rtol=0, atol=1e-14)
    assert np.allclose(H[:, :3], fd[:, :3], rtol=0, atol=1e-8)
    assert np.all(H[:, 3:6] == 0)
    assert np.allclose(H[:, 6:], fd[:, 3:], rtol=0, atol=1e-9)
    assert np.allclose(y, fk - v - accel - H @ dx, rtol=0, atol=1e-14)


def test_raw_model_plausibility_lever_arm_and_recovery(k):
    """Skip when |‖f‖ − g| > acc_norm_tol · g (never without gating); the lever term
    arm · (|ω − b|² + |ω̇|); recovery adds recover_angle² to the tilt and σ_Singer² to the
    manoeuvre variances."""
    p = _params_of(acc_model="raw", acc_norm_tol=0.25)
    up = np.array([0.0, 0.6, 0.8])
    assert k._acc_plausible(G * 1.249 * up, p) and not k._acc_plausible(G * 1.251 * up, p)
    assert k._acc_plausible(G * 0.751 * up, p) and not k._acc_plausible(G * 0.749 * up, p)
    assert k._acc_plausible(G * 3 * up, p._replace(gating=False))
    h, arm = 0.01, 0.2
    x = np.array([[0.5, 1.0, -1.0], [0.7, 0.8, -1.1], [0.0, 0.0, 0.0]])
    b = np.array([0.1, 0.0, 0.2])
    w, wd = x[1] - b, (x[1] - x[0]) / h
    expect = arm * (w @ w + np.linalg.norm(wd))
    assert k._lever_sigma(1, x, h, True, b, arm) == pytest.approx(expect, rel=1e-14)
    P = np.zeros((9, 9))
    assert k._acc_recovery(p, P) == K.F_ACC_RECOVERED
    assert np.allclose(np.diag(P), [0.1**2] * 3 + [0] * 3 + [4.0] * 3, rtol=1e-15)
    P = np.zeros((6, 6))
    k._acc_recovery(p._replace(acc_lowpass=True), P)
    assert np.allclose(np.diag(P), [0.01] * 3 + [0] * 3, rtol=1e-15)


def test_lever_sigma_on_increments_is_causal(k):
    """An epoch ending at sample k may use increments up to interval k − 1 → k (``x[k − 1]``,
    as the rest detector does), never ``x[k]``, which ends at sample k + 1."""
    h, b, arm = 0.01, np.array([0.1, 0.0, 0.2]), 0.2
    rates = np.array([[0.1, 0.2, 0.3], [0.5, 1.0, -1.0], [0.7, 0.8, -1.1], [9.0, 9.0, 9.0]])
    x = rates * h  # increments: x[i] is the interval from sample i to i + 1
    w, wd = x[1] / h - b, (x[1] - x[0]) / h**2
    expect = arm * (w @ w + np.linalg.norm(wd))
    assert k._lever_sigma(2, x, h, False, b, arm) == pytest.approx(expect, rel=1e-12)


# ------------------------------------------------------------------ 6. magnetometer
def _heading_of(dtheta):
    """The heading the estimate C_HAT measures when the truth is q̂ ⊗ q(δθ): the body field
    C_trueᵀ m_ref turned into the reference frame with C_HAT."""
    c_true = dcm_from_quat(quat_multiply(Q_HAT, _q(dtheta)))
    m = C_HAT @ c_true.T @ M_REF
    return np.array([math.atan2(m[1], m[0])])


def test_heading_model_jacobian_and_innovation(k):
    """H (heading row and, through the 60° dip, the tilt rows) against finite differences of
    the measured heading in the attitude error; the innovation atan2(m_n) − ψ_ref − H dx."""
    p = _params_of()
    H, y = np.zeros((1, 6)), np.empty(1)
    dx = np.array([1e-3, -2e-3, 3e-3, 0.5, 0.5, 0.5])
    truth = _q([0.01, -0.02, 0.03])
    mn = C_HAT @ dcm_from_quat(quat_multiply(Q_HAT, truth)).T @ M_REF
    k._heading_model(p.ref_heading, C_HAT, M_REF.copy(), np.zeros(6), H, y)
    fd = _fd_jacobian(_heading_of, 3)
    assert np.allclose(H[:, :3], fd, rtol=0, atol=1e-9)
    assert np.all(H[:, 3:] == 0) and abs(y[0]) < 1e-14
    assert np.linalg.norm(H[0, :3] + C_HAT[2]) > 1.0  # the dip's tilt rows are there
    k._heading_model(p.ref_heading, C_HAT, mn, dx, H, y)
    assert y[0] == pytest.approx(math.atan2(mn[1], mn[0]) - REF[2] - H[0] @ dx, abs=1e-15)


def test_heading_innovation_is_wrapped(k):
    """A heading of 179° against a reference of −179° is 2° of innovation, not −358°."""
    H, y = np.zeros((1, 6)), np.empty(1)
    for ref, head, expect in ((-179.0, 179.0, -2.0), (179.0, -179.0, 2.0)):
        p = _params_of()._replace(ref_heading=math.radians(ref))
        mn = np.array([math.cos(math.radians(head)), math.sin(math.radians(head)), -1.0])
        k._heading_model(p.ref_heading, np.eye(3), mn, np.zeros(6), H, y)
        assert math.degrees(y[0]) == pytest.approx(expect, abs=1e-12)


def _consider(k, P, H, r, y, gate=1e9, force=False):
    dx = np.zeros(P.shape[0])
    out = k._consider_update(P, H, r, y, gate, True, force, dx, C_HAT, np.empty(P.shape[0]),
                             np.empty(P.shape[0]), 6)
    return out, dx


@pytest.mark.parametrize("nx", [6, 9])
def test_consider_update_gain_stays_off_roll_and_pitch(k, nx):
    """S = H P Hᵀ + r with the full H; K = P Hᵀ/S with its attitude part projected on the
    body-frame vertical c and zero beyond the gyro bias; P by the Joseph form
    (I − K H) P (I − K H)ᵀ + K r Kᵀ, computed here in matrix form."""
    rng = np.random.default_rng(nx)
    P = _spd(rng, nx)
    H = np.zeros((1, nx))
    H[0, :3] = [0.4, -0.9, 0.3]
    r, y = 2e-4, np.array([0.05])
    P0 = P.copy()
    S = (H @ P0 @ H.T)[0, 0] + r
    kk = (P0 @ H.T)[:, 0] / S
    c = C_HAT[2]
    kk[:3] = c * (c @ kk[:3])
    kk[6:] = 0.0
    A = np.eye(nx) - np.outer(kk, H[0])
    joseph = A @ P0 @ A.T + r * np.outer(kk, kk)
    (nis, ok, s_out), dx = _consider(k, P, H, r, y)
    assert ok and nis == pytest.approx(0.05**2 / S, rel=1e-13)
    assert s_out == pytest.approx(S, rel=1e-13)
    assert np.allclose(dx, kk * 0.05, rtol=1e-12, atol=1e-18)
    assert np.allclose(P, joseph, rtol=1e-10, atol=1e-16)
    tilt = (C_HAT @ dx[:3])[:2]  # the correction in the reference frame: only about up
    assert np.abs(tilt).max() < 1e-15 * np.linalg.norm(dx[:3])


def test_consider_update_is_the_kalman_update_when_the_projection_is_neutral(k):
    """No dip (H = −c) and an attitude covariance isotropic about c: the projected gain is
    the Kalman gain and P the textbook P − K S Kᵀ."""
    c = C_HAT[2]
    P = np.diag([1e-3] * 3 + [1e-5] * 3)
    P[:3, 3:] = P[3:, :3] = -2e-6 * np.outer(c, c)
    H = np.hstack([-c, np.zeros(3)])[None]
    r = 1e-4
    S = (H @ P @ H.T)[0, 0] + r
    kk = (P @ H.T)[:, 0] / S
    expect = P - S * np.outer(kk, kk)
    (_, ok, _), dx = _consider(k, P, H, r, np.array([0.1]))
    assert ok and np.allclose(dx, 0.1 * kk, rtol=1e-13, atol=0)
    assert np.allclose(P, expect, rtol=1e-12, atol=1e-20)


def test_consider_update_gate(k):
    """NIS beyond the gate: rejected, P and dx untouched; forced (recovery): accepted."""
    P = np.diag([1e-4] * 3 + [1e-6] * 3)
    H = np.hstack([-C_HAT[2], np.zeros(3)])[None]
    nis_expect = 0.05**2 / (1e-4 + 1e-4)
    (nis, ok, s_out), dx = _consider(k, P, H, 1e-4, np.array([0.05]), gate=0.99 * nis_expect)
    assert not ok and nis == pytest.approx(nis_expect, rel=1e-12)
    assert s_out == pytest.approx(2e-4, rel=1e-12)  # S also when rejected
    assert np.array_equal(P, np.diag([1e-4] * 3 + [1e-6] * 3)) and not dx.any()
    (_, ok, _), dx = _consider(k, P, H, 1e-4, np.array([0.05]), gate=1.01 * nis_expect)
    assert ok and dx.any()
    P = np.diag([1e-4] * 3 + [1e-6] * 3)
    (_, ok, _), _ = _consider(k, P, H, 1e-4, np.array([0.05]), gate=0.5 * nis_expect,
                              force=True)
    assert ok


def _level(k, P, H, kc, r, y, gate=1e9, soft=False, force=False):
    n = P.shape[0]
    dx = np.zeros(n)
    out = k._level_update(P, H, kc, r, y, gate, True, force, soft, dx, C_HAT,
                          np.empty((n, 2)), np.empty(n), np.empty(n), np.empty((2, 2)),
                          np.empty((2, 2)))
    return out, dx


def _level_expected(P, H, r, y):
    """Row after row in matrix form: K = P hᵀ/s with its attitude part projected off the
    body-frame vertical c, P by the Joseph form (I − K h) P (I − K h)ᵀ + K r Kᵀ, the row's
    innovation less h times the earlier rows' correction."""
    P = P.copy()
    c = C_HAT[2]
    dx = np.zeros(P.shape[0])
    for h, yj in zip(H, y, strict=True):
        s = h @ P @ h + r
        kk = P @ h / s
        kk[:3] -= c * (c @ kk[:3])
        A = np.eye(P.shape[0]) - np.outer(kk, h)
        P = A @ P @ A.T + r * np.outer(kk, kk)
        dx += kk * (yj - h @ dx)
    return P, dx


@pytest.mark.parametrize("nx", [6, 9, 12])
def test_level_update_gain_stays_off_the_heading(k, nx):
    """The accelerometer's update without a magnetometer (6-axis): each row's gain has its
    attitude part projected off the reference vertical, P by the Joseph form for it; the
    correction turns the estimate about horizontal axes only, while the full Kalman update
    (:func:`_gated_update`) on the same correlated P turns the heading too."""
    rng = np.random.default_rng(nx)
    P = _spd(rng, nx)
    H = np.zeros((2, nx))
    H[0, :3] = -G * C_HAT[1]  # the low-pass model's rows (_acc_lowpass_model)
    H[1, :3] = G * C_HAT[0]
    kc = 3 if nx == 6 else nx
    r, y = 4e-4, np.array([0.03, -0.02])
    P0 = P.copy()
    S = H @ P0 @ H.T + r * np.eye(2)
    P_exp, dx_exp = _level_expected(P0, H, r, y)
    (nis, ok), dx = _level(k, P, H, kc, r, y)
    assert ok and nis == pytest.approx(y @ np.linalg.solve(S, y), rel=1e-12)
    assert np.allclose(dx, dx_exp, rtol=1e-11, atol=1e-18)
    assert np.allclose(P, P_exp, rtol=1e-10, atol=1e-16)
    up = (C_HAT @ dx[:3])[2]  # the correction in the reference frame: none about up
    assert abs(up) < 1e-15 * np.linalg.norm(dx[:3])
    full = np.zeros(nx)
    k._gated_update(P0.copy(), H, kc, r, y, 1e9, True, False, False, full,
                    np.empty((nx, 2)), np.empty((2, 2)), np.empty((2, 2)))
    assert abs((C_HAT @ full[:3])[2]) > 1e-3 * np.linalg.norm(full[:3])


def test_level_update_is_the_kalman_update_when_the_projection_is_neutral(k):
    """An attitude covariance with no heading part (isotropic in the horizontal, nothing
    about c) and no correlation with it: the projected gain is the Kalman gain, and the
    result equals :func:`_gated_update`'s."""
    c = C_HAT[2]
    horiz = np.eye(3) - np.outer(c, c)
    P = np.zeros((6, 6))
    P[:3, :3] = 1e-3 * horiz
    P[3:, 3:] = 1e-5 * np.eye(3)
    H = np.zeros((2, 6))
    H[0, :3] = -G * C_HAT[1]
    H[1, :3] = G * C_HAT[0]
    y = np.array([0.03, -0.02])
    (_, ok), dx = _level(k, P.copy(), H, 3, 4e-4, y)
    full = np.zeros(6)
    Pf = P.copy()
    k._gated_update(Pf, H, 3, 4e-4, y, 1e9, True, False, False, full, np.empty((6, 2)),
                    np.empty((2, 2)), np.empty((2, 2)))
    assert ok and np.allclose(dx, full, rtol=1e-12, atol=1e-18)


def test_level_update_gate(k):
    """NIS beyond a hard gate: rejected, P and dx untouched; a soft gate scales r by
    NIS/gate; forced: accepted."""
    P = np.diag([1e-4] * 3 + [1e-6] * 3)
    H = np.zeros((2, 6))
    H[0, :3] = -G * C_HAT[1]
    H[1, :3] = G * C_HAT[0]
    y = np.array([0.05, 0.02])
    S = H @ P @ H.T + 1e-4 * np.eye(2)
    nis_expect = y @ np.linalg.solve(S, y)
    (nis, ok), dx = _level(k, P, H, 3, 1e-4, y, gate=0.99 * nis_expect)
    assert not ok and nis == pytest.approx(nis_expect, rel=1e-12)
    assert np.array_equal(P, np.diag([1e-4] * 3 + [1e-6] * 3)) and not dx.any()
    (_, ok), dx = _level(k, P.copy(), H, 3, 1e-4, y, gate=0.5 * nis_expect, soft=True)
    _, dx_exp = _level_expected(P, H, 1e-4 * 2.0, y)
    assert ok and np.allclose(dx, dx_exp, rtol=1e-11, atol=1e-18)
    (_, ok), _ = _level(k, P.copy(), H, 3, 1e-4, y, gate=0.5 * nis_expect, force=True)
    assert ok


def _ms(p, norm=REF[0], dip=REF[1], undisturbed=None):
    """The disturbance state as the kernel starts it."""
    ms = np.zeros(8)
    ms[[K.M_NORM, K.M_CNORM]] = norm
    ms[[K.M_DIP, K.M_CDIP]] = dip
    ms[K.M_UNDIST] = p.mag_settle_s if undisturbed is None else undisturbed
    return ms


@pytest.mark.parametrize("unit", [1.0, 0.01, 1000.0])
def test_mag_disturbance_thresholds_are_relative(k, unit):
    """Disturbed when the low-passed norm departs from the learned one by more than
    mag_norm_tol of it, or the dip by more than mag_dip_tol; the same decisions in any unit
    (the norm and reference scaled together)."""
    p = _params_of(mag_norm_tol=0.12, mag_dip_tol=0.1)
    T = 0.01
    for f_norm, f_dip, disturbed in ((0.99, 0, False), (1.01, 0, True), (-0.99, 0, False),
                                     (-1.01, 0, True), (0, 0.99, False), (0, 1.01, True),
                                     (0, -0.99, False), (0, -1.01, True)):
        ms = _ms(p, REF[0] * unit)
        nd = np.array([REF[0] * unit * (1 + f_norm * 0.12), REF[1] + f_dip * 0.1])
        assert bool(k._mag_disturbance(T, 0.0, p, nd, ms)) is disturbed, (f_norm, f_dip)
        assert ms[K.M_DIST] == disturbed


def test_mag_disturbance_settles_and_learns_the_reference(k):
    """After a disturbance the field must agree for mag_settle_s before it is undisturbed;
    then the reference follows it with gain mag_ref_k = 1 − e^{−T/mag_reference_s}."""
    p = _params_of(mag_settle_s=0.5, mag_reference_s=20.0)
    T = 0.01
    assert p.mag_ref_k == pytest.approx(1 - math.exp(-T / 20.0), rel=1e-15)
    ms = _ms(p)
    assert k._mag_disturbance(T, 0.0, p, np.array([1.5 * REF[0], REF[1]]), ms)
    nd = np.array([1.05 * REF[0], REF[1] + 0.02])
    flags = [k._mag_disturbance(T, 0.0, p, nd, ms) for _ in range(60)]
    assert flags.index(False) == 49  # the 50th sample within the tolerances: 0.5 s
    norm = REF[0]
    for _ in range(60 - 49):  # the reference learned on the undisturbed samples only
        norm += p.mag_ref_k * (nd[0] - norm)
    assert ms[K.M_NORM] == pytest.approx(norm, rel=1e-14)


def test_mag_disturbance_accepts_a_new_field_only_with_rotation(k):
    """A field consistent with itself (the candidate) for mag_new_s of rotation faster than
    mag_new_min_rate becomes the reference (a new place); without rotation (a magnet that
    turns with the sensor) it never does."""
    p = _params_of(mag_new_s=1.5625, mag_new_min_rate=0.35)  # 200 T, exactly
    T, new = 1 / 128, np.array([1.4 * REF[0], REF[1] - 0.3])
    for rate, accepted_at in ((0.36, 200), (0.34, None)):
        ms = _ms(p)
        flags = [k._mag_disturbance(T, rate**2, p, new, ms) for _ in range(300)]
        first = flags.index(False) if False in flags else None
        # sample 0 makes the candidate; samples 1 … 200 add up to mag_new_s
        assert first == accepted_at, rate
        if accepted_at:
            assert ms[K.M_NORM] == pytest.approx(new[0], rel=1e-14)


def test_mag_rejection_budget_refills_faster_than_it_drains(k):
    """The time rejected (counted by the loop while disturbed) shrinks by
    mag_disturbed_factor × T per undisturbed sample, not below zero."""
    p = _params_of(mag_disturbed_factor=2.0)
    ms = _ms(p)
    ms[K.M_REJECT] = 0.05
    nd = np.array(REF[:2])
    k._mag_disturbance(0.01, 0.0, p, nd, ms)
    assert ms[K.M_REJECT] == pytest.approx(0.03, abs=1e-16)
    k._mag_disturbance(0.01, 0.0, p, nd, ms)
    k._mag_disturbance(0.01, 0.0, p, nd, ms)
    assert ms[K.M_REJECT] == 0.0


def test_disturbed_factor_and_mag_recovery(k):
    """The heading noise's factor for a disturbed field used beyond the budget: factor ×
    max(1, departure in tolerances)^(2·power); recovery adds recover_angle² about the
    reference vertical only."""
    p = _params_of(mag_disturbed_factor=3.0, mag_disturbed_power=0.5, mag_norm_tol=0.1,
                   mag_dip_tol=0.2)
    ms = _ms(p)
    nd = np.array([REF[0] * 1.25, REF[1] + 0.3])  # 2.5 and 1.5 tolerances
    assert k._disturbed_factor(p, nd, ms) == pytest.approx(3.0 * 2.5, rel=1e-14)
    nd = np.array([REF[0] * 1.05, REF[1] - 0.1])  # inside: at least 1
    assert k._disturbed_factor(p, nd, ms) == pytest.approx(3.0, rel=1e-15)
    P = np.zeros((6, 6))
    assert k._mag_recovery(P, C_HAT, 0.01) == K.F_MAG_RECOVERED
    assert np.allclose(P[:3, :3], 0.01 * np.outer(C_HAT[2], C_HAT[2]), rtol=0, atol=1e-17)
    assert not P[3:].any()


@pytest.mark.parametrize("tau", [0.5, 2.0])
def test_provisional_heading_is_a_lowpass_of_the_field(tau):
    """A start in motion's heading while the field's reference is provisional: its variance
    grows by ``heading_noise² T / τ²`` per epoch against the field's ``heading_noise² / T``,
    so the steady gain K is that of a first-order low-pass of time constant τ: the
    Riccati recursion's fixed point has ``K² / (1 − K) = (T / τ)²``, ``K ≈ T / τ`` per
    epoch, at 50 Hz as at 400 Hz."""
    cfg = AhrsConfig(moving_start_heading_s=tau)
    for h in (0.02, 0.0025):
        p = _params_of(moving_start_heading_s=tau, h=h)
        assert p.provisional_heading_q == pytest.approx((cfg.heading_noise / tau) ** 2,
                                                        rel=1e-15)
        r = cfg.heading_noise ** 2 / h
        v = 1.0
        for _ in range(20000):  # the scalar Riccati recursion to its steady state
            v += h * p.provisional_heading_q
            v -= v * v / (v + r)
        gain = v / r  # the gain on the last measurement
        assert gain ** 2 / (1.0 - gain) == pytest.approx((h / tau) ** 2, rel=1e-9)
        assert gain == pytest.approx(h / tau, rel=h / tau)


@pytest.mark.parametrize("delay", [0, 2, 4])
def test_delay_estimator_finds_the_magnetometer_lag(k, delay):
    """A field fixed in the reference frame turns in the body as ṁ = −ω × m; a magnetometer
    ``delay`` samples late matches the gyro that many samples earlier: the residual's
    argmin over the candidates 0 … 5 is the delay."""
    h, n = 0.01, 600
    t = np.arange(n) * h
    w = np.stack([2.0 * np.sin(3 * t), 1.5 * np.cos(2 * t), 1.0 + 0 * t], axis=1)
    q = np.empty((n, 4))
    q[0] = Q_HAT
    for i in range(1, n):  # exact for the interval's mean rate, which the estimator uses
        q[i] = quat_multiply(q[i - 1], _q(0.5 * h * (w[i] + w[i - 1])))
    m = np.einsum("nji,j->ni", dcm_from_quat(q), M_REF)
    mag = np.vstack([np.repeat(m[:1], delay, 0), m[:n - delay]])
    res = np.zeros(6)
    no_offset = np.zeros((7, 3))  # the online hard-iron state: no offset applied
    last, seen = k._fold_delay_samples(0, n - 1, 0, w, mag, no_offset, h, True, np.zeros(3),
                                       0.01, res)
    assert (last, seen) == (n - 1, n - 1 - 6)
    assert int(np.argmin(res)) == delay
    assert np.sort(res)[1] > 10 * res.min()


# ------------------------------------------------------------------ 7. reset
@pytest.mark.parametrize("nx, singer, lag", [(6, False, 1), (9, True, 3), (12, True, 1),
                                             (9, False, 2)])
def test_reset_injects_the_error_state(k, nx, singer, lag):
    """q ← q(C δθ) ⊗ q, which is q ⊗ q(δθ) exactly (q(C v) = q ⊗ q(v) ⊗ q*), unit; the
    sliding bases turn by the same reference-frame rotation and ring row ``slot`` gets q;
    biases and the manoeuvre state add their corrections; P is symmetrised — and nothing
    more: the reset Jacobian I − ½[δθ×] of an error-state filter is not applied."""
    rng = np.random.default_rng(nx + lag)
    q = Q_HAT.copy()
    ring = np.array([quat_multiply(_q(rng.standard_normal(3)), Q_HAT) for _ in range(lag)])
    ring0 = ring.copy()
    dx = 1e-3 * rng.standard_normal(nx)
    bias, accel, acc_bias = (rng.standard_normal(3) for _ in range(3))
    b0, a0, ab0 = bias.copy(), accel.copy(), acc_bias.copy()
    P = _spd(rng, nx)
    P[0, 1] += 1e-9  # asymmetric by rounding
    P0 = P.copy()
    eps = np.empty(3)
    k._reset(lag - 1, q, ring, bias, accel, acc_bias, P, C_HAT, dx, eps, singer)
    assert np.allclose(eps, C_HAT @ dx[:3], rtol=0, atol=1e-18)
    assert np.allclose(q, quat_multiply(Q_HAT, _q(dx[:3])), rtol=0, atol=1e-15)
    assert abs(q @ q - 1.0) < 4e-16
    for r in range(lag - 1):
        assert np.allclose(ring[r], quat_multiply(_q(eps), ring0[r]), rtol=0, atol=1e-15)
    assert np.array_equal(ring[lag - 1], q)
    assert np.allclose(bias, b0 + dx[3:6], rtol=0, atol=1e-15)
    assert np.array_equal(accel, a0 + dx[6:9] if singer else a0)
    with_ab = nx > (9 if singer else 6)
    assert np.array_equal(acc_bias, ab0 + dx[-3:] if with_ab else ab0)
    assert np.array_equal(P, P.T) and np.array_equal(P, 0.5 * (P0 + P0.T))


# ------------------------------------------------------------------ gating and recovery
@pytest.mark.parametrize("m", [1, 2, 3])
def test_gated_update_is_the_joint_kalman_update(k, m):
    """Row by row (R = r I) equals the joint update K = P Hᵀ S⁻¹, P − K S Kᵀ, and the NIS is
    yᵀ S⁻¹ y; beyond a hard gate P and dx stay untouched, beyond a soft one R is scaled
    by NIS/gate; ``force`` skips the gate; H beyond ``kc`` columns is ignored."""
    rng = np.random.default_rng(m)
    nx, kc = 9, 6
    P0 = _spd(rng, nx)
    H = np.zeros((m, nx))
    H[:, :kc] = rng.standard_normal((m, kc))
    y, r = 0.05 * rng.standard_normal(m), 2e-4

    def joint(r):
        S = H @ P0 @ H.T + r * np.eye(m)
        Kg = P0 @ H.T @ np.linalg.inv(S)
        return Kg @ y, P0 - Kg @ S @ Kg.T, y @ np.linalg.solve(S, y)

    def run(gate, gating=True, force=False, soft=False):
        P, dx = P0.copy(), np.zeros(nx)
        nis, ok = k._gated_update(P, H, kc, r, y, gate, gating, force, soft, dx,
                                  np.empty((nx, m)), np.empty((m, m)), np.empty((m, m)))
        return P, dx, nis, ok

    dx_j, P_j, nis_j = joint(r)
    P, dx, nis, ok = run(1e9)
    assert ok and nis == pytest.approx(nis_j, rel=1e-12)
    assert np.allclose(dx, dx_j, rtol=1e-11, atol=1e-17)
    assert np.allclose(P, P_j, rtol=1e-10, atol=1e-17)
    assert run(1e9, gating=False)[2] == 0.0
    P, dx, nis, ok = run(0.5 * nis_j)
    assert not ok and np.array_equal(P, P0) and not dx.any()
    P, dx, _, ok = run(0.5 * nis_j, force=True)
    assert ok and np.allclose(dx, dx_j, rtol=1e-11, atol=1e-17)
    dx_s, P_s, _ = joint(r * 2.0)
    P, dx, _, ok = run(0.5 * nis_j, soft=True)
    assert ok and np.allclose(dx, dx_s, rtol=1e-11, atol=1e-17)
    assert np.allclose(P, P_s, rtol=1e-10, atol=1e-17)


def test_inverse_of_small_symmetric_matrices(k):
    rng = np.random.default_rng(9)
    for m in (1, 2, 3):
        S = _spd(rng, m, 1.0)
        out = np.empty((m, m))
        k._inverse_sym(S, m, out)
        assert np.allclose(out, np.linalg.inv(S), rtol=1e-13, atol=0)


def test_recovery_and_outcome_rules(k):
    """Recovery is due when gating, the sensor looks clean and rejections have lasted longer
    than the limit; an accepted update clears the run of rejections, a rejection starts it
    (or keeps its start)."""
    assert k._recovery_due(True, True, 1.0, 3.01, 2.0)
    assert not k._recovery_due(True, True, 1.0, 2.99, 2.0)
    assert not k._recovery_due(True, False, 1.0, 9.0, 2.0)
    assert not k._recovery_due(False, True, 1.0, 9.0, 2.0)
    assert not k._recovery_due(True, True, -1.0, 9.0, 2.0)
    assert k._outcome(True, 5.0, 1.0, 1, 2) == (1, -1.0)
    assert k._outcome(False, 5.0, -1.0, 1, 2) == (2, 5.0)
    assert k._outcome(False, 5.0, 1.0, 1, 2) == (2, 1.0)


# ------------------------------------------------------------------ the loop's own rules
def _still(n, h, bias=(0.0, 0.0, 0.0), mag_scale=None):
    """A sensor at rest in attitude Q_HAT: (t, gyro, acc, mag)."""
    t = np.arange(n) * h
    gyro = np.tile(np.asarray(bias, float), (n, 1))
    acc = np.tile(C_HAT.T @ G_UP, (n, 1))
    mag = np.tile(C_HAT.T @ M_REF, (n, 1))
    if mag_scale is not None:
        mag = mag * mag_scale[:, None]
    return t, gyro, acc, mag


@pytest.mark.parametrize("rest_min_s, first", [(0.5, 129), (0.0, 65)])
def test_zero_rate_updates_start_once_rest_has_lasted_rest_min_s(rest_min_s, first):
    """At h = 1/128 s and rest_tau = 0.5 s the detector is settled from sample 65
    (65 · h/rest_tau > 1); the first zero-rate update (REST) comes rest_min_s later."""
    h = 1 / 128
    t, gyro, acc, mag = _still(400, h, bias=(0.01, -0.005, 0.002))
    r = ekf(t, gyro, acc, mag, q0=Q_HAT, config=AhrsConfig(rest_min_s=rest_min_s,
                                                          rest_tau=0.5, gyro_sample="point"))
    rest = (r.flags & Flag.REST) != 0
    assert int(np.argmax(rest)) == first and rest[first:].all()
    assert r.gyro_bias[-1] == pytest.approx([0.01, -0.005, 0.002], abs=2e-4)


def test_a_disturbed_field_is_rejected_for_mag_reject_s_then_used():
    """A field 40 % too strong from 5 s on: disturbed (after the norm's low-pass) and
    rejected for mag_reject_s (2 s) of budget, then used (de-weighted) — the heading update
    runs again, its NIS gate still deciding."""
    h = 0.01
    n = 1200
    scale = np.where(np.arange(n) * h >= 5.0, 1.4, 1.0)
    t, gyro, acc, mag = _still(n, h, mag_scale=scale)
    r = ekf(t, gyro, acc, mag, q0=Q_HAT, mag_reference=M_REF,
            config=AhrsConfig(mag_reject_s=2.0, gyro_sample="point"))
    dist = (r.flags & Flag.MAG_DISTURBED) != 0
    heading = (r.flags & (Flag.MAG_USED | Flag.MAG_REJECTED)) != 0
    assert not dist[:500].any() and heading[1:500].all()
    start = int(np.argmax(dist))
    assert 500 <= start <= 505  # the norm's 0.05 s low-pass crosses 12 % within 5 samples
    assert dist[start:].all()
    skipped = np.flatnonzero(dist & ~heading)
    assert skipped[0] == start and np.all(np.diff(skipped) == 1)
    assert skipped.size == pytest.approx(2.0 / h, abs=1)  # the budget
    assert heading[skipped[-1] + 1:].all()


def test_a_disturbed_field_used_de_weighted_does_not_teach_the_gyro_bias():
    """From 5 s on the field is 40 % too strong and turned 3° in heading: disturbed,
    rejected for mag_reject_s (2 s), then used de-weighted. Its error is the disturbance's,
    not white noise, so those updates pull the heading but leave the gyro bias alone (the
    accelerometer and the rest update off, so that only the field could move it); the
    same field, undisturbed (norm kept, the reference's tolerances wide), teaches it."""
    h = 0.01
    n = 1200
    late = np.arange(n) * h >= 5.0
    t, gyro, acc, mag = _still(n, h)
    turned = C_HAT.T @ dcm_from_quat(quat_from_rotvec(np.radians([0.0, 0.0, 3.0]))) @ M_REF
    cfg = AhrsConfig(mag_reject_s=2.0, gyro_sample="point", use_accelerometer=False,
                     rest_update=False)
    for strong, tol in ((1.4, 0.12), (1.0, 0.5)):
        m = np.where(late[:, None], strong * turned, mag)
        r = ekf(t, gyro, acc, m, q0=Q_HAT, mag_reference=M_REF,
                config=replace(cfg, mag_norm_tol=tol, mag_dip_tol=tol))
        used = (r.flags & Flag.MAG_USED) != 0
        dist = (r.flags & Flag.MAG_DISTURBED) != 0
        if strong > 1.0:
            step = np.abs(np.diff(r.gyro_bias, axis=0)).max(axis=1)
            de_weighted = np.flatnonzero(used & dist)
            assert de_weighted.size > 400  # the last 5 s
            assert np.all(step[de_weighted - 1] == 0.0)
            start = int(np.argmax(dist))  # the norm's low-pass is over the tolerance
            assert np.abs(r.gyro_bias[-1] - r.gyro_bias[start - 1]).max() < 1e-15
        else:
            assert not dist.any() and np.count_nonzero(used[500:]) > 400
            assert np.abs(r.gyro_bias[-1] - r.gyro_bias[499]).max() > 1e-6
