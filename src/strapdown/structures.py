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
    information (papers.md): it raises the output rate, not the accuracy.
    :attr:`AttitudeSolution.chain` tells which chain produced each output.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from strapdown import _kernels
from strapdown._validation import as_quaternions, as_vectors, finite_array, positive
from strapdown.coning import CoefficientSet, coefficient_set

__all__ = ["STRUCTURES", "AttitudeSolution", "conventional", "realtime", "run_structure"]

STRUCTURES = ("conventional", "realtime")


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
        ``"conventional"`` or ``"realtime"``.
    coefficients : CoefficientSet
        The coning correction used.
    h : float
        Increment (subsample) interval (s).
    update_period : float
        Time between successive outputs (s).
    chain : ndarray of shape (m,)
        Index of the interleaved chain that produced each output (all 0 for
        the conventional structure).
    """

    t: np.ndarray
    q: np.ndarray
    structure: str
    coefficients: CoefficientSet
    h: float
    update_period: float
    chain: np.ndarray

    @property
    def chains(self) -> int:
        """Number of interleaved chains (N for the real-time structure, else 1)."""
        return int(self.chain.max()) + 1 if self.chain.size else 1


def _check_inputs(increments, coefficients, h, q0, t0):
    if not isinstance(coefficients, CoefficientSet):
        raise ValueError(
            "coefficients must be a CoefficientSet (see strapdown.coning.coefficient_set), "
            f"got {type(coefficients).__name__}"
        )
    theta = as_vectors(increments, "increments")
    if theta.ndim != 2:
        raise ValueError(f"increments must have shape (n, 3), got {theta.shape}")
    h = positive(h, "h (sample interval)")
    t0 = float(finite_array(t0, "t0"))
    if q0 is None:
        q0 = np.array([1.0, 0.0, 0.0, 0.0])
    else:
        q0 = as_quaternions(q0, "q0")
        if q0.shape != (4,):
            raise ValueError(f"q0 must have shape (4,), got {q0.shape}")
        q0 = q0 / np.linalg.norm(q0)
    n = coefficients.n
    if theta.shape[0] < n:
        raise ValueError(
            f"N = {n} subsamples need at least {n} increments, got {theta.shape[0]}"
        )
    return np.ascontiguousarray(theta), h, q0, t0


def conventional(
    increments,
    coefficients: CoefficientSet,
    *,
    h: float,
    t0: float = 0.0,
    q0=None,
    tail: str = "error",
) -> AttitudeSolution:
    """Conventional structure: an attitude update every ``T = N h``.

    Parameters
    ----------
    increments : array_like of shape (n, 3)
        Angular increments (rad) over consecutive intervals of length ``h``.
    coefficients : CoefficientSet
        Coning correction for N subsamples.
    h : float
        Increment interval (s).
    t0 : float
        Time of the first increment's start edge (s).
    q0 : array_like of shape (4,), optional
        Initial ``q_n_b`` (identity by default).
    tail : {"error", "drop"}
        What to do with increments that do not fill a last update.

    Returns
    -------
    AttitudeSolution
        ``n // N + 1`` outputs at ``t0 + j N h``.
    """
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
    _kernels.conventional_kernel(theta, np.ascontiguousarray(coefficients.matrix), q0, q)
    t = t0 + np.arange(m + 1) * (n * h)
    return AttitudeSolution(t, q, "conventional", coefficients, h, n * h, np.zeros(m + 1, int))


def startup_sets(coefficients: CoefficientSet) -> list[CoefficientSet]:
    """The k-subsample sets (k = 1 … N−1) used by the real-time start-up, then the main set."""
    out = []
    for k in range(1, coefficients.n):
        try:
            out.append(coefficient_set(coefficients.name, k))
        except ValueError:
            out.append(coefficient_set("table3", k))
    out.append(coefficients)
    return out


def stack_sets(sets: Sequence[CoefficientSet]) -> np.ndarray:
    """Pack k-subsample matrices into the ``(N, N, N)`` array the real-time kernel reads."""
    n = len(sets)
    ks = np.zeros((n, n, n))
    for k, s in enumerate(sets, start=1):
        if s.n != k:
            raise ValueError(f"start-up set {k} must have N = {k}, got N = {s.n}")
        ks[k - 1, :k, :k] = s.matrix
    return ks


def realtime(
    increments,
    coefficients: CoefficientSet,
    *,
    h: float,
    t0: float = 0.0,
    q0=None,
    startup: Sequence[CoefficientSet] | None = None,
) -> AttitudeSolution:
    """Li & Zhang 2017 real-time structure (eq. 15): an output every ``h``.

    Parameters
    ----------
    increments, coefficients, h, t0, q0
        As for :func:`conventional`.
    startup : sequence of CoefficientSet, optional
        The k-subsample sets for the first ``N − 1`` outputs, ``k = 1 … N−1``
        (default: :func:`startup_sets`).

    Returns
    -------
    AttitudeSolution
        ``n + 1`` outputs at ``t0 + k h``; output ``k`` belongs to chain ``k mod N``.
    """
    theta, h, q0, t0 = _check_inputs(increments, coefficients, h, q0, t0)
    n = coefficients.n
    sets = startup_sets(coefficients) if startup is None else [*startup, coefficients]
    ks = stack_sets(sets)
    q = np.empty((theta.shape[0] + 1, 4))
    _kernels.realtime_kernel(theta, ks, q0, q)
    k = np.arange(theta.shape[0] + 1)
    return AttitudeSolution(t0 + k * h, q, "realtime", coefficients, h, h, k % n)


def run_structure(name: str, increments, coefficients, *, h, t0=0.0, q0=None) -> AttitudeSolution:
    """Dispatch by structure name (``"conventional"`` or ``"realtime"``).

    The conventional structure drops a tail of fewer than N increments here
    (``tail="drop"``); call :func:`conventional` directly to have it refused.
    """
    if name == "conventional":
        return conventional(increments, coefficients, h=h, t0=t0, q0=q0, tail="drop")
    if name == "realtime":
        return realtime(increments, coefficients, h=h, t0=t0, q0=q0)
    raise ValueError(f"unknown structure {name!r}; choose one of {', '.join(STRUCTURES)}")
