"""Attitude and heading reference: a multiplicative error-state EKF (Wang, Wang & Wang, eqs. 30–35).

The filter (Wang, Wang & Wang's attitude filter, rebuilt from the paper's text
and made well-posed; docs/reproductions.md says what the paper leaves open):

- **state** ``x = [δθ_b, δb_g, a_b]``: attitude error in the body frame
  (``q_true = q̂ ⊗ q(δθ_b)``), gyro-bias error, and the manoeuvre
  (non-gravitational) acceleration in the body frame as a first-order
  Gauss–Markov (Singer) process ``ȧ = −a/τ + w``; optionally the
  accelerometer bias ``δb_a`` (12 states, ``estimate_acc_bias``);
- **propagation** of the attitude by any of the library's algorithms on the
  bias-corrected gyro: ``rate-single``, ``rate-three`` (conventional or
  ``structure=sliding``), ``rk4`` (step 2 td) and ``rotvec:N=…`` (on
  increments formed from the rates by the trapezoid rule); covariance by
  ``Φ = [[exp(−[φ×]), −T I, 0], [0, I, 0], [0, 0, e^{−T/τ} I]]``;
- **updates** at every attitude output: a zero-rate update of the bias while
  the sensor is at rest (gyro and accelerometer variance below thresholds),
  the accelerometer ``f = C_b_n g_up + a_b`` (``H = [[v̂×], 0, I]``) and the
  magnetometer as a heading measurement only (the heading of the field in the
  reference frame, ``H = [−(C_n_b)₃ᵀ, 0, 0]``), so magnetic disturbances never
  reach roll and pitch; Joseph form, sequential, then reset;
- **gating**: an accelerometer or heading innovation whose NIS exceeds a χ²
  threshold is rejected; a magnetometer sample whose norm or dip angle
  departs from the reference field is rejected before that, and after a
  magnetic disturbance the field must stay plausible for ``mag_settle_s``.
  Recovery: when innovations keep failing the gate although the measurement
  itself looks clean — the accelerometer quiet (low variance, norm g) for
  ``recover_acc_s``, or a plausible field for ``recover_mag_s`` — the filter,
  not the sensor, must be wrong: it inflates the affected covariance and
  accepts again;
- **initial attitude** from the mean accelerometer and magnetometer over
  ``init_window_s`` (TRIAD) when none is given (the window is assumed at
  rest); the reference field (norm, dip, heading) is learned there too,
  unless given.

Frames: the filter runs in ENU (x east, y north, z up); ``frame="NED"``
returns q_NED_b. Heading is magnetic unless ``declination_deg`` is given.
Without a magnetometer heading is not observed: it is the gyro's integral from
the initial yaw (0 unless ``q0`` is given) and :attr:`AhrsResult.heading_observed`
is False.

The per-sample loop is :func:`strapdown.ahrs._kernel.ekf_kernel` (numba); what
each output did with its measurements is a :class:`strapdown.ahrs.flags.MeasurementFlag`.
"""

from __future__ import annotations

import math
import typing
from dataclasses import asdict, dataclass, field

import numpy as np

from strapdown._core.validation import as_quaternions
from strapdown.ahrs import _kernel as K
from strapdown.ahrs.flags import MeasurementFlag
from strapdown.rotation.quaternion import quat_multiply

__all__ = ["AhrsConfig", "AhrsResult", "attitude_from_acc_mag", "ekf"]

G = 9.80665
#: q_NED_ENU: rotation by π about (1, 1, 0)/√2 (swaps x and y, flips z).
Q_NED_ENU = np.array([0.0, math.sqrt(0.5), math.sqrt(0.5), 0.0])


@dataclass(frozen=True)
class AhrsConfig:
    """Filter tuning (SI units). Defaults work on consumer MEMS IMUs at 100–1000 Hz.

    Parameters
    ----------
    gyro_noise : float
        Gyro white-noise density (angle random walk), rad/s/√Hz. Default 5e-4
        (≈ 0.03 °/s/√Hz: a consumer MEMS gyro with margin for model error).
    gyro_bias_rw : float
        Bias random walk, rad/s/√s. Default 2e-5.
    gyro_bias_sigma0 : float
        Initial bias uncertainty, rad/s. Default 0.01 (0.6 °/s).
    singer_sigma : float
        Steady-state standard deviation of the manoeuvre acceleration, m/s². Default 2.
    singer_tau : float
        Its correlation time, s. Default 0.2.
    acc_noise : float
        Raw accelerometer model (``acc_model="raw"``): measurement noise
        density (white noise plus vibration), m/s²/√Hz. Default 0.03. All
        measurement noises are densities — an update every ``T`` s uses
        ``R = density²/T`` — so the filter does not change with the
        propagation algorithm's update period.
    acc_model : {"lowpass", "raw"}
        ``lowpass`` (default): the specific force rotated into the reference
        frame and averaged over ``acc_lowpass_s`` is gravity — manoeuvre
        accelerations average out (the idea of Laidig & Seel's VQF); the
        Singer state is then unused. ``raw``: the paper's model, each sample
        ``f = C_b_n g_up + a_b`` with the Singer state ``a_b``.
    acc_lowpass_s : float
        Averaging time constant, s. Default 3.
    acc_lowpass_noise : float
        Noise density of the averaged horizontal specific force, m/s²/√Hz.
        Default 0.018.
    acc_gate_lowpass : float
        NIS gate of the averaged measurement (χ², 2 dof, 99.9 %: 13.82).
    acc_gate_mode : {"hard", "soft"}
        Beyond the gate: reject (hard, default) or de-weight (soft, Huber-type).
    lever_arm : float
        Raw model only: distance (m) from the centre of rotation used to widen
        the accelerometer noise by the centripetal and tangential accelerations
        the gyro sees. Default 0.1.
    heading_noise : float
        Magnetometer heading noise density, rad/√Hz. Default 0.018 (local
        field distortion dominates the sensor noise indoors).
    acc_gate, mag_gate : float
        NIS thresholds (χ² with 3 and 1 degrees of freedom at 99.9 %: 16.27, 10.83).
    mag_norm_tol : float
        Reject a magnetometer sample whose norm departs from the reference by
        more than this fraction. Default 0.1.
    mag_dip_tol : float
        … or whose dip angle departs by more than this, rad. Default 0.1 (5.7°).
    acc_norm_tol : float
        Raw model only: skip the accelerometer when its norm departs from g by
        more than this fraction (sustained manoeuvres, impacts). Default 0.25.
    mag_settle_s : float
        After a magnetic disturbance, the field must stay plausible this long
        before it is used again, s. Default 1.
    recover_acc_s, recover_mag_s : float
        Seconds of consecutive NIS rejections of clean-looking measurements
        (accelerometer quiet; field plausible) after which the covariance is
        inflated by ``recover_angle`` and measurements are accepted again.
    recover_angle : float
        Standard deviation added on recovery, rad. Default 0.1.
    rest_gyro, rest_acc : float
        Rest when the gyro's standard deviation over ``rest_tau`` is below
        ``rest_gyro`` (rad/s) and its mean below 5 × that, and the
        accelerometer's below ``rest_acc`` (m/s²). Defaults 0.01, 0.2.
    rest_noise : float
        Noise density of the zero-rate bias measurement, rad/s/√Hz. Default 1.2e-4.
    rest_tau : float
        Averaging time of the rest detector, s. Default 0.5.
    estimate_acc_bias : bool
        Add the accelerometer bias to the state (12 states). Off by default:
        it is observable only through attitude changes, and a consumer IMU's
        factory calibration usually leaves less than the filter can resolve.
    acc_bias_sigma0 : float
        Its initial uncertainty, m/s². Default 0.1.
    acc_bias_rw : float
        Its random walk, m/s²/√s. Default 1e-4.
    gating : bool
        Innovation gating and magnetic-disturbance rejection (default on).
    rest_update : bool
        Zero-rate bias updates at rest (default on).
    use_accelerometer, use_magnetometer : bool
        Switch the aiding off (the magnetometer is off anyway without data).
    init_window_s : float
        Averaging window for the initial attitude and the reference field, s.
    attitude_sigma0 : float
        Initial attitude uncertainty, rad. Default 0.05.
    declination_deg : float
        Magnetic declination (east positive); 0 gives a magnetic-north heading.
    gravity : float
        m/s². Default 9.80665.
    """

    gyro_noise: float = 5e-4
    gyro_bias_rw: float = 2e-5
    gyro_bias_sigma0: float = 0.01
    singer_sigma: float = 2.0
    singer_tau: float = 0.2
    acc_noise: float = 0.03
    heading_noise: float = 0.018
    acc_gate: float = 16.27
    mag_gate: float = 10.83
    mag_norm_tol: float = 0.1
    mag_dip_tol: float = 0.17
    acc_model: str = "lowpass"
    acc_lowpass_s: float = 3.0
    acc_lowpass_noise: float = 0.018
    acc_gate_lowpass: float = 13.82
    acc_gate_mode: str = "hard"
    lever_arm: float = 0.1
    acc_norm_tol: float = 0.25
    mag_settle_s: float = 2.0
    recover_acc_s: float = 2.0
    recover_mag_s: float = 10.0
    recover_angle: float = 0.1
    rest_gyro: float = 0.01
    rest_acc: float = 0.2
    rest_noise: float = 1.2e-4
    rest_tau: float = 0.5
    estimate_acc_bias: bool = False
    acc_bias_sigma0: float = 0.1
    acc_bias_rw: float = 1e-4
    gating: bool = True
    rest_update: bool = True
    use_accelerometer: bool = True
    use_magnetometer: bool = True
    init_window_s: float = 0.5
    attitude_sigma0: float = 0.05
    declination_deg: float = 0.0
    gravity: float = G

    def __post_init__(self):
        if self.acc_model not in ("lowpass", "raw"):
            raise ValueError(f"AhrsConfig.acc_model must be 'lowpass' or 'raw', got "
                             f"{self.acc_model!r}")
        if self.acc_gate_mode not in ("soft", "hard"):
            raise ValueError(f"AhrsConfig.acc_gate_mode must be 'soft' or 'hard', got "
                             f"{self.acc_gate_mode!r}")
        for name, v in asdict(self).items():
            if isinstance(v, (bool, str)):
                continue
            if not math.isfinite(v):
                raise ValueError(f"AhrsConfig.{name} must be finite, got {v!r}")
            if name not in ("declination_deg", "lever_arm") and not v > 0:
                raise ValueError(f"AhrsConfig.{name} must be positive, got {v!r}")


@dataclass(frozen=True)
class AhrsResult:
    """Filter output: one row per input sample.

    Row 0 is the initial state at the first time stamp (the initial attitude, bias
    and covariance). A row where a filter epoch ended (:attr:`epoch`) holds the
    estimate after that epoch's propagation and measurement updates; with an
    algorithm whose update period spans several samples (``rate-three``, ``rk4``,
    ``rotvec:N≥2``) the rows in between — and after the last epoch — hold the
    attitude propagated from the last epoch by single-period steps on the
    bias-corrected gyro (output only, causal: the filter state is not changed),
    its bias and covariance held.

    Attributes
    ----------
    t : ndarray (n,)
        The input time stamps (s).
    index : ndarray (n,)
        Sample index of each row (``arange(n)``).
    epoch : ndarray (n,) of bool
        True where a filter epoch ended at this sample.
    q : ndarray (n, 4)
        q_n_b in :attr:`frame`.
    frame : {"ENU", "NED"}
    heading_observed : bool
        False without a magnetometer (heading is the gyro's integral).
    gyro_bias : ndarray (n, 3)
        Estimated gyro bias, rad/s.
    accel : ndarray (n, 3)
        Estimated manoeuvre acceleration in the body frame, m/s².
    flags : ndarray (n,) of int
        Bitwise or of :class:`~strapdown.ahrs.flags.MeasurementFlag` per row (0 where
        no epoch ended).
    nis : ndarray (n, 2)
        Accelerometer and heading NIS (NaN where there was no update).
    attitude_sigma : ndarray (n, 3)
        Standard deviation of δθ_b, rad.
    algorithm : str
    acc_bias : ndarray (n, 3) or None
        Estimated accelerometer bias, m/s² (with ``estimate_acc_bias``).
    """

    t: np.ndarray
    index: np.ndarray
    epoch: np.ndarray
    q: np.ndarray
    frame: str
    heading_observed: bool
    gyro_bias: np.ndarray
    accel: np.ndarray
    flags: np.ndarray
    nis: np.ndarray
    attitude_sigma: np.ndarray
    algorithm: str
    config: AhrsConfig = field(repr=False, default_factory=AhrsConfig)
    acc_bias: np.ndarray | None = None

    def __post_init__(self):
        n = self.t.shape[0]
        for name in ("index", "epoch", "q", "gyro_bias", "accel", "flags", "nis",
                     "attitude_sigma", "acc_bias"):
            a = getattr(self, name)
            if a is not None and a.shape[0] != n:
                raise ValueError(f"AhrsResult.{name} has {a.shape[0]} rows, t has {n}: one "
                                 "row per sample")

    def fraction(self, flag: MeasurementFlag | int) -> float:
        """Share of filter epochs with any of ``flag``'s bits set (NaN without epochs), e.g.
        ``result.fraction(MeasurementFlag.MAG_USED)``."""
        f = self.flags[self.epoch]
        return float(np.mean((f & flag) != 0)) if f.size else math.nan


def attitude_from_acc_mag(acc, mag=None, *, declination_deg: float = 0.0) -> np.ndarray:
    """q_ENU_b from one specific-force vector (and a magnetic field vector), by TRIAD.

    Up is the specific force at rest; north is the field's horizontal part
    rotated by the declination. Without ``mag`` the yaw is zero (x_b's
    horizontal projection points east).
    """
    f = np.asarray(acc, float)
    if f.shape != (3,) or not np.all(np.isfinite(f)) or np.linalg.norm(f) == 0:
        raise ValueError(f"acc must be a finite non-zero (3,) vector, got {f!r}")
    up = f / np.linalg.norm(f)
    if mag is None:
        ref = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        east = ref - up * (ref @ up)
        east /= np.linalg.norm(east)
        north = np.cross(up, east)
    else:
        m = np.asarray(mag, float)
        if m.shape != (3,) or not np.all(np.isfinite(m)):
            raise ValueError(f"mag must be a finite (3,) vector, got {m!r}")
        mh = m - up * (m @ up)
        if np.linalg.norm(mh) < 1e-6 * max(float(np.linalg.norm(m)), 1e-300):
            raise ValueError("the magnetic field is vertical: heading is undefined")
        mnorth = mh / np.linalg.norm(mh)
        d = math.radians(declination_deg)
        east_m = np.cross(mnorth, up)
        north = math.cos(d) * mnorth - math.sin(d) * east_m
        east = np.cross(north, up)
    c_b_n = np.column_stack([east, north, up])  # columns: reference axes in body
    from strapdown.rotation.dcm import quat_from_dcm

    return quat_from_dcm(c_b_n.T)


def _algorithm(spec: str):
    """Kernel arguments for a propagation algorithm spec (see AlgorithmSpec.propagation)."""
    from strapdown.algorithms.spec import AlgorithmSpec

    return AlgorithmSpec.parse(spec).propagation()


def _check(name, a, n):
    a = np.ascontiguousarray(a, dtype=np.float64)
    if a.shape != (n, 3):
        raise ValueError(f"{name} must have shape ({n}, 3) to match the gyro, got {a.shape}")
    bad = ~np.all(np.isfinite(a), axis=1)
    if np.any(bad):
        raise ValueError(f"{name} has NaN or infinity in row {int(np.argmax(bad))}")
    return a


def _validate(t, gyro, acc, mag, cfg: AhrsConfig, frame: str):
    """The record checked: (rate record, acc, mag — zeros when absent —, heading observed).

    Raises ValueError naming the problem: the frame, the time stamps and gyro
    (:func:`strapdown.algorithms.rate.check_rate_record`), the shapes, a NaN's
    row, an accelerometer not in m/s² of specific force, a magnetometer reading zero.
    """
    from strapdown.algorithms.rate import check_rate_record

    if frame not in ("ENU", "NED"):
        raise ValueError(f"frame must be 'ENU' or 'NED', got {frame!r}")
    rec = check_rate_record(t, gyro, min_samples=4)
    n = rec.t.size
    acc = _check("acc", acc, n)
    have_mag = mag is not None and cfg.use_magnetometer
    mag = _check("mag", mag, n) if mag is not None else np.zeros((n, 3))
    a_norm = np.median(np.linalg.norm(acc, axis=1))
    if not 0.5 * cfg.gravity < a_norm < 2.0 * cfg.gravity:
        raise ValueError(f"the accelerometer's median norm is {a_norm:.4g}; expected about "
                         f"{cfg.gravity} m/s² (is it in g, or not specific force?)")
    if have_mag and np.median(np.linalg.norm(mag, axis=1)) == 0:
        raise ValueError("the magnetometer reads zero; pass mag=None for no heading")
    return rec, acc, mag, have_mag


def _init_window(rec, cfg: AhrsConfig) -> int:
    """Samples of the initial window (at least 2, at most the record)."""
    return max(2, min(rec.t.size, round(cfg.init_window_s / rec.td)))


def _initial_attitude(rec, acc, mag, have_mag: bool, cfg: AhrsConfig, q0, frame: str):
    """q_ENU_b at the start and the body-frame field there (None without heading).

    Without ``q0`` the initial window is assumed at rest: its mean specific
    force and field give the attitude by TRIAD (:func:`attitude_from_acc_mag`).
    """
    if q0 is None:
        w = _init_window(rec, cfg)
        m0 = mag[:w].mean(axis=0) if have_mag else None
        return attitude_from_acc_mag(acc[:w].mean(axis=0), m0,
                                     declination_deg=cfg.declination_deg), m0
    q_init = as_quaternions(q0, "q0").reshape(4)
    q_init = q_init / np.linalg.norm(q_init)
    if frame == "NED":  # the filter runs in ENU
        q_init = quat_multiply(np.array([0.0, -Q_NED_ENU[1], -Q_NED_ENU[2], 0.0]), q_init)
    return q_init, (mag[0] if have_mag else None)


def _reference_field(rec, mag, q_init, m0, q0, mag_reference, cfg: AhrsConfig):
    """(norm, dip, heading) of the local field in ENU — dip down positive, heading from
    east to north, rad — given (``mag_reference``), or learned (see :func:`ekf`)."""
    from strapdown.rotation.dcm import dcm_from_quat

    if mag_reference is not None:  # the local field is known (ENU)
        mn = np.asarray(mag_reference, float)
        if mn.shape != (3,) or not np.all(np.isfinite(mn)) or not np.linalg.norm(mn) > 0:
            raise ValueError(f"mag_reference must be a finite non-zero (3,) ENU vector, "
                             f"got {mag_reference!r}")
    elif q0 is None:
        mn = dcm_from_quat(q_init) @ m0
    else:  # learn the field over the window along the gyro-propagated attitude
        from strapdown.algorithms.rate import rate_attitude

        w = _init_window(rec, cfg)
        qw = rate_attitude(rec.t[:w], rec.omega[:w], algorithm="rate-single", q0=q_init).q
        mn = np.einsum("nij,nj->ni", dcm_from_quat(qw), mag[:w]).mean(axis=0)
    return (float(np.linalg.norm(mn)), math.atan2(-mn[2], math.hypot(mn[0], mn[1])),
            math.atan2(mn[1], mn[0]))


# Params fields that are not AhrsConfig fields of the same name and meaning
_DERIVED = ("ref_norm", "ref_dip", "ref_heading", "use_magnetometer", "soft_gate",
            "acc_lowpass")


def _params(cfg: AhrsConfig, ref, use_mag: bool) -> K.Params:
    """The kernel's parameter record: the config's fields of the same name, the reference
    field ``ref`` (norm, dip, heading), and the switches derived from the config.

    Every value is converted to its field's type (float or bool), so the
    compiled kernel's signature — and numba's cache entry — never changes.
    """
    derived = dict(zip(_DERIVED[:3], ref, strict=True), use_magnetometer=use_mag,
                   soft_gate=cfg.acc_gate_mode == "soft", acc_lowpass=cfg.acc_model == "lowpass")
    types = typing.get_type_hints(K.Params)
    return K.Params(**{f: types[f](derived[f] if f in derived else getattr(cfg, f))
                       for f in K.Params._fields})


def _propagation(a: dict) -> tuple[K.Propagation, K.Window]:
    """The kernel's propagation records from :func:`_algorithm`'s dict, types fixed (so
    the compiled kernel's signature never changes)."""
    prop = K.Propagation(is_rate=bool(a["is_rate"]), stride=int(a["stride"]),
                         end_off=int(a["end_off"]), lag=int(a["lag"]),
                         start_c=float(a["start_c"]), rk4=bool(a["rk4"]))
    window = K.Window(*(np.ascontiguousarray(a[f], np.int64 if f in ("offsets", "pi", "pj")
                                             else np.float64) for f in K.Window._fields))
    return prop, window


def _initial_covariance(cfg: AhrsConfig) -> np.ndarray:
    """P0: attitude, gyro bias, manoeuvre acceleration (and accelerometer bias)."""
    nx = 12 if cfg.estimate_acc_bias else 9
    P0 = np.zeros((nx, nx))
    P0[:3, :3] = np.eye(3) * cfg.attitude_sigma0**2
    P0[3:6, 3:6] = np.eye(3) * cfg.gyro_bias_sigma0**2
    P0[6:9, 6:9] = np.eye(3) * cfg.singer_sigma**2
    if nx == 12:
        P0[9:, 9:] = np.eye(3) * cfg.acc_bias_sigma0**2
    return P0


def _run(rec, acc, mag, prop: K.Propagation, window: K.Window, params: K.Params,
         init: K.Initial):
    """Run the compiled loop; returns (outputs, number of rows written)."""
    h = rec.td
    x = rec.omega if prop.is_rate else 0.5 * h * (rec.omega[1:] + rec.omega[:-1])
    m = rec.t.size  # at most one output per sample
    out = K.Outputs(q=np.empty((m, 4)), gyro_bias=np.empty((m, 3)), accel=np.empty((m, 3)),
                    acc_bias=np.empty((m, 3)), sample=np.empty(m, np.int64),
                    flags=np.empty(m, np.int64), nis=np.empty((m, 2)),
                    attitude_sigma=np.empty((m, 3)))
    k = K.ekf_kernel(K.Sensors(np.ascontiguousarray(x), acc, mag, float(h)), prop, window,
                     params, init, out)
    return out, k


def _fill_between_epochs(rec, q, bias, last):
    """Rows of ``q`` (ENU) that are not epochs (``last[i] < i``): propagated from the row
    before by one single-period step (``rate-single``, ``td/2 (ω₀ + ω₁) + c td² ω₀ × ω₁``
    with the derived c = 1/6, see :mod:`strapdown.algorithms.rate`) on the gyro corrected
    by the bias of the last epoch. In place."""
    from strapdown.rotation.quaternion import quat_from_rotvec

    n = rec.t.size
    off = np.arange(n) - last  # samples since the last epoch (0 at epochs and row 0)
    h = rec.td
    for j in range(1, int(off.max()) + 1 if n else 1):  # a few samples at most
        i = np.flatnonzero(off == j)
        w0 = rec.omega[i - 1] - bias[i]
        w1 = rec.omega[i] - bias[i]
        phi = 0.5 * h * (w0 + w1) + h * h / 6.0 * np.cross(w0, w1)
        q[i] = quat_multiply(q[i - 1], quat_from_rotvec(phi))


def _result(rec, out: K.Outputs, k: int, init: K.Initial, frame: str, have_mag: bool,
            algorithm: str, cfg: AhrsConfig) -> AhrsResult:
    """One row per sample (see :class:`AhrsResult`): row 0 the initial state, the k epoch
    rows of ``out`` at their samples, the rows between propagated
    (:func:`_fill_between_epochs`), everything else held from the last epoch."""
    n = rec.t.size
    idx = out.sample[:k]
    epoch = np.zeros(n, bool)
    epoch[idx] = True
    rows = np.arange(n)
    last = np.maximum.accumulate(np.where(epoch, rows, 0))  # the last epoch row (or 0)

    def per_sample(first, epochs):
        a = np.empty((n, *np.shape(first)), np.asarray(epochs).dtype)
        a[0] = first
        a[idx] = epochs
        return a[last]

    sigma0 = np.sqrt(np.diag(init.P)[:3])
    bias = per_sample(init.gyro_bias, out.gyro_bias[:k])
    q = per_sample(init.q, out.q[:k])
    _fill_between_epochs(rec, q, bias, last)
    if frame == "NED":
        q = quat_multiply(Q_NED_ENU, q)
    flags = np.zeros(n, np.int64)
    flags[idx] = out.flags[:k]
    nis = np.full((n, 2), np.nan)
    nis[idx] = out.nis[:k]
    return AhrsResult(rec.t, rows, epoch, q, frame, have_mag, bias,
                      per_sample(np.zeros(3), out.accel[:k]), flags, nis,
                      per_sample(sigma0, out.attitude_sigma[:k]), algorithm, cfg,
                      per_sample(np.zeros(3), out.acc_bias[:k]) if cfg.estimate_acc_bias
                      else None)


def ekf(t, gyro, acc, mag=None, *, algorithm: str = "rate-single",
        config: AhrsConfig | None = None, q0=None, gyro_bias0=None,
        mag_reference=None, frame: str = "ENU") -> AhrsResult:
    """Run the AHRS filter over uniformly sampled gyro, accelerometer and magnetometer data.

    The multiplicative error-state EKF of Wang, Wang & Wang (eqs. 30–35), made
    well-posed (see the module docstring).

    Parameters
    ----------
    t : array_like (n,)
        Sample times (s), uniform.
    gyro : array_like (n, 3)
        Body rates, rad/s.
    acc : array_like (n, 3)
        Specific force, m/s² (≈ +g up at rest).
    mag : array_like (n, 3), optional
        Magnetic field, any unit (µT typical). None: no heading (see the module docstring).
    algorithm : str
        Attitude propagation: ``rate-single`` (default), ``rate-three``,
        ``rate-three:structure=sliding``, ``rk4``, ``rotvec:N=3`` …
    config : AhrsConfig, optional
    q0 : array_like (4,), optional
        Initial q_n_b in ``frame``; default from the accelerometer and magnetometer.
    gyro_bias0 : array_like (3,), optional
        Initial bias estimate, rad/s (default zero).
    mag_reference : array_like (3,), optional
        The local magnetic field in ENU (same unit as ``mag``). Default: learned
        over ``init_window_s`` — averaged at rest when ``q0`` is None, else
        rotated into the reference frame along the gyro-propagated attitude.
    frame : {"ENU", "NED"}

    Returns
    -------
    AhrsResult
        One row per input sample, the first the initial attitude at ``t[0]``.

    Raises
    ------
    ValueError
        On invalid input, naming the problem.
    """
    cfg = config or AhrsConfig()
    rec, acc, mag, have_mag = _validate(t, gyro, acc, mag, cfg, frame)
    q_init, m0 = _initial_attitude(rec, acc, mag, have_mag, cfg, q0, frame)
    ref = (_reference_field(rec, mag, q_init, m0, q0, mag_reference, cfg) if have_mag
           else (0.0, 0.0, 0.0))
    b0 = np.zeros(3) if gyro_bias0 is None else _check("gyro_bias0", [gyro_bias0], 1)[0]
    prop, window = _propagation(_algorithm(algorithm))
    init = K.Initial(q_init, b0, _initial_covariance(cfg))
    out, k = _run(rec, acc, mag, prop, window, _params(cfg, ref, have_mag), init)
    return _result(rec, out, k, init, frame, have_mag, algorithm, cfg)
