"""Update structures: how rotation vectors are chained into attitude.

``conventional``
    One attitude update per N increments, update period ``T = N h``
    (Li & Zhang 2017 eq. 10, Figure 2).
``realtime``
    Li & Zhang 2017 eq. 15 (Figure 4): every ``h`` the rotation vector of the
    last N increments updates the attitude of N samples earlier,
    ``q(k) = q(k−N) ⊗ q(φ_k)``.

    Start-up (the paper's "initial alignment" of the first N−1 outputs): for
    ``k < N``, ``q(k) = q(0) ⊗ q(φ)`` where φ uses the k-subsample set on
    increments 1 … k (by default the same family as the main set, or Table 3
    when the family has no k-subsample member).

    The structure is N interleaved conventional chains that never exchange
    information (contrary to Li & Zhang (2017), Table 2): it raises the output rate, not
    the accuracy.
    :attr:`AttitudeSolution.chain` tells which chain produced each output.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, ClassVar, Literal, cast, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import (
    as_quaternions,
    as_vectors,
    finite_array,
    positive,
    positive_int,
)
from strapdown.algorithms import _kernels, tables
from strapdown.algorithms.coning import (
    CoefficientSet,
    WindowedAlgorithm,
    coefficient_set,
    coning_set_name,
    triple_arrays,
)
from strapdown.algorithms.family import IncrementStructure, StructureName
from strapdown.algorithms.finite_amplitude import triple_terms

if TYPE_CHECKING:  # the records the structures take, as AlgorithmSpec.run does
    from strapdown.io.readers import ImuLog
    from strapdown.truth.sensors import GyroRecord

__all__ = [
    "STRUCTURES",
    "STRUCTURE_REGISTRY",
    "AttitudeSolution",
    "IncrementStructure",
    "TailPolicy",
    "UpdateStructure",
    "chain_rotation_vectors",
    "conventional",
    "increment_structure",
    "realtime",
    "register_structure",
    "run_structure",
    "single_chain",
    "structure",
    "windowed",
]

#: What :func:`conventional` does with increments that do not fill a last update.
TailPolicy = Literal["error", "drop"]


class UpdateStructure(str):
    """An update structure: a registered object that answers its own facts.

    It is also its name (a ``str`` subclass): it compares, hashes, prints and serialises as
    ``"conventional"``, ``"realtime"`` … so spec strings, JSON records and file names are
    unchanged, while the library asks it — not its name — what it does. ``update`` below is
    the samples one update of the algorithm spans (N for the rotation vector, the window's
    update for a windowed rate algorithm).

    Attributes
    ----------
    every_sample : bool
        An output every input sample (else one per update).
    interleaved : bool
        Its outputs come from ``update`` interleaved chains that never exchange information
        (the real-time and sliding structures), else from one chain.
    whole_updates : bool
        It consumes increments in whole updates (a tail shorter than one is dropped or
        refused).
    own_startup : bool
        It starts from the first increment with fewer-sample sets of its own (the single
        chain), so one increment gives an output.
    pair_only : bool
        It runs pair-only coefficient sets (no triple cross products).
    runs_increments : bool
        It chains N-subsample coefficient sets on increments (:meth:`run`); the sliding
        structure belongs to the windowed rate algorithms instead.
    runs_velocity : bool
        The velocity and position algorithms run in it (the coning, sculling and scrolling
        update of :mod:`strapdown.algorithms.velocity` and the navigation on it).
    description : str
        One line for help texts.
    """

    every_sample: bool = False
    interleaved: bool = False
    whole_updates: bool = False
    own_startup: bool = False
    pair_only: bool = False
    runs_increments: bool = True
    runs_velocity: bool = False
    description: str = ""

    def __new__(cls, name: str) -> UpdateStructure:
        return super().__new__(cls, name)

    def __reduce__(self) -> tuple[object, tuple[str]]:  # unpickles to the registered object
        return (structure, (str(self),))

    @property
    def name(self) -> str:
        """The registry name (the plain string)."""
        return str(self)

    def update_period(self, update: int, h: float) -> float:
        """Time between outputs for updates of ``update`` samples every ``h`` seconds."""
        return h if self.every_sample else update * h

    def chains(self, update: int) -> int:
        """Interleaved chains behind the outputs."""
        return update if self.interleaved else 1

    def min_increments(self, n: int) -> int:
        """Fewest increments that give one output with an N-subsample set."""
        return 1 if self.own_startup else n

    def usable_samples(self, samples: int, update: int) -> int:
        """The samples of a run of ``samples`` that it uses (whole updates when it needs
        them)."""
        return samples - samples % update if self.whole_updates else samples

    def check_set(self, coefficients: CoefficientSet) -> None:
        """Whether it runs ``coefficients`` (ValueError naming why not)."""
        if self.pair_only and coefficients.triples:
            raise ValueError(f"the {self} structure runs pair-only sets; {coefficients.name!r} "
                             "has triple cross products")

    def chain_subsamples(self, coefficients: CoefficientSet) -> int:
        """The N of the coefficients a chain runs for ``coefficients`` (their own N)."""
        self.check_set(coefficients)
        return coefficients.n

    def triple(self, coefficients: CoefficientSet) -> bool:
        """Whether ``coefficients`` run with triple cross products here."""
        self.check_set(coefficients)
        return bool(coefficients.triples)

    def table(self, coefficients: CoefficientSet) -> NDArray[np.float64]:
        """The coefficient table its kernel reads for ``coefficients``: the N × N matrix
        (conventional), the start-up sets stacked ``(N, N, N)`` (real-time), the start-up
        and steady single-chain coefficients ``(N, N − 1)`` (single chain)."""
        self.check_set(coefficients)
        return np.ascontiguousarray(coefficients.matrix)

    def run(self, increments: ArrayLike | GyroRecord | ImuLog, coefficients: CoefficientSet,
            *, h: float | None = None, t0: float | None = None, q0: ArrayLike | None = None
            ) -> AttitudeSolution:
        """Run ``coefficients`` on increments (an array with ``h``, or a record)."""
        raise ValueError(f"the {self} structure does not run coefficient sets on increments")


class _Conventional(UpdateStructure):
    whole_updates = True
    runs_velocity = True
    description = "an update every N samples (T = N h)"

    def run(self, increments, coefficients, *, h=None, t0=None, q0=None):
        return conventional(increments, coefficients, h=h, t0=t0, q0=q0, tail="drop")


class _Realtime(UpdateStructure):
    every_sample = True
    interleaved = True
    pair_only = True
    description = "Li & Zhang's real-time structure: an output every h from N chains"

    def table(self, coefficients: CoefficientSet) -> NDArray[np.float64]:
        self.check_set(coefficients)
        return stack_sets(startup_sets(coefficients))

    def run(self, increments, coefficients, *, h=None, t0=None, q0=None):
        return realtime(increments, coefficients, h=h, t0=t0, q0=q0)


class _SingleChain(UpdateStructure):
    every_sample = True
    own_startup = True
    runs_velocity = True
    description = "the designer's single chain: an output every h with N-subsample accuracy"
    #: The sets it takes (the designer's), with the subsamples and triple terms each runs.
    _SETS: ClassVar[dict[str, tuple[bool, bool]]] = {  # name: (plain sum, triple terms)
        "table3": (False, False), "none": (True, False), "finite-amplitude": (False, True)}

    def check_set(self, coefficients: CoefficientSet) -> None:
        if coefficients.name not in self._SETS:
            raise ValueError(
                "the single chain takes its coefficients from the designer: use "
                "'table3' (the classical-coning optimum), 'finite-amplitude' or 'none', not "
                f"{coefficients.name!r}"
            )

    def chain_subsamples(self, coefficients: CoefficientSet) -> int:
        """The N of the chain's own coefficients (1 for the plain sum ``none``)."""
        self.check_set(coefficients)
        return 1 if self._SETS[coefficients.name][0] else coefficients.n

    def triple(self, coefficients: CoefficientSet) -> bool:
        """Whether the chain adds its own triple terms (the finite-amplitude set)."""
        self.check_set(coefficients)
        return self._SETS[coefficients.name][1]

    def table(self, coefficients: CoefficientSet) -> NDArray[np.float64]:
        return single_chain_table(self.chain_subsamples(coefficients))

    def run(self, increments, coefficients, *, h=None, t0=None, q0=None):
        return single_chain(increments, self.chain_subsamples(coefficients), h=h, t0=t0,
                            q0=q0, triple=self.triple(coefficients))


class _Sliding(UpdateStructure):
    every_sample = True
    interleaved = True
    runs_increments = False
    description = "Wang et al.'s sliding scheme: an output every td from the window's chains"


#: Every registered update structure by name, in the order the command line lists them.
STRUCTURE_REGISTRY: dict[str, UpdateStructure] = {
    s: s for s in (_Conventional("conventional"), _Realtime("realtime"),
                   _SingleChain("single-chain"), _Sliding("sliding"))}
if tuple(STRUCTURE_REGISTRY) != get_args(StructureName):  # one list of names: the Literal
    raise RuntimeError(f"the structures {tuple(STRUCTURE_REGISTRY)} and StructureName "
                       f"{get_args(StructureName)} disagree")
#: The update structures of increment input, in the order the command line lists them.
STRUCTURES: tuple[UpdateStructure, ...] = tuple(
    s for s in STRUCTURE_REGISTRY.values() if s.runs_increments)


def structure(name: object) -> UpdateStructure:
    """The registered update structure ``name`` (ValueError listing them)."""
    found = STRUCTURE_REGISTRY.get(name) if isinstance(name, str) else None
    if found is None:
        raise ValueError(f"unknown structure {name!r}; choose one of "
                         f"{', '.join(STRUCTURE_REGISTRY)}")
    return found


def register_structure(obj: UpdateStructure) -> UpdateStructure:
    """Add an update structure to the registry (its name must be new)."""
    if not isinstance(obj, UpdateStructure):
        raise ValueError(f"a structure must be an UpdateStructure, got {type(obj).__name__}")
    if obj in STRUCTURE_REGISTRY:
        raise ValueError(f"a structure named {obj.name!r} is already registered")
    STRUCTURE_REGISTRY[obj.name] = obj
    global STRUCTURES
    STRUCTURES = tuple(s for s in STRUCTURE_REGISTRY.values() if s.runs_increments)
    return obj


@dataclass(frozen=True)
class AttitudeSolution:
    """Time-stamped attitude from an update structure.

    Attributes
    ----------
    t : ndarray of shape (m,)
        Output times (s); ``t[0]`` is the initial time.
    q : ndarray of shape (m, 4)
        ``q_n_b`` at those times (unit, scalar first).
    structure : str
        What produced it: an update structure (``"conventional"``, ``"realtime"``,
        ``"single-chain"``, ``"sliding"``) or ``"windowed"``, ``"chained"``, ``"rk4"`` or a
        quaternion algorithm's name.
    coefficients : CoefficientSet or None
        The coning correction used (None for designed/windowed algorithms).
    h : float
        Increment (subsample) interval (s).
    update_period : float
        Time between successive outputs (s).
    chain : ndarray of shape (m,)
        Index of the interleaved chain that produced each output (all 0 for
        the conventional structure).
    startup : int
        Index of the first output in steady state: outputs before it precede
        a start-up transient (N − 1 for the single chain, else 0). Drift is
        measured from here on.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    structure: str
    coefficients: CoefficientSet | None
    h: float
    update_period: float
    chain: NDArray[np.int_]
    startup: int = 0

    @property
    def chains(self) -> int:
        """Number of interleaved chains (N for the real-time structure, else 1)."""
        return int(self.chain.max()) + 1 if self.chain.size else 1


def _check_inputs(increments: ArrayLike, coefficients: CoefficientSet, h: float,
                  q0: ArrayLike | None, t0: float
                  ) -> tuple[NDArray[np.float64], float, NDArray[np.float64], float]:
    if not isinstance(coefficients, CoefficientSet):
        raise ValueError(
            "coefficients must be a CoefficientSet (see "
            "strapdown.algorithms.coning.coefficient_set), "
            f"got {type(coefficients).__name__}"
        )
    theta, h, t0, unit_q0 = _stream_inputs(increments, "increments", h, t0, q0)
    n = coefficients.n
    if theta.shape[0] < n:
        raise ValueError(
            f"N = {n} subsamples need at least {n} increments, got {theta.shape[0]}"
        )
    return np.ascontiguousarray(theta), h, unit_q0, t0


def conventional(
    increments: ArrayLike | GyroRecord | ImuLog,
    coefficients: CoefficientSet,
    *,
    h: float | None = None,
    t0: float | None = None,
    q0: ArrayLike | None = None,
    tail: TailPolicy = "error",
) -> AttitudeSolution:
    """Conventional structure: an attitude update every ``T = N h``.

    Parameters
    ----------
    increments : array_like of shape (n, 3), GyroRecord or ImuLog
        Angular increments (rad) over consecutive intervals of length ``h``; or an increment
        record (:func:`strapdown.truth.sensors.increments`, :func:`strapdown.io.read_imu`),
        which gives ``h`` and ``t0`` itself, as
        :meth:`~strapdown.algorithms.spec.AlgorithmSpec.run` takes it.
    coefficients : CoefficientSet
        Coning correction for N subsamples.
    h : float
        Increment interval (s); required with an array, the record's by default.
    t0 : float
        Time of the first increment's start edge (s); default 0, or the record's.
    q0 : array_like of shape (4,), optional
        Initial ``q_n_b`` (identity by default).
    tail : {"error", "drop"}
        What to do with increments that do not fill a last update.

    Returns
    -------
    AttitudeSolution
        ``n // N + 1`` outputs at ``t0 + j N h``.
    """
    increments, h, t0 = _record_inputs(increments, h, t0, "conventional")
    theta, h, q0, t0 = _check_inputs(increments, coefficients, h, q0, t0)
    n = coefficients.n
    rest = theta.shape[0] % n
    if rest:
        if tail == "error":
            raise ValueError(
                f"{theta.shape[0]} increments do not fill whole updates of N = {n} "
                f"({rest} left over); pass tail='drop' to discard them"
            )
        if tail != "drop":
            raise ValueError(f"tail must be 'error' or 'drop', got {tail!r}")
        theta = theta[: theta.shape[0] - rest]
    m = theta.shape[0] // n
    q = np.empty((m + 1, 4))
    if coefficients.triples:
        _kernels.conventional_triple_kernel(theta, np.ascontiguousarray(coefficients.matrix),
                                            *triple_arrays(coefficients.triples), q0, q)
    else:
        _kernels.conventional_kernel(theta, np.ascontiguousarray(coefficients.matrix), q0, q)
    t = t0 + np.arange(m + 1) * (n * h)
    return AttitudeSolution(t, q, "conventional", coefficients, h, n * h, np.zeros(m + 1, int))


def startup_sets(coefficients: CoefficientSet) -> list[CoefficientSet]:
    """The k-subsample sets (k = 1 … N−1) used by the real-time start-up, then the main set."""
    out = []
    for k in range(1, coefficients.n):
        try:
            out.append(coefficient_set(coning_set_name(coefficients.name), k))
        except ValueError:
            out.append(coefficient_set("table3", k))
    out.append(coefficients)
    return out


def stack_sets(sets: Sequence[CoefficientSet]) -> NDArray[np.float64]:
    """Pack k-subsample matrices into the ``(N, N, N)`` array the real-time kernel reads."""
    n = len(sets)
    ks = np.zeros((n, n, n))
    for k, s in enumerate(sets, start=1):
        if s.n != k:
            raise ValueError(f"start-up set {k} must have N = {k}, got N = {s.n}")
        ks[k - 1, :k, :k] = s.matrix
    return ks


def realtime(
    increments: ArrayLike | GyroRecord | ImuLog,
    coefficients: CoefficientSet,
    *,
    h: float | None = None,
    t0: float | None = None,
    q0: ArrayLike | None = None,
    startup: Sequence[CoefficientSet] | None = None,
) -> AttitudeSolution:
    """Li & Zhang 2017 real-time structure (eq. 15): an output every ``h``.

    Parameters
    ----------
    increments, coefficients, h, t0, q0
        As for :func:`conventional` (an array with ``h``, or an increment record).
    startup : sequence of CoefficientSet, optional
        The k-subsample sets for the first ``N − 1`` outputs, ``k = 1 … N−1``
        (default: :func:`startup_sets`).

    Returns
    -------
    AttitudeSolution
        ``n + 1`` outputs at ``t0 + k h``; output ``k`` belongs to chain ``k mod N``.
    """
    increments, h, t0 = _record_inputs(increments, h, t0, "realtime")
    theta, h, q0, t0 = _check_inputs(increments, coefficients, h, q0, t0)
    n = coefficients.n
    if coefficients.triples:
        raise ValueError(f"the real-time structure runs pair-only sets; {coefficients.name!r} "
                         "has triple terms (run it conventional or single-chain)")
    sets = startup_sets(coefficients) if startup is None else [*startup, coefficients]
    ks = stack_sets(sets)
    q = np.empty((theta.shape[0] + 1, 4))
    _kernels.realtime_kernel(theta, ks, q0, q)
    k = np.arange(theta.shape[0] + 1)
    return AttitudeSolution(t0 + k * h, q, "realtime", coefficients, h, h, k % n)


def increment_structure(name: object) -> UpdateStructure:
    """The registered structure ``name`` if it runs increments, else ValueError listing
    them."""
    found = STRUCTURE_REGISTRY.get(name) if isinstance(name, str) else None
    if found is None or not found.runs_increments:
        raise ValueError(f"unknown structure {name!r}; choose one of {', '.join(STRUCTURES)}")
    return found


def run_structure(name: IncrementStructure | UpdateStructure,
                  increments: ArrayLike | GyroRecord | ImuLog,
                  coefficients: CoefficientSet, *, h: float | None = None,
                  t0: float | None = None, q0: ArrayLike | None = None) -> AttitudeSolution:
    """Run ``coefficients`` in the increment structure ``name`` (:meth:`UpdateStructure.run`).

    The conventional structure drops a tail of fewer than N increments here
    (``tail="drop"``); call :func:`conventional` directly to have it refused.
    """
    return increment_structure(name).run(increments, coefficients, h=h, t0=t0, q0=q0)


def windowed(samples: ArrayLike, algorithm: WindowedAlgorithm, *, h: float, t0: float = 0.0,
             q0: ArrayLike | None = None, sliding: bool = False,
             startup: WindowedAlgorithm | None = None) -> AttitudeSolution:
    """Run a :class:`~strapdown.algorithms.coning.WindowedAlgorithm` on a sample stream.

    Sample ``k`` is the increment over ``[t0 + k h, t0 + (k+1) h]`` or the rate
    at ``t0 + k h``. The first ``algorithm.history`` samples only feed the
    first windows: the initial attitude ``q0`` is at ``t0 + history·h``.

    ``sliding=False``: an update every ``algorithm.update`` samples (one chain).
    ``sliding=True`` (Wang et al.'s sliding scheme): an output every sample,
    ``q(k) = q(k − U) ⊗ q(φ over [k − U, k])``; the first ``U − 1`` outputs come
    from ``startup`` (a one-sample WindowedAlgorithm, e.g. the single-period
    rate algorithm) chained from ``q0``. That is ``U`` interleaved chains.
    """
    if not isinstance(algorithm, WindowedAlgorithm):
        raise ValueError(f"algorithm must be a WindowedAlgorithm, got {type(algorithm).__name__}")
    x, h, t0, q0 = _stream_inputs(samples, "samples", h, t0, q0)
    return _windowed(np.ascontiguousarray(x), algorithm, h, t0, q0, sliding, startup)


def _windowed(x: NDArray[np.float64], algorithm: WindowedAlgorithm, h: float, t0: float,
              q0: NDArray[np.float64], sliding: bool,
              startup: WindowedAlgorithm | None) -> AttitudeSolution:
    """:func:`windowed` on inputs already validated (C-contiguous float64, unit q0)."""
    b0 = algorithm.history
    last = x.shape[0] - 1 - algorithm.span  # largest admissible update start
    if last < b0:
        need = b0 + algorithm.span + 1
        raise ValueError(f"{algorithm.name!r} needs at least {need} samples, got {x.shape[0]}")
    u = algorithm.update
    # output times t0 + (b0 + k·step)·h, built in place: the float arange holds the same
    # integers exactly (< 2**53), then the same product and the same (commutative) sum
    step = 1 if sliding else u
    rows = (last - b0) // step + 1 + (u if sliding else 1)
    t = np.arange(b0, b0 + rows * step, step, dtype=np.float64)
    t *= h
    t += t0
    q = np.empty((rows, 4))
    q[0] = q0
    if not sliding:
        _run_windowed(x, algorithm, h, b0, u, 1, q)
        return AttitudeSolution(t, q, "windowed", None, h, u * h, np.zeros(rows, int))
    if startup is None or startup.update != 1:
        raise ValueError("the sliding scheme needs a one-sample startup algorithm")
    if u > 1:
        _run_windowed(x, startup, h, b0, 1, 1, q[:u])
    _run_windowed(x, algorithm, h, b0, 1, u, q)
    chain = np.empty(rows, dtype=int)  # k mod u, without the temporaries of np.arange % u
    for j in range(u):
        chain[j::u] = j
    return AttitudeSolution(t, q, "sliding", None, h, h, chain)


def _run_windowed(x: NDArray[np.float64], algorithm: WindowedAlgorithm, h: float, b0: int,
                  step: int, stride: int, q: NDArray[np.float64]) -> None:
    """Fused kernel call for a WindowedAlgorithm: the update starting at sample
    ``b0 + r·step`` writes ``q[r + stride]`` from ``q[r]``, for every row after ``q[:stride]``
    (rates scale α by h and β by h²).

    The four-sample window with all six pairs (the three-period rate algorithm) runs in
    :func:`~strapdown.algorithms._kernels.window4_kernel` (registers, no index array, the
    same operations); every other shape in the general ``windowed_kernel``.
    """
    count = q.shape[0] - stride
    if count <= 0:
        return
    sa, sb = (1.0, 1.0) if algorithm.input == "increment" else (h, h * h)
    weights = np.array([float(w) for w in algorithm.weights])
    pc = np.array([float(c) for c in algorithm.pair_coefficients])
    pairs = tuple(tuple(p) for p in algorithm.pairs)
    if tuple(algorithm.offsets) == (0, 1, 2, 3) and pairs == ((0, 1), (0, 2), (0, 3), (1, 2),
                                                               (1, 3), (2, 3)):
        _kernels.window4_kernel(x, weights, pc, sa, sb, b0, step, stride, q)
        return
    ij = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    _kernels.windowed_kernel(x, np.array(algorithm.offsets, dtype=np.int64), weights,
                             np.ascontiguousarray(ij[:, 0]), np.ascontiguousarray(ij[:, 1]),
                             pc, sa, sb, np.arange(b0, b0 + count * step, step, dtype=np.int64),
                             stride, q)


def single_chain_coefficients(n: int) -> tuple[Fraction, ...]:
    """Exact single-chain coefficients ``c_1 … c_{N−1}`` (classical-coning optimum, designer;
    tabulated in :data:`strapdown.algorithms.tables.SINGLE_CHAIN`)."""
    n = positive_int(n, "N (subsamples)")
    if n not in tables.SINGLE_CHAIN:
        raise ValueError(f"single-chain coefficients are tabulated for N = 1 … "
                         f"{max(tables.SINGLE_CHAIN)}, got N = {n}")
    return tables.SINGLE_CHAIN[n]


def single_chain_table(n: int) -> NDArray[np.float64]:
    """Start-up and steady coefficients, shape (N, N − 1): row m holds c_1 … c_m of the
    (m+1)-sample single-chain set (row N − 1 is the steady set)."""
    n = positive_int(n, "N (subsamples)")
    c = np.zeros((n, max(n - 1, 1)))
    for m in range(1, n):
        c[m, :m] = [float(x) for x in single_chain_coefficients(m + 1)]
    return c


def single_chain(increments: ArrayLike | GyroRecord | ImuLog, n: int, *,
                 h: float | None = None, t0: float | None = None, q0: ArrayLike | None = None,
                 triple: bool = False) -> AttitudeSolution:
    """Single-chain high-rate structure: an attitude every h with N-subsample accuracy.

    ``φ_k = θ_k + Σ_{m=1}^{N−1} c_m θ_{k−m} × θ_k``, ``q_k = q_{k−1} ⊗ q(φ_k)``,
    coefficients from the designer (:func:`strapdown.design.single_chain_structure`),
    ``c_m = (K_m − (N−m)/2)/N`` in terms of the conventional lag sums. Its
    classical-coning drift equals the conventional N-subsample drift at the
    same h, from one chain (no sawtooth). Start-up: increment k < N−1 uses the
    (k+1)-sample set.

    ``triple=True``: the finite-amplitude set, the same pairs plus
    ``Σ_m τ_m θ_k × (θ_{k−m} × θ_k)`` once N − 1 previous increments exist
    (:mod:`strapdown.algorithms.finite_amplitude`; the start-up is the plain one).

    ``increments``, ``h`` and ``t0`` as for :func:`conventional`: an array with ``h``, or
    an increment record that gives both.
    """
    increments, h, t0 = _record_inputs(increments, h, t0, "single_chain")
    n = positive_int(n, "N (subsamples)")
    theta = np.ascontiguousarray(as_vectors(increments, "increments"))
    if theta.ndim != 2 or theta.shape[0] < 1:
        raise ValueError(f"increments must have shape (n, 3) with n ≥ 1, got {theta.shape}")
    h = positive(h, "h (sample interval)")
    t0 = float(finite_array(t0, "t0"))
    q0 = _unit_q0(q0)
    q = np.empty((theta.shape[0] + 1, 4))
    q[0] = q0
    if not triple:
        _kernels.single_chain_kernel(theta, single_chain_table(n), 0, 0, q)
    else:
        s = min(n - 1, theta.shape[0])
        _kernels.single_chain_kernel(np.ascontiguousarray(theta[:s]), single_chain_table(n), 0,
                                     0, q[:s + 1])
        if theta.shape[0] > s:
            tm, ti, tj, tc = triple_arrays(triple_terms("single-chain", n))
            c = np.array([float(v) for v in single_chain_coefficients(n)], dtype=np.float64)
            _kernels.single_chain_triple_kernel(theta, c, tm, ti, tj, tc, s, q[s:])
    t = t0 + np.arange(q.shape[0]) * h
    return AttitudeSolution(t, q, "single-chain", None, h, h, np.zeros(t.size, int),
                            min(n - 1, t.size - 1))


def _record_inputs(increments: ArrayLike | GyroRecord | ImuLog, h: float | None,
                   t0: float | None, name: str) -> tuple[ArrayLike, float, float]:
    """``(increments, h, t0)`` of a structure call: an array with ``h`` (``t0`` default 0),
    or a record with ``data``, ``kind``, ``h`` and ``t`` (a GyroRecord, an ImuLog) whose
    own interval and start edge are used, as ``AlgorithmSpec.run`` does (``t`` one entry
    longer than ``data``: the interval edges; as long: the interval ends). An ``h`` or
    ``t0`` given with a record must agree with it."""
    data, kind = getattr(increments, "data", None), getattr(increments, "kind", None)
    if data is None or kind is None:
        if h is None:
            raise ValueError(f"{name} needs h (the increment interval, s) with an array of "
                             "increments; a GyroRecord or ImuLog carries its own")
        return cast("ArrayLike", increments), h, 0.0 if t0 is None else t0
    if kind != "increment":
        raise ValueError(f"{name} takes angular increments; this record holds {kind}s (a rate "
                         "record runs through AlgorithmSpec.run with a rate algorithm)")
    data = np.asarray(data)
    rh = float(getattr(increments, "h"))  # noqa: B009 (a record's, whatever its class)
    t = np.asarray(getattr(increments, "t"), dtype=np.float64)  # noqa: B009
    rt0 = float(t[0]) if t.shape[0] == data.shape[0] + 1 else float(t[0]) - rh
    for what, given, own in (("h", h, rh), ("t0", t0, rt0)):
        if given is not None and not np.isclose(given, own, rtol=1e-12, atol=0.0):
            raise ValueError(f"{name}: {what} = {given!r} contradicts the record's {own!r} "
                             f"(drop {what}=: a record carries its own)")
    return data, rh, rt0


def _stream_inputs(samples: ArrayLike, name: str, h: float, t0: float, q0: ArrayLike | None
                   ) -> tuple[NDArray[np.float64], float, float, NDArray[np.float64]]:
    """Validated (samples (n, 3), h, t0, unit q0) of a sample-stream call."""
    x = as_vectors(samples, name)
    if x.ndim != 2:
        raise ValueError(f"{name} must have shape (n, 3), got {x.shape}")
    return (x, positive(h, "h (sample interval)"), float(finite_array(t0, "t0")),
            _unit_q0(q0))


def _unit_q0(q0: ArrayLike | None) -> NDArray[np.float64]:
    if q0 is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q0 = as_quaternions(q0, "q0")
    if q0.shape != (4,):
        raise ValueError(f"q0 must have shape (4,), got {q0.shape}")
    return q0 / np.linalg.norm(q0)


def chain_rotation_vectors(phi: ArrayLike, *, update_period: float, t0: float = 0.0,
                           q0: ArrayLike | None = None) -> AttitudeSolution:
    """Chain precomputed body rotation vectors: ``q_k = q_{k−1} ⊗ q(φ_k)``."""
    phi = as_vectors(phi, "phi")
    if phi.ndim != 2:
        raise ValueError(f"phi must have shape (n, 3), got {phi.shape}")
    dt = positive(update_period, "update_period")
    q0 = _unit_q0(q0)
    q = np.empty((phi.shape[0] + 1, 4))
    _kernels.chain_kernel(np.ascontiguousarray(phi), q0[None, :], 1, q)
    t = float(finite_array(t0, "t0")) + np.arange(q.shape[0]) * dt
    return AttitudeSolution(t, q, "chained", None, dt, dt, np.zeros(t.size, int))
