"""Sensor models: gyro (increments, rates, pre-averaging), accelerometer and magnetometer, seeded.

Data flow: a :class:`~strapdown.truth.motions.Motion` gives exact increments or
rates; :class:`GyroErrors` corrupts them reproducibly from a seed or a
:class:`numpy.random.Generator`. Nothing here keeps module-level random state.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.kinds import InputKind
from strapdown._core.validation import finite_array, positive, positive_int
from strapdown.truth.motions import Motion

__all__ = [
    "AccelerometerErrors",
    "GyroErrors",
    "GyroRecord",
    "MagnetometerErrors",
    "RngLike",
    "accelerometer",
    "increments",
    "magnetometer",
    "preaveraged_increments",
    "rate_samples",
]


#: What seeds the sensor noise: anything :func:`numpy.random.default_rng` takes.
RngLike = int | Sequence[int] | np.random.SeedSequence | np.random.BitGenerator | (
    np.random.Generator) | None


@dataclass(frozen=True)
class GyroRecord:
    """Gyro output.

    Attributes
    ----------
    t : ndarray (n + 1,) for increments (interval edges) or (n,) for rates (sample times)
    data : ndarray (n, 3)
        Increments (rad) or rates (rad/s).
    kind : {"increment", "rate"}
    h : float
        Sample interval (s).
    """

    t: NDArray[np.float64]
    data: NDArray[np.float64]
    kind: InputKind
    h: float


def _vec3(x: ArrayLike, name: str) -> NDArray[np.float64]:
    a = finite_array(x, name)
    if a.shape == ():
        a = np.full(3, float(a))
    if a.shape != (3,):
        raise ValueError(f"{name} must be a scalar or shape (3,), got {a.shape}")
    return a


@dataclass(frozen=True)
class GyroErrors:
    """Gyro error model (all zero by default = ideal gyro).

    Applied in this order to the true rate (or increment) ``x``:
    ``M (x + b + b_GM(t)) + n`` then saturation, then quantisation, where
    ``M = I + diag(scale_factor) + misalignment``.

    Parameters
    ----------
    white_noise : float
        Rate white-noise density (angle random walk), rad/s/√Hz. An increment
        over ``h`` gets noise of standard deviation ``white_noise·√h`` rad; a
        rate sample ``white_noise/√h`` rad/s.
    bias : float or (3,)
        Constant bias, rad/s.
    gm_sigma : float or (3,)
        Steady-state standard deviation of a first-order Gauss–Markov bias, rad/s.
    gm_tau : float
        Its correlation time, s (exact discretisation ``exp(−h/τ)``).
    scale_factor : float or (3,)
        Relative scale-factor errors (e.g. 1e-4 = 100 ppm).
    misalignment : (3, 3)
        Small-angle cross-coupling matrix (diagonal must be zero).
    quantization : float
        Output resolution: rad per LSB for increments (with the residual
        carried to the next sample, as pulse-output gyros do), rad/s per LSB
        for rates (plain rounding). 0 disables.
    saturation : float
        Rate limit, rad/s (increments are clipped to ``±saturation·h``).
    """

    white_noise: float = 0.0
    bias: float | NDArray[np.float64] = 0.0
    gm_sigma: float | NDArray[np.float64] = 0.0
    gm_tau: float = np.inf
    scale_factor: float | NDArray[np.float64] = 0.0
    misalignment: NDArray[np.float64] = field(default_factory=lambda: np.zeros((3, 3)))
    quantization: float = 0.0
    saturation: float = np.inf

    def __post_init__(self):
        if float(self.white_noise) < 0 or float(self.quantization) < 0:
            raise ValueError("white_noise and quantization must be non-negative")
        if not float(self.saturation) > 0:
            raise ValueError(f"saturation must be positive, got {self.saturation!r}")
        if not float(self.gm_tau) > 0:
            raise ValueError(f"gm_tau must be positive, got {self.gm_tau!r}")
        m = finite_array(self.misalignment, "misalignment")
        if m.shape != (3, 3):
            raise ValueError(f"misalignment must have shape (3, 3), got {m.shape}")
        if np.any(np.diag(m) != 0):
            raise ValueError("misalignment must have a zero diagonal (use scale_factor)")
        for name in ("bias", "gm_sigma", "scale_factor"):
            _vec3(getattr(self, name), name)
        if np.any(_vec3(self.gm_sigma, "gm_sigma") < 0):
            raise ValueError("gm_sigma must be non-negative")

    @property
    def is_ideal(self) -> bool:
        return (
            self.white_noise == 0
            and not np.any(_vec3(self.bias, "bias"))
            and not np.any(_vec3(self.gm_sigma, "gm_sigma"))
            and not np.any(_vec3(self.scale_factor, "scale_factor"))
            and not np.any(self.misalignment)
            and self.quantization == 0
            and not np.isfinite(self.saturation)
        )

    def _gm(self, n, h, rng):
        sigma = _vec3(self.gm_sigma, "gm_sigma")
        if not np.any(sigma):
            return np.zeros((n, 3))
        phi = np.exp(-h / self.gm_tau)
        drive = sigma * np.sqrt(1.0 - phi * phi)
        b = np.empty((n, 3))
        x = sigma * rng.standard_normal(3)
        w = rng.standard_normal((n, 3)) * drive
        for k in range(n):  # a first-order recursion; n-length, cheap next to the algorithm
            b[k] = x
            x = phi * x + w[k]
        return b

    def apply(self, data: NDArray[np.float64], kind: InputKind, h: float, rng: RngLike
              ) -> NDArray[np.float64]:
        """Corrupt true increments or rates ``data`` (n, 3) sampled at interval ``h``."""
        rng = np.random.default_rng(rng)
        n = data.shape[0]
        mat = np.eye(3) + np.diag(_vec3(self.scale_factor, "scale_factor")) + self.misalignment
        scale = h if kind == "increment" else 1.0
        x = data + (_vec3(self.bias, "bias") + self._gm(n, h, rng)) * scale
        x = x @ mat.T
        if self.white_noise > 0:
            sd = self.white_noise * (np.sqrt(h) if kind == "increment" else 1.0 / np.sqrt(h))
            x = x + sd * rng.standard_normal((n, 3))
        lim = self.saturation * scale
        x = np.clip(x, -lim, lim)
        if self.quantization > 0:
            lsb = self.quantization
            if kind == "increment":
                acc = np.cumsum(x, axis=0)
                counts = np.floor(acc / lsb + 0.5)
                x = np.diff(np.vstack([np.zeros((1, 3)), counts]), axis=0) * lsb
            else:
                x = np.round(x / lsb) * lsb
        return x


def _edges(h, n, t0):
    h = positive(h, "h (sample interval)")
    n = positive_int(n, "n (samples)")
    t0 = float(finite_array(t0, "t0"))
    return h, n, t0 + np.arange(n + 1) * h


def increments(motion: Motion, h: float, n: int, *, t0: float = 0.0,
               errors: GyroErrors | None = None, rng: RngLike = None) -> GyroRecord:
    """``n`` angular increments over ``[t0 + k h, t0 + (k+1) h]`` (exact, then corrupted)."""
    h, n, edges = _edges(h, n, t0)
    theta = motion.increments(edges)
    if errors is not None and not errors.is_ideal:
        theta = errors.apply(theta, "increment", h, rng)
    return GyroRecord(edges, theta, "increment", h)


def rate_samples(motion: Motion, h: float, n: int, *, t0: float = 0.0,
                 errors: GyroErrors | None = None, rng: RngLike = None) -> GyroRecord:
    """``n`` rate samples at ``t0 + k h`` (k = 0 … n−1)."""
    h, n, edges = _edges(h, n, t0)
    t = edges[:-1]
    w = motion.rate(t)
    if errors is not None and not errors.is_ideal:
        w = errors.apply(w, "rate", h, rng)
    return GyroRecord(t, w, "rate", h)


def preaveraged_increments(motion: Motion, h: float, n: int, m: int, *, t0: float = 0.0,
                           errors: GyroErrors | None = None, rng: RngLike = None
                           ) -> GyroRecord:
    """Increments from ``m`` raw rate samples per interval, pre-averaged (Li & Zhang 2017 eq. 11).

    Raw rates are taken at the midpoints of the ``m`` sub-intervals of each
    ``h`` and corrupted at their own interval ``h/m``; the processed rate is
    their **mean** (eq. 11 prints a division by ``h``, which is dimensionally
    wrong; Li & Zhang (2017)), and the increment is ``h`` times it.
    """
    h, n, edges = _edges(h, n, t0)
    m = positive_int(m, "m (raw samples per interval)")
    sub = h / m
    t_raw = (edges[:-1, None] + (np.arange(m)[None, :] + 0.5) * sub).reshape(-1)
    w = motion.rate(t_raw)
    if errors is not None and not errors.is_ideal:
        w = errors.apply(w, "rate", sub, rng)
    theta = w.reshape(n, m, 3).mean(axis=1) * h
    return GyroRecord(edges, theta, "increment", h)


@dataclass(frozen=True)
class AccelerometerErrors:
    """Accelerometer error model (zero by default = ideal).

    ``f_meas = (I + diag(scale_factor)) (f + b) + vibration(t) + n`` with
    ``n`` white of density ``white_noise`` (m/s²/√Hz) and the vibration a sum
    of a sinusoid (``vibration_amplitude`` m/s² per axis at
    ``vibration_hz``, random phases) and white ``vibration_noise`` (m/s²
    per sample) switched on between ``vibration_start`` and ``vibration_stop``.
    """

    white_noise: float = 0.0
    bias: float | NDArray[np.float64] = 0.0
    scale_factor: float | NDArray[np.float64] = 0.0
    vibration_amplitude: float = 0.0
    vibration_hz: float = 30.0
    vibration_noise: float = 0.0
    vibration_start: float = 0.0
    vibration_stop: float = np.inf

    def __post_init__(self):
        for name in ("white_noise", "vibration_amplitude", "vibration_noise"):
            if not float(getattr(self, name)) >= 0:
                raise ValueError(f"{name} must be non-negative, got {getattr(self, name)!r}")
        positive(self.vibration_hz, "vibration_hz")
        for name in ("bias", "scale_factor"):
            _vec3(getattr(self, name), name)
        if not self.vibration_stop >= self.vibration_start:
            raise ValueError("vibration_stop must not precede vibration_start")

    def apply(self, t: ArrayLike, f: NDArray[np.float64], h: float, rng: RngLike
              ) -> NDArray[np.float64]:
        """Corrupt the true specific force ``f`` (n, 3) sampled at ``t`` every ``h`` s."""
        rng = np.random.default_rng(rng)
        t = np.asarray(t, float)
        n = f.shape[0]
        x = (f + _vec3(self.bias, "bias")) * (1.0 + _vec3(self.scale_factor, "scale_factor"))
        on = ((t >= self.vibration_start) & (t < self.vibration_stop))[:, None]
        phase = rng.uniform(0.0, 2.0 * np.pi, 3)
        vib = self.vibration_amplitude * np.sin(2 * np.pi * self.vibration_hz * t[:, None]
                                                + phase)
        vib = vib + self.vibration_noise * rng.standard_normal((n, 3))
        x = x + np.where(on, vib, 0.0)
        if self.white_noise > 0:
            x = x + self.white_noise / np.sqrt(h) * rng.standard_normal((n, 3))
        return x


@dataclass(frozen=True)
class MagnetometerErrors:
    """Magnetometer error model (zero by default = ideal).

    ``m_meas = S (m_b + anomaly_b) + hard_iron + n``: ``S = I + soft_iron`` (3, 3),
    ``hard_iron`` a constant body-frame offset, ``n`` white (per sample, same
    unit as the field), and a magnetic anomaly — a reference-frame field
    ``anomaly`` (3,) added between ``anomaly_start`` and ``anomaly_stop``.
    """

    white_noise: float = 0.0
    hard_iron: float | NDArray[np.float64] = 0.0
    soft_iron: NDArray[np.float64] = field(default_factory=lambda: np.zeros((3, 3)))
    anomaly: float | NDArray[np.float64] = 0.0
    anomaly_start: float = 0.0
    anomaly_stop: float = 0.0

    def __post_init__(self):
        if not float(self.white_noise) >= 0:
            raise ValueError(f"white_noise must be non-negative, got {self.white_noise!r}")
        s = finite_array(self.soft_iron, "soft_iron")
        if s.shape != (3, 3):
            raise ValueError(f"soft_iron must have shape (3, 3), got {s.shape}")
        _vec3(self.hard_iron, "hard_iron")
        _vec3(self.anomaly, "anomaly")

    def apply(self, t: ArrayLike, m_b: NDArray[np.float64], c_b_n: NDArray[np.float64],
              rng: RngLike) -> NDArray[np.float64]:
        """Corrupt the true body-frame field ``m_b`` (n, 3); ``c_b_n`` (n, 3, 3) rotates the
        anomaly into the body."""
        rng = np.random.default_rng(rng)
        t = np.asarray(t, float)
        on = ((t >= self.anomaly_start) & (t < self.anomaly_stop))[:, None]
        an = np.einsum("nij,j->ni", c_b_n, _vec3(self.anomaly, "anomaly"))
        x = (m_b + np.where(on, an, 0.0)) @ (np.eye(3) + np.asarray(self.soft_iron)).T
        x = x + _vec3(self.hard_iron, "hard_iron")
        if self.white_noise > 0:
            x = x + self.white_noise * rng.standard_normal(m_b.shape)
        return x


def accelerometer(t: ArrayLike, q_n_b: ArrayLike, specific_force: ArrayLike, h: float, *,
                  errors: AccelerometerErrors | None = None, rng: RngLike = None
                  ) -> NDArray[np.float64]:
    """Accelerometer samples (m/s²) of the true body specific force, corrupted if asked.

    ``q_n_b`` is accepted for symmetry with :func:`magnetometer` and unused.
    """
    f = np.asarray(specific_force, float)
    if errors is None:
        return f.copy()
    return errors.apply(t, f, positive(h, "h"), rng)


def magnetometer(t: ArrayLike, q_n_b: ArrayLike, field_n: ArrayLike, *,
                 errors: MagnetometerErrors | None = None, rng: RngLike = None
                 ) -> NDArray[np.float64]:
    """Magnetometer samples: the reference-frame field ``field_n`` (3,) seen in the body."""
    from strapdown.rotation.dcm import dcm_from_quat

    c_b_n = np.swapaxes(dcm_from_quat(q_n_b), -1, -2)
    m_b = np.einsum("nij,j->ni", c_b_n, np.asarray(field_n, float))
    if errors is None:
        return m_b
    return errors.apply(t, m_b, c_b_n, rng)
