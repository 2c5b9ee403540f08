"""Reference motions: closed forms against adaptive ODE integration and quadrature."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from conftest import quat_close
from strapdown.analysis import integrate_attitude_ode
from strapdown.rotation import attitude_error_angle, quat_multiply
from strapdown.truth import motions as M

CASES = [
    M.ClassicalConing(math.radians(1.0), 2 * math.pi),
    M.ClassicalConing(0.7, -3.0),
    M.PureSpin(math.radians(9000.0)),
    M.SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(1080.0)),
    M.SpinConing(0.3, 5.0, 5.0),  # spin rate equals cone rate: λ = 0 branch
]


@pytest.mark.parametrize("motion", CASES, ids=lambda m: repr(m))
def test_closed_form_attitude_matches_ode(motion):
    # Span limited to ~30 rad of rotation: beyond that the ODE reference's own
    # error (rtol 1e-13, DOP853) approaches 1e-12.
    peak = np.max(np.linalg.norm(motion.rate(np.linspace(0, 1, 50)), axis=-1))
    t = np.linspace(0.0, min(1.3, 30.0 / peak), 27)
    q_ode = integrate_attitude_ode(motion, t)
    assert np.max(attitude_error_angle(q_ode, motion.attitude(t))) <= 1e-12


@pytest.mark.parametrize("motion", CASES, ids=lambda m: repr(m))
def test_closed_form_increments_match_quadrature(motion):
    edges = np.linspace(0.1, 0.9, 41)
    exact = motion.increments(edges)
    # independent: the generic Gauss–Legendre path of the base class
    quad = M.Motion._increments(motion, edges[:-1], edges[1:])
    assert np.max(np.abs(exact - quad)) <= 1e-15 * max(1.0, np.abs(exact).max() * 10)


def test_li2017_increment_formulas():
    a, om, h = 0.02, 6.0, 1e-3
    m = M.ClassicalConing(a, om)
    edges = np.array([0.37, 0.37 + h])
    tm = 0.37 + h / 2
    th = m.increments(edges)[0]
    assert th[0] == pytest.approx(-2 * om * math.sin(a / 2) ** 2 * h, rel=1e-14)
    assert th[1] == pytest.approx(-2 * math.sin(a) * math.sin(om * h / 2) * math.sin(om * tm),
                                  rel=1e-13)
    assert th[2] == pytest.approx(2 * math.sin(a) * math.sin(om * h / 2) * math.cos(om * tm),
                                  rel=1e-13)


def test_coning_rate_is_eq7():
    a, om = 0.1, 2.0
    t = np.array([0.0, 0.4, 1.9])
    w = M.ClassicalConing(a, om).rate(t)
    assert np.allclose(w[:, 0], -2 * om * math.sin(a / 2) ** 2)
    assert np.allclose(w[:, 1], -om * math.sin(a) * np.sin(om * t))
    assert np.allclose(w[:, 2], om * math.sin(a) * np.cos(om * t))


def test_coning_truth_is_periodic():
    m = M.ClassicalConing(0.05, 2 * math.pi)
    assert quat_close(m.attitude(m.period * 7), m.attitude(0.0), 1e-14)


def test_spin_coning_reduces_to_coning_and_spin():
    t = np.linspace(0, 2, 11)
    sc = M.SpinConing(0.2, 3.0, 0.0)
    c = M.ClassicalConing(0.2, 3.0)
    assert np.allclose(sc.attitude(t), c.attitude(t), atol=1e-15)
    assert np.allclose(sc.increments(t), c.increments(t), atol=1e-15)
    s = M.SpinConing(0.0, 3.0, 7.0)
    assert np.allclose(s.attitude(t), M.PureSpin(7.0).attitude(t), atol=1e-15)


def test_spin_coning_period():
    assert M.SpinConing(0.1, 2.0, 6.0).period == pytest.approx(math.pi)
    assert M.SpinConing(0.1, 2.0, 2.0 * math.sqrt(2)).period is None


def test_mp_closed_forms_agree_with_float64():
    m = M.SpinConing(0.3, 2.0, 11.0)
    with mpmath.workdps(40):
        q = m.attitude_mp(0.77)
        th = m.increment_mp(0.5, 0.51)
        assert isinstance(q[0], mpmath.mpf)
    assert np.allclose([float(x) for x in q], m.attitude(0.77), atol=1e-15)
    assert np.allclose([float(x) for x in th], m.increments([0.5, 0.51])[0], atol=1e-17)


def test_rotation_sequence_motion_reproduces_coning():
    # Classical coning as x–z–x cone angles (Zhang & Yu (2021)): δ1 = Ωt − π/2, δ2 = a, δ3 = 0,
    # C = Rx(δ1) Rz(δ2) Rx(δ3 − δ1).
    a, om = 0.3, 2.0
    seq = M.RotationSequenceMotion(
        "xzx",
        lambda t: np.stack([om * t - np.pi / 2, np.full_like(t, a), np.pi / 2 - om * t], -1),
        lambda t: np.stack([np.full_like(t, om), np.zeros_like(t), np.full_like(t, -om)], -1),
    )
    cone = M.ClassicalConing(a, om)
    t = np.linspace(0, 3, 31)
    # Same body motion up to a constant frame rotation: compare rates and increments.
    assert np.allclose(seq.rate(t), cone.rate(t), atol=1e-14)
    edges = np.linspace(0, 1, 101)
    assert np.allclose(seq.increments(edges), cone.increments(edges), atol=1e-16)
    q_ode = integrate_attitude_ode(seq, t)
    assert np.max(attitude_error_angle(q_ode, seq.attitude(t))) <= 1e-12


def test_user_motion_and_ode_consistency():
    w = np.array([0.3, -0.2, 0.5])
    ang = np.linalg.norm(w)

    def att(t):
        t = np.asarray(t)[..., None]
        return np.concatenate([np.cos(ang * t / 2), np.sin(ang * t / 2) * w / ang], -1)

    m = M.UserMotion(att, lambda t: np.broadcast_to(w, (*np.shape(t), 3)))
    t = np.linspace(0, 4, 9)
    assert np.max(attitude_error_angle(integrate_attitude_ode(m, t), m.attitude(t))) <= 1e-12
    assert np.allclose(m.increments(t), np.diff(t)[:, None] * w, atol=1e-15)


def test_user_motion_shape_errors():
    m = M.UserMotion(lambda t: np.zeros(3), lambda t: np.zeros(3))
    with pytest.raises(ValueError, match="attitude"):
        m.attitude(np.array([0.0, 1.0]))


@pytest.mark.parametrize(
    ("factory", "msg"),
    [
        (lambda: M.ClassicalConing(0.1, 0.0), "cone_rate"),
        (lambda: M.ClassicalConing(np.nan, 1.0), "NaN"),
        (lambda: M.PureSpin(np.inf), "NaN or infinity"),
        (lambda: M.RotationSequenceMotion("xqz", np.sin, np.cos), "axes"),
        (lambda: M.UserMotion(1, 2), "callables"),
    ],
)
def test_bad_motion_parameters(factory, msg):
    with pytest.raises(ValueError, match=msg):
        factory()


def test_increments_need_increasing_edges():
    m = M.PureSpin(1.0)
    with pytest.raises(ValueError, match="strictly increasing"):
        m.increments([0.0, 0.2, 0.1])
    with pytest.raises(ValueError, match="at least 2"):
        m.increments([0.0])


def test_no_closed_form_for_user_motion_in_mp():
    m = M.UserMotion(lambda t: t, lambda t: t)
    assert not m.has_closed_form
    with pytest.raises(NotImplementedError, match="closed form"):
        m.attitude_mp(0.0)


def test_quat_multiply_consistency_of_spin_coning():
    # q_n_b(t) = q_cone(t) ⊗ q_x(ω_s t)
    sc = M.SpinConing(0.2, 3.0, 9.0)
    t = np.array([0.0, 0.3, 1.7])
    qx = M.PureSpin(9.0).attitude(t)
    assert np.allclose(sc.attitude(t), quat_multiply(M.ClassicalConing(0.2, 3.0).attitude(t), qx),
                       atol=1e-15)
