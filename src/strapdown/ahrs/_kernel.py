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
3. :func:`_propagate_covariance` and :func:`_add_process_noise` — ``P ← Φ P Φᵀ + Q``,
   with a tilt noise proportional to the rotation rate; :func:`_scale_floor` (with
   ``gyro_scale_sigma``) — the bias's variance kept above an uncalibrated gyro's scale
   error on the averaged rate;
4. :func:`_rest_detect`, :func:`_rest_still` and :func:`_rest_model` — the zero-rate bias
   update, once rest has lasted ``rest_min_s``;
5. the accelerometer: recovery (:func:`_acc_recovery`), then the model of
   ``AhrsConfig.acc_model`` — :func:`_acc_lowpass_model` (Laidig & Seel (2023),
   VQF's idea: the specific force in the almost-inertial reference frame through a
   second-order Butterworth low-pass, :func:`_lowpass`) or :func:`_acc_plausible`,
   :func:`_lever_sigma` and :func:`_acc_raw_model` (the Singer (1970) manoeuvre state);
   the low-pass model's update is :func:`_gated_update`, or without a magnetometer
   :func:`_level_update`, whose gain never reaches the heading;
6. the magnetometer as a heading measurement: the field rotated into the reference
   frame with the attitude of the magnetometer's delay earlier (:func:`_delayed_field`;
   the delay fixed or estimated online, :func:`_fold_delay_samples` and
   :func:`_delay_choice`),
   its norm and dip low-passed and compared with a slowly learned reference
   (:func:`_mag_disturbance`, after Laidig & Seel (2023), Sec. 2.5), recovery
   (:func:`_mag_recovery`), :func:`_heading_model` and the heading update
   :func:`_consider_update`, whose innovation variance includes the tilt error
   (through the field's dip) but whose gain never reaches roll and pitch, and whose
   measurement variance is adapted to its innovations (:func:`_heading_adapt`,
   :func:`_heading_power`);
7. :func:`_reset` — error-state injection into the attitude, the biases, the
   sliding scheme's bases and the low-pass states (:func:`_rotate_small`);
8. the record: the epoch's sample's row of :class:`Outputs`.

A measurement model fills H, R and the innovation y; the loop applies it with
the gated sequential update :func:`_gated_update` (or :func:`_consider_update`). The public
wrapper (:func:`strapdown.ahrs.filter.ekf`) validates everything; the kernel trusts it.
Its arguments are typed records (:class:`Sensors`, :class:`Propagation`,
:class:`Window`, :class:`Params`, :class:`Initial`, :class:`Outputs`),
NamedTuples that numba passes as structs. It is tested against its own
plain-Python execution and, for accuracy, against exact simulated truth.

Written for speed (the loop allocates nothing per epoch): numba keeps a reference
count per array bound to an inlined function's argument and removes that count only
when nothing in between can release a reference. So the stages take their arrays one
by one (never a record holding arrays: records that reach a stage hold scalars
only), every array's last use in a stage is unconditional, a stage allocates
nothing and creates no views. Compiled with numba's ``error_model="numpy"``: a
division by zero gives inf or NaN instead of raising (a raise would also keep the
counts), and the wrapper's inputs never lead to one.

Measurement noises are densities: an update every ``T`` seconds uses
``R = density² / T``, so the filter's bandwidth does not depend on the
propagation algorithm's update period.

Frames: ENU reference; ``q`` is q_n_b (Hamilton, scalar first). Error state
``x = [δθ_b, δb_g]``, then the Singer manoeuvre acceleration ``a_b`` with the raw
accelerometer model, then the accelerometer bias ``δb_a`` when estimated (6, 9 or 12
states; ``P0``'s size and ``Params.acc_lowpass`` say which), with
``q_true = q̂ ⊗ q(δθ_b)``.
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
F_MAG_OFFSET = int(MeasurementFlag.MAG_OFFSET)

# the magnetometer's disturbance state (a float array the stages share, see
# _mag_disturbance): reference norm and dip, time undisturbed, disturbed (0/1), candidate
# norm, dip and time, time rejected
M_NORM, M_DIP, M_UNDIST, M_DIST, M_CNORM, M_CDIP, M_CT, M_REJECT = range(8)
# the online hard-iron estimate (:func:`_hard_iron_span`), its sums forgetting: scalars —
# Σ|r|², Σ 1, Σ|m|², Σ|m|⁴, when its tests began to hold (−1: not holding), whether a
# previous span end is stored (0/1) —, vectors — Σ Aᵀr, the estimate
# b, the offset applied, b when the tests began to hold, the previous span end's field
# (body), Σ m, Σ |m|² m — and matrices — Σ AᵀA, the previous span end's gyro-path C_n_b,
# Σ m mᵀ
H_RR, H_W, H_Q, H_QQ, H_HOLD, H_PREV = range(6)
V_Y, V_B, V_APP, V_HOLD, V_PREV, V_M, V_QM = range(7)
X_N, X_PREV, X_MM = range(3)
#: The slow mean of the low-passed specific force (:func:`_motion_power`) has this many
#: times the low-pass's time constant.
MOTION_SLOW = 4.0


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
    names and units), the reference field, the switches, and coefficients derived for
    the epoch period (the low-passes, the delay in epochs)."""

    gyro_noise: float
    gyro_bias_rw: float
    tilt_rate_noise: float
    heading_rate_noise: float
    gyro_scale_sigma: float
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
    rest_gyro_mean: float
    rest_min_s: float
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
    acc_lowpass_noise: float
    acc_lowpass_s: float
    acc_motion_leak: float
    acc_lowpass_norm_tol: float
    acc_scale_tol: float
    gravity_measured: float  #: gravity's norm as this accelerometer measures it: over the
    #: initial window when it is still, else the nominal ``gravity`` (then the learned norm,
    #: ``acc_scale_tol``) until the first rest
    gravity_known: bool  #: gravity_measured was measured (a still start), not assumed
    gravity_learned: float  #: where the learning of gravity's norm starts (NaN: from
    #: gravity_measured; _learn_gravity)
    mag_provisional_s: float  #: a moving start: the field's reference norm and dip follow
    #: the measurement this long (the start's tilt, and so its dip, is not yet known)
    provisional_heading_q: float  #: meanwhile the heading's variance grows by this (rad²/s):
    #: ``heading_noise² / moving_start_heading_s²``, a low-pass of the field's heading
    acc_gate_lowpass: float
    acc_bias_rw: float
    mag_new_s: float
    mag_new_min_rate: float
    mag_reject_s: float
    mag_disturbed_factor: float
    mag_disturbed_power: float
    lp_b0: float  #: the accelerometer low-pass (second-order Butterworth at the epoch
    lp_b1: float  #: period): numerator,
    lp_b2: float
    lp_a1: float  #: denominator (a0 = 1),
    lp_a2: float
    lp_init_n: int  #: epochs averaged before the filter starts
    lp_settle: int  #: the low-pass model updates from epoch lp_init_n + lp_settle (0 or −lp_init_n)
    dyn_k: float  #: gain per epoch of the motion acceleration's moving mean square
    dyn_k2: float  #: gain per epoch of the slow mean of the low-passed specific force
    scale_k: float  #: gain per epoch of the averaged rate of gyro_scale_sigma (gyro_scale_tau)
    mc_b0: float  #: the low-pass of the field's norm and dip, likewise
    mc_b1: float
    mc_b2: float
    mc_a1: float
    mc_a2: float
    mc_init_n: int
    mag_ref_k: float  #: gain of the reference's slow update per epoch
    mag_delay: int  #: the magnetometer's delay, samples (fixed, or the estimator's start)
    estimate_mag_delay: bool  #: estimate the delay online (:func:`_fold_delay_samples`)
    mag_delay_max: int  #: the estimator's largest candidate, samples
    mag_delay_alpha: float  #: its averaging gain per sample
    mag_delay_z: float  #: its switching threshold, standard deviations (:func:`_delay_choice`)
    store_covariance: bool  #: write attitude_cov and bias_var (the offline combination)
    heading_bridge_noise: bool  #: AhrsConfig.heading_bridge_noise
    meas_lead: float  #: how far the magnetometer's samples lead the attitude they update, s
    #: (half a period for point field samples beside interval gyro samples; :func:`_at_state_time`)
    acc_lead: float  #: the same for the accelerometer's samples, s (``AhrsConfig.acc_sample``)
    hi_on: bool  #: estimate a hard iron online (:func:`_hard_iron_span`)
    hi_span: int  #: its span, epochs
    hi_forget: float  #: its sums' forgetting factor per span
    hi_ridge: float  #: its ridge, a fraction of the trace of Σ AᵀA
    hi_min_explained: float  #: its tests: the fraction of Σ|r|² the estimate explains,
    hi_steadier: float  #: the norm's steadying (coefficient of variation, corrected / raw),
    hi_spread: float  #: the estimate's drift while they hold (a fraction of |b|),
    hi_update: float  #: how far it moves (a fraction of |b|) before it is applied again,
    hi_hold_s: float  #: how long they must hold, s,
    hi_min_spans: float  #: and the sums' weight (spans) they need
    tilt_adapt_level: float  #: the innovation power (NIS per second) above which the tilt's
    #: rate noise grows (:func:`_tilt_adapt`; +inf: never)
    tilt_adapt_max: float  #: the largest factor on its variance
    adapt_k: float  #: gain per epoch of the innovation power's moving mean (tilt_adapt_s)
    clip_level: float  #: the gyro's range, rad/s (0: none known; AhrsConfig.gyro_range)
    clip_s: float  #: how long after a sample at it the norm test is suspended (gyro_clip_s)
    mag_adapt_k: float  #: gain per epoch of the heading NIS's moving mean (mag_adapt_s; 0:
    #: no adaptation, :func:`_heading_adapt`)


class Initial(NamedTuple):
    """Initial q_n_b (4,), gyro bias (3,) and error covariance (6, 9 or 12 square); the
    low-pass model's initial state (4,), NaN for none (the low-pass then averages its
    first ``lp_init_n`` epochs): the low-passed specific force in the reference frame and
    the motion power through it (:func:`_motion_power`), as :func:`ekf_kernel` returns
    them — the power may be given alone (the filter's ``_Start.motion_power``; 0 when
    NaN); and the epochs before the low-pass model's first
    update unless the accelerometer is quiet (0: none)."""

    q: np.ndarray
    gyro_bias: np.ndarray
    P: np.ndarray
    lowpass: np.ndarray
    lowpass_wait: int


class Outputs(NamedTuple):
    """The outputs, allocated by the caller with a row per sample (n): each epoch writes
    the row of its sample k — q (n, 4), gyro_bias, accel, acc_bias (n, 3), flags (n,)
    int64, nis (n, 2) (accelerometer, heading; NaN without an update), attitude_sigma
    (n, 3), attitude_cov (n, 3, 3) (of δθ_b) and bias_var (n, 3) (the gyro bias's
    variances; only with ``Params.store_covariance``), mag_delay (n,) int64 (the
    magnetometer delay in use, samples), mag_nis0 (n,) (the heading NIS against the
    unadapted variance, ``mag_adapt_s``; NaN without an update or where a recovery forced
    it) — and ``sample[e]``, epoch e's sample index; other rows are left as they were
    (accel and acc_bias are not written without their states)."""

    q: np.ndarray
    gyro_bias: np.ndarray
    accel: np.ndarray
    acc_bias: np.ndarray
    sample: np.ndarray
    flags: np.ndarray
    nis: np.ndarray
    attitude_sigma: np.ndarray
    attitude_cov: np.ndarray
    bias_var: np.ndarray
    mag_delay: np.ndarray
    mag_nis0: np.ndarray


# ---------------------------------------------------------------- small numerics
# (Work arrays come from the caller: the loop allocates nothing per epoch.)


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
def _small_rotation(eps):
    """(scalar part, vector-part factor) of q(ε) = [cos(|ε|/2), sin(|ε|/2) ε/|ε|]; below
    |ε| = 0.01 rad (every correction of a filter that is not diverging) by their Taylor
    series to |ε|⁶, whose first omitted terms are below 1e-23."""
    a2 = eps[0] * eps[0] + eps[1] * eps[1] + eps[2] * eps[2]
    if a2 < 1e-4:
        return (1.0 - a2 / 8.0 * (1.0 - a2 / 48.0 * (1.0 - a2 / 120.0)),
                0.5 - a2 / 48.0 * (1.0 - a2 / 80.0 * (1.0 - a2 / 168.0)))
    ang = np.sqrt(a2)
    return np.cos(0.5 * ang), np.sin(0.5 * ang) / ang


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
def _rotate_small(eps, v):
    """v ← (I + [ε×]) v: a vector in the reference frame follows a small rotation ε."""
    l0 = v[0] + eps[1] * v[2] - eps[2] * v[1]
    l1 = v[1] + eps[2] * v[0] - eps[0] * v[2]
    l2 = v[2] + eps[0] * v[1] - eps[1] * v[0]
    v[0] = l0
    v[1] = l1
    v[2] = l2


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
def _gate(P, H, kc, r, y, gate, gating, force, soft, U, S, Sinv):
    """The gate of :func:`_gated_update` and :func:`_level_update`: fills ``U = P Hᵀ``
    (n × m) and, when gating (and not forced), ``S = H U + r I``, its inverse and the NIS
    ``yᵀ S⁻¹ y``; returns (NIS, r, accepted) — beyond ``gate`` a hard gate rejects, a soft
    one returns r scaled by NIS/gate."""
    m = y.size
    for i in range(P.shape[0]):
        for j in range(m):
            acc = 0.0
            for k in range(kc):
                acc += P[i, k] * H[j, k]
            U[i, j] = acc
    nis = 0.0
    if gating and not force:
        for i in range(m):
            for j in range(m):
                acc = r if i == j else 0.0
                for k in range(kc):
                    acc += H[i, k] * U[k, j]
                S[i, j] = acc
        _inverse_sym(S, m, Sinv)
        for i in range(m):
            for j in range(m):
                nis += y[i] * Sinv[i, j] * y[j]
        if nis > gate:
            if not soft:
                return nis, r, False
            r *= nis / gate
    return nis, r, True


@njit(cache=True, inline="always", error_model="numpy")
def _gated_update(P, H, kc, r, y, gate, gating, force, soft, dx, U, S, Sinv):
    """Gated update of P with m ≤ 3 rows H, noise ``R = r I`` and innovation y; returns
    (NIS, accepted). dx += K y. H is zero beyond its first ``kc`` columns.

    The NIS ``yᵀ S⁻¹ y`` (``S = H U + R``, ``U = P Hᵀ``) decides first: beyond the gate
    a hard gate rejects, a soft gate de-weights (R scaled by NIS/gate, a Huber-type
    bounded step). Then, R being diagonal, the rows are applied one after the other,
    which equals the joint update exactly: row j's ``u_j = P_j hⱼᵀ`` on the P the
    earlier rows left is ``U_j − Σ_{i<j} u_i (hⱼ·u_i)/s_i`` (U's columns become the
    u_j), ``s_j = hⱼ·u_j + r``, its gain step ``g_j = (y_j − Σ_{i<j} (hⱼ·u_i) g_i)/s_j``;
    then ``dx += Σ u_j g_j`` and ``P ← P − Σ u_j u_jᵀ/s_j`` (symmetric). Work arrays
    U (n × m); S and Sinv (m × m) hold the gain steps and 1/s_j in their first column
    once the NIS is taken.
    """
    m = y.size
    n = P.shape[0]
    nis, r, ok = _gate(P, H, kc, r, y, gate, gating, force, soft, U, S, Sinv)
    if not ok:
        return nis, False
    for j in range(m):
        innov = y[j]
        for i in range(j):
            hu = 0.0
            for k in range(kc):
                hu += H[j, k] * U[k, i]
            innov -= hu * S[i, 0]  # S[i, 0]: row i's gain step
            c = hu * Sinv[i, 0]  # Sinv[i, 0]: 1 / s_i
            for k in range(n):
                U[k, j] -= U[k, i] * c
        sj = r
        for k in range(kc):
            sj += H[j, k] * U[k, j]
        Sinv[j, 0] = 1.0 / sj
        S[j, 0] = innov * Sinv[j, 0]
    for j in range(m):
        gj = S[j, 0]
        ij = Sinv[j, 0]
        for i in range(n):
            dx[i] += U[i, j] * gj
            ui = U[i, j] * ij
            for k in range(n):
                P[i, k] -= ui * U[k, j]
    return nis, True


@njit(cache=True, inline="always", error_model="numpy")
def _level_update(P, H, kc, r, y, gate, gating, force, soft, dx, C, U, K, w, S, Sinv):
    """:func:`_gated_update` with the gain kept off the heading; returns (NIS, accepted).

    The NIS and the gate are :func:`_gated_update`'s (:func:`_gate`; H zero beyond its
    first ``kc`` columns). Then each row in turn: ``u = P hⱼᵀ``, ``s = hⱼ·u + r``,
    ``K = u / s`` with its attitude part projected off the reference vertical (``c = C₃ᵀ``
    in the body frame: ``K_θ ← (I − c cᵀ) K_θ``), the other states' as they are, and P the
    Joseph form for that gain, ``P − K uᵀ − u Kᵀ + s K Kᵀ``, exact for any gain; the row's
    innovation less what the earlier rows' corrections explain. dx += Σ K innov. Work
    arrays U (n × m; column j holds row j's u), K, w (n,), S, Sinv (m × m). The
    counterpart of :func:`_consider_update`, whose gain stays off roll and pitch.
    """
    m = y.size
    n = P.shape[0]
    nis, r, ok = _gate(P, H, kc, r, y, gate, gating, force, soft, U, S, Sinv)
    if not ok:
        return nis, False
    for i in range(n):
        w[i] = 0.0
    for j in range(m):
        sj = r
        innov = y[j]
        for i in range(n if j > 0 else 0):  # row 0's u is the gate's; later rows' P moved
            acc = 0.0
            for k in range(kc):
                acc += P[i, k] * H[j, k]
            U[i, j] = acc
        for k in range(kc):
            sj += H[j, k] * U[k, j]
            innov -= H[j, k] * w[k]
        kv = (C[2, 0] * U[0, j] + C[2, 1] * U[1, j] + C[2, 2] * U[2, j]) / sj
        for i in range(n):
            K[i] = U[i, j] / sj - (C[2, i] * kv if i < 3 else 0.0)
        for i in range(n):
            for k in range(n):
                P[i, k] += sj * K[i] * K[k] - K[i] * U[k, j] - U[i, j] * K[k]
            w[i] += K[i] * innov
    for i in range(n):
        dx[i] += w[i]
    return nis, True


@njit(cache=True, inline="always", error_model="numpy")
def _recovery_due(gating, clean, bad_since, tk, limit):
    """Innovations have failed the gate for longer than ``limit`` while the sensor looks clean."""
    return gating and clean and bad_since >= 0.0 and tk - bad_since > limit


@njit(cache=True, inline="always", error_model="numpy")
def _outcome(ok, tk, bad_since, used, rejected):
    """Flag bits and the start of the current run of rejections after one gated update."""
    if ok:
        return used, -1.0
    return rejected, tk if bad_since < 0.0 else bad_since


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
def _n_epochs(prop, offsets, n_x, n_samples):
    """Epochs of the main scheme (the sliding start-up steps not counted)."""
    if prop.rk4:
        return (n_samples - 1) // 2
    if n_x - 1 - offsets.max() >= 0:
        return (n_x - 1 - offsets.max()) // prop.stride + 1
    return 0


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
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


@njit(cache=True, inline="always", error_model="numpy")
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


#: A rate at this fraction of the gyro's range or beyond is taken as clipped: a clipped
#: gyro's plateaus are flat to 0.2 % (:mod:`strapdown.ahrs.saturation`).
CLIP_NEAR = 0.98


@njit(cache=True, inline="always", error_model="numpy")
def _rate_at(k, x, h, is_rate, a):
    """The gyro's rate of sample k about axis a, rad/s, bias not removed: ``x[k]`` for
    rate samples (the last row past the record's end), the increment that ends at sample
    k over ``h`` for increments."""
    return x[min(k, x.shape[0] - 1), a] if is_rate else x[k - 1, a] / h


@njit(cache=True, inline="always", error_model="numpy")
def _fold_rest_samples(last, k, ema_n, rest_alpha, x, acc, h, is_rate, gm, g2, am, a2):
    """Stage 2: fold samples last + 1 … k into the rest detector's exponential moving
    averages of gyro and accelerometer (and of their squares); returns (last, ema_n)."""
    while last < k:
        last += 1
        ema_n += 1.0
        al = max(rest_alpha, 1.0 / ema_n)
        for a in range(3):
            wv = _rate_at(last, x, h, is_rate, a)
            gm[a] += al * (wv - gm[a])
            g2[a] += al * (wv * wv - g2[a])
            am[a] += al * (acc[last, a] - am[a])
            a2[a] += al * (acc[last, a] * acc[last, a] - a2[a])
    return last, ema_n


@njit(cache=True, inline="always", error_model="numpy")
def _fold_clip_samples(last, k, x, h, is_rate, params, last_clip):
    """Stage 2: the time of the latest of samples last + 1 … k whose rate reaches the
    gyro's range on an axis (:data:`CLIP_NEAR` of ``clip_level`` or beyond), else
    ``last_clip``."""
    if params.clip_level > 0.0:
        j = last
        while j < k:
            j += 1
            for a in range(3):
                if abs(_rate_at(j, x, h, is_rate, a)) >= CLIP_NEAR * params.clip_level:
                    last_clip = j * h
    return last_clip


@njit(cache=True, inline="always", error_model="numpy")
def _process_noise(T, params):
    """Stage 3, the terms of ``Φ`` and ``Q`` over a step T (scalars): the manoeuvre
    state's decay e^{−T/τ} and the variances added to attitude, gyro bias, manoeuvre
    acceleration (the Singer (1970) process) and accelerometer bias."""
    tau_a = params.singer_tau
    qa = params.singer_sigma ** 2 * (1.0 - np.exp(-2.0 * T / tau_a))
    return (np.exp(-T / tau_a), params.gyro_noise ** 2 * T, params.gyro_bias_rw ** 2 * T, qa,
            params.acc_bias_rw ** 2 * T)


@njit(cache=True, inline="always", error_model="numpy")
def _propagate_covariance(P, phi, T, decay, singer, A, M):
    """Stage 3: ``P ← Φ P Φᵀ`` with Φ = [[exp(−[φ×]), −T I], [0, I]] on attitude and gyro
    bias, ``decay I`` on the Singer state (``singer``: rows 6–8) and I on the
    accelerometer bias, exp(−[φ×]) ≈ I − [φ×] + ½[φ×]²; work arrays A (3 × 3), M (n × n)."""
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
    # in blocks (a: attitude, b: gyro bias, e: the rest), with Y = A P_aa − T P_ba:
    # P_ab ← A P_ab − T P_bb, P_aa ← Y Aᵀ − T P_ab(new), P_bb unchanged; row e of the
    # rest scaled by its decay d_e: P_ea ← d_e (P_ea Aᵀ − T P_eb), P_eb ← d_e P_eb,
    # P_ef ← d_e d_f P_ef. M holds Y and the new P_ab first (constant-size loops).
    for i in range(3):
        for j in range(3):
            M[i, j] = (A[i, 0] * P[0, j] + A[i, 1] * P[1, j] + A[i, 2] * P[2, j]
                       - T * P[3 + i, j])
            M[i, 3 + j] = (A[i, 0] * P[0, 3 + j] + A[i, 1] * P[1, 3 + j]
                           + A[i, 2] * P[2, 3 + j] - T * P[3 + i, 3 + j])
    for i in range(3):
        for j in range(i + 1):
            v = (M[i, 0] * A[j, 0] + M[i, 1] * A[j, 1] + M[i, 2] * A[j, 2]
                 - T * M[i, 3 + j])
            P[i, j] = v
            P[j, i] = v
        for j in range(3):
            P[i, 3 + j] = M[i, 3 + j]
            P[3 + j, i] = M[i, 3 + j]
    for e in range(6, nx):
        de = decay if singer and e < 9 else 1.0
        for j in range(3):
            v = de * (P[e, 0] * A[j, 0] + P[e, 1] * A[j, 1] + P[e, 2] * A[j, 2]
                      - T * P[e, 3 + j])
            M[e, j] = v
        for j in range(3):
            P[e, j] = M[e, j]
            P[j, e] = M[e, j]
            P[e, 3 + j] = de * P[e, 3 + j]
            P[3 + j, e] = P[e, 3 + j]
        for f in range(6, e + 1):
            v = de * (decay if singer and f < 9 else 1.0) * P[e, f]
            P[e, f] = v
            P[f, e] = v


@njit(cache=True, inline="always", error_model="numpy")
def _add_process_noise(P, C, phi, T, qg, qb, qa, qab, params, singer, unobserved, disturbed,
                       tilt_m):
    """Stage 3: ``P += Q``. The attitude gets the gyro's white noise and, for the gyro's
    scale-factor and misalignment errors, ``m tilt_rate_noise² |ω|² T`` on the two tilt
    axes (horizontal in the reference frame: ``I − c cᵀ`` in the body frame with
    c = C₃ᵀ, the vertical; ``m``: ``tilt_m``, :func:`_tilt_adapt`'s factor) and
    ``heading_rate_noise² |ω|² T`` on the heading (``c cᵀ``) unless the last epoch found
    the field disturbed (``disturbed``): a fast rotation lets the accelerometer correct
    tilt sooner and the field correct the heading sooner, while a disturbed field, used
    de-weighted, does not gain weight with the rotation. ``unobserved`` (the last epoch
    rejected a disturbed field, with ``heading_bridge_noise``): the heading takes at least
    the tilt's rate noise — the gyro's rate errors do not know which axis is vertical, and
    with no field they accumulate about the vertical unchecked."""
    w2 = (phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2) / T
    qs = tilt_m * params.tilt_rate_noise ** 2 * w2
    hr = max(params.tilt_rate_noise, params.heading_rate_noise) if unobserved else (
        0.0 if disturbed else params.heading_rate_noise)
    qv = hr ** 2 * w2 - qs
    for r in range(3):
        for c in range(3):
            P[r, c] += ((qg + qs) if r == c else 0.0) + qv * C[2, r] * C[2, c]
    nx = P.shape[0]
    for r in range(3):
        P[3 + r, 3 + r] += qb
        if singer:
            P[6 + r, 6 + r] += qa
        if nx > (9 if singer else 6):
            P[nx - 3 + r, nx - 3 + r] += qab


@njit(cache=True, inline="always", error_model="numpy")
def _tilt_adapt(nis_rate, params):
    """Stage 3: the factor ``m`` on the tilt's rate noise (:func:`_add_process_noise`) —
    1 while the low-pass accelerometer's innovations are as small as the model expects,
    else their power ``nis_rate`` (:func:`_innovation_power`) over ``tilt_adapt_level``, at
    most ``tilt_adapt_max``. Innovations persistently larger than the model allows mean
    that the tilt is off by more than its covariance claims (the gyro's errors outgrew
    ``tilt_rate_noise``: a scale error at a swing's rates, a clipped gyro); the grown
    variance lets the accelerometer correct it (an innovation-based adaptive process
    noise, Mohamed & Schwarz (1999))."""
    if nis_rate <= params.tilt_adapt_level:
        return 1.0
    return min(nis_rate / params.tilt_adapt_level, params.tilt_adapt_max)


@njit(cache=True, inline="always", error_model="numpy")
def _innovation_power(nis_rate, nis, T, params):
    """Stage 5, after the low-pass update (used or rejected; not when the measurement
    is disturbed or waits): the moving mean, gain ``adapt_k`` per epoch (time constant
    ``tilt_adapt_s``), of ``NIS / T``, each NIS counted at most as the gate
    (``acc_gate_lowpass``: one outlier, a tap, does not count as a run of them). With
    ``R = density² / T`` the NIS of an epoch is ``T`` times the innovation's power against
    the density: ``NIS / T`` (1/s) does not change with the sample rate."""
    if not nis >= 0.0:  # no NIS (NaN): nothing learned
        return nis_rate
    return nis_rate + params.adapt_k * (min(nis, params.acc_gate_lowpass) / T - nis_rate)


@njit(cache=True, inline="always", error_model="numpy")
def _heading_adapt(nis_mean, near_clip):
    """Stage 6: the factor ``m`` on the field heading's measurement variance — the moving
    mean ``nis_mean`` (:func:`_heading_power`) of the heading NIS against the unadapted
    variance, when above 1 (a consistent filter's mean), else 1; 1 also within
    ``gyro_clip_s`` of a clipped gyro sample (``near_clip``), where the heading measured
    through the attitude is wrong with the rotation the gyro missed and the gate, not a
    wider variance, is what keeps it out. Heading innovations persistently larger than
    the model allows mean that the measured heading is worse than ``heading_noise`` says
    — at a steep dip, the tilt's error beyond its covariance turned into heading by
    tan(dip) (a swinging body, whose accelerometer never sees gravity alone), or a
    field the norm and dip tests do not call disturbed — and that the gate would reject
    a clean field for good; the grown variance keeps the field in use, weighed as it
    deserves (an innovation-based adaptive measurement noise, Mohamed & Schwarz (1999),
    as :func:`_tilt_adapt` is for the process noise)."""
    if near_clip or not nis_mean > 1.0:
        return 1.0
    return nis_mean


@njit(cache=True, inline="always", error_model="numpy")
def _heading_power(nis_mean, nis0, params):
    """Stage 6, after a heading update (used or rejected) on an undisturbed field that
    no recovery forced, away from a clipped gyro sample: the moving mean, gain
    ``mag_adapt_k`` per epoch (time constant ``mag_adapt_s``), of the NIS against the
    unadapted variance ``nis0``, each counted at most as the gate (``mag_gate``): one
    outlier does not count as a run of them, and the factor stays below the gate — a
    field off by more than the gate's width of the adapted variance (a magnet carried
    along, which the norm and dip tests can miss) is still rejected."""
    if not nis0 >= 0.0:
        return nis_mean
    return nis_mean + params.mag_adapt_k * (min(nis0, params.mag_gate) - nis_mean)


@njit(cache=True, inline="always", error_model="numpy")
def _scale_floor(P, phi, T, sigma, k, w_slow):
    """Stage 3, with ``gyro_scale_sigma`` (``sigma``): the gyro's scale error on a
    sustained rotation is a slowly varying bias ``s ω̄``; the bias's variance is raised to
    at least ``(σ_s ω̄_a)²`` per axis, ``ω̄`` (``w_slow``, updated here) the epoch's
    bias-corrected rate ``φ/T`` averaged with gain ``k`` per epoch (``Params.scale_k``:
    time constant ``gyro_scale_tau``). Raising a diagonal element keeps P positive
    semi-definite."""
    for a in range(3):
        w_slow[a] += k * (phi[a] / T - w_slow[a])
        f = (sigma * w_slow[a]) ** 2
        if P[3 + a, 3 + a] < f:
            P[3 + a, 3 + a] = f


@njit(cache=True, inline="always", error_model="numpy")
def _rest_detect(ema_n, rest_alpha, params, gm, g2, am, a2, g_meas):
    """Stage 4, detection from the moving averages; returns (acc_quiet, at_rest).

    Quiet accelerometer: low variance and a mean of gravity's magnitude as this
    accelerometer measures it (``g_meas``: over a still initial window; after a start in
    motion the nominal one until the first rest measures it; an uncalibrated scale factor
    of a few per cent — OpenAXES's sensors read 9.44 m/s² at rest — is not a sustained
    manoeuvre); at rest: also a gyro of low variance and small mean.
    """
    sg = 0.0
    sacc = 0.0
    for a in range(3):
        sg += max(g2[a] - gm[a] * gm[a], 0.0)
        sacc += max(a2[a] - am[a] * am[a], 0.0)
    wm2 = gm[0] ** 2 + gm[1] ** 2 + gm[2] ** 2
    settled = ema_n * rest_alpha > 1.0
    ra = params.rest_acc
    a_norm = np.sqrt(am[0] ** 2 + am[1] ** 2 + am[2] ** 2)
    acc_quiet = settled and sacc < ra * ra and abs(a_norm - g_meas) < ra
    rg = params.rest_gyro
    at_rest = acc_quiet and sg < rg * rg and wm2 < params.rest_gyro_mean ** 2
    return acc_quiet, at_rest


@njit(cache=True, inline="always", error_model="numpy")
def _rest_still(k, x, acc, h, is_rate, params, gm, am):
    """Stage 4, the latest sample: its gyro within ``rest_gyro`` and its specific force
    within ``rest_acc`` of the moving averages (the norm of the deviation; VQF's per-sample
    test, Laidig & Seel (2023), Sec. 2.6). The averages lag by ``rest_tau``: a motion that
    starts slowly (a spin-up) keeps their variance low for a while and moves their mean
    with it, so without this test the rest update learns the first degrees per second of
    the motion as gyro bias, which no later measurement can undo."""
    dg = 0.0
    da = 0.0
    for a in range(3):
        dg += (_rate_at(k, x, h, is_rate, a) - gm[a]) ** 2
        da += (acc[k, a] - am[a]) ** 2
    return dg < params.rest_gyro ** 2 and da < params.rest_acc ** 2


@njit(cache=True, inline="always", error_model="numpy")
def _rest_model(params, bias, gm, dx, y):
    """Stage 4, measurement: the zero-rate measurement of the gyro bias (at rest the
    gyro's mean is its bias; ``H = [0, I, 0]``, fixed; ``R = rest_noise²/T I``): the
    innovation y."""
    for a in range(3):
        y[a] = gm[a] - (bias[a] + dx[3 + a])


@njit(cache=True, inline="always", error_model="numpy")
def _acc_recovery(params, P):
    """Stage 5, recovery: inflate the tilt covariance (and, in the raw model, the
    manoeuvre acceleration's); returns its flag."""
    ra = params.recover_angle ** 2
    for a in range(3):
        P[a, a] += ra
        if not params.acc_lowpass:
            P[6 + a, 6 + a] += params.singer_sigma ** 2
    return F_ACC_RECOVERED


@njit(cache=True, inline="always", error_model="numpy")
def _lowpass(x, n, n_init, b0, b1, b2, a1, a2, s0, s1, out):
    """One step of a second-order low-pass (direct form II transposed) over the vector x
    into ``out``; returns the updated count n. The first ``n_init`` steps average
    instead, then start the filter in that steady state (Laidig & Seel (2023), VQF's
    ``filterVec``; ``s1`` holds the running sum meanwhile)."""
    m = x.size
    if n < n_init:
        n += 1
        for a in range(m):
            s1[a] += x[a]
            out[a] = s1[a] / n
        if n == n_init:  # the steady state of a constant input (ekf_kernel's Initial.lowpass
            # start likewise: a helper called here cost 8 % of the filter's throughput)
            for a in range(m):
                s0[a] = out[a] * (1.0 - b0)
                s1[a] = out[a] * (b2 - a2)
        return n
    for a in range(m):
        yv = b0 * x[a] + s0[a]
        s0[a] = b1 * x[a] - a1 * yv + s1[a]
        s1[a] = b2 * x[a] - a2 * yv
        out[a] = yv
    return n


@njit(cache=True, inline="always", error_model="numpy")
def _acc_lowpass_model(lp_n, params, C, fk, fn, lp, s0, s1, dx, H, y):
    """Stage 5, low-pass accelerometer model (Laidig & Seel (2023) — VQF's): the specific
    force rotated into the reference frame and low-passed (second-order Butterworth of
    time constant ``acc_lowpass_s``, :func:`_lowpass`) is gravity — manoeuvres average
    out; ``lp − g_up ≈ [g_up×] C δθ`` (horizontal rows). The low-pass states follow
    every correction (:func:`_reset`), so the filter runs in an almost-inertial frame.
    Updates ``lp`` and fills H and the innovation y (``R = acc_lowpass_noise²/T I``);
    returns the count."""
    g = params.gravity
    nx = H.shape[1]
    for a in range(3):
        fn[a] = C[a, 0] * fk[0] + C[a, 1] * fk[1] + C[a, 2] * fk[2]
    lp_n = _lowpass(fn, lp_n, params.lp_init_n, params.lp_b0, params.lp_b1, params.lp_b2,
                    params.lp_a1, params.lp_a2, s0, s1, lp)
    for a in range(3):
        H[0, a] = -g * C[1, a]
        H[1, a] = g * C[0, a]
        if nx > 6:  # the residual accelerometer bias, seen in the reference frame
            H[0, nx - 3 + a] = C[0, a]
            H[1, nx - 3 + a] = C[1, a]
    y[0] = lp[0]
    y[1] = lp[1]
    _sub_hdx(y, H, dx)
    return lp_n


@njit(cache=True, inline="always", error_model="numpy")
def _motion_power(dyn2, lp_n, params, lp, lp2, dmean):
    """Stage 5, low-pass model: what of the motion acceleration the low-pass lets through,
    seen as the low-passed specific force ``lp`` less a slower mean of it ``lp2`` (time
    constant ``MOTION_SLOW`` × ``acc_lowpass_s``, in the same reference frame) on the
    horizontal axes, ``d = lp − lp2``; returns its moving mean square (time constant
    ``acc_lowpass_s``; unchanged while the low-pass is still averaging) and keeps its
    moving mean ``dmean`` over the same window (:func:`_motion_variance`). Tilt errors change
    slowly, gravity not at all: a swing's or a circle's slow acceleration is what moves
    ``lp`` from ``lp2``."""
    if lp_n < params.lp_init_n:
        for a in range(3):
            lp2[a] = lp[a]
        return dyn2
    d2 = 0.0
    for a in range(3):
        lp2[a] += params.dyn_k2 * (lp[a] - lp2[a])
        d = lp[a] - lp2[a]
        dmean[a] += params.dyn_k * (d - dmean[a])
        if a < 2:
            d2 += d * d
    return dyn2 + params.dyn_k * (d2 - dyn2)


@njit(cache=True, inline="always", error_model="numpy")
def _motion_variance(dyn2, dmean):
    """Stage 5, low-pass model: the motion power the accelerometer's weight uses — the
    variance of ``d = lp − lp2`` over the window, its mean square ``dyn2`` less the square of
    its mean ``dmean`` (horizontal axes; :func:`_motion_power`). What the low-pass lets
    through of a swing, a shake or a turn comes and goes within the window; a step of ``lp``
    that stays — the tilt error a burst of rotation leaves behind, which the gyro's timing
    and scale errors make — is in the mean and adds none, so the filter is not made deaf to
    its own error (docs/algorithms.md, "The accelerometer's weight in motion")."""
    return max(dyn2 - dmean[0] * dmean[0] - dmean[1] * dmean[1], 0.0)


@njit(cache=True, inline="always", error_model="numpy")
def _lowpass_variance(params, dyn2, T):
    """Stage 5, low-pass model: the measurement variance per horizontal axis, ``R = (n² +
    κ² τ ā²)/T``: the noise density ``n`` (``acc_lowpass_noise``) and the part of the
    motion acceleration (power ``ā²``, :func:`_motion_variance`) that the low-pass of
    time constant ``τ`` lets through — a fraction ``κ`` (``acc_motion_leak``), correlated
    over ``τ``. A body that swings or circles for minutes is weighed by what its
    accelerometer shows, not dragged by it."""
    k2 = params.acc_motion_leak * params.acc_motion_leak
    return (params.acc_lowpass_noise ** 2 + k2 * params.acc_lowpass_s * dyn2) / T


@njit(cache=True, inline="always", error_model="numpy")
def _lowpass_plausible(lp, params, g_meas):
    """Low-pass model: the low-passed specific force has gravity's norm as this
    accelerometer measures it (``g_meas``: over a still initial window or at the first
    rest; the nominal one before that) within ``acc_lowpass_norm_tol``; a sustained
    acceleration — a coordinated turn's centripetal one, which no low-pass removes —
    makes it longer (by 1.5 % at 10° of bank, 6.4 % at 20°)."""
    n = np.sqrt(lp[0] ** 2 + lp[1] ** 2 + lp[2] ** 2)
    return abs(n - g_meas) <= params.acc_lowpass_norm_tol * g_meas


#: Gravity's norm is not learned (:func:`_learn_gravity`) while the rate about the vertical,
#: averaged as the norm is (time constant ``MOTION_SLOW`` × ``acc_lowpass_s``), lies between
#: these (rad/s): a turn, whose centripetal acceleration lengthens the low-passed specific
#: force as a scale error would. A coordinated turn at a bank of 10° (1.5 % longer) turns at
#: ``g tan φ / v``, 0.03 rad/s at 58 m/s and faster below; no vehicle turns at more than
#: 2 rad/s at such a bank (it would go at under 0.9 m/s on a 0.4 m circle), while a spin
#: about a vertical axis, which carries no centripetal acceleration at its axis, does.
#: Without the test a vehicle cut in a steady turn (at 14.5 °/s, with an accelerometer
#: 1.5 % short) took its turn for gravity (``benchmarks/ahrs_motion_start.py``).
LEARN_MAX_TURN = 0.03
LEARN_MIN_SPIN = 2.0


@njit(cache=True, inline="always", error_model="numpy")
def _learn_gravity(lp, params, g_learn, n_learn):
    """Stage 5, low-pass model, while no still start or rest has measured gravity's norm
    (a start in motion): the norm of the low-passed specific force ``lp``, averaged, is
    gravity's norm as this accelerometer measures it — a swing's, a shake's or a circle's
    acceleration averages out of ``lp``, an accelerometer's scale error does not. The
    average ``g_learn`` over the ``n_learn`` epochs so far is a running mean until it
    spans ``MOTION_SLOW`` × ``acc_lowpass_s`` (gain ``dyn_k2`` per epoch), then a moving
    one with that time constant. Returns it, the count and the norm
    :func:`_lowpass_plausible` tests against: the nominal ``gravity`` until the average
    spans its time constant, then :func:`_gravity_in_use`'s."""
    n_learn += 1.0
    k = max(params.dyn_k2, 1.0 / n_learn)
    g_learn += k * (np.sqrt(lp[0] ** 2 + lp[1] ** 2 + lp[2] ** 2) - g_learn)
    if k > params.dyn_k2:
        return g_learn, n_learn, params.gravity
    return g_learn, n_learn, _gravity_in_use(g_learn, params)


@njit(cache=True, inline="always", error_model="numpy")
def _gravity_in_use(g_learn, params):
    """The learned norm of gravity when it lies within ``acc_scale_tol`` of the nominal
    ``gravity``, else the nominal: a norm further off is a sustained acceleration or an
    accelerometer worse than the filter allows for, and is not taken for gravity's."""
    if abs(g_learn - params.gravity) <= params.acc_scale_tol * params.gravity:
        return g_learn
    return params.gravity


@njit(cache=True, inline="always", error_model="numpy")
def _acc_plausible(fk, params):
    """Raw model: the specific force's norm is g within ``acc_norm_tol`` (always, without
    gating)."""
    fa = np.sqrt(fk[0] ** 2 + fk[1] ** 2 + fk[2] ** 2)
    g = params.gravity
    return not (params.gating and abs(fa - g) > params.acc_norm_tol * g)


@njit(cache=True, inline="always", error_model="numpy")
def _lever_sigma(k, x, h, is_rate, bias, lever_arm):
    """Raw model: the standard deviation that rotation seen at a lever arm adds to the
    accelerometer noise (centripetal ``|ω|²`` plus tangential ``|ω̇|``, times the arm).
    Causal: rates up to sample k, increments up to the interval that ends at it."""
    kk = min(k, x.shape[0] - 1) if is_rate else k - 1
    w2 = 0.0
    wd2 = 0.0
    for a in range(3):
        wa = _rate_at(k, x, h, is_rate, a) - bias[a]
        w2 += wa * wa
        dw = x[kk, a] - x[max(kk - 1, 0), a]
        wd2 += (dw / h if is_rate else dw / (h * h)) ** 2
    return lever_arm * (w2 + np.sqrt(wd2))


@njit(cache=True, inline="always", error_model="numpy")
def _acc_raw_model(params, accel, C, fk, v, dx, H, y):
    """Stage 5, raw accelerometer model (Wang, Wang & Wang): ``f = C_b_n g_up + a_b``,
    ``H = [[v̂×], 0, I (, I)]`` (the noise, ``acc_noise²/T`` widened by the lever
    term of :func:`_lever_sigma`, is the caller's): fills H and the innovation y."""
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


@njit(cache=True, inline="always", error_model="numpy")
def _fold_delay_samples(last, k, n_seen, x, mag, hv, h, is_rate, bias, alpha, res):
    """Stage 6, the delay estimator: fold samples last + 1 … k into ``res[d]``, the moving
    average of the field's kinematic residual ``|Δm_j + h ω̄_{j−d} × m̄_j|²`` for each
    candidate delay d (samples): a field constant in the reference frame turns in the
    body frame as ``ṁ = −ω × m``, so a magnetometer d samples late matches the gyro of
    d samples earlier best (ω̄: the bias-corrected mean rate over the interval, m̄ the
    mean field, less the online hard-iron offset ``hv[V_APP]``, which does not turn).
    Returns (last, samples seen); the delay is the argmin of ``res``."""
    dmax = res.size - 1
    while last < k:
        last += 1
        if last < dmax + 2:
            continue  # every candidate needs its gyro interval
        n_seen += 1
        al = max(alpha, 1.0 / n_seen)
        dm0 = mag[last, 0] - mag[last - 1, 0]
        dm1 = mag[last, 1] - mag[last - 1, 1]
        dm2 = mag[last, 2] - mag[last - 1, 2]
        m0 = 0.5 * (mag[last, 0] + mag[last - 1, 0]) - hv[V_APP, 0]
        m1 = 0.5 * (mag[last, 1] + mag[last - 1, 1]) - hv[V_APP, 1]
        m2 = 0.5 * (mag[last, 2] + mag[last - 1, 2]) - hv[V_APP, 2]
        for d in range(dmax + 1):
            j = last - d  # the interval (j − 1, j]
            if is_rate:
                w0 = h * (0.5 * (x[j, 0] + x[j - 1, 0]) - bias[0])
                w1 = h * (0.5 * (x[j, 1] + x[j - 1, 1]) - bias[1])
                w2 = h * (0.5 * (x[j, 2] + x[j - 1, 2]) - bias[2])
            else:
                w0 = x[j - 1, 0] - h * bias[0]
                w1 = x[j - 1, 1] - h * bias[1]
                w2 = x[j - 1, 2] - h * bias[2]
            r0 = dm0 + w1 * m2 - w2 * m1
            r1 = dm1 + w2 * m0 - w0 * m2
            r2 = dm2 + w0 * m1 - w1 * m0
            res[d] += al * (r0 * r0 + r1 * r1 + r2 * r2 - res[d])
    return last, n_seen


@njit(cache=True, inline="always", error_model="numpy")
def _delay_choice(cur, res, n_seen, alpha, z):
    """Stage 6, the delay estimator's decision: the candidate of least residual (``res``,
    :func:`_fold_delay_samples`) replaces the delay in use ``cur`` only when its advantage
    is significant (``z`` standard deviations, ``mag_delay_z``). Between a true delay and a
    wrong one the mean residuals differ by E, the mean square of ``h (ω_{j−d} − ω_{j−c}) × m``; the
    difference of the averages has the standard deviation ``2 σ √(E/N)`` (σ² the noise per
    axis, ``res_min/3``; N the samples averaged, ``min(n_seen, 2/alpha)``). So the switch
    needs ``res[cur] − res_min > (4/3) z² res_min / N``. A steady spin, whose rate barely
    changes over the candidates, makes every delay fit alike (E ≈ 0): the argmin is then
    noise, and a wrong delay turns the field by ω times the error (2.7° at 9.4 rad/s and
    5 ms) — a heading error the delay in use no longer suffers."""
    d = int(np.argmin(res))
    n_eff = min(float(n_seen), 2.0 / alpha)
    if res[cur] - res[d] > z * z * 4.0 / 3.0 * res[d] / n_eff:
        return d
    return cur


@njit(cache=True, inline="always", error_model="numpy")
def _delayed_field(ringC, j, mk, mn):
    """Stage 6: the field sample ``mk`` (body frame, :func:`_at_state_time`) in the
    reference frame, ``mn = C_j m_k`` with the attitude ``ringC[j]`` of the magnetometer's
    delay earlier (it lags the gyro); returns its norm."""
    for a in range(3):
        mn[a] = ringC[j, a, 0] * mk[0] + ringC[j, a, 1] * mk[1] + ringC[j, a, 2] * mk[2]
    return np.sqrt(mn[0] ** 2 + mn[1] ** 2 + mn[2] ** 2)


@njit(cache=True, inline="always", error_model="numpy")
def _at_state_time(v, k, x, h, is_rate, bias, lead, out):
    """Stages 5 and 6: a body-frame sample ``v`` of a fixed reference-frame vector (the
    field; gravity's part of the specific force) taken at sample k's stamp, as it was
    ``lead`` seconds earlier — when the filter's attitude refers (``Params.meas_lead``,
    ``Params.acc_lead``: half a period for a sample taken at the stamp beside interval gyro
    samples, whose attitude refers to the middle of the sample period, as does an interval
    accelerometer sample): ``v(t − δ) = exp(δ[ω×]) v(t)`` to second
    order, ω the bias-corrected rate of sample k. Without it a body spinning at ω sees
    its field turned by ωδ against the attitude — 0.67° at 9.4 rad/s and 400 Hz, a
    steady heading error."""
    kk = min(k, x.shape[0] - 1)
    w0 = lead * ((x[kk, 0] if is_rate else x[kk - 1, 0] / h) - bias[0])
    w1 = lead * ((x[kk, 1] if is_rate else x[kk - 1, 1] / h) - bias[1])
    w2 = lead * ((x[kk, 2] if is_rate else x[kk - 1, 2] / h) - bias[2])
    c0 = w1 * v[2] - w2 * v[1]
    c1 = w2 * v[0] - w0 * v[2]
    c2 = w0 * v[1] - w1 * v[0]
    out[0] = v[0] + c0 + 0.5 * (w1 * c2 - w2 * c1)
    out[1] = v[1] + c1 + 0.5 * (w2 * c0 - w0 * c2)
    out[2] = v[2] + c2 + 0.5 * (w0 * c1 - w1 * c0)


@njit(cache=True, inline="always", error_model="numpy")
def _store_dcm(ringC, j, C):
    """Stage 6: ring row j ← C."""
    for a in range(3):
        for b in range(3):
            ringC[j, a, b] = C[a, b]


@njit(cache=True, inline="always", error_model="numpy")
def _mag_disturbance(T, rate2, params, nd, ms):
    """Stage 6: the magnetic-disturbance state ``ms`` (indices ``M_*``) after one sample
    whose low-passed norm and dip are ``nd``, the gyro's mean rate squared ``rate2``
    (after Laidig & Seel (2023), Sec. 2.5).

    Undisturbed when norm and dip agree with the reference within the tolerances for
    ``mag_settle_s``; then the reference follows them slowly (gain ``mag_ref_k``). A new
    field is accepted as the reference when a candidate stays consistent for
    ``mag_new_s`` seconds of rotation faster than ``mag_new_min_rate`` (a move to
    another place, not a magnet that turns with the sensor). The time rejected grows
    while disturbed and shrinks ``mag_disturbed_factor`` times faster otherwise.
    Returns True when disturbed.
    """
    kr = params.mag_ref_k
    tol_n = params.mag_norm_tol
    tol_d = params.mag_dip_tol
    if abs(nd[0] - ms[M_NORM]) < tol_n * ms[M_NORM] and abs(nd[1] - ms[M_DIP]) < tol_d:
        ms[M_UNDIST] += T
        if ms[M_UNDIST] >= params.mag_settle_s:
            ms[M_DIST] = 0.0
            ms[M_NORM] += kr * (nd[0] - ms[M_NORM])
            ms[M_DIP] += kr * (nd[1] - ms[M_DIP])
    else:
        ms[M_UNDIST] = 0.0
        ms[M_DIST] = 1.0
    if abs(nd[0] - ms[M_CNORM]) < tol_n * ms[M_CNORM] and abs(nd[1] - ms[M_CDIP]) < tol_d:
        if rate2 >= params.mag_new_min_rate ** 2:
            ms[M_CT] += T
        ms[M_CNORM] += kr * (nd[0] - ms[M_CNORM])
        ms[M_CDIP] += kr * (nd[1] - ms[M_CDIP])
        if ms[M_DIST] > 0.0 and ms[M_CT] >= params.mag_new_s:
            ms[M_NORM] = ms[M_CNORM]
            ms[M_DIP] = ms[M_CDIP]
            ms[M_DIST] = 0.0
            ms[M_UNDIST] = params.mag_settle_s
    else:
        ms[M_CT] = 0.0
        ms[M_CNORM] = nd[0]
        ms[M_CDIP] = nd[1]
    if ms[M_DIST] == 0.0:
        ms[M_REJECT] = max(ms[M_REJECT] - params.mag_disturbed_factor * T, 0.0)
    return ms[M_DIST] > 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _mag_provisional(params, nd, ms):
    """Stage 6, after a moving start: the reference norm and dip (and the candidate's) set
    to the low-passed measurement, undisturbed. The dip is measured with the estimated
    tilt, which a start in motion gets wrong by up to tens of degrees until the
    accelerometer has corrected it; a reference learned from it would call the true field
    disturbed for ``mag_new_s`` and keep the heading from converging."""
    ms[M_NORM] = nd[0]
    ms[M_DIP] = nd[1]
    ms[M_CNORM] = nd[0]
    ms[M_CDIP] = nd[1]
    ms[M_UNDIST] = params.mag_settle_s
    ms[M_DIST] = 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _disturbed_factor(params, nd, ms):
    """Stage 6: the heading noise's variance factor for a disturbed field used beyond the
    rejection budget: ``mag_disturbed_factor`` times the squared departure from the
    reference in tolerances (norm or dip, the larger; at least 1) to the power
    ``mag_disturbed_power`` — a mild disturbance is de-weighted, a strong one all but
    rejected."""
    dn = (nd[0] - ms[M_NORM]) / (params.mag_norm_tol * ms[M_NORM])
    dd = (nd[1] - ms[M_DIP]) / params.mag_dip_tol
    return params.mag_disturbed_factor * max(1.0, dn * dn, dd * dd) ** params.mag_disturbed_power


@njit(cache=True, inline="always", error_model="numpy")
def _mag_recovery(P, C, ra):
    """Stage 6, recovery: inflate the heading covariance (about the reference vertical) by
    ``ra`` (rad²): ``recover_angle²`` for a recovery that is due; ``T`` times
    ``Params.provisional_heading_q`` for a start in motion's heading while the field's
    reference is provisional, a random walk against the field's ``heading_noise²/T`` that
    makes the heading a first-order low-pass of the field's, of time constant
    ``moving_start_heading_s`` whatever the sample rate; returns its flag."""
    for r in range(3):
        for s in range(3):
            P[r, s] += ra * C[2, r] * C[2, s]
    return F_MAG_RECOVERED


@njit(cache=True, inline="always", error_model="numpy")
def _hi_steadier(hs, hv, hM):
    """How much steadier the field's squared norm is with the estimate ``b`` (row V_B)
    subtracted: the coefficient of variation of ``|m − b|²`` over that of ``|m|²``, both
    over the forgetting sums, exactly for this ``b`` (``|m − b|² = |m|² − 2bᵀm + |b|²``,
    whose mean and mean square are linear in Σ|m|², Σm, Σ|m|⁴, Σ|m|²m and Σmmᵀ); 1 when
    the norm is constant. (For small variations the ratio is that of the norms' own
    coefficients of variation, which :mod:`strapdown.ahrs.hard_iron` uses.)"""
    w = hs[H_W]
    eq = hs[H_Q] / w
    var_q = hs[H_QQ] / w - eq * eq
    if not var_q > 0.0:
        return 1.0
    beta = hv[V_B, 0] ** 2 + hv[V_B, 1] ** 2 + hv[V_B, 2] ** 2
    bm = 0.0
    bqm = 0.0
    bmmb = 0.0
    for a in range(3):
        bm += hv[V_B, a] * hv[V_M, a]
        bqm += hv[V_B, a] * hv[V_QM, a]
        for d in range(3):
            bmmb += hv[V_B, a] * hM[X_MM, a, d] * hv[V_B, d]
    e1 = eq - 2.0 * bm / w + beta  # mean of |m − b|²
    e2 = (hs[H_QQ] + 4.0 * bmmb - 4.0 * bqm + 2.0 * beta * hs[H_Q] - 4.0 * beta * bm) / w \
        + beta * beta  # its mean square
    var_c = max(e2 - e1 * e1, 0.0)
    return np.sqrt(var_c / var_q) * eq / e1 if e1 > 0.0 else 1.0


@njit(cache=True, inline="always", error_model="numpy")
def _hi_explained(hs, hv, hM, row):
    """``1 − Σ|r − A b|² / Σ|r|² = (2 bᵀ Σ Aᵀr − bᵀ (Σ AᵀA) b) / Σ|r|²`` of the online
    hard-iron sums for the offset ``b`` in row ``row`` of ``hv`` (0 while Σ|r|² is)."""
    if not hs[H_RR] > 0.0:
        return 0.0
    acc = 0.0
    for a in range(3):
        acc += 2.0 * hv[row, a] * hv[V_Y, a]
        for d in range(3):
            acc -= hv[row, a] * hM[X_N, a, d] * hv[row, d]
    return acc / hs[H_RR]


@njit(cache=True, inline="always", error_model="numpy")
def _hi_distance(hv, i, j):
    """|hv[i] − hv[j]|."""
    return np.sqrt((hv[i, 0] - hv[j, 0]) ** 2 + (hv[i, 1] - hv[j, 1]) ** 2
                   + (hv[i, 2] - hv[j, 2]) ** 2)


# Not inlined: it runs once per span (0.1 s), and inlined into the loop it made the kernel's
# cold compile longer (one ekf call with an empty cache: 68.0 CPU-s, 55.8 as a call).
@njit(cache=True, error_model="numpy")
def _hard_iron_span(params, ringC, j, e, m, tk, hs, hv, hM, r, S, Si, G):
    """Stage 6, the online hard-iron estimate (the causal :mod:`strapdown.ahrs.hard_iron`):
    at the end of each span of ``hi_span`` epochs, with the field ``m`` (body frame, the
    offset applied added back) at the attitude ``ringC[j]`` and the previous span end's:
    ``G m − G_p m_p = (G − G_p) b`` (the Earth's field constant in the reference frame),
    ``G = Eᵀ C`` the gyro's own path — the filter's attitude without the corrections the
    resets made, ``E = dcm(e)`` their product (a field that is off turns the filter's
    heading back and forth as the body swings: with C itself the sums took that for
    residual, and a 30 % offset on a swinging body explained 31 % instead of 59 %) —
    summed with forgetting ``hi_forget`` per span as ``Σ AᵀA``, ``Σ Aᵀr``, ``Σ|r|²``;
    ``b`` by ridge least squares (``hi_ridge`` times the trace: the directions the
    rotations do not observe stay near zero, where ``b`` is a constant field in the
    reference frame too). The offset applied becomes ``b`` once, for ``hi_hold_s``,
    ``b`` explains at least ``hi_min_explained`` of ``Σ|r|²``, steadies the field's norm
    (:func:`_hi_steadier` at most ``hi_steadier``) and drifts by at most ``hi_spread`` of
    ``|b|`` — again when ``b`` moves from it by more than ``hi_update`` of ``|b|`` — and
    returns to zero when it explains less than nothing. Returns whether the offset
    changed; the caller then takes the reference heading from the corrected sample in the
    filter's own frame, so that the heading does not jump (carrying the old reference over
    by the change of the mean field's heading assumed the filter had followed the raw
    field; where it had rejected it as disturbed, the heading innovations then failed the
    gate for ``recover_mag_s`` and the recovery turned the heading by 4°; the mean
    corrected field's heading over the sums' window in the filter's frame, which had
    wandered meanwhile, left a drift of 2.4° over the next 45 s). Work arrays r (3), S, Si,
    G (3, 3)."""
    lam = params.hi_forget
    prev = hs[H_PREV] > 0.0
    _dcm(e, S)
    for a in range(3):
        for c in range(3):
            G[a, c] = S[0, a] * ringC[j, 0, c] + S[1, a] * ringC[j, 1, c] + S[2, a] * ringC[j, 2, c]
    rr = 0.0
    for a in range(3):
        r[a] = 0.0
        for c in range(3):
            r[a] += G[a, c] * m[c] - hM[X_PREV, a, c] * hv[V_PREV, c]
        rr += r[a] * r[a]
    qm = m[0] * m[0] + m[1] * m[1] + m[2] * m[2]
    for a in range(3):
        if prev:
            acc = 0.0
            for c in range(3):
                acc += (G[c, a] - hM[X_PREV, c, a]) * r[c]
            hv[V_Y, a] = lam * hv[V_Y, a] + acc
            for d in range(3):
                acc = 0.0
                for c in range(3):
                    acc += (G[c, a] - hM[X_PREV, c, a]) * (G[c, d] - hM[X_PREV, c, d])
                hM[X_N, a, d] = lam * hM[X_N, a, d] + acc
        hv[V_M, a] = lam * hv[V_M, a] + m[a]
        hv[V_QM, a] = lam * hv[V_QM, a] + qm * m[a]
        for d in range(3):
            hM[X_MM, a, d] = lam * hM[X_MM, a, d] + m[a] * m[d]
    for a in range(3):  # this span's end is the next one's start
        hv[V_PREV, a] = m[a]
        for d in range(3):
            hM[X_PREV, a, d] = G[a, d]
    hs[H_PREV] = 1.0
    if prev:
        hs[H_RR] = lam * hs[H_RR] + rr
    hs[H_W] = lam * hs[H_W] + 1.0
    hs[H_Q] = lam * hs[H_Q] + qm
    hs[H_QQ] = lam * hs[H_QQ] + qm * qm
    if not prev:
        return False
    mu = params.hi_ridge * (hM[X_N, 0, 0] + hM[X_N, 1, 1] + hM[X_N, 2, 2])
    for a in range(3):
        for d in range(3):
            S[a, d] = hM[X_N, a, d] + (mu if a == d else 0.0)
    _inverse_sym(S, 3, Si)
    for a in range(3):
        hv[V_B, a] = Si[a, 0] * hv[V_Y, 0] + Si[a, 1] * hv[V_Y, 1] + Si[a, 2] * hv[V_Y, 2]
    explained = _hi_explained(hs, hv, hM, V_B)
    steadier = _hi_steadier(hs, hv, hM)
    nb = np.sqrt(hv[V_B, 0] ** 2 + hv[V_B, 1] ** 2 + hv[V_B, 2] ** 2)
    ok = (mu > 0.0 and hs[H_W] >= params.hi_min_spans and explained >= params.hi_min_explained
          and steadier <= params.hi_steadier)
    if ok and hs[H_HOLD] >= 0.0 and _hi_distance(hv, V_B, V_HOLD) > params.hi_spread * nb:
        hs[H_HOLD] = -1.0  # drifted: hold again from here
    if not ok:
        hs[H_HOLD] = -1.0
    elif hs[H_HOLD] < 0.0:
        hs[H_HOLD] = tk
        for a in range(3):
            hv[V_HOLD, a] = hv[V_B, a]
    applied = hv[V_APP, 0] != 0.0 or hv[V_APP, 1] != 0.0 or hv[V_APP, 2] != 0.0
    if ok and hs[H_HOLD] >= 0.0 and tk - hs[H_HOLD] >= params.hi_hold_s and (
            not applied or _hi_distance(hv, V_B, V_APP) > params.hi_update * nb):
        for a in range(3):
            hv[V_APP, a] = hv[V_B, a]
    elif applied and _hi_explained(hs, hv, hM, V_APP) < 0.0:
        # the offset applied explains less than none
        for a in range(3):
            hv[V_APP, a] = 0.0
    else:
        return False
    hs[H_HOLD] = -1.0
    return True


@njit(cache=True, inline="always", error_model="numpy")
def _heading_model(ref_heading, C, mn, dx, H, y):
    """Stage 6, measurement: the heading of the field's horizontal part. Its Jacobian
    has the heading row ``−(C_n_b)₃`` and, through the field's dip, the tilt rows
    ``(m_z/m_h²)(m_x (C_n_b)₁ + m_y (C_n_b)₂)``: a tilt error about the field's
    horizontal direction shifts the measured heading by tan(dip) times itself.
    :func:`_consider_update` counts that in the innovation variance but keeps the
    update off roll and pitch. Fills H and the innovation y (wrapped to ±π); the
    noise is ``heading_noise²/T`` (times ``mag_disturbed_factor`` while disturbed).
    ``ref_heading``: the reference field's heading (``Params.ref_heading``, moved by the
    online hard-iron estimate's offsets, :func:`_hard_iron_span`)."""
    mh2 = mn[0] * mn[0] + mn[1] * mn[1]
    cx = mn[2] * mn[0] / mh2
    cy = mn[2] * mn[1] / mh2
    for a in range(3):
        H[0, a] = cx * C[0, a] + cy * C[1, a] - C[2, a]
    yv = np.arctan2(mn[1], mn[0]) - ref_heading
    if yv > np.pi:  # atan2 and the reference are in [−π, π]: one turn at most
        yv -= 2.0 * np.pi
    elif yv < -np.pi:
        yv += 2.0 * np.pi
    y[0] = yv
    _sub_hdx(y, H, dx)


@njit(cache=True, inline="always", error_model="numpy")
def _consider_update(P, H, r, y, gate, gating, force, dx, C, u, K, nb):
    """A gated scalar update whose gain is kept off roll and pitch; returns (NIS,
    accepted, S).

    ``S = H P Hᵀ + r`` with the full H (heading and, through the dip, tilt), so the
    heading measurement weighs less while the tilt is uncertain; the gain
    ``K = P Hᵀ / S`` is then projected: its attitude part onto the reference vertical
    (c = C₃ᵀ in the body frame), zero on the states from ``nb`` on (6: beyond the gyro
    bias; 3: the gyro bias too, while a start in motion's heading is recovered or a
    disturbed field is used de-weighted), and P takes the Joseph form for that gain,
    ``P − K uᵀ − u Kᵀ + S K Kᵀ`` (u = P Hᵀ), exact for any gain. dx += K y. Work arrays
    u, K (n,).
    """
    n = P.shape[0]
    for i in range(n):
        acc = 0.0
        for k in range(3):
            acc += P[i, k] * H[0, k]
        u[i] = acc
    S = r + H[0, 0] * u[0] + H[0, 1] * u[1] + H[0, 2] * u[2]
    nis = y[0] * y[0] / S
    if gating and nis > gate and not force:
        return nis, False, S
    kz = (C[2, 0] * u[0] + C[2, 1] * u[1] + C[2, 2] * u[2]) / S
    for i in range(n):
        K[i] = C[2, i] * kz if i < 3 else (u[i] / S if i < nb else 0.0)
    for i in range(n):
        for j in range(n):
            P[i, j] += S * K[i] * K[j] - K[i] * u[j] - u[i] * K[j]
        dx[i] += K[i] * y[0]
    return nis, True, S


@njit(cache=True, inline="always", error_model="numpy")
def _reset(slot, q, ring, bias, accel, acc_bias, P, C, dx, eps, singer):
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
        if singer:
            accel[a] += dx[6 + a]
        if nx > (9 if singer else 6):
            acc_bias[a] += dx[nx - 3 + a]
    for i in range(nx):  # P ← ½ (P + Pᵀ) in place (a + b = b + a exactly)
        for j in range(i + 1, nx):
            s = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = s
            P[j, i] = s


# Longer than the project's 80 lines on purpose: this is the filter's one compiled loop. Its
# stages are the inlined functions above; moving more of the loop into them would pass the
# records into stages, which numba's reference counting makes about 2× slower (see the
# module docstring).
@njit(cache=True, error_model="numpy")
def ekf_kernel(sensors, prop, window, params, init, out):
    """Run the filter over the record; returns the number of epochs run, gravity's norm as
    measured and whether a rest measured it, the online hard-iron offset (3 values) and
    the low-pass model's state at the end (4 values, :attr:`Initial.lowpass`; NaN when the
    model never ran).

    Records: :class:`Sensors`, :class:`Propagation`, :class:`Window`,
    :class:`Params`, :class:`Initial`, :class:`Outputs`; the stages are listed in the
    module docstring. The loop body is the sequence of stages; everything it needs is
    allocated here, once.
    """
    x, acc, mag, h = sensors.x, sensors.acc, sensors.mag, sensors.h
    offsets, weights, pi, pj, pc = window.offsets, window.weights, window.pi, window.pj, window.pc
    is_rate, lag = prop.is_rate, prop.lag
    nx = init.P.shape[0]  # 6; 9 with the Singer state (raw model); + 3 with the acc bias
    singer = not params.acc_lowpass
    (out_q, out_b, out_a, out_ab, out_idx, out_flags, out_nis, out_sig, out_cov, out_bv,
     out_md, out_nis0) = out
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
    w_slow = np.zeros(3)
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
    last_clip = -np.inf  # the time of the last sample at the gyro's range
    # measurement work: C_n_b, the epoch's error-state correction, bias-corrected
    # specific force (body, reference frame), its low-pass and the low-pass states, the
    # field in the reference frame, H, R, y and the update work arrays
    C = np.empty((3, 3))
    dx = np.zeros(nx)
    fk = np.empty(3)
    mk = np.empty(3)
    fa = np.empty(3)
    fn = np.zeros(3)
    lp = np.zeros(3)
    lp_s0 = np.zeros(3)
    lp_s1 = np.zeros(3)
    lp_n = 0
    if params.acc_lowpass and np.all(np.isfinite(init.lowpass[:3])):
        # started in the steady state of a constant input (as _lowpass after its average)
        lp_n = params.lp_init_n
        for a in range(3):
            lp[a] = init.lowpass[a]
            lp_s0[a] = lp[a] * (1.0 - params.lp_b0)
            lp_s1[a] = lp[a] * (params.lp_b2 - params.lp_a2)
    mn = np.empty(3)
    v = np.empty(3)
    eps = np.empty(3)
    H_rest = np.zeros((3, nx))
    for a in range(3):
        H_rest[a, 3 + a] = 1.0
    H_raw = np.zeros((3, nx))
    H_lp = np.zeros((2, nx))
    H_mag = np.zeros((1, nx))
    y3 = np.empty(3)
    y2 = np.empty(2)
    y1 = np.empty(1)
    ku = np.empty(nx)
    kk = np.empty(nx)
    U3 = np.empty((nx, 3))
    U2 = np.empty((nx, 2))
    S3 = np.empty((3, 3))
    Si3 = np.empty((3, 3))
    S2 = np.empty((2, 2))
    Si2 = np.empty((2, 2))
    # the magnetometer: the attitudes of the last mag_delay epochs, the low-passed norm
    # and dip and their filter, the disturbance state (M_* indices)
    d_max = params.mag_delay_max if params.estimate_mag_delay else params.mag_delay
    n_delay = (d_max + prop.stride // 2) // prop.stride + 1  # an attitude per epoch
    ringC = np.empty((n_delay, 3, 3))
    delay_res = np.zeros(d_max + 1)
    delay = params.mag_delay  # samples
    last_d = 0
    n_delay_seen = 0
    _dcm(init.q, C)
    for j in range(n_delay):
        _store_dcm(ringC, j, C)
    nd_raw = np.empty(2)
    nd = np.empty(2)
    mc_s0 = np.zeros(2)
    mc_s1 = np.zeros(2)
    mc_n = 0
    ms = np.zeros(8)
    ms[M_NORM] = params.ref_norm
    ms[M_DIP] = params.ref_dip
    ms[M_CNORM] = params.ref_norm
    ms[M_CDIP] = params.ref_dip
    ms[M_UNDIST] = params.mag_settle_s
    # the online hard-iron estimate (H_*, V_*, X_* indices; _hard_iron_span), the
    # reference heading it moves, and the epochs left of re-referencing the norm and dip
    hs = np.zeros(6)
    hs[H_HOLD] = -1.0
    hv = np.zeros((7, 3))
    hM = np.zeros((3, 3, 3))
    hr = np.empty(3)
    hS = np.empty((3, 3))
    hSi = np.empty((3, 3))
    hG = np.empty((3, 3))
    e_corr = np.zeros(4)  # the product of the resets' corrections, q(ε) ⊗ …
    e_corr[0] = 1.0
    m_raw = np.empty(3)
    ref_heading = params.ref_heading
    refer = 0
    # moving mean square of the motion acceleration through the low-pass
    # (a start in motion's, or a carried one; Initial.lowpass[3])
    dyn2 = init.lowpass[3] if np.isfinite(init.lowpass[3]) else 0.0
    lp2 = np.zeros(3)  # slow mean of the low-passed specific force
    dmean = np.zeros(3)  # moving mean of lp − lp2 (_motion_power)
    if lp_n > 0:  # an initial low-pass (Initial.lowpass) is its slow mean's start too
        for a in range(3):
            lp2[a] = lp[a]
    rest_since = -1.0  # start of the current run of rest detections (−1: none)
    acc_bad_since = -1.0  # start of the current run of rejections (−1: none)
    nis_rate = 0.0  # the low-pass innovations' power (_innovation_power)
    mag_nis_mean = 0.0  # the heading innovations' mean NIS (_heading_power)
    mag_bad_since = -1.0
    heading_unobserved = False  # the last epoch rejected a disturbed field (heading_bridge_noise)
    g_meas = params.gravity_measured  # gravity's norm as measured (or assumed, g_known false)
    g_known = params.gravity_known
    # gravity's norm learned from the low-pass while not measured (_learn_gravity): its
    # average, and the epochs averaged (a carried average counts as settled)
    g_learn = g_meas
    n_learn = 0.0
    if np.isfinite(params.gravity_learned):
        g_learn = params.gravity_learned
        n_learn = np.inf
        if not g_known and params.acc_scale_tol > 0.0:
            g_meas = _gravity_in_use(g_learn, params)
    yaw_lp = 0.0  # the rate about the vertical, averaged as g_learn (a turn: no learning)
    mag_dist_prev = False  # the last epoch found the field disturbed
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
        last_clip = _fold_clip_samples(last, k, x, h, is_rate, params, last_clip)
        last, ema_n = _fold_rest_samples(last, k, ema_n, rest_alpha, x, acc, h, is_rate,
                                         gm, g2, am, a2)
        _dcm(q, C)
        decay, qg, qb, qa, qab = _process_noise(T, params)
        _propagate_covariance(P, phi, T, decay, singer, A, M)
        _add_process_noise(P, C, phi, T, qg, qb, qa, qab, params, singer, heading_unobserved,
                           mag_dist_prev, _tilt_adapt(nis_rate, params))
        if params.gyro_scale_sigma > 0.0:
            _scale_floor(P, phi, T, params.gyro_scale_sigma, params.scale_k, w_slow)
        flags = 0
        dx[:] = 0.0
        tk = k * h
        near_clip = tk - last_clip < params.clip_s  # the gyro clipped within clip_s
        # stage 4: rest
        acc_quiet, at_rest = _rest_detect(ema_n, rest_alpha, params, gm, g2, am, a2, g_meas)
        at_rest = at_rest and _rest_still(k, x, acc, h, is_rate, params, gm, am)
        rest_since = (rest_since if rest_since >= 0.0 else tk) if at_rest else -1.0
        rest_held = at_rest and tk - rest_since >= params.rest_min_s
        if not g_known and rest_held:
            # a moving start's gravity, measured at its first rest
            g_meas = np.sqrt(am[0] ** 2 + am[1] ** 2 + am[2] ** 2)
            g_known = True
        if params.rest_update and rest_held:
            _rest_model(params, bias, gm, dx, y3)
            _gated_update(P, H_rest, 6, params.rest_noise ** 2 / T, y3, 0.0, False, True, False,
                          dx, U3, S3, Si3)
            flags |= F_REST
        # stage 5: accelerometer (recovery, then the accelerometer model's update)
        nis_acc = np.nan
        if params.use_accelerometer:
            for a in range(3):
                fk[a] = acc[k, a] - acc_bias[a]
            if params.acc_lead > 0.0:  # a point sample, turned back to the state's time
                _at_state_time(fk, k, x, h, is_rate, bias, params.acc_lead, fa)
                for a in range(3):
                    fk[a] = fa[a]
            force = _recovery_due(params.gating, acc_quiet, acc_bad_since, tk,
                                  params.recover_acc_s)
            if force:
                flags |= _acc_recovery(params, P)
            if params.acc_lowpass:
                lp_n = _acc_lowpass_model(lp_n, params, C, fk, fn, lp, lp_s0, lp_s1, dx, H_lp,
                                          y2)
                dyn2 = _motion_power(dyn2, lp_n, params, lp, lp2, dmean)
                if not g_known and params.acc_scale_tol > 0.0:
                    yaw_lp += params.dyn_k2 * ((C[2, 0] * phi[0] + C[2, 1] * phi[1]
                                                + C[2, 2] * phi[2]) / T - yaw_lp)
                    if (lp_n >= params.lp_init_n + params.lp_settle
                            and e >= init.lowpass_wait
                            and not LEARN_MAX_TURN < abs(yaw_lp) < LEARN_MIN_SPIN):
                        g_learn, n_learn, g_meas = _learn_gravity(lp, params, g_learn,
                                                                  n_learn)
                # a sustained acceleration (a coordinated turn) does not average out: the
                # low-passed specific force is then longer than gravity — unless the gyro
                # was clipped within clip_s: the attitude then misses the rotation beyond
                # its range, and the low-pass mixes specific forces turned by two attitudes
                disturbed = (params.gating and not _lowpass_plausible(lp, params, g_meas)
                             and not near_clip)
                ok = False
                # lp_settle = 0: no update while the low-pass is still averaging its first
                # lp_init_n epochs unless the accelerometer is quiet (a running mean of a
                # few samples in motion is not gravity)
                if not disturbed and (acc_quiet or (lp_n >= params.lp_init_n + params.lp_settle
                                                       and e >= init.lowpass_wait)):
                    r_lp = _lowpass_variance(params, _motion_variance(dyn2, dmean), T)
                    # without a field the heading is the gyro's alone: the accelerometer's
                    # gain is kept off it (_level_update)
                    if not params.use_magnetometer:
                        nis_acc, ok = _level_update(P, H_lp, 3 if nx == 6 else nx, r_lp, y2,
                                                    params.acc_gate_lowpass, params.gating,
                                                    force, params.soft_gate, dx, C, U2, ku,
                                                    kk, S2, Si2)
                    else:
                        nis_acc, ok = _gated_update(P, H_lp, 3 if nx == 6 else nx, r_lp, y2,
                                                    params.acc_gate_lowpass, params.gating,
                                                    force, params.soft_gate, dx, U2, S2,
                                                    Si2)
                    nis_rate = _innovation_power(nis_rate, nis_acc, T, params)
            else:
                disturbed = not _acc_plausible(fk, params)
                ok = False
                if not disturbed:
                    lever = _lever_sigma(k, x, h, is_rate, bias, params.lever_arm)
                    _acc_raw_model(params, accel, C, fk, v, dx, H_raw, y3)
                    nis_acc, ok = _gated_update(P, H_raw, nx, params.acc_noise ** 2 / T
                                                + lever * lever, y3, params.acc_gate,
                                                params.gating, force, params.soft_gate, dx, U3,
                                                S3, Si3)
            if disturbed:
                flags |= F_ACC_DISTURBED
            else:
                bits, acc_bad_since = _outcome(ok, tk, acc_bad_since, F_ACC_USED,
                                               F_ACC_REJECTED)
                flags |= bits
        # stage 6: magnetometer (delay, disturbance, rejection or de-weighting, recovery,
        # the heading update)
        nis_mag = np.nan
        nis0 = np.nan
        if params.use_magnetometer:
            if params.estimate_mag_delay:
                last_d, n_delay_seen = _fold_delay_samples(last_d, k, n_delay_seen, x, mag, hv, h,
                                                           is_rate, bias, params.mag_delay_alpha,
                                                           delay_res)
                if n_delay_seen > 0:
                    delay = _delay_choice(delay, delay_res, n_delay_seen, params.mag_delay_alpha,
                                          params.mag_delay_z)
            _store_dcm(ringC, step % n_delay, C)
            jd = (step - (delay + prop.stride // 2) // prop.stride) % n_delay
            for a in range(3):
                m_raw[a] = mag[k, a] - hv[V_APP, a]
            _at_state_time(m_raw, k, x, h, is_rate, bias, params.meas_lead, mk)
            offset_changed = False
            if params.hi_on:
                if (step + 1) % params.hi_span == 0:  # a span ends with this epoch
                    for a in range(3):
                        m_raw[a] = mk[a] + hv[V_APP, a]
                    if _hard_iron_span(params, ringC, jd, e_corr, m_raw, tk, hs, hv, hM, hr, hS,
                                       hSi, hG):
                        # the field with the new offset; its reference follows (below)
                        flags |= F_MAG_OFFSET
                        offset_changed = True
                        refer = params.mc_init_n
                        mc_n = 0  # the norm and dip's low-pass starts again
                        mc_s0[:] = 0.0
                        mc_s1[:] = 0.0
                        for a in range(3):
                            m_raw[a] = mag[k, a] - hv[V_APP, a]
                        _at_state_time(m_raw, k, x, h, is_rate, bias, params.meas_lead, mk)
            nb = _delayed_field(ringC, jd, mk, mn)
            if offset_changed:  # the corrected sample's heading in the filter's frame
                ref_heading = np.arctan2(mn[1], mn[0])
            nd_raw[0] = nb
            nd_raw[1] = -np.arcsin(min(max(mn[2] / nb, -1.0), 1.0)) if nb > 0.0 else 0.0
            mc_n = _lowpass(nd_raw, mc_n, params.mc_init_n, params.mc_b0, params.mc_b1,
                            params.mc_b2, params.mc_a1, params.mc_a2, mc_s0, mc_s1, nd)
            provisional = tk < params.mag_provisional_s
            if provisional or refer > 0:
                _mag_provisional(params, nd, ms)
                refer = max(refer - 1, 0)
            dist = params.gating and _mag_disturbance(T, gm[0] ** 2 + gm[1] ** 2 + gm[2] ** 2,
                                                      params, nd, ms)
            horizontal = mn[0] ** 2 + mn[1] ** 2 > 1e-12 * nb * nb
            if dist:
                flags |= F_MAG_DISTURBED
            if horizontal and not (dist and ms[M_REJECT] <= params.mag_reject_s):
                # after a start in motion the heading follows the field (recovered every
                # epoch, at a rate in time) while the tilt, and with it the measured heading,
                # converges
                due = _recovery_due(params.gating, not dist, mag_bad_since, tk,
                                    params.recover_mag_s)
                force = due or provisional
                if force:
                    flags |= _mag_recovery(P, C, params.recover_angle ** 2 if due
                                           else T * params.provisional_heading_q)
                _heading_model(ref_heading, C, mn, dx, H_mag, y1)
                r_mag = params.heading_noise ** 2 / T * (_disturbed_factor(params, nd, ms)
                                                         if dist else 1.0)
                m_mag = _heading_adapt(mag_nis_mean, near_clip)
                nis_mag, ok, s_mag = _consider_update(
                    P, H_mag, r_mag * m_mag, y1, params.mag_gate, params.gating, force, dx, C,
                    ku, kk,
                    # off the gyro bias: the recovered heading of a start in motion (the
                    # start's error, not the bias's), and a disturbed field (its error is
                    # not white: it would teach the bias its own drift)
                    3 if provisional or dist else 6)
                if not force:  # the NIS against the unadapted variance
                    nis0 = y1[0] * y1[0] / (s_mag - (m_mag - 1.0) * r_mag)
                    if params.mag_adapt_k > 0.0 and not (dist or near_clip):
                        mag_nis_mean = _heading_power(mag_nis_mean, nis0, params)
                bits, mag_bad_since = _outcome(ok, tk, mag_bad_since, F_MAG_USED,
                                               F_MAG_REJECTED)
                flags |= bits
            elif dist:
                ms[M_REJECT] += T
            heading_unobserved = params.heading_bridge_noise and dist and (flags & F_MAG_USED) == 0
            mag_dist_prev = dist
        # stage 7: reset
        _reset((e if step >= n_start else step + 1) % lag, q, ring, bias, accel, acc_bias, P,
               C, dx, eps, singer)
        if params.hi_on:  # the hard-iron estimate's gyro path leaves the correction out
            e_corr[0], e_corr[1], e_corr[2], e_corr[3] = _left_rotated(
                eps, e_corr[0], e_corr[1], e_corr[2], e_corr[3])
        if lp_n > 0:  # the low-passed reference-frame specific force follows the correction
            _rotate_small(eps, lp)
            _rotate_small(eps, lp_s0)
            _rotate_small(eps, lp_s1)
            _rotate_small(eps, lp2)
            _rotate_small(eps, dmean)
        # stage 8: record
        for i in range(4):
            out_q[k, i] = q[i]
        for a in range(3):
            out_b[k, a] = bias[a]
            out_sig[k, a] = np.sqrt(max(P[a, a], 0.0))
        if singer:
            for a in range(3):
                out_a[k, a] = accel[a]
        if nx > (9 if singer else 6):
            for a in range(3):
                out_ab[k, a] = acc_bias[a]
        if params.store_covariance:
            for a in range(3):
                out_bv[k, a] = P[3 + a, 3 + a]
                for c in range(3):
                    out_cov[k, a, c] = P[a, c]
        out_idx[step] = k
        out_md[k] = delay
        out_flags[k] = flags
        out_nis[k, 0] = nis_acc
        out_nis[k, 1] = nis_mag
        out_nis0[k] = nis0
    if lp_n == 0:  # the low-pass model never ran: no state to hand on
        for a in range(3):
            lp[a] = np.nan
    return (total, g_meas, g_known, hv[V_APP, 0], hv[V_APP, 1], hv[V_APP, 2], lp[0], lp[1],
            lp[2], dyn2, g_learn)


@njit(cache=True, error_model="numpy")
def predict(q, omega, bias, lead, out):
    """``out[i] = q[i] ⊗ q(lead (ω_i − b_i))`` for rows 1 …: each attitude predicted over
    ``lead`` seconds on its bias-corrected rate (the samples' latency); row 0 copied."""
    for i in range(4):
        out[0, i] = q[0, i]
    eps = np.empty(3)
    for k in range(1, q.shape[0]):
        for a in range(3):
            eps[a] = (omega[k, a] - bias[k, a]) * lead
        dw, s = _small_rotation(eps)
        ex, ey, ez = s * eps[0], s * eps[1], s * eps[2]
        w0, x0, y0, z0 = q[k, 0], q[k, 1], q[k, 2], q[k, 3]
        out[k, 0] = w0 * dw - x0 * ex - y0 * ey - z0 * ez
        out[k, 1] = w0 * ex + x0 * dw + y0 * ez - z0 * ey
        out[k, 2] = w0 * ey - x0 * ez + y0 * dw + z0 * ex
        out[k, 3] = w0 * ez + x0 * ey - y0 * ex + z0 * dw


@njit(cache=True, error_model="numpy")
def gyro_path(omega, bias, td, interval, out):
    """The attitude the bias-corrected gyro alone gives, from the identity at row 0:
    ``out[k] = out[k−1] ⊗ q(φ_k)``, with ``φ_k = td (ω_k − b_k)`` for interval samples (the
    mean rate over the period that ends at sample k) and, for point samples, rate-single's
    single-period step on ``ω − b_k`` at samples k − 1 and k (:func:`_startup_step`, pair
    coefficient 1/6); each row normalised (:func:`_update`)."""
    out[0, 0] = 1.0
    for i in range(1, 4):
        out[0, i] = 0.0
    phi = np.empty(3)
    tmp = np.empty(4)
    for k in range(1, out.shape[0]):
        if interval:
            for a in range(3):
                phi[a] = td * (omega[k, a] - bias[k, a])
            _update(out[k - 1], phi, out[k])
        else:
            out[k, :] = out[k - 1, :]
            _startup_step(k, omega, td, 1.0 / 6.0, out[k], bias[k], phi, tmp)


@njit(cache=True, error_model="numpy")
def hard_iron_sums(q, m, d, lo, hi, normal, rhs):
    """The hard-iron estimate's sums over the spans starting at samples ``lo … hi − 1``
    (:mod:`strapdown.ahrs.hard_iron`): with ``R = D_{k+d}ᵀ D_k`` (``D`` = C_n_b of ``q``),
    ``A = I − R`` and ``r = m_{k+d} − R m_k``, adds ``AᵀA`` to ``normal`` and ``Aᵀr`` to
    ``rhs``; returns ``Σ |r|²``."""
    d0 = np.empty((3, 3))
    d1 = np.empty((3, 3))
    a = np.empty((3, 3))
    r = np.empty(3)
    rr = 0.0
    for k in range(lo, hi):
        _dcm(q[k], d0)
        _dcm(q[k + d], d1)
        for i in range(3):
            for j in range(3):
                a[i, j] = -(d1[0, i] * d0[0, j] + d1[1, i] * d0[1, j] + d1[2, i] * d0[2, j])
            a[i, i] += 1.0
        for i in range(3):  # r = m_{k+d} − R m_k = m_{k+d} − m_k + A m_k
            r[i] = (m[k + d, i] - m[k, i] + a[i, 0] * m[k, 0] + a[i, 1] * m[k, 1]
                    + a[i, 2] * m[k, 2])
            rr += r[i] * r[i]
        for i in range(3):
            rhs[i] += a[0, i] * r[0] + a[1, i] * r[1] + a[2, i] * r[2]
            for j in range(3):
                normal[i, j] += a[0, i] * a[0, j] + a[1, i] * a[1, j] + a[2, i] * a[2, j]
    return rr


@njit(cache=True, error_model="numpy")
def gyro_plateau_runs(omega, near, flat, step, min_run, runs, samples, level):
    """:func:`strapdown.ahrs.saturation.gyro_plateaus`'s pass over the record, per axis
    ``a``: the plateaus near the axis's largest |rate| (samples at least ``near`` of it
    whose |rate| changed by at most ``flat`` of itself since the sample before; a run of
    them, s … e, is the plateau s − 1 … e) that last ``min_run`` samples and are entered by
    a step of at least ``step`` of the level (sample s − 1 against s − 2). Writes their
    number ``runs[a]``, their samples ``samples[a]`` and the mean of their mean levels
    ``level[a]``."""
    n = omega.shape[0]
    for a in range(3):
        top = 0.0
        for k in range(n):
            top = max(top, abs(omega[k, a]))
        runs[a] = 0
        samples[a] = 0
        level[a] = 0.0
        thr = near * top
        k = 2
        while k < n:
            x0 = abs(omega[k - 1, a])
            x1 = abs(omega[k, a])
            if not (x1 >= thr and abs(x1 - x0) <= flat * x1):
                k += 1
                continue
            total = x0 + x1
            e = k
            while e + 1 < n:
                y0 = abs(omega[e, a])
                y1 = abs(omega[e + 1, a])
                if not (y1 >= thr and abs(y1 - y0) <= flat * y1):
                    break
                e += 1
                total += y1
            count = e - k + 2
            if count >= min_run and abs(x0 - abs(omega[k - 2, a])) >= step * x0:
                runs[a] += 1
                samples[a] += count
                level[a] += total / count
            k = e + 1
        if runs[a] > 0:
            level[a] /= runs[a]
