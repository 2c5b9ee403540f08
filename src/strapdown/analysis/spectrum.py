"""Drift under a general angular vibration from the cross-spectrum of the body rates.

To second order in the rates the drift of a rotation-invariant attitude algorithm is a
time-invariant bilinear functional of the transverse rates, so components at different
frequencies do not interact on average and the drift about axis ``x`` is the sum, over
frequency, of the classical-coning response weighted by the coning (quadrature) power of
the ``(y, z)`` rates (pseudo-coning; Ignagni (1996) designs against it band by band):

    drift_x = ∫ C_yz(f) K(2πf) df,   C_yz = −Im G_yz,   K(ω) = 2 d(ω) / (a² ω²),

``G_yz`` the one-sided cross-spectral density (scipy's convention, ``conj(Y) Z``), and
``d(ω)`` the exact classical-coning drift at cone rate ``ω`` and a small half angle ``a``
(:func:`strapdown.analysis.frequency_response.classical_coning_drift`): a classical cone of
rate amplitude ``A = aω`` has ``C = A²/2`` at ``ω``. Likewise about ``y`` from ``(z, x)`` and
about ``z`` from ``(x, y)``. Spectra come from a gyro log by Welch's method
(:func:`cross_spectra`) or from a file.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal

from strapdown._core.validation import finite_array, positive
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.analysis.frequency_response import classical_coning_drift

__all__ = ["PAIRS", "WELCH_VARIANCE_FACTOR", "coning_kernel", "coning_spectrum", "cross_spectra",
           "predict_drift", "predict_drift_lines", "predict_drift_stderr"]

#: Axis pairs whose coning power drifts about x, y and z.
PAIRS = ((1, 2), (2, 0), (0, 1))
#: Half angle of the kernel's classical cone: a⁴ terms are 1e-16 of the a² ones.
_SMALL_A = 1e-8


@functools.lru_cache(maxsize=4096)
def _kernel_one(spec_text: str, omega: float, h: float) -> float:
    spec = AlgorithmSpec.parse(spec_text)
    try:
        d = classical_coning_drift(spec, _SMALL_A, omega * h, cone_rate=omega, digits=80)
    except ValueError:  # a whole cone turn per update: the mean of the two sides
        d = sum(classical_coning_drift(spec, _SMALL_A, omega * h * (1 + e), cone_rate=omega,
                                       digits=80) for e in (-1e-7, 1e-7)) / 2
    return 2 * d / (_SMALL_A**2 * omega**2)


def coning_kernel(algorithm: AlgorithmSpec, omega: ArrayLike, h: float) -> NDArray[np.float64]:
    """``K(ω)``: drift about an axis (rad/s) per unit coning power (rad²/s²) at rate
    frequencies ``omega`` (rad/s), for input samples every ``h`` seconds."""
    if not isinstance(algorithm, AlgorithmSpec):
        raise ValueError(f"algorithm must be an AlgorithmSpec, got {type(algorithm).__name__}")
    h = positive(h, "h (sample interval)")
    w = finite_array(omega, "omega")
    if np.any(w <= 0) or np.any(w * h >= np.pi):
        raise ValueError("frequencies must lie in (0, Nyquist)")
    return np.array([_kernel_one(str(algorithm), float(x), h) for x in w.ravel()]
                    ).reshape(w.shape)


def cross_spectra(rates: ArrayLike, fs: float, *, nperseg: int = 256
                  ) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """Welch estimate of the one-sided cross-spectral densities of body rates ``(n, 3)``
    sampled at ``fs`` Hz: frequencies (Hz) and ``G`` of shape (F, 3, 3),
    ``G[:, i, j]`` the CSD of axes i and j (``conj(X_i) X_j``)."""
    w = finite_array(rates, "rates")
    if w.ndim != 2 or w.shape[1] != 3 or w.shape[0] < 16:
        raise ValueError(f"rates must have shape (n ≥ 16, 3), got {w.shape}")
    fs = positive(fs, "fs (sample rate)")
    seg = min(int(nperseg), w.shape[0])
    out = None
    f = np.empty(0)
    for i in range(3):
        for j in range(3):
            f, g = signal.csd(w[:, i], w[:, j], fs=fs, nperseg=seg)
            if out is None:
                out = np.empty((f.size, 3, 3), dtype=np.complex128)
            out[:, i, j] = g
    assert out is not None
    return f, out


def coning_spectrum(csd: ArrayLike) -> NDArray[np.float64]:
    """Coning power density ``C = −Im G`` per axis (F, 3) from CSDs (F, 3, 3)."""
    g = np.asarray(csd)
    if g.ndim != 3 or g.shape[1:] != (3, 3):
        raise ValueError(f"cross-spectra must have shape (F, 3, 3), got {g.shape}")
    return np.stack([-g[:, i, j].imag for i, j in PAIRS], axis=-1)


def predict_drift(algorithm: AlgorithmSpec, freqs_hz: ArrayLike, csd: ArrayLike, h: float
                  ) -> NDArray[np.float64]:
    """Predicted drift vector (rad/s) from CSDs ``(F, 3, 3)`` at ``freqs_hz`` (uniform bins,
    as from :func:`cross_spectra`); bins at 0 Hz and at or beyond Nyquist are left out."""
    f = finite_array(freqs_hz, "freqs_hz")
    c = coning_spectrum(csd)
    if f.ndim != 1 or f.size != c.shape[0] or f.size < 2:
        raise ValueError("freqs_hz must be 1-D with one entry per spectral bin")
    df = float(f[1] - f[0])
    keep = (f > 0) & (2 * np.pi * f * h < np.pi * (1 - 1e-9))
    k = coning_kernel(algorithm, 2 * np.pi * f[keep], h)
    return np.sum(c[keep] * k[:, None], axis=0) * df


def predict_drift_lines(algorithm: AlgorithmSpec, omega: ArrayLike, power: ArrayLike, h: float
                        ) -> NDArray[np.float64]:
    """Predicted drift vector (rad/s) from a line spectrum: tones at ``omega`` (rad/s) with
    coning powers ``power`` (K, 3) (e.g. :meth:`strapdown.truth.vibration.ToneVibration.
    coning_power`)."""
    k = coning_kernel(algorithm, omega, h)
    p = finite_array(power, "power")
    if p.shape != (k.size, 3):
        raise ValueError(f"power must have shape ({k.size}, 3), got {p.shape}")
    return np.sum(p * k[:, None], axis=0)


#: Variance of a Welch cross-spectrum sum relative to independent bins and segments: Hann
#: windows correlate neighbouring bins (periodogram correlation (2/3)² and (1/6)²: ×1.94)
#: and 50 % overlap correlates neighbouring segments (×1.06); rounded up.
WELCH_VARIANCE_FACTOR = 2.1


def predict_drift_stderr(algorithm: AlgorithmSpec, freqs_hz: ArrayLike, csd: ArrayLike,
                         h: float, segments: int) -> NDArray[np.float64]:
    """Standard error (rad/s, per axis) of :func:`predict_drift` from a Welch estimate with
    ``segments`` averaged segments, under the null hypothesis of no coning: the quadrature
    estimate of axes i, j has variance ``(P_i P_j − Co_ij²) / (2 K)`` per bin (Bendat &
    Piersol's result for Gaussian processes), times :data:`WELCH_VARIANCE_FACTOR`."""
    f = finite_array(freqs_hz, "freqs_hz")
    g = np.asarray(csd)
    coning_spectrum(g)  # validates the shape
    if segments < 1:
        raise ValueError(f"segments must be at least 1, got {segments}")
    df = float(f[1] - f[0])
    keep = (f > 0) & (2 * np.pi * f * h < np.pi * (1 - 1e-9))
    k = coning_kernel(algorithm, 2 * np.pi * f[keep], h)
    out = np.empty(3)
    for col, (i, j) in enumerate(PAIRS):
        p = np.real(g[keep, i, i]) * np.real(g[keep, j, j]) - np.real(g[keep, i, j]) ** 2
        var = np.maximum(p, 0.0) * WELCH_VARIANCE_FACTOR / (2 * segments)
        out[col] = math.sqrt(float(np.sum(k**2 * var))) * df
    return out
