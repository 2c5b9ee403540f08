"""Earth-referenced trajectories: a vehicle at rest senses Earth rate and normal gravity
exactly; a flight's increments agree with the truth's own attitude and velocity."""

from __future__ import annotations

import numpy as np

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
