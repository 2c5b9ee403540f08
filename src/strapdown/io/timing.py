"""The time base of a recording as it comes: held and duplicated rows, and the sensor's own
clock reconstructed from noisy time stamps.

An IMU samples on its own clock, uniformly; what a file holds are the stamps a logger gave
the rows. Those stamps jitter (the logger stamps on arrival), are rounded to a coarser tick
(whole milliseconds), repeat a sample the sensor has not renewed (a logger faster than its
sensor *holds* the last sample), repeat a whole row (a duplicated stamp), or miss samples
(a gap). This module recovers the sensor's clock from the stamps and says which of these it
saw; the readers (:mod:`strapdown.io.readers`) apply it, the commands report it.

Rows (:func:`clean_rows`)
    * a **duplicated stamp** whose row repeats the previous one exactly is dropped;
    * a duplicated stamp with a different row is an error naming both rows, unless the
      policy ``duplicates="first"`` or ``"last"`` keeps one of them;
    * **held samples** — consecutive rows whose sensor values are all identical — are
      collapsed to one sample at their first stamp. With ``held="auto"`` they are collapsed
      only when the collapse is confirmed by the clock: on the sensor clock fitted to the
      other rows, most repeats fall on a tick a sample already holds (a sensor at rest whose
      quantised output repeats does not pass, nor does a block of identical rows at the
      start or the end of a log: each of those rows has a tick of its own).

Clock (:func:`fit_clock`)
    Each sample ``i`` is assigned a tick ``k_i`` of a clock ``T(k) = c + p·k (+ drift)``:
    first by runs — consecutive samples (intervals under 1.5 times a robust period, the
    mean interval below 1.5 median intervals) are one tick apart, the period is the runs'
    pooled least-squares slope, and a break between runs spans the whole number of periods
    between their fitted lines —, then by least squares of the stamps on the ticks and a
    global re-rounding against the fitted clock, repeated until the ticks stop changing. A
    slowly drifting clock is fitted by a cubic in the tick (Legendre basis) when it
    explains the residuals. A **gap** is whole ticks missing on the fitted clock, not a late
    stamp. The residuals ``t_i − T(k_i)`` classify the stamps:

    ``uniform``
        every interval within :data:`UNIFORM_TOLERANCE` of the period;
    ``quantised``
        stamps on a tick ``τ`` (integer stamps, or decimal ones) with residuals within
        ``τ/2`` — rounding;
    ``noise``
        residuals (99th percentile of ``|r|``) within ``jitter_tolerance`` periods;
    ``drifting``
        as ``noise``, after the drift term (its amplitude reported);
    ``irregular``
        none of these: the samples were not taken on a uniform clock (or ticks collide).

    Thresholds: :data:`JITTER_TOLERANCE` (0.45 period by default: beyond half a period a
    stamp can no longer be given its tick), :data:`COLLISION_LIMIT`.

What each choice costs. Samples taken to lie on the fitted clock (``auto``, ``nominal``)
cost nothing when the sensor does sample on its own clock and only the stamps jitter — the
common case, and the one a logger that stamps on arrival or rounds produces; if instead the
samples were taken at the jittered stamps, integrating them on the clock errs by about
``ω̇·e`` per sample for a stamp error ``e`` (1.5e-6 rad over 2 s of 1° coning at 1 kHz with
±0.5 % jitter, ``tests/cli/test_jitter.py``), and ``resample`` is right: its cubic-spline
error is fourth order in the period (:func:`strapdown.algorithms.rate.resample_uniform`).
A gap bridged by the AHRS interpolates the sensors linearly across it; the attitude there
is the gyro's integral over the interpolated rate, and its error grows with the motion the
gap hides (hence the 1 s limit, ``--on-gap split`` beyond).

Times are handled relative to the first stamp (exact for integer stamps) so that epoch
stamps lose nothing; :func:`format_times` writes them back in the original time base.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError

__all__ = [
    "BRIDGE_MAX_S",
    "CLOCK_KINDS",
    "COLLISION_LIMIT",
    "DUPLICATE_POLICIES",
    "HELD_POLICIES",
    "JITTER_TOLERANCE",
    "TIMING_MODES",
    "UNIFORM_TOLERANCE",
    "ClockKind",
    "DuplicatePolicy",
    "HeldPolicy",
    "RowCleaning",
    "SampleClock",
    "TimeBase",
    "Timing",
    "TimingMode",
    "clean_rows",
    "fit_clock",
    "format_times",
    "reconstruct",
    "relative_times",
    "uniform_timing_record",
]

#: How a command takes a recording's time stamps: ``auto`` (the classification decides:
#: samples on the fitted clock, or resampled when the sampling is irregular), ``nominal``
#: (on the fitted clock whatever the residuals), ``stamps`` (the stamps are the sample
#: times; algorithms that need uniform samples refuse others) or ``resample`` (the samples
#: were taken at the stamps: interpolated onto a uniform grid).
TimingMode = Literal["auto", "nominal", "stamps", "resample"]
TIMING_MODES: tuple[TimingMode, ...] = get_args(TimingMode)
#: What the stamps look like against the fitted clock (see the module docstring).
ClockKind = Literal["uniform", "quantised", "noise", "drifting", "irregular"]
CLOCK_KINDS: tuple[ClockKind, ...] = get_args(ClockKind)
#: Held samples: collapse when the clock confirms them (``auto``), always, or never.
HeldPolicy = Literal["auto", "collapse", "keep"]
HELD_POLICIES: tuple[HeldPolicy, ...] = get_args(HeldPolicy)
#: Duplicated stamps with different rows: an error, or keep the first or the last row.
DuplicatePolicy = Literal["error", "first", "last"]
DUPLICATE_POLICIES: tuple[DuplicatePolicy, ...] = get_args(DuplicatePolicy)

#: Relative spread of the intervals within which stamps count as exactly uniform (the same
#: as :data:`strapdown.algorithms.rate.UNIFORM_TOLERANCE`).
UNIFORM_TOLERANCE = 1e-6
#: Default largest stamp residual (99th percentile of |t − T(k)|, in periods) that is stamp
#: noise on a uniform clock: up to half a period a stamp still names its tick.
JITTER_TOLERANCE = 0.45
#: Largest fraction of samples that may collide on one tick (two stamps rounded to the same
#: tick) before the sampling counts as irregular.
COLLISION_LIMIT = 0.01
_ITERATIONS = 8
#: Longest gap (s) bridged by interpolating the sensors across it (the AHRS, ``nav --on-gap
#: report``): the error there grows with the motion the gap hides.
BRIDGE_MAX_S = 1.0


@dataclass(frozen=True)
class TimeBase:
    """Stamps as read: relative seconds and the origin that makes them absolute.

    ``t`` (s) is relative to the first stamp, computed in the file's own unit before
    scaling (exact for integer stamps); ``origin`` is the first stamp in seconds and
    ``origin_text`` the same exactly, as a decimal string (epoch stamps keep every digit);
    ``tick`` the stamps' resolution in seconds when they are integers (or decimals) of one.
    """

    t: NDArray[np.float64]
    origin: float = 0.0
    origin_text: str = "0"
    tick: float | None = None


def _decimals(x: NDArray[np.float64]) -> int | None:
    """Fewest decimals (0–9) that represent every value of ``x`` and keep every step
    (None: none do)."""
    dx = np.sign(np.diff(x))
    for m in range(10):
        s = x * 10.0**m
        if not np.all(np.abs(s) < 2**53):
            return None
        r = np.rint(s)
        if np.all(np.abs(s - r) <= np.maximum(1e-6, 1e-15 * np.abs(s))) and np.array_equal(
                np.sign(np.diff(r)), dx):
            return m
    return None


def relative_times(raw: NDArray[np.float64], scale: float) -> TimeBase:
    """A :class:`TimeBase` from stamps ``raw`` in a unit of ``scale`` seconds.

    Stamps that are integers (or decimals of at most 9 places) in their unit are made
    relative exactly — an integer difference — before scaling, and their resolution
    (the greatest common divisor of the intervals) is recorded as ``tick``.
    """
    raw = np.asarray(raw, dtype=np.float64)
    if raw.size == 0:
        return TimeBase(raw)
    m = _decimals(raw[: min(raw.size, 4096)]) if np.all(np.isfinite(raw)) else None
    if m is not None and _decimals(raw) == m:
        ints = np.rint(raw * 10.0**m).astype(np.int64)
        rel_i = ints - ints[0]
        d = np.diff(rel_i)
        g = int(np.gcd.reduce(d[d > 0])) if np.any(d > 0) else 0
        unit = scale / 10.0**m
        t = rel_i.astype(np.float64) * unit
        o = int(ints[0])
        sign = "-" if o < 0 else ""
        whole, frac = divmod(abs(o), 10**m)
        text = f"{sign}{whole}" + (f".{frac:0{m}d}".rstrip("0").rstrip(".") if m else "")
        if scale != 1.0:
            text = _scaled_text(text, scale)
        return TimeBase(t, float(raw[0]) * scale, text, g * unit if g else None)
    return TimeBase((raw - raw[0]) * scale, float(raw[0]) * scale, repr(float(raw[0]) * scale))


def _scaled_text(text: str, scale: float) -> str:
    """A decimal string times a power-of-ten ``scale`` (1e-3, 1e-6, 1e-9), exactly."""
    from decimal import Decimal

    e = round(math.log10(scale))
    if not math.isclose(10.0**e, scale):
        return repr(float(Decimal(text)) * scale)
    v = Decimal(text).scaleb(e)
    s = format(v, "f")
    return s.rstrip("0").rstrip(".") if "." in s else s


def format_times(base_origin_text: str, t: NDArray[np.float64], decimals: int = 9) -> list[str]:
    """Absolute times as decimal strings: the exact origin plus relative seconds ``t``,
    rounded to ``decimals`` places (trailing zeros dropped), with no binary rounding of
    the origin (``1733119200.123`` stays so)."""
    from decimal import Decimal

    origin = Decimal(base_origin_text)
    whole = int(origin.to_integral_value(rounding="ROUND_FLOOR"))
    frac = float(origin - whole)
    x = frac + np.asarray(t, dtype=np.float64)
    w = np.floor(x)
    f = np.rint((x - w) * 10**decimals).astype(np.int64)
    carry = f >= 10**decimals
    w = w + carry
    f = np.where(carry, f - 10**decimals, f)
    out = []
    for wi, fi in zip((w + whole).astype(np.int64).tolist(), f.tolist(), strict=True):
        s = f"{fi:0{decimals}d}".rstrip("0")
        out.append(f"{wi}.{s}" if s else f"{wi}")
    return out


@dataclass(frozen=True)
class RowCleaning:
    """What :func:`clean_rows` did.

    Attributes
    ----------
    keep : ndarray of int
        Indices of the rows kept, increasing.
    held : int
        Rows dropped as held samples (repeats of the previous sample at a later stamp).
    duplicates : int
        Rows dropped as duplicated stamps with an identical row.
    duplicates_resolved : int
        Duplicated stamps with different rows resolved by the policy (``first``/``last``).
    held_candidates : int
        Rows that repeat the previous sample at a later stamp (held or not).
    """

    keep: NDArray[np.int64]
    held: int = 0
    duplicates: int = 0
    duplicates_resolved: int = 0
    held_candidates: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"held_rows_collapsed": self.held, "held_candidates": self.held_candidates,
                "duplicated_rows_dropped": self.duplicates,
                "duplicated_stamps_resolved": self.duplicates_resolved}


def clean_rows(path: object, t: NDArray[np.float64], values: NDArray[np.float64], *,
               held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error",
               first_row: int = 1, jitter_tolerance: float = JITTER_TOLERANCE) -> RowCleaning:
    """Drop duplicated rows and collapse held samples (see the module docstring).

    ``t``: relative stamps (non-decreasing: a decreasing stamp is left to the caller's
    checks); ``values``: the sensor columns, ``(n, m)``. Rows in messages count from
    ``first_row`` (the first data row).

    Raises
    ------
    InputError
        A duplicated stamp with different rows under ``duplicates="error"``, naming both
        rows and the option that resolves it.
    """
    if held not in HELD_POLICIES:
        raise InputError(f"held must be one of {', '.join(HELD_POLICIES)}, got {held!r}")
    if duplicates not in DUPLICATE_POLICIES:
        raise InputError(f"duplicates must be one of {', '.join(DUPLICATE_POLICIES)}, got "
                         f"{duplicates!r}")
    n = t.shape[0]
    if n < 2:
        return RowCleaning(np.arange(n))
    same_t = np.diff(t) == 0
    same_v = np.all(values[1:] == values[:-1], axis=1)
    drop = np.zeros(n, bool)
    dup_identical = same_t & same_v
    drop[1:] |= dup_identical
    dup_diff = same_t & ~same_v
    resolved = 0
    if np.any(dup_diff):
        i = int(np.argmax(dup_diff))
        if duplicates == "error":
            raise InputError(
                f"{path}: duplicated time stamp in data rows {i + first_row} and "
                f"{i + 1 + first_row} (t = {float(t[i + 1])!r} s after the first stamp) with "
                f"different values ({int(dup_diff.sum())} such pair(s)); keep one of each "
                "with --duplicate-stamps first or --duplicate-stamps last")
        idx = np.flatnonzero(dup_diff)
        drop[idx + (1 if duplicates == "first" else 0)] = True
        resolved = int(idx.size)
    held_mask = np.zeros(n, bool)
    held_mask[1:] = same_v & ~same_t
    candidates = int(held_mask.sum())
    n_held = 0
    if candidates and held != "keep":
        collapse = held == "collapse" or _held_confirmed(t, drop, held_mask, jitter_tolerance)
        if collapse:
            drop |= held_mask
            n_held = candidates
    return RowCleaning(np.flatnonzero(~drop), n_held, int(dup_identical.sum()), resolved,
                       candidates)


def _held_confirmed(t: NDArray[np.float64], drop: NDArray[np.bool_],
                    held_mask: NDArray[np.bool_], tol: float) -> bool:
    """Whether the repeats are held samples: on the sensor clock fitted to the other rows,
    most repeats fall on a tick that a sample already holds (a logger faster than its
    sensor stamps the same sample again between two of its ticks). A quiet sensor's real
    repeats, or a block of identical rows at the start or the end of the log, each fall on
    a tick of their own: they are samples."""
    if held_mask.sum() == held_mask.size - 1:  # every row the same: a constant signal
        return False
    keep = ~(drop | held_mask)
    kept = t[keep]
    if kept.size < 8:
        return False
    try:
        clock = _fit(kept, None, tol, drift=False)
    except ValueError:
        return False
    with np.errstate(all="ignore"):
        k = np.rint((t[held_mask] - clock.offset) / clock.period)
    free = ~np.isin(k, clock.ticks.astype(np.float64))
    return int(free.sum()) < 0.5 * int(held_mask.sum())


@dataclass(frozen=True)
class SampleClock:
    """The sensor's clock fitted to a recording's stamps (:func:`fit_clock`).

    Attributes
    ----------
    ticks : ndarray of int (n,)
        Tick of each sample, the first 0, strictly increasing.
    period : float
        The clock's period (s).
    offset : float
        Time of tick 0 (s, relative to the first stamp).
    kind : ClockKind
        The classification (module docstring).
    residual_rms, residual_max, residual_p99 : float
        Stamp residuals ``t − T(k)`` (s).
    drift : tuple of float
        Cubic drift coefficients (s) on the Legendre basis P2, P3 of the normalised tick
        (empty: none fitted).
    tick : float or None
        The stamps' resolution (s), when they have one.
    given_period : bool
        Whether the period was given (``--sample-rate-hz``) rather than fitted.
    collisions : int
        Samples moved to the next tick because two stamps rounded to one.
    """

    ticks: NDArray[np.int64]
    period: float
    offset: float
    kind: ClockKind
    residual_rms: float = 0.0
    residual_max: float = 0.0
    residual_p99: float = 0.0
    drift: tuple[float, ...] = ()
    tick: float | None = None
    given_period: bool = False
    collisions: int = 0
    _span: int = field(default=0, repr=False)

    @property
    def missing(self) -> int:
        """Samples missing on the clock (ticks without a sample)."""
        return int(self.ticks[-1] - self.ticks[0] + 1 - self.ticks.size) if self.ticks.size else 0

    def gap_rows(self) -> NDArray[np.int64]:
        """Indices ``i`` (0-based samples) preceded by missing ticks."""
        return np.flatnonzero(np.diff(self.ticks) > 1) + 1

    def gap_lengths(self) -> NDArray[np.int64]:
        """Missing ticks before each of :meth:`gap_rows`."""
        d = np.diff(self.ticks)
        return d[d > 1] - 1

    def longest_gap(self) -> tuple[int, int] | None:
        """``(sample index after it, missing ticks)`` of the longest gap; None without."""
        lengths = self.gap_lengths()
        if not lengths.size:
            return None
        i = int(np.argmax(lengths))
        return int(self.gap_rows()[i]), int(lengths[i])

    def bridge(self, *arrays: NDArray[np.float64] | None
               ) -> tuple[NDArray[np.int64], list[NDArray[np.float64] | None]]:
        """Every tick from the first sample's to the last's, and each ``(n, m)`` array (None
        stays None) on them: the recorded samples as they are, the missing ones linearly
        interpolated (without gaps, the arrays themselves)."""
        full = np.arange(int(self.ticks[-1]) + 1)
        if not self.missing:
            return full, list(arrays)
        return full, [None if x is None else np.column_stack(
            [np.interp(full, self.ticks, x[:, j]) for j in range(x.shape[1])])
            for x in arrays]

    def resample_grid(self, t: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        """``(grid, step)``: a uniform grid from ``t[0]`` to at most ``t[-1]`` to resample
        samples taken at the stamps ``t`` onto — the clock's period, or the median interval
        when the sampling is irregular."""
        step = self.period if self.kind != "irregular" else float(np.median(np.diff(t)))
        m = int(np.floor((t[-1] - t[0]) / step * (1 + 1e-12))) + 1
        return t[0] + np.arange(m) * step, step

    def times(self, ticks: NDArray[np.int64] | None = None) -> NDArray[np.float64]:
        """``T(k)`` (s, relative) at ``ticks`` (default: every sample's)."""
        k = self.ticks if ticks is None else np.asarray(ticks)
        return self.offset + self.period * k + _drift_value(self.drift, k, self._span)

    def uniform_times(self, ticks: NDArray[np.int64] | None = None) -> NDArray[np.float64]:
        """``c + p·k`` without the drift term: the uniform grid the algorithms run on."""
        k = self.ticks if ticks is None else np.asarray(ticks)
        return self.offset + self.period * k.astype(np.float64)

    def describe(self) -> str:
        """``clock 200.0 Hz fitted (stamp noise ±0.21 period, rms 0.12); 10 missing``."""
        p = self.period
        if self.kind == "irregular":
            return (f"irregular sampling: no uniform clock fits the stamps (median interval "
                    f"{_fmt_s(p)}, residuals ±{self.residual_p99 / p:.2g} period at the 99th "
                    "percentile)")
        text = f"clock {1 / p:.6g} Hz {'given' if self.given_period else 'fitted'}"
        what = {"uniform": "uniform stamps", "quantised": "stamps rounded to",
                "noise": "stamp noise", "drifting": "drifting clock, stamp noise",
                "irregular": "irregular sampling, stamps off a uniform clock by"}[self.kind]
        if self.kind == "uniform":
            text += f" ({what})"
        elif self.kind == "quantised" and self.tick:
            text += f" ({what} {_fmt_s(self.tick)}, ±{self.residual_max / p:.2g} period)"
        else:
            text += (f" ({what} ±{self.residual_max / p:.2g} period, "
                     f"rms {self.residual_rms / p:.2g})")
        if self.missing:
            text += (f"; {self.missing} missing sample(s) in {self.gap_rows().size} gap(s), "
                     f"longest {int(self.gap_lengths().max())}")
        return text

    def to_dict(self) -> dict[str, Any]:
        gaps = self.gap_rows()
        return {"kind": self.kind, "period_s": self.period, "rate_hz": 1.0 / self.period,
                "period_given": self.given_period, "offset_s": self.offset,
                "residual_rms_s": self.residual_rms, "residual_max_s": self.residual_max,
                "residual_p99_s": self.residual_p99,
                "residual_max_periods": self.residual_max / self.period,
                "stamp_tick_s": self.tick, "drift_s": list(self.drift),
                "collisions": self.collisions, "missing_samples": self.missing,
                "gaps": int(gaps.size),
                "longest_gap_samples": int(self.gap_lengths().max()) if gaps.size else 0}


def _fmt_s(x: float) -> str:
    for unit, f in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6), ("ns", 1e-9)):
        if x >= f * 0.999:
            return f"{x / f:.4g} {unit}"
    return f"{x:.3g} s"


def _legendre(k: NDArray[np.int64], span: int) -> NDArray[np.float64]:
    """P2, P3 of the normalised tick ``x = 2k/span − 1``, columns."""
    x = 2.0 * np.asarray(k, np.float64) / max(span, 1) - 1.0
    return np.column_stack([0.5 * (3 * x * x - 1), 0.5 * (5 * x**3 - 3 * x)])


def _drift_value(drift: tuple[float, ...], k: NDArray[np.int64], span: int):
    if not drift:
        return 0.0
    return _legendre(k, span) @ np.asarray(drift)


def _robust_period(d: NDArray[np.float64]) -> float:
    """The mean interval below 1.5 median intervals (gaps excluded, rounding averaged)."""
    med = float(np.median(d))
    ok = d[d <= 1.5 * med]
    return float(ok.mean()) if ok.size else med


def _line(k: NDArray[np.float64], t: NDArray[np.float64], period: float | None):
    """Least-squares ``t ≈ c + p k`` (``p`` fixed when given)."""
    if period is None:
        kc = k - k.mean()
        p = float(np.dot(kc, t - t.mean()) / np.dot(kc, kc))
    else:
        p = period
    return float(np.mean(t - p * k)), p


def _fit(t: NDArray[np.float64], period: float | None, tol: float, *, drift: bool
         ) -> SampleClock:
    """Ticks, period, offset and drift for relative stamps ``t`` (strictly increasing)."""
    with np.errstate(all="raise"):
        try:
            return _fit_iterations(t, period, drift)
        except FloatingPointError:
            raise ValueError("the stamps overflow the clock fit") from None


def _runs_ticks(t: NDArray[np.float64], d: NDArray[np.float64], p0: float,
                period: float | None) -> tuple[NDArray[np.int64], float]:
    """Ticks and period from runs of consecutive samples (intervals under 1.5 periods).

    Within a run each sample is one tick on; the period is the pooled least-squares slope
    of the runs (or ``period`` as given); each break between runs spans the whole number of
    periods between the runs' fitted lines (their means, not two noisy stamps).
    """
    n = t.size
    brk = np.flatnonzero(d > 1.5 * p0) + 1  # first sample of each run after the first
    starts = np.concatenate([[0], brk])
    lengths = np.diff(np.concatenate([starts, [n]]))
    run = np.repeat(np.arange(starts.size), lengths)
    m = np.arange(n) - starts[run]  # local index within the run
    mbar = np.bincount(run, m) / lengths
    tbar = np.bincount(run, t) / lengths
    if period is None:
        mc = m - mbar[run]
        den = float(np.dot(mc, mc))
        p = float(np.dot(mc, t - tbar[run]) / den) if den > 0 else p0
        if not p > 0:
            p = p0
    else:
        p = period
    alpha = tbar - p * mbar  # each run's fitted time of its first sample
    span = alpha[1:] - (alpha[:-1] + p * (lengths[:-1] - 1))
    dk = np.maximum(1, np.rint(span / p)).astype(np.int64)
    offsets = np.concatenate([[0], np.cumsum(lengths[:-1] - 1 + dk)])
    return (offsets[run] + m).astype(np.int64), p


def _fit_iterations(t: NDArray[np.float64], period: float | None, drift: bool
                    ) -> SampleClock:
    n = t.size
    d = np.diff(t)
    p0 = period if period is not None else _robust_period(d)
    if not p0 > 0:
        raise ValueError("no positive interval")
    k, p = _runs_ticks(t, d, p0, period)
    coef: tuple[float, ...] = ()
    c = 0.0
    collisions = 0
    for _ in range(_ITERATIONS):
        kf = k.astype(np.float64)
        c, p = _line(kf, t, period)
        span = int(k[-1])
        coef = ()
        if drift and period is None and n >= 64 and span > 0:
            r = t - (c + p * kf)
            basis = _legendre(k, span)
            sol, *_ = np.linalg.lstsq(basis, r - r.mean(), rcond=None)
            fitted = basis @ sol
            # a drift term is kept only when it explains a clear part of the residuals
            if np.std(r - fitted) < 0.8 * np.std(r) and np.ptp(fitted) > 0.05 * p:
                coef = (float(sol[0]), float(sol[1]))
                c += float(np.mean(r - fitted))
        model = c + p * kf + _drift_value(coef, k, span)
        k_new = k + np.rint((t - model) / p).astype(np.int64)
        k_new -= k_new[0]
        step = np.diff(k_new)
        collisions = int(np.sum(step < 1))
        if collisions or np.array_equal(k_new, k):
            # two stamps on one tick: the sampling is not on this clock (or a stamp is an
            # outlier); the ticks stay as they were and the residuals say how far off
            break
        k = k_new
    span = int(k[-1])
    resid = t - (c + p * k + _drift_value(coef, k, span))
    a = np.abs(resid)
    return SampleClock(k, p, c, "noise", float(np.sqrt(np.mean(resid**2))), float(a.max()),
                       float(np.percentile(a, 99)), coef, None, period is not None,
                       collisions, span)


def fit_clock(t: NDArray[np.float64], *, period: float | None = None,
              tick: float | None = None, jitter_tolerance: float = JITTER_TOLERANCE
              ) -> SampleClock:
    """Fit the sensor's clock to relative stamps ``t`` and classify them (module docstring).

    Parameters
    ----------
    t : ndarray (n,)
        Time stamps (s), relative to the first, strictly increasing (clean duplicates and
        held rows first: :func:`clean_rows`).
    period : float, optional
        The sensor's period when known (``1 / sample_rate_hz``); default fitted.
    tick : float, optional
        The stamps' resolution (s), from :func:`relative_times`.
    jitter_tolerance : float
        Largest stamp residual (99th percentile, in periods) that is noise on the clock.
    """
    if not 0 < jitter_tolerance < 0.5:
        raise InputError(f"the jitter tolerance is in periods and must lie in (0, 0.5), got "
                         f"{jitter_tolerance!r}")
    t = np.asarray(t, dtype=np.float64)
    n = t.size
    if n < 2:
        return SampleClock(np.arange(n), period or 1.0, 0.0, "uniform", given_period=bool(period))
    d = np.diff(t)
    if period is None:
        td = float((t[-1] - t[0]) / (n - 1))
        tol = UNIFORM_TOLERANCE * td
        if d.max() - td <= tol and td - d.min() <= tol:  # exactly uniform: O(n), no fit
            k = np.arange(n, dtype=np.int64)
            return SampleClock(k, td, 0.0, "uniform", _span=n - 1, tick=tick)
    try:
        clock = _fit(t, period, jitter_tolerance, drift=True)
    except ValueError as exc:
        raise InputError(f"no sample clock fits the time stamps ({exc})") from None
    p = clock.period
    if period is not None and clock.residual_p99 > jitter_tolerance * p:
        free = _fit(t, None, jitter_tolerance, drift=False)
        if free.residual_p99 <= jitter_tolerance * free.period:
            raise InputError(
                f"the time stamps are not at the given sample period {period:.9g} s "
                f"({1 / period:.9g} Hz): they stray up to {clock.residual_p99 / p:.3g} periods "
                f"from its clock, but lie on one of {1 / free.period:.9g} Hz; drop "
                "--sample-rate-hz or correct it")
    kind: ClockKind
    if clock.residual_max <= UNIFORM_TOLERANCE * p and not clock.collisions:
        kind = "uniform"
    elif clock.collisions > max(1, COLLISION_LIMIT * n) or \
            clock.residual_p99 > jitter_tolerance * p:
        kind = "irregular"
    elif tick is not None and tick < p and clock.residual_max <= 0.55 * tick \
            and not clock.drift:
        kind = "quantised"
    elif clock.drift:
        kind = "drifting"
    else:
        kind = "noise"
    return SampleClock(clock.ticks, p, clock.offset, kind, clock.residual_rms,
                       clock.residual_max, clock.residual_p99, clock.drift, tick,
                       period is not None, clock.collisions, clock._span)


@dataclass(frozen=True)
class Timing:
    """A recording's time base: the stamps as read, what was done to the rows, the fitted
    clock and how the commands take it (:func:`reconstruct`)."""

    base: TimeBase
    cleaning: RowCleaning
    clock: SampleClock | None
    mode: TimingMode = "auto"
    jitter_tolerance: float = JITTER_TOLERANCE

    @property
    def rows(self) -> NDArray[np.int64]:
        """The 1-based data rows of the samples kept."""
        return self.cleaning.keep + 1

    @property
    def on_clock(self) -> bool:
        """Whether the samples are taken to lie on the fitted clock: ``nominal``, or
        ``auto`` with stamps that are not irregular."""
        return self.clock is not None and (
            self.mode == "nominal" or (self.mode == "auto" and self.clock.kind != "irregular"))

    def sample_period(self, t_rel: NDArray[np.float64]) -> float:
        """The samples' period: the clock's when they lie on it, else the median interval
        of their stamps ``t_rel``."""
        if self.clock is not None and self.on_clock:
            return self.clock.period
        return float(np.median(np.diff(t_rel)))

    def gap_rows(self, t_rel: NDArray[np.float64], period: float,
                 gap_tolerance: float) -> list[int]:
        """Data rows (1-based) that follow a gap: missing ticks on the clock when the samples
        lie on it, else an interval of the stamps ``t_rel`` over ``gap_tolerance``
        periods."""
        if self.clock is not None and self.on_clock:
            return [int(self.rows[i]) for i in self.clock.gap_rows()]
        d = np.diff(t_rel)
        return [int(self.rows[i + 1]) for i in np.flatnonzero(d > gap_tolerance * period)]

    def describe(self) -> str:
        """One line: the clock and what was done to the rows."""
        parts = [self.clock.describe() if self.clock is not None else "times from the rate"]
        c = self.cleaning
        if c.held:
            parts.append(f"{c.held} held row(s) collapsed")
        elif c.held_candidates:
            parts.append(f"{c.held_candidates} repeated row(s) kept as samples")
        if c.duplicates:
            parts.append(f"{c.duplicates} duplicated row(s) dropped")
        if c.duplicates_resolved:
            parts.append(f"{c.duplicates_resolved} duplicated stamp(s) resolved")
        if self.mode != "auto":
            parts.append(f"timing {self.mode}")
        elif self.clock is not None and self.clock.kind == "irregular":
            parts.append("resampled onto the uniform grid")
        return "; ".join(parts)

    def to_dict(self) -> dict[str, Any]:
        return {"mode": self.mode, "jitter_tolerance_periods": self.jitter_tolerance,
                "time_origin": self.base.origin_text, "stamp_tick_s": self.base.tick,
                "clock": None if self.clock is None else self.clock.to_dict(),
                **self.cleaning.to_dict(), "summary": self.describe()}


def reconstruct(path: object, base: TimeBase, values: NDArray[np.float64], *,
                period: float | None = None, mode: TimingMode = "auto",
                held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error",
                jitter_tolerance: float = JITTER_TOLERANCE, fit: bool = True) -> Timing:
    """Clean the rows and fit the sensor's clock (:func:`clean_rows`, :func:`fit_clock`).

    ``values``: the sensor columns of every row (all finite). ``mode="stamps"`` keeps every
    row as read but identical duplicates (the stamps are the sample times). ``fit`` False:
    the times come from a stated rate (no clock to fit).

    Raises
    ------
    InputError
        A stamp earlier than its predecessor (naming the row), a duplicated stamp with
        different values (:func:`clean_rows`), a bad option.
    """
    if mode not in TIMING_MODES:
        raise InputError(f"timing must be one of {', '.join(TIMING_MODES)}, got {mode!r}")
    if not 0 < jitter_tolerance < 0.5:
        raise InputError(f"the jitter tolerance is in periods and must lie in (0, 0.5), got "
                         f"{jitter_tolerance!r}")
    t = base.t
    d = np.diff(t)
    if d.size and d.min() < 0:
        i = int(np.argmax(d < 0))
        raise InputError(f"{path}: non-monotonic time stamp in data row {i + 2} (earlier than "
                         f"row {i + 1} by {float(-d[i]):.6g} s); sort the rows by time")
    cleaning = clean_rows(path, t, values, held="keep" if mode == "stamps" else held,
                          duplicates=duplicates, jitter_tolerance=jitter_tolerance)
    if not fit:
        return Timing(base, cleaning, None, mode, jitter_tolerance)
    tk = t[cleaning.keep]
    clock = fit_clock(tk, period=period, tick=base.tick, jitter_tolerance=jitter_tolerance)
    return Timing(base, cleaning, clock, mode, jitter_tolerance)


def uniform_timing_record(period: float, origin_text: str) -> dict[str, Any]:
    """:meth:`Timing.to_dict` of stamps found exactly uniform in a streamed pass (no row
    dropped, no clock residual beyond :data:`UNIFORM_TOLERANCE`), without holding the ticks."""
    clock = {"kind": "uniform", "period_s": period, "rate_hz": 1.0 / period,
             "period_given": False, "offset_s": 0.0, "residual_rms_s": 0.0,
             "residual_max_s": 0.0, "residual_p99_s": 0.0, "residual_max_periods": 0.0,
             "stamp_tick_s": None, "drift_s": [], "collisions": 0, "missing_samples": 0,
             "gaps": 0, "longest_gap_samples": 0}
    summary = f"clock {1 / period:.6g} Hz fitted (uniform stamps)"
    return {"mode": "auto", "jitter_tolerance_periods": JITTER_TOLERANCE,
            "time_origin": origin_text, "stamp_tick_s": None, "clock": clock,
            **RowCleaning(np.zeros(0, np.int64)).to_dict(), "summary": summary}
