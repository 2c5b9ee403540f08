"""A gyro past its range (:mod:`strapdown.ahrs.saturation`): the plateaus it leaves are found
and ``ekf`` / ``offline_ekf`` warn; smooth peaks, steady turns and spins, and slow
constant-rate legs are not taken for it; ``offline_ekf`` takes its tilt from the
accelerometer around the clipped samples (``AhrsConfig.offline_clip_s``)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from strapdown.ahrs import AhrsConfig, GyroSaturationWarning, ekf, offline_ekf
from strapdown.ahrs.saturation import MIN_LEVEL, clipped, gyro_plateaus
from strapdown.analysis.broad import broad_errors
from strapdown.rotation.quaternion import quat_conjugate, quat_from_rotvec, quat_rotate


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
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(0)) if s.name == name)
    assert gyro_plateaus(record(sc, np.random.SeedSequence([0, k])).gyro) == []


def test_the_clipped_samples_are_those_at_the_range():
    """``clipped``: the samples of a found axis within 2 % of its level (7 rad/s) or beyond;
    none without a found axis."""
    _, gyro, _ = _rocking(10.0, 7.0)
    found = gyro_plateaus(gyro)
    mask = clipped(gyro, found)
    np.testing.assert_array_equal(mask, np.abs(gyro[:, 0]) >= 0.98 * found[0].level)
    # |10 cos 2πt| ≥ 6.86 on 50 of the 100 samples of each cycle (k ≤ 12, 38–62, ≥ 88: at
    # k = 13 it is 6.845, far from the threshold against the 2e-4 noise)
    assert mask.mean() == 0.5
    assert not clipped(gyro, []).any()


def _clipped_pendulum(seed: int = 0):
    """The suite's 0.3 m pendulum swung 70°, its gyro clipped at 60 % of its peak rate
    (3.3 rad/s): t, gyro, acc, mag, truth."""
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(seed)) if s.name == "pendulum-0.3m-70deg")
    rec = record(sc, np.random.SeedSequence([seed, k]))
    lim = 0.6 * np.abs(rec.gyro).max()
    return rec.t, np.clip(rec.gyro, -lim, lim), rec.acc, rec.mag, rec.q_n_b


def test_offline_takes_the_accelerometers_tilt_near_a_clipped_gyro():
    """Where the gyro is clipped both passes carry the missed rotation on; near it the offline
    tilt is the accelerometer's. The clipped pendulum from 5 s, total RMSE [m]: 11.7° with
    the rule, 15.4° without (offlineVQF 11.9°; the rest is the swing the gyro never reads).
    Unclipped, no axis is found and the output is the same at any window."""
    t, gyro, acc, mag, truth = _clipped_pendulum()
    moving = t >= 5.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        on = offline_ekf(t, gyro, acc, mag)
        off = offline_ekf(t, gyro, acc, mag, config=AhrsConfig(offline_clip_s=0.0))
    e_on = broad_errors(on.q, truth, moving)["total_deg"]
    e_off = broad_errors(off.q, truth, moving)["total_deg"]
    assert e_on < 12.5 and e_off > 14.5
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(0)) if s.name == "pendulum-0.3m-70deg")
    rec = record(sc, np.random.SeedSequence([0, k]), duration_s=20.0)
    a = offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag)
    b = offline_ekf(rec.t, rec.gyro, rec.acc, rec.mag, config=AhrsConfig(offline_clip_s=0.0))
    np.testing.assert_array_equal(a.q, b.q)


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf])
def test_a_bad_clip_window_is_named(bad):
    with pytest.raises(ValueError, match="offline_clip_s"):
        AhrsConfig(offline_clip_s=bad)


def test_bad_shape_names_the_expected_shape():
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        gyro_plateaus(np.zeros((5, 2)))
