"""What a measured/law drift ratio means: resolved, below the round-off floor, or not the law.

The drift laws (:class:`~strapdown.algorithms.family.DriftLaw`: the Table 1 law of
Li & Zhang (2017) for the rotation vector, the rate-input laws of Wang, Wang & Wang) are
the leading term ``−c·a²Ω(Ωh)^k`` of the classical-coning drift about the cone axis. A
measured/law ratio is meaningful only when

1. the drift stands above the arithmetic's round-off **floor** — otherwise the measured
   value is round-off and the ratio any number (−450 620 for N = 3 at 10 kHz); and
2. the terms of higher order in the half-cone angle ``a`` (``a⁴Ω(Ωh)^j`` with ``j < k``),
   which the law leaves out, are small — otherwise the ratio is far from 1 however
   precise the arithmetic (−3.84 for N = 3, real-time, at 600 Hz: mpmath at 25 digits
   measures the same drift as float64).

**The floor.** In classical coning the attitude's cone-axis component is of size a², so
rounding it costs about ``a²·ε`` rad per update; as a random walk over ``n`` updates it
shifts the slope fitted over the run length ``T`` by about ``a²·ε·√n / T``. We take
:data:`FLOOR_FACTOR` times that::

    floor = 4 · a² · ε · √n / T     (rad/s; ε = 2.2e-16 in float64, 10^(1−digits) in mpmath)

Calibration (float64 against mpmath at 25 digits, same configuration; 70 runs: every
family and structure, 600 Hz–10 kHz, T = 2–20 s, n = 24–10⁵ updates, a = 1e-6 rad–60°):
the float64 cone-axis drift differs from the mpmath one by at most 0.76·a²·ε·√n/T, so the
factor 4 leaves a margin of five. The floor falls with a² as fast as the law: a = 0.01°,
N = 3 real-time at 600 Hz measures the law's −9.0e-22 rad/s to 0.06 % in float64. An
estimate without the a² (ε per update) would overstate the floor ten-thousandfold there.

**Higher order in a.** A ratio outside :data:`RATIO_BAND` while the law or the measured
drift stands above the floor. Higher order in Ωh alone moves the ratio far less: with
a = 0.001° every family stays within 0.6–1.0 up to Ωh = 1 (rk4 0.61, rotvec N = 3 0.81,
rate-three 0.86), whereas rate-three at 100 Hz measures a drift that grows as a⁴
(a = 0.25°, 0.5°, 1°: ratio 93, 369, 1473).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, Literal

__all__ = [
    "BELOW_FLOOR",
    "BELOW_MP_FLOOR",
    "FLOOR_FACTOR",
    "GYRO_ERRORS",
    "HIGHER_ORDER",
    "RATIO_BAND",
    "RESOLVED",
    "LawResolution",
    "LawStatus",
    "describe",
    "judge_law",
    "roundoff_floor",
]

#: The ratio is meaningful: the law stands above the floor and describes the drift.
RESOLVED: Final = "resolved"
#: Neither the law nor the measured drift stands above the arithmetic's floor.
BELOW_FLOOR: Final = "below float64 floor"
#: The same for an arbitrary-precision run.
BELOW_MP_FLOOR: Final = "below mpmath floor"
#: The drift is resolved but is not the law's: the a⁴ terms outweigh the a² law.
HIGHER_ORDER: Final = "higher order in a dominates"
#: The run had gyro errors: the measured drift includes theirs, the law is the ideal gyro's.
GYRO_ERRORS: Final = "gyro errors included"
#: Ratios inside this band count as the law's (higher order in Ωh stays inside it).
RATIO_BAND = (0.5, 2.0)
#: The floor is this many times a²·ε·√n/T (see the module docstring for the calibration).
FLOOR_FACTOR = 4.0

LawStatus = Literal["resolved", "below float64 floor", "below mpmath floor",
                    "higher order in a dominates", "gyro errors included"]


@dataclass(frozen=True)
class LawResolution:
    """The judgement of one measured/law pair.

    Attributes
    ----------
    ratio : float or None
        measured / law (None without a law or a measurement).
    status : str or None
        One of :data:`RESOLVED`, :data:`BELOW_FLOOR`, :data:`BELOW_MP_FLOOR`,
        :data:`HIGHER_ORDER`, :data:`GYRO_ERRORS`; None when there is no ratio.
    floor : float or None
        The round-off floor (rad/s) the drifts were held against.
    note : str
        One sentence: what the status means here and what resolves it ("" when resolved).
    """

    ratio: float | None
    status: LawStatus | None
    floor: float | None
    note: str


def roundoff_floor(half_angle: float, duration: float, updates: float,
                   digits: int | None = None) -> float:
    """The drift (rad/s) below which round-off hides a cone-axis drift (module docstring).

    Parameters
    ----------
    half_angle : float
        Half-cone angle ``a`` (rad).
    duration : float
        Length of the run the drift is fitted over (s).
    updates : float
        Attitude updates in the run (duration / update period).
    digits : int, optional
        mpmath significant digits; None for float64.
    """
    if not duration > 0:
        raise ValueError(f"duration must be positive, got {duration}")
    if not updates >= 1:
        raise ValueError(f"updates must be at least 1, got {updates}")
    eps = 2.0**-52 if digits is None else 10.0 ** (1 - digits)
    return FLOOR_FACTOR * half_angle**2 * eps * math.sqrt(updates) / duration


def judge_law(measured: float | None, predicted: float | None, *, half_angle: float,
              duration: float, updates: float, digits: int | None = None,
              ideal_gyro: bool = True) -> LawResolution:
    """Say whether ``measured / predicted`` is meaningful, and if not why (module docstring).

    Parameters
    ----------
    measured, predicted : float or None
        Measured cone-axis drift and the law's (rad/s).
    half_angle : float
        Half-cone angle ``a`` (rad).
    duration : float
        Run length (s).
    updates : float
        Attitude updates in the run.
    digits : int, optional
        mpmath significant digits of the run; None for float64.
    ideal_gyro : bool
        False when the run's gyro had errors (noise, bias, ...).
    """
    if measured is None or not predicted or not (math.isfinite(measured)
                                                 and math.isfinite(predicted)):
        return LawResolution(None, None, None, "")
    ratio = measured / predicted
    floor = roundoff_floor(half_angle, duration, updates, digits)
    arith = "float64" if digits is None else f"{digits}-digit mpmath"
    if not ideal_gyro:
        return LawResolution(ratio, GYRO_ERRORS, floor,
                             "the measured drift includes the gyro errors' drift; the law is "
                             "the ideal gyro's (run without gyro errors to compare)")
    in_band = RATIO_BAND[0] <= ratio <= RATIO_BAND[1]
    law_above, measured_above = abs(predicted) >= floor, abs(measured) >= floor
    if law_above and in_band:
        return LawResolution(ratio, RESOLVED, floor, "")
    if law_above or measured_above:
        return LawResolution(ratio, HIGHER_ORDER, floor, (
            f"the measured drift {measured:.3g} rad/s is resolved ({arith} floor "
            f"{floor:.2g} rad/s) but is not the a² law's {predicted:.3g} rad/s: terms in a⁴ "
            "dominate; a smaller --half-angle-deg shrinks them as a² (with --precision 30 "
            "once the law falls below the float64 floor)"))
    status: LawStatus = BELOW_FLOOR if digits is None else BELOW_MP_FLOOR
    more = "--precision 30" if digits is None else f"--precision {2 * digits}"
    return LawResolution(ratio, status, floor, (
        f"the law {predicted:.3g} rad/s and the measured {measured:.3g} rad/s are both "
        f"below what {arith} resolves here ({floor:.2g} rad/s = {FLOOR_FACTOR:g}·a²·ε·√n/T): "
        f"the ratio is round-off; {more} resolves it (a longer --duration lowers the floor "
        "as 1/√T)"))


def describe(res: LawResolution) -> str:
    """``"status: note"`` for human output ("" when there is no ratio)."""
    if res.status is None:
        return ""
    return res.status if not res.note else f"{res.status}: {res.note}"
