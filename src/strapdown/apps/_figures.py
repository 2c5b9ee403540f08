"""Error histories drawn so that long periodic logs and overlapping algorithms stay readable.

A 30 s, 1 kHz log with 15 Hz coning has 450 cone periods: drawn point by point its error
curve fills the axes as a solid block and hides whatever was drawn before it. Here a
series longer than :data:`MAX_POINTS` is decimated to an envelope — its minimum and
maximum in each of :data:`BINS` time bins (about one pixel wide), drawn as a band — and
its trend, the mean over :data:`TREND_FRACTION` of the span, drawn as a line. Every
algorithm gets its own colour, line style and marker; lines are drawn thickest first, so a
curve that lies under a later one still shows around its dashes, and the legend says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from strapdown.io.report import Curve, log_ylim, running_envelope

__all__ = ["BINS", "MAX_POINTS", "TREND_FRACTION", "envelope", "plot_curves"]

#: Series with more points than this are decimated to an envelope.
MAX_POINTS = 5000
#: Time bins of the envelope (the axes are about 750 pixels wide at the figures' 120 dpi).
BINS = 800
#: The trend line of a decimated series: its mean over this fraction of the time span.
TREND_FRACTION = 0.02
#: Two lines closer than this in log10 over most of their common span coincide (about 5 %).
_COINCIDE_DEX = 0.02
_STYLES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1)), (0, (1, 2)))
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


@dataclass(frozen=True)
class Envelope:
    """A decimated series: bin centres ``t``, the bins' ``lo``/``hi`` and the ``trend``
    (the running mean over ``window`` seconds), NaN where a bin holds no positive value."""

    t: NDArray[np.float64]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    trend: NDArray[np.float64]
    window: float


def envelope(t: NDArray[np.float64], y: NDArray[np.float64], span: tuple[float, float],
             bins: int = BINS, trend_fraction: float = TREND_FRACTION) -> Envelope:
    """Min, max and running mean of the positive finite ``y`` in ``bins`` equal time bins
    over ``span`` (every curve of a figure uses the same bins)."""
    t0, t1 = span
    t = np.asarray(t, np.float64)
    y = np.asarray(y, np.float64)
    ok = np.isfinite(y) & (y > 0) & np.isfinite(t)
    t, y = t[ok], y[ok]
    width = (t1 - t0) / bins if t1 > t0 else 1.0
    k = np.clip(((t - t0) / width).astype(np.int64), 0, bins - 1)
    lo = np.full(bins, np.inf)
    hi = np.full(bins, -np.inf)
    np.minimum.at(lo, k, y)
    np.maximum.at(hi, k, y)
    count = np.bincount(k, minlength=bins).astype(np.float64)
    total = np.bincount(k, weights=y, minlength=bins)
    w = max(1, round(trend_fraction * bins))  # running mean over w bins, from the samples
    kernel = np.ones(w)
    n_run = np.convolve(count, kernel, mode="same")
    s_run = np.convolve(total, kernel, mode="same")
    empty = count == 0
    with np.errstate(invalid="ignore", divide="ignore"):
        trend = np.where(empty | (n_run == 0), np.nan, s_run / n_run)
    lo[empty] = np.nan
    hi[empty] = np.nan
    centres = (t0 + (np.arange(bins) + 0.5) * width).astype(np.float64)
    return Envelope(centres, lo, hi, trend, w * width)


def _coincides(ta, ya, tb, yb) -> bool:
    """Whether line ``a`` lies on line ``b`` (within :data:`_COINCIDE_DEX`) over at least
    half of ``a``'s points inside their common span."""
    ok_b = np.isfinite(yb) & (yb > 0)
    if np.count_nonzero(ok_b) < 2:
        return False
    tb, yb = tb[ok_b], yb[ok_b]
    sel = np.isfinite(ya) & (ya > 0) & (ta >= tb[0]) & (ta <= tb[-1])
    if np.count_nonzero(sel) < 2:
        return False
    near = np.abs(np.log10(ya[sel]) - np.log10(np.interp(ta[sel], tb, yb))) < _COINCIDE_DEX
    return bool(np.mean(near) >= 0.5)


def plot_curves(ax: Any, curves: Sequence[Curve], *, ylabel: str) -> list[str]:
    """Draw error histories on a log axis so that every algorithm stays visible; returns
    the legend texts (in the curves' order).

    A series longer than :data:`MAX_POINTS` is drawn as its :func:`envelope` (band) and
    trend (line); a shorter sawtooth (``period`` > 1: interleaved chains) as the band of
    its running min/max over a period with its max as a line; a shorter smooth series as
    a line. Lines get distinct colours, styles and markers, are drawn in the curves' order
    with the first thickest, and a line another lies on is named in the legend. Hidden
    curves and curves identically zero get a legend entry saying so.
    """
    spans = [(float(np.min(c.t)), float(np.max(c.t))) for c in curves
             if not c.hidden and np.asarray(c.t).size]
    span = (min(s[0] for s in spans), max(s[1] for s in spans)) if spans else (0.0, 1.0)
    handles: list[tuple[int, Any, str]] = []
    bands, lines, drawn = [], [], []
    for i, c in enumerate(curves):
        y = np.where(np.asarray(c.y) > 0, c.y, np.nan)
        if c.hidden or not np.any(np.isfinite(y)):
            handles.append((i, ax.plot([], [], ls="none", color="0.4")[0],
                            f"{c.label} ({c.hidden or 'identically zero'}, not drawn)"))
            continue
        t = np.asarray(c.t, np.float64)
        if y.size > MAX_POINTS:
            env = envelope(t, y, span)
            drawn += [env.lo, env.hi]
            bands.append((i, env.t, env.lo, env.hi))
            saw = (f", a sawtooth of period {c.period} (interleaved chains)" if c.period > 1
                   else "")
            what = (f"{c.label}: {y.size} outputs, range per {(span[1] - span[0]) / BINS:.2g}"
                    f" s (band), mean over {env.window:.2g} s (line){saw}")
            lines.append((i, env.t, env.trend, what))
        elif c.period > 1:
            lo, hi = running_envelope(y, c.period)
            drawn.append(c.y)
            bands.append((i, t, lo, hi))
            lines.append((i, t, hi, f"{c.label}: range over {c.period} outputs (band) and its "
                          f"max (line), a sawtooth of period {c.period} (interleaved chains)"))
        else:
            drawn.append(c.y)
            lines.append((i, t, y, c.label))
    color = {i: f"C{i % 10}" for i in range(len(curves))}
    widths = {i: float(np.nanmedian(np.log10(hi) - np.log10(lo))) for i, _, lo, hi in bands}
    for z, (i, t, lo, hi) in enumerate(sorted(bands, key=lambda b: -widths[b[0]])):
        ax.fill_between(t, lo, hi, color=color[i], alpha=0.18, lw=0, zorder=1 + z)
    band_of = {b[0] for b in bands}
    for k, (i, t, y, what) in enumerate(lines):
        under = [curves[lines[j][0]].label for j in range(k + 1, len(lines))
                 if _coincides(t, y, lines[j][1], lines[j][2])]
        if under:
            what += f"; under {', '.join(under)} (drawn on top, dashed)"
        every = max(1, y.size // 12)
        (line,) = ax.plot(t, y, color=color[i], lw=max(1.0, 2.8 - 0.5 * k),
                          ls=_STYLES[k % len(_STYLES)], marker=_MARKERS[k % len(_MARKERS)],
                          ms=4, markevery=(k * every // max(1, len(lines)), every),
                          zorder=20 + k)
        if i in band_of:
            import matplotlib.patches as mpatches

            patch = mpatches.Patch(color=color[i], alpha=0.18, lw=0)
            handles.append((i, (patch, line), what))
        else:
            handles.append((i, line, what))
    ax.set_yscale("log")
    lim = log_ylim(drawn)
    if lim is not None:
        ax.set_ylim(*lim)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    handles.sort(key=lambda h: h[0])  # the legend in the curves' order
    texts = [h[2] for h in handles]
    ax.legend([h[1] for h in handles], texts, fontsize=7, loc="upper center",
              bbox_to_anchor=(0.5, -0.13), ncol=1, frameon=False)
    return texts
