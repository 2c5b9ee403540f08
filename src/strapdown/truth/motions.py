"""Reference motions with exact truth: attitude, body rate and angular increments.

Every motion offers one interface:

* :meth:`Motion.attitude` — ``q_n_b(t)``, shape ``(..., 4)``;
* :meth:`Motion.rate` — body angular rate ``ω_b(t)``, shape ``(..., 3)``;
* :meth:`Motion.increments` — exact ``Δθ = ∫ ω dt`` over consecutive time
  edges, shape ``(n - 1, 3)``: closed form where one exists, otherwise
  composite Gauss–Legendre quadrature (:data:`QUADRATURE_NODES` nodes per
  interval).

Closed-form motions also evaluate in arbitrary precision
(:meth:`Motion.attitude_mp`, :meth:`Motion.increment_mp`) for the analysis of
drifts far below float64 round-off.

All motions start at ``t = 0`` in the pose their formula gives; no hidden
state, constructors only store parameters.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.backend import MPMATH, NUMPY, Backend
from strapdown._core.validation import as_quaternions, as_times, as_vectors, finite_array, positive
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply, quat_rotate

__all__ = [
    "QUADRATURE_NODES",
    "ClassicalConing",
    "ConeAngleMotion",
    "KrylovMotion",
    "Motion",
    "PureSpin",
    "RotationSequenceMotion",
    "SpinConing",
    "UserMotion",
    "interval_integrals",
]

#: Gauss–Legendre nodes per interval for motions without closed-form increments.
QUADRATURE_NODES = 12

_GL_X, _GL_W = np.polynomial.legendre.leggauss(QUADRATURE_NODES)

#: A user function of time: float64 times in, values of shape ``t.shape + (k,)`` out.
TimeFunction = Callable[[NDArray[np.float64]], ArrayLike]


def interval_integrals(f: TimeFunction, t0: NDArray[np.float64],
                       t1: NDArray[np.float64]) -> NDArray[np.float64]:
    """``∫ f dt`` over each interval ``[t0_i, t1_i]``, shape ``(n, k)``: Gauss–Legendre
    quadrature with :data:`QUADRATURE_NODES` nodes per interval (exact for a polynomial of
    degree ``2 QUADRATURE_NODES − 1``); ``f`` is evaluated at all nodes in one call."""
    mid = 0.5 * (t0 + t1)
    half = 0.5 * (t1 - t0)
    nodes = mid[:, None] + half[:, None] * _GL_X[None, :]
    vals = np.asarray(f(nodes))  # (n, nodes, k)
    return half[:, None] * np.einsum("k,nkj->nj", _GL_W, vals)


class Motion(abc.ABC):
    """A rigid-body rotation with exact truth.

    Attributes
    ----------
    cone_axis : ndarray of shape (3,) or None
        Unit cone axis in the reference frame for coning motions.
    period : float or None
        Period (s) after which the error pattern of a periodic motion repeats
        (the cone period); ``None`` for aperiodic motions.
    """

    cone_axis: NDArray[np.float64] | None = None
    period: float | None = None

    @abc.abstractmethod
    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        """``q_n_b(t)`` for time(s) ``t``, shape ``t.shape + (4,)``."""

    @abc.abstractmethod
    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body rate ``ω_b(t)`` (rad/s), shape ``t.shape + (3,)``."""

    def increments(self, edges: ArrayLike) -> NDArray[np.float64]:
        """Exact angular increments over consecutive ``edges``, shape ``(n - 1, 3)``."""
        e = as_times(edges, "edges", min_len=2)
        return self._increments(e[:-1], e[1:])

    def _increments(self, t0: NDArray[np.float64], t1: NDArray[np.float64]) -> NDArray[np.float64]:
        return interval_integrals(self.rate, t0, t1)

    # --- arbitrary precision (closed-form motions only) -----------------------------
    @property
    def has_closed_form(self) -> bool:
        """Whether :meth:`attitude_mp` and :meth:`increment_mp` are available."""
        return False

    def attitude_mp(self, t) -> tuple:
        """``q_n_b(t)`` as four mpmath numbers at the current ``mpmath.mp.dps``."""
        raise NotImplementedError(
            f"{type(self).__name__} has no closed form for arbitrary-precision evaluation"
        )

    def increment_mp(self, t0, t1) -> tuple:
        """Exact increment over ``[t0, t1]`` as three mpmath numbers."""
        raise NotImplementedError(
            f"{type(self).__name__} has no closed form for arbitrary-precision evaluation"
        )

    def rate_mp(self, t) -> tuple:
        """Body rate at ``t`` as three mpmath numbers."""
        raise NotImplementedError(
            f"{type(self).__name__} has no closed form for arbitrary-precision evaluation"
        )


class _ClosedForm(Motion):
    """A motion whose attitude and increments are written once for both back-ends."""

    @abc.abstractmethod
    def _attitude(self, m: Backend, t) -> tuple: ...

    @abc.abstractmethod
    def _increment(self, m: Backend, t0, dt) -> tuple:
        """Exact increment over ``[t0, t0 + dt]`` (formulas anchored at the start edge)."""

    @abc.abstractmethod
    def _rate(self, m: Backend, t) -> tuple: ...

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        t = finite_array(t, "t")
        return np.stack(np.broadcast_arrays(*self._attitude(NUMPY, t)), axis=-1)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        t = finite_array(t, "t")
        return np.stack(np.broadcast_arrays(*self._rate(NUMPY, t)), axis=-1)

    def _increments(self, t0: NDArray[np.float64], t1: NDArray[np.float64]) -> NDArray[np.float64]:
        # Anchored at the exact start edge t0 with the exact width t1 − t0 (Sterbenz),
        # phases formed by exact products: no rounded midpoint, no lost phase.
        parts = self._increment(NUMPY, t0, t1 - t0)
        return np.stack(np.broadcast_arrays(*parts), axis=-1)

    @property
    def has_closed_form(self) -> bool:
        return True

    def attitude_mp(self, t) -> tuple:
        return self._attitude(MPMATH, MPMATH.num(t))

    def rate_mp(self, t) -> tuple:
        return self._rate(MPMATH, MPMATH.num(t))

    def increment_mp(self, t0, t1) -> tuple:
        t0 = MPMATH.num(t0)
        t1 = MPMATH.num(t1)
        return self._increment(MPMATH, t0, t1 - t0)


class _ConingAboutX(_ClosedForm):
    """Closed-form motions that cone about the reference x axis at ``cone_rate``."""

    half_angle: float
    cone_rate: float

    def _check_cone(self) -> None:
        finite_array(self.half_angle, "half_angle")
        if float(self.cone_rate) == 0.0 or not np.isfinite(self.cone_rate):
            raise ValueError(f"cone_rate must be finite and non-zero, got {self.cone_rate!r}")

    @property
    def cone_axis(self) -> NDArray[np.float64]:  # type: ignore[override]
        return np.array([1.0, 0.0, 0.0])


@dataclass(frozen=True)
class ClassicalConing(_ConingAboutX):
    """Classical coning (Li & Zhang 2017 eq. 7; Bortz 1971).

    ``q_n_b(t) = [cos(a/2), 0, sin(a/2) cos Ωt, sin(a/2) sin Ωt]``, body rate
    ``ω = [−2Ω sin²(a/2), −Ω sin a sin Ωt, Ω sin a cos Ωt]``. The cone axis is
    the reference x axis. The true attitude is periodic: the true drift is 0.

    Parameters
    ----------
    half_angle : float
        Half cone angle ``a`` (rad).
    cone_rate : float
        Cone angular frequency ``Ω`` (rad/s); may be negative.
    """

    half_angle: float
    cone_rate: float

    def __post_init__(self):
        self._check_cone()

    @property
    def period(self) -> float:  # type: ignore[override]
        return 2.0 * np.pi / abs(float(self.cone_rate))

    def _p(self, m):
        return m.num(self.half_angle), m.num(self.cone_rate)

    def _attitude(self, m, t):
        a, om = self._p(m)
        s = m.sin(a / 2)
        return (m.cos(a / 2) + 0 * t, 0 * t, s * m.cos_lin(om, t), s * m.sin_lin(om, t))

    def _rate(self, m, t):
        a, om = self._p(m)
        sa = m.sin(a)
        return (-2 * om * m.sin(a / 2) ** 2 + 0 * t, -om * sa * m.sin_lin(om, t),
                om * sa * m.cos_lin(om, t))

    def _increment(self, m, t0, dt):
        a, om = self._p(m)
        s = om * m.sin(a)
        return (-2 * om * m.sin(a / 2) ** 2 * dt, -s * _int_sin(m, om, t0, dt),
                s * _int_cos(m, om, t0, dt))


@dataclass(frozen=True)
class PureSpin(_ClosedForm):
    """Constant spin about the body (and reference) x axis: ``q = [cos(ωt/2), sin(ωt/2), 0, 0]``.

    Parameters
    ----------
    spin_rate : float
        Spin rate ``ω_s`` (rad/s).
    """

    spin_rate: float

    def __post_init__(self):
        finite_array(self.spin_rate, "spin_rate")

    @property
    def period(self) -> float | None:  # type: ignore[override]
        w = abs(float(self.spin_rate))
        return 2.0 * np.pi / w if w > 0 else None

    def _attitude(self, m, t):
        ws = m.num(self.spin_rate)
        return (m.cos_lin(ws / 2, t), m.sin_lin(ws / 2, t), 0 * t, 0 * t)

    def _rate(self, m, t):
        ws = m.num(self.spin_rate)
        return (ws + 0 * t, 0 * t, 0 * t)

    def _increment(self, m, t0, dt):
        ws = m.num(self.spin_rate)
        return (ws * dt, 0 * dt, 0 * dt)


@dataclass(frozen=True)
class SpinConing(_ConingAboutX):
    """Spin and coning coexisting: ``q_n_b(t) = q_cone(t) ⊗ q_x(ω_s t)``.

    ``q_cone`` is :class:`ClassicalConing` (half angle ``a``, cone rate ``Ω``)
    and the body additionally spins about its own x axis at ``ω_s``, so
    ``ω_b = [ω_s − 2Ω sin²(a/2), Ω sin a sin λt, Ω sin a cos λt]`` with
    ``λ = ω_s − Ω``. With ``ω_s = 0`` this is classical coning.

    Parameters
    ----------
    half_angle, cone_rate : float
        As for :class:`ClassicalConing` (rad, rad/s).
    spin_rate : float
        Body spin rate ``ω_s`` (rad/s).
    """

    half_angle: float
    cone_rate: float
    spin_rate: float

    def __post_init__(self):
        self._check_cone()
        finite_array(self.spin_rate, "spin_rate")

    @property
    def period(self) -> float | None:  # type: ignore[override]
        # The attitude repeats only when spin and cone rates are commensurate;
        # the drift estimator then samples whole common periods.
        om = abs(float(self.cone_rate))
        ws = abs(float(self.spin_rate))
        if ws == 0.0:
            return 2.0 * np.pi / om
        ratio = ws / om
        for den in range(1, 65):
            num = round(ratio * den)
            if num > 0 and abs(num / den - ratio) < 1e-12 * ratio:
                return 2.0 * np.pi * den / om
        return None

    def _p(self, m):
        return m.num(self.half_angle), m.num(self.cone_rate), m.num(self.spin_rate)

    def _attitude(self, m, t):
        a, om, ws = self._p(m)
        ca, sa = m.cos(a / 2), m.sin(a / 2)
        cs, ss = m.cos_lin(ws / 2, t), m.sin_lin(ws / 2, t)
        cy, sy = sa * m.cos_lin(om, t), sa * m.sin_lin(om, t)
        # [ca, 0, cy, sy] ⊗ [cs, ss, 0, 0]
        return (ca * cs, ca * ss, cy * cs + sy * ss, sy * cs - cy * ss)

    def _rate(self, m, t):
        a, om, ws = self._p(m)
        s = om * m.sin(a)
        sl, cl = _phase(m, (ws, -om), t)
        return (ws - 2 * om * m.sin(a / 2) ** 2 + 0 * t, s * sl, s * cl)

    def _increment(self, m, t0, dt):
        a, om, ws = self._p(m)
        s = om * m.sin(a)
        return ((ws - 2 * om * m.sin(a / 2) ** 2) * dt, s * _int_sin(m, (ws, -om), t0, dt),
                s * _int_cos(m, (ws, -om), t0, dt))


@dataclass(frozen=True)
class KrylovMotion(_ClosedForm):
    """Krylov-angle spherical motion with angles linear in time (Plaksiy, eqs. 2–4).

    ``Λ = Λ1 ∘ Λ2 ∘ Λ3``: ``Λ1`` about axis 3 by ``φ = k1 t``, ``Λ2`` about axis 2
    by ``ψ = k2 t``, ``Λ3`` about axis 1 by ``v = k3 t`` (Hamilton, so
    ``q_n_b = q_z(k1 t) ⊗ q_y(k2 t) ⊗ q_x(k3 t)``). Body rates (eq. 4):
    ``ω1 = k3 − k1 sin k2t``, ``ω2 = k1 cos k2t sin k3t + k2 cos k3t``,
    ``ω3 = k1 cos k2t cos k3t − k2 sin k3t``. Quasi-coordinates over any
    interval have closed forms (products of sin/cos of linear arguments,
    written with ``sinc`` so that equal or zero frequencies are exact).

    Parameters
    ----------
    k1, k2, k3 : float
        Angle rates (rad/s). Plaksiy's printed case is (0.15, 0.25, 0.05).
    """

    k1: float
    k2: float
    k3: float

    def __post_init__(self):
        finite_array([self.k1, self.k2, self.k3], "krylov rates")

    def _k(self, m):
        return m.num(self.k1), m.num(self.k2), m.num(self.k3)

    def _attitude(self, m, t):
        k1, k2, k3 = self._k(m)
        c1, s1 = m.cos_lin(k1 / 2, t), m.sin_lin(k1 / 2, t)
        c2, s2 = m.cos_lin(k2 / 2, t), m.sin_lin(k2 / 2, t)
        c3, s3 = m.cos_lin(k3 / 2, t), m.sin_lin(k3 / 2, t)
        return (c1 * c2 * c3 + s1 * s2 * s3, c1 * c2 * s3 - s1 * s2 * c3,
                c1 * s2 * c3 + s1 * c2 * s3, s1 * c2 * c3 - c1 * s2 * s3)

    def _rate(self, m, t):
        k1, k2, k3 = self._k(m)
        return (k3 - k1 * m.sin_lin(k2, t),
                k1 * m.cos_lin(k2, t) * m.sin_lin(k3, t) + k2 * m.cos_lin(k3, t),
                k1 * m.cos_lin(k2, t) * m.cos_lin(k3, t) - k2 * m.sin_lin(k3, t))

    def _increment(self, m, t0, dt):
        k1, k2, k3 = self._k(m)

        def isin(lam):
            return _int_sin(m, lam, t0, dt)

        def icos(lam):
            return _int_cos(m, lam, t0, dt)

        return (k3 * dt - k1 * isin(k2),
                k1 / 2 * (isin((k3, k2)) + isin((k3, -k2))) + k2 * icos(k3),
                k1 / 2 * (icos((k2, -k3)) + icos((k2, k3))) - k2 * isin(k3))


class UserMotion(Motion):
    """A motion from user functions of time: attitude ``q_n_b(t)`` and body rate ``ω_b(t)``.

    Increments use composite Gauss–Legendre quadrature of ``rate``. The
    functions must accept arrays of times and return ``(..., 4)`` and
    ``(..., 3)``; they are the user's responsibility to keep consistent
    (``q̇ = ½ q ⊗ [0, ω_b]``; nothing checks it).

    Parameters
    ----------
    attitude : callable
        ``t -> q_n_b``.
    rate : callable
        ``t -> ω_b`` (rad/s).
    period : float, optional
        Period of the error pattern, if the motion is periodic.
    cone_axis : array_like of shape (3,), optional
        Reference-frame cone axis, if the motion cones.
    """

    def __init__(
        self,
        attitude: TimeFunction,
        rate: TimeFunction,
        *,
        period: float | None = None,
        cone_axis: ArrayLike | None = None,
    ) -> None:
        if not callable(attitude) or not callable(rate):
            raise ValueError("attitude and rate must be callables of time")
        self._attitude_fn = attitude
        self._rate_fn = rate
        self.period = None if period is None else positive(period, "period")
        if cone_axis is not None:
            ax = as_vectors(cone_axis, "cone_axis")
            if ax.shape != (3,) or np.linalg.norm(ax) == 0:
                raise ValueError("cone_axis must be a non-zero vector of shape (3,)")
            self.cone_axis = ax / np.linalg.norm(ax)

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        t = finite_array(t, "t")
        q = as_quaternions(self._attitude_fn(t), "attitude(t)")
        if q.shape != (*t.shape, 4):
            raise ValueError(f"attitude(t) must have shape {(*t.shape, 4)}, got {q.shape}")
        return q

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        t = finite_array(t, "t")
        w = as_vectors(self._rate_fn(t), "rate(t)")
        if w.shape != (*t.shape, 3):
            raise ValueError(f"rate(t) must have shape {(*t.shape, 3)}, got {w.shape}")
        return w


def _phase(m: Backend, lams, t):
    """(sin, cos) of (Σ λ_i)·t, each λ_i·t formed exactly and combined by angle addition.

    A frequency that is a sum (k3 + k2) is never rounded as a sum before it
    multiplies a large time.
    """
    s, c = m.sin_lin(lams[0], t), m.cos_lin(lams[0], t)
    for lam in lams[1:]:
        s2, c2 = m.sin_lin(lam, t), m.cos_lin(lam, t)
        s, c = s * c2 + c * s2, c * c2 - s * s2
    return s, c


def _int_sin(m: Backend, lams, t0, dt):
    """∫_{t0}^{t0+dt} sin(λt) dt = dt·sinc(λdt/2)·sin(λt0 + λdt/2), λ = Σ lams."""
    lams = lams if isinstance(lams, tuple) else (lams,)
    half = sum(lams) * dt / 2
    s0, c0 = _phase(m, lams, t0)
    return dt * m.sinc(half) * (s0 * m.cos(half) + c0 * m.sin(half))


def _int_cos(m: Backend, lams, t0, dt):
    """∫_{t0}^{t0+dt} cos(λt) dt, λ = Σ lams."""
    lams = lams if isinstance(lams, tuple) else (lams,)
    half = sum(lams) * dt / 2
    s0, c0 = _phase(m, lams, t0)
    return dt * m.sinc(half) * (c0 * m.cos(half) - s0 * m.sin(half))


class ConeAngleMotion(Motion):
    """A motion given by cone angles δ1(t), δ2(t), δ3(t) (Zhang & Yu (2021)).

    ``q_c_b = q_x(δ1) ⊗ q_z(δ2) ⊗ q_x(δ3 − δ1)``; body rates from eq. 6 (exact);
    increments by Gauss–Legendre quadrature. Classical coning is
    ``δ1 = Ωt − π/2, δ2 = a, δ3 = 0``; adding ``δ3 = ω_s t`` gives spin + coning.

    Parameters
    ----------
    angles, angle_rates : callable
        ``t → (..., 3)`` (δ1, δ2, δ3) and their time derivatives (rad, rad/s).
    """

    def __init__(self, angles: TimeFunction,
                 angle_rates: TimeFunction, *, period: float | None = None,
                 cone_axis: ArrayLike | None = (1.0, 0.0, 0.0)) -> None:
        if not callable(angles) or not callable(angle_rates):
            raise ValueError("angles and angle_rates must be callables of time")
        self._d = angles
        self._dd = angle_rates
        self.period = None if period is None else positive(period, "period")
        self.cone_axis = None if cone_axis is None else as_vectors(cone_axis, "cone_axis")

    @classmethod
    def polynomial(cls, start: ArrayLike = (0.0, 0.0, 0.0), rates: ArrayLike = (0.0, 0.0, 0.0),
                   accelerations: ArrayLike = (0.0, 0.0, 0.0)) -> ConeAngleMotion:
        """δ_i(t) = start_i + rate_i t + ½ accel_i t² (Zhang & Yu Tables 5–6), rad."""
        d0 = as_vectors(start, "start")
        r = as_vectors(rates, "rates")
        acc = as_vectors(accelerations, "accelerations")

        def angles(t):
            t = np.asarray(t, dtype=np.float64)[..., None]
            return d0 + r * t + 0.5 * acc * t * t

        def angle_rates(t):
            t = np.asarray(t, dtype=np.float64)[..., None]
            return r + acc * t

        return cls(angles, angle_rates)

    def angles(self, t: ArrayLike) -> NDArray[np.float64]:
        """(δ1, δ2, δ3) at ``t``, shape ``t.shape + (3,)``."""
        t = finite_array(t, "t")
        d = as_vectors(self._d(t), "angles(t)")
        if d.shape != (*t.shape, 3):
            raise ValueError(f"angles(t) must have shape {(*t.shape, 3)}, got {d.shape}")
        return d

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        d = self.angles(t)
        d1, d2, d3 = d[..., 0], d[..., 1], d[..., 2]
        qx1 = np.stack([np.cos(d1 / 2), np.sin(d1 / 2), 0 * d1, 0 * d1], -1)
        qz = np.stack([np.cos(d2 / 2), 0 * d2, 0 * d2, np.sin(d2 / 2)], -1)
        qx3 = np.stack([np.cos((d3 - d1) / 2), np.sin((d3 - d1) / 2), 0 * d1, 0 * d1], -1)
        return quat_multiply(quat_multiply(qx1, qz), qx3)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """Eq. 6: ω = (δ̇1(cos δ2 − 1) + δ̇3, −δ̇1 cos e sin δ2 − δ̇2 sin e,
        −δ̇1 sin e sin δ2 + δ̇2 cos e), e = δ1 − δ3."""
        d = self.angles(t)
        dd = as_vectors(self._dd(finite_array(t, "t")), "angle_rates(t)")
        d1, d2, d3 = d[..., 0], d[..., 1], d[..., 2]
        r1, r2, r3 = dd[..., 0], dd[..., 1], dd[..., 2]
        e = d1 - d3
        return np.stack([r1 * (np.cos(d2) - 1) + r3,
                         -r1 * np.cos(e) * np.sin(d2) - r2 * np.sin(e),
                         -r1 * np.sin(e) * np.sin(d2) + r2 * np.cos(e)], -1)


_AXES = {"x": 0, "y": 1, "z": 2, "1": 0, "2": 1, "3": 2}


class RotationSequenceMotion(Motion):
    """A motion from three successive rotations about body axes with angle functions of time.

    ``q_n_b(t) = q_{axis1}(θ1(t)) ⊗ q_{axis2}(θ2(t)) ⊗ q_{axis3}(θ3(t))``
    (intrinsic sequence), body rate from the angle rates exactly:
    ``ω_b = R3ᵀR2ᵀ e1 θ̇1 + R3ᵀ e2 θ̇2 + e3 θ̇3``. This covers Krylov angles
    (``"zyx"``, Plaksiy eq. 3) and cone angles (``"xzx"``, Zhang & Yu).

    Parameters
    ----------
    axes : str
        Three axes from ``x, y, z`` (or ``1, 2, 3``), e.g. ``"zyx"``.
    angles : callable
        ``t -> (..., 3)`` angles (rad).
    angle_rates : callable
        ``t -> (..., 3)`` their time derivatives (rad/s).
    period : float, optional
        Period of the error pattern, if periodic.
    cone_axis : array_like of shape (3,), optional
        Reference-frame cone axis, if the motion cones.
    """

    def __init__(self, axes: str, angles: TimeFunction,
                 angle_rates: TimeFunction, *, period: float | None = None,
                 cone_axis: ArrayLike | None = None) -> None:
        if not isinstance(axes, str) or len(axes) != 3 or any(c not in _AXES for c in axes):
            raise ValueError(f"axes must be three of 'x', 'y', 'z' (e.g. 'zyx'), got {axes!r}")
        if not callable(angles) or not callable(angle_rates):
            raise ValueError("angles and angle_rates must be callables of time")
        self.axes = axes
        self._idx = [_AXES[c] for c in axes]
        self._angles = angles
        self._angle_rates = angle_rates
        self.period = None if period is None else positive(period, "period")
        if cone_axis is not None:
            ax = as_vectors(cone_axis, "cone_axis")
            self.cone_axis = ax / np.linalg.norm(ax)

    def _axis_quats(self, ang: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        out = []
        for k, i in enumerate(self._idx):
            q = np.zeros((*ang.shape[:-1], 4))
            q[..., 0] = np.cos(0.5 * ang[..., k])
            q[..., 1 + i] = np.sin(0.5 * ang[..., k])
            out.append(q)
        return out

    def _eval(self, t: ArrayLike, fn: TimeFunction, name: str) -> NDArray[np.float64]:
        t = finite_array(t, "t")
        v = as_vectors(fn(t), name)
        if v.shape != (*t.shape, 3):
            raise ValueError(f"{name} must have shape {(*t.shape, 3)}, got {v.shape}")
        return v

    def attitude(self, t: ArrayLike) -> NDArray[np.float64]:
        q1, q2, q3 = self._axis_quats(self._eval(t, self._angles, "angles(t)"))
        return quat_multiply(quat_multiply(q1, q2), q3)

    def rate(self, t: ArrayLike) -> NDArray[np.float64]:
        ang = self._eval(t, self._angles, "angles(t)")
        dang = self._eval(t, self._angle_rates, "angle_rates(t)")
        _, q2, q3 = self._axis_quats(ang)
        e = np.eye(3)
        shape = (*ang.shape[:-1], 3)
        e1 = np.broadcast_to(e[self._idx[0]], shape)
        e2 = np.broadcast_to(e[self._idx[1]], shape)
        e3 = np.broadcast_to(e[self._idx[2]], shape)
        q23c = quat_conjugate(quat_multiply(q2, q3))
        q3c = quat_conjugate(q3)
        return (quat_rotate(q23c, e1) * dang[..., :1] + quat_rotate(q3c, e2) * dang[..., 1:2]
                + e3 * dang[..., 2:3])


