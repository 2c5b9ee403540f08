"""Recordings as devices write them, with exact truth: a phone log, a rounded-stamp gyro log
and a motion-capture lab file, each beside a twin holding the same samples with exact stamps.

The body motion (:func:`hand_held`) is what an AHRS meets in the hand: at rest for the first
``rest_s`` seconds (an AHRS initialises from its first samples, taken to be at rest), then
smooth rotation about all three axes — tens of degrees per second, tilt up to about 40° —
with a small translational acceleration. Frames and conventions: ``q_n_b`` is the Hamilton,
scalar-first quaternion of the body frame in ``n`` = ENU (x east, y north, z up); the
accelerometer measures the specific force (``+9.80665`` m/s² up at rest); the Earth field
points north and down (no declination, so magnetic north is north).

The writers (:func:`phone_recording`, :func:`rounded_gyro_log`, :func:`lab_recording`) make
what a user brings — jittered integer-millisecond epoch stamps and a dropped burst; stamps
rounded to whole milliseconds; a logger that samples a slower IMU, so rows repeat the last
IMU sample, some stamps are written twice and some stretches not at all — and the twin a
careful user would make of it, so that a tool's result on the one can be compared with its
result on the other and both with the truth. Everything random comes from a ``seed`` (any
:func:`numpy.random.default_rng` argument); the same seed writes the same bytes.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_from_rotvec, quat_multiply
from strapdown.truth.motions import Motion, RotationSequenceMotion
from strapdown.truth.sensors import (
    AccelerometerErrors,
    GyroErrors,
    MagnetometerErrors,
    RngLike,
    accelerometer,
    magnetometer,
)

__all__ = [
    "CLEANED_HEADER",
    "EARTH_FIELD_UT",
    "LAB_HEADER",
    "G",
    "HandHeld",
    "ImuSamples",
    "LabRecording",
    "Recording",
    "hand_held",
    "imu_samples",
    "lab_recording",
    "phone_recording",
    "rounded_gyro_log",
]

#: Standard gravity, m/s².
G = 9.80665
#: The Earth field in ENU, µT: 20 horizontal (pointing north), 45 down (a dip of 66°).
EARTH_FIELD_UT = np.array([0.0, 20.0, -45.0])

#: Hand-held rotation: (amplitude deg, frequency Hz) of the two sines of yaw, pitch and roll.
_ANGLE_SINES = (((45.0, 0.07), (15.0, 0.29)),
                ((22.0, 0.13), (10.0, 0.41)),
                ((20.0, 0.17), (9.0, 0.37)))
#: Translational acceleration: (amplitude m/s², frequency Hz) of each ENU axis's sine.
_ACC_SINES = ((0.25, 0.45), (0.2, 0.6), (0.15, 0.8))


def _smoothstep(t: NDArray[np.float64], t0: float, width: float
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The quintic smooth step from 0 (``t ≤ t0``) to 1 (``t ≥ t0 + width``) and its
    derivative: continuous to the second derivative, so the rate is smooth."""
    x = np.clip((t - t0) / width, 0.0, 1.0)
    s = x * x * x * (10.0 - 15.0 * x + 6.0 * x * x)
    ds = 30.0 * x * x * (1.0 - x) ** 2 / width
    return s, ds


@dataclass(frozen=True)
class HandHeld:
    """A hand-held sensor's motion: attitude, body rate, specific force and field, exact.

    Build it with :func:`hand_held`.

    Attributes
    ----------
    motion : Motion
        The rotation, ``q_n_b(t)`` (ENU) and ``ω_b(t)`` (rad/s); ``t`` in seconds from the
        start of the recording.
    acceleration : ndarray of shape (3, 3)
        Rows ``(amplitude m/s², frequency Hz, phase rad)`` of the translational
        acceleration's sine on the east, north and up axes, switched on with the rotation.
    rest_s, ramp_s : float
        The body is at rest until ``rest_s``; the motion grows smoothly over ``ramp_s``.
    field_n : ndarray of shape (3,)
        The Earth field in ENU, µT.
    """

    motion: Motion
    acceleration: NDArray[np.float64]
    rest_s: float
    ramp_s: float
    field_n: NDArray[np.float64]

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        """``q_n_b(t)``, shape ``t.shape + (4,)``."""
        return self.motion.attitude(t)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body angular rate ``ω_b(t)`` (rad/s), shape ``t.shape + (3,)``."""
        return self.motion.rate(t)

    def acceleration_n(self, t: ArrayLike) -> NDArray[np.float64]:
        """Translational acceleration in ENU (m/s²), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        w, _ = _smoothstep(t, self.rest_s, self.ramp_s)
        a, f, p = self.acceleration.T
        return w[..., None] * a * np.sin(2.0 * np.pi * f * t[..., None] + p)

    def specific_force(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body specific force ``f_b = C_b_n (a_n + g_up)`` (m/s²), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        f_n = self.acceleration_n(t) + np.array([0.0, 0.0, G])
        c_n_b = dcm_from_quat(self.attitude(t))
        return np.einsum("...ji,...j->...i", c_n_b, f_n)


def hand_held(seed: RngLike = 0, *, rest_s: float = 2.0, ramp_s: float = 2.0,
              yaw0_deg: float = 30.0) -> HandHeld:
    """A hand-held motion: at rest, then smooth rotation about all three axes.

    Yaw, pitch and roll (ZYX, ``q_n_b = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)``) are each a constant
    plus two sines (yaw ±60°, pitch ±29°, roll ±26°; rates up to about 50 °/s), multiplied
    by a quintic smooth step from 0 at ``rest_s`` to 1 at ``rest_s + ramp_s``; the
    phases come from ``seed``. The translational acceleration (a few tenths of m/s²) is
    switched on the same way. Body rates are exact (:class:`RotationSequenceMotion`).

    Parameters
    ----------
    seed : int, Generator or None
        Phases of the sines.
    rest_s : float
        Time at rest at the start, s.
    ramp_s : float
        Time over which the motion grows to its full amplitude, s.
    yaw0_deg : float
        Heading at rest (ENU yaw, from east towards north), deg.

    Returns
    -------
    HandHeld
    """
    rng = np.random.default_rng(seed)
    amp = np.radians([[a for a, _ in axis] for axis in _ANGLE_SINES])
    om = 2.0 * np.pi * np.array([[f for _, f in axis] for axis in _ANGLE_SINES])
    ph = rng.uniform(0.0, 2.0 * np.pi, amp.shape)
    base = np.array([np.radians(yaw0_deg), 0.0, 0.0])

    def sines(t):
        arg = om * t[..., None, None] + ph
        return ((amp * np.sin(arg)).sum(-1), (amp * om * np.cos(arg)).sum(-1))

    def angles(t):
        w, _ = _smoothstep(t, rest_s, ramp_s)
        s, _ = sines(t)
        return base + w[..., None] * s

    def angle_rates(t):
        w, dw = _smoothstep(t, rest_s, ramp_s)
        s, ds = sines(t)
        return dw[..., None] * s + w[..., None] * ds

    acc = np.array([[a, f, p] for (a, f), p in
                    zip(_ACC_SINES, rng.uniform(0.0, 2.0 * np.pi, 3), strict=True)])
    return HandHeld(RotationSequenceMotion("zyx", angles, angle_rates), acc, float(rest_s),
                    float(ramp_s), EARTH_FIELD_UT.copy())


@dataclass(frozen=True)
class ImuSamples:
    """IMU samples (SI units except the field) at times ``t``.

    Attributes
    ----------
    t : ndarray (n,)
        Sample times, s.
    gyro : ndarray (n, 3)
        Angular rate, rad/s.
    acc : ndarray (n, 3)
        Specific force, m/s².
    mag : ndarray (n, 3)
        Magnetic field in the body, µT.
    """

    t: NDArray[np.float64]
    gyro: NDArray[np.float64]
    acc: NDArray[np.float64]
    mag: NDArray[np.float64]


def imu_samples(body: HandHeld, t: ArrayLike, h: float, seed: RngLike = 0, *,
                gyro_sample: str = "interval", noise: bool = True,
                gyro_noise: float = np.radians(0.007), gyro_bias_sd: float = np.radians(0.2),
                acc_noise: float = 0.002, mag_noise: float = 0.3) -> ImuSamples:
    """Sample ``body`` at the uniform times ``t`` (every ``h`` s) as a consumer MEMS IMU.

    Parameters
    ----------
    body : HandHeld
    t : array_like (n,)
        Sample times, s, uniform with step ``h``.
    h : float
        Sample period, s (the noise per sample scales with ``1/√h``).
    seed : int, Generator or None
        Noise and the gyro bias.
    gyro_sample : {"interval", "point"}
        A gyro sample is the mean rate over the period ending at its time (``interval``,
        as a MEMS gyro's filter gives it) or the rate at its time (``point``).
    noise : bool
        False: ideal sensors (no noise, no bias).
    gyro_noise : float
        Gyro white-noise density, rad/s/√Hz.
    gyro_bias_sd : float
        Standard deviation of the constant gyro bias drawn per axis, rad/s.
    acc_noise : float
        Accelerometer white-noise density, m/s²/√Hz.
    mag_noise : float
        Magnetometer noise per sample, µT.

    Returns
    -------
    ImuSamples
    """
    rng = np.random.default_rng(seed)
    t = np.asarray(t, dtype=np.float64)
    if gyro_sample == "interval":
        edges = np.concatenate([[t[0] - h], t])
        w = body.motion.increments(edges) / np.diff(edges)[:, None]
    elif gyro_sample == "point":
        w = body.rate(t)
    else:
        raise ValueError(f"gyro_sample must be 'interval' or 'point', got {gyro_sample!r}")
    q = body.attitude(t)
    f = body.specific_force(t)
    if not noise:
        return ImuSamples(t, w, accelerometer(t, q, f, h),
                          magnetometer(t, q, body.field_n))
    bias = gyro_bias_sd * rng.standard_normal(3)
    w = GyroErrors(white_noise=gyro_noise, bias=bias).apply(w, "rate", h, rng)
    f = accelerometer(t, q, f, h, errors=AccelerometerErrors(white_noise=acc_noise), rng=rng)
    m = magnetometer(t, q, body.field_n, errors=MagnetometerErrors(white_noise=mag_noise),
                     rng=rng)
    return ImuSamples(t, w, f, m)


@dataclass(frozen=True)
class Recording:
    """A recording as a device wrote it, its exact-stamp twin and the truth.

    Attributes
    ----------
    path : Path
        The file as the device wrote it.
    exact_path : Path
        The same samples with their exact times (same columns, same units).
    t : ndarray (n,)
        True time of each sample in both files, s, in the files' time base (the time
        column converted to seconds).
    q_n_b : ndarray (n, 4)
        True attitude at ``t`` (ENU, scalar first).
    body : HandHeld
        The motion: ``body.attitude(t_file - t_start)`` is the truth at any time.
    t_start : float
        The files' time (s) of the motion's time 0.
    """

    path: Path
    exact_path: Path
    t: NDArray[np.float64]
    q_n_b: NDArray[np.float64]
    body: HandHeld
    t_start: float

    def attitude(self, t_file: ArrayLike) -> NDArray[np.float64]:
        """The true ``q_n_b`` at times ``t_file`` of the files' time base (s)."""
        return self.body.attitude(np.asarray(t_file, dtype=np.float64) - self.t_start)


def _write(path: Path, header: str, rows: Sequence[str]) -> Path:
    """Write a header and rows to ``path`` through a temporary file renamed over it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="\n") as f:
        f.write(header + "\n")
        f.write("".join(r + "\n" for r in rows))
    os.replace(tmp, path)
    return path


def _fmt(values: NDArray[np.float64], fmt: str, sep: str = ",") -> list[str]:
    return [sep.join(fmt % v for v in row) for row in values]


def phone_recording(directory: str | os.PathLike[str], *, seed: RngLike = 0,
                    rate_hz: float = 200.0, duration_s: float = 40.0,
                    jitter_s: float = 1e-3, drop: tuple[int, int] | None = None,
                    epoch_ms: int = 1733119200123, clock_ppm: float = 40.0,
                    noise: bool = True, name: str = "phone") -> Recording:
    """A phone's IMU log: integer-millisecond epoch stamps with jitter, a dropped burst.

    The sensor samples every ``(1 + clock_ppm·10⁻⁶)/rate_hz`` s of the phone's clock; the
    app stamps each sample with ``epoch_ms + round(1000·(t + u))``, ``u`` uniform in
    ``±jitter_s``; ``drop = (start, count)`` rows are missing (a burst lost by the app;
    default: 10 in the middle). Gyro in deg/s (mean rate over the period ending at the
    sample, as a MEMS gyro gives it), accelerometer m/s², magnetometer µT; no units in the
    header. The twin ``NAME_exact.csv`` has the same rows and columns, its stamps the exact
    sample times in (fractional) epoch milliseconds.

    Parameters
    ----------
    directory : path
        Where ``NAME.csv`` and ``NAME_exact.csv`` are written.
    seed : int, Generator or None
        Motion phases, sensor noise, gyro bias and stamp jitter.
    rate_hz : float
        Nominal sample rate, Hz.
    duration_s : float
        Length of the recording, s.
    jitter_s : float
        Half-width of the uniform stamp jitter, s.
    drop : (int, int), optional
        First index and length of the dropped burst; ``(0, 0)`` drops nothing.
    epoch_ms : int
        Stamp of the first sample before jitter (Unix epoch, ms).
    clock_ppm : float
        The sensor clock's rate error against the phone's clock, ppm.
    noise : bool
        False: ideal sensors (the stamps jitter all the same).
    name : str
        File name stem.

    Returns
    -------
    Recording
        ``t`` in epoch seconds; ``t_start = epoch_ms / 1000``.

    Notes
    -----
    Header ``timestamp_ms,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z``.
    """
    rng = np.random.default_rng(seed)
    body = hand_held(rng)
    h = (1.0 + clock_ppm * 1e-6) / rate_hz
    n = int(duration_s * rate_hz)
    t = h * np.arange(n, dtype=np.float64)
    imu = imu_samples(body, t, h, rng, noise=noise)
    stamps = epoch_ms + np.rint(1e3 * (t + rng.uniform(-jitter_s, jitter_s, n))).astype(np.int64)
    if np.any(np.diff(stamps) <= 0):
        raise ValueError("jitter_s too large for rate_hz: the stamps would not increase")
    start, count = (n // 2, 10) if drop is None else drop
    keep = np.ones(n, bool)
    keep[start:start + count] = False
    values = np.hstack([np.degrees(imu.gyro), imu.acc, imu.mag])[keep]
    body_cols = _fmt(values, "%.6f")
    header = "timestamp_ms,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z"
    directory = Path(directory)
    path = _write(directory / f"{name}.csv", header,
                  [f"{s},{r}" for s, r in zip(stamps[keep], body_cols, strict=True)])
    exact = epoch_ms + 1e3 * t[keep]
    exact_path = _write(directory / f"{name}_exact.csv", header,
                        [f"{s:.4f},{r}" for s, r in zip(exact, body_cols, strict=True)])
    t0 = epoch_ms / 1e3
    return Recording(path, exact_path, t0 + t[keep], body.attitude(t[keep]), body, t0)


def rounded_gyro_log(directory: str | os.PathLike[str], *, seed: RngLike = 0,
                     rate_hz: float = 400.0, duration_s: float = 40.0, noise: bool = True,
                     name: str = "rounded") -> Recording:
    """A regular gyro log whose stamps were rounded to whole milliseconds.

    Samples every ``1/rate_hz`` s from ``t = 0``; the stamp is ``round(k/rate_hz, 3)``
    (to even on ties, so at 400 Hz 0, 0.002, 0.005, 0.008, 0.010, …). Rates in deg/s at
    the stamps (point samples, the convention of :func:`strapdown.algorithms` rate
    algorithms), a low-noise gyro with a small bias. The twin ``NAME_exact.csv`` has
    the exact times.

    Parameters
    ----------
    directory : path
        Where ``NAME.csv`` and ``NAME_exact.csv`` are written.
    seed : int, Generator or None
        Motion phases, gyro noise and bias.
    rate_hz : float
        Sample rate, Hz.
    duration_s : float
        Length of the log, s.
    noise : bool
        False: an ideal gyro.
    name : str
        File name stem.

    Returns
    -------
    Recording
        ``t_start = 0``.

    Notes
    -----
    Header ``t,gx,gy,gz``, time in seconds.
    """
    rng = np.random.default_rng(seed)
    body = hand_held(rng)
    h = 1.0 / rate_hz
    n = int(duration_s * rate_hz)
    t = h * np.arange(n, dtype=np.float64)
    imu = imu_samples(body, t, h, rng, gyro_sample="point", noise=noise,
                      gyro_noise=np.radians(0.002), gyro_bias_sd=np.radians(0.01))
    gyro = _fmt(np.degrees(imu.gyro), "%.7f")
    rounded = np.rint(t * 1e3) / 1e3
    directory = Path(directory)
    path = _write(directory / f"{name}.csv", "t,gx,gy,gz",
                  [f"{s:.3f},{r}" for s, r in zip(rounded, gyro, strict=True)])
    exact_path = _write(directory / f"{name}_exact.csv", "t,gx,gy,gz",
                        [f"{s:.7f},{r}" for s, r in zip(t, gyro, strict=True)])
    return Recording(path, exact_path, t, body.attitude(t), body, 0.0)


@dataclass(frozen=True)
class LabRecording:
    """A motion-capture lab file, its hand-cleaned twin and the truth.

    Attributes
    ----------
    path : Path
        The logger's file (``;``, two header rows; see :func:`lab_recording`).
    cleaned_path : Path
        Held rows collapsed, duplicates dropped, time on the IMU's fitted clock.
    t : ndarray (m,)
        The logger's stamps (s), one per distinct row.
    q_n_b : ndarray (m, 4)
        The true attitude at ``t`` (the file's reference without its optical noise).
    imu_t : ndarray (k,)
        True time of each IMU sample the file holds (s, the logger's time base).
    imu_index : ndarray (k,) of int
        Each such sample's index on the IMU's own clock (missing indices: lost in gaps).
    fitted_t : ndarray (k,)
        Those samples' times on the fitted clock: the cleaned file's time column.
    held_fraction : float
        Fraction of the file's data rows that repeat the previous row's IMU sample.
    body : HandHeld
        The motion (``t_start = 0``).
    """

    path: Path
    cleaned_path: Path
    t: NDArray[np.float64]
    q_n_b: NDArray[np.float64]
    imu_t: NDArray[np.float64]
    imu_index: NDArray[np.int64]
    fitted_t: NDArray[np.float64]
    held_fraction: float
    body: HandHeld


#: The lab file's header rows.
LAB_HEADER = ("Time;Vicon Orientation;;;;IMU Acceleration;;;IMU Gyroscope;;;IMU Magnetometer;;",
              "s;W;X;Y;Z;X;Y;Z;X;Y;Z;X;Y;Z")
#: The cleaned twin's header.
CLEANED_HEADER = ("t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s2],ay[m/s2],az[m/s2],mx,my,mz")


def lab_recording(directory: str | os.PathLike[str], *, seed: RngLike = 0,
                  imu_hz: float = 51.0, logger_hz: float = 91.0, duration_s: float = 40.0,
                  gaps_s: Sequence[float] = (0.19, 0.15, 0.1), duplicates: int = 3,
                  latency_s: float = 0.002, optical_noise_deg: float = 0.1,
                  mag_scale: float = 0.01, noise: bool = True, name: str = "lab"
                  ) -> LabRecording:
    """A lab file: a logger stamping on whole milliseconds writes a slower IMU and a
    motion-capture reference.

    The logger writes a row every 10, 11 or 12 ms (probabilities ¼, ½, ¼: ≈ 91 Hz for the
    default ``logger_hz``; other rates scale the steps) with its stamp (s, whole ms), the
    reference orientation at that stamp (the truth with ``optical_noise_deg`` of rotation
    noise per axis), and the IMU's latest sample (available ``latency_s`` after it was
    taken): at 51 Hz about 43 % of the rows repeat the previous row's IMU values exactly.
    ``duplicates`` rows are written twice with the same stamp; at ``len(gaps_s)`` places
    the logger wrote nothing for up to that long (the IMU samples taken then are lost).
    The IMU samples every ``1/imu_hz`` s of its own clock (40 ppm slow against the
    logger's): acceleration m/s², gyro rad/s (mean over the period ending at the sample),
    field in µT times ``mag_scale`` (arbitrary units).

    ``;``-separated, two header rows::

        Time;Vicon Orientation;;;;IMU Acceleration;;;IMU Gyroscope;;;IMU Magnetometer;;
        s;W;X;Y;Z;X;Y;Z;X;Y;Z;X;Y;Z

    so ``--columns 0,8,9,10,5,6,7,11,12,13`` selects time, gyro, accelerometer, field.
    The hand-cleaned twin ``NAME_cleaned.csv`` (header :data:`CLEANED_HEADER`) has one row
    per IMU sample at its first stamp's place, the time column replaced by the IMU's clock
    fitted to those first stamps (least squares against the IMU sample index); the gaps
    stay gaps.

    Parameters
    ----------
    directory : path
        Where ``NAME.csv`` and ``NAME_cleaned.csv`` are written.
    seed : int, Generator or None
        Motion phases, sensor and optical noise, logger steps, gaps and duplicates.
    imu_hz, logger_hz : float
        The IMU's and the logger's rates, Hz.
    duration_s : float
        Length of the recording, s.
    gaps_s : sequence of float
        Longest interval between stamps at each gap, s (after the first 5 s).
    duplicates : int
        Rows written twice.
    latency_s : float
        Delay from an IMU sample to the logger seeing it, s.
    optical_noise_deg : float
        Reference noise, deg per axis (white).
    mag_scale : float
        The field's unit: µT times this (0.01: gauss).
    noise : bool
        False: ideal IMU and reference (the logging artefacts stay).
    name : str
        File name stem.

    Returns
    -------
    LabRecording
    """
    rng = np.random.default_rng(seed)
    body = hand_held(rng)
    # The logger: steps of 10, 11, 12 ms at 91 Hz, from 0.
    mean_ms = 1e3 / logger_hz
    steps = np.rint(rng.choice([-1.0, 0.0, 0.0, 1.0], int(duration_s * logger_hz))
                    + mean_ms).astype(np.int64)
    stamps_ms = np.concatenate([[0], np.cumsum(steps)])
    stamps_ms = stamps_ms[stamps_ms <= duration_s * 1e3]
    # The IMU on its own clock, its first sample just before the logger's first row.
    h = (1.0 + 40e-6) / imu_hz
    t_first = -rng.uniform(0.0, h) - latency_s
    n_imu = int((stamps_ms[-1] * 1e-3 - t_first) / h) + 1
    t_imu = t_first + np.arange(n_imu) * h
    imu = imu_samples(body, t_imu, h, rng, noise=noise)
    tau = stamps_ms / 1e3  # the file's values, exactly
    index = np.floor((tau - latency_s - t_first) / h + 1e-9).astype(np.int64)
    # Gaps: rows after a start row removed while the interval stays within the gap.
    keep = np.ones(tau.size, bool)
    candidates = np.arange(int(5.0 * logger_hz), tau.size - int(2.0 * logger_hz),
                           int(logger_hz))  # a second apart, from 5 s to 2 s before the end
    if candidates.size < len(gaps_s):
        raise ValueError(f"duration_s={duration_s} is too short for {len(gaps_s)} gaps")
    starts = np.sort(rng.choice(candidates, len(gaps_s), replace=False))
    for a, gap in zip(starts, gaps_s, strict=True):
        b = int(np.searchsorted(stamps_ms, stamps_ms[a] + round(gap * 1e3), "right")) - 1
        keep[a + 1:b] = False
    rows = np.flatnonzero(keep)
    # Duplicates: rows written twice (away from the gaps).
    dup = np.sort(rng.choice(rows[int(5 * logger_hz):-int(logger_hz)], duplicates,
                             replace=False))
    dup_rows = {int(i) for i in dup}
    q_true = body.attitude(tau)
    if noise and optical_noise_deg > 0:
        dq = quat_from_rotvec(np.radians(optical_noise_deg) * rng.standard_normal((tau.size, 3)))
        q_ref = quat_multiply(q_true, dq)
    else:
        q_ref = q_true
    imu_vals = np.hstack([imu.acc, imu.gyro, imu.mag * mag_scale])
    ref_text = _fmt(q_ref, "%.6f", ";")
    imu_text = _fmt(imu_vals, "%.6f", ";")
    lines = []
    for i in rows:
        line = f"{stamps_ms[i] // 1000}.{stamps_ms[i] % 1000:03d};{ref_text[i]};" \
               f"{imu_text[index[i]]}"
        lines.append(line)
        if i in dup_rows:
            lines.append(line)
    directory = Path(directory)
    path = _write(directory / f"{name}.csv", "\n".join(LAB_HEADER), lines)
    # The hand-cleaned twin: each IMU sample once, at its first stamp, on the fitted clock.
    idx = index[rows]
    first = np.concatenate([[True], idx[1:] != idx[:-1]])
    held_fraction = 1.0 - first.sum() / first.size
    samples, first_tau = idx[first], tau[rows][first]
    design = np.column_stack([np.ones(samples.size), samples])
    coef, *_ = np.linalg.lstsq(design, first_tau, rcond=None)
    fitted = design @ coef
    vals = np.hstack([imu.gyro, imu.acc, imu.mag * mag_scale])[samples]
    cleaned_path = _write(directory / f"{name}_cleaned.csv", CLEANED_HEADER,
                          [f"{s:.6f},{r}" for s, r in
                           zip(fitted, _fmt(vals, "%.6f"), strict=True)])
    return LabRecording(path, cleaned_path, tau[rows], q_true[rows], t_imu[samples],
                        samples, fitted, float(held_fraction), body)
