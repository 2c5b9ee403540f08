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


def _advice(measured: bool):
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.apps.advise import advise

    f = np.linspace(0.0, 100.0, 101)
    g = np.zeros((f.size, 3, 3), np.complex128)
    g[20, 1, 2], g[20, 2, 1] = 1e-4j, -1e-4j  # coning about x at 20 Hz
    specs = [AlgorithmSpec.parse(s) for s in ("rotvec:N=1", "rotvec:N=2", "rotvec:N=3",
                                              "rotvec:N=6")]
    meas = {"rotvec:N=6": 1e3}  # far above its prediction: a higher-order term

    def measure(spec):
        p = advise(f, g, 1e-3, [spec], lambda s, h: 1.0).candidates[0].predicted_drift_deg_h
        return meas.get(str(spec), p)

    return advise(f, g, 1e-3, specs, lambda s, h: 1e4 * s.subsamples, budget_deg_h=1e-6,
                  measure=measure if measured else None, segments=None)


def test_advise_figure_has_measured_points_budget_line_and_recommendation(tmp_path,
                                                                            monkeypatch):
    """advise.png draws the drift measured on the log beside the predicted, the budget line
    and the recommendation; a gap above 2× is explained in a sentence."""
    import matplotlib.pyplot as plt

    from strapdown.apps import advise as mod

    adv = _advice(True)
    seen = {}
    original = plt.close

    def capture(fig=None):
        ax = fig.axes[0]
        seen["legend"] = [x.get_text() for x in ax.get_legend().get_texts()]
        seen["hlines"] = [ln.get_ydata()[0] for ln in ax.lines
                          if len(set(ln.get_ydata())) == 1 and len(ln.get_xdata()) == 2
                          and ln.get_xdata()[0] == 0 and ln.get_xdata()[1] == 1]
        seen["texts"] = [t.get_text() for t in ax.texts]
        return original(fig)

    monkeypatch.setattr(plt, "close", capture)
    mod.write_figure(adv, tmp_path / "advise.png")
    assert (tmp_path / "advise.png").stat().st_size > 0
    assert seen["hlines"] == [1e-6]
    assert any(t.startswith("budget 1e-06 deg/h") for t in seen["legend"])
    assert any(t.startswith("measured") for t in seen["legend"])
    assert any(t.startswith(f"recommended: {adv.recommended.spec}") for t in seen["legend"])
    assert any(str(adv.recommended.spec) in t for t in seen["texts"])
    assert len(adv.gap_notes) == 1 and "rotvec:N=6 (" in adv.gap_notes[0]
    assert "third order in the amplitude" in adv.gap_notes[0]
    assert adv.to_dict()["gap_notes"] == list(adv.gap_notes)


def test_high_order_spin_figure_clips_points_far_below_the_rest(monkeypatch):
    """A drift of 1e-60 (exactly 0, left by the arithmetic) under values of 1e-24 … 1e-10
    is drawn at a floor with a note: the y-axis spans what matters, not 50 decades."""
    import types

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from strapdown.reproduce import high_order as ho

    labels = ["a", "b"]
    d = {}
    for case, _, _ in ho.SPIN_CASES:
        for k, lab in enumerate(labels):
            y = np.logspace(-24 + k, -10, len(ho.SPIN_RATIOS))
            y[list(ho.SPIN_RATIOS).index(1.0)] = 7.6e-61
            d[case, lab] = y
    seen = {}

    def figure(name, fig):
        seen["axes"] = [(ax.get_ylim(), [t.get_text() for t in ax.texts]) for ax in fig.axes]
        plt.close(fig)

    r = types.SimpleNamespace(plt=plt, figure=figure, add=lambda *a: None)
    ho._spin_figure(r, d, labels)
    for (lo, hi), texts in seen["axes"]:
        assert math.log10(hi / lo) < 20
        assert any("drawn at" in t and "8e-61" in t for t in texts)
