"""An attitude error after fitting a constant world and a constant body rotation.

When the reference is in another world frame than the estimate (a robot's base frame, not
the filter's ENU) and measures another body frame (the link's, not the IMU's axes), an
estimate can only be compared with it after both constant rotations are found. This
module fits them to *each estimate* (the same procedure for every filter compared):

    q_est,k ≈ q_W ⊗ q_ref,k ⊗ q_B,

minimising the chordal (Frobenius) distance of the rotation matrices summed over the
evaluated samples, ``Σ_k ‖C(q_est,k) − C(q_W ⊗ q_ref,k ⊗ q_B)‖²_F = 8 Σ_k (1 − c_k²)``
with ``c_k = q_est,k · (q_W ⊗ q_ref,k ⊗ q_B)`` — insensitive to the sign of every
quaternion. For a fixed ``q_B`` the best ``q_W`` is the chordal L2 mean of
``q_est,k ⊗ (q_ref,k ⊗ q_B)*``, the unit eigenvector of the largest eigenvalue of
``Σ p_k p_kᵀ`` (it maximises the Rayleigh quotient ``Σ (q · p_k)²``); for a fixed ``q_W`` the best
``q_B`` is likewise the mean of ``(q_W ⊗ q_ref,k)* ⊗ q_est,k``. Alternating the two exact
half-steps never increases the cost and converges, but only linearly, and slowly when the
reference turns mostly about one axis (``q_B`` about that axis and ``q_W`` about its image
then nearly trade for each other: on the OpenAXES robot recordings 1600 to more than 2000
sweeps for 1e-12 rad). So the means are alternated until a sweep moves neither rotation by
more than :data:`ALTERNATE_TOL` (or :data:`ALTERNATE_SWEEPS` sweeps), and the same cost is
then minimised by Newton's method over both rotations together (the chordal cost is
``Σ_k ‖ρ_k‖²/4`` with ``ρ_k = 2 vec δq_k``, δq below, ``w >= 0``; its gradient analytic,
its Hessian by differences of the gradient — Gauss–Newton alone, which leaves out the
residuals' curvature, still converged only linearly on those recordings, more than 100
steps) until a step moves them by at most ``tol`` rad — a tolerance, not a fixed count;
:class:`AlignmentWarning` when ``max_iter`` steps do not get there. Each step is halved
until the cost does not rise. The
start is the better (lower final cost) of two: ``q_B`` from the hand–eye equations of the
relative rotations over a quarter of the evaluated samples (``q_B ⊗ A = B ⊗ q_B``, A of the
estimate and B of the reference, solved as the least-squares null vector), and ``q_B`` the
identity.

When the reference turns about one axis only, part of ``q_B`` can be traded for part of
``q_W`` at no cost (a one-parameter family of fits; Newton's step leaves that direction
alone): the errors are then still the minimum, the rotations one of the minimisers.

The errors of the aligned estimate, ``δq_k = q_est,k ⊗ (q_W ⊗ q_ref,k ⊗ q_B)*`` in the
estimate's world frame (vertical z), are BROAD's angles
(:mod:`strapdown.analysis.broad`): total ``2 atan2(‖δq_xyz‖, |δq_w|)``, heading (the twist
about the vertical) and inclination (the tilt between the two vertical axes), each an RMSE
in degrees.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.analysis.broad import _angles
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_conjugate, quat_from_rotvec, quat_multiply

__all__ = ["ALTERNATE_SWEEPS", "ALTERNATE_TOL", "MAX_ITER", "TOL", "Alignment",
           "AlignmentWarning", "aligned_errors", "fit_alignment"]

#: Default convergence tolerance (rad): the fit stops after a step that moves the rotations
#: by at most this.
TOL = 1e-10
#: Default bound on the number of Newton steps.
MAX_ITER = 100
#: The alternating means hand over to Newton's method after a sweep that moves neither rotation
#: by more than this (rad) …
ALTERNATE_TOL = 1e-6
#: … or after this many sweeps.
ALTERNATE_SWEEPS = 50
_FD_STEP = 1e-5


class AlignmentWarning(UserWarning):
    """The fit stopped at ``max_iter`` Newton steps before reaching its tolerance."""


@dataclass(frozen=True)
class Alignment:
    """The fitted constant rotations of ``q_est ≈ q_world ⊗ q_ref ⊗ q_body``.

    Attributes
    ----------
    q_world, q_body : ndarray (4,)
        Unit quaternions, scalar first, ``w >= 0``.
    cost : float
        Mean of ``1 − c_k²`` over the fitted samples (an eighth of the mean squared
        chordal distance).
    sweeps : int
        Alternating sweeps run before Newton's method.
    iterations : int
        Newton steps run.
    converged : bool
        Whether the last step moved the rotations by at most the tolerance.
    """

    q_world: NDArray[np.float64]
    q_body: NDArray[np.float64]
    cost: float
    sweeps: int
    iterations: int
    converged: bool


def _unit(q: NDArray[np.float64]) -> NDArray[np.float64]:
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _mean(p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Chordal L2 mean of the rows of ``p``: the top eigenvector of Σ p pᵀ, ``w >= 0``."""
    _, v = np.linalg.eigh(p.T @ p)
    q = v[:, -1]
    return q if q[0] >= 0 else -q


def _angle(p: NDArray[np.float64], q: NDArray[np.float64]) -> float:
    """Rotation angle between two unit quaternions (rad), sign-insensitive."""
    d = abs(float(p @ q))
    return 2.0 * math.atan2(math.sqrt(max(0.0, 1.0 - d * d)), d)


def _cost(qe, qr, q_w, q_b) -> float:
    c = np.einsum("ij,ij->i", qe, quat_multiply(quat_multiply(q_w, qr), q_b))
    return float(np.mean(1.0 - c * c))


def _hand_eye(qe: NDArray[np.float64], qr: NDArray[np.float64]) -> NDArray[np.float64]:
    """``q_B`` from the relative rotations ``A = q_est,k* ⊗ q_est,k+s`` and
    ``B = q_ref,k* ⊗ q_ref,k+s`` (``A = q_B* ⊗ B ⊗ q_B``), s a quarter of the samples."""
    s = max(1, qe.shape[0] // 4)
    a = quat_multiply(quat_conjugate(qe[:-s]), qe[s:])
    b = quat_multiply(quat_conjugate(qr[:-s]), qr[s:])
    a *= np.where(a[:, 0] * b[:, 0] < 0, -1.0, 1.0)[:, None]  # conjugation keeps w
    bw, bv = b[:, 0], b[:, 1:]
    aw, av = a[:, 0], a[:, 1:]
    # (L(B) − R(A)) q_B = 0, with L(p) q = p ⊗ q and R(p) q = q ⊗ p
    m = np.zeros((a.shape[0], 4, 4))
    m[:, 0, 0] = bw - aw
    m[:, 0, 1:] = -(bv - av)
    m[:, 1:, 0] = bv - av
    m[:, 1:, 1:] = (bw - aw)[:, None, None] * np.eye(3) + _cross(bv + av)
    _, v = np.linalg.eigh(np.einsum("kij,kil->jl", m, m))
    q = v[:, 0]
    return q if q[0] >= 0 else -q


def _cross(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Skew matrices ``[v×]`` of the rows of ``v``."""
    z = np.zeros(v.shape[0])
    x, y, w = v.T
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1),
                     np.stack([-y, x, z], -1)], -2)


def _alternate(qe, qr, q_b, tol: float, max_sweeps: int):
    """Alternating chordal means from ``q_b`` until neither rotation moves by > ``tol``
    rad in a sweep, or ``max_sweeps``: ``(q_W, q_B, sweeps)``."""
    qr_c = quat_conjugate(qr)
    q_w = _mean(quat_multiply(qe, quat_conjugate(quat_multiply(qr, q_b))))
    sweeps = 0
    while sweeps < max_sweeps:
        sweeps += 1
        q_b_new = _mean(quat_multiply(quat_multiply(qr_c, quat_conjugate(q_w)), qe))
        q_w_new = _mean(quat_multiply(qe, quat_conjugate(quat_multiply(qr, q_b_new))))
        moved = max(_angle(q_b, q_b_new), _angle(q_w, q_w_new))
        q_b, q_w = q_b_new, q_w_new
        if moved <= tol:
            break
    return q_w, q_b, sweeps


def _residuals(qe, qr, q_w, q_b):
    """``(fit, w, v)``: the fitted attitudes and, of ``δq = q_est ⊗ fit*`` turned to
    ``w >= 0``, the scalar and vector parts; the cost is ``Σ |v|²``."""
    fit = quat_multiply(quat_multiply(q_w, qr), q_b)
    dq = quat_multiply(qe, quat_conjugate(fit))
    s = np.where(dq[:, 0] < 0, -1.0, 1.0)
    return fit, s * dq[:, 0], s[:, None] * dq[:, 1:]


def _moved(q_w, q_b, x):
    """``q_W ← exp(a) ⊗ q_W``, ``q_B ← q_B ⊗ exp(b)`` for ``x = (a, b)``."""
    return (quat_multiply(quat_from_rotvec(x[:3]), q_w),
            quat_multiply(q_b, quat_from_rotvec(x[3:])))


def _gradient(qe, qr, q_w, q_b):
    """``(Σ ‖ρ‖², its gradient over x = (a, b))`` at ``x = 0``, ``ρ = 2 vec δq``: with
    ``∂ρ/∂x = −(w I + [v×]) [I, C(fit)]`` (δq turns by ``exp(−(a + C b))``), the gradient
    ``2 Σ (∂ρ/∂x)ᵀ ρ = −4 Σ w [v, C(fit)ᵀ v]`` (``[v×]ᵀ v = 0``)."""
    fit, w, v = _residuals(qe, qr, q_w, q_b)
    wv = w[:, None] * v
    g_b = np.einsum("kji,kj->i", dcm_from_quat(fit), wv)
    return 4.0 * float(np.sum(v * v)), -4.0 * np.concatenate([wv.sum(axis=0), g_b])


def _newton(qe, qr, q_w, q_b, tol: float, max_iter: int):
    """Newton on ``Σ ‖ρ‖²`` over ``x = (a, b)`` (module docstring): the gradient analytic,
    the Hessian by central differences of it (``_FD_STEP`` rad), its eigenvalues taken
    by magnitude (a saddle is left along its negative curvature); the step from the
    pseudo-inverse (flat directions dropped), halved until the cost does not rise; until a
    step is at most ``tol`` rad.
    Returns ``(q_W, q_B, steps, converged)``."""
    cost, g = _gradient(qe, qr, q_w, q_b)
    for it in range(1, max_iter + 1):
        cols = []
        for e in np.eye(6) * _FD_STEP:
            cols.append(_gradient(qe, qr, *_moved(q_w, q_b, e))[1]
                        - _gradient(qe, qr, *_moved(q_w, q_b, -e))[1])
        hess = np.array(cols) / (2 * _FD_STEP)
        ev, vec = np.linalg.eigh((hess + hess.T) / 2)
        ev = np.abs(ev)  # away from a saddle along negative curvature
        keep = ev > 1e-12 * ev.max()
        step = -(vec[:, keep] @ ((vec.T @ g)[keep] / ev[keep]))
        while True:
            q_w_new, q_b_new = _moved(q_w, q_b, step)
            new = _gradient(qe, qr, q_w_new, q_b_new)
            if new[0] <= cost or float(np.linalg.norm(step)) <= tol:
                break
            step = step / 2
        if new[0] <= cost:  # else a step within tol that rounding made uphill: not taken
            q_w, q_b, (cost, g) = q_w_new, q_b_new, new
        if float(np.linalg.norm(step)) <= tol:
            return q_w, q_b, it, True
    return q_w, q_b, max_iter, False


def _fit(qe, qr, q_b, tol: float, max_iter: int) -> Alignment:
    """From a start ``q_b``: alternating means, then Newton."""
    q_w, q_b, sweeps = _alternate(qe, qr, q_b, ALTERNATE_TOL, ALTERNATE_SWEEPS)
    q_w, q_b, it, ok = _newton(qe, qr, q_w, q_b, tol, max_iter)
    q_w, q_b = (q if q[0] >= 0 else -q for q in (_unit(q_w), _unit(q_b)))
    return Alignment(q_w, q_b, _cost(qe, qr, q_w, q_b), sweeps, it, ok)


def _inputs(q_est, q_ref, mask) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                         NDArray[np.bool_]]:
    q_est = np.asarray(q_est, float)
    q_ref = np.asarray(q_ref, float)
    n = q_ref.shape[0] if q_ref.ndim == 2 else -1
    mask = np.ones(max(n, 0), bool) if mask is None else np.asarray(mask, bool)
    if q_ref.shape != (n, 4) or q_est.shape != (n, 4) or mask.shape != (n,):
        raise ValueError(f"q_est and q_ref must be (n, 4) and mask (n,), one row per sample; "
                         f"got {q_est.shape}, {q_ref.shape}, {mask.shape}")
    valid = mask & np.all(np.isfinite(q_ref), axis=1)
    if valid.sum() < 2:
        raise ValueError(f"{int(valid.sum())} masked samples with a valid (finite) reference; "
                         "the fit needs at least 2")
    bad = valid & ~np.all(np.isfinite(q_est), axis=1)
    if np.any(bad):
        raise ValueError(f"q_est is not finite at sample {int(np.argmax(bad))}")
    return _unit(q_est[valid]), _unit(q_ref[valid]), valid


def fit_alignment(q_est: ArrayLike, q_ref: ArrayLike, mask: ArrayLike | None = None, *,
                  tol: float = TOL, max_iter: int = MAX_ITER) -> Alignment:
    """Fit constant ``q_W``, ``q_B`` with ``q_est ≈ q_W ⊗ q_ref ⊗ q_B`` (module docstring).

    Parameters
    ----------
    q_est, q_ref : array_like (n, 4)
        Estimate and reference, scalar first, one row per sample (any signs, any
        non-zero norms; rows whose reference is NaN are skipped).
    mask : array_like (n,) of bool, optional
        The samples fitted (default all).
    tol : float
        Stop after a Newton step that moves the rotations by at most ``tol`` rad.
    max_iter : int
        Most Newton steps from each start; reaching it warns
        (:class:`AlignmentWarning`).

    Returns
    -------
    Alignment

    Raises
    ------
    ValueError
        On mismatched shapes, fewer than two valid samples, or a non-finite estimate.
    """
    qe, qr, _ = _inputs(q_est, q_ref, mask)
    fits = [_fit(qe, qr, q_b, tol, max_iter)
            for q_b in (_hand_eye(qe, qr), np.array([1.0, 0.0, 0.0, 0.0]))]
    best = min(fits, key=lambda a: a.cost)
    if not best.converged:
        warnings.warn(f"the alignment fit stopped after {max_iter} Newton steps before "
                      f"a step of at most {tol:g} rad", AlignmentWarning, stacklevel=2)
    return best


def _rmse_deg(x: NDArray[np.float64]) -> float:
    return float(np.degrees(np.sqrt(np.mean(x**2))))


def aligned_errors(q_est: ArrayLike, q_ref: ArrayLike, mask: ArrayLike | None = None, *,
                   tol: float = TOL, max_iter: int = MAX_ITER) -> dict[str, float]:
    """Total, heading and inclination RMSE (degrees) after :func:`fit_alignment`.

    The rotations are fitted to the masked samples and the errors taken over the same
    samples: ``δq_k = q_est,k ⊗ (q_W ⊗ q_ref,k ⊗ q_B)*``, BROAD's angles of δq.

    Parameters
    ----------
    q_est, q_ref, mask, tol, max_iter
        As for :func:`fit_alignment`.

    Returns
    -------
    dict
        ``total_deg``, ``heading_deg``, ``inclination_deg``, ``samples`` (evaluated), and
        of the fit (:class:`Alignment`) ``sweeps``, ``iterations`` and ``cost``.
    """
    qe, qr, valid = _inputs(q_est, q_ref, mask)
    fit = fit_alignment(q_est, q_ref, valid, tol=tol, max_iter=max_iter)
    dq = _unit(quat_multiply(qe, quat_conjugate(quat_multiply(
        quat_multiply(fit.q_world, qr), fit.q_body))))
    total, heading, incl = _angles(dq)
    return {"total_deg": _rmse_deg(total), "heading_deg": _rmse_deg(heading),
            "inclination_deg": _rmse_deg(incl), "samples": int(valid.sum()),
            "sweeps": fit.sweeps, "iterations": fit.iterations, "cost": fit.cost}
