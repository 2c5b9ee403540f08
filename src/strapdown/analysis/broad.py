"""BROAD's error metrics (Laidig, Caruso, Cereatti & Seel, Data 6(7), 2021).

The metric as published (the dataset's example code, ``broad_utils.calculateRMSE``):
the error quaternion ``δq = q_imu ⊗ q_opt*`` in the reference frame, both
normalised, with **no** heading offset removed — the optical reference is
already expressed in the IMU's magnetic ENU frame (every trial's ``info`` says
so); total error ``2 acos|δq_w|``, heading error ``2 atan|δq_z / δq_w|`` (the
rotation about the vertical; taken as ``2 atan2(|δq_z|, |δq_w|)``, the same
value, defined also where both vanish), inclination error ``2 acos √(δq_w² + δq_z²)``
(the rest); each an RMSE in degrees over the movement phases, one estimate per
sample, samples whose reference is NaN (markers lost) skipped. The arc cosines are
evaluated as the equal arc tangents ``2 atan2(‖δq_xyz‖, |δq_w|)`` and
``2 atan2(√(δq_x² + δq_y²), √(δq_w² + δq_z²))``: near zero error ``acos`` turns a
rounding error of 1e-16 in its argument into 1.5e-8 rad (a pure heading error then
showed an inclination of 1e-6° or none, depending on the quaternions' signs); the
arc tangents are exact to rounding there and equal elsewhere.

Removing the constant heading offset between the two frames (the circular mean
of the heading error) is *not* BROAD's metric; :func:`broad_errors` computes it
only when asked (``remove_heading_offset=True``) and then reports it in extra,
separately named keys.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.rotation.quaternion import quat_conjugate, quat_multiply

__all__ = ["broad_errors"]


def _angles(dq: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """BROAD's total, heading and inclination angles (rad) of error quaternions δq."""
    w, x, y, z = np.abs(dq).T
    total = 2.0 * np.arctan2(np.sqrt(x**2 + y**2 + z**2), w)  # = 2 acos|w|
    # = 2 atan|z/w| wherever that is defined; 0 where w = z = 0 (no twist to take)
    heading = 2.0 * np.arctan2(z, w)
    incl = 2.0 * np.arctan2(np.hypot(x, y), np.hypot(w, z))  # = 2 acos √(w² + z²)
    return total, heading, incl


def _rmse_deg(x: NDArray[np.float64]) -> float:
    return float(np.degrees(np.sqrt(np.mean(x**2))))


def broad_errors(q_est: ArrayLike, q_ref: ArrayLike, movement: ArrayLike, *,
                 remove_heading_offset: bool = False) -> dict[str, float]:
    """BROAD's total, heading and inclination RMSE (degrees) over movement phases.

    The metric of Laidig, Caruso, Cereatti & Seel (2021) as published (see the
    module docstring): nothing is aligned before the errors are taken.

    Parameters
    ----------
    q_est, q_ref : (n, 4)
        Estimated and reference q_ENU_b at the same samples, one per sample (NaN
        rows in ``q_ref`` are skipped).
    movement : (n,) bool
    remove_heading_offset : bool
        Also report the errors after removing the constant heading offset (the
        circular mean of the heading error over the evaluated samples), in the
        extra keys ``heading_offset_deg``, ``total_offset_removed_deg``,
        ``heading_offset_removed_deg`` and ``inclination_offset_removed_deg``.
        Not BROAD's metric; off by default.

    Returns
    -------
    dict
        ``total_deg``, ``heading_deg``, ``inclination_deg`` (BROAD's metric),
        ``samples`` (evaluated samples), and the extra keys above when asked.

    Raises
    ------
    ValueError
        When the shapes differ or no movement sample has a valid reference.
    """
    q_est = np.asarray(q_est, float)
    q_ref = np.asarray(q_ref, float)
    movement = np.asarray(movement, bool)
    n = q_ref.shape[0] if q_ref.ndim == 2 else -1
    if q_ref.shape != (n, 4) or q_est.shape != (n, 4) or movement.shape != (n,):
        raise ValueError(f"q_est and q_ref must be (n, 4) and movement (n,), one row per "
                         f"sample; got {q_est.shape}, {q_ref.shape}, {movement.shape}")
    valid = movement & np.all(np.isfinite(q_ref), axis=1)
    if not np.any(valid):
        raise ValueError("no movement samples with a valid reference")
    qe = q_est[valid] / np.linalg.norm(q_est[valid], axis=1)[:, None]
    qr = q_ref[valid] / np.linalg.norm(q_ref[valid], axis=1)[:, None]
    dq = quat_multiply(qe, quat_conjugate(qr))
    dq /= np.linalg.norm(dq, axis=1)[:, None]
    total, heading, incl = _angles(dq)
    out = {"total_deg": _rmse_deg(total), "heading_deg": _rmse_deg(heading),
           "inclination_deg": _rmse_deg(incl), "samples": int(valid.sum())}
    if remove_heading_offset:
        psi = 2.0 * np.arctan2(dq[:, 3], dq[:, 0])
        offset = math.atan2(np.mean(np.sin(psi)), np.mean(np.cos(psi)))
        rot = np.array([math.cos(offset / 2), 0.0, 0.0, -math.sin(offset / 2)])
        total, heading, incl = _angles(quat_multiply(rot, dq))
        out |= {"heading_offset_deg": math.degrees(offset),
                "total_offset_removed_deg": _rmse_deg(total),
                "heading_offset_removed_deg": _rmse_deg(heading),
                "inclination_offset_removed_deg": _rmse_deg(incl)}
    return out
