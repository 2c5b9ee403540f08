"""Quaternions: Hamilton product, scalar first ``[w, x, y, z]``.

All functions broadcast over leading dimensions ``(..., 4)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.scaling import pow2_exponent, safe_norm, safe_unit
from strapdown._core.series import SMALL_ANGLE, sinc
from strapdown._core.validation import as_quaternions, as_vectors

__all__ = [
    "quat_canonical",
    "quat_conjugate",
    "quat_from_rotvec",
    "quat_identity",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "rotvec_from_quat",
]


def quat_identity(shape: tuple[int, ...] = ()) -> NDArray[np.float64]:
    """Identity quaternions of the given batch shape, ``shape + (4,)``."""
    q = np.zeros((*shape, 4))
    q[..., 0] = 1.0
    return q


def quat_multiply(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product ``p ⊗ q`` (broadcast over leading dimensions)."""
    p = as_quaternions(p, "p")
    q = as_quaternions(q, "q")
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def quat_conjugate(q: ArrayLike) -> NDArray[np.float64]:
    """Conjugate ``q*`` (the inverse of a unit quaternion)."""
    q = as_quaternions(q, "q")
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize(q: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternion with the same attitude, for any non-zero finite ``q`` (scaled by a
    power of two first: :func:`strapdown._core.scaling.safe_unit`)."""
    return safe_unit(as_quaternions(q, "q"))


def quat_canonical(q: ArrayLike) -> NDArray[np.float64]:
    """Representative with ``w >= 0`` (ties broken on the first non-zero component).

    ``q`` and ``-q`` are the same attitude; this picks one so that arrays can be
    compared element-wise.
    """
    q = as_quaternions(q, "q")
    sign = np.ones(q.shape[:-1])
    undecided = np.ones(q.shape[:-1], dtype=bool)
    for i in range(4):
        c = q[..., i]
        decide = undecided & (c != 0.0)
        sign = np.where(decide & (c < 0.0), -1.0, sign)
        undecided &= ~decide
    return q * sign[..., None]


def quat_rotate(q: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """Rotate body vectors into the reference frame: ``v_n = q ⊗ [0, v_b] ⊗ q*``.

    ``q`` need not be unit; it is normalised first.
    """
    q = quat_normalize(q)
    v = as_vectors(v, "v")
    e = pow2_exponent(v)  # rotation is linear: scale v by a power of two, then back
    v = np.ldexp(v, -e)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return np.ldexp(v + w * t + np.cross(u, t), e)


def quat_from_rotvec(rotvec: ArrayLike) -> NDArray[np.float64]:
    """Exponential map ``q(φ) = [cos(|φ|/2), sin(|φ|/2) φ/|φ|]``.

    Exact for every angle; ``sin(|φ|/2)/|φ|`` uses its series below
    :data:`~strapdown.rotation.SMALL_ANGLE` (Li & Zhang 2017 eq. 9 in
    quaternion form; conventions.md "Rotation vector").
    """
    phi = as_vectors(rotvec, "rotvec")
    angle = safe_norm(phi)  # 1e308 rad has a norm; 1e-160 rad too
    half = 0.5 * angle
    w = np.cos(half)
    s = 0.5 * sinc(half)  # sin(|φ|/2) / |φ|
    # beyond 1e150 rad, sin(|φ|/2) times the axis (s·φ would lose digits to underflow)
    huge = (angle > 1e150)[..., None]
    v = np.where(huge, np.sin(half)[..., None] * safe_unit(np.where(huge, phi, 1.0)),
                 s[..., None] * phi)
    return np.concatenate([w[..., None], v], axis=-1)


def rotvec_from_quat(q: ArrayLike) -> NDArray[np.float64]:
    """Logarithm map: the rotation vector with ``|φ| ∈ [0, π]``.

    Uses ``|φ| = 2 atan2(|v|, |w|)`` with the sign of ``w`` folded into the
    vector part, which is accurate near 0 and near π and insensitive to the
    norm of ``q`` (scaled by a power of two first, so 1e300 and 1e-300 work too).
    """
    q = as_quaternions(q, "q")
    q = np.ldexp(q, -pow2_exponent(q))
    w = q[..., 0]
    v = q[..., 1:]
    sign = np.where(w < 0.0, -1.0, 1.0)
    w = w * sign
    v = v * sign[..., None]
    s = np.linalg.norm(v, axis=-1)
    angle = 2.0 * np.arctan2(s, w)
    # scale = angle / s = 2 atan(r)/(r w), r = s/w; for small r the series
    # 2/w (1 − r²/3 + r⁴/5 − r⁶/7 + r⁸/9), first omitted term r¹⁰/11 < 1e-21.
    small = s < SMALL_ANGLE * w
    ws = np.where(small, w, 1.0)  # the series only where it is used (w > 0 there): no
    r2 = (s / ws) ** 2  # overflow from a tiny w on the other branch
    series = 2.0 / ws * (1.0 - r2 * (1.0 / 3.0 - r2 * (1.0 / 5.0 - r2 * (1.0 / 7.0
                                                                      - r2 / 9.0))))
    ss = np.where(s == 0.0, 1.0, s)
    scale = np.where(small, series, angle / ss)
    return scale[..., None] * v


