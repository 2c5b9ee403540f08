"""The WGS-84 Earth: radii of curvature, normal gravity, Earth and transport rates (NED).

Constants of the WGS-84 ellipsoid (NIMA TR8350.2 (2000)); normal gravity by Somigliana's
closed formula with the second-order free-air height correction
``γ(L, h) = γ0(L) [1 − 2/a (1 + f + m − 2 f sin²L) h + 3 h²/a²]`` (``model="wgs84"``, the
default) or its linear term only (``model="linear"``: without ``3 h²/a²``, lighter by
7.2e-7 m/s² at 1 km and 7.2e-5 m/s² at 10 km); the navigation frame is local
north–east–down (Savage (1998b)). The compiled navigation kernel
(:mod:`strapdown.navigation._kernels`) repeats these formulas; the tests hold them
equal.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "E2",
    "GE",
    "GK",
    "GM_RATIO",
    "GRAVITY_MODELS",
    "OMEGA",
    "A",
    "F",
    "GravityModel",
    "earth_rate",
    "gravity",
    "gravity_quadratic",
    "radii",
    "transport_rate",
]

#: Semi-major axis (m) and flattening.
A = 6378137.0
F = 1.0 / 298.257223563
#: First eccentricity squared.
E2 = F * (2.0 - F)
#: Earth rotation rate (rad/s).
OMEGA = 7.292115e-5
#: Normal gravity at the equator (m/s²) and Somigliana's constant k.
GE = 9.7803253359
GK = 0.00193185265241
#: m = ω² a² b / GM.
GM_RATIO = 0.00344978650684
#: Normal gravity's height correction: second order (WGS-84's formula) or linear.
GravityModel = Literal["wgs84", "linear"]
GRAVITY_MODELS: tuple[GravityModel, ...] = get_args(GravityModel)


def radii(lat: ArrayLike, h: ArrayLike = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(R_N + h, R_E + h)``: meridian and transverse radii of curvature plus height (m)."""
    s2 = np.sin(np.asarray(lat, dtype=np.float64)) ** 2
    h = np.asarray(h, dtype=np.float64)
    d = 1.0 - E2 * s2
    return A * (1.0 - E2) / (d * np.sqrt(d)) + h, A / np.sqrt(d) + h


def gravity(lat: ArrayLike, h: ArrayLike = 0.0,
            model: GravityModel = "wgs84") -> NDArray[np.float64]:
    """Normal gravity magnitude ``γ(L, h)`` (m/s², positive down), with the second-order
    height correction (``"wgs84"``) or the linear one (``"linear"``)."""
    quad = gravity_quadratic(model)
    s2 = np.sin(lat) ** 2
    g0 = GE * (1.0 + GK * s2) / np.sqrt(1.0 - E2 * s2)
    h = np.asarray(h, dtype=np.float64)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + GM_RATIO - 2.0 * F * s2) * h
                 + quad * (3.0 * h * h / (A * A)))


def gravity_quadratic(model: object) -> float:
    """The factor of normal gravity's ``3 h²/a²`` term for a :data:`GravityModel` (1.0 or
    0.0); an unknown model is an error naming the choices."""
    if model not in GRAVITY_MODELS:
        raise ValueError(f"unknown gravity model {model!r}; choose one of "
                         f"{', '.join(GRAVITY_MODELS)}")
    return 1.0 if model == "wgs84" else 0.0


def earth_rate(lat: ArrayLike) -> NDArray[np.float64]:
    """``ω_ie`` in NED (rad/s), shape ``lat.shape + (3,)``."""
    lat = np.asarray(lat, dtype=np.float64)
    return np.stack([OMEGA * np.cos(lat), 0.0 * lat, -OMEGA * np.sin(lat)], axis=-1)


def transport_rate(lat: ArrayLike, h: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """``ω_en`` in NED (rad/s) for NED velocity ``v`` (..., 3)."""
    v = np.asarray(v, dtype=np.float64)
    rn, re = radii(lat, h)
    return np.stack([v[..., 1] / re, -v[..., 0] / rn, -v[..., 1] * np.tan(lat) / re], axis=-1)
