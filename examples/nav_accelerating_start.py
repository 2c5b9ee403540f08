"""Navigation that starts in a manoeuvre: the error order at 100 and 200 Hz.

A flight over the WGS-84 Earth (:class:`strapdown.truth.trajectory.EarthFlight`, exact
increments) navigated from 10 s into it: 250 m/s in a 4 °/s climbing turn (5°) at the
start — 17.5 m/s² of lateral acceleration, the transport rate turning from the first update
on — and, 6 s later, a 4 s ramp into a level 3 °/s turn; 40 s, conventional N = 2, through
the public :func:`strapdown.navigate`. The largest attitude, velocity, horizontal and height
errors are printed as JSON for 100 and 200 Hz with their ratios: 8 for the navigation's
third order, 16 where the error is of fourth order.

Run: ``python examples/nav_accelerating_start.py``.
"""

from __future__ import annotations

import json

import numpy as np

import strapdown
from strapdown.rotation.error import attitude_error_angle
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment

START, DURATION = 10.0, 40.0
flight = EarthFlight([EarthSegment(4.0), EarthSegment(12.0, 4.0, 5.0),
                      EarthSegment(40.0, 3.0, 0.0)], lat_deg=45.0, lon_deg=7.0,
                     height=3000.0, speed=250.0, ramp=4.0)
s0 = flight.state(np.array([START]))
keys = ("attitude_rad", "velocity_m_s", "horizontal_m", "height_m")
out: dict[str, dict[str, float]] = {}
for rate in (100, 200):
    h = 1.0 / rate
    gyro, accel = flight.increments(START + np.arange(round(DURATION * rate) + 1) * h)
    sol = strapdown.navigate(gyro, accel, 2, h=h, lat=s0.lat[0], lon=s0.lon[0],
                             height=s0.height[0], v0=s0.velocity[0], q0=s0.q[0], t0=START)
    truth = flight.state(sol.t)
    rn, re = earth.radii(truth.lat, truth.height)
    horizontal = np.hypot((sol.lat - truth.lat) * rn,
                          (sol.lon - truth.lon) * re * np.cos(truth.lat))
    errors = (attitude_error_angle(sol.q, truth.q).max(),
              np.linalg.norm(sol.v - truth.velocity, axis=1).max(), horizontal.max(),
              np.abs(sol.height - truth.height).max())
    out[f"{rate}_hz"] = {k: float(e) for k, e in zip(keys, errors, strict=True)}
out["ratios"] = {k: out["100_hz"][k] / out["200_hz"][k] for k in keys}
print(json.dumps(out, indent=2))
