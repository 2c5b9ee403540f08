"""Coning correction of the rotation vector from N angular increments.

Every correction has the general pair form (Li & Zhang 2017 eq. 6 generalised)

.. math::  φ = Σ_{i=1}^{N} θ_i + Σ_{i<j} k_{ij}\\, θ_i × θ_j ,

with an upper-triangular coefficient matrix ``K`` (``K[i, j]`` multiplies
``θ_{i+1} × θ_{j+1}`` in 0-based storage). Named sets:

``table3``
    Li & Zhang 2017 Table 3 read as "cross with the last subsample"
    (Li & Zhang (2017) print eq. 6 over all pairs):
    ``φ = Σθ + Σ_{m=1}^{N−1} ς_m θ_{N−m} × θ_N``. The
    classical-coning optimum; drift constant N!(N+1)!/(2N+2)!.
``lag``
    The same lag sums ``K_m = ς_m`` spread evenly over all ``N − m`` pairs of
    lag ``m`` — same leading drift under classical coning.
``eq6-printed``
    Eq. 6 exactly as printed, ``Σ_{i<j} ς_i θ_i × θ_j``
    (:func:`strapdown.algorithms.errata.eq6_printed_matrix`, with its measured
    difference). Kept so the report can show that it drifts 10⁵–10¹² times
    faster than Table 1 for N ≥ 3.
``miller``
    Miller (1983) three-sample set: ``33/80 θ1×θ3 + 57/80 θ2×(θ3 − θ1)``.
``none``
    No correction (``φ = Σθ``).
``finite-amplitude``
    Table 3 plus triple cross products ``Σ_m τ_m θ_N × (θ_{N−m} × θ_N)`` that cancel the
    ``a⁴`` classical-coning drift through the order of the Table 1 law
    (:mod:`.finite_amplitude`; the single chain has its own set there). Runs in the
    conventional and single-chain structures.

A user set is any ``(N, N)`` strictly upper-triangular matrix
(:func:`user_coefficients`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.kinds import InputKind
from strapdown._core.validation import as_vectors, finite_array, positive_int
from strapdown.algorithms.errata import eq6_printed_matrix
from strapdown.algorithms.finite_amplitude import triple_terms

__all__ = [
    "CONING_SETS",
    "MAX_SUBSAMPLES",
    "TABLE3",
    "CoefficientSet",
    "ConingSetName",
    "WindowedAlgorithm",
    "coefficient_set",
    "coefficient_set_names",
    "coning_set_name",
    "rotation_vectors",
    "table1_drift_constant",
    "triple_arrays",
    "user_coefficients",
]

#: Largest N for which named sets are tabulated (N = 6 extends Table 3 by the
#: same classical-coning optimisation; see :data:`TABLE3`).
MAX_SUBSAMPLES = 6

F = Fraction

#: The named coefficient sets (see the module docstring).
ConingSetName = Literal["table3", "lag", "eq6-printed", "miller", "none", "finite-amplitude"]
#: Their names, in the order the command line lists them.
CONING_SETS: tuple[ConingSetName, ...] = get_args(ConingSetName)

#: Li & Zhang 2017 Table 3 (ς_1 … ς_{N−1}); N = 6 is our extension, derived by
#: the same classical-coning optimisation (exact rationals, checked against the
#: Table 1 drift law 1/24024 in the test suite).
TABLE3: dict[int, tuple[Fraction, ...]] = {
    1: (),
    2: (F(2, 3),),
    3: (F(27, 20), F(9, 20)),
    4: (F(214, 105), F(92, 105), F(54, 105)),
    5: (F(1375, 504), F(325, 252), F(25, 24), F(125, 252)),
    6: (F(15797, 4620), F(3917, 2310), F(608, 385), F(2279, 2310), F(463, 924)),
}


def table1_drift_constant(n: int) -> Fraction:
    """Classical-coning drift constant ``c_N = N!(N+1)!/(2N+2)!`` of the optimal N-subsample set.

    Drift about the cone axis is ``−c_N a² Ω (Ωh)^{2N}`` to leading order in the
    half-cone angle ``a`` (Li & Zhang 2017 Table 1: 1/12, 1/60, 1/280, 1/1260, 1/5544).
    """
    from math import factorial

    n = positive_int(n, "N")
    return F(factorial(n) * factorial(n + 1), factorial(2 * n + 2))


@dataclass(frozen=True)
class CoefficientSet:
    """A coning-correction coefficient matrix for N subsamples.

    Attributes
    ----------
    name : str
        Registry name (``"table3"``, ``"lag"``, ``"eq6-printed"``, ``"miller"``,
        ``"none"`` or ``"user"``).
    n : int
        Number of subsamples N.
    matrix : ndarray of shape (N, N)
        Strictly upper-triangular float64 ``K``.
    exact : tuple of tuple of Fraction, optional
        The exact rational matrix when the set is rational.
    reference : str
        Where the set comes from.
    classical_optimum : bool
        Whether the set has the optimal classical-coning lag sums, so that the
        Table 1 drift law applies.
    triples : tuple of (int, int, int, Fraction)
        Triple cross products ``(m, i, j, τ)``: ``τ θ_m × (θ_i × θ_j)`` added to φ (0-based;
        empty for the pair-only sets).
    """

    name: str
    n: int
    matrix: NDArray[np.float64] = field(repr=False)
    exact: tuple[tuple[Fraction, ...], ...] | None = field(default=None, repr=False)
    reference: str = ""
    classical_optimum: bool = False
    triples: tuple[tuple[int, int, int, Fraction], ...] = field(default=(), repr=False)

    def lag_sums(self) -> NDArray[np.float64]:
        """``K_m = Σ_{j−i=m} k_ij`` for ``m = 1 … N−1``."""
        return np.array([np.trace(self.matrix, offset=m) for m in range(1, self.n)])


def _from_exact(name, rows, reference, optimum) -> CoefficientSet:
    n = len(rows)
    mat = np.array([[float(v) for v in r] for r in rows], dtype=np.float64).reshape(n, n)
    return CoefficientSet(name, n, mat, tuple(tuple(r) for r in rows), reference, optimum)


def _zeros(n):
    return [[F(0)] * n for _ in range(n)]


def _table3(n):
    k = _zeros(n)
    for m, s in enumerate(TABLE3[n], start=1):
        k[n - 1 - m][n - 1] = s
    return _from_exact("table3", k, "Li & Zhang 2017 Table 3, cross-with-last", True)


def _lag(n):
    k = _zeros(n)
    for m, s in enumerate(TABLE3[n], start=1):
        for i in range(n - m):
            k[i][i + m] = s / (n - m)
    return _from_exact("lag", k, "Table 3 lag sums spread evenly over each lag", True)


def _eq6(n):
    k = eq6_printed_matrix(TABLE3[n])
    return _from_exact("eq6-printed", k, "Li & Zhang 2017 eq. 6 as printed", n <= 2)


def _miller(n):
    if n != 3:
        raise ValueError(f"the 'miller' set exists for N = 3 only, got N = {n}")
    k = _zeros(3)
    k[0][2] = F(33, 80)
    k[1][2] = F(57, 80)
    k[0][1] = F(57, 80)  # θ2 × (−θ1) = θ1 × θ2
    return _from_exact("miller", k, "Miller 1983 three-sample set", False)


def _none(n):
    return _from_exact("none", _zeros(n), "no coning correction", n == 1)


def _finite_amplitude(n):
    base = _table3(n)
    return CoefficientSet("finite-amplitude", n, base.matrix, base.exact,
                          "Table 3 + triple cross products (strapdown designer: a⁴ cancelled, "
                          "and a⁶ for N = 4-6)",
                          True, triple_terms("conventional", n))


def triple_arrays(triples: tuple[tuple[int, int, int, Fraction], ...]
                  ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
                             NDArray[np.float64]]:
    """Triple terms ``(m, i, j, τ)`` as the kernels read them: m, i, j (int64) and τ arrays."""
    cols = [np.array([t[k] for t in triples], dtype=np.int64) for k in range(3)]
    return cols[0], cols[1], cols[2], np.array([float(t[3]) for t in triples],
                                               dtype=np.float64)


_REGISTRY: dict[ConingSetName, Callable[[int], CoefficientSet]] = {
    "table3": _table3,
    "lag": _lag,
    "eq6-printed": _eq6,
    "miller": _miller,
    "none": _none,
    "finite-amplitude": _finite_amplitude,
}
if tuple(_REGISTRY) != CONING_SETS:  # one list of names: the Literal
    raise RuntimeError(f"coefficient sets {tuple(_REGISTRY)} and ConingSetName {CONING_SETS} "
                       "disagree")


def coefficient_set_names() -> tuple[ConingSetName, ...]:
    """Names accepted by :func:`coefficient_set`."""
    return CONING_SETS


def coning_set_name(name: object) -> ConingSetName:
    """``name`` if it names a coefficient set, else ValueError listing the names."""
    if name not in CONING_SETS:
        raise ValueError(
            f"unknown coefficient set {name!r}; choose one of {', '.join(CONING_SETS)} "
            "or pass a matrix to user_coefficients()"
        )
    return name


def coefficient_set(name: ConingSetName, n: int) -> CoefficientSet:
    """A named coefficient set for ``N = n`` subsamples.

    Raises
    ------
    ValueError
        For an unknown name or an N outside ``1 … MAX_SUBSAMPLES``.
    """
    n = positive_int(n, "N (subsamples)")
    name = coning_set_name(name)
    if n > MAX_SUBSAMPLES:
        raise ValueError(f"named sets are tabulated for N = 1 … {MAX_SUBSAMPLES}, got N = {n}")
    return _REGISTRY[name](n)


def user_coefficients(matrix: ArrayLike, *, name: str = "user") -> CoefficientSet:
    """Wrap a user ``(N, N)`` matrix ``K`` (only the strict upper triangle may be non-zero)."""
    k = finite_array(matrix, "coefficient matrix")
    if k.ndim != 2 or k.shape[0] != k.shape[1] or k.shape[0] < 1:
        raise ValueError(f"coefficient matrix must have shape (N, N), got {k.shape}")
    if np.any(np.tril(k) != 0.0):
        raise ValueError(
            "coefficient matrix must be strictly upper triangular: K[i, j] multiplies "
            "θ_i × θ_j for i < j"
        )
    return CoefficientSet(name, k.shape[0], k.copy(), None, "user matrix", False)


def rotation_vectors(increments: ArrayLike, coefficients: CoefficientSet
                     ) -> NDArray[np.float64]:
    """Rotation vectors of consecutive non-overlapping groups of N increments.

    Parameters
    ----------
    increments : array_like of shape (M·N, 3)
        Angular increments θ (rad).
    coefficients : CoefficientSet
        The correction for N subsamples.

    Returns
    -------
    ndarray of shape (M, 3)
        ``φ = Σθ + Σ_{i<j} k_ij θ_i × θ_j`` for each group (Li & Zhang 2017
        eq. 6 in general pair form), plus the set's triple terms ``τ θ_m × (θ_i × θ_j)``.
    """
    theta = as_vectors(increments, "increments")
    if theta.ndim != 2:
        raise ValueError(f"increments must have shape (n, 3), got {theta.shape}")
    n = coefficients.n
    if theta.shape[0] < n or theta.shape[0] % n:
        raise ValueError(
            f"increments must hold a whole number of groups of N = {n} samples, "
            f"got {theta.shape[0]}"
        )
    g = theta.reshape(-1, n, 3)
    phi = g.sum(axis=1)
    k = coefficients.matrix
    for i in range(n):
        for j in range(i + 1, n):
            if k[i, j] != 0.0:
                phi = phi + k[i, j] * np.cross(g[:, i], g[:, j])
    for m, i, j, c in coefficients.triples:
        phi = phi + float(c) * np.cross(g[:, m], np.cross(g[:, i], g[:, j]))
    return phi


@dataclass(frozen=True)
class WindowedAlgorithm:
    """A rotation-vector algorithm over a window of samples (general form).

    ``φ = s_α Σ_n w_n x_{b+o_n} + s_β Σ_p c_p x_{b+o_i} × x_{b+o_j}`` for the
    update starting at sample ``b``, with ``s_α = 1, s_β = 1`` for increment
    input and ``s_α = h, s_β = h²`` for rate input. Updates every ``update``
    samples.

    Attributes
    ----------
    input : {"increment", "rate"}
    update : int
    offsets : tuple of int
        Node offsets from the update's first sample (negative: history).
    weights, pair_coefficients : tuple of Fraction
        Exact weights per node and coefficient per pair.
    pairs : tuple of (int, int)
        Node indices of each cross product.
    name : str
    """

    input: InputKind
    update: int
    offsets: tuple[int, ...]
    weights: tuple[Fraction, ...]
    pairs: tuple[tuple[int, int], ...]
    pair_coefficients: tuple[Fraction | float, ...]
    name: str = "windowed"

    @property
    def history(self) -> int:
        """Samples needed before the first update's start."""
        return max(0, -min(self.offsets))

    @property
    def span(self) -> int:
        """Largest node offset (the update needs samples up to b + span)."""
        return max(self.offsets)

    def rotation_vectors(self, samples: NDArray[np.float64], starts: NDArray[np.int64],
                         h: float) -> NDArray[np.float64]:
        """φ for the updates starting at sample indices ``starts`` (vectorised)."""
        idx = starts[:, None] + np.asarray(self.offsets)[None, :]
        s = samples[idx]  # (updates, nodes, 3)
        sa, sb = (1.0, 1.0) if self.input == "increment" else (h, h * h)
        w = np.array([float(x) for x in self.weights])
        phi = sa * np.einsum("n,unk->uk", w, s)
        for (i, j), c in zip(self.pairs, self.pair_coefficients, strict=True):
            if c != 0:
                phi += (sb * float(c)) * np.cross(s[:, i], s[:, j])
        return phi

