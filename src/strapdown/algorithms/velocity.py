"""Velocity and position updates with rotation, sculling and scrolling compensation.

Over an update of N gyro increments ``θ_j`` and accelerometer increments ``v_j`` (rad,
m/s; ``α = Σθ_j``, ``υ = Σv_j``) the body-frame quantities at the update start are
(Savage (1998b), the velocity and position algorithms; Ignagni (1998), the duality):

rotation vector (coning)
    ``φ = α + Σ_{i<j} k_ij θ_i × θ_j`` — Li & Zhang (2017) eq. 6, Table 3.
velocity increment (rotation + sculling compensation)
    ``Δv_b = υ + ½ α × υ + ⅙ α × (α × υ) + Σ_{i<j} s_ij (θ_i × v_j + v_i × θ_j)``;
    ``½ α × υ + ⅙ α × (α × υ)`` is the rotation compensation of a constant rate to second
    order, the pair sum the sculling compensation ``½∫(α × f + υ × ω) dt``. Two velocity
    sets (``velocity_set``): ``"classical"``, the designer's sculling target on the pairs
    with the last subsample (:data:`strapdown.algorithms.tables.SCULLING_CONVENTIONAL`, the
    coning set of the same structure), and ``"coning-force"`` (the default), the designer's
    ``coning-force`` target on all pairs ``i < j``
    (:data:`strapdown.algorithms.tables.SCULLING_CONING_FORCE`): the same classical-sculling
    law, and a body coning in a constant specific force (gravity) is also cancelled to
    order 2N. The classical sets leave that coning × force term at ``(Ωh)⁴`` for every
    N ≥ 2 with a constant that grows with N (:func:`coning_force_law`, constants
    −1/20, −31/40, −59/20, −2665/336, −1049/60 for N = 2–6): on a coning body in gravity
    a classical N ≥ 3 set is worse than N = 2. N = 1, 2 have one set.
position increment (scrolling compensation)
    ``ΔR_b = h (Σ_{j=1}^{N−1} ΔV_j + ½ Δv_b)``: the trapezoid rule over the
    subsample-resolved velocity increment ``ΔV_j`` (rotation compensation on the partial
    sums plus Savage's recursive two-sample sculling ``(1/12)(θ_{j−1} × v_j + v_{j−1} ×
    θ_j)``), closed by the N-sample ``Δv_b``. Exact for constant specific force and rate to
    second order; its error for a time-varying force telescopes in the navigation frame.

The single chain (``single-chain``) updates every sample with the designer's single-chain
coefficients for both corrections, ``Δv_k = v_k + ½ θ_k × v_k + ⅙ θ_k × (θ_k × v_k) +
Σ_m c_m (θ_{k−m} × v_k + v_{k−m} × θ_k)`` and ``ΔR_k = ½ h Δv_k`` (start-up: sample
k < N − 1 uses the (k+1)-sample set). Its N − 1 coefficients are all fixed by the sculling
conditions, so no set of this form cancels the coning × force term beyond ``(Ωh)⁴``
(:func:`strapdown.design.derive` with ``target="coning-force"`` stops there); its
constant is small (1/30, 1/120, 11/1680 for N = 2–4), and both velocity-set names select
its one (classical) set.

Classical-sculling law (derived by :func:`strapdown.design.derive` with
``target="sculling"``): the rectified velocity error rate along the axis normal to both
vibrations is ``−c · θ0 A cos ψ (Ωh)^{2N}``, ``c = N!(N+1)!/(2N+2)!``, for both
structures (:func:`sculling_law`).

:func:`integrate_inertial` chains the increments in a non-rotating frame without gravity
(the sculling studies); :mod:`strapdown.algorithms.navigation` on the WGS-84 Earth.

Rate input (:func:`integrate_inertial_rates`): from rate and specific-force samples
``ω_k``, ``f_k`` every ``td`` — the dual of Wang, Wang & Wang's single-period rate
algorithm (``rate-single``, :mod:`strapdown.algorithms.rate`), an update every ``td``:
``θ = td/2 (ω_{k−1} + ω_k)``, ``υ = td/2 (f_{k−1} + f_k)``,
``φ = θ + c td² ω_{k−1} × ω_k``,
``Δv_b = υ + ½ θ × υ + ⅙ θ × (θ × υ) + c td² (ω_{k−1} × f_k + f_{k−1} × ω_k)``,
``ΔR_b = ½ td Δv_b``, with the same ``c`` for both (Ignagni (1998)'s duality):
``derived`` c = 1/6 — the sculling law is the coning one,
``−(11/1440) θ0 A cos ψ (Ωtd)^4``; ``paper`` c = 1/12 — ``−(1/12) θ0 A cos ψ (Ωtd)^2``
(:func:`rate_sculling_law`, :data:`strapdown.algorithms.tables.RATE_SINGLE_DRIFT`).
``rate-three`` likewise dualises the three-period algorithm (ω, f at 0, td, 2td, 3td;
Simpson's 3/8 rule for α and υ; the pair coefficients k_ij on ``ω_i × f_j + f_i × ω_j``),
an update every 3 td; its sculling law is the coning law of ``rate-three``
(:data:`strapdown.algorithms.tables.RATE_THREE_DRIFT`: derived (Ωtd)^8, paper (Ωtd)^4).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from fractions import Fraction
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_quaternions, as_vectors, finite_array, positive
from strapdown._core.validation import positive_int as _positive_int
from strapdown.algorithms import _nav_kernels, tables
from strapdown.algorithms.coning import MAX_SUBSAMPLES, coefficient_set
from strapdown.algorithms.structures import single_chain_table

__all__ = [
    "DEFAULT_VELOCITY_SET",
    "NAV_STRUCTURES",
    "RATE_VELOCITY_ALGORITHMS",
    "VELOCITY_SETS",
    "BodyIncrements",
    "ConingForceLaw",
    "InertialSolution",
    "NavStructure",
    "ScullingLaw",
    "VelocitySet",
    "body_increments",
    "coning_force_law",
    "effective_velocity_set",
    "integrate_inertial",
    "integrate_inertial_mp",
    "integrate_inertial_rates",
    "rate_sculling_law",
    "sculling_law",
    "sculling_matrix",
    "sculling_single_chain_table",
]

#: Update structures of the velocity/position algorithms.
NavStructure = Literal["conventional", "single-chain"]
NAV_STRUCTURES: tuple[NavStructure, ...] = get_args(NavStructure)
#: The velocity (sculling) sets of the conventional structure (module docstring).
VelocitySet = Literal["coning-force", "classical"]
VELOCITY_SETS: tuple[VelocitySet, ...] = get_args(VelocitySet)
#: What ``body_increments``, ``integrate_inertial`` and the navigation run by default.
DEFAULT_VELOCITY_SET: VelocitySet = "coning-force"


@dataclass(frozen=True)
class ScullingLaw:
    """Rectified classical-sculling velocity error rate ``−c · θ0 A cos ψ (Ωh)^order``."""

    order: int
    constant: Fraction

    def predict(self, angle_amplitude: float, accel_amplitude: float, phase: float,
                frequency: float, h: float) -> float:
        """The law's rate (m/s²) along the axis normal to both vibrations."""
        return (-float(self.constant) * angle_amplitude * accel_amplitude * np.cos(phase)
                * (frequency * h) ** self.order)


def _n(n: int) -> int:
    n = _positive_int(n, "N (subsamples)")
    if n > MAX_SUBSAMPLES:
        raise ValueError(f"N (subsamples) must be at most {MAX_SUBSAMPLES}, got {n}")
    return n


def _structure(structure: object) -> NavStructure:
    if structure not in NAV_STRUCTURES:
        raise ValueError(f"unknown velocity structure {structure!r}; choose one of "
                         f"{', '.join(NAV_STRUCTURES)}")
    return structure


def _velocity_set(name: object) -> VelocitySet:
    if name not in VELOCITY_SETS:
        raise ValueError(f"unknown velocity set {name!r}; choose one of "
                         f"{', '.join(VELOCITY_SETS)}")
    return name


@dataclass(frozen=True)
class ConingForceLaw:
    """Rectified velocity error rate along the cone axis of a body coning (half angle ``a``,
    cone rate ``Ω``) in a constant specific force ``f`` along that axis:
    ``−c · a² f (Ωh)^order`` (leading order in ``a``)."""

    order: int
    constant: Fraction

    def predict(self, half_angle: float, force: float, cone_rate: float, h: float) -> float:
        """The law's rate (m/s²) along the cone axis."""
        return -float(self.constant) * half_angle**2 * force * (cone_rate * h) ** self.order


def effective_velocity_set(structure: NavStructure,
                           velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> VelocitySet:
    """The set a structure runs for the name given: the single chain has one set, the
    classical one (module docstring)."""
    return "classical" if _structure(structure) == "single-chain" else _velocity_set(
        velocity_set)


def coning_force_law(n: int, structure: NavStructure = "conventional",
                     velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> ConingForceLaw:
    """The coning-in-constant-force law of a structure's velocity set
    (:data:`tables.CONING_FORCE_DRIFT`; the single chain has one set)."""
    n = _n(n)
    order, c = tables.CONING_FORCE_DRIFT[(structure, effective_velocity_set(
        structure, velocity_set))][n]
    return ConingForceLaw(order, c)


def sculling_law(n: int) -> ScullingLaw:
    """The classical-sculling law of the N-sample sets (:data:`tables.SCULLING_DRIFT`)."""
    order, c = tables.SCULLING_DRIFT[_n(n)]
    return ScullingLaw(order, c)


def sculling_matrix(n: int, *, exact: bool = False, velocity_set: VelocitySet = "classical"):
    """``(N, N)`` upper-triangular sculling matrix of the conventional structure:
    ``"classical"``: ``s[N−1−m, N−1] = ς_m`` (cross with the last subsample);
    ``"coning-force"``: ``s[i, j] = k_ij`` over all pairs. ``exact=True``: nested lists of
    :class:`~fractions.Fraction`."""
    n = _n(n)
    rows = [[Fraction(0)] * n for _ in range(n)]
    if _velocity_set(velocity_set) == "coning-force":
        pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
        for (i, j), c in zip(pairs, tables.SCULLING_CONING_FORCE[n], strict=True):
            rows[i][j] = c
    else:
        for m, c in enumerate(tables.SCULLING_CONVENTIONAL[n], start=1):
            rows[n - 1 - m][n - 1] = c
    if exact:
        return rows
    return np.array([[float(v) for v in r] for r in rows])


def sculling_single_chain_table(n: int, *, exact: bool = False):
    """Start-up and steady single-chain sculling coefficients, shape (N, N − 1), laid out as
    :func:`strapdown.algorithms.structures.single_chain_table`."""
    n = _n(n)
    rows = [[Fraction(0)] * max(n - 1, 1) for _ in range(n)]
    for m in range(1, n):
        rows[m][:m] = tables.SCULLING_SINGLE_CHAIN[m + 1]
    if exact:
        return rows
    return np.array([[float(v) for v in r] for r in rows])


@dataclass(frozen=True)
class BodyIncrements:
    """Per-update body-frame increments (at each update's start attitude).

    Attributes
    ----------
    phi, dv, dr : ndarray of shape (m, 3)
        Rotation vector (rad), compensated velocity increment (m/s) and position increment
        (m).
    h, update_period : float
        Sample interval and time between updates (s).
    structure : str
    n : int
    """

    phi: NDArray[np.float64]
    dv: NDArray[np.float64]
    dr: NDArray[np.float64]
    h: float
    update_period: float
    structure: NavStructure
    n: int


def _inputs(gyro: ArrayLike, accel: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    g = as_vectors(gyro, "gyro increments")
    a = as_vectors(accel, "accelerometer increments")
    if g.ndim != 2 or a.shape != g.shape:
        raise ValueError(f"gyro and accelerometer increments must both have shape (n, 3); got "
                         f"{g.shape} and {a.shape}")
    return np.ascontiguousarray(g), np.ascontiguousarray(a)


def body_increments(gyro: ArrayLike, accel: ArrayLike, n: int, *, h: float,
                    structure: NavStructure = "conventional", sculling: bool = True,
                    velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> BodyIncrements:
    """Coning, sculling and scrolling compensated body increments (module docstring).

    Parameters
    ----------
    gyro, accel : array_like of shape (k, 3)
        Gyro (rad) and accelerometer (m/s) increments over consecutive intervals ``h``.
    n : int
        N, samples per update (conventional) or the single chain's N.
    h : float
        Sample interval (s).
    structure : {"conventional", "single-chain"}
    sculling : bool
        False drops the sculling pair terms (rotation compensation only), to show their
        effect; the coning correction stays.
    velocity_set : {"coning-force", "classical"}
        The conventional structure's sculling pairs (module docstring); the single chain
        has one set.

    Notes
    -----
    The conventional structure drops a tail of fewer than N samples.
    """
    g, a = _inputs(gyro, accel)
    n, h = _n(n), positive(h, "h (sample interval)")
    velocity_set = _velocity_set(velocity_set)
    if _structure(structure) == "conventional":
        m = g.shape[0] // n
        if m < 1:
            raise ValueError(f"N = {n} needs at least {n} samples, got {g.shape[0]}")
        kc = np.ascontiguousarray(coefficient_set("table3", n).matrix)
        ks = sculling_matrix(n, velocity_set=velocity_set) if sculling else np.zeros((n, n))
        out = np.empty((3, m, 3))
        _nav_kernels.conventional_body_kernel(g[: m * n], a[: m * n], kc, ks, h, out[0],
                                              out[1], out[2])
        return BodyIncrements(out[0], out[1], out[2], h, n * h, structure, n)
    if g.shape[0] < 1:
        raise ValueError("the single chain needs at least one sample")
    tab_s = sculling_single_chain_table(n)
    out = np.empty((3, g.shape[0], 3))
    _nav_kernels.single_chain_body_kernel(g, a, single_chain_table(n),
                                          tab_s if sculling else np.zeros_like(tab_s), h,
                                          out[0], out[1], out[2])
    return BodyIncrements(out[0], out[1], out[2], h, h, structure, n)


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
    _nav_kernels.inertial_kernel(b.phi, b.dv, b.dr, b.update_period, q0, v0, p0, q, v, p)
    t = t0 + np.arange(m + 1) * b.update_period
    startup = min(b.n - 1, m) if structure == "single-chain" else 0
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
    rational coefficients and the plain-Python twin of the kernels
    (:mod:`strapdown.algorithms._nav_reference`) at ``digits`` significant digits; the
    errors against the exact velocity and position are converted to float64 at the end.
    """
    import mpmath

    from strapdown._core.backend import MPMATH
    from strapdown.algorithms import _nav_reference as ref
    from strapdown.algorithms.precision import MAX_MP_SAMPLES

    n, h = _n(n), positive(h, "h (sample interval)")
    samples, digits = _positive_int(samples, "samples"), _positive_int(digits, "digits")
    if samples > MAX_MP_SAMPLES:
        raise ValueError(f"{samples} samples exceed the arbitrary-precision limit of "
                         f"{MAX_MP_SAMPLES}")
    if digits < 17:
        raise ValueError(f"digits must be at least 17 (float64 is ~16), got {digits}")
    _structure(structure)
    _velocity_set(velocity_set)
    with mpmath.workdps(digits):
        hm = mpmath.mpf(h)
        edges = [k * hm for k in range(samples + 1)]
        g = [motion.increment_mp(a, b) for a, b in itertools.pairwise(edges)]
        a = [motion.velocity_increment_mp(a, b) for a, b in itertools.pairwise(edges)]
        zero = mpmath.mpf(0)

        def mp(rows):
            return [[mpmath.mpf(v.numerator) / v.denominator for v in r] for r in rows]

        if structure == "conventional":
            kc = mp(coefficient_set("table3", n).exact)
            body = ref.conventional_body(g, a, kc, mp(sculling_matrix(
                n, exact=True, velocity_set=velocity_set)), hm, zero)
            period, startup = n * hm, 0
        else:
            from strapdown.algorithms.structures import single_chain_coefficients

            tab_c = [[Fraction(0)] * max(n - 1, 1) for _ in range(n)]
            for m_ in range(1, n):
                tab_c[m_][:m_] = single_chain_coefficients(m_ + 1)
            body = ref.single_chain_body(g, a, mp(tab_c), mp(sculling_single_chain_table(
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


#: The rate-input velocity algorithms: the duals of the rate-input coning algorithms of
#: :mod:`strapdown.algorithms.rate` (module docstring).
RATE_VELOCITY_ALGORITHMS = ("rate-single", "rate-three")


def rate_sculling_law(coefficients: str = "derived", algorithm: str = "rate-single"
                      ) -> ScullingLaw:
    """Classical-sculling law of the rate-input update (module docstring), ``h`` = ``td``:
    the coning law of the same rate algorithm with the same coefficients (the duality)."""
    laws = {"rate-single": tables.RATE_SINGLE_DRIFT, "rate-three": tables.RATE_THREE_DRIFT}
    if algorithm not in laws:
        raise ValueError(f"unknown rate-input velocity algorithm {algorithm!r}; choose one of "
                         f"{', '.join(RATE_VELOCITY_ALGORITHMS)}")
    if coefficients not in laws[algorithm]:
        raise ValueError(f"unknown rate-input coefficients {coefficients!r}; choose one of "
                         f"{', '.join(laws[algorithm])}")
    order, c = laws[algorithm][coefficients]
    return ScullingLaw(order, c)


def _rate_three_body(w, f, td: float, coefficients: str):
    """Body increments of the three-period dual (an update every 3 td, samples 0 … 3m)."""
    m = (w.shape[0] - 1) // 3
    ws = [w[j: 3 * m + j: 3][:m] for j in range(4)]
    fs = [f[j: 3 * m + j: 3][:m] for j in range(4)]
    wts = [float(x) for x in tables.RATE_THREE_WEIGHTS]
    alpha = td * sum(c * x for c, x in zip(wts, ws, strict=True))
    ups = td * sum(c * x for c, x in zip(wts, fs, strict=True))
    k = [float(x) for x in tables.RATE_THREE[coefficients]]  # type: ignore[index]
    pairs = tables.RATE_THREE_PAIRS
    beta = td * td * sum(kk * np.cross(ws[i], ws[j]) for kk, (i, j) in zip(k, pairs, strict=True))
    scul = td * td * sum(kk * (np.cross(ws[i], fs[j]) + np.cross(fs[i], ws[j]))
                         for kk, (i, j) in zip(k, pairs, strict=True))
    return alpha, ups, alpha + beta, scul


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
    rate_sculling_law(coefficients, algorithm)  # validates both names
    need = 2 if algorithm == "rate-single" else 4
    if w.shape[0] < need:
        raise ValueError(f"{algorithm} needs at least {need} samples, got {w.shape[0]}")
    td = positive(td, "td (sample interval)")
    q0, v0, p0 = _state(q0, v0, p0)
    if algorithm == "rate-single":
        c = float(tables.RATE_SINGLE[coefficients])  # type: ignore[index]
        w0, w1, f0, f1 = w[:-1], w[1:], f[:-1], f[1:]
        th, ups = 0.5 * td * (w0 + w1), 0.5 * td * (f0 + f1)
        phi = th + c * td * td * np.cross(w0, w1)
        scul = c * td * td * (np.cross(w0, f1) + np.cross(f0, w1))
        period, n, structure = td, 1, "single-chain"
    else:
        th, ups, phi, scul = _rate_three_body(w, f, td, coefficients)
        period, n, structure = 3 * td, 3, "conventional"
    dv = ups + 0.5 * np.cross(th, ups) + np.cross(th, np.cross(th, ups)) / 6.0 + scul
    dr = 0.5 * period * dv
    m = phi.shape[0]
    q, v, p = np.empty((m + 1, 4)), np.empty((m + 1, 3)), np.empty((m + 1, 3))
    _nav_kernels.inertial_kernel(np.ascontiguousarray(phi), np.ascontiguousarray(dv),
                                 np.ascontiguousarray(dr), period, q0, v0, p0, q, v, p)
    t = float(finite_array(t0, "t0")) + np.arange(m + 1) * period
    return InertialSolution(t, q, v, p, structure, n, td, period, 0)  # type: ignore[arg-type]
