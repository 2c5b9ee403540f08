"""Angular-rate-input attitude algorithms (Wang, Wang & Wang; see docs/references.md).

Many MEMS gyros output rates, not increments. On uniformly spaced rate
samples ``ω_k`` at ``t_k = t_0 + k·td``:

``rate-single``
    Single-period rotation vector, ``ΔΦ = td/2 (ω_{k−1} + ω_k) + c td² ω_{k−1} × ω_k``.
    ``paper``: c = 1/12 (the paper's start-up form) — truly second order under
    coning, no better than c = 0; ``derived``: c = 1/6 (designer, quadrature
    error included) — fourth order.
``rate-three``
    Three-period algorithm: ω1…ω4 at 0, T/3, 2T/3, T (T = 3 td), cubic fit
    ⇒ α = T/8 (ω1 + 3ω2 + 3ω3 + ω4), β = td² Σ_{i<j} k_ij ω_i × ω_j with lag
    sums split evenly. ``paper``: lag sums fitted to the coning term alone
    (the paper's eqs. 14–16 as reconstructed) — claims (Ωtd)^8, is (Ωtd)^4;
    ``derived``: the designer with the quadrature error — truly (Ωtd)^8.
    Structures: ``conventional`` (an update every 3 td) and ``sliding``
    (the paper's eqs. 20–29: Q(t1), Q(t2) by single-period steps, then
    ``Q(t_k) = Q(t_{k−3}) ⊗ q(ΔΦ[t_{k−3}, t_k])`` every td — three interleaved
    three-period chains).
``rk4``
    Quaternion 4th-order Runge–Kutta on ``q̇ = ½ q ⊗ ω``, normalised after
    each step. ``rk4_step="2td"`` (default, the paper's baseline: step 2 td,
    middle rate = the middle sample) is fourth order, drift +a²Ω(Ωtd)⁴/60;
    ``"td-interp"`` (step td, middle rate = mean of the ends) is second order,
    drift −a²Ω(Ωtd)²/12 (both derived in
    :func:`strapdown.design.rk4_classical_coning_drift`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_quaternions, finite_array, first_bad_step
from strapdown.algorithms import _kernels, tables
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.algorithms.family import (
    DriftLaw,
    Family,
    RateCoefficients,
    Rk4Step,
    StructureName,
)
from strapdown.algorithms.structures import AttitudeSolution, _windowed

if TYPE_CHECKING:
    from strapdown.algorithms.precision import MpSolution
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.truth.motions import Motion

__all__ = [
    "ALGORITHMS",
    "COEFFICIENTS",
    "FAMILIES",
    "JITTER_TOLERANCE",
    "RK4_DRIFT",
    "RK4_STEPS",
    "UNIFORM_TOLERANCE",
    "RateRecord",
    "check_rate_record",
    "rate_attitude",
    "resample_uniform",
    "single_period_algorithm",
    "three_period_algorithm",
]

F = Fraction
#: The rate-input families defined here, in registry order.
RateAlgorithmName = Literal["rate-single", "rate-three", "rk4", "rate-two"]
#: Coefficient sets of the rate algorithms (:data:`~strapdown.algorithms.family.RateCoefficients`).
COEFFICIENTS: tuple[RateCoefficients, ...] = get_args(RateCoefficients)
#: RK4 step variants (:data:`~strapdown.algorithms.family.Rk4Step`).
RK4_STEPS: tuple[Rk4Step, ...] = get_args(Rk4Step)
#: Classical-coning drift (order, c) of RK4, drift = −c·a²Ω(Ωtd)^order; derived symbolically
#: by :func:`strapdown.design.rk4_classical_coning_drift` (re-derived in the test suite).
RK4_DRIFT = tables.RK4_DRIFT
#: Relative spread of sample intervals within which time stamps count as exactly uniform:
#: such stamps are used as given, with td = (t[-1] − t[0]) / (n − 1).
UNIFORM_TOLERANCE = 1e-6
#: Largest deviation of a time stamp from the best-fit uniform grid, in sample periods, that
#: counts as jitter (beyond it the record is non-uniform: a gap, a drifting clock).
JITTER_TOLERANCE = 0.1


@dataclass(frozen=True)
class RateRecord:
    """Validated rates on a uniform grid (see :func:`check_rate_record`).

    Attributes
    ----------
    t : ndarray (n,)
        The uniform sample times the algorithms use: the time stamps themselves when they
        are uniform to :data:`UNIFORM_TOLERANCE` (and no period was given), else the
        nominal grid ``t[0] + k·td``.
    omega : ndarray (n, 3)
        Rates (rad/s) at ``t``: the samples as given, or interpolated onto the grid
        (``resampled``).
    td : float
        Nominal sample period (s).
    jitter : float
        Largest deviation of the time stamps from the best-fit uniform grid of period
        ``td``, in periods (0.005: ±0.5 % of td); for uniform stamps measured when first
        asked for (an O(n) pass the algorithms do not need).
    stamps : ndarray (n_stamps,) or None
        The time stamps as given when ``t`` is the nominal grid (None: ``t`` is them).
    resampled : bool
        Whether ``omega`` was interpolated onto the grid.
    """

    t: NDArray[np.float64]
    omega: NDArray[np.float64]
    td: float
    stamps: NDArray[np.float64] | None = None
    resampled: bool = False
    measured_jitter: float | None = field(default=None, repr=False)

    @functools.cached_property
    def jitter(self) -> float:
        """See the class docstring."""
        if self.measured_jitter is not None:
            return self.measured_jitter
        return _grid_fit(self.t if self.stamps is None else self.stamps, self.td)[1]


def _checked_arrays(stamps: ArrayLike, omega: ArrayLike, min_samples: int
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(t, omega, diff(t))`` as float64 after the shape, finiteness, length and
    monotonicity checks."""
    t = np.asarray(stamps, dtype=np.float64)
    w = np.asarray(omega, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"t must be 1-D time stamps of shape (n,), got shape {t.shape}")
    if w.shape != (t.size, 3):
        raise ValueError(f"rates must have shape ({t.size}, 3) to match t, got {w.shape}")
    for name, arr in (("t", t), ("rates", w)):
        # a finite sum means every value is finite (one pass, no temporary); a sum that
        # overflowed or met NaN/inf is checked element by element to name the row
        if not np.isfinite(np.add.reduce(arr, axis=None)):
            bad = ~np.isfinite(arr)
            if np.any(bad):
                row = int(np.argwhere(bad)[0][0])
                raise ValueError(f"{name} has NaN or infinity at row {row}")
    if t.size < min_samples:
        raise ValueError(f"the record has {t.size} samples; this algorithm needs at least "
                         f"{min_samples}")
    d = np.diff(t)
    fault = first_bad_step(d)
    if fault is not None:
        i, kind = fault
        raise ValueError(f"{kind} time stamp at row {i + 1}: t[{i + 1}] = {t[i + 1]!r} after "
                         f"t[{i}] = {t[i]!r}")
    return t, w, d


def _uniform(d: NDArray[np.float64], td: float) -> bool:
    """Every interval within :data:`UNIFORM_TOLERANCE` of ``td``: the same test as
    ``all(|d − td| ≤ tol·td)``, on the extremes (rounding of ``d − td`` is monotonic in
    ``d``), so two passes and no temporaries."""
    tol = UNIFORM_TOLERANCE * td
    return bool(d.max() - td <= tol and td - d.min() <= tol)


def _grid_fit(t: NDArray[np.float64], td: float | None) -> tuple[float, float]:
    """``(td, jitter)``: the period (least squares over every stamp unless given) and the
    largest deviation of the stamps from the best-fit line ``c + k·td``, in periods.

    Least squares, not the median interval: with stamps ``t_k = t_0 + k·T + e_k`` the
    median interval's error falls as n^-½ and accumulates over the record into a grid
    offset of many jitter amplitudes; the fitted slope's falls as n^-3/2 (σ_e √12 / n^3/2).
    One stamp within the tolerance moves it by at most 6·tol·T/n² — bounded influence.
    """
    k = np.arange(t.size, dtype=np.float64)
    rel = t - t[0]
    if td is None:
        kc = k - 0.5 * (t.size - 1)
        td = float(np.dot(kc, rel) / np.dot(kc, kc))
    resid = rel - k * td
    resid -= resid.mean()
    return td, float(np.max(np.abs(resid)) / td)


def resample_uniform(t: ArrayLike, values: ArrayLike, grid: ArrayLike) -> NDArray[np.float64]:
    """``values`` sampled at the times ``t`` interpolated onto ``grid`` (not-a-knot cubic
    spline per column).

    The interpolation error at a grid point ``δ`` from the nearest stamp is about
    ``δ·td³·|f⁗|/12`` — fourth order in the period, and small with δ for jitter (measured
    in ``tests/cli/test_jitter.py``: on spin + coning at 1 kHz with ±0.5 % jitter the
    resampled rates' attitude error equals the jitter-free one to three digits).
    """
    from scipy.interpolate import CubicSpline

    ts = np.asarray(t, dtype=np.float64)
    g = np.asarray(grid, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if ts.size < 2:
        raise ValueError("resampling needs at least 2 samples")
    return np.ascontiguousarray(CubicSpline(ts - ts[0], v, axis=0)(g - ts[0]))


def _non_uniform(d: NDArray[np.float64], jitter: float, tolerance: float) -> ValueError:
    """The error for stamps beyond the jitter tolerance, naming the most irregular interval."""
    med = float(np.median(d))
    row = int(np.argmax(np.abs(d - med))) + 1
    return ValueError(f"non-uniform sampling between samples {row} and {row + 1}: interval "
                      f"{float(d[row - 1]):.9g} s against the median {med:.9g} s; the time "
                      f"stamps stray up to {jitter:.3g} periods from a uniform grid (jitter "
                      f"tolerance {tolerance:g} period) — rate algorithms need uniform "
                      "samples: put them on the sensor's clock, t = "
                      "strapdown.io.timing.fit_clock(t - t[0]).uniform_times() + t[0], or "
                      "interpolate them onto a uniform grid "
                      "(strapdown.algorithms.rate.resample_uniform)")


def check_rate_record(t: ArrayLike, omega: ArrayLike, *, min_samples: int = 2,
                      td: float | None = None, resample: bool = False,
                      jitter_tolerance: float = JITTER_TOLERANCE) -> RateRecord:
    """Validate time stamps and rates and put them on a uniform grid; errors name the row.

    Raises on NaN/inf (row given), shape mismatch, non-increasing or duplicated time
    stamps, records shorter than ``min_samples`` and stamps that stray from a uniform
    grid by more than ``jitter_tolerance`` periods (gaps, a drifting clock).

    Stamps uniform to :data:`UNIFORM_TOLERANCE` (relative spread of the intervals) are used
    as given, ``td = (t[-1] − t[0]) / (n − 1)``. Jittered stamps — every one within
    ``jitter_tolerance`` periods of the best-fit line ``c + k·td`` — give the nominal period
    ``td`` by least squares (or ``td`` as given, the sensor's rate) and the grid
    ``t[0] + k·td``: with ``resample`` false the samples are taken to lie on it (the sensor
    samples on its own clock, the stamps jitter: nothing to correct), with ``resample`` the
    rates are interpolated onto it (:func:`resample_uniform`; the samples were taken at the
    stamps), the grid ending at the last stamp. The jitter seen is
    :attr:`RateRecord.jitter`.

    Parameters
    ----------
    t : array_like (n,)
        Time stamps (s), strictly increasing.
    omega : array_like (n, 3)
        Rates (rad/s).
    min_samples : int
        Fewest samples the algorithm needs.
    td : float, optional
        The nominal period (s), e.g. ``1 / sample_rate_hz``; default from the stamps.
    resample : bool
        Interpolate the rates onto the uniform grid instead of taking them to lie on it.
    jitter_tolerance : float
        Largest deviation of a stamp from the uniform grid, in periods.
    """
    ts, w, d = _checked_arrays(t, omega, min_samples)
    if td is None:
        td_end = float((ts[-1] - ts[0]) / (ts.size - 1))  # nominal interval: O(n), no sort
        if _uniform(d, td_end):
            return RateRecord(ts, w, td_end)
        med = float(np.median(d))
        if _uniform(d, med):
            return RateRecord(ts, w, med)
    elif not td > 0 or not np.isfinite(td):
        raise ValueError(f"the sample period must be positive and finite, got {td!r}")
    period, jitter = _grid_fit(ts, None if td is None else float(td))
    if jitter > jitter_tolerance:
        if td is not None and _grid_fit(ts, None)[1] <= jitter_tolerance:
            raise ValueError(f"the time stamps are not at the given sample period {td:.9g} s "
                             f"({1 / td:.9g} Hz): they stray up to {jitter:.3g} periods from "
                             f"its grid, but lie on one of period {_grid_fit(ts, None)[0]:.9g} s")
        raise _non_uniform(d, jitter, jitter_tolerance)
    if not resample:
        grid = ts[0] + np.arange(ts.size) * period
        return RateRecord(grid, w, period, stamps=ts, measured_jitter=jitter)
    m = min(ts.size, int(np.floor((ts[-1] - ts[0]) / period * (1 + 1e-12))) + 1)
    if m < min_samples:
        raise ValueError(f"the resampled record has {m} samples; this algorithm needs at least "
                         f"{min_samples}")
    grid = ts[0] + np.arange(m) * period
    return RateRecord(grid, resample_uniform(ts, w, grid), period, stamps=ts,
                      resampled=True, measured_jitter=jitter)


def single_period_algorithm(coefficients: RateCoefficients = "derived") -> WindowedAlgorithm:
    """The single-period rate algorithm as a windowed algorithm (update every td)."""
    c = _single_coefficient(coefficients)
    return WindowedAlgorithm("rate", 1, (0, 1), (F(1, 2), F(1, 2)), ((0, 1),), (c,),
                             f"rate-single ({coefficients})")


def _single_coefficient(coefficients: RateCoefficients) -> Fraction:
    return tables.RATE_SINGLE[_rate_coefficients(coefficients)]


def _rate_coefficients(name: object) -> RateCoefficients:
    """``name`` if it is a rate coefficient set, else ValueError listing the sets."""
    if name not in COEFFICIENTS:
        raise ValueError(f"rate coefficients must be one of {', '.join(COEFFICIENTS)}, "
                         f"got {name!r}")
    return name


def three_period_algorithm(coefficients: RateCoefficients = "derived") -> WindowedAlgorithm:
    """The three-period rate algorithm (update every 3 td), coefficients from
    :data:`strapdown.algorithms.tables.RATE_THREE`."""
    coefficients = _rate_coefficients(coefficients)
    return WindowedAlgorithm("rate", 3, (0, 1, 2, 3), tables.RATE_THREE_WEIGHTS,
                             tables.RATE_THREE_PAIRS, tables.RATE_THREE[coefficients],
                             f"rate-three ({coefficients})")


def _check_step(step: object) -> Rk4Step:
    if step not in RK4_STEPS:
        raise ValueError(f"rk4_step must be one of {', '.join(RK4_STEPS)}, got {step!r}")
    return step


def rate_attitude(t: ArrayLike, omega: ArrayLike, *, algorithm: RateAlgorithmName,
                  structure: StructureName = "conventional",
                  coefficients: RateCoefficients = "derived", rk4_step: Rk4Step = "2td",
                  q0: ArrayLike | None = None) -> AttitudeSolution:
    """Attitude from uniformly sampled rates.

    A convenience over :class:`~strapdown.algorithms.spec.AlgorithmSpec` for the rate
    families.

    Parameters
    ----------
    t : array_like (n,)
        Sample times (s), strictly increasing and uniform.
    omega : array_like (n, 3)
        Body rates (rad/s).
    algorithm : {"rate-single", "rate-three", "rk4"}
    structure : {"conventional", "sliding"}
        ``sliding`` exists for ``rate-three`` only.
    coefficients : {"derived", "paper"}
        Not used by ``rk4``.
    rk4_step : {"2td", "td-interp"}
    q0 : array_like (4,), optional
        Attitude at ``t[0]``.

    Returns
    -------
    AttitudeSolution
        Outputs start at ``t[0]``; ``chain`` marks the sliding scheme's three chains.
    """
    from strapdown.algorithms.spec import AlgorithmSpec

    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown rate algorithm {algorithm!r}; choose one of "
                         f"{', '.join(ALGORITHMS)}")
    spec = AlgorithmSpec(algorithm, structure=structure, rk4_step=rk4_step,
                         coefficients=None if algorithm == "rk4" else coefficients)
    return spec.run_rates(t, omega, q0=q0)


def _coefficients(spec: AlgorithmSpec) -> RateCoefficients:
    """The rate coefficient set a spec runs (the family default when it names none)."""
    return _rate_coefficients(spec.resolved_coefficients)


class WindowedRateFamily(Family):
    """Shared by the windowed rate families: validated record in, attitude out."""

    input_kind = "rate"
    default_coefficients: ClassVar[RateCoefficients | None] = "derived"
    reference = ""

    def coefficient_names(self) -> tuple[RateCoefficients, ...]:
        return COEFFICIENTS

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        """The configured windowed algorithm (what the C exporter and the filter need)."""
        raise NotImplementedError

    def run(self, spec: AlgorithmSpec, data: ArrayLike, *, h: float, t: ArrayLike | None = None,
            t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
        if t is None:
            raise ValueError(f"{self.name} needs the sample times t of the rates")
        rec = check_rate_record(t, data, min_samples=self.min_samples(spec))
        w = np.ascontiguousarray(rec.omega)  # validated once, by check_rate_record
        sliding = spec.update_structure.interleaved
        startup = single_period_algorithm(_coefficients(spec)) if sliding else None
        return _windowed(w, self.windowed(spec), rec.td, float(rec.t[0]), _q0(q0), sliding,
                         startup)

    def min_samples(self, spec: AlgorithmSpec) -> int:
        """One window: its history, then ``span + 1`` rate samples."""
        w = self.windowed(spec)
        return w.history + w.span + 1

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return spec.update_structure.update_period(self.windowed(spec).update, h)

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        from strapdown.algorithms.precision import run_windowed_mp

        w = self.windowed(spec)
        if spec.update_structure.interleaved:  # the sliding scheme, started by single-period steps
            return run_windowed_mp(motion, w, h=h, updates=samples - w.span, digits=digits,
                                   sliding=True,
                                   startup=single_period_algorithm(_coefficients(spec)))
        return run_windowed_mp(motion, w, h=h, updates=(samples - 1 - w.span + w.update)
                               // w.update, digits=digits)

    def propagation(self, spec: AlgorithmSpec) -> dict[str, Any]:
        w = self.windowed(spec)
        sliding = spec.update_structure.interleaved
        # the sliding scheme starts with single-period steps of the same coefficient set
        start_c = (float(single_period_algorithm(_coefficients(spec))
                         .pair_coefficients[0]) if sliding else 0.0)
        return dict(is_rate=True, offsets=np.array(w.offsets, np.int64),
                    weights=np.array([float(x) for x in w.weights]),
                    pi=np.array([p[0] for p in w.pairs], np.int64),
                    pj=np.array([p[1] for p in w.pairs], np.int64),
                    pc=np.array([float(c) for c in w.pair_coefficients]),
                    stride=1 if sliding else w.update, span=w.span, end_off=w.span,
                    lag=w.span if sliding else 1, start_c=start_c, rk4=False)


class RateSingle(WindowedRateFamily):
    """``rate-single``: ΔΦ = td/2 (ω₀ + ω₁) + c td² ω₀ × ω₁, an update every td."""

    name = "rate-single"
    reference = ("Wang, Wang & Wang: single-period rate algorithm (start-up form; c = 1/12 "
                 "as printed, c = 1/6 derived)")

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        return single_period_algorithm(_coefficients(spec))

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*tables.RATE_SINGLE_DRIFT[_coefficients(spec)])


class RateThree(WindowedRateFamily):
    """``rate-three``: the three-period cubic-fit algorithm, conventional or sliding."""

    name = "rate-three"
    structures: ClassVar[tuple[StructureName, ...]] = ("conventional", "sliding")
    reference = ("Wang, Wang & Wang: three-period cubic-fit algorithm, eqs. 4-17 as "
                 "reconstructed; sliding scheme eqs. 20-29")

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        return three_period_algorithm(_coefficients(spec))

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*tables.RATE_THREE_DRIFT[_coefficients(spec)])


class Rk4(Family):
    """``rk4``: quaternion fourth-order Runge–Kutta on q̇ = ½ q ⊗ ω, normalised each step."""

    name = "rk4"
    input_kind = "rate"
    options = frozenset({"rk4_step"})
    reference = ("Quaternion 4th-order Runge-Kutta on q' = q (x) [0, w] / 2, step 2 td "
                 "(Wang, Wang & Wang's baseline)")

    def check(self, spec: AlgorithmSpec) -> None:
        super().check(spec)
        _check_step(spec.rk4_step)

    def min_samples(self, spec: AlgorithmSpec) -> int:
        return 3 if spec.rk4_step == "2td" else 2

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return 2 * h if spec.rk4_step == "2td" else h

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*RK4_DRIFT[spec.rk4_step])

    def run(self, spec: AlgorithmSpec, data: ArrayLike, *, h: float, t: ArrayLike | None = None,
            t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
        if t is None:
            raise ValueError("rk4 needs the sample times t of the rates")
        rec = check_rate_record(t, data, min_samples=self.min_samples(spec))
        mode = 0 if spec.rk4_step == "2td" else 1
        stride = 2 if mode == 0 else 1
        m = (rec.t.size - 1) // stride
        q = np.empty((m + 1, 4))
        _kernels.rk4_kernel(np.ascontiguousarray(rec.omega), rec.td, _q0(q0), mode, q)
        tt = rec.t[0] + np.arange(m + 1) * stride * rec.td
        return AttitudeSolution(tt, q, "rk4", None, rec.td, stride * rec.td,
                                np.zeros(m + 1, int))

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        from strapdown.algorithms.precision import run_rk4_mp

        return run_rk4_mp(motion, h=h, samples=samples, step=spec.rk4_step, digits=digits)

    def propagation(self, spec: AlgorithmSpec) -> dict[str, Any]:
        if spec.rk4_step != "2td" or spec.update_structure.every_sample:
            raise ValueError("the filter's rk4 is the 2td step, conventional structure")
        i0, f0 = np.zeros(0, np.int64), np.zeros(0)
        return dict(is_rate=True, offsets=i0, weights=f0, pi=i0, pj=i0, pc=f0, stride=2,
                    span=2, end_off=2, lag=1, start_c=0.0, rk4=True)


class RateTwo(WindowedRateFamily):
    """``rate-two``: the designer's two-period algorithm, an update every 2 td.

    Rates at 0, td, 2td; ``α = td/3 (ω₀ + 4ω₁ + ω₂)`` (Simpson), ``β = td² Σ k_ij ω_i × ω_j``
    with the classical-coning optimum ``k = (3/10, 1/30, 3/10)`` for the pairs (0,1), (0,2),
    (1,2): ``derive(rate_structure(2))``, quadrature error included. Drift
    ``−37/15120 · a²Ω(Ωtd)⁶``, between rate-single (4th order) and rate-three (8th).
    One coefficient set, ``derived``.
    """

    name = "rate-two"
    reference = "strapdown designer: rate_structure(2) (Simpson quadrature, all pairs)"
    _PAIRS = ((0, 1), (0, 2), (1, 2))
    _WEIGHTS = (F(1, 3), F(4, 3), F(1, 3))
    _SETS: ClassVar[dict[RateCoefficients, tuple[F, ...]]] = {
        "derived": (F(3, 10), F(1, 30), F(3, 10))}
    _DRIFT: ClassVar[dict[RateCoefficients, tuple[int, F]]] = {"derived": (6, F(37, 15120))}

    def coefficient_names(self) -> tuple[RateCoefficients, ...]:
        return tuple(self._SETS)

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        c = _coefficients(spec)
        return WindowedAlgorithm("rate", 2, (0, 1, 2), self._WEIGHTS, self._PAIRS,
                                 self._SETS[c], f"rate-two ({c})")

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*self._DRIFT[_coefficients(spec)])


#: The families this module defines, in registry order.
FAMILIES: tuple[Family, ...] = (RateSingle(), RateThree(), Rk4(), RateTwo())
#: Their names (:data:`RateAlgorithmName`), in registry order.
ALGORITHMS: tuple[RateAlgorithmName, ...] = get_args(RateAlgorithmName)


def _q0(q0: ArrayLike | None) -> NDArray[np.float64]:
    if q0 is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q = as_quaternions(q0, "q0")
    if q.shape != (4,):
        raise ValueError(f"q0 must have shape (4,), got {q.shape}")
    return q / np.linalg.norm(finite_array(q, "q0"))
