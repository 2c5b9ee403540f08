"""Rotation vectors: skew matrices and the DCM form of Li & Zhang 2017 eq. 9."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.scaling import safe_norm, safe_unit
from strapdown._core.series import sinc
from strapdown._core.validation import as_vectors

__all__ = ["dcm_from_rotvec", "f1_f2", "skew"]


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Cross-product matrix ``(v×)`` so that ``skew(v) @ u == cross(v, u)``; ``(..., 3, 3)``."""
    v = as_vectors(v, "v")
    x, y, z = np.moveaxis(v, -1, 0)
    zero = np.zeros_like(x)
    return np.stack(
        [
            np.stack([zero, -z, y], axis=-1),
            np.stack([z, zero, -x], axis=-1),
            np.stack([-y, x, zero], axis=-1),
        ],
        axis=-2,
    )


def f1_f2(angle: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``f1 = sin|φ|/|φ|`` and ``f2 = (1 − cos|φ|)/|φ|²`` (Li & Zhang 2017 eq. 9).

    ``f2`` is evaluated as ``½ (sin(|φ|/2)/(|φ|/2))²``, which is the same
    function without the cancellation of ``1 − cos`` at small angles.
    """
    angle = np.asarray(angle, dtype=np.float64)
    f1 = sinc(angle)
    f2 = 0.5 * sinc(0.5 * angle) ** 2
    return f1, f2


def dcm_from_rotvec(rotvec: ArrayLike) -> NDArray[np.float64]:
    """``C = I + f1 (φ×) + f2 (φ×)²`` (Li & Zhang 2017 eq. 9), shape ``(..., 3, 3)``.

    For an interval's body rotation vector this is ``C_b(k-1)_b(k)``.
    """
    phi = as_vectors(rotvec, "rotvec")
    angle = safe_norm(phi)
    if np.any(angle > 1e150):  # (φ×)² overflows: the same matrix from the unit axis
        return _dcm_from_axis_angle(phi, angle)
    f1, f2 = f1_f2(angle)
    k = skew(phi)
    eye = np.broadcast_to(np.eye(3), k.shape)
    return eye + f1[..., None, None] * k + f2[..., None, None] * (k @ k)


def _dcm_from_axis_angle(phi: NDArray[np.float64], angle: NDArray[np.float64]
                         ) -> NDArray[np.float64]:
    """``I + sin a (n×) + (1 − cos a)(n×)²`` with ``n = φ/|φ|`` (a = 0: the identity)."""
    zero = (angle == 0.0)[..., None]
    k = skew(np.where(zero, 0.0, safe_unit(np.where(zero, 1.0, phi))))
    eye = np.broadcast_to(np.eye(3), k.shape)
    return (eye + np.sin(angle)[..., None, None] * k
            + (1.0 - np.cos(angle))[..., None, None] * (k @ k))
