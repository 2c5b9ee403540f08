"""The generalisation suite's truth (strapdown.truth.scenarios) is consistent: the body rate
integrates to the attitude, the accelerometer is the specific force of the kinematics, the
pendulum keeps its energy and its exact period, the field is a magnetostatic one, and the
same seed gives the same recording."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad_vec, solve_ivp
from scipy.special import ellipk

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply
from strapdown.truth import scenarios as S

G = 9.80665
#: The suite, built once (its construction integrates the pendulums).
SUITE = {sc.name: sc for sc in S.suite(0)}
NAMES = list(SUITE)


def _angle(q1, q2):
    """Rotation angle between attitudes (rad)."""
    dq = quat_multiply(quat_conjugate(q1), q2)
    return 2 * np.arctan2(np.linalg.norm(dq[..., 1:], axis=-1), np.abs(dq[..., 0]))


@pytest.mark.parametrize("name", NAMES)
def test_body_rate_integrates_to_the_attitude(name):
    """q̇ = ½ q ⊗ [0, ω_b] integrated (DOP853, rtol 1e-12, atol 1e-14) from q(0) through the rest and
    into the motion reproduces q(t) to 1e-8 rad."""
    sc = SUITE[name]
    body = sc.body
    t_end = min(sc.rest_s + 15.0, sc.duration_s)
    t = np.linspace(0.0, t_end, 81)

    def rhs(tt, q):
        x, y, z = body.rate(np.array([tt]))[0]
        omega = np.array([[0, -x, -y, -z], [x, 0, z, -y], [y, -z, 0, x], [z, y, -x, 0]])
        return 0.5 * omega @ q  # q ⊗ [0, ω]

    sol = solve_ivp(rhs, (0.0, t_end), body.attitude(np.array([0.0]))[0], method="DOP853",
                    rtol=1e-12, atol=1e-14, t_eval=t)
    assert sol.success
    err = _angle(sol.y.T, body.attitude(t))
    assert err.max() < 1e-8, err.max()
    assert np.degrees(_angle(body.attitude(t[:1]), body.attitude(t))).max() > 1.0


@pytest.mark.parametrize("name", NAMES)
def test_gyro_sample_is_the_mean_rate_over_its_period(name):
    """A noise-free gyro sample is ∫ ω dt over [t − h, t] divided by h (to 1e-9 rad/s: the
    pendulum's rate and angle are the ODE solution's dense output, each to ~1e-10)."""
    sc = SUITE[name]
    rec = S.record(sc, noise=False, duration_s=min(sc.rest_s + 6.0, sc.duration_s))
    for k in np.linspace(1, rec.t.size - 1, 12).astype(int):
        mean, _ = quad_vec(lambda tt: sc.body.rate(np.array([tt]))[0], rec.t[k] - rec.h,
                           rec.t[k], epsabs=1e-13)
        np.testing.assert_allclose(rec.gyro[k], mean / rec.h, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", [n for n in NAMES if SUITE[n].body.velocity is not None])
def test_accelerometer_is_the_specific_force_of_the_kinematics(name):
    """The noise-free accelerometer is C_b_n (a_n − g_n), a_n the derivative of the body's
    velocity (central differences, independent of the scenario's acceleration formula), and
    the velocity the derivative of the position where there is one."""
    sc = SUITE[name]
    body = sc.body
    assert body.velocity is not None
    rec = S.record(sc, noise=False)
    idx = np.linspace(0, rec.t.size - 1, 200).astype(int)
    t = rec.t[idx]
    d = 1e-4
    v = [body.velocity(t + j * d) for j in (-2, -1, 1, 2)]
    a_n = (v[0] - 8 * v[1] + 8 * v[2] - v[3]) / (12 * d)
    c_n_b = dcm_from_quat(rec.q_n_b[idx])
    f = np.einsum("nji,nj->ni", c_n_b, a_n - np.array([0.0, 0.0, -G]))
    np.testing.assert_allclose(rec.acc[idx], f, rtol=0, atol=1e-6)
    if body.position is not None:
        p = [body.position(t + j * d) for j in (-2, -1, 1, 2)]
        np.testing.assert_allclose((p[0] - 8 * p[1] + 8 * p[2] - p[3]) / (12 * d),
                                   body.velocity(t), rtol=0, atol=1e-7)


def test_accelerometer_of_the_shaken_hand_is_its_acceleration_less_gravity():
    """The hand-held scenario (no velocity given): f_b = C_n_bᵀ (a_n + g up), with a_n the
    shaking's acceleration — which reaches a quarter g."""
    sc = SUITE["hand-held"]
    rec = S.record(sc, noise=False)
    a_n = sc.body.acceleration(rec.t)
    f = np.einsum("nji,nj->ni", dcm_from_quat(rec.q_n_b), a_n + np.array([0.0, 0.0, G]))
    np.testing.assert_allclose(rec.acc, f, rtol=0, atol=1e-12)
    assert np.linalg.norm(a_n, axis=1).max() > 2.5


@pytest.mark.parametrize("name", ["pendulum-0.3m-70deg", "vehicle", "loiter", "spin-coning"])
def test_the_accelerometer_sees_sustained_non_gravitational_force(name):
    """Not gravity alone: the specific force departs from g (sensor at the bob: not at all
    along the swing), or turns away from the vertical for seconds (vehicle, loiter)."""
    rec = S.record(SUITE[name], noise=False)
    up_b = np.einsum("nji,j->ni", dcm_from_quat(rec.q_n_b), [0.0, 0.0, 1.0])
    f = rec.acc
    tilt = np.degrees(np.arccos(np.clip(np.sum(f * up_b, 1) / np.linalg.norm(f, axis=1),
                                        -1, 1)))
    assert tilt.max() > 10.0, tilt.max()


def test_pendulum_accelerometer_at_the_bob_points_along_the_rod():
    """A mathematical pendulum's bob, once released, feels no tangential force:
    f_n ∥ (pivot − sensor)."""
    sc = SUITE["pendulum-0.3m-70deg"]
    body = sc.body
    assert body.position is not None
    rec = S.record(sc, noise=False)
    swinging = rec.t >= sc.rest_s
    f_n = np.einsum("nij,nj->ni", dcm_from_quat(rec.q_n_b), rec.acc)[swinging]
    rod = np.array([0.0, 0.0, 1.3]) - body.position(rec.t[swinging])
    cross = np.linalg.norm(np.cross(f_n, rod / np.linalg.norm(rod, axis=1)[:, None]), axis=1)
    assert cross.max() < 1e-9, cross.max()
    assert abs(np.linalg.norm(rod, axis=1) - 0.3).max() < 1e-12


@pytest.mark.parametrize("length, amplitude", [(0.3, 70.0), (0.8, 45.0), (1.5, 20.0)])
def test_pendulum_conserves_energy_and_keeps_its_exact_period(length, amplitude):
    """½ θ̇² + (g/L)(1 − cos θ) stays at its release value to 1e-10 relative over a minute,
    the swing keeps its amplitude, and θ crosses zero every half period 2√(L/g) K(sin²(θ0/2))
    (the large-angle period, not the small-angle one)."""
    sc = S.pendulum(length, amplitude, duration_s=60.0)
    m = sc.body.motion
    assert isinstance(m, S.PendulumMotion)
    t = np.linspace(sc.rest_s, 60.0, 60001)
    e = m.energy(t)
    e0 = G / length * (1 - math.cos(math.radians(amplitude)))
    assert abs(e / e0 - 1).max() < 1e-10
    th, _, _ = m.angle(t)
    assert abs(np.degrees(th).max() - amplitude) < 1e-3
    i = np.flatnonzero(np.sign(th[1:]) != np.sign(th[:-1]))
    tz = t[i] - th[i] * (t[i + 1] - t[i]) / (th[i + 1] - th[i])
    period = 4 * math.sqrt(length / G) * ellipk(math.sin(math.radians(amplitude) / 2) ** 2)
    np.testing.assert_allclose(np.diff(tz), period / 2, rtol=0, atol=1e-5)
    assert abs(tz[0] - sc.rest_s - period / 4) < 1e-5


def test_pendulum_increments_are_exact_differences_of_the_swing():
    """A fixed-axis rotation: the noise-free gyro, summed, is the swing angle's change."""
    sc = SUITE["pendulum-1.5m-20deg"]
    m = sc.body.motion
    assert isinstance(m, S.PendulumMotion)
    rec = S.record(sc, noise=False)
    th, _, _ = m.angle(rec.t)
    swept = np.cumsum(rec.gyro @ m.axis_b) * rec.h
    np.testing.assert_allclose(swept[1:], th[1:] - th[0], rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", NAMES)
def test_magnetometer_is_the_field_in_the_body_in_the_scenarios_unit(name):
    """Noise-free: mag = C_b_n B_n(r(t)) × unit."""
    sc = SUITE[name]
    rec = S.record(sc, noise=False, duration_s=min(20.0, sc.duration_s))
    b_n = sc.body.field_n(rec.t)
    m = np.einsum("nji,nj->ni", dcm_from_quat(rec.q_n_b), b_n) * sc.sensors.mag_unit
    np.testing.assert_allclose(rec.mag, m, rtol=1e-12, atol=1e-12 * np.abs(m).max())


def test_steel_frame_field_is_magnetostatic_and_disturbs_near_the_frame():
    """The frame's field has no divergence and no curl off the steel; the body meets a
    disturbance of 0.8 of the Earth field near the frame and almost none at the walk's ends."""
    sc = SUITE["steel-frame"]
    assert sc.body.field is not None and sc.body.position is not None
    rng = np.random.default_rng(1)
    r = np.column_stack([rng.uniform(-1, 1, 20), rng.uniform(-0.3, 0.3, 20),
                         rng.uniform(0.5, 1.6, 20)])
    d = 1e-5
    jac = np.stack([(sc.body.field(r + d * e) - sc.body.field(r - d * e)) / (2 * d)
                    for e in np.eye(3)], axis=-1)  # jac[n, i, j] = ∂B_i/∂x_j
    scale = np.abs(jac).max()
    assert abs(np.trace(jac, axis1=1, axis2=2)).max() < 1e-6 * scale
    assert abs(jac - np.swapaxes(jac, 1, 2)).max() < 1e-6 * scale
    rec = S.record(sc, noise=False)
    dist = np.linalg.norm(sc.body.field_n(rec.t) - S.EARTH_FIELD_UT, axis=1)
    earth = np.linalg.norm(S.EARTH_FIELD_UT)
    assert 0.6 * earth < dist.max() <= 0.8 * earth * (1 + 1e-9)
    assert dist[0] < 0.02 * earth  # at the walk's end, 4 m away


@pytest.mark.parametrize("name", NAMES)
def test_every_scenario_starts_at_rest(name):
    """Until ``rest_s``: no rotation and the specific force is gravity alone."""
    sc = SUITE[name]
    rec = S.record(sc, noise=False, duration_s=sc.rest_s - 1e-6)
    assert rec.t[-1] >= sc.rest_s - rec.h - 1e-6
    np.testing.assert_allclose(rec.gyro, 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(rec.acc, axis=1), G, rtol=0, atol=1e-12)


def test_the_suite_covers_the_issue():
    """Every kind, pendulums spanning 0.3–1.5 m and 20–70°, rates of 50–400 Hz, fields in
    several units."""
    kinds = {sc.kind for sc in SUITE.values()}
    assert kinds == set(S.SCENARIO_KINDS)
    pend = [sc.parameters for sc in SUITE.values() if sc.kind == "pendulum"]
    assert {p["length m"] for p in pend} >= {0.3, 1.5}
    assert {p["amplitude deg"] for p in pend} >= {20.0, 70.0}
    rates = {sc.sensors.rate_hz for sc in SUITE.values()}
    assert min(rates) <= 51 and max(rates) >= 400
    assert len({sc.sensors.mag_unit for sc in SUITE.values()}) >= 3


def test_same_seed_same_recording_other_seed_other_noise():
    """Determinism by seed: the recording and the seeded motions (hand-held phases, the
    frame's remanence) repeat; another seed changes the noise and those motions."""
    sc = SUITE["steel-frame"]
    a = S.record(sc, 7, duration_s=10.0)
    b = S.record(sc, 7, duration_s=10.0)
    c = S.record(sc, 8, duration_s=10.0)
    for x in ("gyro", "acc", "mag", "gyro_bias", "q_n_b"):
        np.testing.assert_array_equal(getattr(a, x), getattr(b, x))
    assert not np.array_equal(a.gyro, c.gyro)
    np.testing.assert_array_equal(a.q_n_b, c.q_n_b)
    s1, s2, s3 = (S.suite(7), S.suite(7), S.suite(8))
    t = np.linspace(0.0, 30.0, 50)
    for i in (6, 7):  # hand-held, steel frame
        np.testing.assert_array_equal(s1[i].body.attitude(t), s2[i].body.attitude(t))
        np.testing.assert_array_equal(s1[i].body.field_n(t), s2[i].body.field_n(t))
        assert not np.array_equal(s1[i].body.attitude(t), s3[i].body.attitude(t))


def test_sensor_errors_have_the_stated_size():
    """Gyro noise ≈ density/√h about the true bias (constant plus slow), accelerometer noise
    ≈ density/√h, magnetometer noise as stated (in the scenario's unit)."""
    sc = SUITE["rests"]
    ideal = S.record(sc, noise=False)
    rec = S.record(sc, 3)
    s = sc.sensors
    g_err = rec.gyro - ideal.gyro - rec.gyro_bias
    np.testing.assert_allclose(g_err.std(0), s.gyro_noise / math.sqrt(rec.h), rtol=0.05)
    assert np.abs(rec.gyro_bias).max() > 0
    a_err = rec.acc - ideal.acc
    np.testing.assert_allclose((a_err - a_err.mean(0)).std(0), s.acc_noise / math.sqrt(rec.h),
                               rtol=0.05)
    m_err = (rec.mag - ideal.mag) / s.mag_unit
    np.testing.assert_allclose(m_err.std(0), s.mag_noise, rtol=0.05)


def _assert_drawn_sizes(scenario, attr: str, scale: float, cross: float):
    """Over 200 seeds the drawn matrix's diagonal less one and its off-diagonal entries have
    standard deviations ``scale`` and ``cross`` (within 15 %)."""
    mats = np.array([getattr(S.record(scenario, s, duration_s=0.05), attr) - np.eye(3)
                     for s in range(200)])
    off = ~np.eye(3, dtype=bool)
    assert 0.85 * scale < mats[:, ~off].std() < 1.15 * scale
    assert 0.85 * cross < mats[:, off].std() < 1.15 * cross


def test_gyro_scale_and_cross_axis_errors_multiply_the_true_rate_and_bias():
    """With ``gyro_scale_sd`` and ``gyro_misalignment_sd`` the gyro reads ``M (ω + b) + n``:
    the same noise, bias, accelerometer and field as without them (M is drawn last), the
    difference exactly ``(M − I)(ω + b)``, M's diagonal and off-diagonal of the stated
    sizes over many seeds; without them M is the identity."""
    sc = SUITE["spin-coning"]
    bad = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, gyro_scale_sd=0.01, gyro_misalignment_sd=0.005))
    dur = sc.rest_s + 2.0  # the rest, then two seconds of spin
    ideal = S.record(sc, noise=False, duration_s=dur)
    plain = S.record(sc, 5, duration_s=dur)
    rec = S.record(bad, 5, duration_s=dur)
    np.testing.assert_array_equal(plain.gyro_matrix, np.eye(3))
    for x in ("acc", "mag", "gyro_bias", "q_n_b"):
        np.testing.assert_array_equal(getattr(rec, x), getattr(plain, x))
    err = rec.gyro_matrix - np.eye(3)
    np.testing.assert_allclose(rec.gyro - plain.gyro, (ideal.gyro + plain.gyro_bias) @ err.T,
                               rtol=0, atol=1e-12)
    assert np.abs(rec.gyro - plain.gyro).max() > 1e-3  # the spin reads visibly off
    _assert_drawn_sizes(bad, "gyro_matrix", scale=0.01, cross=0.005)
    with pytest.raises(ValueError, match="gyro_scale_sd"):
        S.Sensors(100.0, gyro_scale_sd=-0.01)


def test_accelerometer_scale_and_cross_axis_errors_multiply_the_true_force_and_bias():
    """With ``acc_scale_sd`` and ``acc_misalignment_sd`` the accelerometer reads
    ``M_a (f + b_a) + n``: every other draw as without them (``M_a`` is drawn after the
    gyro's), the difference exactly ``(M_a − I)(f + b_a)`` with the recorded bias, ``M_a``'s
    diagonal and off-diagonal of the stated sizes over many seeds; without them the
    identity."""
    sc = SUITE["rests"]
    bad = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, acc_scale_sd=0.01, acc_misalignment_sd=0.005, gyro_scale_sd=0.01))
    gyro_only = dataclasses.replace(sc, sensors=dataclasses.replace(
        sc.sensors, gyro_scale_sd=0.01))
    dur = 16.0  # a rest, a turn and the next rest
    ideal = S.record(sc, noise=False, duration_s=dur)
    plain = S.record(gyro_only, 5, duration_s=dur)
    rec = S.record(bad, 5, duration_s=dur)
    np.testing.assert_array_equal(plain.acc_matrix, np.eye(3))
    for x in ("gyro", "mag", "gyro_bias", "gyro_matrix", "acc_bias", "q_n_b"):
        np.testing.assert_array_equal(getattr(rec, x), getattr(plain, x))
    np.testing.assert_allclose(np.linalg.norm(plain.acc_bias), np.linalg.norm(
        (plain.acc - ideal.acc).mean(0)), rtol=0.05)  # the recorded bias is the one applied
    err = rec.acc_matrix - np.eye(3)
    np.testing.assert_allclose(rec.acc - plain.acc, (ideal.acc + plain.acc_bias) @ err.T,
                               rtol=0, atol=1e-12)
    assert np.abs(rec.acc - plain.acc).max() > 0.02  # gravity reads visibly off
    ideal_bad = S.record(bad, noise=False, duration_s=0.05)
    assert not np.any(ideal_bad.acc_bias)
    np.testing.assert_array_equal(ideal_bad.acc_matrix, np.eye(3))
    _assert_drawn_sizes(bad, "acc_matrix", scale=0.01, cross=0.005)
    with pytest.raises(ValueError, match="acc_misalignment_sd"):
        S.Sensors(100.0, acc_misalignment_sd=-0.01)


def test_record_refuses_a_duration_beyond_the_scenario():
    with pytest.raises(ValueError, match="exceeds"):
        S.record(SUITE["rests"], duration_s=1000.0)


def test_interval_integrals_are_exact_for_a_polynomial_of_degree_23():
    """``motions.interval_integrals`` (the gyro's increments and an interval
    accelerometer's samples): twelve Gauss–Legendre nodes per interval integrate a
    polynomial of degree 2·12 − 1 to round-off (closed form: the antiderivative's
    difference)."""
    from strapdown.truth.motions import QUADRATURE_NODES, interval_integrals

    t, h = np.linspace(0.1, 2.0, 7), 0.05
    c = np.random.default_rng(3).normal(size=2 * QUADRATURE_NODES)  # degree 23

    def f(s):
        return np.stack([np.polyval(c, s), np.polyval(c[-4:], s), np.ones_like(s)], -1)

    P = np.polyint(c)
    want = np.polyval(P, t) - np.polyval(P, t - h)
    got = interval_integrals(f, t - h, t)
    assert QUADRATURE_NODES == 12
    np.testing.assert_allclose(got[:, 0], want, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got[:, 2], h, rtol=1e-14, atol=0)


def test_interval_accelerometer_sample_is_the_mean_specific_force():
    """``Sensors(acc_sample="interval")``: each noise-free sample is the specific force
    averaged over its period — here against a 200-point midpoint sum — and differs from the
    point sample where the body turns (the rests' quintic turn at 50 Hz)."""
    import dataclasses

    sc = S.rests(duration_s=16.0)
    iv = dataclasses.replace(sc, sensors=dataclasses.replace(sc.sensors, acc_sample="interval"))
    a, b = S.record(sc, 0, noise=False), S.record(iv, 0, noise=False)
    k = np.flatnonzero((a.t > 12.5) & (a.t < 13.5))
    h = a.h
    mid = a.t[k, None] - h + (np.arange(200) + 0.5) * h / 200
    want = sc.body.specific_force(mid.ravel()).reshape(k.size, 200, 3).mean(axis=1)
    np.testing.assert_allclose(b.acc[k], want, rtol=0, atol=1e-6)
    assert np.max(np.abs(a.acc[k] - b.acc[k])) > 0.05
    rest = a.t < 12.0  # at rest they agree, to the quadrature weights' round-off
    np.testing.assert_allclose(b.acc[rest], a.acc[rest], rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match="acc_sample must be 'point' or 'interval'"):
        dataclasses.replace(sc.sensors, acc_sample="mean")
