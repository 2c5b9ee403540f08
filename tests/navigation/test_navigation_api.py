"""The public navigation API's options: the gravity model (WGS-84's second-order height
correction or the linear one), a trailing partial update (dropped with a warning, or
refused), the stamp conventions of the solution's rows."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import strapdown
from strapdown._core.errors import InputError
from strapdown.navigation import NavStream, TrailingSamplesWarning, _kernels, navigate
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment


@pytest.mark.parametrize(("quad", "model"), [(1.0, "wgs84"), (0.0, "linear")])
def test_kernel_gravity_is_the_earth_models(quad, model):
    out = np.empty(9)
    v = np.zeros(3)
    for hgt in (0.0, 1234.0, 1.0e4):
        _kernels._rates(0.7, hgt, v, out, quad)
        assert out[5] == pytest.approx(float(earth.gravity(0.7, hgt, model)), rel=1e-15)
    # the two differ by the second-order term only: 3 h²/a² γ0
    h = 1.0e4
    g0 = float(earth.gravity(0.7, 0.0))
    diff = float(earth.gravity(0.7, h) - earth.gravity(0.7, h, "linear"))
    assert diff == pytest.approx(3.0 * h * h / earth.A**2 * g0, rel=1e-9)
    with pytest.raises(ValueError, match="unknown gravity model 'egm'; choose one of wgs84"):
        earth.gravity(0.7, h, "egm")  # type: ignore[arg-type]


def test_linear_gravity_at_10_km_is_the_missing_term():
    # at rest at 10 km, ideal increments of the WGS-84 truth: navigated with the linear
    # correction, gravity is 3 h²/a² γ0 (7.2e-5 m/s²) short, so the vertical velocity error
    # grows as −Δγ t (the vertical channel's instability is 1e-8 of it after 10 s)
    fl = EarthFlight([EarthSegment(10.0)], lat_deg=40.0, height=1.0e4)
    h = 0.01
    g, a = fl.increments(np.arange(1001) * h)
    kw = {"h": h, "lat": fl.lat0, "lon": fl.lon0, "height": fl.h0, "q0": fl.state(
        np.array([0.0])).q[0]}
    wgs = navigate(g, a, 2, **kw)
    lin = navigate(g, a, 2, gravity="linear", **kw)
    dg = float(earth.gravity(fl.lat0, 1.0e4) - earth.gravity(fl.lat0, 1.0e4, "linear"))
    assert np.max(np.abs(wgs.v)) < 1e-9
    assert lin.v[-1, 2] == pytest.approx(-dg * 10.0, rel=1e-3)
    stream = NavStream(2, gravity="linear", **kw)
    assert np.array_equal(stream.feed(g, a).v, lin.v[1:])
    with pytest.raises(ValueError, match="unknown gravity model"):
        navigate(g, a, 2, gravity="WGS84", **kw)  # type: ignore[arg-type]


def _log(k: int):
    rng = np.random.default_rng(3)
    g = 1e-3 * rng.normal(size=(k, 3))
    a = np.array([0.0, 0.0, -9.8 * 0.01]) + 1e-4 * rng.normal(size=(k, 3))
    return g, a, {"h": 0.01, "lat": 0.8, "lon": 0.1, "height": 100.0, "t0": 5.0}


def test_trailing_partial_update_dropped_with_a_warning_or_refused():
    g, a, kw = _log(11)  # N = 3: three whole updates and 2 increments left
    with pytest.warns(TrailingSamplesWarning, match=r"2 increment\(s\) after the last "
                      r"whole update of N = 3 \(0\.02 s"):
        sol = navigate(g, a, 3, **kw)
    assert sol.t.size == 4 and sol.t[-1] == pytest.approx(5.0 + 3 * 0.03)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        whole = navigate(g[:9], a[:9], 3, **kw)  # whole updates: no warning
        chain = navigate(g, a, 3, structure="single-chain", **kw)  # every sample
    assert chain.t.size == 12
    for name in ("t", "lat", "lon", "height", "v", "q"):
        assert np.array_equal(getattr(sol, name), getattr(whole, name))
    with pytest.raises(InputError, match=r"2 increment\(s\) .* not a whole update "
                       r"\(trailing='error'\)"):
        navigate(g, a, 3, trailing="error", **kw)
    with pytest.raises(ValueError, match="trailing must be one of drop, error"):
        navigate(g, a, 3, trailing="keep", **kw)  # type: ignore[arg-type]
    # fewer increments than one update: nothing to navigate, an error whatever the policy
    with pytest.raises(ValueError, match="N = 3 needs at least 3 samples, got 2"):
        navigate(g[:2], a[:2], 3, **kw)


def test_stream_pending_is_what_navigate_drops():
    g, a, kw = _log(11)
    stream = NavStream(3, **kw)
    stream.feed(g[:4], a[:4])
    assert stream.pending == 1
    stream.feed(g[4:], a[4:])
    assert stream.pending == 2
    assert NavStream(3, structure="single-chain", **kw).pending == 0


def test_rows_are_stamped_from_the_start_of_the_first_interval():
    # increments stamped at the ends of their intervals, t_i = 2.0 + i h (i = 1 … 8):
    # the initial state is at t_1 − h, update m at t0 + m N h
    g, a, kw = _log(8)
    stamps = 2.0 + np.arange(1, 9) * kw["h"]
    kw["t0"] = stamps[0] - kw["h"]
    sol = strapdown.navigate(g, a, 2, **kw)
    assert sol.t[0] == stamps[0] - kw["h"]
    assert np.allclose(sol.t, [2.0, *stamps[1::2]], rtol=0, atol=1e-14)
    assert sol.lat[0] == 0.8 and np.array_equal(sol.q[0], [1.0, 0.0, 0.0, 0.0])
    assert math.isclose(sol.update_period, 0.02)
