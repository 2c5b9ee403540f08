"""Figures of error histories: envelopes of sawtooth curves, y-limits, drawing order, legends."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from strapdown.apps._figures import plot_curves
from strapdown.io.report import Curve, log_ylim, running_envelope


def _sawtooth(n=300, period=3):
    """Three interleaved smooth chains at 1×, 10× and 100× a growing base."""
    t = np.arange(n) * 1e-3
    scale = np.array([1.0, 10.0, 100.0])[np.arange(n) % period]
    return t, 1e-10 * (1 + t) * scale


def test_running_envelope_of_a_sawtooth():
    t, y = _sawtooth()
    lo, hi = running_envelope(y, 3)
    inner = slice(1, -1)  # full windows
    base = 1e-10 * (1 + t)
    # over any three consecutive outputs the low chain (1×) and the high chain (100×) appear
    assert np.all(hi[inner] >= 100 * base[inner] * (1 - 2e-3))
    assert np.all(lo[inner] <= base[inner] * (1 + 2e-3))
    assert np.all(lo <= y) and np.all(hi >= y)
    lo1, hi1 = running_envelope(y, 1)
    assert np.array_equal(lo1, y) and np.array_equal(hi1, y)
    with pytest.raises(ValueError, match="positive integer"):
        running_envelope(y, 0)
    _, hi_nan = running_envelope(np.array([np.nan, 1.0, np.nan, np.nan, np.nan]), 3)
    assert hi_nan[1] == 1.0 and np.isnan(hi_nan[3])


def test_log_ylim_ignores_startup_outliers():
    y = np.concatenate([[1e-24], np.linspace(1e-9, 1e-8, 999)])
    lo, hi = log_ylim([y, np.zeros(3)])
    assert 1e-10 < lo < 1e-9 and hi == pytest.approx(2e-8)
    assert log_ylim([np.zeros(4)]) is None


def test_drawing_order_and_legend():
    t, saw = _sawtooth()
    smooth = 3e-10 * (1 + t)  # inside the sawtooth's band: must be drawn on top of it
    fig, ax = plt.subplots()
    plot_curves(ax, [Curve(t, saw, "sliding", 3), Curve(t, smooth, "rate-three"),
                           Curve(t, smooth, "rk4", hidden="the reference"),
                           Curve(t, np.zeros_like(t), "zero")], ylabel="difference (rad)")
    texts = [x.get_text() for x in ax.get_legend().get_texts()]
    assert texts[0].startswith("sliding: range over 3 outputs (band) and its max (line)")
    assert texts[1:] == ["rate-three", "rk4 (the reference, not drawn)",
                         "zero (identically zero, not drawn)"]
    band_z = max(c.get_zorder() for c in ax.collections)
    drawn = [ln for ln in ax.get_lines() if ln.get_xydata().size]
    line_z = {ln.get_zorder() for ln in drawn if np.allclose(ln.get_ydata(), smooth)}
    assert line_z and min(line_z) > band_z
    assert ax.get_ylabel() == "difference (rad)" and ax.get_yscale() == "log"
    plt.close(fig)


def test_wider_band_below_narrower():
    t, saw = _sawtooth()
    narrow = saw ** 0.5 * 1e-5  # the same sawtooth, half as many decades wide
    fig, ax = plt.subplots()
    plot_curves(ax, [Curve(t, narrow, "narrow", 3), Curve(t, saw, "wide", 3)],
                      ylabel="e")
    fills = ax.collections
    assert len(fills) == 2
    # the first band drawn is the wide one (its top is the wide curve's maximum), lowest
    assert fills[0].get_paths()[0].vertices[:, 1].max() == pytest.approx(saw.max(), rel=1e-9)
    assert fills[0].get_zorder() < fills[1].get_zorder()
    plt.close(fig)
