"""Quaternion algorithms of the Ukrainian school on sub-interval increments (Plaksiy 2024).

``miller`` (A1, eq. 5)
    Thirds of the step: ``φ = θ* + α θ⁽¹⁾×θ⁽³⁾ + β θ⁽²⁾×(θ⁽³⁾ − θ⁽¹⁾)``; stated
    ``α = 33/80, β = 57/80`` (Miller 1983).
``panov`` (A2, eq. 6)
    Halves: ``φ = θ* + α θ⁽⁴⁾×θ*``, ``θ⁽⁴⁾`` the first half; stated ``α = 2/3``.
``power`` (A3, eq. 8)
    Halves, no intermediate rotation vector: ``ΔΛ = [1 − θ*²/8 + θ*⁴/384,
    ½θ*(1 − θ*²/24) + α θ⁽⁴⁾×θ*]``; stated ``α = 1/3``.

A1 and A2 turn φ into the step quaternion with the truncated series of eq. 7
(``1 − θ²/8 + θ⁴/384``, ``½θ(1 − θ²/24)``): a named algorithm choice, not the
exponential map. ``exact_exp=True`` uses the exponential map instead (for A3:
``exp(θ* + 2α θ⁽⁴⁾×θ*)``), separating truncation from coning error.
``Λ_n = Λ_{n−1} ∘ ΔΛ_n`` without renormalisation, as in the paper.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike

from strapdown._core.validation import as_quaternions, as_vectors, finite_array, positive
from strapdown.algorithms import _kernels
from strapdown.algorithms.family import Family
from strapdown.algorithms.structures import AttitudeSolution

if TYPE_CHECKING:
    from strapdown.algorithms.spec import AlgorithmSpec

__all__ = ["ALGORITHMS", "FAMILIES", "STATED", "QuaternionAlgorithm", "has_beta",
           "quaternion_attitude", "subintervals"]

#: Plaksiy's quaternion algorithms A1–A3, the families defined here.
QuaternionAlgorithmName = Literal["miller", "panov", "power"]
#: The algorithms (:data:`QuaternionAlgorithmName`).
ALGORITHMS: tuple[QuaternionAlgorithmName, ...] = get_args(QuaternionAlgorithmName)
#: Coefficients as the paper states them (α, β).
STATED: dict[QuaternionAlgorithmName, tuple[float, float]] = {
    "miller": (33 / 80, 57 / 80), "panov": (2 / 3, 0.0), "power": (1 / 3, 0.0)}
_MODE: dict[QuaternionAlgorithmName, int] = {"miller": 1, "panov": 2, "power": 3}


def subintervals(algorithm: QuaternionAlgorithmName) -> int:
    """Increments per step: 3 for Miller (thirds), 2 for Panov and power (halves)."""
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r}; choose one of {', '.join(ALGORITHMS)}")
    return 3 if algorithm == "miller" else 2


@dataclass(frozen=True)
class QuaternionAlgorithm:
    """One configured algorithm: name, coefficients, increment map."""

    name: QuaternionAlgorithmName
    alpha: float
    beta: float = 0.0
    exact_exp: bool = False

    def __post_init__(self) -> None:
        subintervals(self.name)
        finite_array([self.alpha, self.beta], "alpha/beta")
        if self.name != "miller" and self.beta != 0.0:
            raise ValueError(f"{self.name} has one coefficient (alpha); beta must be 0")

    @classmethod
    def stated(cls, name: QuaternionAlgorithmName, *, exact_exp: bool = False
               ) -> QuaternionAlgorithm:
        """The paper's stated coefficients."""
        subintervals(name)
        a, b = STATED[name]
        return cls(name, a, b, exact_exp)


def quaternion_attitude(increments: ArrayLike, algorithm: QuaternionAlgorithm, *, step: float,
                        t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
    """Run A1/A2/A3 on sub-interval increments.

    Parameters
    ----------
    increments : array_like (M·s, 3)
        Increments over the thirds (Miller, s = 3) or halves (s = 2) of each step.
    algorithm : QuaternionAlgorithm
    step : float
        Computation step ΔT (s).
    """
    if not isinstance(algorithm, QuaternionAlgorithm):
        raise ValueError("algorithm must be a QuaternionAlgorithm")
    theta = as_vectors(increments, "increments")
    if theta.ndim != 2:
        raise ValueError(f"increments must have shape (n, 3), got {theta.shape}")
    sub = subintervals(algorithm.name)
    if theta.shape[0] < sub or theta.shape[0] % sub:
        raise ValueError(f"{algorithm.name} needs whole steps of {sub} increments, "
                         f"got {theta.shape[0]}")
    step = positive(step, "step")
    if q0 is None:
        q0 = np.array([1.0, 0.0, 0.0, 0.0])
    else:
        q0 = as_quaternions(q0, "q0")
        if q0.shape != (4,):
            raise ValueError(f"q0 must have shape (4,), got {q0.shape}")
    m = theta.shape[0] // sub
    q = np.empty((m + 1, 4))
    _kernels.quaternion_increment_kernel(np.ascontiguousarray(theta), _MODE[algorithm.name],
                                         float(algorithm.alpha), float(algorithm.beta),
                                         bool(algorithm.exact_exp), q0, q)
    t = float(t0) + np.arange(m + 1) * step
    return AttitudeSolution(t, q, algorithm.name, None, step / sub, step, np.zeros(m + 1, int))


class _QuaternionFamily(Family):
    """Plaksiy's A1–A3: increments over sub-intervals of the computation step ΔT."""

    name: ClassVar[QuaternionAlgorithmName]
    input_kind = "increment"
    stepped = True
    #: Whether the algorithm has the second coefficient β (Miller's).
    has_beta: ClassVar[bool] = False
    options = frozenset({"alpha", "beta", "step", "exact_exp"})
    reference = ("Plaksiy (2024): quaternion algorithms A1 (Miller), A2 (Panov), A3 (power) "
                 "on the spherical (Krylov-angle) model")

    def check(self, spec: AlgorithmSpec) -> None:
        if spec.coefficients is not None:
            raise ValueError(f"{self.name} takes --alpha/--beta, not --coefficients")
        if spec.beta is not None and self.name != "miller":
            raise ValueError(f"{self.name} has one coefficient (--alpha)")
        self._step(spec)
        super().check(spec)

    def configured(self, spec: AlgorithmSpec) -> QuaternionAlgorithm:
        """The algorithm with the spec's coefficients (the paper's stated ones by default)."""
        a0, b0 = STATED[self.name]
        return QuaternionAlgorithm(self.name, a0 if spec.alpha is None else spec.alpha,
                                   b0 if spec.beta is None else spec.beta, spec.exact_exp)

    def record(self, spec: AlgorithmSpec) -> dict[str, Any]:
        """The coefficients as run (stated unless given), ``beta`` where the algorithm has
        one, the increment map and the step."""
        a0, b0 = STATED[self.name]
        return {"alpha": a0 if spec.alpha is None else spec.alpha,
                "beta": (b0 if spec.beta is None else spec.beta) if self.has_beta else None,
                "exact_exp": spec.exact_exp, "step_s": spec.step}

    def _step(self, spec: AlgorithmSpec) -> float:
        if spec.step is None:
            raise ValueError(f"{self.name} needs --step (the computation step ΔT, s)")
        return spec.step

    def min_samples(self, spec: AlgorithmSpec) -> int:
        return subintervals(self.name)

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return self._step(spec)

    def run(self, spec: AlgorithmSpec, data: ArrayLike, *, h: float, t: ArrayLike | None = None,
            t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
        return quaternion_attitude(data, self.configured(spec), step=self._step(spec), t0=t0,
                                   q0=q0)


class Miller(_QuaternionFamily):
    """A1: Miller's three-sample quaternion algorithm (α, β)."""

    name = "miller"
    has_beta = True


class Panov(_QuaternionFamily):
    """A2: Panov's two-sample algorithm (α)."""

    name = "panov"


class Power(_QuaternionFamily):
    """A3: the power (series) algorithm (α)."""

    name = "power"


#: The families this module defines, in registry order.
FAMILIES: tuple[Family, ...] = (Miller(), Panov(), Power())
_BY_NAME: dict[str, _QuaternionFamily] = {f.name: f for f in (Miller(), Panov(), Power())}


def has_beta(name: QuaternionAlgorithmName) -> bool:
    """Whether algorithm ``name`` has the second coefficient β (Miller's A1)."""
    subintervals(name)
    return _BY_NAME[name].has_beta
