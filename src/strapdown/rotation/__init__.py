"""Rotation math, batched over leading dimensions; one module per representation.

Conversions are named ``target_from_source``. See :mod:`strapdown` for the
conventions (Hamilton, scalar first, ``q_n_b``).

Small-angle threshold
---------------------
:data:`SMALL_ANGLE` (1e-2): below it ``sin(x)/x`` ratios switch to a Taylor
series (first omitted term below 3e-22 relative; the compiled kernels also take
``cos`` from its series), so the exponential and logarithm maps are exact to
round-off from 1e-300 rad up to π.
"""

from strapdown._core.series import SMALL_ANGLE
from strapdown.rotation.cone_angles import (
    cone_angles_from_dcm,
    cone_angles_from_quat,
    dcm_from_cone_angles,
    pitch_yaw_roll_from_cone_angles,
    quat_from_cone_angles,
)
from strapdown.rotation.dcm import dcm_from_quat, quat_from_dcm
from strapdown.rotation.error import (
    attitude_error_angle,
    attitude_error_quat,
    attitude_error_vector,
)
from strapdown.rotation.euler import dcm_from_euler_zyx, euler_zyx_from_dcm
from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat
from strapdown.rotation.quaternion import (
    quat_canonical,
    quat_conjugate,
    quat_from_rotvec,
    quat_identity,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    rotvec_from_quat,
)
from strapdown.rotation.rotvec import dcm_from_rotvec, f1_f2, skew

__all__ = [
    "SMALL_ANGLE",
    "attitude_error_angle",
    "attitude_error_quat",
    "attitude_error_vector",
    "cone_angles_from_dcm",
    "cone_angles_from_quat",
    "dcm_from_cone_angles",
    "dcm_from_euler_zyx",
    "dcm_from_quat",
    "dcm_from_rotvec",
    "euler_zyx_from_dcm",
    "f1_f2",
    "pitch_yaw_roll_from_cone_angles",
    "quat_canonical",
    "quat_conjugate",
    "quat_from_cone_angles",
    "quat_from_dcm",
    "quat_from_rotvec",
    "quat_from_scipy",
    "quat_identity",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "rotvec_from_quat",
    "scipy_from_quat",
    "skew",
]
