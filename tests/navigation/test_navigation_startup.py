"""The navigation update at full order from its first update on: a manoeuvre that accelerates
from the navigation's start, exact increments, 100 and 200 Hz.

The flight (:class:`strapdown.truth.trajectory.EarthFlight`, navigated from 10 s into it):
250 m/s in a 4 °/s climbing turn (5°) at the start — 17.5 m/s² of lateral acceleration, the
transport rate turning at |ω̇_en| ≈ 2.7e-6 rad/s² — and, 6 s later, a 4 s ramp into a level
3 °/s turn; 40 s. Before the fix, the first update integrated the navigation-frame rotation
ζ by a rectangle rule (the rates at its start only), a one-off ½ T² |ω̇_in| tilt, and the
velocity update counted the body's rotation twice in its frame-rotation terms and left out
the change of ω_in: conventional N = 2 reached ratios 4.0, 3.8, 3.7, 3.4 in attitude,
velocity, horizontal position and height; now 15.9, 8.1, 8.5, 8.0.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from strapdown.navigation import navigate
from strapdown.rotation.error import attitude_error_angle
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment

START = 10.0  # s into the flight: in the climbing turn
DURATION = 40.0
FLIGHT = EarthFlight([EarthSegment(4.0), EarthSegment(12.0, 4.0, 5.0),
                      EarthSegment(40.0, 3.0, 0.0)], lat_deg=45.0, lon_deg=7.0, height=3000.0,
                     speed=250.0, ramp=4.0)


@functools.cache
def _navigate(rate: float, n: int = 2, structure: str = "conventional"):
    """Navigation from ``START`` on exact increments, and the truth at its rows."""
    h = 1.0 / rate
    k = round(DURATION / h)
    k -= k % n if structure == "conventional" else 0  # whole updates: nothing to drop
    g, a = FLIGHT.increments(START + np.arange(k + 1) * h)
    s0 = FLIGHT.state(np.array([START]))
    sol = navigate(g, a, n, h=h, lat=s0.lat[0], lon=s0.lon[0], height=s0.height[0],
                   v0=s0.velocity[0], q0=s0.q[0], structure=structure, t0=START,
                   trailing="error")
    return sol, FLIGHT.state(sol.t)


@functools.cache
def _errors(rate: float, n: int = 2, structure: str = "conventional") -> np.ndarray:
    """Largest attitude (rad), velocity (m/s), horizontal and height (m) errors."""
    sol, tr = _navigate(rate, n, structure)
    rn, re = earth.radii(tr.lat, tr.height)
    horizontal = np.hypot((sol.lat - tr.lat) * rn, (sol.lon - tr.lon) * re * np.cos(tr.lat))
    return np.array([attitude_error_angle(sol.q, tr.q).max(),
                     np.linalg.norm(sol.v - tr.velocity, axis=1).max(), horizontal.max(),
                     np.abs(sol.height - tr.height).max()])


def test_the_flight_accelerates_from_the_start():
    # the case the test is about: the transport rate changes from the first update on
    t = START + np.array([0.0, 0.5])
    s = FLIGHT.state(t)
    w_en = earth.transport_rate(s.lat, s.height, s.velocity)
    assert np.linalg.norm(w_en[1] - w_en[0]) / 0.5 > 2e-6  # rad/s²
    assert np.linalg.norm(s.velocity[1] - s.velocity[0]) / 0.5 > 15.0  # m/s²


def test_conventional_two_converges_at_third_order_from_the_start():
    low, high = _errors(100.0), _errors(200.0)
    ratios = low / high
    print("errors 100 Hz", low, "200 Hz", high, "ratios", ratios)
    assert np.all(ratios >= 7.0), ratios
    # above rounding (the attitude floor of a 40 s run is ~1e-14 rad)
    assert high[0] > 1e-13 and high[1] > 1e-9


def test_first_update_attitude_error_is_third_order():
    # the start-up's error alone: after 0.02 s, one update at 100 Hz, two at 200 Hz; the
    # rectangle rule's ½ T² |ω̇_in| (7.6e-10 rad at 100 Hz, now 1.3e-13) shrank by 4 per
    # halving
    errs = []
    for rate in (100.0, 200.0):
        sol, tr = _navigate(rate)
        i = int(np.argmin(np.abs(sol.t - (START + 0.02))))
        errs.append(attitude_error_angle(sol.q[i], tr.q[i]))
    assert errs[0] < 1e-12, errs
    assert errs[0] / errs[1] >= 7.0, errs


@pytest.mark.parametrize(("n", "structure"), [(3, "conventional"), (2, "single-chain")])
def test_other_structures_hold_their_order_in_attitude_and_velocity(n, structure):
    ratios = _errors(100.0, n, structure) / _errors(200.0, n, structure)
    assert np.all(ratios[:2] >= 7.0), ratios
