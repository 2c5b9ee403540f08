"""Vehicle trajectories and accelerometer/magnetometer models."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.rate import rate_attitude
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.error import attitude_error_angle
from strapdown.truth import sensors
from strapdown.truth.trajectory import (
    WANG_VARIANTS,
    CoordinatedFlight,
    EarthField,
    Segment,
    wang_circle,
)

G = 9.80665


@pytest.mark.parametrize("variant", WANG_VARIANTS)
def test_wang_circle_is_consistent(variant):
    f = wang_circle(variant)
    t = np.arange(0.0, 250.0 + 1e-9, 0.01)
    s = f.sample(t)
    # coordinated: no lateral specific force; f = C_b_n (a + g_up) to round-off
    assert np.abs(s.specific_force[:, 1]).max() < 1e-12
    fn = np.einsum("nij,nj->ni", dcm_from_quat(s.q), s.specific_force)
    assert np.allclose(fn, s.acceleration + np.array([0, 0, G]), atol=1e-12)
    # the attitude is the integral of the body rates (RK4, 2td = 20 ms, fourth order)
    sol = rate_attitude(t, s.omega, algorithm="rk4", q0=s.q[0])
    assert attitude_error_angle(sol.q, s.q[::2][: sol.q.shape[0]]).max() < 1e-9
    # velocity is the derivative of position (five-point stencil, error O(dt⁴) ~ 1e-8)
    p = s.position
    dv = (-p[4:] + 8 * p[3:-1] - 8 * p[1:-3] + p[:-4]) / (12 * 0.01)
    assert np.allclose(dv, s.velocity[2:-2], atol=1e-6)
    # the steady turn: radius and bank as the reading says
    steady = t > 70
    r = f.speed / np.abs(np.gradient(s.heading, t)[steady])
    bank = np.degrees(s.bank[steady])
    expect = {"speed-radius": (600.0, math.degrees(math.atan(400 / (600 * G)))),
              "speed-bank": (400 / (G * math.tan(math.radians(20))), 20.0),
              "radius-bank": (600.0, 20.0)}[variant]
    assert np.allclose(r, expect[0], rtol=1e-6)
    assert np.allclose(bank, expect[1], rtol=1e-12)
    assert s.heading[0] == 0.0 and np.allclose(s.position[:, 2], 200.0)


def test_flight_errors():
    with pytest.raises(ValueError, match="segment 1 is shorter than the roll time"):
        CoordinatedFlight([Segment(10.0), Segment(1.0, 30.0)], speed=20.0, roll_time=2.0)
    with pytest.raises(ValueError, match="bank must be within"):
        CoordinatedFlight([Segment(10.0, 90.0)], speed=20.0)
    with pytest.raises(ValueError, match="speed must be a finite positive number"):
        CoordinatedFlight([Segment(10.0)], speed=0.0)
    f = CoordinatedFlight([Segment(10.0)], speed=20.0)
    with pytest.raises(ValueError, match=r"within \[0, 10.0\]"):
        f.sample(np.array([11.0]))
    with pytest.raises(ValueError, match="variant must be one of"):
        wang_circle("radius-speed")


def test_earth_field():
    m = EarthField(50.0, 60.0, 10.0).magnetic_enu()
    assert np.linalg.norm(m) == pytest.approx(50.0)
    assert math.degrees(math.atan2(-m[2], math.hypot(m[0], m[1]))) == pytest.approx(60.0)
    assert math.degrees(math.atan2(m[0], m[1])) == pytest.approx(10.0)  # east of north


def test_accelerometer_and_magnetometer_models():
    t = np.arange(1000) * 0.01
    f = np.tile([0.0, 0.0, G], (1000, 1))
    q = np.tile([1.0, 0, 0, 0], (1000, 1))
    assert np.array_equal(sensors.accelerometer(t, q, f, 0.01), f)
    e = sensors.AccelerometerErrors(white_noise=0.02, bias=[0.1, 0, 0], vibration_amplitude=2.0,
                                    vibration_hz=7.0, vibration_start=5.0)
    a1 = sensors.accelerometer(t, q, f, 0.01, errors=e, rng=4)
    a2 = sensors.accelerometer(t, q, f, 0.01, errors=e, rng=4)
    assert np.array_equal(a1, a2)  # seeded
    quiet, shaken = t < 5, t >= 5
    assert np.mean(a1[quiet, 0]) == pytest.approx(0.1, abs=0.02)
    assert np.std(a1[quiet, 0]) == pytest.approx(0.2, rel=0.15)  # 0.02/√0.01
    assert np.std(a1[shaken, 0]) > 1.0  # vibration on
    field = np.array([0.0, 20.0, -40.0])
    m = sensors.magnetometer(t, q, field)
    assert np.allclose(m, field)
    me = sensors.MagnetometerErrors(hard_iron=[5.0, 0, 0], soft_iron=np.diag([0.1, 0, 0]),
                                    anomaly=[0, 0, 10.0], anomaly_start=2.0, anomaly_stop=3.0)
    mm = sensors.magnetometer(t, q, field, errors=me)
    assert np.allclose(mm[0], [5.0, 20.0, -40.0])
    assert np.allclose(mm[250], [5.0, 20.0, -30.0])
    with pytest.raises(ValueError, match=r"soft_iron must have shape \(3, 3\)"):
        sensors.MagnetometerErrors(soft_iron=np.zeros(3))
    with pytest.raises(ValueError, match="white_noise must be non-negative"):
        sensors.AccelerometerErrors(white_noise=-1.0)


@pytest.mark.slow
def test_reproduce_wang_sliding(tmp_path):
    from strapdown.cli import main

    assert main(["reproduce", "wang-sliding", "--out", str(tmp_path / "ws")]) == 0
    report = (tmp_path / "ws" / "report.md").read_text()
    assert "the paper's ordering" in report
    rows = (tmp_path / "ws" / "flight_errors.csv").read_text().splitlines()
    assert len(rows) == 1 + 3 * 4
    # in the steady turn the algorithms alone are far below the filter errors
    ol = [float(r.split(",")[6]) for r in rows[1:] if not r.split(",")[1].startswith("control")]
    assert max(ol) < 1e-4
