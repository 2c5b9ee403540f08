"""A gyro past its range (:mod:`strapdown.ahrs.saturation`): the plateaus it leaves are found
and ``ekf`` / ``offline_ekf`` warn; smooth peaks, steady turns and spins, and slow
constant-rate legs are not taken for it; near a clipped sample ``ekf`` suspends its
low-pass accelerometer's norm test and ``offline_ekf`` takes its tilt from the accelerometer
(``AhrsConfig.gyro_range``, ``gyro_clip_s``)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, GyroSaturationWarning, ekf, offline_ekf
from strapdown.ahrs.saturation import MIN_LEVEL, clipped, gyro_plateaus, gyro_range
from strapdown.analysis.broad import broad_errors
from strapdown.rotation.quaternion import quat_conjugate, quat_from_rotvec, quat_rotate
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
    total RMSE [m]: causal 11.8° with the rule, 15.6° without (VQF 11.8°): without it the
    low-pass accelerometer's norm test calls the smeared specific force disturbed and the
    tilt runs on the clipped gyro; offline 11.8° against 15.4° (offlineVQF 11.9°). The rest
    is the swing the gyro never reads. The range found from the record acts as the range
    given does."""
    t, gyro, acc, mag, truth, level = clipped_pendulum()
    off = AhrsConfig(gyro_clip_s=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        for run in (ekf, offline_ekf):
            on = run(t, gyro, acc, mag)
            assert _total(on.q, truth, t) < 12.5
            assert _total(run(t, gyro, acc, mag, config=off).q, truth, t) > 14.5
            given = run(t, gyro, acc, mag, config=AhrsConfig(gyro_range=level))
            np.testing.assert_array_equal(given.q, on.q)
            none = run(t, gyro, acc, mag, config=AhrsConfig(gyro_range=math.inf))
            assert _total(none.q, truth, t) > 14.5


@pytest.mark.parametrize("run", [ekf, offline_ekf])
def test_an_unclipped_record_is_the_same_at_any_clip_window(run):
    """Unclipped, no range is found and nothing changes; a range above every rate neither."""
    rec = suite_record("pendulum-0.3m-70deg", duration_s=20.0)
    args = (rec.t, rec.gyro, rec.acc, rec.mag)
    a = run(*args)
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
