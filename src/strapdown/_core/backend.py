"""Two arithmetic back-ends for closed-form formulas: float64 arrays and mpmath scalars.

A closed form is written once against the small namespace below (``sin``,
``cos``, ``sqrt``, ``sinc``, ``atan2``) and evaluated either vectorised in
float64 (:data:`NUMPY`) or in arbitrary precision (:func:`mp_backend`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np

from strapdown._core.series import sinc as _np_sinc


@dataclass(frozen=True)
class Backend:
    """Elementary functions of one arithmetic.

    ``sin_lin(lam, t)`` and ``cos_lin(lam, t)`` evaluate ``sin(λ t)`` and
    ``cos(λ t)`` for large phases: in float64 the product is formed exactly
    (``λ t = p + e``, Dekker/Veltkamp two-product) and ``sin(p + e)`` is
    ``sin p + e cos p``, so a phase of 10⁵ rad loses no more than its own
    representation.
    """

    name: str
    sin: Any
    cos: Any
    sqrt: Any
    atan2: Any
    sinc: Any  # sin(x)/x, 1 at 0
    num: Any  # converts a Python/NumPy number to this arithmetic
    zero: Any
    one: Any
    sin_lin: Any
    cos_lin: Any


_SPLIT = 134217729.0  # 2^27 + 1


def _two_prod(a, b):
    """``a·b = p + e`` exactly (barring overflow), elementwise."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    p = a * b
    big_a = _SPLIT * a
    ah = big_a - (big_a - a)
    al = a - ah
    big_b = _SPLIT * b
    bh = big_b - (big_b - b)
    bl = b - bh
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def _np_sin_lin(lam, t):
    p, e = _two_prod(lam, t)
    return np.sin(p) + e * np.cos(p)


def _np_cos_lin(lam, t):
    p, e = _two_prod(lam, t)
    return np.cos(p) - e * np.sin(p)


NUMPY = Backend(
    name="float64",
    sin=np.sin,
    cos=np.cos,
    sqrt=np.sqrt,
    atan2=np.arctan2,
    sinc=_np_sinc,
    num=np.float64,
    zero=np.float64(0.0),
    one=np.float64(1.0),
    sin_lin=_np_sin_lin,
    cos_lin=_np_cos_lin,
)


def _mp_sinc(x):
    return mpmath.mpf(1) if x == 0 else mpmath.sin(x) / x


def _mp_num(x):
    if isinstance(x, mpmath.mpf):
        return x
    if isinstance(x, str):
        return mpmath.mpf(x)
    return mpmath.mpf(float(x)) if isinstance(x, np.floating) else mpmath.mpf(x)


MPMATH = Backend(
    name="mpmath",
    sin=mpmath.sin,
    cos=mpmath.cos,
    sqrt=mpmath.sqrt,
    atan2=mpmath.atan2,
    sinc=_mp_sinc,
    num=_mp_num,
    zero=mpmath.mpf(0),
    one=mpmath.mpf(1),
    sin_lin=lambda lam, t: mpmath.sin(lam * t),
    cos_lin=lambda lam, t: mpmath.cos(lam * t),
)
