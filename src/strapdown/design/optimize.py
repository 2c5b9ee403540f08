"""Numerical optimisation of coefficients against any motion and metric, with transfer checks.

The exact designer (:mod:`strapdown.design`) optimises against the
classical-coning series. Here any algorithm's coefficients are tuned by
simulation against any reference motion and metric, reproducibly:

* ``method="nelder-mead"`` — deterministic simplex from ``x0`` (scipy
  ``minimize``, ``xatol``/``fatol`` documented below);
* ``method="differential-evolution"`` — global search inside ``bounds``,
  seeded (scipy ``differential_evolution`` with ``seed``, ``workers=1``,
  ``polish=True``).

Optimising to one motion overfits (Plaksiy (2024)'s optimised sets do; see
docs/reproductions.md); :func:`transfer`
evaluates optimised sets on other motions, step sizes and cone angles.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize as so

from strapdown import analysis
from strapdown._core.validation import finite_array, positive, positive_int
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.algorithms.precision import run_windowed_mp
from strapdown.algorithms.structures import windowed
from strapdown.design import Structure
from strapdown.truth.motions import Motion

__all__ = [
    "METHODS",
    "METRICS",
    "ObjectiveMetric",
    "OptimizationResult",
    "OptimizerMethod",
    "TransferCase",
    "algorithm_from_groups",
    "optimize",
    "simulate_windowed",
    "transfer",
    "windowed_objective",
]

#: What an objective scores: the drift rate about the cone axis (or its norm without one), or
#: the largest error.
ObjectiveMetric = Literal["drift-rate", "max-error"]
METRICS: tuple[ObjectiveMetric, ...] = get_args(ObjectiveMetric)
#: The optimisers (see the module docstring).
OptimizerMethod = Literal["nelder-mead", "differential-evolution"]
METHODS: tuple[OptimizerMethod, ...] = get_args(OptimizerMethod)


def algorithm_from_groups(structure: Structure, values: ArrayLike) -> WindowedAlgorithm:
    """A structure's algorithm with its free groups set to ``values`` (one per group)."""
    vals = finite_array(values, "values")
    if vals.shape != (len(structure.groups),):
        raise ValueError(
            f"values must have shape ({len(structure.groups)},), one per group, got {vals.shape}"
        )
    coeffs = [0.0] * len(structure.pairs)
    for v, members in zip(vals, structure.groups, strict=True):
        for k, mult in members:
            coeffs[k] += float(mult) * float(v)
    if any(s != int(s) for s in structure.nodes):
        raise ValueError("nodes off the sample grid cannot run on a sample stream")
    return WindowedAlgorithm(structure.input, structure.update,
                             tuple(int(s) for s in structure.nodes),
                             structure.weights, structure.pairs, tuple(coeffs), structure.name)


def simulate_windowed(motion: Motion, algorithm: WindowedAlgorithm, *, h: float, updates: int,
                      digits: int | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Errors of a windowed algorithm on a motion (history sampled from the motion).

    Returns ``(t, err)`` with ``err`` the reference-frame error vectors at the
    ``updates + 1`` outputs starting at ``t = 0``.
    """
    h = positive(h, "h (sample interval)")
    updates = positive_int(updates, "updates")
    if digits is not None:
        s = run_windowed_mp(motion, algorithm, h=h, updates=updates, digits=digits)
        return s.t, s.err
    hist = algorithm.history
    n = hist + (updates - 1) * algorithm.update + algorithm.span + 1
    k = np.arange(-hist, n - hist)
    if algorithm.input == "increment":
        edges = np.append(k, k[-1] + 1) * h
        x = motion.increments(edges)
    else:
        x = motion.rate(k * h)
    sol = windowed(x, algorithm, h=h, t0=-hist * h, q0=motion.attitude(0.0))
    err, _ = analysis.attitude_errors(sol.t, sol.q, motion)
    return sol.t, err


def _metric(name: ObjectiveMetric, motion: Motion, t: NDArray[np.float64],
            err: NDArray[np.float64]) -> float:
    if name == "drift-rate":
        d = analysis.drift_rate(t, err, period=motion.period)
        axis = motion.cone_axis
        return abs(float(d.rate @ axis)) if axis is not None else float(np.linalg.norm(d.rate))
    if name == "max-error":
        return float(np.max(np.linalg.norm(err, axis=-1)))
    raise ValueError(f"unknown metric {name!r}; choose one of {', '.join(METRICS)}")


def windowed_objective(structure: Structure, motion: Motion, *, h: float, updates: int,
                       metric: ObjectiveMetric = "drift-rate", digits: int | None = None
                       ) -> Callable[[NDArray[np.float64]], float]:
    """Objective ``values → metric`` for a structure's free groups on one motion."""
    if metric not in METRICS:
        raise ValueError(f"unknown metric {metric!r}; choose one of {', '.join(METRICS)}")

    def f(values: NDArray[np.float64]) -> float:
        alg = algorithm_from_groups(structure, values)
        t, err = simulate_windowed(motion, alg, h=h, updates=updates, digits=digits)
        return _metric(metric, motion, t, err)

    return f


@dataclass(frozen=True)
class OptimizationResult:
    """Outcome of :func:`optimize`."""

    x: NDArray[np.float64]
    fun: float
    start: NDArray[np.float64]
    start_fun: float
    method: OptimizerMethod
    evaluations: int
    seed: int | None
    message: str


def optimize(objective: Callable[[NDArray[np.float64]], float], x0: ArrayLike, *,
             method: OptimizerMethod = "nelder-mead",
             bounds: Sequence[tuple[float, float]] | None = None, seed: int | None = None,
             xatol: float = 1e-12, fatol: float = 0.0, maxiter: int = 2000
             ) -> OptimizationResult:
    """Minimise ``objective`` reproducibly.

    Parameters
    ----------
    objective : callable
        ``x (k,) → float``; a metric such as :func:`windowed_objective` returns.
    x0 : array_like (k,)
        Start (e.g. the published coefficients).
    method : {"nelder-mead", "differential-evolution"}
    bounds : sequence of (low, high), optional
        Required by differential evolution; Nelder–Mead ignores them.
    seed : int, optional
        Differential evolution's seed (required for it: results must repeat).
    xatol, fatol, maxiter
        Nelder–Mead tolerances / iteration cap (differential evolution:
        ``tol=fatol``, ``maxiter``).
    """
    x0 = finite_array(x0, "x0").reshape(-1)
    f0 = float(objective(x0))
    if method == "nelder-mead":
        r = so.minimize(objective, x0, method="Nelder-Mead",
                        options={"xatol": xatol, "fatol": fatol, "maxiter": maxiter,
                                 "maxfev": 4 * maxiter})
        x, fun, nfev, msg = r.x, float(r.fun), int(r.nfev), str(r.message)
    elif method == "differential-evolution":
        if bounds is None or seed is None:
            raise ValueError("differential evolution needs bounds and a seed")
        r = so.differential_evolution(objective, bounds, seed=seed, workers=1, polish=True,
                                      tol=fatol, maxiter=maxiter, x0=x0)
        x, fun, nfev, msg = r.x, float(r.fun), int(r.nfev), str(r.message)
    else:
        raise ValueError(f"unknown method {method!r}; choose 'nelder-mead' or "
                         "'differential-evolution'")
    if f0 < fun:  # never return something worse than the start
        x, fun = x0, f0
    return OptimizationResult(np.asarray(x, float), fun, x0, f0, method, nfev, seed, msg)


@dataclass(frozen=True)
class TransferCase:
    """One evaluation condition for :func:`transfer`."""

    label: str
    motion: Motion
    h: float
    updates: int


def transfer(structure: Structure, sets: dict[str, Sequence[float]],
             cases: Sequence[TransferCase], *, metric: ObjectiveMetric = "drift-rate",
             digits: int | None = None) -> list[dict[str, Any]]:
    """Evaluate coefficient sets (group values) on other conditions.

    Returns one record per (case, set): ``case``, ``set``, ``metric``,
    ``value``, and ``ratio_to_first`` (value over the first set's value on the
    same case) — the transfer table.
    """
    if not sets:
        raise ValueError("sets must name at least one coefficient set")
    rows = []
    for case in cases:
        base = None
        for name, vals in sets.items():
            f = windowed_objective(structure, case.motion, h=case.h, updates=case.updates,
                                   metric=metric, digits=digits)
            v = f(np.asarray(vals, float))
            base = v if base is None else base
            rows.append({"case": case.label, "set": name, "metric": metric, "value": v,
                         "ratio_to_first": v / base if base else float("nan")})
    return rows
