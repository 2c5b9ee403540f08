"""Small-angle-safe scalar functions shared by the rotation modules."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Below this angle argument x (rad), ``sin(x)/x`` uses its Taylor series
#: (terms to x⁶; the first omitted term x⁸/9! is below 3e-22 relative) and the
#: compiled exponential maps also take ``cos x`` from its series (terms to x⁸;
#: omitted x¹⁰/10! < 3e-27): exact to round-off, no libm call for the small
#: rotations of high-rate updates, and no loss at 1e-300 rad or exactly zero.
SMALL_ANGLE = 1e-2


def sinc(x: ArrayLike) -> NDArray[np.float64]:
    """``sin(x)/x`` (unnormalised), exact at 0, series below :data:`SMALL_ANGLE`."""
    x = np.asarray(x, dtype=np.float64)
    small = np.abs(x) < SMALL_ANGLE
    xs = np.where(small, 1.0, x)
    x2 = np.where(small, x, 0.0) ** 2  # the series only where it is used (no overflow)
    series = 1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))
    return np.where(small, series, np.sin(xs) / xs)
