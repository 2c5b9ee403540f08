"""The algorithm model: one frozen, validated value for every attitude algorithm, and the
registry of algorithm families.

An :class:`AlgorithmSpec` names a configured algorithm — family, update structure,
coefficient set and options — and knows its input kind, minimum samples, update period,
drift law, how to run it and what the AHRS and the C exporter need. It parses from and
prints to the spec grammar of ``strapdown compare`` and ``strapdown sweep``::

    rotvec:N=3:structure=realtime      rate-three:structure=sliding
    rk4:rk4_step=td-interp             miller:step=0.01:alpha=0.45

the family name, then ``key=value`` options separated by colons (``N`` is short for
``subsamples``). An unknown family, key or value is an error that lists what is allowed.

The registry (:data:`REGISTRY`) holds one :class:`~strapdown.algorithms.family.Family` per
algorithm, defined beside its implementation: :mod:`.rotvec`, :mod:`.rate` and
:mod:`.quaternion`. Adding an algorithm is adding a family there.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, cast, get_args

from strapdown._core.validation import positive, positive_int
from strapdown.algorithms import quaternion, rate, rotvec
from strapdown.algorithms.coning import MAX_SUBSAMPLES, ConingSetName
from strapdown.algorithms.family import (
    DriftLaw,
    Family,
    InputKind,
    RateCoefficients,
    Rk4Step,
    StructureName,
)
from strapdown.algorithms.quaternion import QuaternionAlgorithmName
from strapdown.algorithms.rate import RateAlgorithmName
from strapdown.algorithms.rotvec import RotvecName
from strapdown.algorithms.structures import AttitudeSolution, UpdateStructure
from strapdown.algorithms.structures import structure as structure_object

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from strapdown.algorithms.precision import MpSolution
    from strapdown.io.readers import ImuLog
    from strapdown.truth.motions import Motion
    from strapdown.truth.sensors import GyroRecord

__all__ = [
    "ALGORITHMS",
    "REGISTRY",
    "SPEC_KEYS",
    "STRUCTURES",
    "AlgorithmSpec",
    "CoefficientName",
    "algorithms_taking",
    "family",
    "parse_spec",
    "register",
]

#: A coefficient set some family takes: a named coning set or a rate-algorithm set.
CoefficientName = ConingSetName | RateCoefficients
#: Every registered family, in registry order: the names each family module declares.
AlgorithmName = Literal[RotvecName, RateAlgorithmName, QuaternionAlgorithmName]
#: Every registered family by name, in the order the command line lists them.
REGISTRY: dict[AlgorithmName, Family] = {
    cast("AlgorithmName", f.name): f
    for f in (*rotvec.FAMILIES, *rate.FAMILIES, *quaternion.FAMILIES)}
if tuple(REGISTRY) != get_args(AlgorithmName):  # the one list of names is the Literal
    raise RuntimeError(f"the registry {tuple(REGISTRY)} and AlgorithmName "
                       f"{get_args(AlgorithmName)} disagree; a family was added to one only")
#: Registered family names.
ALGORITHMS: tuple[AlgorithmName, ...] = tuple(REGISTRY)
#: Every update structure some family runs in.
STRUCTURES: tuple[StructureName, ...] = tuple(dict.fromkeys(s for f in REGISTRY.values()
                                                            for s in f.structures))
if set(STRUCTURES) != set(get_args(StructureName)):
    raise RuntimeError(f"the families run in {STRUCTURES}, StructureName lists "
                       f"{get_args(StructureName)}")
#: Spec fields a spec string may set (``N`` is short for ``subsamples``).
SPEC_KEYS = ("subsamples", "coefficients", "structure", "rk4_step", "alpha", "beta", "step",
             "exact_exp")
_ALIASES = {"N": "subsamples", "n": "subsamples"}
_INT = {"subsamples"}
_FLOAT = {"alpha", "beta", "step"}
_BOOL = {"exact_exp"}


def register(fam: Family) -> Family:
    """Add an algorithm family to the registry: everything that lists, parses, runs,
    evaluates, compares, sweeps, advises, propagates or exports families sees it from here
    on (a plug-in; the shipped families are registered on import).

    The family must name itself, its input kind and registered structures, and its name
    must be new; ValueError otherwise.
    """
    global ALGORITHMS, STRUCTURES
    if not isinstance(fam, Family):
        raise ValueError(f"a family must be a Family instance, got {type(fam).__name__}")
    name = getattr(fam, "name", None)
    if not isinstance(name, str) or not name or ":" in name or "=" in name:
        raise ValueError(f"a family needs a name without ':' or '=', got {name!r}")
    if name in REGISTRY:
        raise ValueError(f"a family named {name!r} is already registered")
    if getattr(fam, "input_kind", None) not in ("increment", "rate"):
        raise ValueError(f"family {name!r}: input_kind must be 'increment' or 'rate'")
    for s in fam.structures:
        structure_object(s)  # unknown structures fail here, listing the registered ones
    REGISTRY[cast("AlgorithmName", name)] = fam
    ALGORITHMS = tuple(REGISTRY)
    STRUCTURES = tuple(dict.fromkeys(s for f in REGISTRY.values() for s in f.structures))
    return fam


def family(name: AlgorithmName) -> Family:
    """The registered family ``name``; an unknown name lists the known ones."""
    try:
        return REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown algorithm {name!r}; choose one of "
                         f"{', '.join(ALGORITHMS)}") from None


def algorithms_taking(kind: InputKind) -> tuple[AlgorithmName, ...]:
    """Names of the families whose input is ``kind`` (``"increment"`` or ``"rate"``)."""
    return tuple(n for n, f in REGISTRY.items() if f.input_kind == kind)


@dataclass(frozen=True)
class AlgorithmSpec:
    """A configured attitude algorithm (frozen; validated on construction).

    Parameters
    ----------
    algorithm : AlgorithmName
        Family name, one of :data:`ALGORITHMS`.
    subsamples : int
        N, the subsamples per rotation-vector update (``rotvec`` only).
    coefficients : CoefficientName, optional
        Coefficient set; ``None`` is the family's default (``table3`` for ``rotvec``,
        ``derived`` for the rate algorithms; ``rk4`` and the quaternion algorithms have
        none).
    structure : StructureName
        Update structure, one the family runs in (given by name; held as the registered
        :class:`~strapdown.algorithms.structures.UpdateStructure`, which is also its name).
    rk4_step : {"2td", "td-interp"}
        RK4 step variant (``rk4`` only).
    alpha, beta : float, optional
        Quaternion-algorithm coefficients (``None``: the paper's stated values).
    step : float, optional
        Computation step ΔT (s) of the quaternion algorithms (required there).
    exact_exp : bool
        Quaternion algorithms: exact exponential instead of the truncated series.
    """

    algorithm: AlgorithmName = "rotvec"
    subsamples: int = 3
    coefficients: CoefficientName | None = None
    structure: StructureName | UpdateStructure = "conventional"
    rk4_step: Rk4Step = "2td"
    alpha: float | None = None
    beta: float | None = None
    step: float | None = None
    exact_exp: bool = False

    def __post_init__(self) -> None:
        fam = family(self.algorithm)
        n = positive_int(self.subsamples, "subsamples N")
        if n > MAX_SUBSAMPLES:
            raise ValueError(f"subsamples N must be at most {MAX_SUBSAMPLES}, got {n}")
        if self.structure not in fam.structures:
            raise ValueError(f"{self.algorithm} supports the structures "
                             f"{', '.join(fam.structures)}, not {self.structure!r}")
        # the registered object, which answers the structure's facts (and is its name)
        object.__setattr__(self, "structure", structure_object(self.structure))
        if self.step is not None:
            positive(self.step, "step")
        fam.check(self)

    # ------------------------------------------------------------------ the grammar
    @classmethod
    def parse(cls, text: str, **defaults: Any) -> AlgorithmSpec:
        """Parse a spec string; ``defaults`` fill the fields the string leaves out."""
        fields = {**defaults, **parse_spec(text)}
        unknown = set(fields) - {f.name for f in dataclasses.fields(cls)}
        if unknown:
            raise ValueError(f"unknown algorithm fields {sorted(unknown)}")
        return cls(**fields)

    def __str__(self) -> str:
        parts: list[str] = [self.algorithm]
        if "subsamples" in self.family.options:
            parts.append(f"N={self.subsamples}")
        for f in dataclasses.fields(self):
            if f.name in ("algorithm", "subsamples"):
                continue
            v = getattr(self, f.name)
            if v != f.default:
                parts.append(f"{f.name}={str(v).lower() if isinstance(v, bool) else v}")
        return ":".join(parts)

    # ------------------------------------------------------------------ facts
    @property
    def family(self) -> Family:
        """The registered family this spec configures."""
        return REGISTRY[self.algorithm]

    @property
    def update_structure(self) -> UpdateStructure:
        """The registered update structure (the object ``structure`` holds, typed as such):
        ask it for the structure's facts (update period, chains, start-up …)."""
        return cast(UpdateStructure, self.structure)

    @property
    def input_kind(self) -> InputKind:
        """``"increment"`` (angular increments, rad) or ``"rate"`` (rate samples, rad/s)."""
        return self.family.input_kind

    @property
    def resolved_coefficients(self) -> CoefficientName | None:
        """The coefficient set that runs (the family default when none is given)."""
        return self.coefficients if self.coefficients is not None else (
            self.family.default_coefficients)

    @property
    def min_samples(self) -> int:
        """Fewest input samples that give one update."""
        return self.family.min_samples(self)

    def update_period(self, h: float) -> float:
        """Time between attitude outputs for input samples every ``h`` seconds."""
        return self.family.update_period(self, positive(h, "h (sample interval)"))

    def drift_law(self) -> DriftLaw | None:
        """The classical-coning drift law, where one is known."""
        return self.family.drift_law(self)

    def propagation(self) -> dict[str, Any]:
        """What the AHRS kernel's propagation step needs (see :mod:`strapdown.ahrs`)."""
        return self.family.propagation(self)

    # ------------------------------------------------------------------ running
    def run(self, record: GyroRecord | ImuLog, *, q0: ArrayLike | None = None
            ) -> AttitudeSolution:
        """Run on a gyro record (:class:`~strapdown.truth.sensors.GyroRecord` or
        :class:`~strapdown.io.ImuLog`): attitude ``q_n_b`` from ``q0`` at the first time.

        Increment records whose ``t`` has one more entry than ``data`` rows give the
        interval edges; otherwise ``t`` holds the interval end times.
        """
        kind = record.kind
        if kind != self.input_kind:
            have = "increments" if kind == "increment" else "rates"
            want = "increments" if self.input_kind == "increment" else "rate samples"
            raise ValueError(f"{self.algorithm} takes {want}; this log holds {have}")
        if kind == "rate":
            return self.family.run(self, record.data, h=record.h, t=record.t, q0=q0)
        t = record.t
        t0 = float(t[0]) if t.shape[0] == record.data.shape[0] + 1 else float(t[0]) - record.h
        return self.family.run(self, record.data, h=record.h, t0=t0, q0=q0)

    def run_increments(self, increments: ArrayLike, *, h: float, t0: float = 0.0,
                       q0: ArrayLike | None = None) -> AttitudeSolution:
        """Run on angular increments ``(n, 3)`` (rad) every ``h`` seconds from ``t0``."""
        self._need("increment")
        return self.family.run(self, increments, h=h, t0=t0, q0=q0)

    def run_rates(self, t: ArrayLike, omega: ArrayLike, *, q0: ArrayLike | None = None
                  ) -> AttitudeSolution:
        """Run on rate samples ``omega`` ``(n, 3)`` (rad/s) at uniform times ``t`` ``(n,)``."""
        self._need("rate")
        return self.family.run(self, omega, h=0.0, t=t, q0=q0)

    def run_mp(self, motion: Motion, *, h: float, samples: int, digits: int) -> MpSolution:
        """Run on a closed-form motion in arbitrary precision (``digits`` significant)."""
        return self.family.run_mp(self, motion, h=h, samples=samples, digits=digits)

    def _need(self, kind: InputKind) -> None:
        if self.input_kind != kind:
            raise ValueError(f"{self.algorithm} takes "
                             f"{'increments' if self.input_kind == 'increment' else 'rates'}")


def parse_spec(spec: str) -> dict[str, Any]:
    """``"rotvec:N=3:structure=realtime"`` → ``{"algorithm": "rotvec", "subsamples": 3, ...}``.

    Only the fields the string names; :meth:`AlgorithmSpec.parse` validates the whole.
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"an algorithm spec must be a non-empty string, got {spec!r}")
    name, *opts = [p.strip() for p in spec.split(":")]
    if name not in REGISTRY:
        raise ValueError(f"spec {spec!r}: unknown algorithm {name!r}; choose one of "
                         f"{', '.join(ALGORITHMS)}")
    out: dict[str, Any] = {"algorithm": name}
    for o in opts:
        key, eq, value = o.partition("=")
        key = _ALIASES.get(key.strip(), key.strip())
        if not eq or key not in SPEC_KEYS:
            raise ValueError(f"spec {spec!r}: {o!r} is not key=value with a key among "
                             f"N, {', '.join(SPEC_KEYS)}")
        if key not in ("structure", "coefficients") and key not in REGISTRY[name].options:
            shown = "N (subsamples)" if key == "subsamples" else key
            raise ValueError(f"spec {spec!r}: {name} takes no {shown}")
        out[key] = _value(spec, key, value.strip())
    return out


def _value(spec: str, key: str, value: str) -> str | int | float | bool:
    try:
        if key in _INT:
            return int(value)
        if key in _FLOAT:
            return float(value)
        if key in _BOOL:
            if value.lower() not in ("true", "false", "1", "0"):
                raise ValueError(value)
            return value.lower() in ("true", "1")
        return value
    except ValueError:
        raise ValueError(f"spec {spec!r}: bad value {value!r} for {key}") from None
