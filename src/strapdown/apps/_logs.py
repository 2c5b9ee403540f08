"""What the log commands (``run``, ``compare``, ``ahrs``) share: rate records per gap-free
segment with the jitter they showed, the unit-check policy, the check that a result is
finite, and an attitude file written together with its metadata sidecar.

The sidecar ``OUT.meta.json`` and ``OUT`` are both written to temporary names beside the
target; only when both are complete is a stale sidecar removed, ``OUT`` renamed into place
and then — last — the sidecar. A failure before that leaves neither (nor any temporary
file); an ``OUT`` without its sidecar can only be the trace of a run killed between the two
renames, and a sidecar always describes the ``OUT`` beside it.
"""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError
from strapdown.algorithms.rate import (
    UNIFORM_TOLERANCE,
    RateRecord,
    check_rate_record,
    resample_uniform,
)
from strapdown.io.files import atomic_path
from strapdown.io.readers import ImuLog, UnitAction
from strapdown.io.timing import Timing

__all__ = ["JitterSummary", "PairedOutput", "check_finite", "log_segments",
           "output_with_sidecar", "rate_records", "sidecar_path", "unit_action"]


def unit_action(accept_unit_warning: bool) -> UnitAction:
    """Magnitudes that suggest another unit than declared: an error unless accepted."""
    return "warn" if accept_unit_warning else "error"


@dataclass(frozen=True)
class JitterSummary:
    """The time base the rate algorithms ran on, over every segment."""

    period: float  # nominal sample period (s) of the longest segment
    jitter: float  # largest deviation of a stamp from its segment's grid, in periods
    resampled: bool
    segments: int
    timing: Timing | None = None

    def describe(self) -> str:
        """The clock and rows (:meth:`strapdown.io.timing.Timing.describe`), else
        ``nominal period 0.001 s (1000 Hz), jitter ±0.5 % of it`` (+ resampled)."""
        if self.timing is not None and self.timing.clock is not None:
            text = self.timing.describe()
            if self.resampled and "resampled" not in text:
                text += "; resampled onto the uniform grid"
            return text
        text = f"nominal period {self.period:.6g} s ({1 / self.period:.6g} Hz), "
        text += (f"jitter ±{100 * self.jitter:.2g} % of it" if self.jitter > UNIFORM_TOLERANCE
                 else "uniform time stamps")
        return text + (", resampled onto the uniform grid" if self.resampled else "")

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"sample_period_s": self.period, "jitter_periods": self.jitter,
               "resampled": self.resampled, "segments": self.segments}
        if self.timing is not None:
            out["timing"] = self.timing.to_dict()
        return out


def _gap_error(path: Path, log: ImuLog, remedy: str) -> InputError:
    """The refusal of a log with gaps, naming the first and what gets past it."""
    r = log.gaps[0]
    i = log.index_of_row(r)
    gap = float(log.t[i] - log.t[i - 1])
    on_clock = log.timing is not None and log.timing.on_clock
    what = (f"{log.timing.clock.missing} sample(s) missing on the fitted "
            f"{1 / log.h:.6g} Hz clock" if on_clock and log.timing and log.timing.clock
            else "interval(s) over the gap tolerance")
    return InputError(f"{path}: {len(log.gaps)} gap(s) ({what}), the first of {gap:.6g} s "
                      f"before data row {r}; {remedy}")


def rate_records(path: Path, log: ImuLog, *, split: bool, min_samples: int,
                 resample: bool) -> tuple[list[RateRecord], JitterSummary]:
    """The log's rates on a uniform grid, one record per gap-free segment (``split``) or
    one for the whole log, and their time base.

    How the stamps are taken is the log's :class:`~strapdown.io.timing.Timing` (``resample``
    forces ``resample``): on the fitted sensor clock (``auto`` unless the sampling is
    irregular, ``nominal``) the samples are taken at ``c + p·k`` of their ticks — the grid
    is uniform, and a gap is whole missing periods; ``stamps`` requires uniform stamps;
    ``resample`` (and ``auto`` on irregular sampling) interpolates the rates onto a uniform
    grid (:func:`strapdown.algorithms.rate.resample_uniform`, a cubic spline: its error is
    fourth order in the period). Gaps in an unsplit log are an error (rate algorithms
    cannot bridge one).
    """
    timing = log.timing
    mode = "resample" if resample else (timing.mode if timing is not None else "stamps")
    if log.gaps and not split:
        raise _gap_error(path, log, "rate algorithms cannot bridge a gap: pass --on-gap split "
                         "(each gap-free segment on its own, from the previous one's last "
                         "attitude)")
    cuts = log.segments() if split else [slice(0, log.t.size)]
    recs = []
    for k, c in enumerate(cuts):
        where = f" segment {k} (data rows {_row(log, c.start)}-{_row(log, c.stop - 1)})" \
            if split else ""
        try:
            recs.append(_record(log, c, mode, min_samples))
        except ValueError as exc:
            raise InputError(f"{path}:{where} {exc}") from None
    longest = max(recs, key=lambda r: r.t.size)
    return recs, JitterSummary(longest.td, max(r.jitter for r in recs),
                               any(r.resampled for r in recs), len(recs), timing)


def _row(log: ImuLog, i: int) -> int:
    return int(log.timing.rows[i]) if log.timing is not None else i + 1


def _record(log: ImuLog, c: slice, mode: str, min_samples: int) -> RateRecord:
    """One segment's :class:`RateRecord` under the timing ``mode`` (see rate_records)."""
    timing = log.timing
    t, w = log.t[c], log.data[c]
    clock = None if timing is None else timing.clock
    if timing is None or clock is None or mode == "stamps":
        if clock is not None and clock.kind != "uniform":
            raise ValueError(
                f"the time stamps are not uniform ({clock.describe()}); rate algorithms need "
                "uniform samples: --timing auto or nominal (the samples on the sensor's "
                "clock) or --timing resample (interpolated at the stamps)")
        return check_rate_record(t, w, min_samples=min_samples, td=log.nominal_period)
    if t.size < min_samples:
        raise ValueError(f"the record has {t.size} samples; this algorithm needs at least "
                         f"{min_samples}")
    base = float(log.t[0])
    if mode == "resample" or not timing.on_clock:
        grid, p = clock.resample_grid(t)
        if grid.size < min_samples:
            raise ValueError(f"the resampled record has {grid.size} samples; this algorithm "
                             f"needs at least {min_samples}")
        return RateRecord(grid, resample_uniform(t, w, grid), p, stamps=t, resampled=True,
                          measured_jitter=clock.residual_max / clock.period)
    ticks = clock.ticks[c]
    if clock.kind == "uniform" and log.nominal_period is None:
        return RateRecord(t, w, clock.period, measured_jitter=0.0)
    grid = base + (clock.uniform_times(ticks) - clock.uniform_times(clock.ticks[:1])[0])
    return RateRecord(grid, w, clock.period, stamps=t,
                      measured_jitter=clock.residual_max / clock.period)


def log_segments(path: Path, log: ImuLog, *, split: bool, min_samples: int,
                 resample: bool) -> tuple[list[ImuLog], JitterSummary | None]:
    """The log as the gap-free records the algorithms run on (one unless ``split``), each an
    :class:`~strapdown.io.ImuLog`: rate logs on their uniform grid (:func:`rate_records`),
    increment logs as read; with the rate logs' time base (None for increments)."""
    if log.kind == "rate":
        recs, base = rate_records(path, log, split=split, min_samples=min_samples,
                                  resample=resample)
        return [ImuLog(r.t, r.omega, "rate", r.td, units=log.units) for r in recs], base
    if resample:
        raise InputError("--resample applies to rate logs (--rates) only")
    cuts = log.segments() if split else [slice(0, log.t.size)]
    return [ImuLog(log.t[c], log.data[c], "increment", log.h, units=log.units)
            for c in cuts], None


def check_finite(what: str, t: NDArray[np.float64], *arrays: NDArray[np.float64]) -> None:
    """Raise when a result is NaN or infinite anywhere, naming the first row and time."""
    for a in arrays:
        bad = ~np.all(np.isfinite(a.reshape(a.shape[0], -1)), axis=1)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{what} is NaN or infinite from output row {i + 1} (t = "
                             f"{float(t[i]):.6g} s); nothing written")


def sidecar_path(out: Path) -> Path:
    """``OUT.meta.json`` beside ``OUT``."""
    return out.with_name(out.name + ".meta.json")


@dataclass
class PairedOutput:
    """Where to write the attitude (a temporary path) and the metadata to put beside it."""

    path: Path
    meta: dict[str, Any] = field(default_factory=dict)


def _strict_json(x: Any) -> Any:
    """``x`` with every non-finite float as the string ``"nan"``, ``"inf"`` or ``"-inf"``:
    JSON has no such numbers (Python's ``NaN``/``Infinity`` tokens are not JSON)."""
    if isinstance(x, float) and not math.isfinite(x):
        return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if isinstance(x, dict):
        return {k: _strict_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_strict_json(v) for v in x]
    return x


@contextlib.contextmanager
def output_with_sidecar(out: Path) -> Iterator[PairedOutput]:
    """Write ``out`` and ``OUT.meta.json`` together (see the module docstring).

    Yields a :class:`PairedOutput`: write the attitude to its ``path`` and fill its
    ``meta``; both land when the block ends without an exception, the sidecar last.
    """
    meta_path = sidecar_path(out)
    landed = False  # OUT renamed into place, its sidecar not yet
    try:
        with atomic_path(meta_path) as meta_tmp:
            with atomic_path(out) as tmp:
                paired = PairedOutput(Path(tmp))
                yield paired
                if not paired.meta:
                    raise RuntimeError("output_with_sidecar: no metadata was given")
                meta_tmp.write_text(json.dumps(_strict_json(paired.meta), indent=2,
                                               ensure_ascii=False, allow_nan=False)
                                    + "\n", encoding="utf-8")
                meta_path.unlink(missing_ok=True)  # no stale sidecar for the new OUT
            landed = True
    except BaseException:
        if landed:  # the sidecar's rename failed: an OUT without its metadata is not left
            out.unlink(missing_ok=True)
        raise
    # atomic_path(out) renamed the attitude first, atomic_path(meta_path) the sidecar last
