"""Angular vibration with exact truth and a known cross-spectrum: pseudo-coning.

The attitude is ``q_n_b(t) = exp(v(t))`` with a rotation vector made of tones,
``v_i(t) = Σ_k b_ki sin(ω_k t + φ_ki)``, so the truth is exact at every time and the body
rate is ``ω_b = J_r(v) v̇`` (``J_r`` the right Jacobian of the exponential map); increments
come from Gauss–Legendre quadrature of the rate (:class:`~strapdown.truth.motions.UserMotion`).
To first order the body rates are ``v̇``, so tone ``k`` contributes the quadrature (coning)
power ``½ A_ki A_kj sin(φ_ki − φ_kj)`` (``A_ki = ω_k b_ki``) to the pair of axes
``(i, j)``: the line spectrum :meth:`ToneVibration.coning_power` that the spectral drift
prediction (:mod:`strapdown.analysis.spectrum`) is checked against (Ignagni (1996) treats
the same pseudo-coning as a sum of coning motions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import finite_array
from strapdown.truth.motions import UserMotion

__all__ = ["ToneVibration", "random_tone_vibration"]


@dataclass(frozen=True)
class ToneVibration:
    """Tones of a rotation-vector vibration ``v_i = Σ_k b_ki sin(ω_k t + φ_ki)``.

    Attributes
    ----------
    omega : ndarray (K,)
        Tone frequencies (rad/s).
    amplitude : ndarray (K, 3)
        Rotation-vector amplitudes ``b_ki`` (rad).
    phase : ndarray (K, 3)
        Phases ``φ_ki`` (rad).
    """

    omega: NDArray[np.float64]
    amplitude: NDArray[np.float64]
    phase: NDArray[np.float64]

    def __post_init__(self) -> None:
        w = finite_array(self.omega, "omega")
        if w.ndim != 1 or np.any(w <= 0):
            raise ValueError("omega must be a 1-D array of positive frequencies (rad/s)")
        for name in ("amplitude", "phase"):
            if np.shape(getattr(self, name)) != (w.size, 3):
                raise ValueError(f"{name} must have shape ({w.size}, 3)")

    def rotation_vector(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``v(t)`` and ``v̇(t)``, shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)[..., None, None]
        arg = self.omega[:, None] * t + self.phase
        v = np.sum(self.amplitude * np.sin(arg), axis=-2)
        vd = np.sum(self.amplitude * self.omega[:, None] * np.cos(arg), axis=-2)
        return v, vd

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        v, _ = self.rotation_vector(t)
        ang = np.linalg.norm(v, axis=-1, keepdims=True)
        s = np.where(ang > 0, np.sin(ang / 2) / np.where(ang > 0, ang, 1.0), 0.5)
        return np.concatenate([np.cos(ang / 2), s * v], axis=-1)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        v, vd = self.rotation_vector(t)
        th = np.linalg.norm(v, axis=-1, keepdims=True)
        small = th < 1e-4
        th2 = np.where(small, 1.0, th * th)
        c1 = np.where(small, 0.5 - th**2 / 24, (1 - np.cos(th)) / th2)
        c2 = np.where(small, 1 / 6 - th**2 / 120,
                      (th - np.sin(th)) / (np.where(small, 1.0, th) * th2))
        vxv = np.cross(v, vd)
        return vd - c1 * vxv + c2 * np.cross(v, vxv)  # J_r(v) v̇

    def motion(self) -> UserMotion:
        """The motion (exact attitude and rate; increments by quadrature)."""
        return UserMotion(self.attitude, self.rate)

    def coning_power(self) -> NDArray[np.float64]:
        """Quadrature power per tone and axis pair, shape (K, 3): columns (y, z), (z, x),
        (x, y), i.e. the power that cones about x, y and z (rad²/s²)."""
        a = self.amplitude * self.omega[:, None]
        out = np.empty((self.omega.size, 3))
        for col, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):
            out[:, col] = 0.5 * a[:, i] * a[:, j] * np.sin(self.phase[:, i] - self.phase[:, j])
        return out


def random_tone_vibration(band_hz: tuple[float, float], tones: int, amplitude: ArrayLike,
                          relative_phase: ArrayLike, rng: np.random.Generator
                          ) -> ToneVibration:
    """Tones evenly spread over ``band_hz`` with random common phases.

    ``amplitude`` (3,) is each axis's rotation-vector amplitude per tone (rad) and
    ``relative_phase`` (3,) each axis's phase offset (rad): the chosen cross-spectrum. Only
    the common phase of each tone is drawn from ``rng``.
    """
    lo, hi = (float(b) for b in band_hz)
    if not 0 < lo < hi or tones < 1:
        raise ValueError(f"band_hz must be 0 < lo < hi and tones ≥ 1, got {band_hz}, {tones}")
    f = np.linspace(lo, hi, tones)
    amp = np.broadcast_to(finite_array(amplitude, "amplitude"), (tones, 3)).copy()
    rel = np.broadcast_to(finite_array(relative_phase, "relative_phase"), (tones, 3))
    phase = rng.uniform(0, 2 * np.pi, size=(tones, 1)) + rel
    return ToneVibration(2 * np.pi * f, amp, phase)
