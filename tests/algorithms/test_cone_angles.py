"""Cone angles (Zhang & Yu 2021): conversions, motion, flight-control integration, navigation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from strapdown.algorithms.cone_kinematics import (
    integrate_cone_angles,
    integrate_cone_angles_reference,
)
from strapdown.algorithms.errata import (
    TABLE7,
    paper_cone_angles_from_dcm,
    paper_dcm_from_cone_angles,
    paper_pitch_yaw_from_cone_angles,
    triple_cross_rotation_vectors,
)
from strapdown.analysis import integrate_attitude_ode
from strapdown.rotation import (
    attitude_error_angle,
    cone_angles_from_dcm,
    cone_angles_from_quat,
    dcm_from_cone_angles,
    dcm_from_euler_zyx,
    euler_zyx_from_dcm,
    quat_from_cone_angles,
)
from strapdown.truth.cone_motions import zhang_yu_simulation
from strapdown.truth.motions import ClassicalConing, ConeAngleMotion, SpinConing
from strategies import angles

D = math.radians


_TWO_PI = st.floats(0.0, 2 * math.pi, exclude_max=True)


@given(st.lists(st.tuples(_TWO_PI, angles(), _TWO_PI), min_size=1, max_size=30))
def test_round_trip_random_including_tiny_and_near_pi(triples):
    d1, d2, d3 = (np.array(x) for x in zip(*triples, strict=True))
    c = dcm_from_cone_angles(d1, d2, d3)
    assert np.abs(dcm_from_cone_angles(*cone_angles_from_dcm(c)) - c).max() <= 1e-12
    q = quat_from_cone_angles(d1, d2, d3)
    assert np.abs(dcm_from_cone_angles(*cone_angles_from_quat(q)) - c).max() <= 1e-12


def test_angles_recovered_where_defined():
    rng = np.random.default_rng(1)
    d1, d3 = rng.uniform(0, 2 * np.pi, (2, 500))
    d2 = rng.uniform(1e-3, np.pi - 1e-3, 500)
    a1, a2, a3 = cone_angles_from_dcm(dcm_from_cone_angles(d1, d2, d3))
    assert np.allclose(a2, d2, atol=1e-12)
    assert np.allclose(np.angle(np.exp(1j * (a1 - d1))), 0, atol=1e-9)
    assert np.allclose(np.angle(np.exp(1j * (a3 - d3))), 0, atol=1e-9)
    # δ3 stays defined at δ2 = 0
    _, b2, b3 = cone_angles_from_dcm(dcm_from_cone_angles(1.2, 0.0, 2.5))
    assert b2 == 0.0 and b3 == pytest.approx(2.5, abs=1e-15)


def test_euler_round_trip():
    rng = np.random.default_rng(2)
    y, r = rng.uniform(-np.pi, np.pi, (2, 300))
    p = rng.uniform(-np.pi / 2 + 1e-6, np.pi / 2 - 1e-6, 300)
    c = dcm_from_euler_zyx(y, p, r)
    assert np.allclose(np.stack(euler_zyx_from_dcm(c)), np.stack([y, p, r]), atol=1e-9)


def test_classical_coning_and_spin_coning_in_cone_angles():
    t = np.linspace(0, 3, 31)
    a, om, ws = 0.1, 2.0, 7.0
    cone = ConeAngleMotion.polynomial((-np.pi / 2, a, 0.0), (om, 0.0, 0.0))
    q = cone.attitude(t)
    assert np.max(attitude_error_angle(q, ClassicalConing(a, om).attitude(t))) < 1e-14
    assert np.allclose(cone.rate(t), ClassicalConing(a, om).rate(t), atol=1e-14)
    sc = ConeAngleMotion.polynomial((-np.pi / 2, a, 0.0), (om, 0.0, ws))
    assert np.max(attitude_error_angle(sc.attitude(t), SpinConing(a, om, ws).attitude(t))) < 1e-13


@pytest.mark.parametrize("sim", [1, 2])
def test_eq6_rates_consistent_with_attitude(sim):
    m = zhang_yu_simulation(sim)
    t = np.linspace(0, 3, 13)
    assert np.max(attitude_error_angle(integrate_attitude_ode(m, t), m.attitude(t))) <= 1e-11


@pytest.mark.parametrize("sim", [1, 2])
def test_flight_control_methods_within_1e6_deg_over_30s(sim):
    m = zhang_yu_simulation(sim)
    t = np.arange(300_001) / 10_000.0
    w = m.rate(t)
    truth = m.angles(t[::2])
    for method in ("cone", "nutation", "euler"):
        s = integrate_cone_angles(t, w, truth[0], method=method)
        e3 = np.angle(np.exp(1j * (s.angles[:, 2] - truth[:, 2])))
        e2 = s.angles[:, 1] - truth[:, 1]
        assert np.degrees(np.abs(e3).max()) <= 1e-6, method
        assert np.degrees(np.abs(e2).max()) <= 1e-6, method
    bad = integrate_cone_angles(t[:20001], w[:20001], truth[0], method="cone-printed")
    assert np.degrees(np.abs(bad.angles[:, 1] - truth[: bad.angles.shape[0], 1]).max()) > 1.0


def test_euler_roll_is_not_delta3():
    m = zhang_yu_simulation(1)
    t = np.linspace(0, 30, 3001)
    d = m.angles(t)
    c = dcm_from_cone_angles(*d.T)
    _, _, roll = euler_zyx_from_dcm(c)
    diff = np.abs(np.angle(np.exp(1j * (roll - d[:, 2]))))
    bound = np.arcsin(np.tan(d[:, 1] / 2) ** 2)
    assert np.all(diff <= bound + 1e-12)
    assert diff[-300:].max() > 0.9 * bound[-1]


@pytest.mark.parametrize("method", ["cone", "cone-printed", "nutation", "euler"])
def test_kernel_matches_reference(method):
    m = zhang_yu_simulation(2)
    t = np.arange(2001) / 10_000.0
    w = m.rate(t)
    a = integrate_cone_angles(t, w, m.angles(0.0), method=method)
    b = integrate_cone_angles_reference(t, w, m.angles(0.0), method=method)
    assert np.abs(a.angles - b.angles).max() <= 1e-12
    assert a.switches == b.switches


def test_paper_formulas_fail_where_the_errata_say():
    rng = np.random.default_rng(3)
    d1, d3 = rng.uniform(0, 2 * np.pi, (2, 200))
    d2 = rng.uniform(0.1, np.pi - 0.1, 200)
    c = dcm_from_cone_angles(d1, d2, d3)
    printed = paper_dcm_from_cone_angles(d1, d2, d3)
    assert np.allclose(printed[:, :2, :], c[:, :2, :], atol=1e-15)  # rows 1–2 are right
    assert np.abs(printed[:, 2, 1:] - c[:, 2, 1:]).max() > 0.5  # C32, C33 typos
    # eq. 19 loses precision near δ2 = 0, atan2 does not
    small = dcm_from_cone_angles(1.0, 1e-7, 2.0)
    assert abs(paper_cone_angles_from_dcm(small)[1] - 1e-7) > 1e-12
    assert abs(cone_angles_from_dcm(small)[1] - 1e-7) < 1e-20
    # eq. 21 is the negative of the z-y-x pitch
    _, pitch, _ = euler_zyx_from_dcm(c)
    theta, _ = paper_pitch_yaw_from_cone_angles(d1, d2)
    assert np.allclose(theta, -pitch, atol=1e-9)


def test_table7_structure():
    rng = np.random.default_rng(4)
    th = rng.normal(size=(6, 3)) * 0.01
    phi = triple_cross_rotation_vectors(th)
    t1, t2, t3 = th[:3]
    k = TABLE7
    ref = th[:3].sum(0) + k["k11"] * np.cross(t1, t3) + k["k12"] * np.cross(t2, t3 - t1)
    for ij, (a, b) in {"12": (t1, t2), "23": (t2, t3), "13": (t1, t3)}.items():
        for m, tm in enumerate((t1, t2, t3), start=1):
            ref = ref + k[f"k{m}{ij}"] * np.cross(tm, np.cross(a, b))
    assert np.allclose(phi[0], ref, atol=1e-20)
    plain = triple_cross_rotation_vectors(th, triple=False)
    assert not np.allclose(plain, phi, atol=1e-12)
    with pytest.raises(ValueError, match="unknown Table 7"):
        triple_cross_rotation_vectors(th, {"k99": 1.0})


def test_bad_input():
    with pytest.raises(ValueError, match="unknown method"):
        integrate_cone_angles(np.arange(5) * 0.1, np.zeros((5, 3)), (0, 0, 0), method="x")
    with pytest.raises(ValueError, match="three finite"):
        integrate_cone_angles(np.arange(5) * 0.1, np.zeros((5, 3)), (0, np.nan, 0))
    with pytest.raises(ValueError, match="NaN"):
        dcm_from_cone_angles(np.nan, 0.1, 0.2)
