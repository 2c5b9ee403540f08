"""Norms and normalisation across the whole float64 range, by exact powers of two.

A vector is scaled by ``2**-e`` so that its largest component lies in [0.5, 1) — exact:
only the exponent changes — before anything is squared, so neither ``1e300`` (whose square
overflows) nor ``1e-160`` (whose square underflows) loses its norm. For vectors already in
that range (every unit quaternion: its largest component is at least 0.5) ``e = 0`` and
results are bit-identical to the unscaled formulas; for others the scaled computation
differs from the unscaled one only where that one overflowed or underflowed, because
scaling by a power of two commutes exactly with products, sums, square roots and ratios.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["pow2_exponent", "safe_norm", "safe_unit"]


def pow2_exponent(x: ArrayLike) -> NDArray[np.int_]:
    """``e`` with ``max|x| = f · 2**e``, ``f`` in [0.5, 1), over the last axis (kept); 0 for
    a zero vector."""
    m = np.max(np.abs(np.asarray(x, dtype=np.float64)), axis=-1, keepdims=True)
    return np.frexp(m)[1]


def safe_norm(x: ArrayLike) -> NDArray[np.float64]:
    """Euclidean norm over the last axis without overflow or underflow (inf only when the
    norm itself exceeds the float64 range)."""
    x = np.asarray(x, dtype=np.float64)
    e = pow2_exponent(x)
    with np.errstate(over="ignore"):  # a norm above 1.8e308 is inf, as it must be
        return np.ldexp(np.linalg.norm(np.ldexp(x, -e), axis=-1), e[..., 0])


def safe_unit(x: ArrayLike) -> NDArray[np.float64]:
    """``x / |x|`` over the last axis for any non-zero finite ``x`` (a zero vector stays
    zero-divided: the callers refuse zero vectors first)."""
    x = np.asarray(x, dtype=np.float64)
    u = np.ldexp(x, -pow2_exponent(x))
    return u / np.linalg.norm(u, axis=-1, keepdims=True)
