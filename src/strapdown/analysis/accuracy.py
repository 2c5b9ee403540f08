"""Accuracy analysis: attitude errors, drift rates, analytic predictions.

Drift rate (conventions.md): least-squares slope of the reference-frame error
vector against time. For periodic motions only the outputs that fall on whole
periods after a reference time are used, which removes the periodic part of
the error exactly; otherwise all outputs are used and the result says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

from strapdown._core.validation import (
    as_quaternions,
    as_times,
    as_vectors,
    finite_array,
    positive,
    positive_int,
)
from strapdown.algorithms.coning import table1_drift_constant
from strapdown.algorithms.family import IncrementStructure
from strapdown.algorithms.structures import increment_structure
from strapdown.rotation.error import attitude_error_angle, attitude_error_vector
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply
from strapdown.truth.motions import Motion

__all__ = [
    "DriftEstimate",
    "accumulated_drift",
    "attitude_errors",
    "chain_drift_rate",
    "drift_rate",
    "integrate_attitude_ode",
    "rotation_per_update",
    "sawtooth_amplitude",
    "table1_prediction",
    "update_period",
]

#: Outputs within this fraction of a sample interval of a whole period count as on it.
PERIOD_TOLERANCE = 1e-6

_CHUNK = 1_000_000


def attitude_errors(t: ArrayLike, q_est: ArrayLike, motion: Motion
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Reference-frame error vectors and angles of ``q_est`` against the motion's truth.

    Evaluated in chunks, so 10⁸-sample records need no more than a few
    hundred MB.

    Returns
    -------
    err : ndarray of shape (n, 3)
        ``log(q_est ⊗ q_true*)`` (rad).
    angle : ndarray of shape (n,)
        Error angle (rad).
    """
    t = as_times(t, "t")
    q_est = as_quaternions(q_est, "q_est")
    if q_est.shape != (t.size, 4):
        raise ValueError(f"q_est must have shape ({t.size}, 4) to match t, got {q_est.shape}")
    err = np.empty((t.size, 3))
    ang = np.empty(t.size)
    for s in range(0, t.size, _CHUNK):
        sl = slice(s, s + _CHUNK)
        q_true = motion.attitude(t[sl])
        err[sl] = attitude_error_vector(q_est[sl], q_true)
        ang[sl] = attitude_error_angle(q_est[sl], q_true)
    return err, ang


@dataclass(frozen=True)
class DriftEstimate:
    """A drift-rate estimate.

    Attributes
    ----------
    rate : ndarray of shape (3,)
        Least-squares slope of the error vector (rad/s, reference frame).
    method : str
        ``"whole-periods"`` or ``"all-samples"``.
    points : int
        Number of error samples used.
    """

    rate: NDArray[np.float64]
    method: str
    points: int


def drift_rate(t: ArrayLike, err: ArrayLike, *, period: float | None = None,
               reference_time: float | None = None, h: float | None = None) -> DriftEstimate:
    """Least-squares drift rate of an error series.

    Parameters
    ----------
    t : array_like of shape (n,)
        Strictly increasing times (s).
    err : array_like of shape (n, 3) or (n,)
        Error vectors (or a scalar component), rad.
    period : float, optional
        Period of the motion's error pattern. When given and at least two
        samples lie on whole periods after ``reference_time`` (within
        :data:`PERIOD_TOLERANCE` of a sample interval), only those are used.
    reference_time : float, optional
        Phase origin for the whole periods (default ``t[0]``).
    h : float, optional
        Sample spacing used for the tolerance (default: median spacing).
    """
    t = as_times(t, "t", min_len=2)
    e = np.asarray(err, dtype=np.float64)
    scalar = e.ndim == 1
    e2 = e[:, None] if scalar else as_vectors(e, "err")
    if e2.shape[0] != t.size:
        raise ValueError(f"err must have {t.size} rows to match t, got {e2.shape[0]}")
    method = "all-samples"
    sel = np.ones(t.size, dtype=bool)
    if period is not None:
        period = positive(period, "period")
        ref = t[0] if reference_time is None else float(reference_time)
        dt = float(np.median(np.diff(t))) if h is None else positive(h, "h")
        k = (t - ref) / period
        on = np.abs(k - np.round(k)) * period < PERIOD_TOLERANCE * dt
        on &= t >= ref - PERIOD_TOLERANCE * dt
        if np.count_nonzero(on) >= 2:
            sel = on
            method = "whole-periods"
    ts = t[sel]
    es = e2[sel]
    tc = ts - ts.mean()
    slope = (tc @ (es - es.mean(axis=0))) / (tc @ tc)
    rate = slope[0] if scalar else slope
    return DriftEstimate(np.asarray(rate), method, int(ts.size))


def chain_drift_rate(t: ArrayLike, err: ArrayLike, chain: ArrayLike, *,
                     period: float | None = None) -> tuple[DriftEstimate, ...]:
    """Drift of each interleaved chain of a multi-chain structure.

    Each chain is sampled at whole periods after its own first output, so its
    start-up offset and periodic error cancel.
    """
    t = as_times(t, "t", min_len=2)
    chain = np.asarray(chain)
    if chain.shape != t.shape:
        raise ValueError(f"chain must have shape {t.shape} to match t, got {chain.shape}")
    h = float(np.median(np.diff(t)))
    out = []
    for c in np.unique(chain):
        idx = np.flatnonzero(chain == c)
        out.append(drift_rate(t[idx], np.asarray(err)[idx], period=period,
                              reference_time=t[idx[0]], h=h))
    return tuple(out)


def sawtooth_amplitude(err: ArrayLike, chain: ArrayLike, window: int) -> NDArray[np.float64]:
    """Peak-to-peak N-periodic component of an error series, per window of samples.

    In each window the error is regressed on a linear trend plus one constant
    per chain label; the spread of those constants is the sawtooth amplitude.
    On a single-chain output, pass ``k mod N`` labels to measure what the
    regression finds in a series with no chains (the noise baseline).
    """
    e = np.asarray(err, dtype=np.float64)
    chain = np.asarray(chain)
    if e.ndim != 1 or chain.shape != e.shape:
        raise ValueError(f"err and chain must be 1-D of equal length, got {e.shape}, {chain.shape}")
    window = positive_int(window, "window")
    n = int(chain.max()) + 1
    out = []
    for w0 in range(0, e.size - window + 1, window):
        k = np.arange(w0, w0 + window)
        x = np.column_stack([k - k.mean()] + [(chain[k] == r).astype(float) for r in range(n)])
        c, *_ = np.linalg.lstsq(x, e[k], rcond=None)
        out.append(np.ptp(c[1:]))
    return np.array(out)


def accumulated_drift(q_est: ArrayLike, q_true: ArrayLike) -> NDArray[np.float64]:
    """Plaksiy's accumulated drift time series: ``2 |vec(Λ_true* ∘ Λ_est)|`` (rad).

    The vector part has the same norm in the body- and reference-frame error
    conventions; ``q_est`` need not be unit (the paper does not renormalise).
    The paper's figure of merit is the maximum of this series over the run.
    """
    q_est = as_quaternions(q_est, "q_est")
    q_true = as_quaternions(q_true, "q_true")
    d = quat_multiply(quat_conjugate(q_true), q_est)
    return 2.0 * np.linalg.norm(d[..., 1:], axis=-1)


def table1_prediction(half_angle: float, cone_rate: float, h: float, n: int) -> float:
    """Table 1 drift about the cone axis (rad/s): ``−c_N a² Ω (Ωh)^{2N}``.

    Leading order in the half-cone angle ``a`` for the optimal N-subsample set
    (Li & Zhang 2017 Table 1; ``c_N = N!(N+1)!/(2N+2)!``). The sign
    is negative: the computed attitude drifts against the cone rotation.
    """
    h = positive(h, "h")
    half_angle, cone_rate = finite_array([half_angle, cone_rate], "half_angle/cone_rate")
    c = float(table1_drift_constant(n))
    return -c * half_angle**2 * cone_rate * (cone_rate * h) ** (2 * n)


def update_period(structure: IncrementStructure, n: int, h: float) -> float:
    """Time between attitude outputs of an N-subsample increment structure: ``N h``
    (conventional) or ``h`` (real-time, single chain) — the structure's own answer
    (:meth:`~strapdown.algorithms.structures.UpdateStructure.update_period`)."""
    n = positive_int(n, "N")
    h = positive(h, "h")
    return increment_structure(structure).update_period(n, h)


def rotation_per_update(rate: float, structure: IncrementStructure, n: int, h: float) -> float:
    """Rotation angle between outputs for a constant rate: ``|ω| · update_period`` (rad).

    This is what Li & Zhang 2017 Tables 4/5 call the "angular increment per update".
    """
    return abs(float(finite_array(rate, "rate"))) * update_period(structure, n, h)


def integrate_attitude_ode(motion: Motion, t: ArrayLike, *, q0: ArrayLike | None = None,
                           rtol: float = 1e-13, atol: float = 1e-15) -> NDArray[np.float64]:
    """Integrate ``q̇ = ½ q ⊗ [0, ω_b]`` with DOP853 at ``rtol ≤ 1e-12``.

    An independent check of a motion's closed-form attitude (or of a
    :class:`~strapdown.truth.motions.UserMotion`'s consistency).

    Returns
    -------
    ndarray of shape (len(t), 4)
    """
    t = as_times(t, "t")
    if rtol > 1e-12:
        raise ValueError(f"rtol must be at most 1e-12 for a truth reference, got {rtol}")
    q0 = motion.attitude(t[0]) if q0 is None else as_quaternions(q0, "q0")

    def f(tt, q):
        w = motion.rate(np.array(tt))
        return 0.5 * quat_multiply(q, np.concatenate([[0.0], w]))

    if t.size == 1:
        return q0[None, :]
    sol = solve_ivp(f, (t[0], t[-1]), q0, method="DOP853", t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"ODE integration failed: {sol.message}")
    return sol.y.T
