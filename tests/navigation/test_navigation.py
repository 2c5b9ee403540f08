"""WGS-84 navigation: static 2 h with ideal sensors, the Schuler oscillation of a north
accelerometer bias against its closed form, a 10-minute flight at 100 and 200 Hz."""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
import pytest

from strapdown.navigation import _kernels, navigate
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment

#: The flight tests share one flight's increments (``_flight``, an in-process cache): on one
#: worker they are computed once.
ONE_WORKER = True


def _run(flight, rate, n=1, structure="conventional", bias=None, increments=None):
    """Navigate ``flight``'s exact increments at ``rate``; the solution and its position
    and velocity errors. ``increments``: those increments, computed before."""
    h = 1.0 / rate
    if increments is None:
        edges = np.arange(round(flight.duration / h) + 1) * h
        increments = flight.increments(edges)
    g, a = increments
    if bias is not None:
        a = a + np.asarray(bias) * h
    s0 = flight.state(np.array([0.0]))
    sol = navigate(g, a, n, h=h, lat=flight.lat0, lon=flight.lon0, height=flight.h0,
                   q0=s0.q[0], v0=s0.velocity[0], structure=structure)
    tr = flight.state(sol.t)
    rn, re = earth.radii(tr.lat, tr.height)
    dp = np.stack([(sol.lat - tr.lat) * rn, (sol.lon - tr.lon) * re * np.cos(tr.lat),
                   tr.height - sol.height], axis=-1)
    return sol, dp, sol.v - tr.velocity


def test_kernel_rates_are_the_earth_model():
    assert (_kernels._A, _kernels._E2, _kernels._OMEGA, _kernels._GE,
            _kernels._GK, _kernels._GM_RATIO) == (earth.A, earth.E2, earth.OMEGA,
                                                          earth.GE, earth.GK, earth.GM_RATIO)
    out = np.empty(9)
    v = np.array([80.0, -60.0, 5.0])
    _kernels._rates(0.7, 1234.0, v, out, 1.0)
    wie = earth.earth_rate(0.7)
    win = wie + earth.transport_rate(0.7, 1234.0, v)
    rn, re = earth.radii(0.7, 1234.0)
    assert np.allclose(out[:3], win, rtol=1e-15, atol=1e-20)
    grav = np.array([0.0, 0.0, earth.gravity(0.7, 1234.0)]) - np.cross(wie + win, v)
    assert np.allclose(out[3:6], grav, rtol=1e-14, atol=1e-18)
    assert np.allclose(out[6:], [v[0] / rn, v[1] / (re * np.cos(0.7)), -v[2]], rtol=1e-15)
    # Somigliana: equator and pole values of WGS-84 normal gravity
    assert earth.gravity(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert earth.gravity(math.pi / 2) == pytest.approx(9.8321849378, abs=1e-9)


def _flight_inputs(fl: EarthFlight, structure: str, **extra):
    """600 steps of 10 ms of ``fl``: its increments, and :func:`navigate`'s keywords for
    starting from its initial state (plus ``extra``)."""
    h = 0.01
    g, a = fl.increments(np.arange(601) * h)
    s0 = fl.state(np.array([0.0]))
    kw = {"h": h, "lat": fl.lat0, "lon": fl.lon0, "height": fl.h0, "q0": s0.q[0],
          "v0": s0.velocity[0], "structure": structure, **extra}
    return g, a, kw


@pytest.mark.parametrize(("structure", "n"), [("conventional", 2), ("single-chain", 3)])
def test_kernel_equals_plain_twin(structure, n):
    from strapdown._core.backend import NUMPY
    from strapdown.algorithms.velocity import body_increments
    from strapdown.navigation import _reference as ref

    fl = EarthFlight([EarthSegment(2.0), EarthSegment(4.0, 6.0, 8.0)], lat_deg=50.0,
                     speed=120.0, ramp=3.0)
    g, a, kw = _flight_inputs(fl, structure)
    sol = navigate(g, a, n, **kw)
    b = body_increments(g, a, n, h=kw["h"], structure=structure)
    body = [(tuple(map(float, p)), tuple(map(float, d))) for p, d in zip(b.phi, b.dv,
                                                                       strict=True)]
    ps, vs, qs = ref.earth_nav(body, b.update_period, (fl.lat0, fl.lon0, fl.h0),
                               tuple(map(float, kw["v0"])), tuple(map(float, kw["q0"])),
                               NUMPY)
    assert np.allclose(np.array(ps)[:, :2], np.stack([sol.lat, sol.lon], 1), rtol=0,
                       atol=1e-15)
    assert np.allclose(np.array(ps)[:, 2], sol.height, rtol=0, atol=1e-9)
    assert np.allclose(np.array(vs), sol.v, rtol=0, atol=1e-11)
    assert np.allclose(np.array(qs), sol.q, rtol=0, atol=1e-14)


def test_static_two_hours_ideal_sensors_below_a_millimetre():
    sol, dp, dv = _run(EarthFlight([EarthSegment(7200.0)], lat_deg=45.0, lon_deg=10.0,
                                   height=100.0, heading_deg=30.0), 10.0)
    assert sol.t[-1] == pytest.approx(7200.0)
    assert np.max(np.abs(dp)) < 1e-3
    assert np.max(np.abs(dv)) < 1e-6


def test_schuler_oscillation_of_a_north_accelerometer_bias():
    # at the equator (no Foucault rotation of the oscillation), level, heading north
    b = 1e-4 * 9.80665
    sol, dp, dv = _run(EarthFlight([EarthSegment(7200.0)], lat_deg=0.0), 10.0,
                       bias=[b, 0.0, 0.0])
    rn, _ = earth.radii(0.0, 0.0)
    ws = math.sqrt(earth.gravity(0.0) / rn)
    vn = dv[:, 0]
    i = np.nonzero(np.sign(vn[1:]) != np.sign(vn[:-1]))[0]
    crossings = sol.t[i] - vn[i] * (sol.t[i + 1] - sol.t[i]) / (vn[i + 1] - vn[i])
    crossings = crossings[crossings > 100.0]
    period = 2 * np.mean(np.diff(crossings))
    assert abs(period / (2 * math.pi * math.sqrt(rn / earth.gravity(0.0))) - 1) < 0.005
    # closed form of the north channel: δp_N = (b/ω_s²)(1 − cos ω_s t)
    assert abs(dp[:, 0].max() / (2 * b / ws**2) - 1) < 0.01
    closed = b / ws**2 * (1 - np.cos(ws * sol.t))
    assert np.max(np.abs(dp[:, 0] - closed)) < 0.01 * 2 * b / ws**2


_FLIGHT = [EarthSegment(60), EarthSegment(120, 3.0), EarthSegment(60), EarthSegment(120, 0, 5.0),
           EarthSegment(120, -3.0, 5.0), EarthSegment(120)]


@functools.cache
def _flight(rate):
    """The 10-minute flight and its exact increments at ``rate`` (the same for every
    structure and N: computed once, the costly part of each test below)."""
    fl = EarthFlight(_FLIGHT, lat_deg=45.0, lon_deg=10.0, height=1000.0, speed=100.0)
    h = 1.0 / rate
    return fl, fl.increments(np.arange(round(fl.duration / h) + 1) * h)


@functools.cache
def _flight_errors(structure, n):
    """Largest horizontal, height and velocity errors at 100 and 200 Hz, and their ratios."""
    errs = []
    for rate in (100.0, 200.0):
        fl, increments = _flight(rate)
        _, dp, dv = _run(fl, rate, n, structure, increments=increments)
        errs.append((np.abs(dp[:, :2]).max(), np.abs(dp[:, 2]).max(), np.abs(dv).max()))
    return np.array(errs), np.array(errs[0]) / np.array(errs[1])


def test_flight_first_order_subsampling_is_second_order():
    # N = 1: no coning or sculling term, a local error O(T³) in attitude and velocity
    errs, ratios = _flight_errors("conventional", 1)
    assert np.all((ratios > 3.8) & (ratios < 4.2)), ratios
    assert errs[1][0] < 0.2


@pytest.mark.parametrize(("structure", "n"), [("conventional", 2), ("conventional", 3),
                                              ("conventional", 6), ("single-chain", 2),
                                              ("single-chain", 4)])
def test_flight_errors_shrink_at_third_order(structure, n):
    # N ≥ 2: velocity third order (the body update's ⅙ α × (α × υ) and the pair sculling
    # terms are exact for a constant rate and specific force only; for N ≥ 3 also the
    # Table 3 coning sets, not exact for a linearly varying rate); the Earth navigation is
    # of fourth order and the position follows the velocity
    errs, ratios = _flight_errors(structure, n)
    assert 6.0 < ratios[2] < 9.0, ratios
    assert np.all(ratios[:2] > 6.0), ratios
    assert errs[1][2] < 1e-5


def test_bad_initial_state():
    z = np.zeros((4, 3))
    with pytest.raises(ValueError, match="±90"):
        navigate(z, z, 1, h=0.1, lat=2.0, lon=0.0, height=0.0)
    with pytest.raises(ValueError, match="NaN"):
        navigate(z, z, 1, h=0.1, lat=0.1, lon=float("nan"), height=0.0)
    with pytest.raises(ValueError, match="NaN"):
        navigate(z, z, 1, h=0.1, lat=0.1, lon=0.0, height=0.0, v0=[0, np.inf, 0])
    with pytest.raises(ValueError, match="latitude"):
        EarthFlight([EarthSegment(1.0)], lat_deg=95.0)


@pytest.mark.parametrize(("structure", "n"), [("conventional", 1), ("conventional", 3),
                                              ("single-chain", 1), ("single-chain", 4)])
def test_stream_equals_navigate_bit_for_bit(structure, n):
    from strapdown.navigation import NavStream

    fl = EarthFlight([EarthSegment(3.0), EarthSegment(3.0, 5.0, 4.0)], lat_deg=40.0,
                     speed=90.0, ramp=2.0)
    g, a, kw = _flight_inputs(fl, structure, t0=2.5)
    sol = navigate(g, a, n, **kw)
    stream = NavStream(n, **kw)
    cuts = [0, 0, 1, 2, 3, 50, 51, 200, 333, 598, 600]  # chunks shorter than N, empty ones too
    parts = [stream.feed(g[i:j], a[i:j]) for i, j in itertools.pairwise(cuts)]
    for name in ("t", "lat", "lon", "height", "v", "q"):
        got = np.concatenate([getattr(p, name) for p in parts])
        assert np.array_equal(got, getattr(sol, name)[1:]), name
