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

import itertools
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
    "EarthFlight",
    "EarthSegment",
    "EarthState",
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


# ------------------------------------------------------------ Earth-referenced trajectories
@dataclass(frozen=True)
class EarthSegment:
    """One leg of an :class:`EarthFlight`: ``duration`` s, heading rate ``turn_rate_dps``
    (°/s, positive clockwise seen from above) and flight-path angle ``climb_deg`` (°, nose
    up), each reached over the flight's ramp time from the previous leg's value."""

    duration: float
    turn_rate_dps: float = 0.0
    climb_deg: float = 0.0


@dataclass(frozen=True)
class EarthState:
    """Truth of an :class:`EarthFlight` at times ``t``: latitude, longitude (rad), height
    (m), NED velocity (m/s) and ``q_n_b`` (NED navigation frame, FRD body)."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    q: np.ndarray


#: The smooth ramp's first RAMP_SMOOTHNESS derivatives vanish at its ends: enough for the
#: orders the navigation algorithms reach (C-infinity is not needed).
RAMP_SMOOTHNESS = 8


def _smoothstep(x, k: int = RAMP_SMOOTHNESS):
    """``S, S', S''`` and ``∫_0^x S`` of the smoothstep of degree 2k + 1 on [0, 1]:
    ``S' = c (x(1 − x))^k``, ``c = (2k+1)!/(k!)²``, so that S rises from 0 to 1 with its
    first k derivatives zero at both ends. Evaluated in ``y = 2x − 1``, where
    ``x(1 − x) = (1 − y²)/4`` and the sums are short and well conditioned (the power basis
    in x loses ~1e-10 to cancellation)."""
    c = math.factorial(2 * k + 1) / math.factorial(k) ** 2 / 4.0**k
    y = 2.0 * x - 1.0
    u = 1.0 - y * y
    s = 0.5 + 0.5 * c * sum(math.comb(k, j) * (-1) ** j * y ** (2 * j + 1) / (2 * j + 1)
                            for j in range(k + 1))
    integral = 0.5 * x + 0.25 * c * sum(
        math.comb(k, j) * (-1) ** j * (y ** (2 * j + 2) - 1.0) / ((2 * j + 1) * (2 * j + 2))
        for j in range(k + 1))
    return s, c * u**k, -4.0 * c * k * y * u ** (k - 1), integral


def _ramp(s, tau, a, b, shape="smooth"):
    """Value, rate, acceleration and integral of ``a → b`` over ``τ``: ``(1 − cos(π s/τ))/2``
    (``shape="cosine"``, its second derivative jumps at the ends) or the smoothstep ``S``
    (``"smooth"``, :data:`RAMP_SMOOTHNESS` derivatives continuous)."""
    s = np.asarray(s, dtype=np.float64)
    on = s < tau
    if shape == "cosine":
        x = np.pi * np.minimum(s, tau) / tau
        val = np.where(on, a + (b - a) * (1 - np.cos(x)) / 2, b)
        rate = np.where(on, (b - a) * np.pi / (2 * tau) * np.sin(x), 0.0)
        acc = np.where(on, (b - a) * (np.pi / tau) ** 2 / 2 * np.cos(x), 0.0)
        ramp_int = a * np.minimum(s, tau) + (b - a) / 2 * (np.minimum(s, tau)
                                                           - tau / np.pi * np.sin(x))
    else:
        sv, s1, s2, si = _smoothstep(np.minimum(s, tau) / tau)
        val = np.where(on, a + (b - a) * sv, b)
        rate = np.where(on, (b - a) / tau * s1, 0.0)
        acc = np.where(on, (b - a) / tau**2 * s2, 0.0)
        ramp_int = a * np.minimum(s, tau) + (b - a) * tau * si
    integral = ramp_int + b * np.maximum(s - tau, 0.0)
    return val, rate, acc, integral


#: Position solutions of flights already solved in this process, by their defining
#: parameters (:meth:`EarthFlight._key`): tests and reports build equal flights many times
#: (a 10-minute flight's quadrature takes ~50 ms; the DOP853 integration it replaced took
#: ~110 s). At most :data:`_EARTH_FLIGHT_CACHE` are kept.
_EARTH_FLIGHT_SOLUTIONS: dict[tuple, tuple] = {}
_EARTH_FLIGHT_CACHE = 8


class EarthFlight:
    """A flight over the WGS-84 Earth: legs of constant speed with smooth turns and climbs.

    The heading rate and the flight-path angle ramp between legs over ``ramp`` s, by the
    smoothstep polynomial of degree 17 (``ramp_shape="smooth"``, the default: its first
    :data:`RAMP_SMOOTHNESS` derivatives vanish at the ramp's ends, so the body rates and
    specific force have no kink a navigation algorithm of order ≤ 8 could see) or by
    ``(1 − cos(π s/τ))/2`` (``"cosine"``, the shape before: its second derivative jumps at
    the ends, a kink in the body rates that caps the navigation error's order at two);
    the body banks as in a coordinated turn (``tan φ = V ψ̇ / g0``) and pitches with the
    flight path (``θ = γ``); ``C_n_b = Rz(ψ) Ry(θ) Rx(φ)`` (NED, z-y-x). Heading, attitude,
    velocity and their rates are closed forms; latitude, longitude and height are their
    displacement from the start (so that the error bounds it, not the latitude: 1e-14 of
    10 km rather than of 0.8 rad), ``L̇ = v_N/(R_N + h)``, ``λ̇ = v_E/((R_E + h) cos L)``,
    ``ḣ = −v_D``, by spectral quadrature of the closed-form velocity on pieces between the
    legs' starts and the ramps' ends (a Picard iteration for L, whose rate depends on it
    only through ``R_N``; see :func:`_position_quadrature`): within ~1e-13 of the
    displacement of the adaptive integration used before (DOP853, rtol 1e-13, atol 1e-18,
    :class:`_OdeDisplacement`), which a test holds. Ideal gyro and accelerometer increments
    are Gauss–Legendre quadratures (12 nodes per interval) of
    ``ω_ib = ω_nb + C_b_n (ω_ie + ω_en)`` and ``f_b = C_b_n (v̇ + (2ω_ie + ω_en) × v − γ)``
    with the normal gravity of :mod:`strapdown.truth.earth`. ``speed = 0`` is a static
    vehicle.
    """

    def __init__(self, segments, *, lat_deg: float, lon_deg: float = 0.0, height: float = 0.0,
                 speed: float = 0.0, heading_deg: float = 0.0, ramp: float = 5.0,
                 ramp_shape: Literal["smooth", "cosine"] = "smooth"):
        self.segments = tuple(segments)
        if not self.segments:
            raise ValueError("give at least one segment")
        if not (math.isfinite(lat_deg) and abs(lat_deg) < 89.0):
            raise ValueError(f"latitude must be finite and within ±89°, got {lat_deg}")
        for i, s in enumerate(self.segments):
            positive(s.duration, f"segment {i} duration")
            if not abs(s.climb_deg) < 60.0:
                raise ValueError(f"segment {i}: climb angle must be within ±60°")
        self.lat0, self.lon0 = math.radians(lat_deg), math.radians(lon_deg)
        self.h0 = float(height)
        if not (math.isfinite(speed) and speed >= 0):
            raise ValueError(f"speed must be finite and non-negative, got {speed}")
        self.speed = float(speed)
        self.heading0 = math.radians(heading_deg)
        self.ramp = positive(ramp, "ramp")
        if ramp_shape not in ("smooth", "cosine"):
            raise ValueError(f"ramp_shape must be 'smooth' or 'cosine', got {ramp_shape!r}")
        self.ramp_shape = ramp_shape
        self.starts = np.concatenate([[0.0], np.cumsum([s.duration for s in self.segments])])
        self._sol = None

    @property
    def duration(self) -> float:
        return float(self.starts[-1])

    def _profiles(self, t):
        """ψ, ψ̇, ψ̈, γ, γ̇, γ̈ at times ``t``."""
        t = np.asarray(t, dtype=np.float64)
        out = [np.zeros_like(t) for _ in range(6)]
        psi0, r_prev, g_prev = self.heading0, 0.0, 0.0
        seg = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0,
                      len(self.segments) - 1)
        for i, s in enumerate(self.segments):
            r, g = math.radians(s.turn_rate_dps), math.radians(s.climb_deg)
            m = seg == i
            ds = t[m] - self.starts[i]
            rv, ra, _, ri = _ramp(ds, self.ramp, r_prev, r, self.ramp_shape)
            gv, gr, ga, _ = _ramp(ds, self.ramp, g_prev, g, self.ramp_shape)
            for arr, val in zip(out, (psi0 + ri, rv, ra, gv, gr, ga), strict=True):
                arr[m] = val
            psi0 += float(_ramp(s.duration, self.ramp, r_prev, r, self.ramp_shape)[3])
            r_prev, g_prev = r, g
        return out

    def _velocity(self, t):
        psi, dpsi, _, gam, dgam, _ = self._profiles(t)
        v = self.speed
        cg, sg, cp, sp_ = np.cos(gam), np.sin(gam), np.cos(psi), np.sin(psi)
        vel = v * np.stack([cg * cp, cg * sp_, -sg], axis=-1)
        acc = v * (dgam[..., None] * np.stack([-sg * cp, -sg * sp_, -cg], axis=-1)
                   + dpsi[..., None] * np.stack([-cg * sp_, cg * cp, 0 * cg], axis=-1))
        return vel, acc

    def _euler(self, t):
        """(ψ, θ, φ) and their rates."""
        psi, dpsi, ddpsi, gam, dgam, _ = self._profiles(t)
        k = self.speed / G
        phi = np.arctan(k * dpsi)
        dphi = k * ddpsi / (1.0 + (k * dpsi) ** 2)
        return (psi, gam, phi), (dpsi, dgam, dphi)

    def _key(self) -> tuple:
        """What the position integration depends on (a flight's defining parameters)."""
        return (self.segments, self.lat0, self.lon0, self.h0, self.speed, self.heading0,
                self.ramp, self.ramp_shape)

    def _solve(self):
        if self._sol is None and self._key() in _EARTH_FLIGHT_SOLUTIONS:
            # an equal flight was solved in this process: its solution is immutable
            self._sol = _EARTH_FLIGHT_SOLUTIONS[self._key()]
        if self._sol is None:
            self._sol = _position_quadrature(self)
            while len(_EARTH_FLIGHT_SOLUTIONS) >= _EARTH_FLIGHT_CACHE:  # oldest out
                _EARTH_FLIGHT_SOLUTIONS.pop(next(iter(_EARTH_FLIGHT_SOLUTIONS)))
            _EARTH_FLIGHT_SOLUTIONS[self._key()] = self._sol
        return self._sol

    def _knots(self) -> NDArray[np.float64]:
        """The legs' starts and their ramps' ends: the manoeuvre's kinks."""
        return np.unique(np.concatenate([self.starts, np.minimum(
            self.starts[:-1] + self.ramp, self.starts[1:])]))

    def _position(self, t):
        t = np.asarray(t, dtype=np.float64)
        y = self._solve().displacement(t.ravel())
        y += np.array([self.lat0, self.lon0, self.h0])[:, None]
        return tuple(c.reshape(t.shape) for c in y)

    def state(self, t) -> EarthState:
        """Truth at times ``t`` (s, within ``[0, duration]``)."""
        t = np.asarray(t, dtype=np.float64)
        if t.ndim != 1 or t.size == 0 or t.min() < 0 or t.max() > self.duration * (1 + 1e-12):
            raise ValueError(f"t must be a non-empty 1-D array within [0, {self.duration}] s")
        lat, lon, hgt = self._position(t)
        (psi, th, phi), _ = self._euler(t)
        return EarthState(t, lat, lon, hgt, self._velocity(t)[0], _q_zyx(psi, th, phi))

    def _body(self, t):
        """ω_ib^b and f_b at times ``t`` (any shape)."""
        from strapdown.truth.earth import earth_rate, gravity, transport_rate

        lat, _, hgt = self._position(t)
        (psi, th, phi), (dpsi, dth, dphi) = self._euler(t)
        vel, acc = self._velocity(t)
        c_nb = _dcm_zyx(psi, th, phi)
        wie = earth_rate(lat)
        win = wie + transport_rate(lat, hgt, vel)
        sth, cth, sph, cph = np.sin(th), np.cos(th), np.sin(phi), np.cos(phi)
        w_nb = np.stack([dphi - dpsi * sth, dth * cph + dpsi * sph * cth,
                         -dth * sph + dpsi * cph * cth], axis=-1)
        g = np.zeros_like(vel)
        g[..., 2] = gravity(lat, hgt)
        f_n = acc + np.cross(wie + win, vel) - g
        w_ib = w_nb + np.einsum("...ji,...j->...i", c_nb, win)
        return w_ib, np.einsum("...ji,...j->...i", c_nb, f_n)

    def sensed(self, t) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Ideal gyro rate ``ω_ib`` (rad/s) and specific force ``f_b`` (m/s²) in the body
        frame at times ``t`` (any shape, s): the samples of a rate log."""
        return self._body(np.asarray(t, dtype=np.float64))

    def increments(self, edges):
        """Ideal gyro (rad) and accelerometer (m/s) increments over consecutive ``edges``."""
        from strapdown._core.validation import as_times

        edges = as_times(edges, "edges", min_len=2)
        x, w = np.polynomial.legendre.leggauss(12)
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
        out_g, out_a = [], []
        for lo in range(0, mid.size, 20000):  # bounded memory
            sl = slice(lo, lo + 20000)
            nodes = mid[sl, None] + half[sl, None] * x[None, :]
            wb, fb = self._body(nodes)
            out_g.append(half[sl, None] * np.einsum("k,nkj->nj", w, wb))
            out_a.append(half[sl, None] * np.einsum("k,nkj->nj", w, fb))
        return np.concatenate(out_g), np.concatenate(out_a)


#: Chebyshev nodes per piece of the position quadrature and the longest piece (s); the
#: pieces are halved until the velocity's last two Chebyshev coefficients on every piece are
#: below :data:`_QUAD_TAIL` of the speed (rounding leaves ~5e-16 of it; a 10-minute flight's
#: coefficients reach that floor by the tenth).
_QUAD_NODES = 32
_QUAD_PIECE = 4.0
_QUAD_TAIL = 1e-14


@dataclass(frozen=True)
class _Displacement:
    """Piecewise-Chebyshev displacement ``(ΔL, Δλ, Δh)`` from a flight's start: on piece
    ``k`` (``edges[k]`` to ``edges[k + 1]``) ``start[k] + Σ_j coef[k, j] T_j(x)``,
    ``x ∈ [−1, 1]``."""

    edges: NDArray[np.float64]
    start: NDArray[np.float64]  # (K, 3)
    coef: NDArray[np.float64]  # (K, n, 3)

    def displacement(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """``(3, t.size)`` at the 1-D times ``t``."""
        k = np.clip(np.searchsorted(self.edges, t, side="right") - 1, 0, self.start.shape[0] - 1)
        lo, hi = self.edges[k], self.edges[k + 1]
        x = ((2.0 * (t - lo) / (hi - lo)) - 1.0)[:, None]
        b1 = np.zeros((t.size, 3))
        b2 = np.zeros((t.size, 3))
        for j in range(self.coef.shape[1] - 1, 0, -1):  # Clenshaw
            b1, b2 = self.coef[k, j] + 2.0 * x * b1 - b2, b1
        return (self.start[k] + self.coef[k, 0] + x * b1 - b2).T


def _chebyshev_integration(n: int):
    """Chebyshev points of the first kind ``x`` (n), and the matrices taking an integrand's
    values there to the Chebyshev coefficients (n + 1) of its integral from −1 (over a
    piece of length 2), and those coefficients to the integral's values at ``x``."""
    from numpy.polynomial import chebyshev as C

    x = np.cos(np.pi * (np.arange(n) + 0.5) / n)[::-1]
    to_coef = np.linalg.inv(C.chebvander(x, n - 1))
    integ = C.chebint(np.eye(n), lbnd=-1.0, axis=0)  # (n + 1, n)
    return x, to_coef, integ @ to_coef, C.chebvander(x, n)


def _position_quadrature(fl: EarthFlight) -> _Displacement:
    """Latitude, longitude and height of ``fl`` from its closed-form velocity:
    ``Δh = −∫ v_D``, ``ΔL = ∫ v_N/(R_N(L) + h)`` (a Picard iteration over the whole flight,
    which contracts by ~|∂_L(v_N/R_N)| · duration ≈ 1e-4 per sweep for a 10-minute flight),
    ``Δλ = ∫ v_E/((R_E(L) + h) cos L)``, each by spectral (Chebyshev) quadrature on pieces
    of at most :data:`_QUAD_PIECE` s between the manoeuvre's kinks, exact to rounding for
    the integrands' polynomial part of degree < :data:`_QUAD_NODES` (their coefficients are
    checked to have decayed below :data:`_QUAD_TAIL`)."""
    from strapdown.truth.earth import radii

    n = _QUAD_NODES
    x, to_coef, integ, vander = _chebyshev_integration(n)
    knots = fl._knots()
    longest = _QUAD_PIECE
    for _ in range(12):
        counts = np.maximum(np.ceil(np.diff(knots) / longest - 1e-9).astype(int), 1)
        edges = np.concatenate([np.linspace(a, b, c + 1)[:-1] for a, b, c in
                                zip(knots[:-1], knots[1:], counts, strict=True)] + [knots[-1:]])
        half = 0.5 * np.diff(edges)
        mid = 0.5 * (edges[1:] + edges[:-1])
        vel = fl._velocity(mid[:, None] + half[:, None] * x[None, :])[0]  # (K, n, 3)
        coef = np.einsum("jn,kni->kji", to_coef, vel)
        if np.max(np.abs(coef[:, -2:]), initial=0.0) <= _QUAD_TAIL * fl.speed:
            break
        longest /= 2.0
    else:  # pragma: no cover
        raise RuntimeError("position quadrature: the velocity is not resolved")

    def integral(f):
        """Coefficients of the integral over each piece, and the displacement at its
        start (the pieces' integrals summed in order)."""
        c = half[:, None] * np.einsum("jn,kn->kj", integ, f)  # (K, n + 1); T_j(1) = 1
        return c, np.concatenate([[0.0], np.cumsum(c.sum(axis=1))[:-1]])

    def at_nodes(c, start):
        return start[:, None] + np.einsum("nj,kj->kn", vander, c)

    ch, sh = integral(-vel[..., 2])
    dh = at_nodes(ch, sh)
    dlat, change = np.zeros_like(dh), math.inf
    for _ in range(60):  # until the sweeps change nothing but rounding
        rn, _ = radii(fl.lat0 + dlat, fl.h0 + dh)
        cl, sl = integral(vel[..., 0] / rn)
        new = at_nodes(cl, sl)
        last, change = change, float(np.max(np.abs(new - dlat), initial=0.0))
        dlat = new
        if change <= 1e-15 * float(np.max(np.abs(dlat), initial=0.0)) or change >= last:
            break
    else:  # pragma: no cover
        raise RuntimeError("position quadrature: the latitude iteration did not converge")
    lat = fl.lat0 + dlat
    _, re = radii(lat, fl.h0 + dh)
    cn, sn = integral(vel[..., 1] / (re * np.cos(lat)))
    return _Displacement(edges, np.stack([sl, sn, sh], axis=-1),
                         np.stack([cl, cn, ch], axis=-1))


class _OdeDisplacement:
    """The position integration before the quadrature, kept to test it against: DOP853 at
    rtol 1e-13, atol 1e-18 of the displacement ``(ΔL, Δλ, Δh)`` with the closed-form
    velocity on the right-hand side, in pieces between the manoeuvre's kinks (a 10-minute
    flight takes about 110 s)."""

    def __init__(self, fl: EarthFlight):
        from scipy.integrate import solve_ivp

        from strapdown.truth.earth import radii

        lat0, h0 = fl.lat0, fl.h0

        def rhs(t, y):
            v = fl._velocity(np.array([t]))[0][0]
            rn, re = radii(lat0 + y[0], h0 + y[2])
            return [v[0] / rn, v[1] / (re * np.cos(lat0 + y[0])), -v[2]]

        self.knots = fl._knots()
        y0, self.sols = [0.0, 0.0, 0.0], []
        for lo, hi in itertools.pairwise(self.knots):
            sol = solve_ivp(rhs, (lo, hi), y0, method="DOP853", rtol=1e-13, atol=1e-18,
                            dense_output=True)
            if not sol.success:  # pragma: no cover
                raise RuntimeError(f"trajectory integration failed: {sol.message}")
            self.sols.append(sol)
            y0 = sol.y[:, -1]

    def displacement(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        y = np.empty((3, t.size))
        seg = np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, len(self.sols) - 1)
        for i, sol in enumerate(self.sols):
            m = seg == i
            if np.any(m):
                y[:, m] = sol.sol(t[m])
        return y


def _dcm_zyx(psi, th, phi):
    """``C_n_b = Rz(ψ) Ry(θ) Rx(φ)``, shape ``(..., 3, 3)``."""
    cps, sps, cth, sth, cph, sph = (np.cos(psi), np.sin(psi), np.cos(th), np.sin(th),
                                    np.cos(phi), np.sin(phi))
    return np.stack([
        np.stack([cps * cth, cps * sth * sph - sps * cph, cps * sth * cph + sps * sph], -1),
        np.stack([sps * cth, sps * sth * sph + cps * cph, sps * sth * cph - cps * sph], -1),
        np.stack([-sth, cth * sph, cth * cph], -1)], -2)


def _q_zyx(psi, th, phi):
    """``q_n_b = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)``."""
    c1, s1, c2, s2, c3, s3 = (np.cos(psi / 2), np.sin(psi / 2), np.cos(th / 2), np.sin(th / 2),
                              np.cos(phi / 2), np.sin(phi / 2))
    return np.stack([c1 * c2 * c3 + s1 * s2 * s3, c1 * c2 * s3 - s1 * s2 * c3,
                     c1 * s2 * c3 + s1 * c2 * s3, s1 * c2 * c3 - c1 * s2 * s3], axis=-1)
