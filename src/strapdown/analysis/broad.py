"""BROAD's error metrics (Laidig, Caruso, Cereatti & Seel, Data 6(7), 2021).

Metrics (BROAD's): the error quaternion ``δq = q_imu ⊗ q_opt*`` in the
reference frame, after removing the constant heading offset between the
IMU's magnetic frame and the optical frame (the circular mean of the heading
error over the evaluated samples); total error = the angle of δq, heading
error = its twist about the vertical, inclination error = the angle of the
remaining swing; each as an RMSE in degrees over movement phases where the
reference is valid.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.rotation.quaternion import quat_conjugate, quat_multiply

__all__ = ["broad_errors"]


def _twist_z(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation angle of the twist of q about the vertical (rad, in (−π, π])."""
    return 2.0 * np.arctan2(q[..., 3], q[..., 0])


def broad_errors(q_est: ArrayLike, q_ref: ArrayLike, movement: ArrayLike, *,
                 heading_offset: bool = True) -> dict[str, float]:
    """BROAD's total, heading and inclination RMSE (degrees) over movement phases.

    Parameters
    ----------
    q_est, q_ref : (n, 4)
        Estimated and reference q_ENU_b at the same samples (NaN rows in
        ``q_ref`` are skipped).
    movement : (n,) bool
    heading_offset : bool
        Remove the constant heading offset (on by default: magnetic north and
        the optical frame's y axis differ).
    """
    q_est = np.asarray(q_est, float)
    q_ref = np.asarray(q_ref, float)
    valid = np.asarray(movement, bool) & np.all(np.isfinite(q_ref), axis=1)
    if not np.any(valid):
        raise ValueError("no movement samples with a valid reference")
    dq = quat_multiply(q_est[valid], quat_conjugate(q_ref[valid]))
    offset = 0.0
    if heading_offset:
        psi = _twist_z(dq)
        offset = math.atan2(np.mean(np.sin(psi)), np.mean(np.cos(psi)))
        rot = np.array([math.cos(offset / 2), 0.0, 0.0, -math.sin(offset / 2)])
        dq = quat_multiply(rot, dq)
    w = np.clip(np.abs(dq[:, 0]), 0.0, 1.0)
    total = 2.0 * np.arctan2(np.linalg.norm(dq[:, 1:], axis=1), w)
    twist = _twist_z(dq)
    heading = np.abs((twist + np.pi) % (2 * np.pi) - np.pi)
    # swing = δq ⊗ twist*: its angle is the inclination error
    half = 0.5 * twist
    twist_conj = np.column_stack([np.cos(half), np.zeros_like(half), np.zeros_like(half),
                                  -np.sin(half)])
    swing = quat_multiply(dq, twist_conj)
    incl = 2.0 * np.arctan2(np.linalg.norm(swing[:, 1:], axis=1), np.abs(swing[:, 0]))

    def rmse(x):
        return float(np.degrees(np.sqrt(np.mean(x**2))))

    return {"total_deg": rmse(total), "heading_deg": rmse(heading),
            "inclination_deg": rmse(incl), "heading_offset_deg": math.degrees(offset),
            "samples": int(valid.sum())}
