"""The AHRS filter loop, compiled with numba (``cache=True``). Private.

:func:`ekf_kernel` runs the whole multiplicative error-state EKF of
:mod:`strapdown.ahrs` (Wang, Wang & Wang, eqs. 30–35, made well-posed) over a
record as ONE compiled loop. Each epoch runs the stages in order; each stage is
a small function that numba inlines into the loop (``inline="always"``):

1. propagation of the attitude on the bias-corrected gyro — :func:`_window_step`
   (a windowed rotation-vector algorithm: any of the library's rate or
   increment forms, conventional or sliding), :func:`_startup_step` (the
   sliding scheme's first outputs) or :func:`_rk4_step` (quaternion RK4);
2. :func:`_fold_rest_samples` — the rest detector's moving averages;
3. :func:`_process_noise` and :func:`_propagate_covariance` — ``P ← Φ P Φᵀ + Q``;
4. :func:`_rest_detect` and :func:`_rest_model` — the zero-rate bias update;
5. the accelerometer: recovery (:func:`_acc_recovery`), then the model of
   ``AhrsConfig.acc_model`` — :func:`_acc_lowpass_model` (Laidig & Seel
   (2023) — VQF's idea) or :func:`_acc_plausible`, :func:`_lever_sigma` and
   :func:`_acc_raw_model` (the Singer (1970) manoeuvre state);
6. the magnetometer as a heading measurement: :func:`_mag_plausible`, the
   settling time, recovery (:func:`_mag_recovery`), :func:`_heading_model`;
7. :func:`_reset` — error-state injection into the attitude, the biases and the
   sliding scheme's bases (and :func:`_rotate_small` for the averaged specific force);
8. the record: one row of :class:`Outputs`.

A measurement model fills H, R and the innovation y; the loop applies it with
the gated Joseph-form update :func:`_joseph`. The public wrapper
(:func:`strapdown.ahrs.filter.ekf`) validates everything; the kernel trusts it.
Its arguments are typed records (:class:`Sensors`, :class:`Propagation`,
:class:`Window`, :class:`Params`, :class:`Initial`, :class:`Outputs`),
NamedTuples that numba passes as structs. It is tested against its own
plain-Python execution and, for accuracy, against exact simulated truth.

Written for speed (the loop allocates nothing per epoch and runs as fast as the
single-function kernel it replaced): numba keeps a reference count per array
bound to an inlined function's argument and removes that count only when
nothing in between can release a reference. So the stages take their arrays one
by one (never a record holding arrays: records that reach a stage hold scalars
only), every array's last use in a stage is unconditional, a stage allocates
nothing and creates no views, and calls to the non-inlined :func:`_joseph` and
the divisions that may raise (Python's ``ZeroDivisionError``) stay out of the
stages where they can.

Measurement noises are densities: an update every ``T`` seconds uses
``R = density² / T``, so the filter's bandwidth does not depend on the
propagation algorithm's update period.

Frames: ENU reference; ``q`` is q_n_b (Hamilton, scalar first). Error state
``x = [δθ_b, δb_g, a_b]`` (``+ δb_a``, the accelerometer bias, when ``P0`` is
12 × 12) with ``q_true = q̂ ⊗ q(δθ_b)``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from strapdown.ahrs.flags import MeasurementFlag
from strapdown.algorithms._kernels import _update

# the flags' values as plain ints: compile-time constants in the loop
F_ACC_USED = int(MeasurementFlag.ACC_USED)
F_ACC_REJECTED = int(MeasurementFlag.ACC_REJECTED)
F_MAG_USED = int(MeasurementFlag.MAG_USED)
F_MAG_REJECTED = int(MeasurementFlag.MAG_REJECTED)
F_MAG_DISTURBED = int(MeasurementFlag.MAG_DISTURBED)
F_REST = int(MeasurementFlag.REST)
F_ACC_RECOVERED = int(MeasurementFlag.ACC_RECOVERED)
F_MAG_RECOVERED = int(MeasurementFlag.MAG_RECOVERED)
F_ACC_DISTURBED = int(MeasurementFlag.ACC_DISTURBED)


class Sensors(NamedTuple):
    """The record: ``x`` is rates (n, 3) if :attr:`Propagation.is_rate`, else increments
    (n − 1, 3); sample ``i`` of ``acc`` / ``mag`` (n, 3) is at time ``i h``."""

    x: np.ndarray
    acc: np.ndarray
    mag: np.ndarray
    h: float


class Propagation(NamedTuple):
    """The attitude algorithm's stepping. Windowed form (:class:`Window`): epoch ``e``
    uses nodes ``x[e·stride + offsets]`` and outputs at sample ``e·stride + end_off``;
    its base attitude is the output ``lag`` epochs earlier (``lag > 1``: the sliding
    scheme, started by single-period steps with pair coefficient ``start_c``).
    ``rk4``: quaternion RK4 over two rate intervals (no window). Scalars only, so the
    stages take it whole (see :func:`ekf_kernel`)."""

    is_rate: bool
    stride: int
    end_off: int
    lag: int
    start_c: float
    rk4: bool


class Window(NamedTuple):
    """The windowed form: node offsets, node weights, and the cross-product pairs
    ``(pi, pj)`` of nodes with coefficients ``pc``."""

    offsets: np.ndarray
    weights: np.ndarray
    pi: np.ndarray
    pj: np.ndarray
    pc: np.ndarray


class Params(NamedTuple):
    """Tuning (the fields of :class:`strapdown.ahrs.AhrsConfig` the loop reads, same
    names and units), the reference field and the switches."""

    gyro_noise: float
    gyro_bias_rw: float
    singer_sigma: float
    singer_tau: float
    acc_noise: float
    heading_noise: float
    acc_gate: float
    mag_gate: float
    mag_norm_tol: float
    mag_dip_tol: float
    ref_norm: float  #: reference field: norm,
    ref_dip: float  #: dip angle (rad, down positive),
    ref_heading: float  #: heading of its horizontal part (rad, from east to north)
    recover_acc_s: float
    recover_mag_s: float
    rest_gyro: float
    rest_acc: float
    rest_noise: float
    rest_tau: float
    use_accelerometer: bool
    use_magnetometer: bool  #: False also without magnetometer data
    gating: bool
    rest_update: bool
    gravity: float
    recover_angle: float
    acc_norm_tol: float
    mag_settle_s: float
    soft_gate: bool  #: acc_gate_mode == "soft"
    lever_arm: float
    acc_lowpass: bool  #: acc_model == "lowpass" (else "raw")
    acc_lowpass_s: float
    acc_lowpass_noise: float
    acc_gate_lowpass: float
    acc_bias_rw: float


class Initial(NamedTuple):
    """Initial q_n_b (4,), gyro bias (3,) and error covariance (9 × 9 or 12 × 12)."""

    q: np.ndarray
    gyro_bias: np.ndarray
    P: np.ndarray


class Outputs(NamedTuple):
    """Output rows, one per epoch (allocated by the caller, at least as many as epochs):
    q (m, 4), gyro_bias, accel, acc_bias (m, 3), sample (the epoch's sample index), flags
    (m,) int64, nis (m, 2) (accelerometer, heading; NaN without an update), attitude_sigma
    (m, 3)."""

    q: np.ndarray
    gyro_bias: np.ndarray
    accel: np.ndarray
    acc_bias: np.ndarray
    sample: np.ndarray
    flags: np.ndarray
    nis: np.ndarray
    attitude_sigma: np.ndarray


# ---------------------------------------------------------------- small numerics
# (Work arrays come from the caller: the loop allocates nothing per epoch.)


@njit(cache=True, inline="always")
def _dcm(q, c):
    """C_n_b of q (3, 3) into c."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    c[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    c[0, 1] = 2.0 * (x * y - w * z)
    c[0, 2] = 2.0 * (x * z + w * y)
    c[1, 0] = 2.0 * (x * y + w * z)
    c[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    c[1, 2] = 2.0 * (y * z - w * x)
    c[2, 0] = 2.0 * (x * z - w * y)
    c[2, 1] = 2.0 * (y * z + w * x)
    c[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, inline="always")
def _small_rotation(eps):
    """(scalar part, vector-part factor) of q(ε) = [cos(|ε|/2), sin(|ε|/2) ε/|ε|]."""
    ang = np.sqrt(eps[0] * eps[0] + eps[1] * eps[1] + eps[2] * eps[2])
    if ang < 1e-8:
        return 1.0 - ang * ang / 8.0, 0.5 - ang * ang / 48.0
    return np.cos(0.5 * ang), np.sin(0.5 * ang) / ang


@njit(cache=True, inline="always")
def _left_rotated(eps, w0, x0, y0, z0):
    """q(ε) ⊗ (w0, x0, y0, z0), normalised (a small reference-frame rotation)."""
    dw, s = _small_rotation(eps)
    ex, ey, ez = s * eps[0], s * eps[1], s * eps[2]
    w = dw * w0 - ex * x0 - ey * y0 - ez * z0
    x = dw * x0 + ex * w0 + ey * z0 - ez * y0
    y = dw * y0 - ex * z0 + ey * w0 + ez * x0
    z = dw * z0 + ex * y0 - ey * x0 + ez * w0
    nrm = np.sqrt(w * w + x * x + y * y + z * z)
    return w / nrm, x / nrm, y / nrm, z / nrm


@njit(cache=True, inline="always")
def _rotate_small(eps, v):
    """v ← (I + [ε×]) v: a vector in the reference frame follows a small rotation ε."""
    l0 = v[0] + eps[1] * v[2] - eps[2] * v[1]
    l1 = v[1] + eps[2] * v[0] - eps[0] * v[2]
    l2 = v[2] + eps[0] * v[1] - eps[1] * v[0]
    v[0] = l0
    v[1] = l1
    v[2] = l2


@njit(cache=True, inline="always")
def _window_phi(x, b, offsets, weights, pi, pj, pc, sa, sb, bias_x, phi, nodes):
    """φ of the windowed form over samples starting at b, bias removed from every node
    (``nodes``: a work array with a row per node)."""
    m = offsets.size
    for n in range(m):
        for a in range(3):
            nodes[n, a] = x[b + offsets[n], a] - bias_x[a]
    phi[0] = 0.0
    phi[1] = 0.0
    phi[2] = 0.0
    for n in range(m):
        for a in range(3):
            phi[a] += sa * weights[n] * nodes[n, a]
    for p in range(pi.size):
        i = pi[p]
        j = pj[p]
        c = sb * pc[p]
        phi[0] += c * (nodes[i, 1] * nodes[j, 2] - nodes[i, 2] * nodes[j, 1])
        phi[1] += c * (nodes[i, 2] * nodes[j, 0] - nodes[i, 0] * nodes[j, 2])
        phi[2] += c * (nodes[i, 0] * nodes[j, 1] - nodes[i, 1] * nodes[j, 0])


@njit(cache=True, inline="always")
def _rk4(q, w, h2, out, k, y):
    """One quaternion RK4 step of length h2 with rates w[0], w[1], w[2] at start, middle,
    end (work arrays k (4, 4), y (4,))."""
    for s in range(4):
        r = 0 if s == 0 else (1 if s < 3 else 2)
        if s == 0:
            for i in range(4):
                y[i] = q[i]
        elif s == 1 or s == 2:
            for i in range(4):
                y[i] = q[i] + 0.5 * h2 * k[s - 1, i]
        else:
            for i in range(4):
                y[i] = q[i] + h2 * k[2, i]
        k[s, 0] = 0.5 * (-y[1] * w[r, 0] - y[2] * w[r, 1] - y[3] * w[r, 2])
        k[s, 1] = 0.5 * (y[0] * w[r, 0] + y[2] * w[r, 2] - y[3] * w[r, 1])
        k[s, 2] = 0.5 * (y[0] * w[r, 1] - y[1] * w[r, 2] + y[3] * w[r, 0])
        k[s, 3] = 0.5 * (y[0] * w[r, 2] + y[1] * w[r, 1] - y[2] * w[r, 0])
    nrm = 0.0
    for i in range(4):
        out[i] = q[i] + h2 / 6.0 * (k[0, i] + 2.0 * k[1, i] + 2.0 * k[2, i] + k[3, i])
        nrm += out[i] * out[i]
    nrm = np.sqrt(nrm)
    for i in range(4):
        out[i] /= nrm


@njit(cache=True, inline="always")
def _inverse_sym(S, m, out):
    """Inverse of a symmetric m × m matrix, m ≤ 3 (explicit cofactors)."""
    if m == 1:
        out[0, 0] = 1.0 / S[0, 0]
    elif m == 2:
        det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
        out[0, 0] = S[1, 1] / det
        out[1, 1] = S[0, 0] / det
        out[0, 1] = -S[0, 1] / det
        out[1, 0] = -S[1, 0] / det
    else:
        a, b, c = S[0, 0], S[0, 1], S[0, 2]
        d, e, f = S[1, 0], S[1, 1], S[1, 2]
        g, h, k = S[2, 0], S[2, 1], S[2, 2]
        c00 = e * k - f * h
        c01 = -(d * k - f * g)
        c02 = d * h - e * g
        det = a * c00 + b * c01 + c * c02
        out[0, 0] = c00 / det
        out[1, 0] = c01 / det
        out[2, 0] = c02 / det
        out[0, 1] = -(b * k - c * h) / det
        out[1, 1] = (a * k - c * g) / det
        out[2, 1] = -(a * h - b * g) / det
        out[0, 2] = (b * f - c * e) / det
        out[1, 2] = -(a * f - c * d) / det
        out[2, 2] = (a * e - b * d) / det


@njit(cache=True, inline="always")
def _mul_bt(X, H, out):
    """out = X Hᵀ (X: n × k, H: m × k)."""
    for i in range(X.shape[0]):
        for j in range(H.shape[0]):
            acc = 0.0
            for k in range(X.shape[1]):
                acc += X[i, k] * H[j, k]
            out[i, j] = acc


@njit(cache=True)
def _joseph(P, H, R, y, gate, gating, force, dx, soft, wk):
    """Gated Joseph-form update of P with (H, R, y); returns (NIS, accepted). dx += K y.

    ``P ← (I − KH) P (I − KH)ᵀ + K R Kᵀ``, written out for m ≤ 3 rows without
    temporaries from BLAS. Beyond the gate a hard gate rejects; a soft gate
    de-weights instead (R scaled by NIS/gate, a Huber-type bounded step).
    ``wk``: work arrays PHᵀ, K, WHᵀ, KR (n × m), W (n × n), S, S⁻¹ (m × m).
    """
    m = y.size
    n = P.shape[0]
    PHt, K, WHt, KR, W, S, Sinv = wk
    _mul_bt(P, H, PHt)
    for i in range(m):
        for j in range(m):
            acc = R[i, j]
            for k in range(n):
                acc += H[i, k] * PHt[k, j]
            S[i, j] = acc
    _inverse_sym(S, m, Sinv)
    nis = 0.0
    for i in range(m):
        for j in range(m):
            nis += y[i] * Sinv[i, j] * y[j]
    scale = 1.0
    if gating and nis > gate and not force:
        if not soft:
            return nis, False
        scale = nis / gate
        for i in range(m):
            for j in range(m):
                S[i, j] += (scale - 1.0) * R[i, j]
        _inverse_sym(S, m, Sinv)
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += PHt[i, k] * Sinv[k, j]
            K[i, j] = acc
    # W = (I − KH) P = P − K (HP), HP = PHtᵀ
    for i in range(n):
        for j in range(n):
            acc = P[i, j]
            for k in range(m):
                acc -= K[i, k] * PHt[j, k]
            W[i, j] = acc
    # P = W (I − KH)ᵀ + K R Kᵀ = W − (W Hᵀ) Kᵀ + K R Kᵀ
    _mul_bt(W, H, WHt)
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += K[i, k] * R[k, j] * scale
            KR[i, j] = acc
    for i in range(n):
        for j in range(n):
            acc = W[i, j]
            for k in range(m):
                acc += (KR[i, k] - WHt[i, k]) * K[j, k]
            P[i, j] = acc
    for i in range(n):
        acc = 0.0
        for k in range(m):
            acc += K[i, k] * y[k]
        dx[i] += acc
    return nis, True


@njit(cache=True, inline="always")
def _joseph_work(nx, m):
    """Work arrays of :func:`_joseph` for m measurement rows."""
    return (np.empty((nx, m)), np.empty((nx, m)), np.empty((nx, m)), np.empty((nx, m)),
            np.empty((nx, nx)), np.empty((m, m)), np.empty((m, m)))


@njit(cache=True, inline="always")
def _scaled_identity(R, num, den):
    """R ← (I · num) / den, element by element (as ``np.eye(m) * num / den``)."""
    m = R.shape[0]
    for i in range(m):
        for j in range(m):
            R[i, j] = ((1.0 if i == j else 0.0) * num) / den


@njit(cache=True, inline="always")
def _recovery_due(gating, clean, bad_since, tk, limit):
    """Innovations have failed the gate for longer than ``limit`` while the sensor looks clean."""
    return gating and clean and bad_since >= 0.0 and tk - bad_since > limit


@njit(cache=True, inline="always")
def _outcome(ok, tk, bad_since, used, rejected):
    """Flag bits and the start of the current run of rejections after one gated update."""
    if ok:
        return used, -1.0
    return rejected, tk if bad_since < 0.0 else bad_since


@njit(cache=True, inline="always")
def _sub_hdx(y, H, dx):
    """y −= H dx."""
    for i in range(y.size):
        acc = 0.0
        for k in range(dx.size):
            acc += H[i, k] * dx[k]
        y[i] -= acc


# ---------------------------------------------------------------- the stages
# Written so that numba can drop the reference counts of their array arguments (see
# the module docstring): arrays one by one, last uses unconditional, no allocation.


@njit(cache=True, inline="always")
def _n_epochs(prop, offsets, n_x, n_samples):
    """Epochs of the main scheme (the sliding start-up steps not counted)."""
    if prop.rk4:
        return (n_samples - 1) // 2
    if n_x - 1 - offsets.max() >= 0:
        return (n_x - 1 - offsets.max()) // prop.stride + 1
    return 0


@njit(cache=True, inline="always")
def _startup_step(k, x, h, start_c, q, bias, phi, tmp):
    """Stage 1, sliding start-up: output ``k`` by one single-period step (pair coefficient
    ``start_c``) from output ``k − 1``; returns the step length."""
    for a in range(3):
        ua = x[k - 1, a] - bias[a]
        phi[a] = 0.5 * h * (ua + x[k, a] - bias[a])
    wa0, wa1, wa2 = x[k - 1, 0] - bias[0], x[k - 1, 1] - bias[1], x[k - 1, 2] - bias[2]
    wb0, wb1, wb2 = x[k, 0] - bias[0], x[k, 1] - bias[1], x[k, 2] - bias[2]
    c = start_c * h * h
    phi[0] += c * (wa1 * wb2 - wa2 * wb1)
    phi[1] += c * (wa2 * wb0 - wa0 * wb2)
    phi[2] += c * (wa0 * wb1 - wa1 * wb0)
    _update(q, phi, tmp)
    for i in range(4):
        q[i] = tmp[i]
    return h


@njit(cache=True, inline="always")
def _rk4_step(e, x, h, q, bias, phi, tmp, rates, rk, ry):
    """Stage 1, RK4: epoch e of the 2td quaternion RK4 (output at sample 2e + 2) on the
    bias-corrected rates; returns (k, T)."""
    k = 2 * e + 2
    for a in range(3):
        rates[0, a] = x[k - 2, a] - bias[a]
        rates[1, a] = x[k - 1, a] - bias[a]
        rates[2, a] = x[k, a] - bias[a]
    _rk4(q, rates, 2.0 * h, tmp, rk, ry)
    for i in range(4):
        q[i] = tmp[i]
    T = 2.0 * h
    for a in range(3):
        phi[a] = rates[1, a] * T
    return k, T


@njit(cache=True, inline="always")
def _window_step(e, x, h, prop, offsets, weights, pi, pj, pc, ring, q, bias, phi, tmp, base,
                 nodes, bias_x):
    """Stage 1, windowed form: epoch e (conventional, or sliding from the base ``lag``
    epochs back: ring row ``e % lag``, which is q itself when lag is 1) on the
    bias-corrected gyro; returns (k, T). φ is the window's rotation vector."""
    sa = h if prop.is_rate else 1.0
    sb = h * h if prop.is_rate else 1.0
    for a in range(3):
        bias_x[a] = bias[a] if prop.is_rate else bias[a] * h
    for i in range(4):
        base[i] = ring[e % prop.lag, i]
    b = e * prop.stride
    _window_phi(x, b, offsets, weights, pi, pj, pc, sa, sb, bias_x, phi, nodes)
    _update(base, phi, tmp)
    for i in range(4):
        q[i] = tmp[i]
    return b + prop.end_off, prop.stride * h


@njit(cache=True, inline="always")
def _fold_rest_samples(last, k, ema_n, rest_alpha, x, acc, h, is_rate, gm, g2, am, a2):
    """Stage 2: fold samples last + 1 … k into the rest detector's exponential moving
    averages of gyro and accelerometer (and of their squares); returns (last, ema_n)."""
    while last < k:
        last += 1
        ema_n += 1.0
        al = max(rest_alpha, 1.0 / ema_n)
        for a in range(3):
            wv = x[min(last, x.shape[0] - 1), a] if is_rate else x[last - 1, a] / h
            gm[a] += al * (wv - gm[a])
            g2[a] += al * (wv * wv - g2[a])
            am[a] += al * (acc[last, a] - am[a])
            a2[a] += al * (acc[last, a] * acc[last, a] - a2[a])
    return last, ema_n


@njit(cache=True, inline="always")
def _process_noise(T, params):
    """Stage 3, the terms of ``Φ`` and ``Q`` over a step T (scalars): the manoeuvre
    state's decay e^{−T/τ} and the variances added to attitude, gyro bias, manoeuvre
    acceleration (the Singer (1970) process) and accelerometer bias."""
    tau_a = params.singer_tau
    qa = params.singer_sigma ** 2 * (1.0 - np.exp(-2.0 * T / tau_a))
    return (np.exp(-T / tau_a), params.gyro_noise ** 2 * T, params.gyro_bias_rw ** 2 * T, qa,
            params.acc_bias_rw ** 2 * T)


@njit(cache=True, inline="always")
def _propagate_covariance(P, phi, T, decay, qg, qb, qa, qab, A, M):
    """Stage 3: ``P ← Φ P Φᵀ + Q`` with Φ = [[exp(−[φ×]), −T I, 0], [0, I, 0],
    [0, 0, decay I]] (and an identity block for an accelerometer bias when P is
    12 × 12), exp(−[φ×]) ≈ I − [φ×] + ½[φ×]²; work arrays A (3 × 3), M (n × n)."""
    px, py, pz = phi[0], phi[1], phi[2]
    # A = I − [φ×] + ½[φ×]²
    A[0, 0] = 1.0 - 0.5 * (py * py + pz * pz)
    A[1, 1] = 1.0 - 0.5 * (px * px + pz * pz)
    A[2, 2] = 1.0 - 0.5 * (px * px + py * py)
    A[0, 1] = pz + 0.5 * px * py
    A[1, 0] = -pz + 0.5 * px * py
    A[0, 2] = -py + 0.5 * px * pz
    A[2, 0] = py + 0.5 * px * pz
    A[1, 2] = px + 0.5 * py * pz
    A[2, 1] = -px + 0.5 * py * pz
    nx = P.shape[0]
    for c in range(nx):  # M = Φ P
        for r in range(3):
            M[r, c] = (A[r, 0] * P[0, c] + A[r, 1] * P[1, c] + A[r, 2] * P[2, c]
                       - T * P[3 + r, c])
            M[3 + r, c] = P[3 + r, c]
            M[6 + r, c] = decay * P[6 + r, c]
            if nx > 9:
                M[9 + r, c] = P[9 + r, c]
    for r in range(nx):  # (Φ P) Φᵀ
        for c in range(3):
            P[r, c] = (M[r, 0] * A[c, 0] + M[r, 1] * A[c, 1] + M[r, 2] * A[c, 2]
                       - T * M[r, 3 + c])
            P[r, 3 + c] = M[r, 3 + c]
            P[r, 6 + c] = decay * M[r, 6 + c]
            if nx > 9:
                P[r, 9 + c] = M[r, 9 + c]
    for r in range(3):
        P[r, r] += qg
        P[3 + r, 3 + r] += qb
        P[6 + r, 6 + r] += qa
        if nx > 9:
            P[9 + r, 9 + r] += qab


@njit(cache=True, inline="always")
def _rest_detect(ema_n, rest_alpha, params, gm, g2, am, a2):
    """Stage 4, detection from the moving averages; returns (acc_quiet, at_rest).

    Quiet accelerometer: low variance and a mean of magnitude g (no sustained
    manoeuvre); at rest: also a gyro of low variance and small mean.
    """
    sg = 0.0
    sacc = 0.0
    for a in range(3):
        sg += max(g2[a] - gm[a] * gm[a], 0.0)
        sacc += max(a2[a] - am[a] * am[a], 0.0)
    wm = np.sqrt(gm[0] ** 2 + gm[1] ** 2 + gm[2] ** 2)
    amn = np.sqrt(am[0] ** 2 + am[1] ** 2 + am[2] ** 2)
    settled = ema_n * rest_alpha > 1.0
    acc_quiet = (settled and np.sqrt(sacc) < params.rest_acc
                 and abs(amn - params.gravity) < params.rest_acc)
    at_rest = acc_quiet and np.sqrt(sg) < params.rest_gyro and wm < 5.0 * params.rest_gyro
    return acc_quiet, at_rest


@njit(cache=True, inline="always")
def _rest_model(T, params, bias, gm, dx, R, y):
    """Stage 4, measurement: the zero-rate measurement of the gyro bias (at rest the
    gyro's mean is its bias; ``H = [0, I, 0]``, fixed): R and the innovation y."""
    _scaled_identity(R, params.rest_noise ** 2, T)
    for a in range(3):
        y[a] = gm[a] - (bias[a] + dx[3 + a])


@njit(cache=True, inline="always")
def _acc_recovery(params, P):
    """Stage 5, recovery: inflate the tilt covariance (and, in the raw model, the
    manoeuvre acceleration's); returns its flag."""
    ra = params.recover_angle ** 2
    for a in range(3):
        P[a, a] += ra
        if not params.acc_lowpass:
            P[6 + a, 6 + a] += params.singer_sigma ** 2
    return F_ACC_RECOVERED


@njit(cache=True, inline="always")
def _acc_lowpass_model(T, lp_init, params, C, fk, fn, lp, dx, H, R, y):
    """Stage 5, low-pass accelerometer model (the idea of Laidig & Seel (2023) — VQF):
    the specific force in the reference frame, averaged over τ, is gravity
    (manoeuvres average out); ``lp − g_up ≈ [g_up×] C δθ`` (horizontal rows).
    Updates the average ``lp`` and fills H, R and the innovation y."""
    g = params.gravity
    nx = H.shape[1]
    for a in range(3):
        fn[a] = C[a, 0] * fk[0] + C[a, 1] * fk[1] + C[a, 2] * fk[2]
    al = min(1.0, T / params.acc_lowpass_s)
    for a in range(3):
        lp[a] = lp[a] + al * (fn[a] - lp[a]) if lp_init else fn[a]
    for a in range(3):
        H[0, a] = -g * C[1, a]
        H[1, a] = g * C[0, a]
        if nx > 9:  # the residual accelerometer bias, seen in the reference frame
            H[0, 9 + a] = C[0, a]
            H[1, 9 + a] = C[1, a]
    y[0] = lp[0]
    y[1] = lp[1]
    _sub_hdx(y, H, dx)
    _scaled_identity(R, params.acc_lowpass_noise ** 2, T)


@njit(cache=True, inline="always")
def _acc_plausible(fk, params):
    """Raw model: the specific force's norm is g within ``acc_norm_tol`` (always, without
    gating)."""
    fa = np.sqrt(fk[0] ** 2 + fk[1] ** 2 + fk[2] ** 2)
    g = params.gravity
    return not (params.gating and abs(fa - g) > params.acc_norm_tol * g)


@njit(cache=True, inline="always")
def _lever_sigma(k, x, h, is_rate, bias, lever_arm):
    """Raw model: the standard deviation that rotation seen at a lever arm adds to the
    accelerometer noise (centripetal ``|ω|²`` plus tangential ``|ω̇|``, times the arm)."""
    kk = min(k, x.shape[0] - 1)
    w2 = 0.0
    wd2 = 0.0
    for a in range(3):
        wa = x[kk, a] - bias[a] if is_rate else x[kk, a] / h - bias[a]
        w2 += wa * wa
        dw = x[kk, a] - x[kk - 1, a]
        wd2 += (dw / h if is_rate else dw / (h * h)) ** 2
    return lever_arm * (w2 + np.sqrt(wd2))


@njit(cache=True, inline="always")
def _acc_raw_model(T, lever, params, accel, C, fk, v, dx, H, R, y):
    """Stage 5, raw accelerometer model (Wang, Wang & Wang): ``f = C_b_n g_up + a_b``,
    ``H = [[v̂×], 0, I (, I)]``, the noise widened by ``lever``
    (:func:`_lever_sigma`): fills H, R and the innovation y."""
    g = params.gravity
    nx = H.shape[1]
    for a in range(3):
        v[a] = C[2, a] * g  # C_b_n [0, 0, g]
    H[0, 1] = -v[2]
    H[0, 2] = v[1]
    H[1, 0] = v[2]
    H[1, 2] = -v[0]
    H[2, 0] = -v[1]
    H[2, 1] = v[0]
    for a in range(3):
        H[a, 6 + a] = 1.0
        if nx > 9:
            H[a, 9 + a] = 1.0
    for a in range(3):
        y[a] = fk[a] - (v[a] + accel[a])
    _sub_hdx(y, H, dx)
    _scaled_identity(R, params.acc_noise ** 2 / T + lever * lever, 1.0)


@njit(cache=True, inline="always")
def _mag_plausible(mn, nb, params):
    """Stage 6, plausibility: the field's norm ``nb`` and the dip of ``mn`` (the field in
    the reference frame; rad, down positive) agree with the reference within the
    tolerances."""
    mh = np.sqrt(mn[0] ** 2 + mn[1] ** 2)
    dip = np.arctan2(-mn[2], mh)
    return not (abs(nb - params.ref_norm) > params.mag_norm_tol * params.ref_norm
                or abs(dip - params.ref_dip) > params.mag_dip_tol)


@njit(cache=True, inline="always")
def _mag_recovery(params, P, C):
    """Stage 6, recovery: inflate the heading covariance (about the reference vertical);
    returns its flag."""
    ra = params.recover_angle ** 2
    for r in range(3):
        for s in range(3):
            P[r, s] += ra * C[2, r] * C[2, s]
    return F_MAG_RECOVERED


@njit(cache=True, inline="always")
def _heading_model(T, params, C, mn, dx, H, R, y):
    """Stage 6, measurement: the magnetometer as a heading measurement,
    ``H = [−(C_n_b)₃ᵀ, 0, 0]``, so that a magnetic disturbance never reaches roll and
    pitch: fills H, R and the innovation y (wrapped to ±π)."""
    for a in range(3):
        H[0, a] = -C[2, a]
    yv = np.arctan2(mn[1], mn[0]) - params.ref_heading
    y[0] = (yv + np.pi) % (2.0 * np.pi) - np.pi
    _sub_hdx(y, H, dx)
    _scaled_identity(R, params.heading_noise ** 2, T)


@njit(cache=True, inline="always")
def _reset(slot, q, ring, bias, accel, acc_bias, P, C, dx, eps):
    """Stage 7: inject the correction dx into the estimate and symmetrise P.

    The attitude error, rotated into the reference frame (ε = C δθ_b, left in
    ``eps``), turns q and, in the sliding scheme, the bases of the other chains
    (they share the reference frame); ring row ``slot`` then receives q.
    """
    for a in range(3):
        eps[a] = C[a, 0] * dx[0] + C[a, 1] * dx[1] + C[a, 2] * dx[2]
    q[0], q[1], q[2], q[3] = _left_rotated(eps, q[0], q[1], q[2], q[3])
    n_ring = ring.shape[0]
    for r in range(n_ring if n_ring > 1 else 0):
        ring[r, 0], ring[r, 1], ring[r, 2], ring[r, 3] = _left_rotated(
            eps, ring[r, 0], ring[r, 1], ring[r, 2], ring[r, 3])
    for i in range(4):
        ring[slot, i] = q[i]
    nx = dx.size
    for a in range(3):
        bias[a] += dx[3 + a]
        accel[a] += dx[6 + a]
        if nx > 9:
            acc_bias[a] += dx[9 + a]
    for i in range(nx):  # P ← ½ (P + Pᵀ) in place (a + b = b + a exactly)
        for j in range(i + 1, nx):
            s = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = s
            P[j, i] = s


# Longer than the project's 80 lines on purpose: this is the filter's one compiled loop. Its
# stages are the inlined functions above; moving more of the loop into them would pass the
# records into stages, which numba's reference counting makes about 2× slower (see the
# module docstring).
@njit(cache=True)
def ekf_kernel(sensors, prop, window, params, init, out):
    """Run the filter over the record; returns the number of output rows written.

    Records: :class:`Sensors`, :class:`Propagation`, :class:`Window`,
    :class:`Params`, :class:`Initial`, :class:`Outputs`; the stages are listed in the
    module docstring. The loop body is the sequence of stages; everything it needs is
    allocated here, once.
    """
    x, acc, mag, h = sensors.x, sensors.acc, sensors.mag, sensors.h
    offsets, weights, pi, pj, pc = window.offsets, window.weights, window.pi, window.pj, window.pc
    is_rate, lag = prop.is_rate, prop.lag
    nx = init.P.shape[0]  # 9, or 12 with the accelerometer bias
    out_q, out_b, out_a, out_ab, out_idx, out_flags, out_nis, out_sig = out
    # the estimate: attitude, gyro bias, manoeuvre acceleration, accelerometer bias,
    # covariance, and the outputs of the last `lag` epochs (the sliding bases; with
    # lag 1 the row is q itself)
    q = init.q.copy()
    bias = init.gyro_bias.copy()
    accel = np.zeros(3)
    acc_bias = np.zeros(3)
    P = init.P.copy()
    ring = np.zeros((lag, 4))
    for i in range(lag):
        ring[i] = init.q
    # propagation work: rotation vector of the epoch (per epoch, for the covariance),
    # quaternion, nodes of the windowed form, bias in the units of x, RK4 rates and stages
    phi = np.empty(3)
    tmp = np.empty(4)
    base = np.empty(4)
    nodes = np.empty((max(offsets.size, 1), 3))
    bias_x = np.empty(3)
    rates = np.empty((3, 3))
    rk = np.empty((4, 4))
    ry = np.empty(4)
    A = np.empty((3, 3))
    M = np.empty((nx, nx))
    # rest detector: exponential moving averages of gyro, gyro², acc, acc²
    gm = np.zeros(3)
    g2 = np.zeros(3)
    am = np.zeros(3)
    a2 = np.zeros(3)
    rest_alpha = h / params.rest_tau
    ema_n = 0.0
    last = 0  # last sample folded into the rest detector
    # measurement work: C_n_b, the epoch's error-state correction, bias-corrected
    # specific force (body, reference frame), its average (low-pass model), the field in
    # the reference frame, H, R, y and the Joseph work arrays per row count
    C = np.empty((3, 3))
    dx = np.zeros(nx)
    fk = np.empty(3)
    fn = np.zeros(3)
    lp = np.zeros(3)
    mn = np.empty(3)
    v = np.empty(3)
    eps = np.empty(3)
    H_rest = np.zeros((3, nx))
    for a in range(3):
        H_rest[a, 3 + a] = 1.0
    H_raw = np.zeros((3, nx))
    H_lp = np.zeros((2, nx))
    H_mag = np.zeros((1, nx))
    R3 = np.empty((3, 3))
    R2 = np.empty((2, 2))
    R1 = np.empty((1, 1))
    y3 = np.empty(3)
    y2 = np.empty(2)
    y1 = np.empty(1)
    wk3 = _joseph_work(nx, 3)
    wk2 = _joseph_work(nx, 2)
    wk1 = _joseph_work(nx, 1)
    lp_init = False
    acc_bad_since = -1.0  # start of the current run of rejections (−1: none)
    mag_bad_since = -1.0
    mag_clean_since = -1.0  # start of the current run of plausible magnetometer samples
    e = 0
    # start-up outputs of the sliding scheme (samples 1 … lag−1 by single-period steps)
    n_start = lag - 1 if lag > 1 else 0
    total = n_start + _n_epochs(prop, offsets, x.shape[0], acc.shape[0])
    for step in range(total):
        # stage 1: attitude propagation
        if step < n_start:
            k = step + 1  # output sample
            T = _startup_step(k, x, h, prop.start_c, q, bias, phi, tmp)
        elif prop.rk4:
            e = step
            k, T = _rk4_step(e, x, h, q, bias, phi, tmp, rates, rk, ry)
        else:
            e = step - n_start
            k, T = _window_step(e, x, h, prop, offsets, weights, pi, pj, pc, ring, q, bias, phi,
                                tmp, base, nodes, bias_x)
            if lag > 1:
                for a in range(3):
                    phi[a] = phi[a] / lag  # per-epoch rotation for the covariance
        # stages 2, 3: rest detector, covariance
        last, ema_n = _fold_rest_samples(last, k, ema_n, rest_alpha, x, acc, h, is_rate,
                                         gm, g2, am, a2)
        decay, qg, qb, qa, qab = _process_noise(T, params)
        _propagate_covariance(P, phi, T, decay, qg, qb, qa, qab, A, M)
        flags = 0
        dx[:] = 0.0
        tk = k * h
        _dcm(q, C)
        # stage 4: rest
        acc_quiet, at_rest = _rest_detect(ema_n, rest_alpha, params, gm, g2, am, a2)
        if params.rest_update and at_rest:
            _rest_model(T, params, bias, gm, dx, R3, y3)
            _joseph(P, H_rest, R3, y3, 0.0, False, True, dx, False, wk3)
            flags |= F_REST
        # stage 5: accelerometer (recovery, then the accelerometer model's update)
        nis_acc = np.nan
        if params.use_accelerometer:
            for a in range(3):
                fk[a] = acc[k, a] - acc_bias[a]
            force = _recovery_due(params.gating, acc_quiet, acc_bad_since, tk,
                                  params.recover_acc_s)
            if force:
                flags |= _acc_recovery(params, P)
            if params.acc_lowpass:
                _acc_lowpass_model(T, lp_init, params, C, fk, fn, lp, dx, H_lp, R2, y2)
                lp_init = True
                nis_acc, ok = _joseph(P, H_lp, R2, y2, params.acc_gate_lowpass, params.gating,
                                      force, dx, params.soft_gate, wk2)
                disturbed = False
            else:
                disturbed = not _acc_plausible(fk, params)
                ok = False
                if not disturbed:
                    lever = _lever_sigma(k, x, h, is_rate, bias, params.lever_arm)
                    _acc_raw_model(T, lever, params, accel, C, fk, v, dx, H_raw, R3, y3)
                    nis_acc, ok = _joseph(P, H_raw, R3, y3, params.acc_gate, params.gating,
                                          force, dx, params.soft_gate, wk3)
            if disturbed:
                flags |= F_ACC_DISTURBED
            else:
                bits, acc_bad_since = _outcome(ok, tk, acc_bad_since, F_ACC_USED,
                                               F_ACC_REJECTED)
                flags |= bits
        # stage 6: magnetometer (plausibility, settling, recovery, the heading update)
        nis_mag = np.nan
        if params.use_magnetometer:
            for a in range(3):
                mn[a] = C[a, 0] * mag[k, 0] + C[a, 1] * mag[k, 1] + C[a, 2] * mag[k, 2]
            nb = np.sqrt(mag[k, 0] ** 2 + mag[k, 1] ** 2 + mag[k, 2] ** 2)
            if _mag_plausible(mn, nb, params):
                if mag_clean_since < 0.0:
                    mag_clean_since = tk
                settling = tk - mag_clean_since < params.mag_settle_s
            else:
                mag_clean_since = -1.0
                settling = True
            if params.gating and settling:
                flags |= F_MAG_DISTURBED
            else:
                force = _recovery_due(params.gating, True, mag_bad_since, tk,
                                      params.recover_mag_s)
                if force:
                    flags |= _mag_recovery(params, P, C)
                _heading_model(T, params, C, mn, dx, H_mag, R1, y1)
                nis_mag, ok = _joseph(P, H_mag, R1, y1, params.mag_gate, params.gating, force, dx,
                                      False, wk1)
                bits, mag_bad_since = _outcome(ok, tk, mag_bad_since, F_MAG_USED,
                                               F_MAG_REJECTED)
                flags |= bits
        # stage 7: reset
        _reset((e if step >= n_start else step + 1) % lag, q, ring, bias, accel, acc_bias, P,
               C, dx, eps)
        if lp_init:  # the averaged reference-frame specific force follows the correction
            _rotate_small(eps, lp)
        # stage 8: record
        out_q[step] = q
        out_b[step] = bias
        out_a[step] = accel
        out_ab[step] = acc_bias
        out_idx[step] = k
        out_flags[step] = flags
        out_nis[step, 0] = nis_acc
        out_nis[step, 1] = nis_mag
        for a in range(3):
            out_sig[step, a] = np.sqrt(max(P[a, a], 0.0))
    return total
