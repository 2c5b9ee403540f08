"""Sculling motions with exact truth: gyro and accelerometer increments, navigation-frame
velocity and position, in float64 and in arbitrary precision.

:class:`ScullingMotion` is an angular oscillation ``θ0 sin Ωt`` about the body x axis in
phase (``ψ``) with a linear vibration ``A sin(Ωt + ψ)`` along the body y axis — classical
sculling (Savage (1998b); Ignagni (1998)) — optionally on a body that also spins about x
at ``ω_s`` and cones (half angle ``a``, cone rate ``Ω_c``, as
:class:`~strapdown.truth.motions.ClassicalConing`):

.. math::  q_{n b}(t) = q_{cone}(t) ⊗ q_x(χ(t)),\\qquad χ(t) = ω_s t + θ_0 \\sin Ωt,

    f_b(t) = (0,\\ A \\sin(Ωt + ψ),\\ 0)  \\quad\\text{(specific force, no gravity)}.

The navigation frame is inertial (no gravity, no Earth rate): ``v̇_n = C_n_b f_b``,
``ṗ_n = v_n``, ``v_n(0) = p_n(0) = 0``.

Exact sums
----------
With body y–z components written as complex numbers ``y + iz``, every quantity is a
finite or rapidly convergent sum of complex exponentials ``Σ c_j e^{iλ_j t}``: the
Jacobi–Anger expansion ``e^{iθ0 sin Ωt} = Σ_k J_k(θ0) e^{ikΩt}`` turns the oscillating
attitude into exponentials, Rodrigues' formula rotates them by the cone, and each term
integrates once (velocity) or twice (position) in closed form. The series is summed
until ``|J_k(θ0)|`` falls below the working precision (float64: 1e-20; mpmath:
``10^-(dps+5)``), so the truth is exact to round-off. The gyro increments about x and
the accelerometer increments are elementary closed forms.

With ``a = 0`` and ``ω_s = 0`` (classical sculling) the rectified velocity is along the
navigation z axis: ``v̇_z`` has the mean ``A J1(θ0) cos ψ`` (≈ ½ θ0 A cos ψ).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np

from strapdown._core.backend import MPMATH, NUMPY, Backend
from strapdown._core.validation import as_times, finite_array
from strapdown.truth.motions import _ClosedForm, _int_cos, _int_sin

__all__ = ["ExpSum", "ScullingMotion", "classical_sculling"]

#: Bessel terms below this magnitude are dropped in float64.
_F64_TOL = 1e-20


@dataclass(frozen=True)
class ExpSum:
    """``s(t) = Σ_j c_j e^{iλ_j t}`` (complex amplitudes ``c``, real frequencies ``λ``).

    One arithmetic throughout: Python complex / numpy values or mpmath numbers.
    """

    terms: tuple[tuple[Any, Any], ...]

    def scale(self, s) -> ExpSum:
        return ExpSum(tuple((s * c, lam) for c, lam in self.terms))

    def shift(self, nu) -> ExpSum:
        """Multiply by ``e^{iνt}``."""
        return ExpSum(tuple((c, lam + nu) for c, lam in self.terms))

    def conj(self) -> ExpSum:
        return ExpSum(tuple((_conj(c), -lam) for c, lam in self.terms))

    def __add__(self, other: ExpSum) -> ExpSum:
        return ExpSum(self.terms + other.terms)

    def real(self) -> ExpSum:
        """``Re s`` as an exponential sum (``(s + s̄)/2``)."""
        return (self + self.conj()).scale(0.5)

    def imag(self) -> ExpSum:
        """``Im s`` as an exponential sum (``(s − s̄)/(2i)``)."""
        return (self + self.conj().scale(-1)).scale(-0.5j)

    # ------------------------------------------------------------------ evaluation
    def value(self, m: Backend, t):
        """``s(t)``."""
        return _sum(m, ((c, _cis(m, lam, t)) for c, lam in self.terms), t)

    def integral(self, m: Backend, t0, dt):
        """``∫_{t0}^{t0+dt} s`` (anchored at ``t0``: no cancellation for small ``dt``)."""
        return _sum(m, ((c * dt, _cis(m, lam, t0) * _g1(m, lam * dt)) for c, lam in self.terms),
                    t0)

    def double_integral(self, m: Backend, t):
        """``∫_0^t ∫_0^s s(u) du ds``."""
        return _sum(m, ((c * t * t, _g2(m, lam * t)) for c, lam in self.terms), t)


def _conj(c):
    return c.conjugate() if hasattr(c, "conjugate") else mpmath.conj(c)


def _sum(m: Backend, pairs, t):
    out = m.zero * t
    for a, b in pairs:
        out = out + a * b
    return out


def _cis(m: Backend, lam, t):
    """``e^{iλt}`` with the exact-product phase of the back-end."""
    if m is MPMATH:
        return mpmath.expj(lam * t)
    return m.cos_lin(lam, t) + 1j * m.sin_lin(lam, t)


def _g1(m: Backend, y):
    """``(e^{iy} − 1)/(iy)`` = ``e^{iy/2} sinc(y/2)``, 1 at 0."""
    return _cis(m, 0.5, y) * m.sinc(y / 2)


def _g2(m: Backend, y):
    """``(e^{iy} − 1 − iy)/(iy)²`` = ``Σ_n (iy)^n/(n+2)!``, ½ at 0 (series for |y| < 1)."""
    if m is MPMATH:
        if abs(y) >= 1:
            return (mpmath.expj(y) - 1 - 1j * y) / (-(y * y))
        term, out, n = mpmath.mpf(1) / 2, mpmath.mpc(0), 0
        eps = mpmath.mpf(10) ** (-mpmath.mp.dps - 5)
        while abs(term) > eps:
            out += term
            n += 1
            term = term * 1j * y / (n + 2)
        return out
    y = np.asarray(y, dtype=np.float64)
    small = np.abs(y) < 1.0
    ys = np.where(small, 1.0, y)
    direct = (np.cos(ys) - 1.0 + 1j * (np.sin(ys) - ys)) / (-(ys * ys))
    series = np.zeros_like(y, dtype=complex)
    term = np.full(y.shape, 0.5, dtype=complex)
    for n in range(1, 22):  # |y| < 1: the omitted term is below 1/24! < 2e-24
        series = series + term
        term = term * 1j * y / (n + 2)
    return np.where(small, series, direct)


@dataclass(frozen=True)
class ScullingMotion(_ClosedForm):
    """Sculling (angular ``θ0 sin Ωt`` about body x, linear ``A sin(Ωt + ψ)`` along body y),
    optionally with spin ``ω_s`` about body x and coning (``a``, ``Ω_c``); see the module
    docstring for the formulas (Savage (1998b); Ignagni (1998)).

    Parameters
    ----------
    angle_amplitude : float
        θ0 (rad).
    frequency : float
        Ω (rad/s) of both vibrations; non-zero.
    accel_amplitude : float
        A (m/s²).
    phase : float
        ψ (rad): the linear vibration leads the angular one by ψ.
    half_angle, cone_rate : float
        Coning half angle ``a`` (rad) and cone rate ``Ω_c`` (rad/s); ``a = 0`` is no cone.
    spin_rate : float
        ω_s (rad/s).
    """

    angle_amplitude: float
    frequency: float
    accel_amplitude: float
    phase: float = 0.0
    half_angle: float = 0.0
    cone_rate: float = 0.0
    spin_rate: float = 0.0

    def __post_init__(self):
        finite_array([self.angle_amplitude, self.frequency, self.accel_amplitude, self.phase,
                      self.half_angle, self.cone_rate, self.spin_rate], "sculling parameters")
        if float(self.frequency) == 0.0:
            raise ValueError("sculling frequency must be non-zero")
        if float(self.half_angle) != 0.0 and float(self.cone_rate) == 0.0:
            raise ValueError("a cone (half_angle ≠ 0) needs a non-zero cone_rate")

    @property
    def period(self) -> float | None:  # type: ignore[override]
        if float(self.half_angle) == 0.0 and float(self.spin_rate) == 0.0:
            return 2.0 * math.pi / abs(float(self.frequency))
        return None

    # ------------------------------------------------------------------ parameters
    def _p(self, m: Backend):
        return tuple(m.num(v) for v in (self.angle_amplitude, self.frequency,
                                        self.accel_amplitude, self.phase, self.half_angle,
                                        self.cone_rate, self.spin_rate))

    def _bessel(self, m: Backend):
        """``[(k, J_k(θ0))]`` for every k whose term is above the working precision."""
        if m is MPMATH:
            return _mp_bessel(float(self.angle_amplitude), mpmath.mp.dps)
        from scipy.special import jv

        return _bessel_terms(np.float64(self.angle_amplitude), jv, _F64_TOL)


    def _e_ichi(self, m: Backend, sign: int) -> ExpSum:
        """``e^{±iχ(t)}`` = ``e^{±iω_s t} Σ_k J_k(θ0) e^{±ikΩt}``."""
        _, om, _, _, _, _, ws = self._p(m)
        return ExpSum(tuple((j, sign * (ws + k * om)) for k, j in self._bessel(m)))

    # ------------------------------------------------------------------ attitude, rate
    def _attitude(self, m: Backend, t):
        th, om, _, _, a, omc, ws = self._p(m)
        half_chi = (m.sin_lin(om, t) * th + ws * t) / 2  # χ/2 (ω_s t formed in one product)
        cs, ss = m.cos(half_chi), m.sin(half_chi)
        ca, sa = m.cos(a / 2), m.sin(a / 2)
        cy, sy = sa * m.cos_lin(omc, t), sa * m.sin_lin(omc, t)
        # [ca, 0, cy, sy] ⊗ [cs, ss, 0, 0]
        return (ca * cs, ca * ss, cy * cs + sy * ss, sy * cs - cy * ss)

    def _rate_yz(self, m: Backend) -> ExpSum:
        """Body rate ``y + iz`` = ``iΩ_c sin a e^{iΩ_c t} e^{−iχ}``."""
        _, _, _, _, a, omc, _ = self._p(m)
        return self._e_ichi(m, -1).shift(omc).scale(1j * omc * m.sin(a))

    def _rate(self, m: Backend, t):
        th, om, _, _, a, omc, ws = self._p(m)
        wx = ws - 2 * omc * m.sin(a / 2) ** 2 + th * om * m.cos_lin(om, t)
        if float(self.half_angle) == 0.0:
            return (wx, 0 * t, 0 * t)
        yz = self._rate_yz(m).value(m, t)
        return (wx, _re(yz), _im(yz))

    def _increment(self, m: Backend, t0, dt):
        th, om, _, _, a, omc, ws = self._p(m)
        ix = (ws - 2 * omc * m.sin(a / 2) ** 2) * dt + th * om * _int_cos(m, om, t0, dt)
        if float(self.half_angle) == 0.0:
            return (ix, 0 * dt, 0 * dt)
        yz = self._rate_yz(m).integral(m, t0, dt)
        return (ix, _re(yz), _im(yz))

    # ------------------------------------------------------------------ specific force
    def specific_force(self, t) -> np.ndarray:
        """Body specific force ``f_b(t)`` (m/s²), shape ``t.shape + (3,)``."""
        t = finite_array(t, "t")
        _, om, acc, psi, *_ = self._p(NUMPY)
        fy = acc * _sin_shift(NUMPY, om, psi, t)
        return np.stack(np.broadcast_arrays(0 * t, fy, 0 * t), axis=-1)

    def velocity_increments(self, edges) -> np.ndarray:
        """Exact accelerometer increments ``Δv_b = ∫ f_b dt`` over consecutive ``edges``,
        shape ``(n − 1, 3)`` (m/s)."""
        edges = as_times(edges, "edges", min_len=2)
        parts = self._dv(NUMPY, edges[:-1], edges[1:] - edges[:-1])
        return np.stack(np.broadcast_arrays(*parts), axis=-1)

    def velocity_increment_mp(self, t0, t1) -> tuple:
        """Exact ``Δv_b`` over ``[t0, t1]`` as three mpmath numbers."""
        t0 = MPMATH.num(t0)
        return self._dv(MPMATH, t0, MPMATH.num(t1) - t0)

    def _dv(self, m: Backend, t0, dt):
        _, om, acc, psi, *_ = self._p(m)
        # ∫ sin(Ωt + ψ) = cos ψ ∫ sin Ωt + sin ψ ∫ cos Ωt
        iy = acc * (m.cos(psi) * _int_sin(m, om, t0, dt) + m.sin(psi) * _int_cos(m, om, t0, dt))
        return (0 * dt, iy, 0 * dt)

    # ------------------------------------------------------------------ navigation frame
    def _force_nav(self, m: Backend) -> tuple[ExpSum, ExpSum]:
        """Navigation-frame specific force: (x as a real exponential sum, y + iz)."""
        _, om, acc, psi, a, omc, _ = self._p(m)
        # w = A sin(Ωt + ψ) e^{iχ} (body force rotated by q_x(χ)), y + iz
        e = self._e_ichi(m, 1)
        ep = _cis(m, 1, psi)
        w = e.shift(om).scale(acc * ep / 2j) + e.shift(-om).scale(-acc * _conj(ep) / 2j)
        if float(self.half_angle) == 0.0:
            return ExpSum(()), w
        # Rodrigues about u = (0, cos Ω_c t, sin Ω_c t) by a:
        # x = sin a Im(e^{−iΩ_c t} w);  y + iz = w cos a + e^{iΩ_c t} Re(e^{−iΩ_c t} w)(1 − cos a)
        u = w.shift(-omc)
        x = u.imag().scale(m.sin(a))
        yz = w.scale(m.cos(a)) + u.real().shift(omc).scale(1 - m.cos(a))
        return x, yz

    def _nav(self, m: Backend, t, kind: str):
        x, yz = self._force_nav(m)
        if kind == "force":
            vx, vyz = x.value(m, t), yz.value(m, t)
        elif kind == "velocity":
            vx, vyz = x.integral(m, 0 * t, t), yz.integral(m, 0 * t, t)
        else:
            vx, vyz = x.double_integral(m, t), yz.double_integral(m, t)
        return (_re(vx) if x.terms else 0 * t, _re(vyz), _im(vyz))

    def force_nav(self, t) -> np.ndarray:
        """Navigation-frame specific force ``C_n_b f_b`` (m/s²), shape ``t.shape + (3,)``."""
        return self._stack(t, "force")

    def velocity(self, t) -> np.ndarray:
        """Exact navigation-frame velocity ``v_n(t)`` (m/s), ``v_n(0) = 0``."""
        return self._stack(t, "velocity")

    def position(self, t) -> np.ndarray:
        """Exact navigation-frame position ``p_n(t)`` (m), ``p_n(0) = 0``."""
        return self._stack(t, "position")

    def _stack(self, t, kind):
        t = finite_array(t, "t")
        return np.stack(np.broadcast_arrays(*self._nav(NUMPY, t, kind)), axis=-1)

    def velocity_mp(self, t) -> tuple:
        """``v_n(t)`` as three mpmath numbers at the current ``mpmath.mp.dps``."""
        return self._nav(MPMATH, MPMATH.num(t), "velocity")

    def position_mp(self, t) -> tuple:
        """``p_n(t)`` as three mpmath numbers."""
        return self._nav(MPMATH, MPMATH.num(t), "position")

    def force_nav_mp(self, t) -> tuple:
        """``C_n_b f_b`` at ``t`` as three mpmath numbers."""
        return self._nav(MPMATH, MPMATH.num(t), "force")

    def rectified_acceleration(self) -> float:
        """Classical sculling only (``a = ω_s = 0``): the mean of ``v̇_z``, ``A J1(θ0) cos ψ``."""
        if float(self.half_angle) != 0.0 or float(self.spin_rate) != 0.0:
            raise ValueError("the rectified acceleration is tabulated for classical sculling "
                             "(no cone, no spin)")
        from scipy.special import j1

        return float(self.accel_amplitude * j1(self.angle_amplitude) * math.cos(self.phase))


def _bessel_terms(th, jv, tol):
    """``[(k, J_k(θ0))]`` for k = 0, ±1, … until ``|J_k| < tol`` beyond ``k > |θ0|``."""
    out = [(0, jv(0, th))]
    k = 1
    while True:
        j = jv(k, th)
        if abs(j) < tol and k > abs(th):
            break
        out += [(k, j), (-k, j if k % 2 == 0 else -j)]  # J_{−k} = (−1)^k J_k
        k += 1
    return out


@functools.lru_cache(maxsize=64)
def _mp_bessel(th: float, dps: int):
    """The Bessel terms in mpmath at ``dps`` digits (memoised: every evaluation needs them)."""
    return _bessel_terms(mpmath.mpf(th), mpmath.besselj, mpmath.mpf(10) ** (-dps - 5))


def classical_sculling(angle_amplitude: float, frequency: float, accel_amplitude: float,
                       phase: float = 0.0) -> ScullingMotion:
    """Classical sculling: ``θ0 sin Ωt`` about body x, ``A sin(Ωt + ψ)`` along body y."""
    return ScullingMotion(angle_amplitude, frequency, accel_amplitude, phase)


def _sin_shift(m: Backend, om, psi, t):
    """``sin(Ωt + ψ)`` with the exact-product phase Ωt."""
    return m.sin_lin(om, t) * m.cos(psi) + m.cos_lin(om, t) * m.sin(psi)


def _re(z):
    return z.real if not isinstance(z, mpmath.mpc) else mpmath.re(z)


def _im(z):
    return z.imag if not isinstance(z, mpmath.mpc) else mpmath.im(z)
