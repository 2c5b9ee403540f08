"""Analysis: attitude errors, drift rates and their analytic predictions, one configuration
evaluated end to end, and BROAD's AHRS metrics.

The accuracy functions are re-exported here (``strapdown.analysis.drift_rate``); the
evaluation and the BROAD metrics live in :mod:`strapdown.analysis.evaluate` and
:mod:`strapdown.analysis.broad`.
"""

from strapdown.analysis.accuracy import (
    DriftEstimate,
    accumulated_drift,
    attitude_errors,
    chain_drift_rate,
    drift_rate,
    integrate_attitude_ode,
    rotation_per_update,
    sawtooth_amplitude,
    table1_prediction,
    update_period,
)

__all__ = [
    "DriftEstimate",
    "accumulated_drift",
    "attitude_errors",
    "chain_drift_rate",
    "drift_rate",
    "integrate_attitude_ode",
    "rotation_per_update",
    "sawtooth_amplitude",
    "table1_prediction",
    "update_period",
]
