"""Small-angle-safe scalar functions shared by the rotation modules."""

from __future__ import annotations

import numpy as np

#: Below this angle argument (rad) the ratios ``sin(x)/x`` use their Taylor
#: series (terms to x⁶, truncation < 1e-31 relative), so that rotation
#: vectors down to 1e-300 rad and exactly zero lose no accuracy.
SMALL_ANGLE = 1e-3


def sinc(x: np.ndarray) -> np.ndarray:
    """``sin(x)/x`` (unnormalised), exact at 0, series below :data:`SMALL_ANGLE`."""
    x = np.asarray(x, dtype=np.float64)
    small = np.abs(x) < SMALL_ANGLE
    xs = np.where(small, 1.0, x)
    x2 = x * x
    series = 1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))
    return np.where(small, series, np.sin(xs) / xs)
