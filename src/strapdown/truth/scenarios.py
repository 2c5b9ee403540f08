"""Simulated AHRS recordings with exact truth: the generalisation suite.

Each scenario is a body with exact kinematics — attitude ``q_n_b(t)`` (Hamilton, scalar
first, ``n`` = ENU), body rate, translational acceleration, and the magnetic field at the
body's place — sampled as a consumer MEMS IMU at a realistic rate: gyro (rad/s, the mean
rate over the sample period ending at the sample, white noise, a constant bias and a slow
first-order Gauss–Markov bias), accelerometer (specific force ``f_b = C_b_n (a_n − g_n)``,
``g_n = [0, 0, −g]``, m/s², white noise and a constant bias), magnetometer (the field in the
body, white noise, in the scenario's unit: µT times ``mag_unit``). Every recording starts at
rest for ``rest_s`` seconds (an AHRS initialises from its first samples, taken to be at rest).

The kinds (:data:`SCENARIO_KINDS`):

- ``pendulum`` (:func:`pendulum`): a rigid pendulum about a horizontal pivot axis, held at
  its swing amplitude during the rest and released with zero rate; ``θ̈ = −(g/L) sin θ``
  (``L`` the equivalent length: the period's), integrated by ``solve_ivp`` (DOP853,
  rtol 1e-12, atol 1e-12, dense output) — not a small-angle closed form. The sensor sits on
  the rod ``sensor_m`` from the pivot (at ``sensor_m = L`` the accelerometer sees no
  tangential force: it always points along the rod), mounted askew. Undamped: the swing
  keeps its amplitude and energy;
- ``vehicle`` (:func:`vehicle`): a car on a flat road (body FLU) that starts from rest,
  circles left and right and turns at a steady lateral acceleration, rolling outwards and
  pitching with its accelerations (roll about the sensor);
- ``loiter`` (:func:`loiter`): Wang, Wang & Wang's turning aircraft, a coordinated level
  turn (:class:`~strapdown.truth.trajectory.CoordinatedFlight`, 20 m/s at 20° bank) — the
  accelerometer points along the body's vertical throughout the turn;
- ``spin-coning`` (:func:`spin_coning`): :class:`~strapdown.truth.motions.SpinConing` about a
  vertical cone axis, spun up smoothly after the rest (the motion on a warped clock), the
  sensor a few centimetres off the rotation centre (centripetal and tangential force);
- ``hand-held`` (:func:`hand_shaking`): the hand-held rotation of
  :func:`~strapdown.truth.recordings.hand_held` with a vigorous translational shaking
  (metres per second squared at 2–4 Hz);
- ``steel-frame`` (:func:`steel_frame`): the hand-held rotation carried back and forth
  through a steel door frame whose magnetised members (lines of dipoles, induced and
  remanent) disturb the field near it;
- ``rests`` (:func:`rests`): stationary rests in seven poses joined by two-second turns.

:func:`suite` lists the standard set, :func:`record` samples one. Everything random takes a
seed or a :class:`numpy.random.Generator`; the same seed gives the same numbers.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import finite_array, positive
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import (
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_rotate,
)
from strapdown.truth.motions import (
    Motion,
    RotationSequenceMotion,
    SpinConing,
    UserMotion,
    interval_integrals,
)
from strapdown.truth.recordings import EARTH_FIELD_UT, G, hand_held
from strapdown.truth.sensors import (
    AccelerometerErrors,
    GyroErrors,
    MagnetometerErrors,
    RngLike,
    accelerometer,
)
from strapdown.truth.trajectory import CoordinatedFlight, Segment

__all__ = [
    "G_N",
    "SCENARIO_KINDS",
    "Body",
    "Scenario",
    "ScenarioKind",
    "Sensors",
    "SimulatedRecording",
    "hand_shaking",
    "loiter",
    "pendulum",
    "record",
    "rests",
    "spin_coning",
    "steel_frame",
    "suite",
    "vehicle",
]

ScenarioKind = Literal["pendulum", "vehicle", "loiter", "spin-coning", "hand-held",
                       "steel-frame", "rests"]
#: The scenario kinds, in the order :func:`suite` lists them.
SCENARIO_KINDS: tuple[ScenarioKind, ...] = get_args(ScenarioKind)
#: Gravity in ENU, m/s² (the specific force is ``a_n − G_N``).
G_N = np.array([0.0, 0.0, -G])

VecFn = Callable[[NDArray[np.float64]], NDArray[np.float64]]


# ------------------------------------------------------------------------------ helpers
def _quintic(x: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """The quintic smooth step S from 0 (x ≤ 0) to 1 (x ≥ 1), S', S'' and ∫_0^x S."""
    c = np.clip(x, 0.0, 1.0)
    s = c**3 * (10.0 - 15.0 * c + 6.0 * c * c)
    s1 = 30.0 * c * c * (1.0 - c) ** 2
    s2 = 60.0 * c * (1.0 - c) * (1.0 - 2.0 * c)
    si = np.where(x < 1.0, 2.5 * c**4 - 3.0 * c**5 + c**6, x - 0.5)
    return s, s1, s2, si


def _steps(t: NDArray[np.float64], times: ArrayLike, values: ArrayLike, ramp_s: float
           ) -> tuple[NDArray[np.float64], ...]:
    """Piecewise-constant ``values`` joined by quintic ramps starting at ``times`` (≥ 0),
    each ``ramp_s`` long: the value at ``t``, its first and second derivatives, and its
    integral from 0 (continuous to the second derivative)."""
    t = np.asarray(t, dtype=np.float64)
    vals = np.asarray(values, dtype=np.float64)
    v = np.full_like(t, vals[0])
    d1 = np.zeros_like(t)
    d2 = np.zeros_like(t)
    integral = vals[0] * t
    for t_i, a, b in zip(np.asarray(times, float), vals[:-1], vals[1:], strict=True):
        s, s1, s2, si = _quintic((t - t_i) / ramp_s)
        v = v + (b - a) * s
        d1 = d1 + (b - a) * s1 / ramp_s
        d2 = d2 + (b - a) * s2 / ramp_s**2
        integral = integral + (b - a) * ramp_s * si
    return v, d1, d2, integral


def _qaxis(axis: int, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation by ``angle`` about coordinate axis ``axis`` (0, 1, 2), shape ``(..., 4)``."""
    a = np.asarray(angle, dtype=np.float64)
    q = np.zeros((*a.shape, 4))
    q[..., 0] = np.cos(a / 2)
    q[..., 1 + axis] = np.sin(a / 2)
    return q


def _rotz(angle: float, v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``R_z(angle) v`` for vectors ``v`` of shape ``(..., 3)``."""
    c, s = math.cos(angle), math.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1], v[..., 2]],
                    axis=-1)


# ------------------------------------------------------------------------------ the body
@dataclass(frozen=True)
class Body:
    """A body's exact kinematics and the field it moves through.

    Attributes
    ----------
    motion : Motion
        ``q_n_b(t)`` (ENU) and ``ω_b(t)`` (rad/s) with exact increments.
    acceleration : callable
        ``t -> a_n`` (m/s², ENU), shape ``t.shape + (3,)``: the acceleration of the
        sensor's place.
    velocity, position : callable or None
        ``t -> v_n`` (m/s), ``t -> r_n`` (m), where the scenario defines them (the tests
        differentiate them to check ``acceleration``).
    field : callable or None
        ``r_n -> B_n`` (µT, ENU) at the places ``r_n``, shape ``r_n.shape``; None: the
        uniform :data:`~strapdown.truth.recordings.EARTH_FIELD_UT`.
    """

    motion: Motion
    acceleration: VecFn
    velocity: VecFn | None = None
    position: VecFn | None = None
    field: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        """``q_n_b(t)``, shape ``t.shape + (4,)``."""
        return self.motion.attitude(t)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body rate ``ω_b(t)`` (rad/s), shape ``t.shape + (3,)``."""
        return self.motion.rate(t)

    def specific_force(self, t: ArrayLike) -> NDArray[np.float64]:
        """``f_b = C_b_n (a_n − g_n)`` (m/s²), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        return quat_rotate(quat_conjugate(self.attitude(t)), self.acceleration(t) - G_N)

    def field_n(self, t: ArrayLike) -> NDArray[np.float64]:
        """The field at the body's place in ENU (µT), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        if self.field is None:
            return np.broadcast_to(EARTH_FIELD_UT, (*t.shape, 3)).copy()
        if self.position is None:
            raise ValueError("a spatially varying field needs the body's position")
        return self.field(self.position(t))

    def field_b(self, t: ArrayLike) -> NDArray[np.float64]:
        """The field in the body (µT), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        return quat_rotate(quat_conjugate(self.attitude(t)), self.field_n(t))


@dataclass(frozen=True)
class Sensors:
    """A consumer MEMS IMU: sample rate and error model (SI units; the field in µT).

    Parameters
    ----------
    rate_hz : float
        Sample rate, Hz.
    gyro_noise : float
        Gyro white-noise density, rad/s/√Hz (default 0.007 °/s/√Hz).
    gyro_bias_sd : float
        Standard deviation of the constant gyro bias drawn per axis, rad/s (0.3 °/s).
    gyro_bias_gm_sigma, gyro_bias_gm_tau : float
        The slow bias: a first-order Gauss–Markov process of this steady-state standard
        deviation (rad/s, 0.03 °/s) and correlation time (s, 200).
    acc_noise : float
        Accelerometer white-noise density, m/s²/√Hz.
    acc_bias_sd : float
        Standard deviation of the constant accelerometer bias per axis, m/s².
    mag_noise : float
        Magnetometer noise per sample, µT.
    mag_unit : float
        The recorded field is µT times this (0.01: gauss; any other: arbitrary units).
    gyro_scale_sd, gyro_misalignment_sd : float
        Standard deviations of the gyro's relative scale-factor errors (diagonal of
        ``M − I``) and of its cross-axis sensitivities (off-diagonal), drawn per recording:
        the measured rate is ``M (ω + b) + n`` (:class:`~strapdown.truth.sensors.GyroErrors`'s
        order). Default 0 (the suite's recordings); a consumer MEMS gyro's data sheet gives
        ±1–3 % and ±1–2 % untrimmed (a standard deviation of about 0.01 and 0.005). Drawn
        after every other error but the accelerometer's matrix, so a recording with and
        without them shares its noise.
    acc_scale_sd, acc_misalignment_sd : float
        The same for the accelerometer: the measured specific force is ``M_a (f + b_a) + n``
        with ``M_a − I`` drawn so. Default 0 (the suite's recordings); a consumer MEMS
        accelerometer's data sheet gives a sensitivity tolerance of ±1–3 % and a cross-axis
        sensitivity of ±1–2 % (trimmed, about 0.005 and 0.005). Drawn after the gyro's, so
        a recording with and without them shares every other draw.
    acc_sample : {"point", "interval"}
        What an accelerometer sample is: the specific force at the stamp (``point``,
        default: the suite's recordings) or its mean over the sample period that ends at
        the stamp (``interval``: gyro and accelerometer through one decimation filter, as
        the gyro samples here always are), by Gauss–Legendre quadrature of the exact
        specific force (:func:`~strapdown.truth.motions.interval_integrals`).
    """

    rate_hz: float
    gyro_noise: float = math.radians(0.007)
    gyro_bias_sd: float = math.radians(0.3)
    gyro_bias_gm_sigma: float = math.radians(0.03)
    gyro_bias_gm_tau: float = 200.0
    acc_noise: float = 0.002
    acc_bias_sd: float = 0.03
    mag_noise: float = 0.3
    mag_unit: float = 1.0
    gyro_scale_sd: float = 0.0
    gyro_misalignment_sd: float = 0.0
    acc_scale_sd: float = 0.0
    acc_misalignment_sd: float = 0.0
    acc_sample: Literal["point", "interval"] = "point"

    def __post_init__(self):
        positive(self.rate_hz, "rate_hz")
        if self.acc_sample not in ("point", "interval"):
            raise ValueError(f"acc_sample must be 'point' or 'interval', got {self.acc_sample!r}")
        positive(self.mag_unit, "mag_unit")
        positive(self.gyro_bias_gm_tau, "gyro_bias_gm_tau")
        for name in ("gyro_noise", "gyro_bias_sd", "gyro_bias_gm_sigma", "acc_noise",
                     "acc_bias_sd", "mag_noise", "gyro_scale_sd", "gyro_misalignment_sd",
                     "acc_scale_sd", "acc_misalignment_sd"):
            if not float(getattr(self, name)) >= 0:
                raise ValueError(f"{name} must be non-negative, got {getattr(self, name)!r}")


@dataclass(frozen=True)
class Scenario:
    """One simulated scenario: a body, how long, at rest how long, and its sensors.

    Attributes
    ----------
    name : str
        Unique within :func:`suite`, e.g. ``pendulum-0.3m-70deg``.
    kind : ScenarioKind
    body : Body
    duration_s, rest_s : float
        Length of the recording and of the rest at its start, s.
    sensors : Sensors
    parameters : dict
        What the scenario was built with (for tables).
    """

    name: str
    kind: ScenarioKind
    body: Body
    duration_s: float
    rest_s: float
    sensors: Sensors
    parameters: dict[str, float | str] = field(default_factory=dict)

    def describe(self) -> str:
        """One line: kind, rate, duration, unit and the parameters."""
        p = ", ".join(f"{k} {v}" for k, v in self.parameters.items())
        return (f"{self.kind}: {self.sensors.rate_hz:g} Hz, {self.duration_s:g} s "
                f"(rest {self.rest_s:g} s), field in µT×{self.sensors.mag_unit:g}; {p}")


@dataclass(frozen=True)
class SimulatedRecording:
    """Samples of a scenario and their truth.

    Attributes
    ----------
    scenario : Scenario
    t : ndarray (n,)
        Sample times, s (uniform, from 0).
    h : float
        Sample period, s.
    q_n_b : ndarray (n, 4)
        True attitude at ``t`` (ENU, scalar first).
    gyro : ndarray (n, 3)
        rad/s: the mean rate over ``[t − h, t]``, corrupted unless ``noise=False``.
    acc : ndarray (n, 3)
        Specific force, m/s².
    mag : ndarray (n, 3)
        Field in the body, µT × ``scenario.sensors.mag_unit``.
    gyro_bias : ndarray (n, 3)
        The true gyro bias (constant plus slow), rad/s; zero when ``noise=False``.
    gyro_matrix : ndarray (3, 3)
        The gyro's scale-factor and cross-axis matrix ``M`` (``Sensors.gyro_scale_sd``,
        ``gyro_misalignment_sd``); the identity when they are zero or ``noise=False``.
    acc_bias : ndarray (3,)
        The accelerometer's constant bias ``b_a``, m/s²; zero when ``noise=False``.
    acc_matrix : ndarray (3, 3)
        The accelerometer's scale-factor and cross-axis matrix ``M_a``
        (``Sensors.acc_scale_sd``, ``acc_misalignment_sd``); the identity when they are zero
        or ``noise=False``.
    """

    scenario: Scenario
    t: NDArray[np.float64]
    h: float
    q_n_b: NDArray[np.float64]
    gyro: NDArray[np.float64]
    acc: NDArray[np.float64]
    mag: NDArray[np.float64]
    gyro_bias: NDArray[np.float64]
    gyro_matrix: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))
    acc_bias: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    acc_matrix: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))

    @property
    def name(self) -> str:
        return self.scenario.name


def _error_matrix(scale_sd: float, misalignment_sd: float, rng: np.random.Generator
                  ) -> NDArray[np.float64]:
    """A sensor's ``M − I``: cross-axis sensitivities of standard deviation
    ``misalignment_sd`` off the diagonal, scale-factor errors of ``scale_sd`` on it (drawn
    in that order from ``rng``)."""
    err = misalignment_sd * rng.standard_normal((3, 3))
    np.fill_diagonal(err, scale_sd * rng.standard_normal(3))
    return err


def record(scenario: Scenario, seed: RngLike = 0, *, noise: bool = True,
           duration_s: float | None = None) -> SimulatedRecording:
    """Sample ``scenario`` at its rate from ``t = 0`` for ``duration_s`` (default: the
    scenario's), with sensor errors drawn from ``seed`` (``noise=False``: ideal sensors)."""
    s = scenario.sensors
    dur = scenario.duration_s if duration_s is None else positive(duration_s, "duration_s")
    if dur > scenario.duration_s * (1 + 1e-12):
        raise ValueError(f"duration_s {dur} exceeds the scenario's {scenario.duration_s} s")
    h = 1.0 / s.rate_hz
    n = math.floor(dur * s.rate_hz + 1e-9) + 1
    t = h * np.arange(n, dtype=np.float64)
    body = scenario.body
    edges = np.concatenate([[t[0] - h], t])
    w = body.motion.increments(edges) / h
    q = body.attitude(t)
    f = (body.specific_force(t) if s.acc_sample == "point"  # else the mean over each period
         else interval_integrals(body.specific_force, edges[:-1], t) / np.diff(edges)[:, None])
    m_b = body.field_b(t)
    bias = np.zeros((n, 3))
    mat = np.eye(3)
    acc_b = np.zeros(3)
    acc_mat = np.eye(3)
    if noise:
        rng = np.random.default_rng(seed)
        b0 = s.gyro_bias_sd * rng.standard_normal(3)
        # the bias alone first (same generator), so that the truth can report it
        slow = GyroErrors(gm_sigma=s.gyro_bias_gm_sigma, gm_tau=s.gyro_bias_gm_tau)
        bias = b0 + slow.apply(np.zeros((n, 3)), "rate", h, rng)
        w_b = w + bias
        w = GyroErrors(white_noise=s.gyro_noise).apply(w_b, "rate", h, rng)
        acc_b = s.acc_bias_sd * rng.standard_normal(3)
        acc_err = AccelerometerErrors(white_noise=s.acc_noise, bias=acc_b)
        f_true = f
        f = accelerometer(t, q, f, h, errors=acc_err, rng=rng)
        c_b_n = np.swapaxes(dcm_from_quat(q), -1, -2)
        m_b = MagnetometerErrors(white_noise=s.mag_noise).apply(t, m_b, c_b_n, rng)
        if s.gyro_scale_sd > 0 or s.gyro_misalignment_sd > 0:  # M (ω + b) + n, M drawn last
            err = _error_matrix(s.gyro_scale_sd, s.gyro_misalignment_sd, rng)
            w = w + w_b @ err.T
            mat = mat + err
        if s.acc_scale_sd > 0 or s.acc_misalignment_sd > 0:  # M_a (f + b_a) + n, after M
            err = _error_matrix(s.acc_scale_sd, s.acc_misalignment_sd, rng)
            f = f + (f_true + acc_b) @ err.T
            acc_mat = acc_mat + err
    return SimulatedRecording(scenario, t, h, q, w, f, m_b * s.mag_unit, bias, mat, acc_b,
                              acc_mat)


# ------------------------------------------------------------------------------ pendulum
class PendulumMotion(Motion):
    """A rigid pendulum's rotation: ``q_n_b(t) = q_z(azimuth) ⊗ q_x(θ(t)) ⊗ q_mount``.

    ``θ`` is the swing angle from the downward vertical about the pivot axis (the
    reference x axis turned by ``azimuth`` about the vertical); ``θ = θ0`` and ``θ̇ = 0``
    until ``release_s``, then ``θ̈ = −(g/L) sin θ`` integrated by ``solve_ivp`` (DOP853,
    rtol 1e-12, atol 1e-12) to ``end_s``. A fixed-axis rotation, so the increments are
    exact differences of ``θ``.
    """

    def __init__(self, length_m: float, amplitude_rad: float, release_s: float, end_s: float,
                 *, azimuth_rad: float = 0.0, mount: ArrayLike = (1.0, 0.0, 0.0, 0.0)):
        from scipy.integrate import solve_ivp

        self.length = positive(length_m, "length_m")
        self.theta0 = float(finite_array(amplitude_rad, "amplitude_rad"))
        self.release = float(release_s)
        self.end = float(end_s)
        self.azimuth = float(azimuth_rad)
        self.mount = np.asarray(mount, dtype=np.float64) / np.linalg.norm(mount)
        self.axis_b = quat_rotate(quat_conjugate(self.mount), np.array([1.0, 0.0, 0.0]))
        k = G / self.length

        def rhs(_t, y):
            return [y[1], -k * math.sin(y[0])]

        sol = solve_ivp(rhs, (self.release, self.end + 1.0), [self.theta0, 0.0],
                        method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
        if not sol.success:  # pragma: no cover
            raise RuntimeError(f"pendulum integration failed: {sol.message}")
        self._sol = sol.sol
        self.period = None

    def angle(self, t: ArrayLike) -> tuple[NDArray[np.float64], ...]:
        """``θ, θ̇, θ̈`` at ``t`` (rad, rad/s, rad/s²)."""
        t = finite_array(t, "t")
        if np.any(t > self.end + 1.0):
            raise ValueError(f"the pendulum was integrated to {self.end} s only")
        flat = t.reshape(-1)
        th = np.full(flat.shape, self.theta0)
        dth = np.zeros(flat.shape)
        on = flat > self.release
        if np.any(on):
            y = self._sol(flat[on])
            th[on], dth[on] = y[0], y[1]
        ddth = np.where(flat >= self.release, -G / self.length * np.sin(th), 0.0)
        return th.reshape(t.shape), dth.reshape(t.shape), ddth.reshape(t.shape)

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        th, _, _ = self.angle(t)
        q = quat_multiply(_qaxis(2, self.azimuth), _qaxis(0, th))
        return quat_multiply(q, self.mount)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        _, dth, _ = self.angle(t)
        return dth[..., None] * self.axis_b

    def _increments(self, t0: NDArray[np.float64], t1: NDArray[np.float64]
                    ) -> NDArray[np.float64]:
        return (self.angle(t1)[0] - self.angle(t0)[0])[:, None] * self.axis_b

    def energy(self, t: ArrayLike) -> NDArray[np.float64]:
        """Energy per unit moment of inertia, ``½ θ̇² + (g/L)(1 − cos θ)`` (1/s²): constant
        after the release."""
        th, dth, _ = self.angle(t)
        return 0.5 * dth**2 + G / self.length * (1.0 - np.cos(th))


def pendulum(length_m: float = 0.8, amplitude_deg: float = 45.0, *, sensor_m: float | None = None,
             rate_hz: float = 100.0, duration_s: float = 60.0, rest_s: float = 2.0,
             azimuth_deg: float = 25.0, mount_deg: ArrayLike = (8.0, -12.0, 30.0),
             mag_unit: float = 1.0, name: str | None = None) -> Scenario:
    """A rigid pendulum swinging ``amplitude_deg`` about a horizontal pivot axis.

    Parameters
    ----------
    length_m : float
        Equivalent length ``L`` (its period is ``2π√(L/g)`` at small swings), m.
    amplitude_deg : float
        Swing amplitude: held there during the rest, then released, deg.
    sensor_m : float, optional
        Distance of the sensor from the pivot along the rod, m (default ``L``: the
        accelerometer then reads along the rod only).
    rate_hz, duration_s, rest_s : float
        Sample rate (Hz), length (s) and time held before the release (s).
    azimuth_deg : float
        The pivot axis, counter-clockwise from east, deg.
    mount_deg : (3,)
        The sensor's mounting on the rod, a rotation vector in degrees.
    mag_unit : float
        The field's unit (µT times this).
    name : str, optional
        Default ``pendulum-{L}m-{amplitude}deg``.
    """
    r = length_m if sensor_m is None else positive(sensor_m, "sensor_m")
    mount = quat_from_rotvec(np.radians(np.asarray(mount_deg, dtype=np.float64)))
    motion = PendulumMotion(length_m, math.radians(amplitude_deg), rest_s, duration_s,
                            azimuth_rad=math.radians(azimuth_deg), mount=mount)
    az = motion.azimuth
    pivot = np.array([0.0, 0.0, 1.0 + r])

    def position(t):
        th, _, _ = motion.angle(t)
        local = np.stack([0 * th, r * np.sin(th), -r * np.cos(th)], axis=-1)
        return pivot + _rotz(az, local)

    def velocity(t):
        th, dth, _ = motion.angle(t)
        local = np.stack([0 * th, r * np.cos(th) * dth, r * np.sin(th) * dth], axis=-1)
        return _rotz(az, local)

    def acceleration(t):
        th, dth, ddth = motion.angle(t)
        c, s = np.cos(th), np.sin(th)
        local = np.stack([0 * th, r * (c * ddth - s * dth**2), r * (s * ddth + c * dth**2)],
                         axis=-1)
        return _rotz(az, local)

    body = Body(motion, acceleration, velocity, position)
    label = name or f"pendulum-{length_m:g}m-{amplitude_deg:g}deg"
    return Scenario(label, "pendulum", body, float(duration_s), float(rest_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"length m": length_m, "amplitude deg": amplitude_deg, "sensor at m": r,
                     "period s": round(_pendulum_period(length_m, amplitude_deg), 3)})


def _pendulum_period(length_m: float, amplitude_deg: float) -> float:
    """The exact period ``4 √(L/g) K(sin²(θ0/2))``."""
    from scipy.special import ellipk

    return 4.0 * math.sqrt(length_m / G) * float(
        ellipk(math.sin(math.radians(amplitude_deg) / 2) ** 2))


# ------------------------------------------------------------------------------ vehicle
def vehicle(*, speed: float = 12.0, lateral_acc: float = 3.0, rate_hz: float = 100.0,
            duration_s: float | None = None, rest_s: float = 3.0, heading_deg: float = 60.0,
            roll_per_acc_deg: float = 0.6, pitch_per_acc_deg: float = 0.5,
            mag_unit: float = 1.0, name: str = "vehicle") -> Scenario:
    """A car on a flat road: from rest to ``speed``, two left circles, a right circle, a
    straight, a 90° left turn and a stop, at a steady ``lateral_acc`` in the turns.

    Speed and yaw rate are piecewise constant joined by quintic ramps (C²); heading is
    their exact integral. The body (FLU) rolls outwards by ``roll_per_acc_deg`` per m/s²
    of lateral acceleration and pitches nose-up by ``pitch_per_acc_deg`` per m/s² of
    forward acceleration: ``q_n_b = q_z(ψ) ⊗ q_y(−θ) ⊗ q_x(φ)`` (exact body rates through
    :class:`~strapdown.truth.motions.RotationSequenceMotion`); the sensor is at the roll
    and pitch centre. Acceleration ``a_n = v̇ [cos ψ, sin ψ, 0] + v ψ̇ [−sin ψ, cos ψ, 0]``.
    """
    r = lateral_acc / speed  # yaw rate in the circles, rad/s
    circle = 2 * math.pi / r
    ramp = 2.0
    t_go = rest_s
    t1 = t_go + 10.0  # straight after speeding up over 8 s
    yaw_times = [t1, t1 + 2 * circle, t1 + 3 * circle + ramp]
    yaw_vals = [0.0, r, -r, 0.0]
    t_turn = yaw_times[-1] + ramp + 6.0
    turn_s = math.pi / 2 / r - ramp  # a quarter circle, counting the ramps
    yaw_times += [t_turn, t_turn + ramp + turn_s]
    yaw_vals += [r, 0.0]
    t_stop = yaw_times[-1] + ramp + 5.0
    speed_times, speed_vals, speed_ramp = [t_go, t_stop], [0.0, speed, 0.0], 8.0
    end = t_stop + speed_ramp + 4.0
    duration_s = end if duration_s is None else float(duration_s)
    if duration_s > end:
        raise ValueError(f"the vehicle's course lasts {end:.1f} s; duration_s={duration_s}")
    psi0 = math.radians(heading_deg)
    kr, kp = math.radians(roll_per_acc_deg), math.radians(pitch_per_acc_deg)

    def kin(t):
        t = np.asarray(t, dtype=np.float64)
        v, dv, ddv, _ = _steps(t, speed_times, speed_vals, speed_ramp)
        w, dw, _, iw = _steps(t, yaw_times, yaw_vals, ramp)
        return v, dv, ddv, w, dw, psi0 + iw

    def angles(t):
        v, dv, _, w, _, psi = kin(t)
        return np.stack([psi, -kp * dv, kr * v * w], axis=-1)

    def angle_rates(t):
        v, dv, ddv, w, dw, _ = kin(t)
        return np.stack([w, -kp * ddv, kr * (dv * w + v * dw)], axis=-1)

    def velocity(t):
        v, _, _, _, _, psi = kin(t)
        return np.stack([v * np.cos(psi), v * np.sin(psi), 0 * v], axis=-1)

    def acceleration(t):
        v, dv, _, w, _, psi = kin(t)
        c, s = np.cos(psi), np.sin(psi)
        return np.stack([dv * c - v * w * s, dv * s + v * w * c, 0 * v], axis=-1)

    body = Body(RotationSequenceMotion("zyx", angles, angle_rates), acceleration, velocity)
    return Scenario(name, "vehicle", body, float(duration_s), float(rest_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"speed m/s": speed, "lateral acc m/s²": lateral_acc,
                     "circle radius m": round(speed / r, 1), "course s": round(end, 1)})


# ------------------------------------------------------------------------------ loiter
def loiter(*, speed: float = 20.0, bank_deg: float = 20.0, straight_s: float = 8.0,
           rate_hz: float = 100.0, duration_s: float = 130.0, roll_time: float = 2.0,
           mag_unit: float = 1.0, name: str = "loiter") -> Scenario:
    """Wang, Wang & Wang's loiter (their ``speed-bank`` reading: 20 m/s at 20°, radius
    112 m): level coordinated flight (:class:`~strapdown.truth.trajectory.CoordinatedFlight`,
    ENU, body FLU), ``straight_s`` straight and level — to the sensor indistinguishable
    from rest — then a steady turn to the end. Times before 0 repeat the straight leg's
    start (exact: it is unaccelerated)."""
    flight = CoordinatedFlight([Segment(straight_s), Segment(duration_s - straight_s + 1.0,
                                                             bank_deg)],
                               speed=speed, altitude=100.0, heading0_deg=30.0,
                               roll_time=roll_time)

    def sampled(attr: str, k: int) -> VecFn:
        def fn(t):
            t = np.asarray(t, dtype=np.float64)
            flat = np.clip(t.reshape(-1), 0.0, flight.duration)
            return np.asarray(getattr(flight.sample(flat), attr)).reshape((*t.shape, k))
        return fn

    start = sampled("position", 3)
    v0 = flight.sample(np.array([0.0])).velocity[0]

    def position(t):  # before 0: the straight leg's start, extended back
        t = np.asarray(t, dtype=np.float64)
        return start(t) + np.minimum(t, 0.0)[..., None] * v0

    motion = UserMotion(sampled("q", 4), sampled("omega", 3))
    body = Body(motion, sampled("acceleration", 3), sampled("velocity", 3), position)
    radius = speed**2 / (G * math.tan(math.radians(bank_deg)))
    return Scenario(name, "loiter", body, float(duration_s), float(straight_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"speed m/s": speed, "bank deg": bank_deg, "radius m": round(radius, 1),
                     "straight s": straight_s})


# ------------------------------------------------------------------------------ spin-coning
class SpunUpMotion(Motion):
    """A :class:`~strapdown.truth.motions.SpinConing` run on a warped clock: at rest until
    ``start_s``, then its rates grow smoothly to full over ``ramp_s``.

    ``q_n_b(t) = q_frame ⊗ q_sc(τ(t))`` with ``τ̇ = S((t − start)/ramp)`` (the quintic
    smooth step), so ``ω_b(t) = τ̇ ω_sc(τ)`` exactly; increments by the default quadrature.
    """

    def __init__(self, base: SpinConing, frame: ArrayLike, start_s: float, ramp_s: float):
        self.base = base
        self.frame = np.asarray(frame, dtype=np.float64)
        self.start = float(start_s)
        self.ramp = positive(ramp_s, "ramp_s")
        self.period = None

    def clock(self, t: ArrayLike) -> tuple[NDArray[np.float64], ...]:
        """``τ, τ̇, τ̈`` at ``t``."""
        t = finite_array(t, "t")
        s, s1, _, si = _quintic((t - self.start) / self.ramp)
        return self.ramp * si, s, s1 / self.ramp

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        tau, _, _ = self.clock(t)
        return quat_multiply(self.frame, self.base.attitude(tau))

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        tau, dtau, _ = self.clock(t)
        return dtau[..., None] * self.base.rate(tau)

    def angular_acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        """``ω̇_b = τ̈ ω_sc(τ) + τ̇² ω̇_sc(τ)`` (rad/s²)."""
        tau, dtau, ddtau = self.clock(t)
        a, om, ws = self.base.half_angle, self.base.cone_rate, self.base.spin_rate
        s, lam = om * math.sin(a), ws - om
        dw = np.stack([0 * tau, s * lam * np.cos(lam * tau), -s * lam * np.sin(lam * tau)], -1)
        return ddtau[..., None] * self.base.rate(tau) + (dtau**2)[..., None] * dw


def spin_coning(*, spin_hz: float = 1.5, cone_hz: float = 0.5, half_angle_deg: float = 15.0,
                lever_arm_m: ArrayLike = (0.02, 0.03, 0.01), rate_hz: float = 400.0,
                duration_s: float = 40.0, rest_s: float = 3.0, spin_up_s: float = 3.0,
                mag_unit: float = 6.67, name: str = "spin-coning") -> Scenario:
    """A body spinning about its x axis at ``spin_hz`` while that axis cones at ``cone_hz``
    about the vertical, ``half_angle_deg`` from it; at rest (tilted by the half angle) for
    ``rest_s``, spun up over ``spin_up_s``. The sensor sits ``lever_arm_m`` (body frame) from
    the fixed rotation centre: ``a_n = C_n_b (ω̇ × r + ω × (ω × r))``."""
    base = SpinConing(math.radians(half_angle_deg), 2 * math.pi * cone_hz, 2 * math.pi * spin_hz)
    frame = _qaxis(1, -math.pi / 2)  # the cone axis (reference x) points up
    motion = SpunUpMotion(base, frame, rest_s, spin_up_s)
    arm = np.asarray(lever_arm_m, dtype=np.float64)
    centre = np.array([0.0, 0.0, 1.0])

    def position(t):
        return centre + quat_rotate(motion.attitude(t), np.broadcast_to(arm, (*np.shape(t), 3)))

    def velocity(t):
        w = motion.rate(t)
        return quat_rotate(motion.attitude(t), np.cross(w, arm))

    def acceleration(t):
        w = motion.rate(t)
        dw = motion.angular_acceleration(t)
        a_b = np.cross(dw, arm) + np.cross(w, np.cross(w, arm))
        return quat_rotate(motion.attitude(t), a_b)

    body = Body(motion, acceleration, velocity, position)
    peak = float(np.linalg.norm(np.cross(base.rate(0.0), np.cross(base.rate(0.0), arm))))
    return Scenario(name, "spin-coning", body, float(duration_s), float(rest_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"spin Hz": spin_hz, "cone Hz": cone_hz, "half angle deg": half_angle_deg,
                     "lever arm m": round(float(np.linalg.norm(arm)), 3),
                     "centripetal m/s²": round(peak, 2)})


# ------------------------------------------------------------------------------ hand-held
def hand_shaking(seed: RngLike = 0, *, shake_acc: ArrayLike = (3.0, 2.5, 2.0),
                 shake_hz: ArrayLike = (2.1, 2.9, 3.7), rate_hz: float = 200.0,
                 duration_s: float = 60.0, rest_s: float = 2.0, mag_unit: float = 1.0,
                 name: str = "hand-held") -> Scenario:
    """The hand-held rotation of :func:`~strapdown.truth.recordings.hand_held` (its phases
    from ``seed``) shaken along east, north and up by ``shake_acc`` m/s² at ``shake_hz``
    (random phases; switched on with the rotation over 2 s): a centimetre or two of
    displacement, accelerations of a quarter g and more."""
    rng = np.random.default_rng(seed)
    hh = hand_held(rng, rest_s=rest_s, ramp_s=2.0)
    acc = np.column_stack([np.asarray(shake_acc, float), np.asarray(shake_hz, float),
                           rng.uniform(0.0, 2 * math.pi, 3)])
    hh = dataclasses.replace(hh, acceleration=acc)
    body = Body(hh.motion, hh.acceleration_n)
    return Scenario(name, "hand-held", body, float(duration_s), float(rest_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"shake m/s²": "/".join(f"{a:g}" for a in acc[:, 0]),
                     "shake Hz": "/".join(f"{f:g}" for f in acc[:, 1])})


# ------------------------------------------------------------------------------ steel frame
@dataclass(frozen=True)
class SteelFrame:
    """Magnetised steel members as lines of point dipoles (µT at places in m).

    Attributes
    ----------
    points : ndarray (k, 3)
        Dipole positions, m (ENU).
    moments : ndarray (k, 3)
        Dipole moments times µ0/4π, µT·m³.
    """

    points: NDArray[np.float64]
    moments: NDArray[np.float64]

    def disturbance(self, r: ArrayLike) -> NDArray[np.float64]:
        """The frame's field at places ``r`` (…, 3): ``Σ (3 (m·u) u − m) / d³``, µT."""
        r = np.asarray(r, dtype=np.float64)
        flat = r.reshape(-1, 3)
        out = np.zeros_like(flat)
        for k in range(0, flat.shape[0], 4096):  # bounded memory
            d = flat[k:k + 4096, None, :] - self.points[None, :, :]
            dist = np.linalg.norm(d, axis=-1)
            u = d / dist[..., None]
            mu = np.einsum("nkj,kj->nk", u, self.moments)
            out[k:k + 4096] = ((3 * mu[..., None] * u - self.moments[None]) /
                               dist[..., None] ** 3).sum(axis=1)
        return out.reshape(r.shape)

    def field(self, r: ArrayLike) -> NDArray[np.float64]:
        """Earth field plus the frame's, µT."""
        return EARTH_FIELD_UT + self.disturbance(r)


def _door_frame(rng: np.random.Generator, half_width: float, height: float,
                spacing: float = 0.05) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Dipole places and unscaled moments of a steel door frame at x = 0: two columns at
    y = ±half_width and a lintel at z = height. Each segment is magnetised along its member
    by the Earth field (induced) plus a remanence that varies along the member."""
    members = [(np.array([0.0, -half_width, 0.0]), np.array([0.0, -half_width, height])),
               (np.array([0.0, half_width, 0.0]), np.array([0.0, half_width, height])),
               (np.array([0.0, -half_width, height]), np.array([0.0, half_width, height]))]
    e = EARTH_FIELD_UT / np.linalg.norm(EARTH_FIELD_UT)
    pts, mom = [], []
    for a, b in members:
        length = float(np.linalg.norm(b - a))
        k = round(length / spacing)
        s = (np.arange(k) + 0.5) / k
        p = a + s[:, None] * (b - a)
        axis = (b - a) / length
        induced = 1.0 * np.dot(e, axis) * axis
        raw = rng.standard_normal((k + 6, 3))
        remanent = 0.8 * np.array([np.convolve(raw[:, j], np.ones(7) / np.sqrt(7), "valid")
                                   for j in range(3)]).T
        pts.append(p)
        mom.append(induced + remanent[:k])
    return np.vstack(pts), np.vstack(mom)


def steel_frame(seed: RngLike = 0, *, strength: float = 0.8, clearance_m: float = 0.3,
                walk_m: float = 8.0, period_s: float = 20.0, rate_hz: float = 100.0,
                duration_s: float = 90.0, rest_s: float = 2.0, mag_unit: float = 1.0,
                name: str = "steel-frame") -> Scenario:
    """The hand-held rotation (:func:`~strapdown.truth.recordings.hand_held`) carried back
    and forth along east, ``walk_m`` end to end, through a steel door frame (1 m wide,
    2.1 m high, at the walk's middle), ``clearance_m`` from one column at 1.1 m height.

    The frame is lines of dipoles every 5 cm (:class:`SteelFrame`) magnetised along each
    member by the Earth field plus a remanence varying along it (from ``seed``), scaled so
    that the disturbance's largest norm on the walk's line is ``strength`` times the Earth
    field's. The walk: ``x = −walk/2 + (walk/2)(1 − cos φ)``, ``φ̇ = (2π/period) S`` with S
    the quintic smooth step over 2 s after the rest.
    """
    rng = np.random.default_rng(seed)
    hh = hand_held(rng, rest_s=rest_s, ramp_s=2.0, yaw0_deg=-20.0)
    half_w, height = 0.5, 2.1
    pts, mom = _door_frame(rng, half_w, height)
    y0, z0, amp = half_w - clearance_m, 1.1, walk_m / 2
    line = np.column_stack([np.linspace(-amp, amp, 4001), np.full(4001, y0), np.full(4001, z0)])
    peak = np.max(np.linalg.norm(SteelFrame(pts, mom).disturbance(line), axis=1))
    frame = SteelFrame(pts, mom * strength * np.linalg.norm(EARTH_FIELD_UT) / peak)
    om, ramp = 2 * math.pi / period_s, 2.0

    def phase(t):
        s, s1, _, si = _quintic((np.asarray(t, dtype=np.float64) - rest_s) / ramp)
        return om * ramp * si, om * s, om * s1 / ramp

    def position(t):
        ph, _, _ = phase(t)
        x = -amp + amp * (1 - np.cos(ph))
        return np.stack([x, np.full_like(x, y0), np.full_like(x, z0)], axis=-1)

    def velocity(t):
        ph, dph, _ = phase(t)
        vx = amp * np.sin(ph) * dph
        return np.stack([vx, 0 * vx, 0 * vx], axis=-1)

    def acceleration(t):
        ph, dph, ddph = phase(t)
        ax = amp * (np.cos(ph) * dph**2 + np.sin(ph) * ddph)
        return np.stack([ax, 0 * ax, 0 * ax], axis=-1)

    body = Body(hh.motion, acceleration, velocity, position, frame.field)
    return Scenario(name, "steel-frame", body, float(duration_s), float(rest_s),
                    Sensors(rate_hz, mag_unit=mag_unit),
                    {"peak disturbance / Earth field": strength, "clearance m": clearance_m,
                     "walk m": walk_m, "period s": period_s})


# ------------------------------------------------------------------------------ rests
#: The rests' poses: yaw, pitch, roll (ZYX, ENU, deg).
REST_POSES = ((20.0, 10.0, -5.0), (20.0, 10.0, 85.0), (110.0, 10.0, 85.0), (110.0, -50.0, 0.0),
              (200.0, -50.0, 0.0), (200.0, 40.0, -120.0), (290.0, 0.0, 0.0))


def rests(*, hold_s: float = 12.0, turn_s: float = 2.0, rate_hz: float = 50.0,
          duration_s: float | None = None, mag_unit: float = 0.01, name: str = "rests"
          ) -> Scenario:
    """Stationary rests of ``hold_s`` in each of :data:`REST_POSES`, joined by quintic turns
    of ``turn_s`` (yaw, pitch and roll each ramped; exact body rates), about the sensor."""
    poses = np.radians(np.asarray(REST_POSES))
    times = hold_s + (hold_s + turn_s) * np.arange(len(poses) - 1)
    end = float(times[-1] + turn_s + hold_s)
    dur = end if duration_s is None else float(duration_s)
    if dur > end:
        raise ValueError(f"the rests last {end} s; duration_s={duration_s}")

    def angles(t):
        return np.stack([_steps(t, times, poses[:, j], turn_s)[0] for j in range(3)], -1)

    def angle_rates(t):
        return np.stack([_steps(t, times, poses[:, j], turn_s)[1] for j in range(3)], -1)

    motion = RotationSequenceMotion("zyx", angles, angle_rates)
    body = Body(motion, lambda t: np.zeros((*np.shape(t), 3)),
                lambda t: np.zeros((*np.shape(t), 3)),
                lambda t: np.broadcast_to([0.0, 0.0, 1.0], (*np.shape(t), 3)).copy())
    return Scenario(name, "rests", body, dur, float(hold_s), Sensors(rate_hz, mag_unit=mag_unit),
                    {"poses": len(poses), "hold s": hold_s, "turn s": turn_s})


# ------------------------------------------------------------------------------ the suite
def suite(seed: RngLike = 0) -> list[Scenario]:
    """The generalisation suite: three pendulums (0.3 m at 70°, 0.8 m at 45°, 1.5 m at 20°),
    the vehicle, the loiter, spin-coning, hand-held shaking, the steel frame and the rests,
    at 50–400 Hz, the field in µT, gauss, counts or arbitrary units. ``seed`` draws the
    random parts of the motions (hand-held phases, the frame's remanence)."""
    rng = np.random.default_rng(seed)
    return [
        pendulum(0.3, 70.0, rate_hz=100.0, duration_s=60.0, mag_unit=0.01),
        pendulum(0.8, 45.0, sensor_m=0.6, rate_hz=200.0, duration_s=60.0,
                 azimuth_deg=-40.0, mount_deg=(-5.0, 20.0, -70.0)),
        pendulum(1.5, 20.0, sensor_m=1.2, rate_hz=51.0, duration_s=90.0, azimuth_deg=100.0,
                 mount_deg=(90.0, 0.0, 0.0), mag_unit=1.0 / 49.2),
        vehicle(),
        loiter(),
        spin_coning(),
        hand_shaking(rng),
        steel_frame(rng),
        rests(),
    ]
