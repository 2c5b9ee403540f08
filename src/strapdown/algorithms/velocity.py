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

The navigation layer chains these increments: in a non-rotating frame without gravity
(:func:`strapdown.navigation.inertial.integrate_inertial`, the sculling studies) and on the
WGS-84 Earth (:mod:`strapdown.navigation.earth`).

Rate input (:class:`WindowedRateVelocity`, chained by
:func:`strapdown.navigation.inertial.integrate_inertial_rates`): from rate and
specific-force samples
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

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_vectors, positive
from strapdown._core.validation import positive_int as _positive_int
from strapdown.algorithms import _velocity_kernels, tables
from strapdown.algorithms.coning import MAX_SUBSAMPLES, coefficient_set
from strapdown.algorithms.structures import (
    STRUCTURE_REGISTRY,
    UpdateStructure,
    single_chain_table,
)

if TYPE_CHECKING:
    from strapdown._core.kinds import InputKind
    from strapdown.algorithms.coning import WindowedAlgorithm
    from strapdown.algorithms.family import Family
    from strapdown.algorithms.spec import AlgorithmSpec

    #: The rate-input velocity algorithms (:func:`rate_velocity_algorithms`, read from the
    #: registry when asked: module ``__getattr__``).
    RATE_VELOCITY_ALGORITHMS: tuple[str, ...]

__all__ = [
    "DEFAULT_VELOCITY_SET",
    "NAV_STRUCTURES",
    "RATE_VELOCITY_ALGORITHMS",
    "VELOCITY_SETS",
    "BodyIncrements",
    "ConingForceLaw",
    "NavStructure",
    "ScullingLaw",
    "VelocitySet",
    "body_increments",
    "coning_force_law",
    "effective_velocity_set",
    "rate_sculling_law",
    "sculling_law",
    "sculling_matrix",
    "sculling_single_chain_table",
]

#: Update structures of the velocity/position algorithms.
NavStructure = Literal["conventional", "single-chain"]
#: The registered structures they run in (``UpdateStructure.runs_velocity``; also
#: :func:`nav_structures`, which sees one registered later), the objects themselves.
NAV_STRUCTURES: tuple[NavStructure, ...] = tuple(
    s for s in STRUCTURE_REGISTRY.values() if s.runs_velocity)  # type: ignore[misc]
if NAV_STRUCTURES != get_args(NavStructure):  # one list of names: the Literal
    raise RuntimeError(f"the velocity structures {NAV_STRUCTURES} and NavStructure "
                       f"{get_args(NavStructure)} differ")
#: The velocity (sculling) sets of the conventional structure (module docstring).
VelocitySet = Literal["coning-force", "classical"]
VELOCITY_SETS: tuple[VelocitySet, ...] = get_args(VelocitySet)
#: What ``body_increments`` and the navigation (inertial and Earth) run by default.
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


def _structure(structure: object) -> UpdateStructure:
    """The registered structure of that name, if the velocity algorithms run in it
    (``UpdateStructure.runs_velocity``)."""
    from strapdown.algorithms.structures import STRUCTURE_REGISTRY

    found = STRUCTURE_REGISTRY.get(structure) if isinstance(structure, str) else None
    if found is None or not found.runs_velocity:
        raise ValueError(f"unknown velocity structure {structure!r}; choose one of "
                         f"{', '.join(nav_structures())}")
    return found


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


def effective_velocity_set(structure: NavStructure | UpdateStructure,
                           velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> VelocitySet:
    """The set a structure runs for the name given: the single chain has one set, the
    classical one (module docstring)."""
    # the structure with its own start-up sets is the single chain: its N − 1 coefficients
    # are all fixed by the sculling conditions, one set
    return "classical" if _structure(structure).own_startup else _velocity_set(velocity_set)


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


def _classical_pairs(n: int) -> list[tuple[tuple[int, int], Fraction]]:
    """The classical set: the pairs with the last subsample, ``s[N−1−m, N−1] = ς_m``."""
    return [((n - 1 - m, n - 1), c) for m, c in enumerate(tables.SCULLING_CONVENTIONAL[n],
                                                          start=1)]


def _coning_force_pairs(n: int) -> list[tuple[tuple[int, int], Fraction]]:
    """The coning-force set: every pair ``i < j``, ``s[i, j] = k_ij``."""
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    return list(zip(pairs, tables.SCULLING_CONING_FORCE[n], strict=True))


#: The conventional structure's sculling pairs per velocity set.
_SCULLING_PAIRS = {"classical": _classical_pairs, "coning-force": _coning_force_pairs}


def sculling_matrix(n: int, *, exact: bool = False, velocity_set: VelocitySet = "classical"):
    """``(N, N)`` upper-triangular sculling matrix of the conventional structure:
    ``"classical"``: ``s[N−1−m, N−1] = ς_m`` (cross with the last subsample);
    ``"coning-force"``: ``s[i, j] = k_ij`` over all pairs. ``exact=True``: nested lists of
    :class:`~fractions.Fraction`."""
    n = _n(n)
    rows = [[Fraction(0)] * n for _ in range(n)]
    for (i, j), c in _SCULLING_PAIRS[_velocity_set(velocity_set)](n):
        rows[i][j] = c
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
    st = _structure(structure)
    if st.whole_updates:  # the conventional structure
        m = g.shape[0] // n
        if m < 1:
            raise ValueError(f"N = {n} needs at least {n} samples, got {g.shape[0]}")
        kc = np.ascontiguousarray(coefficient_set("table3", n).matrix)
        ks = sculling_matrix(n, velocity_set=velocity_set) if sculling else np.zeros((n, n))
        out = np.empty((3, m, 3))
        _velocity_kernels.conventional_body_kernel(g[: m * n], a[: m * n], kc, ks, h, out[0],
                                              out[1], out[2])
        return BodyIncrements(out[0], out[1], out[2], h, n * h, structure, n)
    if g.shape[0] < 1:
        raise ValueError("the single chain needs at least one sample")
    tab_s = sculling_single_chain_table(n)
    out = np.empty((3, g.shape[0], 3))
    _velocity_kernels.single_chain_body_kernel(g, a, single_chain_table(n),
                                          tab_s if sculling else np.zeros_like(tab_s), h,
                                          out[0], out[1], out[2])
    return BodyIncrements(out[0], out[1], out[2], h, h, structure, n)


class VelocityUpdate:
    """The velocity counterpart of a configured attitude algorithm (what
    :meth:`strapdown.algorithms.family.Family.velocity` answers): how its samples become
    body-frame rotation, velocity and position increments per update (module docstring).

    Attributes
    ----------
    input_kind : {"increment", "rate"}
        Increments (rad, m/s) or rate and specific-force samples (rad/s, m/s²).
    structure : UpdateStructure
        The update structure of the increments it gives (``BodyIncrements.structure``).
    n : int
        Samples per update (conventional) or the single chain's N.
    min_samples : int
        Fewest input samples that give one update.
    start : int
        Input samples before the first update's start (a window's history): the initial
        state belongs to sample ``start``.
    """

    input_kind: InputKind
    structure: UpdateStructure
    n: int
    min_samples: int
    start: int = 0

    def update_period(self, h: float) -> float:
        """Time between updates for samples every ``h`` seconds."""
        return self.structure.update_period(self.n, h)

    def body(self, gyro: NDArray[np.float64], accel: NDArray[np.float64],
             h: float) -> BodyIncrements:
        """Body increments of validated ``(k, 3)`` samples every ``h``."""
        raise NotImplementedError


class IncrementVelocity(VelocityUpdate):
    """The N-subsample coning, sculling and scrolling update on increments
    (:func:`body_increments`) in a structure that runs it (``UpdateStructure.runs_velocity``).
    """

    input_kind = "increment"

    def __init__(self, structure: UpdateStructure, n: int, *,
                 velocity_set: VelocitySet = DEFAULT_VELOCITY_SET, sculling: bool = True):
        if not structure.runs_velocity:
            raise ValueError(f"the velocity algorithms run in the "
                             f"{' or '.join(nav_structures())} structure, not {structure}")
        self.structure, self.n = structure, _n(n)
        self.velocity_set, self.sculling = _velocity_set(velocity_set), bool(sculling)
        self.min_samples = structure.min_increments(self.n)

    def body(self, gyro, accel, h):
        return body_increments(gyro, accel, self.n, h=h, structure=self.structure,
                               sculling=self.sculling, velocity_set=self.velocity_set)


class WindowedRateVelocity(VelocityUpdate):
    """The dual of a windowed rate algorithm (module docstring, rate input): its quadrature
    weights on ω and f give ``α`` and ``υ``, its pair coefficients ``c_p`` both the coning
    term ``td² Σ c_p ω_i × ω_j`` and the sculling term ``td² Σ c_p (ω_i × f_j + f_i × ω_j)``
    (Ignagni's duality); ``ΔR_b = ½ T Δv_b``. An update every ``update`` samples, a single
    chain when that is one."""

    input_kind = "rate"

    def __init__(self, windowed: WindowedAlgorithm, *, sculling: bool = True):
        from strapdown.algorithms.structures import structure

        self.windowed, self.sculling = windowed, bool(sculling)
        self.n = windowed.update
        self.structure = structure("single-chain" if windowed.update == 1 else "conventional")
        self.start = windowed.history
        self.min_samples = windowed.history + windowed.span + 1

    def _pairs(self, ws, fs, td: float):
        """The coning and sculling pair sums (one pair: ``c td td`` first, as
        ``rate-single`` always computed it; zeros without pairs)."""
        w = self.windowed
        k = [float(c) for c in w.pair_coefficients]
        if not k:
            return np.zeros_like(ws[0]), np.zeros_like(ws[0])
        if len(k) == 1:
            (i, j), c = w.pairs[0], k[0]
            return (c * td * td * np.cross(ws[i], ws[j]),
                    c * td * td * (np.cross(ws[i], fs[j]) + np.cross(fs[i], ws[j])))
        beta = td * td * sum(kk * np.cross(ws[i], ws[j]) for kk, (i, j) in zip(k, w.pairs,
                                                                                 strict=True))
        scul = td * td * sum(kk * (np.cross(ws[i], fs[j]) + np.cross(fs[i], ws[j]))
                             for kk, (i, j) in zip(k, w.pairs, strict=True))
        return beta, scul

    def body(self, gyro, accel, h):
        w = self.windowed
        m = (gyro.shape[0] - self.min_samples) // w.update + 1
        starts = w.history + w.update * np.arange(m)
        ws = [gyro[starts + o] for o in w.offsets]
        fs = [accel[starts + o] for o in w.offsets]
        wts = [float(x) for x in w.weights]
        th = h * sum(c * x for c, x in zip(wts, ws, strict=True))
        ups = h * sum(c * x for c, x in zip(wts, fs, strict=True))
        beta, scul = self._pairs(ws, fs, h)
        phi = th + beta if w.pairs else th
        dv = ups + 0.5 * np.cross(th, ups) + np.cross(th, np.cross(th, ups)) / 6.0
        if self.sculling:
            dv = dv + scul
        period = self.update_period(h)
        return BodyIncrements(np.ascontiguousarray(phi), np.ascontiguousarray(dv),
                              np.ascontiguousarray(0.5 * period * dv), h, period,
                              self.structure, self.n)


def velocity_update(family: Family, spec: AlgorithmSpec, *,
                    velocity_set: VelocitySet = DEFAULT_VELOCITY_SET,
                    sculling: bool = True) -> VelocityUpdate | None:
    """The velocity counterpart of ``spec`` (:meth:`Family.velocity`), or None: the N-subsample
    update for a family running the designed N-subsample coning sets in a structure that runs
    velocity, the windowed dual for a windowed rate family (not interleaved)."""
    s = spec.update_structure
    if family.input_kind == "increment":
        if not (family.coning_sets and s.runs_velocity and spec.coefficients in (
                None, family.default_coefficients)):
            return None
        return IncrementVelocity(s, spec.subsamples, velocity_set=velocity_set,
                                 sculling=sculling)
    windowed = getattr(family, "windowed", None)
    if windowed is None or s.interleaved:
        return None
    return WindowedRateVelocity(windowed(spec), sculling=sculling)


def nav_structures() -> tuple[NavStructure, ...]:
    """The registered update structures the velocity algorithms run in
    (``UpdateStructure.runs_velocity``), in registry order."""
    from strapdown.algorithms.structures import STRUCTURE_REGISTRY

    return tuple(s for s in STRUCTURE_REGISTRY.values()  # type: ignore[misc]
                 if s.runs_velocity)


def rate_velocity_algorithms() -> tuple[str, ...]:
    """The registered rate-input families with a velocity counterpart (in registry order):
    the duals of the rate-input coning algorithms (module docstring), asked of each family
    (:meth:`strapdown.algorithms.family.Family.velocity`), so a newly registered one is
    included."""
    from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec

    return tuple(name for name, fam in REGISTRY.items() if fam.input_kind == "rate"
                 and fam.velocity(AlgorithmSpec(name)) is not None)


#: The inertial integrators that moved to :mod:`strapdown.navigation.inertial` (issue 26),
#: still reachable here with a ``DeprecationWarning`` for one release.
_MOVED_TO_NAVIGATION = ("InertialSolution", "MpInertialSolution", "integrate_inertial",
                        "integrate_inertial_mp", "integrate_inertial_rates")


def __getattr__(name: str) -> object:
    # RATE_VELOCITY_ALGORITHMS and NAV_STRUCTURES are read from the registries when asked,
    # so a family or structure registered after this module's import is in them
    if name == "RATE_VELOCITY_ALGORITHMS":
        return rate_velocity_algorithms()
    if name in _MOVED_TO_NAVIGATION:  # deprecated aliases, for one release (issue 26)
        import warnings

        from strapdown.navigation import inertial

        warnings.warn(f"strapdown.algorithms.velocity.{name} moved to "
                      f"strapdown.navigation.{name} (issue 26); this alias goes with the "
                      "next release", DeprecationWarning, stacklevel=2)
        return getattr(inertial, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _rate_spec(coefficients: str | None, algorithm: str):
    """The spec of a rate-input velocity algorithm (``coefficients`` None: the family's
    default), or the error naming those there are."""
    from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec

    fam = REGISTRY.get(algorithm)  # type: ignore[call-overload]
    vel = None
    if fam is not None and fam.input_kind == "rate":
        vel = fam.velocity(AlgorithmSpec(algorithm))  # type: ignore[arg-type]
    if vel is None:
        raise ValueError(f"unknown rate-input velocity algorithm {algorithm!r}; choose one of "
                         f"{', '.join(rate_velocity_algorithms())}")
    if coefficients is None:
        return AlgorithmSpec(algorithm)  # type: ignore[arg-type]
    if coefficients not in fam.coefficient_names():
        raise ValueError(f"unknown rate-input coefficients {coefficients!r}; choose one of "
                         f"{', '.join(fam.coefficient_names())}")
    return AlgorithmSpec(algorithm, coefficients=coefficients)  # type: ignore[arg-type]


def rate_sculling_law(coefficients: str = "derived", algorithm: str = "rate-single"
                      ) -> ScullingLaw:
    """Classical-sculling law of the rate-input update (module docstring), ``h`` = ``td``:
    the coning law of the same rate algorithm with the same coefficients (the duality)."""
    spec = _rate_spec(coefficients, algorithm)
    law = spec.family.drift_law(spec)
    if law is None:
        raise ValueError(f"{algorithm} has no known sculling law (its coning law is unknown)")
    return ScullingLaw(law.order, law.constant)
