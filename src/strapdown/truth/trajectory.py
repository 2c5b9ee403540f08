"""Vehicle trajectories for aided-attitude studies: straight legs and coordinated turns.

A :class:`CoordinatedFlight` is level flight at constant speed made of
segments — straight legs and constant-bank turns — with the bank rolled in
and out smoothly (``φ(s) = φ_turn (1 − cos(π s/τ))/2`` over the roll time
``τ``). Every instant is a coordinated turn: ``ψ̇ = −g tan φ / V``, so the
lateral specific force is zero. The heading and the horizontal position come
from adaptive ODE integration (rtol 1e-12); attitude, body rates and specific
force follow in closed form from them.

Frames: reference ENU (x east, y north, z up); body FLU (x forward, y left,
z up). Attitude ``C_n_b = Rz(ψ) Ry(−θ) Rx(φ)`` with heading ``ψ``
counter-clockwise from east, pitch ``θ`` nose up (0 here) and bank ``φ``
positive right wing down; a right turn (ψ decreasing) has positive bank.

:func:`wang_circle` builds Wang, Wang & Wang's scenario (60 s straight east, then a
circle, 250 s in all) in one of its three consistent readings — the paper's
600 m radius, 20 m/s and 20° bank cannot hold together:

- ``"speed-radius"``: 20 m/s on 600 m ⇒ bank 3.90°;
- ``"speed-bank"``: 20 m/s at 20° ⇒ radius 112.0 m;
- ``"radius-bank"``: 600 m at 20° ⇒ speed 46.3 m/s.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import positive

__all__ = [
    "WANG_VARIANTS",
    "CoordinatedFlight",
    "EarthField",
    "Segment",
    "VehicleState",
    "WangVariant",
    "wang_circle",
]

G = 9.80665
#: The consistent readings of Wang, Wang & Wang's loiter (see the module docstring).
WangVariant = Literal["speed-radius", "speed-bank", "radius-bank"]
#: Their names, in the order the module docstring lists them.
WANG_VARIANTS: tuple[WangVariant, ...] = get_args(WangVariant)


@dataclass(frozen=True)
class EarthField:
    """Local gravity and magnetic field.

    Parameters
    ----------
    intensity_uT : float
        Total field, µT. Default 50.
    inclination_deg : float
        Dip below the horizontal (positive in the northern hemisphere). Default 60.
    declination_deg : float
        Magnetic north east of true north. Default 0.
    gravity : float
        m/s².
    """

    intensity_uT: float = 50.0
    inclination_deg: float = 60.0
    declination_deg: float = 0.0
    gravity: float = G

    def magnetic_enu(self) -> NDArray[np.float64]:
        """The field vector in ENU, µT."""
        i = math.radians(self.inclination_deg)
        d = math.radians(self.declination_deg)
        h = self.intensity_uT * math.cos(i)
        return np.array([h * math.sin(d), h * math.cos(d), -self.intensity_uT * math.sin(i)])


@dataclass(frozen=True)
class Segment:
    """A straight leg (``bank_deg = 0``) or a constant-bank turn, ``duration`` s long."""

    duration: float
    bank_deg: float = 0.0


@dataclass(frozen=True)
class VehicleState:
    """Sampled trajectory (SI units, ENU reference, FLU body)."""

    t: NDArray[np.float64]
    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    q: NDArray[np.float64]
    omega: NDArray[np.float64]
    specific_force: NDArray[np.float64]
    heading: NDArray[np.float64]
    bank: NDArray[np.float64]


class CoordinatedFlight:
    """Level coordinated flight through a list of segments (see the module docstring).

    Parameters
    ----------
    segments : sequence of Segment
    speed : float
        m/s.
    altitude : float
        m (constant).
    heading0_deg : float
        Initial heading, counter-clockwise from east (0 = flying east).
    roll_time : float
        Time to roll into or out of a turn, s; taken from the start of each
        segment whose bank differs from the previous one.
    gravity : float
    """

    def __init__(self, segments: Iterable[Segment], *, speed: float, altitude: float = 0.0,
                 heading0_deg: float = 0.0, roll_time: float = 2.0, gravity: float = G) -> None:
        self.segments = tuple(segments)
        if not self.segments:
            raise ValueError("give at least one segment")
        for i, s in enumerate(self.segments):
            positive(s.duration, f"segment {i} duration")
            if not abs(s.bank_deg) < 89.0:
                raise ValueError(f"segment {i}: bank must be within ±89°, got {s.bank_deg}")
        self.speed = positive(speed, "speed")
        self.altitude = float(altitude)
        self.heading0 = math.radians(heading0_deg)
        self.roll_time = positive(roll_time, "roll_time")
        self.gravity = positive(gravity, "gravity")
        self.starts = np.concatenate([[0.0], np.cumsum([s.duration for s in self.segments])])
        for i in range(1, len(self.segments)):
            if (self.segments[i].bank_deg != self.segments[i - 1].bank_deg
                    and self.segments[i].duration < self.roll_time):
                raise ValueError(f"segment {i} is shorter than the roll time {self.roll_time} s")
        self._sol = None

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    def _bank(self, t):
        """Bank φ(t), φ̇(t), φ̈(t)."""
        t = np.asarray(t, float)
        phi = np.zeros_like(t)
        dphi = np.zeros_like(t)
        ddphi = np.zeros_like(t)
        prev = 0.0
        tau = self.roll_time
        for i, seg in enumerate(self.segments):
            b = math.radians(seg.bank_deg)
            lo, hi = self.starts[i], self.starts[i + 1]
            m = (t >= lo) & ((t < hi) | ((i == len(self.segments) - 1) & (t <= hi)))
            s = t[m] - lo
            if b == prev:
                phi[m] = b
            else:
                ramp = s < tau
                x = np.pi * np.minimum(s, tau) / tau
                phi[m] = np.where(ramp, prev + (b - prev) * (1 - np.cos(x)) / 2, b)
                dphi[m] = np.where(ramp, (b - prev) * np.pi / (2 * tau) * np.sin(x), 0.0)
                ddphi[m] = np.where(ramp, (b - prev) * (np.pi / tau) ** 2 / 2 * np.cos(x), 0.0)
            prev = b
        return phi, dphi, ddphi

    def _solve(self):
        if self._sol is None:
            from scipy.integrate import solve_ivp

            v, g = self.speed, self.gravity

            def rhs(t, y):
                phi = self._bank(np.array([t]))[0][0]
                psi = y[0]
                return [-g * math.tan(phi) / v, v * math.cos(psi), v * math.sin(psi)]

            # integrate segment by segment so the ramp kinks are grid points
            y0 = [self.heading0, 0.0, 0.0]
            sols = []
            for i in range(len(self.segments)):
                sol = solve_ivp(rhs, (self.starts[i], self.starts[i + 1]), y0, method="DOP853",
                                rtol=1e-12, atol=1e-12, dense_output=True)
                if not sol.success:  # pragma: no cover
                    raise RuntimeError(f"trajectory integration failed: {sol.message}")
                sols.append(sol)
                y0 = sol.y[:, -1]
            self._sol = sols
        return self._sol

    def sample(self, t: ArrayLike) -> VehicleState:
        """The trajectory at times ``t`` (s, within ``[0, duration]``)."""
        t = np.asarray(t, float)
        if t.ndim != 1 or t.size == 0:
            raise ValueError(f"t must be a non-empty 1-D array, got shape {t.shape}")
        if t.min() < 0 or t.max() > self.duration * (1 + 1e-12):
            raise ValueError(f"t must lie within [0, {self.duration}] s")
        sols = self._solve()
        y = np.empty((3, t.size))
        seg = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(sols) - 1)
        for i, sol in enumerate(sols):
            m = seg == i
            if np.any(m):
                y[:, m] = sol.sol(t[m])
        psi = y[0]
        phi, dphi, _ = self._bank(t)
        v, g = self.speed, self.gravity
        dpsi = -g * np.tan(phi) / v
        vel = np.column_stack([v * np.cos(psi), v * np.sin(psi), np.zeros_like(t)])
        acc = np.column_stack([-v * dpsi * np.sin(psi), v * dpsi * np.cos(psi),
                               np.zeros_like(t)])
        pos = np.column_stack([y[1], y[2], np.full_like(t, self.altitude)])
        # q = qz(ψ) ⊗ qx(φ)
        cz, sz = np.cos(psi / 2), np.sin(psi / 2)
        cx, sx = np.cos(phi / 2), np.sin(phi / 2)
        q = np.column_stack([cz * cx, cz * sx, sz * sx, sz * cx])
        omega = np.column_stack([dphi, dpsi * np.sin(phi), dpsi * np.cos(phi)])
        # f_b = C_b_n (a + g_up) = Rx(φ)ᵀ Rz(ψ)ᵀ (a + g_up)
        ah = np.column_stack([np.zeros_like(t), v * dpsi, np.full_like(t, g)])  # heading frame
        f = np.column_stack([ah[:, 0], np.cos(phi) * ah[:, 1] + np.sin(phi) * ah[:, 2],
                             -np.sin(phi) * ah[:, 1] + np.cos(phi) * ah[:, 2]])
        return VehicleState(t, pos, vel, acc, q, omega, f, psi, phi)


def wang_circle(variant: WangVariant = "speed-radius", *,
                roll_time: float = 2.0) -> CoordinatedFlight:
    """Wang, Wang & Wang's loiter scenario in a consistent reading (see the module docstring)."""
    if variant not in WANG_VARIANTS:
        raise ValueError(f"variant must be one of {', '.join(WANG_VARIANTS)}, got {variant!r}")
    speed, radius, bank = 20.0, 600.0, math.radians(20.0)
    if variant == "speed-radius":
        bank = math.atan(speed**2 / (radius * G))
    elif variant == "speed-bank":
        radius = speed**2 / (G * math.tan(bank))
    else:
        speed = math.sqrt(radius * G * math.tan(bank))
    del radius  # implied by speed and bank
    return CoordinatedFlight([Segment(60.0), Segment(190.0, math.degrees(bank))], speed=speed,
                             altitude=200.0, heading0_deg=0.0, roll_time=roll_time)
