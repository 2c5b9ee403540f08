"""Direction cosine matrices ``C_n_b`` (``v_n = C_n_b @ v_b``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.scaling import safe_unit
from strapdown._core.validation import as_dcms, as_quaternions

__all__ = ["dcm_from_quat", "quat_from_dcm"]


def dcm_from_quat(q: ArrayLike) -> NDArray[np.float64]:
    """``C_n_b`` from ``q_n_b`` (normalised first), shape ``(..., 3, 3)``."""
    u = safe_unit(as_quaternions(q, "q"))
    w, x, y, z = np.moveaxis(u, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def quat_from_dcm(dcm: ArrayLike) -> NDArray[np.float64]:
    """``q_n_b`` from ``C_n_b`` by Shepperd's method (largest-pivot branch).

    Returns the representative with ``w >= 0``. The input is assumed
    orthonormal; it is not re-orthogonalised.
    """
    c = as_dcms(dcm, "dcm")
    tr = np.trace(c, axis1=-2, axis2=-1)
    diag = np.diagonal(c, axis1=-2, axis2=-1)
    # Candidates 4w², 4x², 4y², 4z²; pick the largest for each matrix.
    cand = np.stack([1 + tr, 1 + 2 * diag[..., 0] - tr, 1 + 2 * diag[..., 1] - tr,
                     1 + 2 * diag[..., 2] - tr], axis=-1)
    k = np.argmax(cand, axis=-1)
    r = np.sqrt(np.maximum(np.take_along_axis(cand, k[..., None], -1)[..., 0], 0.0))
    c21_12 = c[..., 2, 1] - c[..., 1, 2]
    c02_20 = c[..., 0, 2] - c[..., 2, 0]
    c10_01 = c[..., 1, 0] - c[..., 0, 1]
    c10p01 = c[..., 1, 0] + c[..., 0, 1]
    c02p20 = c[..., 0, 2] + c[..., 2, 0]
    c21p12 = c[..., 2, 1] + c[..., 1, 2]
    rows = [
        np.stack([r * r, c21_12, c02_20, c10_01], -1),
        np.stack([c21_12, r * r, c10p01, c02p20], -1),
        np.stack([c02_20, c10p01, r * r, c21p12], -1),
        np.stack([c10_01, c02p20, c21p12, r * r], -1),
    ]
    q = np.choose(k[..., None], rows) / (2.0 * r)[..., None]
    q = q * np.where(q[..., :1] < 0.0, -1.0, 1.0)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


