"""Rate-input sculling (the dual of rate-single) against the exact classical-sculling truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.velocity import rate_sculling_law
from strapdown.navigation import integrate_inertial_rates
from strapdown.truth.sculling import classical_sculling

THETA, PSI = 1e-3, 0.3


def _rate(spp: int, coefficients: str, periods: int = 6) -> float:
    """Rectified velocity-error rate (nav z) over periods 1..periods, 1 Hz, exact samples."""
    mo = classical_sculling(THETA, 2 * math.pi, 1.0, PSI)
    t = np.arange(periods * spp + 1) / spp
    sol = integrate_inertial_rates(mo.rate(t), mo.specific_force(t), td=1 / spp,
                                   coefficients=coefficients, q0=mo.attitude(0.0))
    dv = sol.v[:, 2] - mo.velocity(sol.t)[:, 2]
    return float((dv[-1] - dv[spp]) / (sol.t[-1] - sol.t[spp]))


@pytest.mark.parametrize(("coefficients", "order", "c"),
                         [("derived", 4, 11 / 1440), ("paper", 2, 1 / 12)])
def test_rate_input_sculling_law(coefficients, order, c):
    # the dual of the rate-single coning law: −c θ0 A cos ψ (Ωtd)^order (c = 11/1440 for the
    # designer's 1/6, 1/12 for the printed start-up form), measured on exact samples
    law = rate_sculling_law(coefficients)
    assert (law.order, float(law.constant)) == (order, pytest.approx(c, rel=1e-15))
    rates = [_rate(spp, coefficients) for spp in (60, 120)]
    for r, spp in zip(rates, (60, 120), strict=True):
        pred = -c * THETA * math.cos(PSI) * (2 * math.pi / spp) ** order
        assert r / pred == pytest.approx(1.0, abs=0.01)
    assert math.log2(rates[0] / rates[1]) == pytest.approx(order, abs=0.02)


def test_rate_input_attitude_and_velocity_track_the_truth():
    mo = classical_sculling(math.radians(1.0), 2 * math.pi * 10, 10.0, 0.0)
    t = np.arange(1201) / 1200
    sol = integrate_inertial_rates(mo.rate(t), mo.specific_force(t), td=1 / 1200,
                                   q0=mo.attitude(0.0))
    # the trapezoid's periodic error on a sinusoid: x0 (Ωtd)²/12 about its start, so at most
    # twice that from the exact start (x0 = A/Ω for velocity, θ0 for the angle)
    x = (2 * math.pi / 120) ** 2 / 12
    dv = np.max(np.abs(sol.v - mo.velocity(sol.t)))
    assert 0.5 * 2 * x * 10.0 / (2 * math.pi * 10) < dv < 1.05 * 2 * x * 10.0 / (2 * math.pi * 10)
    dot = np.clip(np.abs(np.sum(sol.q * mo.attitude(sol.t), axis=1)), 0.0, 1.0)
    assert np.max(2 * np.arccos(dot)) < 1.05 * 2 * x * math.radians(1.0)


def test_rate_input_bad_input():
    with pytest.raises(ValueError, match="needs at least 2 samples"):
        integrate_inertial_rates(np.zeros((1, 3)), np.zeros((1, 3)), td=0.01)
    with pytest.raises(ValueError, match="coefficients"):
        integrate_inertial_rates(np.zeros((3, 3)), np.zeros((3, 3)), td=0.01,
                                 coefficients="table3")
    with pytest.raises(ValueError, match="td"):
        integrate_inertial_rates(np.zeros((3, 3)), np.zeros((3, 3)), td=-1.0)
    with pytest.raises(ValueError, match="shape"):
        integrate_inertial_rates(np.zeros((3, 3)), np.zeros((4, 3)), td=0.01)


def _rate_three(spp: int, coefficients: str) -> float:
    mo = classical_sculling(1e-4, 2 * math.pi, 1.0, PSI)
    t = np.arange(6 * spp + 1) / spp
    sol = integrate_inertial_rates(mo.rate(t), mo.specific_force(t), td=1 / spp,
                                   coefficients=coefficients, algorithm="rate-three",
                                   q0=mo.attitude(0.0))
    dv = sol.v[:, 2] - mo.velocity(sol.t)[:, 2]
    i0 = spp // 3
    law = rate_sculling_law(coefficients, "rate-three").predict(1e-4, 1.0, PSI, 2 * math.pi,
                                                                1 / spp)
    return float((dv[-1] - dv[i0]) / (sol.t[-1] - sol.t[i0])) / law


def test_rate_three_dual_follows_the_rate_three_coning_law():
    # derived: (Ωtd)^8 with 433/806400; measured/law 0.988-0.989 at Ωtd = 2π/24, 2π/30 in
    # float64 (finer steps reach round-off) — the order is 8 to 0.05
    r24, r30 = _rate_three(24, "derived"), _rate_three(30, "derived")
    assert r24 == pytest.approx(1, abs=0.02) and r30 == pytest.approx(1, abs=0.02)
    assert abs(math.log(r24 / r30) / math.log(30 / 24)) < 0.05
    # paper: (Ωtd)^4 with −1/80, approached from below as Ωtd shrinks (0.915, 0.945, 0.962)
    ratios = [_rate_three(spp, "paper") for spp in (24, 30, 36)]
    assert ratios == sorted(ratios) and 0.95 < ratios[-1] < 1.0
    with pytest.raises(ValueError, match="at least 4 samples"):
        integrate_inertial_rates(np.zeros((3, 3)), np.zeros((3, 3)), td=0.01,
                                 algorithm="rate-three")
    with pytest.raises(ValueError, match="rate-input velocity algorithm"):
        integrate_inertial_rates(np.zeros((3, 3)), np.zeros((3, 3)), td=0.01, algorithm="rk4")
