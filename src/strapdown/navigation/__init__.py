"""Navigation: the body increments of :mod:`strapdown.algorithms.velocity` chained into
attitude, velocity and position.

``earth``
    on the WGS-84 Earth (NED): :func:`~strapdown.navigation.earth.navigate` from gyro and
    accelerometer increments, :func:`~strapdown.navigation.earth.navigate_rates` from rate
    and specific-force samples with a rate family's velocity counterpart,
    :class:`~strapdown.navigation.earth.NavStream` over a log fed in chunks.
``inertial``
    in a non-rotating frame without gravity (the sculling studies), in float64 and in
    arbitrary precision.

The compiled kernels (``_kernels``) and their plain-Python twins (``_reference``) sit beside
them. The layer lies between ``algorithms`` (the velocity update it navigates) and
``analysis`` (which evaluates it).
"""

from strapdown.navigation.earth import (
    GRAVITY_MODELS,
    POLE_LIMIT_DEG,
    TRAILING_POLICIES,
    GravityModel,
    NavSolution,
    NavStream,
    TrailingPolicy,
    TrailingSamplesWarning,
    navigate,
    navigate_rates,
)
from strapdown.navigation.inertial import (
    InertialSolution,
    MpInertialSolution,
    integrate_inertial,
    integrate_inertial_mp,
    integrate_inertial_rates,
)

__all__ = ["GRAVITY_MODELS", "POLE_LIMIT_DEG", "TRAILING_POLICIES", "GravityModel",
           "InertialSolution", "MpInertialSolution", "NavSolution", "NavStream",
           "TrailingPolicy", "TrailingSamplesWarning", "integrate_inertial",
           "integrate_inertial_mp", "integrate_inertial_rates", "navigate", "navigate_rates"]
