"""The AHRS: a multiplicative error-state EKF propagated by any of the library's attitude
algorithms (:mod:`strapdown.ahrs.filter`), compiled as one loop (:mod:`strapdown.ahrs._kernel`):
:func:`ekf` (causal, real time) and :func:`offline_ekf` (forward and backward, acausal:
post-processing); :class:`MeasurementFlag` says what each output did with its measurements;
:func:`start_is_still` says whether a record starts still or in motion, as the filter decides;
:class:`GyroSaturationWarning` says that a record's gyro looks clipped at its range
(:mod:`strapdown.ahrs.saturation`).
"""

from strapdown.ahrs.filter import (
    AccelerometerUnusedWarning,
    AhrsConfig,
    AhrsResult,
    attitude_from_acc_mag,
    ekf,
    offline_ekf,
    start_is_still,
)
from strapdown.ahrs.flags import MeasurementFlag
from strapdown.ahrs.saturation import GyroSaturationWarning

__all__ = ["AccelerometerUnusedWarning", "AhrsConfig", "AhrsResult", "GyroSaturationWarning",
           "MeasurementFlag", "attitude_from_acc_mag", "ekf", "offline_ekf", "start_is_still"]
