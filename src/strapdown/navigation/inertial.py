"""Body increments chained in a non-rotating frame without gravity: the sculling studies'
integrator (:func:`integrate_inertial`, :func:`integrate_inertial_rates`) and its
arbitrary-precision form (:func:`integrate_inertial_mp`).

Per update of period ``T`` with the body increments ``φ``, ``Δv_b``, ``ΔR_b`` of
:func:`strapdown.algorithms.velocity.body_increments` (or of a rate family's velocity
counterpart, :meth:`strapdown.algorithms.family.Family.velocity`):
``v_m = v_{m−1} + C_{m−1} Δv_b``, ``p_m = p_{m−1} + v_{m−1} T + C_{m−1} ΔR_b``,
``q_m = q_{m−1} ⊗ q(φ_m)``. The velocity and position algorithms themselves, their sets
and error laws are documented in :mod:`strapdown.algorithms.velocity`; the navigation on
the WGS-84 Earth is :mod:`strapdown.navigation.earth`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_quaternions, as_vectors, finite_array, positive
from strapdown._core.validation import positive_int as _positive_int
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.velocity import (
    DEFAULT_VELOCITY_SET,
    NavStructure,
    VelocitySet,
    _inputs,
    _n,
    _rate_spec,
    _structure,
    _velocity_set,
    body_increments,
    sculling_matrix,
    sculling_single_chain_table,
)
from strapdown.navigation import _kernels

__all__ = ["InertialSolution", "MpInertialSolution", "integrate_inertial",
           "integrate_inertial_mp", "integrate_inertial_rates"]


@dataclass(frozen=True)
class InertialSolution:
    """Attitude, velocity and position in a non-rotating frame without gravity.

    ``t`` (m,), ``q`` (m, 4) ``q_n_b``, ``v`` (m, 3) m/s, ``p`` (m, 3) m; ``startup`` the
    first steady-state output (N − 1 for the single chain, else 0).
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    v: NDArray[np.float64]
    p: NDArray[np.float64]
    structure: NavStructure
    n: int
    h: float
    update_period: float
    startup: int = 0


def _state(q0, v0, p0):
    q = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else as_quaternions(q0, "q0")
    if q.shape != (4,):
        raise ValueError(f"q0 must have shape (4,), got {q.shape}")
    v = np.zeros(3) if v0 is None else as_vectors(v0, "v0")
    p = np.zeros(3) if p0 is None else as_vectors(p0, "p0")
    if v.shape != (3,) or p.shape != (3,):
        raise ValueError(f"v0 and p0 must have shape (3,), got {v.shape} and {p.shape}")
    return q / np.linalg.norm(q), v, p


def integrate_inertial(gyro: ArrayLike, accel: ArrayLike, n: int, *, h: float,
                       structure: NavStructure = "conventional", t0: float = 0.0,
                       q0: ArrayLike | None = None, v0: ArrayLike | None = None,
                       p0: ArrayLike | None = None, sculling: bool = True,
                       velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> InertialSolution:
    """Strapdown integration in a non-rotating frame without gravity (sculling studies).

    ``v_m = v_{m−1} + C_{m−1} Δv_b``, ``p_m = p_{m−1} + v_{m−1} T + C_{m−1} ΔR_b``,
    ``q_m = q_{m−1} ⊗ q(φ_m)`` with the increments of :func:`body_increments`.
    """
    q0, v0, p0 = _state(q0, v0, p0)
    t0 = float(finite_array(t0, "t0"))
    b = body_increments(gyro, accel, n, h=h, structure=structure, sculling=sculling,
                        velocity_set=velocity_set)
    m = b.phi.shape[0]
    q = np.empty((m + 1, 4))
    v = np.empty((m + 1, 3))
    p = np.empty((m + 1, 3))
    _kernels.inertial_kernel(b.phi, b.dv, b.dr, b.update_period, q0, v0, p0, q, v, p)
    t = t0 + np.arange(m + 1) * b.update_period
    startup = min(b.n - 1, m) if _structure(b.structure).own_startup else 0
    return InertialSolution(t, q, v, p, structure, b.n, b.h, b.update_period, startup)


@dataclass(frozen=True)
class MpInertialSolution:
    """Errors of an arbitrary-precision run, formed in high precision, as float64.

    ``t`` (m,) output times; ``dv``, ``dp`` (m, 3) velocity and position errors
    (computed − true) in the navigation frame.
    """

    t: NDArray[np.float64]
    dv: NDArray[np.float64]
    dp: NDArray[np.float64]
    digits: int
    startup: int = 0


def integrate_inertial_mp(motion, n: int, *, h: float, samples: int, digits: int,
                          structure: NavStructure = "conventional",
                          velocity_set: VelocitySet = DEFAULT_VELOCITY_SET
                          ) -> MpInertialSolution:
    """:func:`integrate_inertial` in arbitrary precision on a closed-form sculling motion.

    Exact increments (:meth:`~strapdown.truth.sculling.ScullingMotion.increment_mp`,
    :meth:`~strapdown.truth.sculling.ScullingMotion.velocity_increment_mp`), exact
    rational coefficients and the plain-Python twins of the kernels
    (:mod:`strapdown.algorithms._velocity_reference`, :mod:`strapdown.navigation._reference`)
    at ``digits`` significant digits; the errors against the exact velocity and position
    are converted to float64 at the end.
    """
    import mpmath

    from strapdown._core.backend import MPMATH
    from strapdown.algorithms import _velocity_reference as vref
    from strapdown.algorithms.precision import MAX_MP_SAMPLES
    from strapdown.navigation import _reference as ref

    n, h = _n(n), positive(h, "h (sample interval)")
    samples, digits = _positive_int(samples, "samples"), _positive_int(digits, "digits")
    if samples > MAX_MP_SAMPLES:
        raise ValueError(f"{samples} samples exceed the arbitrary-precision limit of "
                         f"{MAX_MP_SAMPLES}")
    if digits < 17:
        raise ValueError(f"digits must be at least 17 (float64 is ~16), got {digits}")
    st = _structure(structure)
    _velocity_set(velocity_set)
    with mpmath.workdps(digits):
        hm = mpmath.mpf(h)
        edges = [k * hm for k in range(samples + 1)]
        g = [motion.increment_mp(a, b) for a, b in itertools.pairwise(edges)]
        a = [motion.velocity_increment_mp(a, b) for a, b in itertools.pairwise(edges)]
        zero = mpmath.mpf(0)

        def mp(rows):
            return [[mpmath.mpf(v.numerator) / v.denominator for v in r] for r in rows]

        if st.whole_updates:  # the conventional structure
            kc = mp(coefficient_set("table3", n).exact)
            body = vref.conventional_body(g, a, kc, mp(sculling_matrix(
                n, exact=True, velocity_set=velocity_set)), hm, zero)
            period, startup = n * hm, 0
        else:
            from strapdown.algorithms.structures import single_chain_coefficients

            tab_c = [[Fraction(0)] * max(n - 1, 1) for _ in range(n)]
            for m_ in range(1, n):
                tab_c[m_][:m_] = single_chain_coefficients(m_ + 1)
            body = vref.single_chain_body(g, a, mp(tab_c), mp(sculling_single_chain_table(
                n, exact=True)), hm)
            period, startup = hm, n - 1
        _qs, vs, ps = ref.inertial(body, period, motion.attitude_mp(zero), (zero,) * 3,
                                  (zero,) * 3, MPMATH)
        t = [k * period for k in range(len(vs))]
        dv = np.array([[float(c - e) for c, e in zip(v, motion.velocity_mp(tt), strict=True)]
                       for v, tt in zip(vs, t, strict=True)])
        dp = np.array([[float(c - e) for c, e in zip(p, motion.position_mp(tt), strict=True)]
                       for p, tt in zip(ps, t, strict=True)])
    return MpInertialSolution(np.array([float(x) for x in t]), dv, dp, digits,
                              min(startup, len(t) - 1))


def integrate_inertial_rates(omega: ArrayLike, force: ArrayLike, *, td: float,
                             coefficients: str = "derived", algorithm: str = "rate-single",
                             t0: float = 0.0, q0: ArrayLike | None = None,
                             v0: ArrayLike | None = None,
                             p0: ArrayLike | None = None) -> InertialSolution:
    """Rate-input strapdown integration in a non-rotating frame without gravity.

    Parameters
    ----------
    omega, force : array_like of shape (k, 3)
        Angular rate (rad/s) and specific force (m/s²) samples every ``td``.
    td : float
        Sample interval (s).
    coefficients : {"derived", "paper"}
        The rate algorithm's coning coefficients, used for the sculling terms too.
    algorithm : {"rate-single", "rate-three"}
        ``rate-single``: an update every td (k ≥ 2); ``rate-three``: Simpson's 3/8 rule and
        the three-period pair coefficients on ω, f at 0, td, 2td, 3td, an update every 3 td
        (k ≥ 4; a tail of fewer than three intervals is dropped). Module docstring.

    Notes
    -----
    The solution's ``structure`` is ``"single-chain"`` for rate-single (an update every
    sample interval, ``n`` 1) and ``"conventional"`` for rate-three (``n`` 3).
    """
    w, f = _inputs(omega, force)
    spec = _rate_spec(coefficients, algorithm)
    vel = spec.family.velocity(spec)
    assert vel is not None  # _rate_spec: a velocity counterpart
    if w.shape[0] < vel.min_samples:
        raise ValueError(f"{algorithm} needs at least {vel.min_samples} samples, got "
                         f"{w.shape[0]}")
    td = positive(td, "td (sample interval)")
    q0, v0, p0 = _state(q0, v0, p0)
    b = vel.body(w, f, td)
    m = b.phi.shape[0]
    q, v, p = np.empty((m + 1, 4)), np.empty((m + 1, 3)), np.empty((m + 1, 3))
    _kernels.inertial_kernel(b.phi, b.dv, b.dr, b.update_period, q0, v0, p0, q, v, p)
    t = float(finite_array(t0, "t0")) + vel.start * td + np.arange(m + 1) * b.update_period
    return InertialSolution(t, q, v, p, b.structure, b.n, td, b.update_period, 0)
