"""Angular-rate-input attitude algorithms (Wang, Wang & Wang; seed 001, papers.md).

Many MEMS gyros output rates, not increments. On uniformly spaced rate
samples ``ω_k`` at ``t_k = t_0 + k·td``:

``rate-single``
    Single-period rotation vector, ``ΔΦ = td/2 (ω_{k−1} + ω_k) + c td² ω_{k−1} × ω_k``.
    ``paper``: c = 1/12 (the seed's start-up form) — truly second order under
    coning, no better than c = 0; ``derived``: c = 1/6 (designer, quadrature
    error included) — fourth order.
``rate-three``
    Three-period algorithm: ω1…ω4 at 0, T/3, 2T/3, T (T = 3 td), cubic fit
    ⇒ α = T/8 (ω1 + 3ω2 + 3ω3 + ω4), β = td² Σ_{i<j} k_ij ω_i × ω_j with lag
    sums split evenly. ``paper``: lag sums fitted to the coning term alone
    (seed eqs. 14–16 as reconstructed) — claims (Ωtd)^8, is (Ωtd)^4;
    ``derived``: the designer with the quadrature error — truly (Ωtd)^8.
    Structures: ``conventional`` (an update every 3 td) and ``sliding``
    (seed eqs. 20–29: Q(t1), Q(t2) by single-period steps, then
    ``Q(t_k) = Q(t_{k−3}) ⊗ q(ΔΦ[t_{k−3}, t_k])`` every td — three interleaved
    three-period chains).
``rk4``
    Quaternion 4th-order Runge–Kutta on ``q̇ = ½ q ⊗ ω``, normalised after
    each step. ``rk4_step="2td"`` (default, the seed's baseline: step 2 td,
    middle rate = the middle sample) is fourth order, drift +a²Ω(Ωtd)⁴/60;
    ``"td-interp"`` (step td, middle rate = mean of the ends) is second order,
    drift −a²Ω(Ωtd)²/12 (both derived in :func:`strapdown.design.rk4_classical_coning_drift`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from strapdown._core.validation import as_quaternions, finite_array, first_bad_step
from strapdown.algorithms import _kernels
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.algorithms.structures import AttitudeSolution, _windowed

__all__ = [
    "ALGORITHMS",
    "COEFFICIENTS",
    "RK4_DRIFT",
    "RK4_STEPS",
    "UNIFORM_TOLERANCE",
    "RateRecord",
    "check_rate_record",
    "predicted_drift_law",
    "rate_attitude",
    "single_period_algorithm",
    "three_period_algorithm",
    "update_period",
]

F = Fraction
ALGORITHMS = ("rate-single", "rate-three", "rk4")
STRUCTURES = {"rate-single": ("conventional",), "rate-three": ("conventional", "sliding"),
              "rk4": ("conventional",)}
COEFFICIENTS = ("derived", "paper")
RK4_STEPS = ("2td", "td-interp")
#: Classical-coning drift (order, c) of RK4, drift = −c·a²Ω(Ωtd)^order; derived symbolically
#: by :func:`strapdown.design.rk4_classical_coning_drift` (re-derived in the test suite).
RK4_DRIFT = {"2td": (4, F(-1, 60)), "td-interp": (2, F(1, 12))}
#: Relative spread of sample intervals tolerated as "uniform".
UNIFORM_TOLERANCE = 1e-6


@dataclass(frozen=True)
class RateRecord:
    """Validated uniformly sampled rates."""

    t: np.ndarray
    omega: np.ndarray
    td: float


def check_rate_record(t, omega, *, min_samples: int = 2) -> RateRecord:
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


def single_period_algorithm(coefficients: str = "derived") -> WindowedAlgorithm:
    """The single-period rate algorithm as a windowed algorithm (update every td)."""
    c = _single_coefficient(coefficients)
    return WindowedAlgorithm("rate", 1, (0, 1), (F(1, 2), F(1, 2)), ((0, 1),), (c,),
                             f"rate-single ({coefficients})")


def _single_coefficient(coefficients: str) -> Fraction:
    if coefficients == "paper":
        return F(1, 12)
    if coefficients == "derived":
        from strapdown.design import derive, rate_structure

        return derive(rate_structure(1)).coefficients[0]
    raise ValueError(f"rate coefficients must be one of {', '.join(COEFFICIENTS)}, "
                     f"got {coefficients!r}")


def three_period_algorithm(coefficients: str = "derived") -> WindowedAlgorithm:
    """The three-period rate algorithm (update every 3 td)."""
    from strapdown.design import derive, three_period_structure

    if coefficients not in COEFFICIENTS:
        raise ValueError(f"rate coefficients must be one of {', '.join(COEFFICIENTS)}, "
                         f"got {coefficients!r}")
    d = derive(three_period_structure(), quadrature=coefficients == "derived")
    alg = d.algorithm()
    return WindowedAlgorithm(alg.input, alg.update, alg.offsets, alg.weights, alg.pairs,
                             alg.pair_coefficients, f"rate-three ({coefficients})")


def update_period(algorithm: str, td: float, *, structure: str = "conventional",
                  rk4_step: str = "2td") -> float:
    """Time between attitude outputs of a rate algorithm sampled every ``td``."""
    if algorithm == "rate-single":
        return td
    if algorithm == "rate-three":
        return td if structure == "sliding" else 3 * td
    if algorithm == "rk4":
        _check_step(rk4_step)
        return 2 * td if rk4_step == "2td" else td
    raise ValueError(f"unknown rate algorithm {algorithm!r}; choose one of {', '.join(ALGORITHMS)}")


def predicted_drift_law(algorithm: str, *, coefficients: str = "derived",
                        rk4_step: str = "2td") -> tuple[int, Fraction]:
    """Classical-coning drift law ``(order, c)``: drift = −c·a²Ω(Ωtd)^order (the true one)."""
    from strapdown.design import classical_coning_drift, rate_structure, three_period_structure

    if algorithm == "rk4":
        _check_step(rk4_step)
        return RK4_DRIFT[rk4_step]
    if algorithm == "rate-single":
        return classical_coning_drift(rate_structure(1), [_single_coefficient(coefficients)])
    if algorithm == "rate-three":
        alg = three_period_algorithm(coefficients)
        return classical_coning_drift(three_period_structure(), alg.pair_coefficients)
    raise ValueError(f"unknown rate algorithm {algorithm!r}; choose one of {', '.join(ALGORITHMS)}")


def _check_step(step):
    if step not in RK4_STEPS:
        raise ValueError(f"rk4_step must be one of {', '.join(RK4_STEPS)}, got {step!r}")


def rate_attitude(t, omega, *, algorithm: str, structure: str = "conventional",
                  coefficients: str = "derived", rk4_step: str = "2td",
                  q0=None) -> AttitudeSolution:
    """Attitude from uniformly sampled rates.

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
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown rate algorithm {algorithm!r}; choose one of "
                         f"{', '.join(ALGORITHMS)}")
    if structure not in STRUCTURES[algorithm]:
        raise ValueError(f"{algorithm} supports the structures {', '.join(STRUCTURES[algorithm])}"
                         f", not {structure!r}")
    need = {"rate-single": 2, "rate-three": 4, "rk4": 3 if rk4_step == "2td" else 2}[algorithm]
    rec = check_rate_record(t, omega, min_samples=need)
    q0 = _q0(q0)
    if algorithm == "rk4":
        _check_step(rk4_step)
        mode = 0 if rk4_step == "2td" else 1
        stride = 2 if mode == 0 else 1
        m = (rec.t.size - 1) // stride
        q = np.empty((m + 1, 4))
        _kernels.rk4_kernel(np.ascontiguousarray(rec.omega), rec.td, q0, mode, q)
        tt = rec.t[0] + np.arange(m + 1) * stride * rec.td
        return AttitudeSolution(tt, q, "rk4", None, rec.td, stride * rec.td,
                                np.zeros(m + 1, int))
    w = np.ascontiguousarray(rec.omega)  # validated once, by check_rate_record
    if algorithm == "rate-single":
        return _windowed(w, single_period_algorithm(coefficients), rec.td, float(rec.t[0]), q0,
                         False, None)
    return _windowed(w, three_period_algorithm(coefficients), rec.td, float(rec.t[0]), q0,
                     structure == "sliding", single_period_algorithm(coefficients))


def _q0(q0):
    if q0 is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q = as_quaternions(q0, "q0")
    if q.shape != (4,):
        raise ValueError(f"q0 must have shape (4,), got {q.shape}")
    return q / np.linalg.norm(finite_array(q, "q0"))
