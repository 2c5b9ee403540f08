"""Attitude error of an estimate against truth (conventions.md "Errors and metrics")."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.scaling import pow2_exponent
from strapdown._core.validation import as_quaternions
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply, rotvec_from_quat

__all__ = ["attitude_error_angle", "attitude_error_quat", "attitude_error_vector"]


def attitude_error_quat(q_est: ArrayLike, q_true: ArrayLike) -> NDArray[np.float64]:
    """``δq = q_est ⊗ q_true*`` (reference-frame error quaternion)."""
    return quat_multiply(q_est, quat_conjugate(q_true))


def _scaled(q: ArrayLike, name: str) -> NDArray[np.float64]:
    """``q`` scaled by a power of two to a largest component in [0.5, 1) (unit quaternions
    are unchanged), so that the product of two cannot overflow or underflow."""
    q = as_quaternions(q, name)
    return np.ldexp(q, -pow2_exponent(q))


def attitude_error_vector(q_est: ArrayLike, q_true: ArrayLike) -> NDArray[np.float64]:
    """Reference-frame error rotation vector ``δφ_n = log(q_est ⊗ q_true*)``, rad.

    Invariant under ``q → −q`` of either argument, and under their scale.
    """
    return rotvec_from_quat(attitude_error_quat(_scaled(q_est, "q_est"),
                                                _scaled(q_true, "q_true")))


def attitude_error_angle(q_est: ArrayLike, q_true: ArrayLike) -> NDArray[np.float64]:
    """Error angle ``2 atan2(|vec δq|, |w δq|)`` in ``[0, π]``, rad."""
    dq = attitude_error_quat(_scaled(q_est, "q_est"), _scaled(q_true, "q_true"))
    return 2.0 * np.arctan2(np.linalg.norm(dq[..., 1:], axis=-1), np.abs(dq[..., 0]))
