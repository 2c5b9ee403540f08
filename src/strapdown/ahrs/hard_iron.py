"""A magnetometer's hard-iron offset from the gyro, over a whole record (acausal).

A field fixed in the body (a magnetised part, an uncalibrated sensor's offset) adds a
constant ``b`` to every sample: ``m_k = C_k^T m_n + b``. Over a short span the gyro gives the
body's rotation ``R`` from sample k to sample k + d, and the Earth's field, constant in the
reference frame, turns with it: ``m_{k+d} − b = R (m_k − b)``, so

    m_{k+d} − R m_k = (I − R) b,

linear in ``b`` whatever the field's unit, its reference direction or the attitude. The
least-squares ``b`` over every span of the record is what :func:`hard_iron` returns —
in the directions the rotations observe: a body turning about one axis only (a pendulum)
says nothing of ``b`` along that axis (``I − R`` has it in its null space), and there ``b``
is a constant field in the reference frame as well, which the filter's learned reference
takes up; those directions are left at zero. Soft iron (a scaling) is not modelled.

Not a calibration to apply blindly: on BROAD's calibrated magnetometers it finds offsets of
2–4 % of the field's norm that explain nothing of the residual (the field's spatial
variation, its delay behind the gyro and noise dominate) and, subtracted, made the offline
filter worse; on its attached-magnet trials the magnet is there for part of the record
only. :attr:`HardIron.explained` says how much of ``m_{k+d} − R m_k`` the offset accounts
for, :attr:`HardIron.spread` how well the record's two halves agree on it,
:attr:`HardIron.steadier` how much steadier the field's norm is without it (soft iron, which
the model lacks, bends the estimate: then the norm hardly steadies, and subtracting it made
the simulated spin-coning worse, 0.08° → 0.47°); :func:`strapdown.ahrs.offline_ekf`
subtracts it only when it explains at least ``AhrsConfig.offline_hard_iron_min_explained``,
the halves agree within :data:`SPREAD_MAX` and the norm's spread falls to
:data:`STEADIER_MAX` of the raw field's or below.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import finite_array
from strapdown.ahrs import _kernel as K
from strapdown.algorithms.rate import check_rate_record

__all__ = ["SPAN_S", "SPREAD_MAX", "STEADIER_MAX", "HardIron", "hard_iron"]

#: The span over which the gyro's rotation is set against the field's change, s: long
#: enough for the rotation to stand out of the field's noise, short enough for the gyro's
#: drift.
SPAN_S = 0.1

#: A hard iron is constant: the two halves' offsets may differ by at most this fraction of
#: the whole record's (simulated offsets: ≤ 0.04; BROAD's 2 cm magnet, attached for part of
#: the trial: 1.43, its halves explaining 85 % and 6 %).
SPREAD_MAX = 0.2
#: Subtracting a hard iron steadies the field's norm: its coefficient of variation falls to
#: at most this fraction of the raw field's (simulated offsets of 5–30 % of the norm: 0.07–0.41
#: where subtracting helped, 0.45–0.76 where soft iron of 3–10 % bent the estimate and it
#: hurt).
STEADIER_MAX = 0.42


@dataclass(frozen=True)
class HardIron:
    """The estimate of :func:`hard_iron`.

    Attributes
    ----------
    offset : ndarray (3,)
        ``b``, body frame, in the magnetometer's unit; zero in unobserved directions.
    explained : float
        ``1 − Σ|r − (I − R) b|² / Σ|r|²`` over the spans (``r = m_{k+d} − R m_k``): the
        fraction of the field's change unexplained by the rotation alone that ``b``
        accounts for (0: nothing; 1: all).
    observed : int
        Directions of ``b`` the rotations observe (0–3).
    spread : float
        ``|b₁ − b₂| / |b|``: how far the estimates from the record's first and second half
        (same directions) lie apart, relative to the whole record's (∞ when ``b`` is 0).
    steadier : float
        The coefficient of variation of ``|m − b|`` over that of ``|m|`` (1 when ``|m|`` is
        constant).
    """

    offset: NDArray[np.float64]
    explained: float
    observed: int
    spread: float
    steadier: float


def hard_iron(t: ArrayLike, gyro: ArrayLike, mag: ArrayLike, *, span_s: float = SPAN_S,
              min_eigen: float = 0.05, gyro_sample: str = "interval") -> HardIron:
    """Estimate a magnetometer's hard-iron offset from the gyro (module docstring).

    Parameters
    ----------
    t : array_like (n,)
        Sample times, s, uniform (as :func:`strapdown.algorithms.rate.check_rate_record`
        takes them).
    gyro : array_like (n, 3)
        Body rates, rad/s (as in :func:`strapdown.ahrs.ekf`; a bias of a degree per second
        turns a 0.1 s span by 0.1°, negligible here).
    mag : array_like (n, 3)
        The field in the body, any unit.
    span_s : float
        Length of each span (s; at least one sample). Default :data:`SPAN_S`.
    min_eigen : float
        A direction is observed when its eigenvalue of ``Σ (I − R)ᵀ(I − R)`` is at least this
        fraction of the largest. Default 0.05.
    gyro_sample : {"interval", "point"}
        What a gyro sample is (``AhrsConfig.gyro_sample``).

    Returns
    -------
    HardIron

    Raises
    ------
    ValueError
        On invalid time stamps or rates (:func:`~strapdown.algorithms.rate.check_rate_record`
        names the row), a field of another shape or not finite, a non-positive ``span_s``,
        ``min_eigen`` outside (0, 1], or fewer than two spans.
    """
    rec = check_rate_record(t, gyro, min_samples=3)
    n = rec.t.size
    m = finite_array(mag, "mag")
    if m.shape != (n, 3):
        raise ValueError(f"mag must have shape ({n}, 3) to match t, got {m.shape}")
    if not span_s > 0 or not 0 < min_eigen <= 1:
        raise ValueError(f"need span_s > 0 and 0 < min_eigen <= 1; got {span_s}, {min_eigen}")
    return _hard_iron(rec.omega, m, rec.td, span_s, min_eigen, gyro_sample)


def _hard_iron(omega, m, td: float, span_s: float = SPAN_S, min_eigen: float = 0.05,
               gyro_sample: str = "interval") -> HardIron:
    """:func:`hard_iron` on a validated record: rates and field (n, 3), uniform period
    ``td``."""
    n = m.shape[0]
    d = max(1, round(span_s / td))
    if n - d < 2:
        raise ValueError(f"the record ({n} samples) holds fewer than two spans of {d}")
    m = np.ascontiguousarray(m, dtype=np.float64)
    q = np.empty((n, 4))
    K.gyro_path(np.ascontiguousarray(omega, dtype=np.float64), np.zeros((n, 3)), float(td),
                gyro_sample == "interval", q)
    half = (n - d) // 2
    normal, rhs = np.zeros((2, 3, 3)), np.zeros((2, 3))  # per half: Σ AᵀA, Σ Aᵀr
    rr = sum(K.hard_iron_sums(q, m, d, lo, hi, normal[j], rhs[j])
             for j, (lo, hi) in enumerate(((0, half), (half, n - d))))
    n_all, r_all = normal.sum(axis=0), rhs.sum(axis=0)
    lam, vec = np.linalg.eigh(n_all)
    keep = lam >= min_eigen * lam[-1] if lam[-1] > 0 else np.zeros(3, bool)
    v = vec[:, keep]
    b = v @ ((v.T @ r_all) / lam[keep])
    # each half in the same directions (their least squares restricted to them)
    bh = [v @ np.linalg.lstsq(v.T @ normal[j] @ v, v.T @ rhs[j], rcond=None)[0] for j in (0, 1)]
    nb = float(np.linalg.norm(b))
    spread = float(np.linalg.norm(bh[0] - bh[1])) / nb if nb > 0 else math.inf
    # Σ|r − A b|² = Σ|r|² − 2 bᵀ(Σ Aᵀr) + bᵀ(Σ AᵀA) b
    left = rr - 2.0 * float(b @ r_all) + float(b @ n_all @ b)
    explained = 1.0 - max(left, 0.0) / rr if rr > 0 else 0.0
    return HardIron(b, float(explained) if math.isfinite(explained) else 0.0, int(keep.sum()),
                    spread, _cv(m - b) / cv if (cv := _cv(m)) > 0 else 1.0)


def _cv(m) -> float:
    """The coefficient of variation of the rows' norms."""
    n = np.linalg.norm(m, axis=1)
    mean = float(n.mean())
    return float(n.std()) / mean if mean > 0 else 0.0
