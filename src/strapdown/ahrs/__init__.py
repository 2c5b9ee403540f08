"""The AHRS: a multiplicative error-state EKF propagated by any of the library's attitude
algorithms (:mod:`strapdown.ahrs.filter`), compiled as one loop (:mod:`strapdown.ahrs._kernel`).
"""

from strapdown.ahrs.filter import AhrsConfig, AhrsResult, attitude_from_acc_mag, ekf

__all__ = ["AhrsConfig", "AhrsResult", "attitude_from_acc_mag", "ekf"]
