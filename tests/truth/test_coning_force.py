"""Exact truth of a body coning in a constant specific force, against adaptive ODE
integration (DOP853, rtol 1e-13) and mpmath; the coned flight's rates against its attitude."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from strapdown.rotation.quaternion import quat_multiply
from strapdown.truth.coning_force import ConedFlight, ConingInForce
from strapdown.truth.trajectory import EarthFlight, EarthSegment

MOTION = ConingInForce(math.radians(2.0), 2 * math.pi * 5.0, (-9.8, 0.7, -1.3))


def _rotate_inv(q, x):
    w, v = q[0], -q[1:]
    t = 2.0 * np.cross(v, x)
    return x + w * t + np.cross(v, t)


def _ode(motion, edges):
    """Quaternion from the body rates and ∫ C_b_n f_n dt, integrated together."""
    f = np.asarray(motion.force)

    def rhs(t, y):
        q = y[:4] / np.linalg.norm(y[:4])
        w = motion.rate(np.array([t]))[0]
        dq = 0.5 * np.concatenate([[-q[1:] @ w], q[0] * w + np.cross(q[1:], w)])
        return np.concatenate([dq, _rotate_inv(q, f)])

    y0 = np.concatenate([motion.attitude(0.0), np.zeros(3)])
    sol = solve_ivp(rhs, (edges[0], edges[-1]), y0, method="DOP853", rtol=1e-13, atol=1e-16,
                    t_eval=edges)
    return sol.y[:4].T, sol.y[4:].T


def test_accelerometer_increments_match_the_ode():
    edges = np.linspace(0.0, 0.3, 31)
    q_ode, v_ode = _ode(MOTION, edges)
    dv = MOTION.velocity_increments(edges)
    assert np.max(np.abs(np.diff(v_ode, axis=0) - dv)) <= 2e-13 * np.max(np.abs(dv))
    # the attitude the force is rotated by is the motion's own
    assert np.max(np.abs(q_ode - MOTION.attitude(edges))) <= 1e-11


def test_specific_force_rotates_back_to_the_constant_navigation_force():
    t = np.linspace(0.0, 1.0, 17)
    fb = MOTION.specific_force(t)
    q = MOTION.attitude(t)
    fn = [_rotate_inv(np.array([qq[0], *(-qq[1:])]), f) for qq, f in zip(q, fb, strict=True)]
    assert np.allclose(fn, np.broadcast_to(MOTION.force, (17, 3)), rtol=0, atol=1e-14)
    # the compensated increment of an update is C_b_n(t0) f_n T
    assert np.allclose(MOTION.velocity_increment_b0(0.25, 0.3), fb[4] * 0.05, atol=1e-16)


def test_arbitrary_precision_agrees_with_float64():
    with mpmath.workdps(40):
        mp = [float(x) for x in MOTION.velocity_increment_mp(0.1, 0.11)]
        v = [float(x) for x in MOTION.velocity_mp(0.37)]
        p = [float(x) for x in MOTION.position_mp(0.37)]
    assert np.allclose(mp, MOTION.velocity_increments([0.1, 0.11])[0], rtol=1e-14, atol=0)
    assert np.array_equal(MOTION.velocity(0.37), np.asarray(MOTION.force) * 0.37)
    assert np.allclose(v, MOTION.velocity(0.37), rtol=1e-15)
    assert np.allclose(p, MOTION.position(0.37), rtol=1e-15)


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="force must have shape"):
        ConingInForce(0.1, 1.0, (1.0, 2.0))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="NaN or infinity"):
        ConingInForce(0.1, 1.0, (1.0, math.nan, 0.0))


def test_coned_flight_cone_rate_integrates_to_its_attitude():
    fl = EarthFlight([EarthSegment(4.0, 3.0)], lat_deg=45.0, speed=100.0, ramp=2.0)
    cf = ConedFlight(fl, half_angle=math.radians(2.0), cone_rate=2 * math.pi * 5.0)

    def rhs(t, q):
        w = cf._cone(np.array(t))[1]
        return 0.5 * quat_multiply(q, np.concatenate([[0.0], w]))

    sol = solve_ivp(rhs, (0.0, 0.37), cf._cone(np.array(0.0))[0], method="DOP853",
                    rtol=1e-13, atol=1e-15, t_eval=[0.37])
    assert np.max(np.abs(sol.y[:, -1] - cf._cone(np.array(0.37))[0])) <= 1e-12
    # ω_ib = C_c^T ω_if + ω_c, f_b = C_c^T f_f; q_n_b = q_n_f ⊗ q_c
    t = np.array([1.3])
    (w_b, f_b), (w_f, f_f) = cf.sensed(t), fl.sensed(t)
    qc, wc = cf._cone(t)
    assert np.allclose(w_b[0], _rotate_inv(qc[0], w_f[0]) + wc[0], rtol=0, atol=1e-16)
    assert np.allclose(f_b[0], _rotate_inv(qc[0], f_f[0]), rtol=0, atol=1e-14)
    assert np.allclose(cf.state(t).q, quat_multiply(fl.state(t).q, qc), rtol=0, atol=1e-16)
