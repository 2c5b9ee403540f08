"""Cone angles of the double-rotation representation (Zhang & Yu (2021)).

``C_c_b = Rx(δ1) Rz(δ2) Rx(δ3 − δ1)`` (active rotations; c = the cone frame, our
``n``): δ1 precession, δ2 nutation (the half-cone angle), δ3 roll measured
from the precession. Equivalently ``C_c_b = exp([ν×]) Rx(δ3)`` with the
nutation rotation vector ``ν = δ2 (0, −sin δ1, cos δ1)``. Ranges: δ1, δ3 in
[0, 2π), δ2 in [0, π].

Inverse (robust): ``δ2 = atan2(√(C21² + C31²), C11)``, ``δ1 = atan2(C31, C21)``;
for δ2 ≤ π/2, ``δ3 = atan2(C32 − C23, C22 + C33)`` (these equal
``(1 + cos δ2)(sin δ3, cos δ3)``, so δ3 stays defined at δ2 = 0, where only δ1
is lost and is returned as 0); for δ2 > π/2, ``2δ1 − δ3 = atan2(−(C32 + C23),
C33 − C22)`` (these equal ``(1 − cos δ2)(−sin, cos)(2δ1 − δ3)``).

The paper's own conversions are kept, with their measured failures, in
:mod:`strapdown.algorithms.errata` (``paper_*``): eq. 19 (``arccos C11``) loses
all precision near δ2 = 0; Table 2's quadrant logic for δ3 is wrong; eqs. 21–22
give the negative of the z-y-x pitch and a wrong yaw beyond δ2 = 90°.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_dcms, as_quaternions, finite_array
from strapdown.rotation.dcm import dcm_from_quat, quat_from_dcm
from strapdown.rotation.euler import _rx, _rz, euler_zyx_from_dcm

__all__ = [
    "cone_angles_from_dcm",
    "cone_angles_from_quat",
    "dcm_from_cone_angles",
    "pitch_yaw_roll_from_cone_angles",
    "quat_from_cone_angles",
]

_TWO_PI = 2.0 * np.pi


def dcm_from_cone_angles(d1: ArrayLike, d2: ArrayLike, d3: ArrayLike) -> NDArray[np.float64]:
    """``C_c_b = Rx(δ1) Rz(δ2) Rx(δ3 − δ1)``: Zhang & Yu eq. 4 transposed, eq. 2 corrected."""
    d1, d2, d3 = np.broadcast_arrays(finite_array(d1, "delta1"), finite_array(d2, "delta2"),
                                     finite_array(d3, "delta3"))
    return _rx(d1) @ _rz(d2) @ _rx(d3 - d1)


def quat_from_cone_angles(d1: ArrayLike, d2: ArrayLike, d3: ArrayLike) -> NDArray[np.float64]:
    """``q_c_b`` of the cone angles (w ≥ 0)."""
    return quat_from_dcm(dcm_from_cone_angles(d1, d2, d3))


def cone_angles_from_dcm(dcm: ArrayLike
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(δ1, δ2, δ3) from ``C_c_b``, robust at δ2 = 0 and δ2 = π (see module docstring)."""
    c = as_dcms(dcm, "dcm")
    s2 = np.hypot(c[..., 1, 0], c[..., 2, 0])
    d2 = np.arctan2(s2, c[..., 0, 0])
    d1 = np.mod(np.arctan2(c[..., 2, 0], c[..., 1, 0]), _TWO_PI)
    d3_low = np.arctan2(c[..., 2, 1] - c[..., 1, 2], c[..., 1, 1] + c[..., 2, 2])
    g = np.arctan2(-(c[..., 2, 1] + c[..., 1, 2]), c[..., 2, 2] - c[..., 1, 1])
    d3 = np.where(d2 <= np.pi / 2, d3_low, 2.0 * d1 - g)
    return d1, d2, np.mod(d3, _TWO_PI)


def cone_angles_from_quat(q: ArrayLike
                          ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(δ1, δ2, δ3) from ``q_c_b``."""
    return cone_angles_from_dcm(dcm_from_quat(as_quaternions(q, "q")))


def pitch_yaw_roll_from_cone_angles(
    d1: ArrayLike, d2: ArrayLike, d3: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """z-y-x (yaw, pitch, roll) of the same attitude, through the DCM (valid for every δ2)."""
    return euler_zyx_from_dcm(dcm_from_cone_angles(d1, d2, d3))

