"""Conversion to and from :class:`scipy.spatial.transform.Rotation` (``scalar_first=True``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from strapdown._core.scaling import pow2_exponent
from strapdown._core.validation import as_quaternions

__all__ = ["quat_from_scipy", "scipy_from_quat"]


def scipy_from_quat(q: ArrayLike) -> Rotation:
    """A scipy ``Rotation`` holding ``q_n_b`` (shape ``(4,)`` or ``(n, 4)``)."""
    q = as_quaternions(q, "q")
    if q.ndim > 2:
        raise ValueError(f"q must have shape (4,) or (n, 4) for scipy, got shape {q.shape}")
    # a power-of-two scale first (unit quaternions unchanged): scipy's norm cannot overflow
    return Rotation.from_quat(np.ldexp(q, -pow2_exponent(q)), scalar_first=True)


def quat_from_scipy(rotation: Rotation) -> NDArray[np.float64]:
    """Scalar-first quaternion(s) of a scipy ``Rotation``."""
    if not isinstance(rotation, Rotation):
        raise ValueError(f"rotation must be a scipy Rotation, got {type(rotation).__name__}")
    return np.asarray(rotation.as_quat(scalar_first=True), dtype=np.float64)
