"""What every attitude algorithm family declares: the contract behind the registry.

An *algorithm family* (``rotvec``, ``rate-three``, ``miller`` …) is one object that knows
everything the library needs about its algorithm: input kind, update structures,
coefficient choices, options, minimum samples, update period, classical-coning drift law,
how to run it (float64 and arbitrary precision) and what the AHRS propagation and the C
exporter need. Each family lives beside its implementation (:mod:`.rotvec`, :mod:`.rate`,
:mod:`.quaternion`); :mod:`.spec` collects them into the registry. A configured algorithm
is an :class:`~strapdown.algorithms.spec.AlgorithmSpec`.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, ClassVar, Literal

if TYPE_CHECKING:
    from strapdown.algorithms.precision import MpSolution
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.algorithms.structures import AttitudeSolution
    from strapdown.truth.motions import Motion

__all__ = ["DriftLaw", "Family", "InputKind"]

InputKind = Literal["increment", "rate"]


@dataclass(frozen=True)
class DriftLaw:
    """Classical-coning drift ``−c · a² Ω (Ω h)^order`` about the cone axis (rad/s).

    Leading order in the half-cone angle ``a``; ``h`` is the input sample interval.
    """

    order: int
    constant: Fraction

    def predict(self, half_angle: float, cone_rate: float, h: float) -> float:
        """The law's drift (rad/s) for half angle ``a`` (rad), cone rate ``Ω`` (rad/s)."""
        return -float(self.constant) * half_angle**2 * cone_rate * (cone_rate * h) ** self.order


class Family:
    """Base of the algorithm families (one instance each, registered in :mod:`.spec`).

    Subclasses set the class attributes and override what applies; the defaults describe
    a family with one structure, no coefficients and no options.
    """

    #: Registry name, the first field of a spec string.
    name: ClassVar[str]
    #: What the algorithm consumes: angular increments (rad) or rate samples (rad/s).
    input_kind: ClassVar[InputKind]
    #: Update structures it runs in; the first is the default.
    structures: ClassVar[tuple[str, ...]] = ("conventional",)
    #: Spec fields besides ``algorithm``/``structure``/``coefficients`` that it reads.
    options: ClassVar[frozenset[str]] = frozenset()
    #: Whether the input comes in whole computation steps ``spec.step`` of
    #: ``min_samples`` sub-interval increments (Plaksiy's algorithms) rather than at a
    #: sample rate.
    stepped: ClassVar[bool] = False
    #: Default coefficient set (``None``: the family takes no ``coefficients``).
    default_coefficients: ClassVar[str | None] = None
    #: Full reference of the algorithm (see docs/references.md).
    reference: ClassVar[str] = ""

    def coefficient_names(self) -> tuple[str, ...]:
        """Names ``coefficients=`` accepts (empty: none)."""
        return ()

    def check(self, spec: AlgorithmSpec) -> None:
        """Validate the options and coefficients ``spec`` gives this family (ValueError)."""
        if "alpha" not in self.options and (spec.alpha is not None or spec.beta is not None
                                            or spec.exact_exp):
            raise ValueError("--alpha, --beta and --exact-exp belong to miller, panov and power")
        if "step" not in self.options and spec.step is not None:
            raise ValueError(f"{self.name} takes no --step (that is the quaternion "
                             "algorithms' computation step)")
        names = self.coefficient_names()
        if spec.coefficients is not None and spec.coefficients not in names:
            if not names:
                raise ValueError(f"{self.name} has no coefficients; drop --coefficients")
            raise ValueError(f"{self.name} takes coefficients {' or '.join(names)}, "
                             f"not {spec.coefficients!r}")

    def min_samples(self, spec: AlgorithmSpec) -> int:
        """Fewest input samples that produce one update."""
        raise NotImplementedError

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        """Time between attitude outputs for input samples every ``h`` seconds."""
        raise NotImplementedError

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw | None:
        """The classical-coning drift law, where one is known."""
        return None

    def run(self, spec: AlgorithmSpec, data, *, h: float, t=None, t0: float = 0.0,
            q0=None) -> AttitudeSolution:
        """Run on validated input: increments ``(n, 3)`` every ``h`` from ``t0``, or rates
        ``(n, 3)`` at times ``t``."""
        raise NotImplementedError

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        """Run on a closed-form motion in arbitrary precision."""
        raise ValueError(f"{self.name} runs in float64 only; drop --precision")

    def propagation(self, spec: AlgorithmSpec) -> dict:
        """Arguments of the AHRS kernel's propagation step (see :mod:`strapdown.ahrs`)."""
        raise ValueError(f"the filter propagates with rate-single, rate-three (sliding), rk4 or "
                         f"rotvec:N=…, not {self.name!r}")
