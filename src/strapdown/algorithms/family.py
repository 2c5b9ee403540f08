"""What every attitude algorithm family declares: the contract behind the registry.

An *algorithm family* (``rotvec``, ``rate-three``, ``miller`` …) is one object that knows
everything the library needs about its algorithm: input kind, update structures,
coefficient choices, options, minimum samples, update period, classical-coning drift law,
how to run it (float64 and arbitrary precision), its velocity counterpart (what the
navigation runs, :meth:`Family.velocity`) and what the AHRS propagation and the C exporter
need. Each family lives beside its implementation (:mod:`.rotvec`, :mod:`.rate`,
:mod:`.quaternion`); :mod:`.spec` collects them into the registry. A configured algorithm
is an :class:`~strapdown.algorithms.spec.AlgorithmSpec`.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar, Literal

from strapdown._core.kinds import InputKind

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from strapdown.algorithms.coning import ConingSetName
    from strapdown.algorithms.precision import MpSolution
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.algorithms.structures import AttitudeSolution
    from strapdown.algorithms.velocity import VelocitySet, VelocityUpdate
    from strapdown.truth.motions import Motion

__all__ = [
    "DriftLaw",
    "Family",
    "IncrementStructure",
    "InputKind",
    "RateCoefficients",
    "Rk4Step",
    "StructureName",
]

# The vocabulary of an algorithm spec: every string option, once. The run-time tuples
# (spec.ALGORITHMS, structures.STRUCTURES, rate.RK4_STEPS …) are derived from these.
# The family names are declared beside their families (rotvec.RotvecName,
# rate.RateAlgorithmName, quaternion.QuaternionAlgorithmName) and joined in
# spec.AlgorithmName, so that a new family is one module's change.
#: The update structures of increment input (:mod:`.structures`).
IncrementStructure = Literal["conventional", "realtime", "single-chain"]
#: Every update structure some family runs in (``sliding``: Wang et al.'s scheme of
#: ``rate-three``).
StructureName = Literal[IncrementStructure, "sliding"]
#: RK4 step variants: step 2 td with the middle sample, or step td with the mean of the ends.
Rk4Step = Literal["2td", "td-interp"]
#: Coefficient sets of the rate algorithms: the designer's (``derived``) or as printed.
RateCoefficients = Literal["derived", "paper"]


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
    name: ClassVar[str]  # an AlgorithmName (spec.py joins the families' names)
    #: What the algorithm consumes: angular increments (rad) or rate samples (rad/s).
    input_kind: ClassVar[InputKind]
    #: Update structures it runs in; the first is the default.
    structures: ClassVar[tuple[StructureName, ...]] = ("conventional",)
    #: Spec fields besides ``algorithm``/``structure``/``coefficients`` that it reads.
    options: ClassVar[frozenset[str]] = frozenset()
    #: Whether the input comes in whole computation steps ``spec.step`` of
    #: ``min_samples`` sub-interval increments (Plaksiy's algorithms) rather than at a
    #: sample rate.
    stepped: ClassVar[bool] = False
    #: Whether it runs named N-subsample coning sets (:mod:`.coning`), which a user's
    #: :class:`~strapdown.algorithms.coning.CoefficientSet` may replace.
    coning_sets: ClassVar[bool] = False
    #: Default coefficient set (``None``: the family takes no ``coefficients``).
    default_coefficients: ClassVar[ConingSetName | RateCoefficients | None] = None
    #: Full reference of the algorithm (see docs/references.md).
    reference: ClassVar[str] = ""

    def coefficient_names(self) -> tuple[ConingSetName | RateCoefficients, ...]:
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

    def run(self, spec: AlgorithmSpec, data: ArrayLike, *, h: float, t: ArrayLike | None = None,
            t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
        """Run on validated input: increments ``(n, 3)`` every ``h`` from ``t0``, or rates
        ``(n, 3)`` at times ``t``."""
        raise NotImplementedError

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        """Run on a closed-form motion in arbitrary precision."""
        raise ValueError(f"{self.name} runs in float64 only; drop --precision")

    def record(self, spec: AlgorithmSpec) -> dict[str, Any]:
        """Keys the family adds to an evaluation's record (its coefficients as run)."""
        return {}

    def candidates(self) -> tuple[AlgorithmSpec, ...]:
        """The configurations ``strapdown advise`` ranks: by default the family's default
        in each of its structures (none for a stepped family, whose step is the user's)."""
        from strapdown.algorithms.spec import AlgorithmSpec

        if self.stepped:
            return ()
        name: Any = self.name  # an AlgorithmName once registered
        return tuple(AlgorithmSpec(name, structure=s) for s in self.structures)

    def amplitude_cubed(self, spec: AlgorithmSpec) -> bool:
        """Whether the configuration has a drift term of third order in the coning amplitude
        (which a second-order spectral prediction leaves out; ``advise`` says so)."""
        return False

    def velocity(self, spec: AlgorithmSpec, *, velocity_set: VelocitySet | None = None,
                 sculling: bool = True) -> VelocityUpdate | None:
        """The velocity counterpart of the configuration (sculling and scrolling beside its
        coning update), or None where it has none: what the navigation runs
        (:func:`strapdown.algorithms.velocity.velocity_update`: the N-subsample update for a
        family of designed coning sets in a structure that runs velocity, the windowed dual
        for a windowed rate family). ``velocity_set``: the conventional structure's sculling
        pairs (default :data:`~strapdown.algorithms.velocity.DEFAULT_VELOCITY_SET`)."""
        from strapdown.algorithms.velocity import DEFAULT_VELOCITY_SET, velocity_update

        return velocity_update(self, spec, velocity_set=velocity_set or DEFAULT_VELOCITY_SET,
                               sculling=sculling)

    def propagation(self, spec: AlgorithmSpec) -> dict[str, Any]:
        """Arguments of the AHRS kernel's propagation step (see :mod:`strapdown.ahrs`)."""
        raise ValueError(f"the filter propagates with rate-single, rate-three (sliding), rk4 or "
                         f"rotvec:N=…, not {self.name!r}")
