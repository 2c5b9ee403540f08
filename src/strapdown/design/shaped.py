"""Frequency-shaped coning design: coefficients that minimise the drift over a band or a
spectrum, beside the polynomial (order-by-order) target of :mod:`.designer`.

Ignagni (1996) chose coning coefficients to minimise the drift of pseudo-coning spread over
a frequency band rather than to raise the order at ``Ωh → 0``. To second order in the
amplitude the classical-coning drift at ``x = Ωh`` is affine in the pair coefficients,
``d(x) = d₀(x) + Σ_k c_k d_k(x)``, for every structure (increment or rate input; the rate
quadrature error does not involve the pairs), and the drift under a spectrum is
``∫ C(f) d(2πfh) …`` (:mod:`strapdown.analysis.spectrum`). :func:`shaped_design` minimises
``Σ_g w_g d(x_g)²`` over a grid of ``x`` — a band (``w = 1``) or a coning spectrum's
kernel-weighted powers (``w = |C|``) — by linear least squares, the columns ``d₀, d_k``
taken from the exact response (:func:`strapdown.analysis.frequency_response.
classical_coning_drift` at a small half angle). The result is float64, not exact.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import finite_array
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.analysis.frequency_response import classical_coning_drift
from strapdown.design.designer import Structure

__all__ = ["ShapedDesign", "band_response", "shaped_design"]

_SMALL_A = 1e-8


@dataclass(frozen=True)
class ShapedDesign:
    """Least-squares coefficients (one per pair of ``structure``) and the weighted RMS of the
    drift constant ``d(x)/(a²Ω)`` over the grid, for them and for the reference set."""

    structure: Structure
    coefficients: tuple[float, ...]
    rms: float
    reference_rms: float


def _algorithm(st: Structure, coefficients: Sequence[float | Fraction]) -> WindowedAlgorithm:
    return WindowedAlgorithm(st.input, st.update, tuple(int(s) for s in st.nodes), st.weights,
                             st.pairs, tuple(coefficients), st.name)


def band_response(structure: Structure, coefficients: Sequence[float | Fraction],
                  omega_h: ArrayLike) -> NDArray[np.float64]:
    """``d(x)/(a²Ω)`` at the ``omega_h`` values (leading order in ``a``, exact in ``x``)."""
    x = finite_array(omega_h, "omega_h")
    alg = _algorithm(structure, coefficients)
    return np.array([classical_coning_drift(alg, _SMALL_A, float(v), digits=80) / _SMALL_A**2
                     for v in x.ravel()]).reshape(x.shape)


def shaped_design(structure: Structure, omega_h: ArrayLike, weights: ArrayLike | None = None,
                  *, reference: Sequence[float | Fraction] | None = None) -> ShapedDesign:
    """Pair coefficients minimising ``Σ w (d(x)/(a²Ω))²`` over the grid ``omega_h``.

    ``weights`` default to 1 (a band); ``reference`` (default: zeros) is the set the RMS is
    compared with, e.g. the order-by-order design. Integer-node structures only.
    """
    x = finite_array(omega_h, "omega_h").ravel()
    if x.size < len(structure.pairs) + 1 or np.any(x <= 0):
        raise ValueError("omega_h must hold more positive points than the structure has pairs")
    w = np.ones_like(x) if weights is None else finite_array(weights, "weights").ravel()
    if w.shape != x.shape or np.any(w < 0) or not np.any(w > 0):
        raise ValueError("weights must be non-negative, one per omega_h, not all zero")
    k = len(structure.pairs)
    d0 = band_response(structure, [0.0] * k, x)
    cols = np.stack([band_response(structure, [float(i == j) for i in range(k)], x) - d0
                     for j in range(k)], axis=1)
    sw = np.sqrt(w)
    c, *_ = np.linalg.lstsq(cols * sw[:, None], -d0 * sw, rcond=None)
    ref = np.zeros(k) if reference is None else np.array([float(v) for v in reference])

    def rms(coef):
        r = d0 + cols @ coef
        return float(np.sqrt(np.sum(w * r * r) / np.sum(w)))

    return ShapedDesign(structure, tuple(float(v) for v in c), rms(c), rms(ref))
