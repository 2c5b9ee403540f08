"""Velocity sets on a body coning in a constant specific force: the designer's laws measured
in arbitrary precision, the issue-26 case at rest in gravity in float64, and a short coned
flight (the full 10-minute one is ``strapdown reproduce sculling``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.velocity import (
    DEFAULT_VELOCITY_SET,
    body_increments,
    coning_force_law,
    sculling_matrix,
)
from strapdown.navigation import integrate_inertial, integrate_inertial_mp, navigate
from strapdown.truth.coning_force import ConedFlight, ConingInForce
from strapdown.truth.trajectory import EarthFlight, EarthSegment

G = 9.80665
CASES = [*(("conventional", "coning-force", n) for n in range(1, 7)),
         ("conventional", "classical", 3), ("conventional", "classical", 6),
         ("single-chain", "classical", 3)]


@pytest.mark.parametrize(("structure", "velocity_set", "n"), CASES)
def test_coning_force_law_in_arbitrary_precision(structure, velocity_set, n):
    # a = 1e-10 rad (the a⁴ terms 20 decades below), 120 samples per cone period, the rate
    # between whole periods 1 and 3, exact increments, 60 digits
    a, om, spp = 1e-10, 2 * math.pi, 120
    motion = ConingInForce(a, om, (G, 0.0, 0.0))
    sol = integrate_inertial_mp(motion, n, h=1 / spp, samples=3 * spp, digits=60,
                                structure=structure, velocity_set=velocity_set)
    i0, i1 = np.searchsorted(sol.t, 1.0 - 1e-9), len(sol.t) - 1
    rate = (sol.dv[i1] - sol.dv[i0]) / (sol.t[i1] - sol.t[i0])
    law = coning_force_law(n, structure, velocity_set).predict(a, G, om, 1 / spp)
    assert abs(rate[0] / law - 1) <= 0.015


def _rest_rates(ns, structure, velocity_set):
    """Issue 26's case: at rest in gravity, coning 2° at 5 Hz about the vertical, 100 Hz,
    exact increments; the rectified vertical velocity error rate (m/s²)."""
    m = ConingInForce(math.radians(2.0), 2 * math.pi * 5.0, (G, 0.0, 0.0))
    edges = np.arange(6001) * 0.01
    g, a = m.increments(edges), m.velocity_increments(edges)
    out = {}
    for n in ns:
        sol = integrate_inertial(g, a, n, h=0.01, q0=m.attitude(0.0), structure=structure,
                                 velocity_set=velocity_set)
        sel = sol.t > 0.2
        out[n] = np.polyfit(sol.t[sel], (sol.v - m.velocity(sol.t))[sel, 0], 1)[0]
    return out


def test_at_rest_in_gravity_the_new_sets_hold_and_the_classical_ones_do_not():
    new = _rest_rates(range(2, 7), "conventional", "coning-force")
    old = _rest_rates(range(2, 7), "conventional", "classical")
    chain = _rest_rates([3], "single-chain", "classical")
    assert new[2] == old[2]  # N = 2 has one set
    assert all(abs(old[n]) > 10 * abs(old[2]) for n in range(3, 7))  # the finding
    assert all(abs(new[n]) <= 0.2 * abs(new[2]) for n in range(3, 7))  # a⁴ floor at N ≥ 4
    assert abs(new[3]) < abs(chain[3])


def _coned_height_errors(segments, runs):
    """Largest height error (m) of each ``(n, structure, velocity_set)`` on a coned flight:
    2° coning at 5 Hz about body z on 100 m/s at 1000 m, 45° N, 100 Hz, exact increments."""
    fl = EarthFlight(segments, lat_deg=45.0, lon_deg=10.0, height=1000.0, speed=100.0)
    cf = ConedFlight(fl, half_angle=math.radians(2.0), cone_rate=2 * math.pi * 5.0)
    h = 0.01
    g, a = cf.increments(np.arange(round(fl.duration / h) + 1) * h)
    s0 = cf.state(np.array([0.0]))
    out = {}
    for n, structure, velocity_set in runs:
        sol = navigate(g, a, n, h=h, lat=s0.lat[0], lon=s0.lon[0], height=s0.height[0],
                       v0=s0.velocity[0], q0=s0.q[0], structure=structure,
                       velocity_set=velocity_set)
        truth = cf.state(np.minimum(sol.t, fl.duration)).height
        out[(n, structure, velocity_set)] = np.max(np.abs(sol.height - truth))
    return out


def test_a_coned_turn_holds_its_height():
    # 60 s level, then a 3 °/s coordinated turn for 120 s (the reproduction flies 10 minutes)
    runs = [(n, "conventional", DEFAULT_VELOCITY_SET) for n in range(2, 7)]
    e = _coned_height_errors([EarthSegment(60.0), EarthSegment(120.0, 3.0)],
                             [*runs, (3, "single-chain", "classical")])
    two = e[(2, "conventional", DEFAULT_VELOCITY_SET)]
    assert all(e[r] <= two for r in runs[1:])
    assert e[(3, "conventional", DEFAULT_VELOCITY_SET)] <= e[(3, "single-chain", "classical")]


def test_a_coned_level_flight_shows_the_classical_sets_failing():
    runs = [(n, "conventional", vs) for n in (2, 3, 6) for vs in ("classical", "coning-force")]
    e = _coned_height_errors([EarthSegment(180.0)], runs)
    two = e[(2, "conventional", "classical")]
    assert e[(3, "conventional", "classical")] > 10 * two
    assert e[(6, "conventional", "classical")] > 100 * two
    assert max(e[(n, "conventional", "coning-force")] for n in (3, 6)) < 0.2 * two


def test_velocity_sets_by_name():
    assert DEFAULT_VELOCITY_SET == "coning-force"
    # N = 2: one pair, the same matrix; N = 3: the classical set crosses with the last only
    assert np.array_equal(sculling_matrix(2), sculling_matrix(2, velocity_set="coning-force"))
    k = sculling_matrix(3, velocity_set="coning-force")
    assert k[0, 1] == 31 / 20 and k[0, 2] == 9 / 20 and k[1, 2] == -1 / 5
    assert sculling_matrix(3)[0, 1] == 0.0
    with pytest.raises(ValueError, match="unknown velocity set 'new'"):
        body_increments(np.zeros((3, 3)), np.zeros((3, 3)), 3, h=0.01,
                        velocity_set="new")  # type: ignore[arg-type]
