"""Yaw–pitch–roll (z-y-x) Euler angles: ``C_n_b = Rz(yaw) Ry(pitch) Rx(roll)``."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_dcms, finite_array

__all__ = ["dcm_from_euler_zyx", "euler_zyx_from_dcm"]


def _rx(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1),
                     np.stack([z, s, c], -1)], -2)


def _ry(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1),
                     np.stack([-s, z, c], -1)], -2)


def _rz(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1),
                     np.stack([z, z, o], -1)], -2)


def dcm_from_euler_zyx(yaw: ArrayLike, pitch: ArrayLike, roll: ArrayLike) -> NDArray[np.float64]:
    """``C_n_b = Rz(yaw) Ry(pitch) Rx(roll)`` (active rotations), rad."""
    yaw, pitch, roll = np.broadcast_arrays(finite_array(yaw, "yaw"), finite_array(pitch, "pitch"),
                                           finite_array(roll, "roll"))
    return _rz(yaw) @ _ry(pitch) @ _rx(roll)


def euler_zyx_from_dcm(dcm: ArrayLike
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(yaw, pitch, roll) with pitch ∈ [−π/2, π/2]; at gimbal lock roll is set to 0."""
    c = as_dcms(dcm, "dcm")
    pitch = np.arctan2(-c[..., 2, 0], np.hypot(c[..., 0, 0], c[..., 1, 0]))
    lock = np.hypot(c[..., 0, 0], c[..., 1, 0]) < 1e-12
    yaw = np.where(lock, np.arctan2(-c[..., 0, 1], c[..., 1, 1]),
                   np.arctan2(c[..., 1, 0], c[..., 0, 0]))
    roll = np.where(lock, 0.0, np.arctan2(c[..., 2, 1], c[..., 2, 2]))
    return yaw, pitch, roll
