"""Shared output for reproduction reports: tables as CSV + Markdown, figures as PNG, and
what drawing error histories needs (:class:`Curve`, :func:`running_envelope`,
:func:`log_ylim`; the drawing itself is ``plot_curves`` in ``strapdown.apps._figures``)."""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.io.files import csv_table, markdown_table, save_figure, write_text


def prepare_out(out: str | os.PathLike[str]) -> Path:
    """Create the output directory; refuse a path that is an existing file."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    return out


class ReportWriter:
    """Writes a report's tables and figures atomically and remembers their names."""

    def __init__(self, out: Path):
        self.out = out
        self.files: list[str] = []

    def table(self, stem: str, header: list[str], rows: list[list]) -> str:
        """Write ``stem.csv`` and ``stem.md``; return the Markdown."""
        write_text(self.out / f"{stem}.csv", csv_table(header, rows))
        md = markdown_table(header, rows)
        write_text(self.out / f"{stem}.md", md)
        self.files += [f"{stem}.csv", f"{stem}.md"]
        return md

    def figure(self, name: str, fig) -> str:
        """Save and close a matplotlib figure."""
        import matplotlib.pyplot as plt

        save_figure(fig, self.out / name, dpi=120, bbox_inches="tight")
        plt.close(fig)
        self.files.append(name)
        return name

    def file_list(self) -> list[str]:
        """Markdown links to every file written."""
        return [f"- [{f}]({f})" for f in self.files]


@dataclass
class Report:
    """One report being written: where it goes, what has been said, how to say more.

    Attributes
    ----------
    out : Path
        The output directory.
    writer : ReportWriter
        Writes the tables and figures and remembers their names.
    say : callable
        The progress callback (a no-op when none was given).
    plt : module
        ``matplotlib.pyplot`` on the headless Agg backend.
    t_start : float
        ``time.perf_counter()`` when the report began.
    parts : list of str
        The Markdown sections, in order; each reproduction joins them its own way.
    """

    out: Path
    writer: ReportWriter
    say: Callable[[str], None]
    plt: Any
    t_start: float
    parts: list[str] = field(default_factory=list)

    @classmethod
    def begin(cls, out: str | os.PathLike[str],
              progress: Callable[[str], None] | None = None) -> Report:
        """Start a report: headless matplotlib, the output directory, its writer."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        out = prepare_out(out)
        say = progress or (lambda _msg: None)
        return cls(out, ReportWriter(out), say, plt, time.perf_counter())

    def add(self, *texts: str) -> None:
        """Append Markdown parts."""
        self.parts.extend(texts)

    def table(self, stem: str, header: list[str], rows: list[list]) -> str:
        """Write ``stem.csv`` and ``stem.md`` (see :meth:`ReportWriter.table`)."""
        return self.writer.table(stem, header, rows)

    def figure(self, name: str, fig) -> str:
        """Save and close a figure (see :meth:`ReportWriter.figure`)."""
        return self.writer.figure(name, fig)

    def file_list(self) -> list[str]:
        """Markdown links to every file written so far."""
        return self.writer.file_list()

    def elapsed(self) -> float:
        """Seconds since the report began."""
        return time.perf_counter() - self.t_start

    def write(self, text: str) -> Path:
        """Write ``report.md`` (atomically); returns its path."""
        return write_text(self.out / "report.md", text)



# -- figures of error histories ---------------------------------------------------------------


def running_envelope(y: ArrayLike, period: int) -> tuple[NDArray[np.float64],
                                                          NDArray[np.float64]]:
    """Running minimum and maximum of ``y`` over centred windows of ``period`` points.

    The envelope of an N-periodic sawtooth (N interleaved chains, each smooth): over any
    ``period`` consecutive outputs every chain appears once, so the window's extremes are
    the lowest and the highest chain there. NaN points are ignored (a window of NaN only
    gives NaN). ``period`` 1 returns ``y`` twice.
    """
    y = np.asarray(y, dtype=np.float64)
    if not isinstance(period, (int, np.integer)) or period < 1:
        raise ValueError(f"period must be a positive integer, got {period!r}")
    if period == 1 or y.size == 0:
        return y.copy(), y.copy()
    lo_pad, hi_pad = (period - 1) // 2, period // 2
    padded = np.concatenate([np.full(lo_pad, np.nan), y, np.full(hi_pad, np.nan)])
    windows = np.lib.stride_tricks.sliding_window_view(padded, period)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN windows give NaN
        return np.nanmin(windows, axis=1), np.nanmax(windows, axis=1)


def log_ylim(arrays: Iterable[ArrayLike], *, percentile: float = 1.0
             ) -> tuple[float, float] | None:
    """Log-axis limits that show the curves, not their outliers.

    The lower limit is the ``percentile``-th percentile of all positive finite values
    (so a start-up point at 1e-24 under curves at 1e-9 does not stretch the axis over 15
    decades), divided by 2; the upper limit is the largest value times 2. None when no
    value is positive.
    """
    vals = [np.asarray(a, dtype=np.float64).ravel() for a in arrays]
    allv = np.concatenate(vals) if vals else np.empty(0)
    pos = allv[np.isfinite(allv) & (allv > 0)]
    if pos.size == 0:
        return None
    return float(np.percentile(pos, percentile)) / 2.0, float(pos.max()) * 2.0


@dataclass(frozen=True)
class Curve:
    """One error history to draw: ``y`` against ``t``, a sawtooth of ``period`` outputs.

    ``hidden``: a reason not to draw the curve (e.g. "the reference", "round-off only");
    it then appears in the legend only, with that reason.
    """

    t: NDArray[np.float64]
    y: NDArray[np.float64]
    label: str
    period: int = 1
    hidden: str = ""
