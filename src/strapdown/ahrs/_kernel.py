"""The AHRS filter loop, compiled with numba (``cache=True``). Private.

One function, :func:`ekf_kernel`, runs the whole multiplicative error-state
EKF of :mod:`strapdown.ahrs` over a record: attitude propagation by a
windowed rotation-vector algorithm (any of the library's rate or increment
forms, conventional or sliding) or quaternion RK4, covariance propagation,
rest (zero-rate) update, accelerometer and magnetometer-heading updates with
innovation gating and recovery, Joseph-form update and reset. The public
wrapper validates everything; the kernel trusts it. It is tested against its
own plain-Python execution (``ekf_kernel.py_func``) and, for accuracy,
against exact simulated truth.

Measurement noises are densities: an update every ``T`` seconds uses
``R = density² / T``, so the filter's bandwidth does not depend on the
propagation algorithm's update period.

Frames: ENU reference; ``q`` is q_n_b (Hamilton, scalar first). Error state
``x = [δθ_b, δb_g, a_b]`` (``+ δb_a``, the accelerometer bias, when ``P0`` is
12 × 12) with ``q_true = q̂ ⊗ q(δθ_b)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from strapdown.ahrs.flags import MeasurementFlag
from strapdown.algorithms._kernels import _update

# indices into the parameter vector (see strapdown.ahrs._params)
P_GYRO_NOISE = 0
P_BIAS_RW = 1
P_SINGER_SIGMA = 2
P_SINGER_TAU = 3
P_ACC_NOISE = 4
P_HEADING_NOISE = 5
P_ACC_GATE = 6
P_MAG_GATE = 7
P_MAG_NORM_TOL = 8
P_MAG_DIP_TOL = 9
P_REF_NORM = 10
P_REF_DIP = 11
P_REF_HEADING = 12
P_RECOVER_ACC = 13
P_RECOVER_MAG = 14
P_REST_GYRO = 15
P_REST_ACC = 16
P_REST_NOISE = 17
P_REST_TAU = 18
P_USE_ACC = 19
P_USE_MAG = 20
P_GATING = 21
P_USE_REST = 22
P_GRAVITY = 23
P_RECOVER_ANGLE = 24
P_ACC_NORM_TOL = 25
P_MAG_SETTLE = 26
P_SOFT_ACC = 27
P_LEVER = 28
P_ACC_LP_TAU = 29
P_ACC_LP_NOISE = 30
P_ACC_GATE_LP = 31
P_ACC_BIAS_RW = 32
N_PARAMS = 33

# flags per output: the values of strapdown.ahrs.flags.MeasurementFlag as plain ints
F_ACC_USED = int(MeasurementFlag.ACC_USED)
F_ACC_REJECTED = int(MeasurementFlag.ACC_REJECTED)
F_MAG_USED = int(MeasurementFlag.MAG_USED)
F_MAG_REJECTED = int(MeasurementFlag.MAG_REJECTED)
F_MAG_DISTURBED = int(MeasurementFlag.MAG_DISTURBED)
F_REST = int(MeasurementFlag.REST)
F_ACC_RECOVERED = int(MeasurementFlag.ACC_RECOVERED)
F_MAG_RECOVERED = int(MeasurementFlag.MAG_RECOVERED)
F_ACC_DISTURBED = int(MeasurementFlag.ACC_DISTURBED)


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
def _left_rotate(eps, q):
    """q ← q(ε) ⊗ q (a small reference-frame rotation), normalised."""
    ang = np.sqrt(eps[0] * eps[0] + eps[1] * eps[1] + eps[2] * eps[2])
    if ang < 1e-8:
        s = 0.5 - ang * ang / 48.0
        dw = 1.0 - ang * ang / 8.0
    else:
        s = np.sin(0.5 * ang) / ang
        dw = np.cos(0.5 * ang)
    ex, ey, ez = s * eps[0], s * eps[1], s * eps[2]
    w = dw * q[0] - ex * q[1] - ey * q[2] - ez * q[3]
    x = dw * q[1] + ex * q[0] + ey * q[3] - ez * q[2]
    y = dw * q[2] - ex * q[3] + ey * q[0] + ez * q[1]
    z = dw * q[3] + ex * q[2] - ey * q[1] + ez * q[0]
    nrm = np.sqrt(w * w + x * x + y * y + z * z)
    q[0] = w / nrm
    q[1] = x / nrm
    q[2] = y / nrm
    q[3] = z / nrm


@njit(cache=True)
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
        u = nodes[pi[p]]
        v = nodes[pj[p]]
        c = sb * pc[p]
        phi[0] += c * (u[1] * v[2] - u[2] * v[1])
        phi[1] += c * (u[2] * v[0] - u[0] * v[2])
        phi[2] += c * (u[0] * v[1] - u[1] * v[0])


@njit(cache=True)
def _rk4(q, w0, w1, w2, h2, out):
    """One quaternion RK4 step of length h2 with rates at start, middle, end."""
    k = np.empty((4, 4))
    y = q.copy()
    for s in range(4):
        if s == 0:
            w = w0
            y[:] = q
        elif s == 1 or s == 2:
            w = w1
            for i in range(4):
                y[i] = q[i] + 0.5 * h2 * k[s - 1, i]
        else:
            w = w2
            for i in range(4):
                y[i] = q[i] + h2 * k[2, i]
        k[s, 0] = 0.5 * (-y[1] * w[0] - y[2] * w[1] - y[3] * w[2])
        k[s, 1] = 0.5 * (y[0] * w[0] + y[2] * w[2] - y[3] * w[1])
        k[s, 2] = 0.5 * (y[0] * w[1] - y[1] * w[2] + y[3] * w[0])
        k[s, 3] = 0.5 * (y[0] * w[2] + y[1] * w[1] - y[2] * w[0])
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
    """
    m = y.size
    n = P.shape[0]
    PHt = wk[0][:, :m]
    K = wk[1][:, :m]
    WHt = wk[2][:, :m]
    KR = wk[3][:, :m]
    W = wk[4]
    S = wk[5][:m, :m]
    Sinv = wk[6][:m, :m]
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


@njit(cache=True)
def _propagate(P, phi, T, decay, qg, qb, qa, qab):
    """P ← Φ P Φᵀ + Q with Φ = [[exp(−[φ×]), −T I, 0], [0, I, 0], [0, 0, decay I]]
    (and an identity block for an accelerometer bias when P is 12 × 12)."""
    px, py, pz = phi[0], phi[1], phi[2]
    # A = I − [φ×] + ½[φ×]²
    A = np.empty((3, 3))
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
    M = np.empty((nx, nx))  # Φ P
    for c in range(nx):
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


@njit(cache=True)
def ekf_kernel(x, is_rate, h, offsets, weights, pi, pj, pc, stride, span, end_off, lag,
               start_c, rk4, acc, mag, params, q0, b0, P0,
               out_q, out_b, out_a, out_ab, out_idx, out_flags, out_nis, out_sig):
    """Run the filter; returns the number of outputs written.

    ``x``: rates (n, 3) if ``is_rate`` else increments (n − 1, 3); sample ``i``
    of ``acc``/``mag`` is at time ``i h``. Windowed form: epoch ``e`` uses
    nodes ``x[e·stride + offsets]`` and outputs at sample ``e·stride + end_off``;
    its base attitude is the output ``lag`` epochs earlier (``lag > 1``: the
    sliding scheme, started by single-period steps with coefficient
    ``start_c``). ``rk4``: quaternion RK4 over two rate intervals.
    """
    n_samples = acc.shape[0]
    sa = h if is_rate else 1.0
    sb = h * h if is_rate else 1.0
    g = params[P_GRAVITY]
    use_acc = params[P_USE_ACC] != 0.0
    use_mag = params[P_USE_MAG] != 0.0
    gating = params[P_GATING] != 0.0
    use_rest = params[P_USE_REST] != 0.0
    P = P0.copy()
    q = q0.copy()
    bias = b0.copy()
    accel = np.zeros(3)
    ring = np.zeros((lag, 4))  # outputs of the last `lag` epochs (the sliding bases)
    for i in range(lag):
        ring[i] = q0
    C = np.empty((3, 3))
    phi = np.empty(3)
    tmp = np.empty(4)
    nx = P0.shape[0]  # 9, or 12 with the accelerometer bias
    dx = np.zeros(nx)
    acc_bias = np.zeros(3)
    fk = np.empty(3)  # bias-corrected specific force of the current sample
    eps = np.empty(3)
    bias_x = np.empty(3)
    nodes = np.empty((max(offsets.size, 1), 3))
    wk = (np.empty((nx, 3)), np.empty((nx, 3)), np.empty((nx, 3)), np.empty((nx, 3)),
          np.empty((nx, nx)), np.empty((3, 3)), np.empty((3, 3)))
    # rest detector (exponential moving averages of gyro and accelerometer)
    gm = np.zeros(3)
    g2 = np.zeros(3)
    am = np.zeros(3)
    a2 = np.zeros(3)
    rest_alpha = h / params[P_REST_TAU]
    ema_n = 0.0
    acc_bad_since = -1.0
    mag_bad_since = -1.0
    mag_clean_since = -1.0  # start of the current run of plausible magnetometer samples
    lp_tau = params[P_ACC_LP_TAU]
    lp = np.zeros(3)
    fn = np.zeros(3)
    lp_init = False
    n_out = 0
    last = 0  # last sample folded into the rest detector
    # start-up outputs of the sliding scheme (samples 1 … lag−1 by single-period steps)
    e = 0
    n_start = lag - 1 if lag > 1 else 0
    n_epochs = 0
    if rk4:
        n_epochs = (n_samples - 1) // 2
    else:
        n_x = x.shape[0]
        if n_x - 1 - offsets.max() >= 0:
            n_epochs = (n_x - 1 - offsets.max()) // stride + 1
    total = n_start + n_epochs
    for step in range(total):
        # ---------------- attitude propagation ----------------
        for a in range(3):
            bias_x[a] = bias[a] if is_rate else bias[a] * h
        if step < n_start:
            k = step + 1  # output sample
            u0 = x[k - 1]
            u1 = x[k]
            for a in range(3):
                ua = u0[a] - bias[a]
                phi[a] = 0.5 * h * (ua + u1[a] - bias[a])
            wa0, wa1, wa2 = u0[0] - bias[0], u0[1] - bias[1], u0[2] - bias[2]
            wb0, wb1, wb2 = u1[0] - bias[0], u1[1] - bias[1], u1[2] - bias[2]
            c = start_c * h * h
            phi[0] += c * (wa1 * wb2 - wa2 * wb1)
            phi[1] += c * (wa2 * wb0 - wa0 * wb2)
            phi[2] += c * (wa0 * wb1 - wa1 * wb0)
            _update(q, phi, tmp)
            q[:] = tmp
            T = h
        elif rk4:
            e = step
            k = 2 * e + 2
            w0 = x[k - 2] - bias
            w1 = x[k - 1] - bias
            w2 = x[k] - bias
            _rk4(q, w0, w1, w2, 2.0 * h, tmp)
            q[:] = tmp
            T = 2.0 * h
            for a in range(3):
                phi[a] = w1[a] * T
        else:
            e = step - n_start
            b = e * stride
            k = b + end_off
            _window_phi(x, b, offsets, weights, pi, pj, pc, sa, sb, bias_x, phi, nodes)
            base = ring[e % lag] if lag > 1 else q
            _update(base, phi, tmp)
            q[:] = tmp
            T = stride * h
            if lag > 1:
                for a in range(3):
                    phi[a] = phi[a] / lag  # per-epoch rotation for the covariance
        # ---------------- rest detector over the samples of this epoch ----------------
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
        # ---------------- covariance propagation ----------------
        # Φ_θθ = exp(−[φ×]) ≈ I − [φ×] + ½[φ×]², Φ_θb = −T I, Φ_aa = e^{−T/τ} I
        tau_a = params[P_SINGER_TAU]
        qa = params[P_SINGER_SIGMA] ** 2 * (1.0 - np.exp(-2.0 * T / tau_a))
        _propagate(P, phi, T, np.exp(-T / tau_a), params[P_GYRO_NOISE] ** 2 * T,
                   params[P_BIAS_RW] ** 2 * T, qa, params[P_ACC_BIAS_RW] ** 2 * T)
        # ---------------- measurement updates ----------------
        flags = 0
        dx[:] = 0.0
        tk = k * h
        _dcm(q, C)
        sg = 0.0
        sacc = 0.0
        for a in range(3):
            sg += max(g2[a] - gm[a] * gm[a], 0.0)
            sacc += max(a2[a] - am[a] * am[a], 0.0)
        wm = np.sqrt(gm[0] ** 2 + gm[1] ** 2 + gm[2] ** 2)
        amn = np.sqrt(am[0] ** 2 + am[1] ** 2 + am[2] ** 2)
        settled = ema_n * rest_alpha > 1.0
        # quiet accelerometer: low variance and a mean of magnitude g (no sustained manoeuvre)
        acc_quiet = (settled and np.sqrt(sacc) < params[P_REST_ACC]
                     and abs(amn - g) < params[P_REST_ACC])
        if use_rest:
            if (acc_quiet and np.sqrt(sg) < params[P_REST_GYRO]
                    and wm < 5.0 * params[P_REST_GYRO]):
                H = np.zeros((3, nx))
                for a in range(3):
                    H[a, 3 + a] = 1.0
                R = np.eye(3) * params[P_REST_NOISE] ** 2 / T
                y = gm - (bias + dx[3:6])
                _joseph(P, H, R, y, 0.0, False, True, dx, False, wk)
                flags |= F_REST
        nis_acc = np.nan
        for a in range(3):
            fk[a] = acc[k, a] - acc_bias[a]
        # recovery: inflate the tilt (and, in the raw model, the manoeuvre acceleration)
        force = use_acc and _recovery_due(gating, acc_quiet, acc_bad_since, tk,
                                          params[P_RECOVER_ACC])
        if force:
            ra = params[P_RECOVER_ANGLE] ** 2
            for a in range(3):
                P[a, a] += ra
                if lp_tau <= 0.0:
                    P[6 + a, 6 + a] += params[P_SINGER_SIGMA] ** 2
            flags |= F_ACC_RECOVERED
        if use_acc and lp_tau > 0.0:
            # low-pass model: the specific force in the reference frame, averaged over τ,
            # is gravity (manoeuvres average out); lp − g_up ≈ [g_up×] C δθ (horizontal rows)
            for a in range(3):
                fn[a] = C[a, 0] * fk[0] + C[a, 1] * fk[1] + C[a, 2] * fk[2]
            if not lp_init:
                lp[:] = fn
                lp_init = True
            else:
                al = min(1.0, T / lp_tau)
                for a in range(3):
                    lp[a] += al * (fn[a] - lp[a])
            H = np.zeros((2, nx))
            for a in range(3):
                H[0, a] = -g * C[1, a]
                H[1, a] = g * C[0, a]
                if nx > 9:  # the residual accelerometer bias, seen in the reference frame
                    H[0, 9 + a] = C[0, a]
                    H[1, 9 + a] = C[1, a]
            y = np.empty(2)
            y[0] = lp[0]
            y[1] = lp[1]
            _sub_hdx(y, H, dx)
            R = np.eye(2) * params[P_ACC_LP_NOISE] ** 2 / T
            nis_acc, ok = _joseph(P, H, R, y, params[P_ACC_GATE_LP], gating, force, dx,
                                  params[P_SOFT_ACC] != 0.0, wk)
            bits, acc_bad_since = _outcome(ok, tk, acc_bad_since, F_ACC_USED, F_ACC_REJECTED)
            flags |= bits
        elif use_acc:
            v = np.empty(3)
            for a in range(3):
                v[a] = C[2, a] * g  # C_b_n [0, 0, g]
            H = np.zeros((3, nx))
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
            fa = np.sqrt(fk[0] ** 2 + fk[1] ** 2 + fk[2] ** 2)
            acc_disturbed = gating and abs(fa - g) > params[P_ACC_NORM_TOL] * g
            y = np.empty(3)
            for a in range(3):
                y[a] = fk[a] - (v[a] + accel[a])
            _sub_hdx(y, H, dx)
            # rotation seen at a lever arm (centripetal + tangential) widens the noise
            kk = min(k, x.shape[0] - 1)
            if is_rate:
                w2 = 0.0
                wd2 = 0.0
                for a in range(3):
                    wa = x[kk, a] - bias[a]
                    w2 += wa * wa
                    wd2 += ((x[kk, a] - x[kk - 1, a]) / h) ** 2
            else:
                w2 = 0.0
                wd2 = 0.0
                for a in range(3):
                    wa = x[kk, a] / h - bias[a]
                    w2 += wa * wa
                    wd2 += ((x[kk, a] - x[kk - 1, a]) / (h * h)) ** 2
            lever = params[P_LEVER] * (w2 + np.sqrt(wd2))
            R = np.eye(3) * (params[P_ACC_NOISE] ** 2 / T + lever * lever)
            if acc_disturbed:
                flags |= F_ACC_DISTURBED
            else:
                nis_acc, ok = _joseph(P, H, R, y, params[P_ACC_GATE], gating, force, dx,
                                      params[P_SOFT_ACC] != 0.0, wk)
                bits, acc_bad_since = _outcome(ok, tk, acc_bad_since, F_ACC_USED,
                                               F_ACC_REJECTED)
                flags |= bits
        nis_mag = np.nan
        if use_mag:
            mb = mag[k]
            nb = np.sqrt(mb[0] ** 2 + mb[1] ** 2 + mb[2] ** 2)
            mn = np.empty(3)
            for a in range(3):
                mn[a] = C[a, 0] * mb[0] + C[a, 1] * mb[1] + C[a, 2] * mb[2]
            mh = np.sqrt(mn[0] ** 2 + mn[1] ** 2)
            dip = np.arctan2(-mn[2], mh)
            disturbed = (abs(nb - params[P_REF_NORM]) > params[P_MAG_NORM_TOL] * params[P_REF_NORM]
                         or abs(dip - params[P_REF_DIP]) > params[P_MAG_DIP_TOL])
            if disturbed:
                mag_clean_since = -1.0
            elif mag_clean_since < 0.0:
                mag_clean_since = tk
            if gating and (disturbed or tk - mag_clean_since < params[P_MAG_SETTLE]):
                flags |= F_MAG_DISTURBED
            else:
                H = np.zeros((1, nx))
                for a in range(3):
                    H[0, a] = -C[2, a]
                yv = np.arctan2(mn[1], mn[0]) - params[P_REF_HEADING]
                yv = (yv + np.pi) % (2.0 * np.pi) - np.pi
                y = np.array([yv])
                _sub_hdx(y, H, dx)
                R = np.eye(1) * params[P_HEADING_NOISE] ** 2 / T
                force = _recovery_due(gating, True, mag_bad_since, tk, params[P_RECOVER_MAG])
                if force:
                    ra = params[P_RECOVER_ANGLE] ** 2
                    for r in range(3):
                        for s in range(3):
                            P[r, s] += ra * C[2, r] * C[2, s]
                    force = True
                    flags |= F_MAG_RECOVERED
                nis_mag, ok = _joseph(P, H, R, y, params[P_MAG_GATE], gating, force, dx, False, wk)
                bits, mag_bad_since = _outcome(ok, tk, mag_bad_since, F_MAG_USED,
                                               F_MAG_REJECTED)
                flags |= bits
        # ---------------- reset ----------------
        for a in range(3):
            eps[a] = C[a, 0] * dx[0] + C[a, 1] * dx[1] + C[a, 2] * dx[2]
        _left_rotate(eps, q)
        if lp_init:  # the averaged reference-frame specific force follows the correction
            l0 = lp[0] + eps[1] * lp[2] - eps[2] * lp[1]
            l1 = lp[1] + eps[2] * lp[0] - eps[0] * lp[2]
            l2 = lp[2] + eps[0] * lp[1] - eps[1] * lp[0]
            lp[0] = l0
            lp[1] = l1
            lp[2] = l2
        if lag > 1:  # the bases of the other chains share the reference frame: correct them too
            for r in range(lag):
                _left_rotate(eps, ring[r])
            ring[(e if step >= n_start else step + 1) % lag] = q
        for a in range(3):
            bias[a] += dx[3 + a]
            accel[a] += dx[6 + a]
            if nx > 9:
                acc_bias[a] += dx[9 + a]
        P = 0.5 * (P + P.T)
        out_q[n_out] = q
        out_b[n_out] = bias
        out_a[n_out] = accel
        out_ab[n_out] = acc_bias
        out_idx[n_out] = k
        out_flags[n_out] = flags
        out_nis[n_out, 0] = nis_acc
        out_nis[n_out, 1] = nis_mag
        for a in range(3):
            out_sig[n_out, a] = np.sqrt(max(P[a, a], 0.0))
        n_out += 1
    return n_out
