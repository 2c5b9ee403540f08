"""Analysis: attitude errors, drift rates and their analytic predictions, one configuration
evaluated end to end, and BROAD's AHRS metrics.

The accuracy functions are re-exported here (``strapdown.analysis.drift_rate``); the
evaluation and the BROAD metrics live in :mod:`strapdown.analysis.evaluate` and
:mod:`strapdown.analysis.broad`.
"""

from strapdown.analysis import accuracy as _accuracy
from strapdown.analysis.accuracy import *  # noqa: F403  (the subpackage's public face)

__all__ = list(_accuracy.__all__)
