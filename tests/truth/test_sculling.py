"""Exact sculling truth against adaptive ODE integration (DOP853) and mpmath quadrature."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import j1

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_multiply
from strapdown.truth.sculling import ScullingMotion, classical_sculling

MOTIONS = {
    "classical": classical_sculling(0.3, 2 * math.pi * 2, 5.0, 0.4),
    "coning+spin": ScullingMotion(0.2, 2 * math.pi * 1.5, 3.0, -0.7, half_angle=0.25,
                                  cone_rate=2 * math.pi * 0.8, spin_rate=3.0),
    "spin only": ScullingMotion(0.05, 7.0, 2.0, 1.1, spin_rate=-20.0),
}


def _ode(mo, times):
    """q̇ = ½ q ⊗ ω, v̇ = C f, ṗ = v, Θ̇ = ω, V̇ = f integrated from the rates and forces."""
    def rhs(t, s):
        w = mo.rate(np.array(t))
        f = mo.specific_force(np.array(t))
        dq = 0.5 * quat_multiply(s[:4], np.r_[0.0, w])
        return np.r_[dq, dcm_from_quat(s[:4]) @ f, s[4:7], w, f]

    y0 = np.r_[mo.attitude(0.0), np.zeros(12)]
    sol = solve_ivp(rhs, (times[0], times[-1]), y0, method="DOP853", rtol=1e-12, atol=1e-14,
                    t_eval=times)
    assert sol.success
    return sol.y.T


@pytest.mark.parametrize("name", sorted(MOTIONS))
def test_closed_form_matches_adaptive_integration(name):
    mo = MOTIONS[name]
    t = np.linspace(0.0, 3.0, 13)
    y = _ode(mo, t)
    assert np.max(np.abs(y[:, :4] - mo.attitude(t))) < 1e-11
    v, p = mo.velocity(t), mo.position(t)
    assert np.max(np.abs(y[:, 4:7] - v)) < 1e-11 * max(1.0, np.abs(v).max())
    assert np.max(np.abs(y[:, 7:10] - p)) < 1e-11 * max(1.0, np.abs(p).max())
    assert np.max(np.abs(np.diff(y[:, 10:13], axis=0) - mo.increments(t))) < 1e-12
    assert np.max(np.abs(np.diff(y[:, 13:16], axis=0) - mo.velocity_increments(t))) < 1e-12
    # the navigation-frame force is the body force rotated by the attitude
    fn = np.einsum("nij,nj->ni", dcm_from_quat(mo.attitude(t)), mo.specific_force(t))
    assert np.max(np.abs(fn - mo.force_nav(t))) < 1e-13


def _f_nav_mp(mo, t):
    """C(q(t)) f_b(t) in mpmath, from the attitude quaternion (not the exponential sums)."""
    w, x, y, z = mo.attitude_mp(t)
    fy = mpmath.mpf(mo.accel_amplitude) * mpmath.sin(mpmath.mpf(mo.frequency) * t
                                                     + mpmath.mpf(mo.phase))
    return (2 * (x * y - w * z) * fy, (1 - 2 * (x * x + z * z)) * fy, 2 * (y * z + w * x) * fy)


@pytest.mark.parametrize("name", ["classical", "coning+spin"])
def test_arbitrary_precision_against_mpmath_quadrature(name):
    mo = MOTIONS[name]
    with mpmath.workdps(30):
        t1 = mpmath.mpf("1.3")
        v = mo.velocity_mp(t1)
        for k in range(3):
            ref = mpmath.quad(lambda s, k=k: _f_nav_mp(mo, s)[k], mpmath.linspace(0, t1, 9))
            assert abs(v[k] - ref) < mpmath.mpf(10) ** -24
        # position: ṗ = v, by quadrature of the closed-form velocity (Gauss-Legendre: the
        # integrand is smooth, so it converges in 180 evaluations where tanh-sinh took 500, to
        # the same reference at 30 digits)
        p = mo.position_mp(t1)
        ref = mpmath.quad(lambda s: mo.velocity_mp(s)[2], mpmath.linspace(0, t1, 5),
                          method="gauss-legendre")
        assert abs(p[2] - ref) < mpmath.mpf(10) ** -24
        # gyro increment = ∫ rate; rate = 2 q* ⊗ q̇ (numerical derivative of the attitude)
        t0, t2 = mpmath.mpf("0.41"), mpmath.mpf("0.47")
        inc = mo.increment_mp(t0, t2)
        for k in range(3):
            ref = mpmath.quad(lambda s, k=k: mo.rate_mp(s)[k], [t0, t2])
            assert abs(inc[k] - ref) < mpmath.mpf(10) ** -26
        tm = mpmath.mpf("0.9")
        q = mo.attitude_mp(tm)
        dq = [mpmath.diff(lambda s, i=i: mo.attitude_mp(s)[i], tm) for i in range(4)]
        w = quat_mp(tuple(q[0:1]) + tuple(-c for c in q[1:]), dq)
        for k in range(3):
            assert abs(2 * w[k + 1] - mo.rate_mp(tm)[k]) < mpmath.mpf(10) ** -20
        dv = mo.velocity_increment_mp(t0, t2)
        ref = mpmath.quad(lambda s: mpmath.mpf(mo.accel_amplitude) * mpmath.sin(
            mpmath.mpf(mo.frequency) * s + mpmath.mpf(mo.phase)), [t0, t2])
        assert abs(dv[1] - ref) < mpmath.mpf(10) ** -26
    # float64 and arbitrary precision agree
    assert np.allclose([float(c) for c in mo.velocity_mp(1.3)], mo.velocity(1.3), rtol=0,
                       atol=1e-13)


def quat_mp(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw)


def test_classical_sculling_rectifies_along_z():
    mo = classical_sculling(0.2, 2 * math.pi, 4.0, 0.3)
    assert mo.rectified_acceleration() == pytest.approx(4.0 * j1(0.2) * math.cos(0.3),
                                                        rel=1e-15)
    # over whole periods the z velocity grows by exactly the rectified rate
    t = np.array([0.0, 10.0])
    v = mo.velocity(t)
    assert (v[1, 2] - v[0, 2]) / 10.0 == pytest.approx(mo.rectified_acceleration(), rel=1e-12)
    assert abs(v[1, 1] - v[0, 1]) < 1e-12  # no rectification along y
    # small amplitude: A J1(θ0) ≈ ½ θ0 A
    assert classical_sculling(1e-4, 3.0, 2.0).rectified_acceleration() == pytest.approx(
        1e-4, rel=1e-8)


def test_zero_frequency_and_cone_without_rate_refused():
    with pytest.raises(ValueError, match="frequency"):
        ScullingMotion(0.1, 0.0, 1.0)
    with pytest.raises(ValueError, match="cone_rate"):
        ScullingMotion(0.1, 1.0, 1.0, half_angle=0.1)
    with pytest.raises(ValueError, match="NaN"):
        ScullingMotion(float("nan"), 1.0, 1.0)
    with pytest.raises(ValueError, match="classical"):
        ScullingMotion(0.1, 1.0, 1.0, spin_rate=1.0).rectified_acceleration()
