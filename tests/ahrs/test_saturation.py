"""A gyro past its range (:mod:`strapdown.ahrs.saturation`): the plateaus it leaves are found
and ``ekf`` / ``offline_ekf`` warn; smooth peaks, steady turns and spins, and slow
constant-rate legs are not taken for it; the rate beyond the range is taken from the field
(``declip``, ``AhrsConfig.gyro_declip``); near a clipped sample ``ekf`` suspends its
low-pass accelerometer's norm test and ``offline_ekf`` takes its tilt from the accelerometer
(``AhrsConfig.gyro_range``, ``gyro_clip_s``)."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, GyroSaturationWarning, ekf, offline_ekf
from strapdown.ahrs.saturation import (
    DECLIP_ACROSS,
    MIN_LEVEL,
    clipped,
    declip,
    field_plateaus,
    gyro_plateaus,
    gyro_range,
)
from strapdown.analysis.broad import broad_errors
from strapdown.rotation.quaternion import (
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_rotate,
)
from suite_records import clipped_pendulum, suite_record


def _rocking(amplitude_rate: float, clip: float | None, n: int = 3000, h: float = 0.01):
    """A body rocking about its x axis at 1 Hz, its rate peaking at ``amplitude_rate``
    (rad/s), read by a gyro clipped at ``clip``; t, gyro, acc (gravity's specific force)."""
    t = np.arange(n) * h
    om = 2 * math.pi
    theta = amplitude_rate / om * np.sin(om * t)
    q = quat_from_rotvec(np.outer(theta, [1.0, 0.0, 0.0]))
    rng = np.random.default_rng(3)
    rate = amplitude_rate * np.cos(om * t) + 2e-4 * rng.normal(size=n)
    if clip is not None:
        rate = np.clip(rate, -clip, clip)
    gyro = np.column_stack([rate, 2e-4 * rng.normal(size=n), 2e-4 * rng.normal(size=n)])
    acc = 9.80665 * quat_rotate(quat_conjugate(q), np.array([0.0, 0.0, 1.0]))
    return t, gyro, acc


def test_a_clipped_gyro_is_found_and_warned_about():
    """A rate of 10 rad/s amplitude clipped at 7: the x axis, level 7 rad/s, two plateaus a
    cycle (0.12 s each, entered by a 0.4 rad/s step); both filters warn, naming the axis
    and the level."""
    t, gyro, acc = _rocking(10.0, 7.0)
    (p,) = gyro_plateaus(gyro)
    assert p.axis == 0 and p.level == pytest.approx(7.0, abs=1e-3)
    assert p.runs >= 2 * 29  # two a cycle, 30 cycles (the first may start on one)
    for run in (ekf, offline_ekf):
        with pytest.warns(GyroSaturationWarning, match=r"axis x stops at 7 rad/s"):
            run(t, gyro, acc)


@pytest.mark.parametrize("amplitude,clip", [(10.0, None), (6.0, 7.0), (1.0, 0.7)])
def test_smooth_peaks_and_slow_plateaus_are_not_clipping(amplitude, clip):
    """The same rocking unclipped, or with a range above its peak rate: smooth peaks, no
    plateau; clipped at 0.7 rad/s, below ``MIN_LEVEL`` (no gyro's range is so low): not
    reported."""
    assert clip is None or clip > amplitude or clip < MIN_LEVEL
    t, gyro, acc = _rocking(amplitude, clip)
    assert gyro_plateaus(gyro) == []
    with warnings.catch_warnings():
        warnings.simplefilter("error", GyroSaturationWarning)
        ekf(t, gyro, acc)


@pytest.mark.parametrize("name", ["loiter", "spin-coning", "vehicle", "pendulum-0.3m-70deg"])
def test_the_suites_steady_turns_and_spins_are_not_clipping(name):
    """A steady turn (the loiter: 0.17 rad/s; the vehicle) and a steady spin (9.4 rad/s,
    spun up over 3 s) are flat but not entered by a step; the 0.3 m pendulum's undamped
    peaks (5 rad/s, every swing the same) are smooth."""
    assert gyro_plateaus(suite_record(name).gyro) == []


def test_the_clipped_samples_are_those_at_the_range():
    """``gyro_range``: the found axis's level (7 rad/s); ``clipped``: the samples within 2 %
    of it or beyond; none at no range (0 or infinite)."""
    _, gyro, _ = _rocking(10.0, 7.0)
    level = gyro_range(gyro_plateaus(gyro))
    assert level == pytest.approx(7.0, abs=1e-3)
    mask = clipped(gyro, level)
    np.testing.assert_array_equal(mask, np.any(np.abs(gyro) >= 0.98 * level, axis=1))
    # |10 cos 2πt| ≥ 6.86 on 50 of the 100 samples of each cycle (k ≤ 12, 38–62, ≥ 88: at
    # k = 13 it is 6.845, far from the threshold against the 2e-4 noise)
    assert mask.mean() == 0.5
    assert gyro_range([]) == 0.0
    assert not clipped(gyro, 0.0).any() and not clipped(gyro, math.inf).any()


def _total(q, truth, t):
    return broad_errors(q, truth, t >= 5.0)["total_deg"]


def test_near_a_clipped_gyro_the_attitude_is_distrusted():
    """The suite's 0.3 m pendulum read by a gyro clipped at 60 % of its peak rate, from 5 s,
    without the field's rate (``gyro_declip=False``), total RMSE [m]: causal 11.8° with the
    rule, 15.6° without (VQF 11.8°): without it the low-pass accelerometer's norm test
    calls the smeared specific force disturbed and the tilt runs on the clipped gyro;
    offline 11.8° against 15.4° (offlineVQF 11.9°). The rest is the swing the gyro never
    reads. The range found from the record acts as the range given does."""
    t, gyro, acc, mag, truth, level = clipped_pendulum()
    base = AhrsConfig(gyro_declip=False)
    off = replace(base, gyro_clip_s=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        for run in (ekf, offline_ekf):
            on = run(t, gyro, acc, mag, config=base)
            assert _total(on.q, truth, t) < 12.5
            assert _total(run(t, gyro, acc, mag, config=off).q, truth, t) > 14.5
            given = run(t, gyro, acc, mag, config=replace(base, gyro_range=level))
            np.testing.assert_array_equal(given.q, on.q)
            none = run(t, gyro, acc, mag, config=replace(base, gyro_range=math.inf))
            assert _total(none.q, truth, t) > 14.5


def _spin(rate: float, field, n: int = 400, h: float = 0.01, wobble: float = 0.0):
    """A body spinning about its x axis at ``rate`` (rad/s) while turning about its y axis
    at ``wobble`` (a constant body rate), the field ``field`` (reference frame) read
    exactly; the attitude from the closed form, the gyro the exact (constant) rate."""
    t = np.arange(n) * h
    w = np.array([rate, wobble, 0.0])
    q = quat_from_rotvec(np.outer(t, w))  # a constant body rate: q(t) = exp(t w / 2)
    mag = quat_rotate(quat_conjugate(q), np.asarray(field, dtype=float))
    return t, np.tile(w, (n, 1)), mag, q


def test_declip_recovers_an_exact_spin():
    """A spin at 12 rad/s (0.12 rad per sample) about x read by a gyro clipped at 7, the
    field at 60° to the axis: every clipped sample after the first recovers the rate to
    1e-12 relative (the chord and the mean: ``(2/h) atan(u h/2)`` is exact for a turn
    about the axis alone); the first sample has no field before it and stays as read; the
    units of the field cancel."""
    field = [math.cos(math.radians(60.0)), 0.0, -math.sin(math.radians(60.0))]
    _t, w, mag, _ = _spin(12.0, field)
    read = np.clip(w, -7.0, 7.0)
    got, done = declip(read, mag, 7.0, 0.01)
    assert done[1:, 0].all() and not done[0].any() and not done[:, 1:].any()
    np.testing.assert_allclose(got[1:, 0], 12.0, rtol=1e-12)
    assert got[0, 0] == 7.0
    np.testing.assert_array_equal(got[:, 1:], read[:, 1:])
    np.testing.assert_allclose(declip(read, 1e4 * mag, 7.0, 0.01)[0], got, rtol=1e-12)
    # the sign: the opposite spin
    got_neg, _ = declip(-read, _spin(-12.0, field)[2], 7.0, 0.01)
    np.testing.assert_allclose(got_neg[1:, 0], -12.0, rtol=1e-12)


def test_declip_with_a_second_axis_turning():
    """The same spin while the body also turns at 1 rad/s about y (read, unclipped): the
    rate about x recovered to 1e-4 relative (the unclipped y reading is in the Cayley
    vector unstretched) where the clipped reading was 42 % short; the attitude integrated
    from the recovered rates from the first recovered sample on ends within 0.03° of the
    closed form after 4 s (48 rad of spin)."""
    from strapdown.algorithms.rate import rate_attitude

    field = [0.3, 0.5, -0.8]
    t, w, mag, q = _spin(12.0, field, wobble=1.0)
    got, done = declip(np.clip(w, -7.0, 7.0), mag, 7.0, 0.01)
    assert done[1:, 0].all()
    np.testing.assert_allclose(got[1:, 0], 12.0, rtol=1e-4)
    q_est = rate_attitude(t[1:], got[1:], q0=q[1], algorithm="rate-single").q
    e = quat_multiply(quat_conjugate(q[-1]), q_est[-1])
    assert 2 * math.degrees(math.acos(min(1.0, abs(e[0])))) < 0.03  # measured 0.016°


def test_declip_leaves_what_the_field_cannot_tell():
    """A field along the clipped axis (its part across below ``DECLIP_ACROSS``) turns too
    little about it: kept as read; so are samples clipped on two axes when the field has no
    part along the third, on all three, and everything when no range is known (0 or
    infinite) or the field is not finite there, or held (a sample equal to the one before:
    a magnetometer slower than the gyro)."""
    _t, w, mag, _ = _spin(12.0, [1.0, 0.0, 0.0])
    read = np.clip(w, -7.0, 7.0)
    assert DECLIP_ACROSS > 0.0
    got, done = declip(read, mag + np.array([0.0, 0.0, 0.05]), 7.0, 0.01)  # across: 0.05
    assert not done.any()
    np.testing.assert_array_equal(got, read)
    # two clipped axes, x and y, and a field with no part along z: the field cannot tell
    # a turn about x from one about y there; three clipped axes never
    both = read.copy()
    both[:, 1] = 7.0
    assert not declip(both, mag, 7.0, 0.01)[1].any()
    every = np.full_like(read, 7.0)
    assert not declip(every, _spin(12.0, [0.5, 0.0, -0.8])[2], 7.0, 0.01)[1].any()
    for level in (0.0, math.inf):
        assert not declip(read, mag, level, 0.01)[1].any()
    holed = _spin(12.0, [0.5, 0.0, -0.8])[2]
    holed[5] = np.nan
    _, done = declip(read, holed, 7.0, 0.01)
    assert not done[5:7].any() and done[4, 0] and done[7, 0]
    # a magnetometer at half the gyro's rate, each sample held once: no fresh pair
    held = _spin(12.0, [0.5, 0.0, -0.8])[2]
    held[1::2] = held[0:-1:2]
    assert not declip(read, held, 7.0, 0.01)[1].any()
    with pytest.raises(ValueError, match=r"same shape \(n, 3\)"):
        declip(read, mag[:-1], 7.0, 0.01)


def test_the_fields_rate_beyond_the_range_corrects_the_pendulum():
    """The suite's 0.3 m pendulum clipped at 60 % (3.3 rad/s; its swing peaks at 5.5 rad/s,
    every swing clipped), from 5 s, total RMSE [m]: with the field's rate causal 2.1°,
    offline 1.1°, against 11.8° and 11.8° without it (VQF 11.8°, offlineVQF 11.9°, which
    read the clipped gyro)."""
    t, gyro, acc, mag, truth, level = clipped_pendulum()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        causal, offline = ekf(t, gyro, acc, mag), offline_ekf(t, gyro, acc, mag)
        assert _total(causal.q, truth, t) < 2.5
        assert _total(offline.q, truth, t) < 1.3
        # the result counts the samples at the range (found: 0.2 % below the clip level)
        # and those recovered: every one, the field lying across the swing's axes
        n = int(clipped(gyro, level).sum())
        for res in (causal, offline):
            assert res.gyro_clipped >= n > 3000 and res.gyro_recovered == res.gyro_clipped
        kept = ekf(t, gyro, acc, mag, config=AhrsConfig(gyro_declip=False))
        assert kept.gyro_clipped == causal.gyro_clipped and kept.gyro_recovered == 0
        # without a field there is nothing to take it from
        six = ekf(t, gyro, acc, config=AhrsConfig(gyro_declip=True))
        np.testing.assert_array_equal(
            six.q, ekf(t, gyro, acc, config=AhrsConfig(gyro_declip=False)).q)


@pytest.mark.parametrize("run", [ekf, offline_ekf])
def test_an_unclipped_record_is_the_same_at_any_clip_window(run):
    """Unclipped, no range is found and nothing changes; a range above every rate neither."""
    rec = suite_record("pendulum-0.3m-70deg", duration_s=20.0)
    args = (rec.t, rec.gyro, rec.acc, rec.mag)
    a = run(*args)
    assert a.gyro_clipped == a.gyro_recovered == 0
    np.testing.assert_array_equal(a.q, run(*args, config=AhrsConfig(gyro_clip_s=0.0)).q)
    np.testing.assert_array_equal(a.q, run(*args, config=AhrsConfig(gyro_range=100.0)).q)


@pytest.mark.parametrize("field,bad", [("gyro_clip_s", -1.0), ("gyro_clip_s", math.nan),
                                       ("gyro_clip_s", math.inf), ("gyro_range", -1.0),
                                       ("gyro_range", math.nan)])
def test_bad_clip_settings_are_named(field, bad):
    with pytest.raises(ValueError, match=field):
        AhrsConfig(**{field: bad})


def test_bad_shape_names_the_expected_shape():
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        gyro_plateaus(np.zeros((5, 2)))


def test_a_spin_beyond_the_range_with_the_range_given():
    """The suite's spin-coning (9.4 rad/s about a body axis, 400 Hz) read by a gyro clipped
    at 80 % of its peak rate (7.5 rad/s), the range given (the spin-up's steps into the
    plateaus are under 2 %: the steps do not find it; the field does, below), from 5 s
    [m]: causal 1.1°, offline 1.1° (VQF 104.5°, offlineVQF 104.4°, reading the clipped
    gyro; ours without the field's rates 104.7°): the field comes within 8.2° of the spin
    axis once a coning cycle, and every clipped sample is recovered."""
    rec = suite_record("spin-coning")
    level = 0.8 * float(np.abs(rec.gyro).max())
    gyro = np.clip(rec.gyro, -level, level)
    assert gyro_plateaus(gyro) == []
    _, done = declip(gyro, rec.mag, level, rec.t[1] - rec.t[0])
    assert done.any(axis=1).sum() == clipped(gyro, level).sum()
    cfg = AhrsConfig(gyro_range=level)
    kept = replace(cfg, gyro_declip=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)  # the field finds it too
        assert _total(ekf(rec.t, gyro, rec.acc, rec.mag, config=cfg).q, rec.q_n_b,
                      rec.t) < 1.5
        assert _total(offline_ekf(rec.t, gyro, rec.acc, rec.mag, config=cfg).q, rec.q_n_b,
                      rec.t) < 1.5
        assert _total(ekf(rec.t, gyro, rec.acc, rec.mag, config=kept).q, rec.q_n_b,
                      rec.t) > 90.0


def _spin_up(top: float, clip: float | None, n: int = 600, h: float = 0.01):
    """A body spun up about its x axis from rest to ``top`` rad/s over 2 s (a smooth ramp)
    and held there, read by a gyro clipped at ``clip``, the field [0.5, 0, −0.8] read
    exactly; t, gyro, field."""
    t = np.arange(n) * h
    rate = top * np.minimum(t / 2.0, 1.0) ** 2 * (3.0 - 2.0 * np.minimum(t / 2.0, 1.0))
    angle = np.concatenate([[0.0], np.cumsum(0.5 * h * (rate[1:] + rate[:-1]))])
    q = quat_from_rotvec(np.outer(angle, [1.0, 0.0, 0.0]))
    mag = quat_rotate(quat_conjugate(q), np.array([0.5, 0.0, -0.8]))
    gyro = np.column_stack([rate, np.zeros(n), np.zeros(n)])
    if clip is not None:
        gyro = np.clip(gyro, -clip, clip)
    return t, gyro, mag


def test_a_smooth_spin_up_past_the_range_is_found_by_the_field():
    """Spun up smoothly to 12 rad/s, read by a gyro clipped at 7: no step enters the
    plateau, so :func:`gyro_plateaus` finds nothing, but over the 4.4 s at the range the
    field turns 12/7 times faster than the gyro reads: :func:`field_plateaus` finds axis x
    at 7 rad/s. Unclipped, the steady 12 rad/s is a flat plateau too, and the field turns as
    the gyro reads (ratio 1 to round-off): nothing found; nor without enough plateau."""
    _t, gyro, mag = _spin_up(12.0, 7.0)
    assert gyro_plateaus(gyro) == []
    (p,) = field_plateaus(gyro, mag, 0.01)
    assert p.axis == 0 and p.level == pytest.approx(7.0, rel=1e-4)  # a run starts 0.2 % below
    _, steady, mag_steady = _spin_up(12.0, None)
    assert field_plateaus(steady, mag_steady, 0.01) == []
    # the ramp reaches the range at 1.11 s: the first 1.5 s hold 0.4 s at it
    assert field_plateaus(gyro[:150], mag[:150], 0.01) == []
    assert field_plateaus(gyro[:200], mag[:200], 0.01) != []  # 0.9 s


def test_the_spin_coning_past_the_range_is_found_and_recovered():
    """The suite's spin-coning read by a gyro clipped at 80 % of its peak rate, no range
    given: its spin-up steps into the plateau by under 2 %, not found by the steps, found
    by the field (the field turns 1.25 times faster than the gyro reads there [m]); both
    filters warn and take the rate from the field: from 5 s, 1.1° causal and offline [m]
    (VQF 104.5°), as with the range given. The unclipped spin is not found."""
    rec = suite_record("spin-coning")
    h = rec.t[1] - rec.t[0]
    assert field_plateaus(rec.gyro, rec.mag, h) == []
    level = 0.8 * float(np.abs(rec.gyro).max())
    gyro = np.clip(rec.gyro, -level, level)
    assert gyro_plateaus(gyro) == []
    (p,) = field_plateaus(gyro, rec.mag, h)
    assert p.level == pytest.approx(level, rel=0.06)
    for run in (ekf, offline_ekf):
        with pytest.warns(GyroSaturationWarning, match="field turns at least 1.1 times"):
            res = run(rec.t, gyro, rec.acc, rec.mag)
        assert _total(res.q, rec.q_n_b, rec.t) < 1.5


def test_no_broad_trial_is_taken_for_clipped():
    """BROAD's fifteen trials (286 Hz): their smooth peaks are flat near the top for at
    most 0.08 s a trial, under ``FIELD_MIN_S``; neither rule finds a range."""
    from conftest import BROAD
    from strapdown.io.broad import read_broad

    if BROAD is None or not any(BROAD.glob("*.mat")):
        pytest.skip("BROAD not found (set STRAPDOWN_BROAD)")
    for f in sorted(BROAD.glob("*.mat")):
        tr = read_broad(f)
        assert gyro_plateaus(tr.gyro) == [], f.name
        assert field_plateaus(tr.gyro, tr.mag, tr.h) == [], f.name
