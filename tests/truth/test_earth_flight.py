"""Earth-referenced trajectories: a vehicle at rest senses Earth rate and normal gravity
exactly; a flight's increments agree with the truth's own attitude and velocity."""

from __future__ import annotations

import numpy as np
import pytest

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment


def test_static_vehicle_senses_earth_rate_and_gravity():
    fl = EarthFlight([EarthSegment(10.0)], lat_deg=30.0, height=500.0, heading_deg=40.0)
    g, a = fl.increments(np.linspace(0.0, 10.0, 11))
    c_nb = dcm_from_quat(fl.state(np.array([0.0])).q[0])
    lat = np.radians(30.0)
    assert np.allclose(g, c_nb.T @ earth.earth_rate(lat), rtol=1e-14, atol=0)
    assert np.allclose(a, c_nb.T @ [0.0, 0.0, -earth.gravity(lat, 500.0)], rtol=1e-14, atol=0)


def test_flight_velocity_and_position_are_consistent():
    fl = EarthFlight([EarthSegment(20.0), EarthSegment(20.0, 3.0, 5.0)], lat_deg=45.0,
                     speed=100.0, ramp=5.0)
    t = np.linspace(0.0, 40.0, 81)
    s = fl.state(t)
    rn, _re = earth.radii(s.lat, s.height)
    # latitude rate = v_N / (R_N + h) (central differences of the integrated position)
    dlat = np.gradient(s.lat, t, edge_order=2)
    assert np.allclose(dlat[2:-2], (s.velocity[:, 0] / rn)[2:-2], rtol=1e-4)
    # the climb leg reaches 5° flight-path angle: v_D = −V sin 5°
    assert np.isclose(s.velocity[-1, 2], -100.0 * np.sin(np.radians(5.0)), rtol=1e-12)


def test_equal_flights_share_one_integration_and_others_do_not():
    from strapdown.truth.trajectory import EarthFlight, EarthSegment

    legs = [EarthSegment(20.0), EarthSegment(20.0, 3.0)]
    a = EarthFlight(legs, lat_deg=30.0, speed=50.0)
    t = np.linspace(0.0, 40.0, 7)
    pa = a.state(t)
    b = EarthFlight(list(legs), lat_deg=30.0, speed=50.0)
    b.state(t)
    assert b._sol is a._sol  # taken from the cache, not integrated again
    c = EarthFlight(legs, lat_deg=30.0, speed=50.0, height=10.0)
    pc = c.state(t)
    assert c._sol is not a._sol
    assert np.array_equal(b.state(t).lat, pa.lat) and not np.array_equal(pc.height, pa.height)


def _quadrature_and_ode(fl, t):
    from strapdown.truth.trajectory import _OdeDisplacement

    return fl._solve().displacement(t), _OdeDisplacement(fl).displacement(t)


def test_position_quadrature_equals_the_ode_integration():
    """The spectral quadrature of the closed-form velocity against the DOP853 integration
    at rtol 1e-13 it replaced, to 1e-12 of the displacement: a smooth-ramp turn-and-climb
    (the ODE is slow on the degree-17 ramp: 1.5 s of flight), and 40 s of the cosine ramp
    with turns of 400 °/s that make the pieces halve, south of the equator, heading
    south-west, near the antimeridian, climbing and descending."""
    cases = [
        EarthFlight([EarthSegment(0.5), EarthSegment(1.0, 6.0, 8.0)], lat_deg=50.0,
                    speed=120.0, ramp=0.5),
        EarthFlight([EarthSegment(3.0), EarthSegment(12.0, 400.0, 20.0),
                     EarthSegment(5.0, -60.0, -10.0), EarthSegment(20.0, 3.0)],
                    lat_deg=-35.0, lon_deg=179.9, height=3000.0, heading_deg=200.0,
                    speed=300.0, ramp=2.0, ramp_shape="cosine"),
    ]
    assert np.diff(cases[1]._solve().edges).max() < 4.0  # halved
    for fl in cases:
        t = np.concatenate([np.linspace(0.0, fl.duration, 997), fl._knots()])
        new, old = _quadrature_and_ode(fl, t)
        scale = np.max(np.abs(old), axis=1, keepdims=True)
        assert np.all(scale > 0)
        assert np.all(np.abs(new - old) <= 1e-12 * scale), np.max(np.abs(new - old) / scale,
                                                                  axis=1)
        s = fl.state(t)
        assert np.array_equal(s.lat, fl.lat0 + new[0]) and np.array_equal(s.height,
                                                                          fl.h0 + new[2])


def test_height_is_the_quadrature_of_the_vertical_velocity():
    """Independent of both integrators: Δh(t) = −∫ v_D by adaptive Gauss–Kronrod."""
    from scipy.integrate import quad

    fl = EarthFlight([EarthSegment(20.0), EarthSegment(60.0, 3.0, 5.0),
                      EarthSegment(40.0, -2.0, -4.0)], lat_deg=45.0, height=1000.0,
                     speed=100.0)
    t = np.array([0.0, 3.0, 20.0, 27.5, 80.0, 81.0, 119.0, 120.0])
    dh = fl.state(t).height - 1000.0
    for ti, got in zip(t, dh, strict=True):
        knots = [k for k in fl._knots() if 0.0 < k < ti]
        want, _ = quad(lambda s: -fl._velocity(np.array([s]))[0][0, 2], 0.0, ti,
                       points=knots or None, epsabs=1e-11, epsrel=1e-13, limit=400)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-9)


def test_position_of_a_static_vehicle_is_its_start():
    fl = EarthFlight([EarthSegment(7200.0)], lat_deg=45.0, lon_deg=10.0, height=100.0)
    s = fl.state(np.linspace(0.0, 7200.0, 101))
    assert np.all(s.lat == fl.lat0) and np.all(s.lon == fl.lon0) and np.all(s.height == 100.0)
