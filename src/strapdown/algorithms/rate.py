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

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_quaternions, finite_array, first_bad_step
from strapdown.algorithms import _kernels, tables
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.algorithms.family import (
    DriftLaw,
    Family,
    RateAlgorithmName,
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
    "RK4_DRIFT",
    "RK4_STEPS",
    "UNIFORM_TOLERANCE",
    "RateRecord",
    "check_rate_record",
    "rate_attitude",
    "single_period_algorithm",
    "three_period_algorithm",
]

F = Fraction
#: Coefficient sets of the rate algorithms (:data:`~strapdown.algorithms.family.RateCoefficients`).
COEFFICIENTS: tuple[RateCoefficients, ...] = get_args(RateCoefficients)
#: RK4 step variants (:data:`~strapdown.algorithms.family.Rk4Step`).
RK4_STEPS: tuple[Rk4Step, ...] = get_args(Rk4Step)
#: Classical-coning drift (order, c) of RK4, drift = −c·a²Ω(Ωtd)^order; derived symbolically
#: by :func:`strapdown.design.rk4_classical_coning_drift` (re-derived in the test suite).
RK4_DRIFT = tables.RK4_DRIFT
#: Relative spread of sample intervals tolerated as "uniform".
UNIFORM_TOLERANCE = 1e-6


@dataclass(frozen=True)
class RateRecord:
    """Validated uniformly sampled rates."""

    t: NDArray[np.float64]
    omega: NDArray[np.float64]
    td: float


def check_rate_record(t: ArrayLike, omega: ArrayLike, *, min_samples: int = 2) -> RateRecord:
    """Validate time stamps and rates; errors name the offending row.

    Raises on NaN/inf (row given), shape mismatch, non-increasing or
    duplicated time stamps, non-uniform spacing beyond
    :data:`UNIFORM_TOLERANCE`, and records shorter than ``min_samples``.
    """
    t = np.asarray(t, dtype=np.float64)
    w = np.asarray(omega, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"t must be 1-D time stamps of shape (n,), got shape {t.shape}")
    if w.shape != (t.size, 3):
        raise ValueError(f"rates must have shape ({t.size}, 3) to match t, got {w.shape}")
    for name, arr in (("t", t), ("rates", w)):
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
    td = float((t[-1] - t[0]) / (t.size - 1))  # nominal interval: O(n), no sort
    if np.any(np.abs(d - td) > UNIFORM_TOLERANCE * td):
        # something is off: locate it against the robust (median) interval
        med = float(np.median(d))
        off = np.abs(d - med) > UNIFORM_TOLERANCE * med
        if np.any(off):
            row = int(np.argmax(off)) + 1
            raise ValueError(f"non-uniform sampling between samples {row} and {row + 1}: "
                             f"interval {float(d[row - 1]):.9g} s against the median "
                             f"{float(med):.9g} s (tolerance {UNIFORM_TOLERANCE:g} relative); "
                             "rate algorithms need uniform samples — split logs at gaps")
        td = med
    return RateRecord(t, w, td)


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


class _RateFamily(Family):
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
        sliding = spec.structure == "sliding"
        startup = single_period_algorithm(_coefficients(spec)) if sliding else None
        return _windowed(w, self.windowed(spec), rec.td, float(rec.t[0]), _q0(q0), sliding,
                         startup)

    def propagation(self, spec: AlgorithmSpec) -> dict[str, Any]:
        w = self.windowed(spec)
        sliding = spec.structure == "sliding"
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


class RateSingle(_RateFamily):
    """``rate-single``: ΔΦ = td/2 (ω₀ + ω₁) + c td² ω₀ × ω₁, an update every td."""

    name = "rate-single"
    reference = ("Wang, Wang & Wang: single-period rate algorithm (start-up form; c = 1/12 "
                 "as printed, c = 1/6 derived)")

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        return single_period_algorithm(_coefficients(spec))

    def min_samples(self, spec: AlgorithmSpec) -> int:
        return 2

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return h

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*tables.RATE_SINGLE_DRIFT[_coefficients(spec)])

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        from strapdown.algorithms.precision import run_windowed_mp

        return run_windowed_mp(motion, self.windowed(spec), h=h, updates=samples - 1,
                               digits=digits)


class RateThree(_RateFamily):
    """``rate-three``: the three-period cubic-fit algorithm, conventional or sliding."""

    name = "rate-three"
    structures: ClassVar[tuple[StructureName, ...]] = ("conventional", "sliding")
    reference = ("Wang, Wang & Wang: three-period cubic-fit algorithm, eqs. 4-17 as "
                 "reconstructed; sliding scheme eqs. 20-29")

    def windowed(self, spec: AlgorithmSpec) -> WindowedAlgorithm:
        return three_period_algorithm(_coefficients(spec))

    def min_samples(self, spec: AlgorithmSpec) -> int:
        return 4

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return h if spec.structure == "sliding" else 3 * h

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw:
        return DriftLaw(*tables.RATE_THREE_DRIFT[_coefficients(spec)])

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        from strapdown.algorithms.precision import run_windowed_mp

        c = _coefficients(spec)
        if spec.structure == "sliding":
            return run_windowed_mp(motion, self.windowed(spec), h=h, updates=samples - 3,
                                   digits=digits, sliding=True,
                                   startup=single_period_algorithm(c))
        return run_windowed_mp(motion, self.windowed(spec), h=h, updates=(samples - 1) // 3,
                               digits=digits)


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
        if spec.rk4_step != "2td" or spec.structure != "conventional":
            raise ValueError("the filter's rk4 is the 2td step, conventional structure")
        i0, f0 = np.zeros(0, np.int64), np.zeros(0)
        return dict(is_rate=True, offsets=i0, weights=f0, pi=i0, pj=i0, pc=f0, stride=2,
                    span=2, end_off=2, lag=1, start_c=0.0, rk4=True)


#: The families this module defines, in registry order.
FAMILIES: tuple[Family, ...] = (RateSingle(), RateThree(), Rk4())
#: Their names (:data:`~strapdown.algorithms.family.RateAlgorithmName`), in registry order.
ALGORITHMS: tuple[RateAlgorithmName, ...] = get_args(RateAlgorithmName)


def _q0(q0: ArrayLike | None) -> NDArray[np.float64]:
    if q0 is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q = as_quaternions(q0, "q0")
    if q.shape != (4,):
        raise ValueError(f"q0 must have shape (4,), got {q.shape}")
    return q / np.linalg.norm(finite_array(q, "q0"))
