"""Figures that inform: what the compare, advise and high-order figures draw (issue 28)."""

from __future__ import annotations

import math

import numpy as np
import pytest

SPECS = ["rk4", "rate-single", "rate-two", "rate-three"]


@pytest.fixture(scope="module")
def coning_log(tmp_path_factory):
    """A 30 s, 1 kHz rate log of 15 Hz coning (450 cone periods) and its exact truth."""
    from strapdown.truth.motions import SpinConing

    d = tmp_path_factory.mktemp("cone")
    m = SpinConing(half_angle=math.radians(2.0), cone_rate=2 * math.pi * 15,
                   spin_rate=math.radians(100))
    t = np.arange(30001) / 1000.0
    np.savetxt(d / "cone.csv", np.column_stack([t, m.rate(t)]), delimiter=",", fmt="%.17g",
               header="t,gx[rad/s],gy[rad/s],gz[rad/s]", comments="")
    np.savetxt(d / "truth.csv", np.column_stack([t, m.attitude(t)]), delimiter=",",
               fmt="%.17g", header="t,qw,qx,qy,qz", comments="")
    return d


def _capture(monkeypatch):
    from strapdown.io.report import ReportWriter

    seen = {}
    original = ReportWriter.figure

    def capture(self, name, fig):
        ax = fig.axes[0]
        seen["lines"] = [ln for ln in ax.lines if len(ln.get_xdata())]
        seen["bands"] = list(ax.collections)
        seen["legend"] = [x.get_text() for x in ax.get_legend().get_texts()]
        return original(self, name, fig)

    monkeypatch.setattr(ReportWriter, "figure", capture)
    return seen


@pytest.mark.parametrize("truth", [True, False])
def test_compare_figure_decimates_long_periodic_log_and_shows_every_algorithm(
        coning_log, tmp_path, monkeypatch, truth):
    """On 450 cone periods every plotted series has at most a few thousand points (an
    envelope per pixel-sized bin and a trend line), every algorithm has its own visible
    line (distinct colour and style), and a line lying under another says so."""
    from strapdown.apps.compare import compare_log

    seen = _capture(monkeypatch)
    compare_log(coning_log / "cone.csv", SPECS, tmp_path / "o", kind="rate", units=None,
                truth=coning_log / "truth.csv" if truth else None)
    lines, legend = seen["lines"], seen["legend"]
    assert len(legend) == len(SPECS)
    for spec, text in zip(SPECS, legend, strict=True):
        assert text.startswith(spec)
    drawn = [t for t in legend if "not drawn" not in t]
    assert len(lines) == len(drawn) == (4 if truth else 3)
    assert all(len(ln.get_xdata()) <= 2000 for ln in lines)
    assert all(len(b.get_paths()[0].vertices) <= 4000 for b in seen["bands"])
    assert all("mean over" in t for t in drawn)  # the trend is the line
    styles = {(ln.get_color(), str(ln.get_linestyle())) for ln in lines}
    assert len(styles) == len(lines) and len({ln.get_linestyle() for ln in lines}) == len(lines)
    if not truth:  # every difference is the reference's own error: the lines coincide
        assert "under" in drawn[0] and "drawn on top" in drawn[0]
