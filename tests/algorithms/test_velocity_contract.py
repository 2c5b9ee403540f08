"""The velocity counterpart of the Family contract (issue 26): every family answers
``velocity(spec)``, the navigation and the rate-input velocity update ask it, and rate
families navigate through it without name switches."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms import velocity as V
from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec
from strapdown.algorithms.structures import STRUCTURE_REGISTRY
from strapdown.navigation import integrate_inertial_rates, navigate_rates
from strapdown.truth.trajectory import EarthFlight, EarthSegment

H = 0.01
FLIGHT = EarthFlight([EarthSegment(8.0), EarthSegment(12.0, 4.0, 6.0)], lat_deg=52.0,
                     lon_deg=-3.0, height=350.0, speed=80.0, heading_deg=20.0, ramp=4.0)


def test_every_family_answers_and_the_lists_come_from_the_registries():
    answered = {}
    for name, fam in REGISTRY.items():
        if fam.stepped:
            continue  # needs its step; has no velocity counterpart
        answered[name] = fam.velocity(AlgorithmSpec(name))
    assert isinstance(answered["rotvec"], V.IncrementVelocity)
    assert answered["rk4"] is None  # no window to dualise
    assert V.rate_velocity_algorithms() == V.RATE_VELOCITY_ALGORITHMS
    assert set(V.rate_velocity_algorithms()) == {
        n for n, v in answered.items() if isinstance(v, V.WindowedRateVelocity)}
    assert V.nav_structures() == tuple(s for s in STRUCTURE_REGISTRY.values()
                                       if s.runs_velocity)
    assert V.nav_structures() == V.NAV_STRUCTURES
    # the interleaved structures run no velocity
    assert AlgorithmSpec("rotvec", structure="realtime").family.velocity(
        AlgorithmSpec("rotvec", structure="realtime")) is None
    sliding = AlgorithmSpec("rate-three", structure="sliding")
    assert sliding.family.velocity(sliding) is None


@pytest.mark.parametrize(("algorithm", "n", "every"), [("rate-single", 1, True),
                                                       ("rate-three", 3, False),
                                                       ("rate-two", 2, False)])
def test_windowed_duals_shape_their_updates(algorithm, n, every):
    spec = AlgorithmSpec(algorithm)
    vel = spec.family.velocity(spec)
    w = spec.family.windowed(spec)
    assert vel.n == n and vel.structure.every_sample is every
    assert vel.min_samples == w.history + w.span + 1 == spec.family.min_samples(spec)
    assert vel.update_period(H) == pytest.approx(n * H)


@pytest.mark.parametrize("algorithm", ["rate-single", "rate-three", "rate-two"])
def test_rate_families_navigate_the_flight(algorithm):
    """Exact rates and specific force of a 20 s flight with a turn and a climb at 100 Hz:
    each rate family's velocity counterpart navigates it to the centimetre."""
    t = np.arange(round(FLIGHT.duration / H) + 1) * H
    w, f = FLIGHT.sensed(t)
    s0 = FLIGHT.state(np.array([0.0]))
    sol = navigate_rates(w, f, td=H, lat=math.radians(52.0), lon=math.radians(-3.0),
                         height=350.0, v0=s0.velocity[0], q0=s0.q[0], algorithm=algorithm)
    truth = FLIGHT.state(sol.t)
    north = (sol.lat - truth.lat) * 6.37e6
    assert sol.t[0] == 0.0 and np.all(np.diff(sol.t) > 0)
    assert np.max(np.abs(north)) < 1e-3 and np.max(np.abs(sol.height - truth.height)) < 1e-3
    assert np.max(np.abs(sol.v - truth.velocity)) < 1e-3


def test_rate_velocity_equals_the_inertial_duals_and_the_increment_path():
    """The windowed dual is what integrate_inertial_rates runs (bit for bit), and the
    increment family's counterpart is body_increments."""
    rng = np.random.default_rng(3)
    w, f = rng.normal(0, 0.3, (40, 3)), rng.normal(0, 5.0, (40, 3))
    for alg in ("rate-single", "rate-three"):
        spec = AlgorithmSpec(alg)
        b = spec.family.velocity(spec).body(w, f, H)
        sol = integrate_inertial_rates(w, f, td=H, algorithm=alg)
        assert sol.structure == b.structure and sol.n == b.n
        assert b.phi.shape[0] == sol.t.size - 1
    spec = AlgorithmSpec("rotvec", subsamples=3)
    b = spec.family.velocity(spec).body(w * H, f * H, H)
    ref = V.body_increments(w * H, f * H, 3, h=H)
    assert np.array_equal(b.dv, ref.dv) and np.array_equal(b.phi, ref.phi)


def test_bad_rate_navigation():
    w = np.zeros((10, 3))
    with pytest.raises(ValueError, match="choose one of rate-single, rate-three, rate-two"):
        navigate_rates(w, w, td=H, lat=0.1, lon=0.0, height=0.0, algorithm="rk4")
    with pytest.raises(ValueError, match="needs at least 4 samples"):
        navigate_rates(w[:3], w[:3], td=H, lat=0.1, lon=0.0, height=0.0,
                       algorithm="rate-three")
    with pytest.raises(ValueError, match="unknown rate-input coefficients"):
        navigate_rates(w, w, td=H, lat=0.1, lon=0.0, height=0.0, coefficients="bogus")
