"""The generated AHRS C (``export-c --algorithm ahrs``) against the library's ``ekf``, row by
row: double to 1e-8 rad at every sample (the harness that catches a kernel change the C
does not follow), float within 0.05° mean and 0.5° max, on the shared BROAD trials and on
simulated recordings over the filter's options."""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from ahrs_harness import Stream, angle, build, run

from conftest import BROAD
from strapdown.ahrs import AhrsConfig, GyroSaturationWarning, ekf
from strapdown.ahrs import _kernel as K
from strapdown.algorithms.rate import check_rate_record
from strapdown.codegen.ahrs_c import generate_ahrs
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.quaternion import quat_from_rotvec
from strapdown.truth.motions import SpinConing
from suite_records import clipped_pendulum, released_pendulum, steep_soft_iron_pendulum

TEMPLATE = Path(K.__file__).parents[1] / "codegen" / "templates" / "ahrs.c.in"
WAIT, ERR_INPUT, ERR_NUMERIC = 1, -1, -3
DOUBLE_RAD = 1e-8
FLOAT_MEAN_DEG, FLOAT_MAX_DEG = 0.05, 0.5
TRIALS = sorted(BROAD.glob("*.mat")) if BROAD is not None else []


def _compare(res, q, rc, fl, w):
    """Errors (rad) of the C rows against the library's from the window's last sample on;
    the return codes and flags checked on the way."""
    assert np.all(rc[: w - 1] == WAIT), np.unique(rc[: w - 1])
    assert np.all(rc[w - 1:] == 0), np.unique(rc[w - 1:], return_counts=True)
    return angle(res.q[w - 1:], q[w - 1:])


@pytest.fixture(scope="module")
def broad_builds(tmp_path_factory):
    """Double and float modules for a sample period, built once per period (the trials'
    periods, taken from their stamps as the library does, differ in the last bit)."""
    folder = tmp_path_factory.mktemp("ahrs_broad")
    cache: dict[float, dict] = {}

    def get(h):
        if h not in cache:
            cache[h] = {real: build(folder / f"{len(cache)}", h=h, real=real,
                                    name=f"broad_{real}") for real in ("double", "float")}
        return cache[h]

    return get


@pytest.mark.skipif(BROAD is None, reason="BROAD data not found (set STRAPDOWN_BROAD)")
@pytest.mark.parametrize("trial", TRIALS, ids=lambda p: p.stem[:2])
def test_broad_trial_equals_library(trial, broad_builds):
    from strapdown.io.broad import read_broad

    tr = read_broad(trial)
    h = check_rate_record(tr.t, tr.gyro, min_samples=4).td
    res = ekf(tr.t, tr.gyro, tr.acc, tr.mag)
    for real, (e, lib) in broad_builds(h).items():
        q, rc, fl = run(e, lib, tr.gyro, tr.acc, tr.mag)
        err = _compare(res, q, rc, fl, e.init_samples)
        if real == "double":
            assert err.max() <= DOUBLE_RAD, (err.max(), int(err.argmax()))
            np.testing.assert_array_equal(fl[e.init_samples - 1:],
                                          res.flags[e.init_samples - 1:])
        else:
            deg = np.degrees(err)
            assert deg.mean() <= FLOAT_MEAN_DEG and deg.max() <= FLOAT_MAX_DEG, (deg.mean(),
                                                                                deg.max())


def simulated(n=6000, fs=200.0, seed=7, rest_s=5.0):
    """A recording with exact motion, noise and a gyro bias: rest, then spin and coning; a
    magnetic disturbance and a linear-acceleration burst on the way."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    tm = np.maximum(t - rest_s, 0.0)
    q = m.attitude(tm)
    w = np.where((t > rest_s)[:, None], m.rate(tm), 0.0)
    c = dcm_from_quat(q)
    f_n = np.tile([0.0, 0.0, 9.80665], (n, 1))
    burst = (t > 15) & (t < 16)
    f_n[burst, 0] += 3.0
    b_n = np.tile([0.0, 20.0, -40.0], (n, 1))
    b_n[(t > 20) & (t < 23)] += [15.0, 0.0, 0.0]
    acc = np.einsum("nji,nj->ni", c, f_n) + 0.02 * rng.normal(size=(n, 3))
    mag = np.einsum("nji,nj->ni", c, b_n) + 0.3 * rng.normal(size=(n, 3))
    gyro = w + [0.01, -0.005, 0.003] + 1e-3 * rng.normal(size=(n, 3))
    return t, gyro, acc, mag


SIM = simulated()
#: (algorithm, config changes, magnetometer): the options of ``strapdown ahrs``, 1:1
OPTIONS = [
    ("rate-single", {}, True),
    ("rate-single", {}, False),
    ("rate-three", {}, True),
    ("rate-two", {}, True),
    ("rk4", {}, True),
    ("rate-single", {"acc_model": "raw"}, True),
    ("rate-single", {"estimate_acc_bias": True}, True),
    ("rate-single", {"acc_model": "raw", "estimate_acc_bias": True, "acc_gate_mode": "soft",
                     "acc_sample": "point"}, True),
    ("rate-single", {"gyro_sample": "point", "latency_s": 0.01}, True),
    ("rate-single", {"gating": False, "declination_deg": 12.5}, True),
    ("rate-single", {"estimate_mag_delay": False, "mag_delay_s": 0.02,
                     "mag_disturbed_power": 1.0, "heading_rate_noise": 1e-3}, True),
    ("rate-single", {"rest_update": False, "use_accelerometer": False}, True),
    # issue 25's kernel: the motion-acceleration weight (with point accelerometer samples,
    # turned back half a period), and field samples not turned
    ("rate-single", {"acc_motion_leak": 0.5, "acc_sample": "point"}, True),
    ("rate-single", {"acc_motion_leak": 0.3, "estimate_acc_bias": True, "mag_sample": "interval"},
     True),
    # the bias floor of an uncalibrated gyro on a sustained rotation (a short average, so
    # that the floor binds within the record)
    ("rate-single", {"gyro_scale_sigma": 0.02, "gyro_scale_tau": 0.5}, True),
    # the disturbance (20–23 s; 5.6 % in norm) used de-weighted after a short budget (108
    # epochs), off the gyro bias
    ("rate-single", {"mag_reject_s": 1.0, "mag_norm_tol": 0.03}, True),
]


@pytest.mark.parametrize("algorithm,changes,mag", OPTIONS,
                         ids=lambda v: v if isinstance(v, str) else None)
def test_simulated_equals_library(tmp_path, algorithm, changes, mag):
    t, gyro, acc, m = SIM
    cfg = AhrsConfig(**changes)
    res = ekf(t, gyro, acc, m if mag else None, algorithm=algorithm, config=cfg)
    h = check_rate_record(t, gyro, min_samples=4).td
    for real in ("double", "float"):
        e, lib = build(tmp_path, h=h, real=real, mag=mag, algorithm=algorithm, config=cfg,
                       name=f"sim_{real}", opt="-O1")  # 28 modules; -O2: the BROAD ones
        q, rc, fl = run(e, lib, gyro, acc, m if mag else None)
        err = _compare(res, q, rc, fl, e.init_samples)
        if real == "double":
            assert err.max() <= DOUBLE_RAD, (err.max(), int(err.argmax()))
            np.testing.assert_array_equal(fl[e.init_samples - 1:],
                                          res.flags[e.init_samples - 1:])
        else:
            deg = np.degrees(err)
            assert deg.mean() <= FLOAT_MEAN_DEG and deg.max() <= FLOAT_MAX_DEG
            norm = np.linalg.norm(q[e.init_samples - 1:], axis=1)
            assert np.all(np.abs(norm - 1.0) <= 1e-6)  # the 10^7 run: benchmarks/ahrs_c_stream.py


def moving_start(n=4000, fs=200.0, seed=11):
    """A record that starts in motion (spin and coning from the first sample), holds still
    from 8 s to 12 s (the first rest: gravity measured there) and moves on."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    hold = (t >= 8.0) & (t < 12.0)
    tm = np.where(t < 8.0, t, np.where(hold, 8.0, t - 4.0)) + 1.0
    q = m.attitude(tm)
    w = np.where(hold[:, None], 0.0, m.rate(tm))
    c = dcm_from_quat(q)
    acc = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.7]) + 0.02 * rng.normal(size=(n, 3))
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0]) + 0.3 * rng.normal(size=(n, 3))
    gyro = w + [0.01, -0.005, 0.003] + 1e-3 * rng.normal(size=(n, 3))
    return t, gyro, acc, mag


MOVING = moving_start()


@pytest.mark.parametrize("algorithm,changes,mag", [
    ("rate-single", {}, True), ("rate-single", {}, False), ("rk4", {}, True),
    ("rate-single", {"acc_lowpass_settle": True, "moving_start_sigma0": 0.2}, True),
    ("rate-single", {"moving_start_window_s": 0.3}, True)],
    ids=lambda v: v if isinstance(v, str) else None)
def test_a_start_in_motion_equals_library(tmp_path, algorithm, changes, mag):
    """The start in motion (its own window turned by the gyro, the motion power it sets,
    the wider P0, the low-pass's wait, the provisional field reference, gravity nominal
    until the rest at 8 s measures the accelerometer's 9.7 m/s²) row by row as the
    library's, double; also with a moving window shorter than the still test's (the C then
    starts when the still test's window is full and averages the first samples of it)."""
    from strapdown.ahrs import start_is_still

    t, gyro, acc, m = MOVING
    cfg = AhrsConfig(**changes)
    assert not start_is_still(t, gyro, acc, cfg)
    res = ekf(t, gyro, acc, m if mag else None, algorithm=algorithm, config=cfg)
    assert np.any(res.flags & int(K.F_REST))
    h = check_rate_record(t, gyro, min_samples=4).td
    e, lib = build(tmp_path, h=h, real="double", mag=mag, algorithm=algorithm, config=cfg,
                   name="moving")
    q, rc, fl = run(e, lib, gyro, acc, m if mag else None)
    w = max(e.moving_samples, e.init_samples)  # a start in motion waits for its own window
    assert (w > e.init_samples) == ("moving_start_window_s" not in changes)
    err = _compare(res, q, rc, fl, w)
    assert err.max() <= DOUBLE_RAD, (err.max(), int(err.argmax()))
    np.testing.assert_array_equal(fl[w - 1:], res.flags[w - 1:])


@pytest.mark.parametrize("real", ["double", "float"])
def test_a_still_start_shorter_than_the_window_equals_library(tmp_path, real):
    """A record still for 0.35 s, then swinging (the suite's 0.8 m pendulum, 200 Hz): the
    initial window is not still, its first ``init_still_min_s`` are, and the C starts
    still over those (their means, the bias's σ of that shorter rest) as the library does,
    row by row from the window's last sample: double to ``DOUBLE_RAD`` with the same
    flags, float within the float bounds."""
    from strapdown.ahrs import filter as F

    t, gyro, acc, m, _truth = released_pendulum()
    cfg = AhrsConfig()
    rec = F._validate(t, gyro, acc, m, cfg, "ENU")[0]
    assert not F._still(rec, acc, cfg) and F._still_window(rec, acc, cfg) > 0
    res = ekf(t, gyro, acc, m)
    assert res.start_still
    _c_equals_library(tmp_path, res, t, gyro, acc, m, cfg, real, f"prefix_{real}")


def test_the_tilts_adapted_rate_noise_equals_library(tmp_path):
    """On the suite's swinging 0.8 m pendulum the low-pass innovations' power exceeds
    ``tilt_adapt_level`` for most of the record, so the tilt's rate noise grows
    (``_kernel._tilt_adapt``, ``_innovation_power``): the library's output moves with the
    adaptation switched off, and the C follows the library row by row, double to
    ``DOUBLE_RAD`` with the same flags."""
    t, gyro, acc, m, _truth = released_pendulum()
    res = ekf(t, gyro, acc, m)
    off = ekf(t, gyro, acc, m, config=AhrsConfig(tilt_adapt_level=math.inf))
    assert np.abs(res.q - off.q).max() > 1e-4  # the adaptation acts on this record
    _c_equals_library(tmp_path, res, t, gyro, acc, m, AhrsConfig(), "double", "adapt_double")


def test_the_clipped_gyros_suspended_norm_test_equals_library(tmp_path):
    """A gyro clipped at its range, given as ``gyro_range`` (the C export cannot find it
    from a record): the clipped axes' rates taken from the field (``saturation.declip``,
    one and two axes at once), and within ``gyro_clip_s`` of a clipped sample the low-pass
    model's norm test suspended (``_kernel._fold_clip_samples``). On the suite's 0.3 m
    pendulum clipped at 60 % of its peak rate both act (the library's output moves without
    either), and the C follows the library row by row, double to ``DOUBLE_RAD`` with the
    same flags; so it does without the field's rates, and with every fourth field sample
    held (no rate from a held sample or the one after it)."""
    t, gyro, acc, m, _truth, level = clipped_pendulum(duration_s=20.0)
    cfg = AhrsConfig(gyro_range=level)
    kept = replace(cfg, gyro_declip=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        res = ekf(t, gyro, acc, m, config=cfg)
        off = ekf(t, gyro, acc, m, config=replace(cfg, gyro_clip_s=0.0))
        as_read = ekf(t, gyro, acc, m, config=kept)
    assert np.abs(res.q - off.q).max() > 1e-2  # the rule acts on this record
    assert np.abs(res.q - as_read.q).max() > 1e-2  # so do the field's rates
    _c_equals_library(tmp_path, res, t, gyro, acc, m, cfg, "double", "clip_double")
    _c_equals_library(tmp_path, as_read, t, gyro, acc, m, kept, "double", "clip_read_double")
    # every fourth field sample held (equal to the one before): no rate from it or the next
    held = m.copy()
    held[3::4] = held[2:-1:4]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GyroSaturationWarning)
        res_held = ekf(t, gyro, acc, held, config=cfg)
    _c_equals_library(tmp_path, res_held, t, gyro, acc, held, cfg, "double", "clip_held_double")


def test_the_adapted_heading_variance_equals_library(tmp_path):
    """A swinging body at a steep dip read by a magnetometer with ±8 % soft iron: the
    heading's innovations outgrow its variance and the variance is widened
    (``_kernel._heading_adapt``, ``_heading_power``; the library's output moves without
    it), and the C follows the library row by row, double to ``DOUBLE_RAD`` with the same
    flags."""
    t, gyro, acc, m, _truth = steep_soft_iron_pendulum()
    cfg = AhrsConfig()
    res = ekf(t, gyro, acc, m, config=cfg)
    off = ekf(t, gyro, acc, m, config=replace(cfg, mag_adapt_s=0.0))
    assert np.abs(res.q - off.q).max() > 1e-2  # the rule acts on this record
    _c_equals_library(tmp_path, res, t, gyro, acc, m, cfg, "double", "heading_adapt_double")


def rocking_start(n=4000, fs=100.0, seed=5, scale=1.018):
    """A record that starts in motion and never rests: rocking ±0.5 rad at 0.7 Hz about the
    body's x axis (about the sensor's point: the specific force is gravity's), its
    accelerometer ``scale`` times too long."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    om = 2 * math.pi * 0.7
    c = dcm_from_quat(quat_from_rotvec(np.outer(0.5 * np.sin(om * t), [1.0, 0.0, 0.0])))
    acc = np.einsum("nji,j->ni", c, [0.0, 0.0, scale * 9.80665]) + 0.02 * rng.normal(size=(n, 3))
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0]) + 0.3 * rng.normal(size=(n, 3))
    w = np.column_stack([0.5 * om * np.cos(om * t), 0 * t, 0 * t])
    gyro = w + [0.01, -0.005, 0.003] + 1e-3 * rng.normal(size=(n, 3))
    return t, gyro, acc, mag


@pytest.mark.parametrize("real", ["double", "float"])
def test_a_learned_gravity_equals_library(tmp_path, real):
    """A start in motion with an accelerometer 1.8 % long and no rest: the library learns
    gravity's norm (``_kernel._learn_gravity``) and uses the accelerometer from about 10 s
    on, where with the nominal g it would skip every update; the C export row by row as
    the library: double to ``DOUBLE_RAD`` with the same flags, float within the float
    bounds."""
    from strapdown.ahrs import AccelerometerUnusedWarning

    t, gyro, acc, m = rocking_start()
    res = ekf(t, gyro, acc, m)
    with pytest.warns(AccelerometerUnusedWarning):
        off = ekf(t, gyro, acc, m, config=AhrsConfig(acc_scale_tol=0.0))
    assert not res.start_still
    assert res.fraction(K.F_ACC_USED) > 0.5 > off.fraction(K.F_ACC_USED)
    h = check_rate_record(t, gyro, min_samples=4).td
    e, lib = build(tmp_path, h=h, real=real, mag=True, algorithm="rate-single",
                   config=AhrsConfig(), name=f"learn_{real}")
    q, rc, fl = run(e, lib, gyro, acc, m)
    _equals_library(res, q, rc, fl, max(e.moving_samples, e.init_samples), real)


def _c_equals_library(tmp_path, res, t, gyro, acc, m, cfg, real, name):
    """The 9-axis rate-single module for ``cfg`` built and run on the record: its rows
    equal the library's result ``res`` (:func:`_equals_library`)."""
    h = check_rate_record(t, gyro, min_samples=4).td
    e, lib = build(tmp_path, h=h, real=real, mag=True, algorithm="rate-single", config=cfg,
                   name=name)
    q, rc, fl = run(e, lib, gyro, acc, m)
    _equals_library(res, q, rc, fl, e.init_samples, real)


def _equals_library(res, q, rc, fl, w, real):
    """The C rows from the ``w``-th sample on against the library's: double to
    ``DOUBLE_RAD`` with the same flags, float within the float bounds."""
    err = _compare(res, q, rc, fl, w)
    if real == "double":
        assert err.max() <= DOUBLE_RAD, (err.max(), int(err.argmax()))
        np.testing.assert_array_equal(fl[w - 1:], res.flags[w - 1:])
    else:
        deg = np.degrees(err)
        assert deg.mean() <= FLOAT_MEAN_DEG and deg.max() <= FLOAT_MAX_DEG, (deg.mean(),
                                                                            deg.max())


@pytest.mark.parametrize("real", ["double", "float"])
def test_an_online_hard_iron_equals_library(tmp_path, real):
    """The online hard-iron estimate (``_kernel._hard_iron_span``): the spun-and-coned record
    with a 40 % offset in its field — the library applies an offset (``MAG_OFFSET``) — row
    by row as the library's: double to ``DOUBLE_RAD`` with the same flags, float within the
    float bounds."""
    t, gyro, acc, m = MOVING
    m = m + np.array([9.0, -14.0, 6.0])
    res = ekf(t, gyro, acc, m)
    assert np.any(res.flags & int(K.F_MAG_OFFSET)) and res.mag_offset is not None
    h = check_rate_record(t, gyro, min_samples=4).td
    e, lib = build(tmp_path, h=h, real=real, mag=True, algorithm="rate-single",
                   config=AhrsConfig(), name=f"hi_{real}")
    q, rc, fl = run(e, lib, gyro, acc, m)
    _equals_library(res, q, rc, fl, e.moving_samples, real)  # the record starts in motion


def test_chunks_equal_one_stream(tmp_path):
    # the state is all the filter keeps: any split of the record gives the same rows
    _t, gyro, acc, mag = SIM
    e, lib = build(tmp_path, h=1 / 200.0, name="chunks")
    whole = run(e, lib, gyro, acc, mag)[0]
    s = Stream(e, lib)
    parts = [s.feed(gyro[a:b], acc[a:b], mag[a:b])[0]
             for a, b in ((0, 1), (1, 150), (150, 3001), (3001, 6000))]
    np.testing.assert_array_equal(np.concatenate(parts), whole)


def test_bad_input_and_numerical_failure(tmp_path):
    _t, gyro, acc, mag = SIM
    e, lib = build(tmp_path, h=1 / 200.0, name="fail")
    s = Stream(e, lib)
    q, rc, _ = s.feed(gyro[:500], acc[:500], mag[:500])
    assert rc[-1] == 0
    bad = gyro[500:501].copy()
    bad[0, 1] = np.nan
    q2, rc2, _ = s.feed(bad, acc[500:501], mag[500:501])
    assert rc2[0] == ERR_INPUT and np.array_equal(q2[0], q[-1])  # sample ignored
    # the next good sample continues as if the bad one had not come
    ref = run(e, lib, np.r_[gyro[:500], gyro[501:510]], np.r_[acc[:500], acc[501:510]],
              np.r_[mag[:500], mag[501:510]])[0]
    q3 = s.feed(gyro[501:510], acc[501:510], mag[501:510])[0]
    np.testing.assert_array_equal(q3, ref[500:])
    # a rate that overflows the covariance: an error, the last good attitude, a new window
    huge = np.full((1, 3), 1e300)
    q4, rc4, _ = s.feed(huge, acc[510:511], mag[510:511])
    assert rc4[0] == ERR_NUMERIC and np.array_equal(q4[0], q3[-1])
    _, rc5, _ = s.feed(gyro[511:520], acc[511:520], mag[511:520])
    assert np.all(rc5 == WAIT)


def test_refuses_what_it_cannot_run():
    with pytest.raises(ValueError, match="sliding"):
        generate_ahrs(100.0, algorithm="rate-three:structure=sliding")
    with pytest.raises(ValueError, match="increments"):
        generate_ahrs(100.0, algorithm="rotvec:N=3")
    with pytest.raises(ValueError, match="one of them"):
        generate_ahrs()


#: kernel functions the C does not repeat, and why
NOT_MIRRORED = {"_startup_step": "the sliding structure is not exported",
                "gyro_path": "offline_ekf's smoothing: the exported filter is causal",
                "hard_iron_sums": "offline_ekf's hard-iron estimate: the exported filter is causal",
                "gyro_plateau_runs": "a warning about the whole record, which the C never holds"}


def test_every_kernel_function_has_its_mirror():
    # a function added to the kernel must get its C twin (or a reason here)
    kernel = re.findall(r"^def (\w+)\(", Path(K.__file__).read_text(), re.M)
    text = TEMPLATE.read_text()
    missing = [f for f in kernel if f not in NOT_MIRRORED and f"_kernel.{f}" not in text]
    assert not missing, f"no C mirror (a comment '_kernel.NAME') for {missing}"


def test_every_params_field_is_a_constant_or_learned():
    from strapdown.codegen.ahrs_c import LEARNED

    src = generate_ahrs(100.0).source
    for f in K.Params._fields:
        if f in LEARNED or f in ("store_covariance", "mag_delay_max", "rest_tau"):
            continue
        if f[:3] in ("lp_", "mc_") and f[3:] in ("b0", "b1", "b2", "a1", "a2"):
            continue
        assert re.search(rf"\.{f} = ", src), f


def test_every_libm_call_of_the_template_is_counted():
    """The operation count compiles the module with a counting type: every libm function
    the template calls (``ahrs_c._MATH``, the names the float build suffixes) needs an
    overload in ``count.hpp``, or the count's build fails (``atan`` had none when
    ``saturation.declip`` first called it)."""
    from strapdown.codegen import ahrs_c

    hpp = (Path(ahrs_c.__file__).parent / "templates" / "count.hpp").read_text()
    source = generate_ahrs(100.0, config=AhrsConfig()).source
    for f in ahrs_c._MATH:
        if re.search(rf"\b{f}\(", source):
            assert re.search(rf"SD_FN1\({f}, |Counted<T> {f}\(", hpp), f


def test_the_operation_count_runs(tmp_path):
    """``count_operations`` builds the double module against the counting type and runs it
    over a simulated recording: a positive count of each arithmetic class per update, and
    the window's update far above the mean. Skipped without a C++ compiler."""
    import shutil

    from strapdown.codegen.ahrs_count import count_operations

    if not (shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")):
        pytest.skip("no C++ compiler")
    cost = count_operations(generate_ahrs(100.0, config=AhrsConfig(), name="count_ahrs"),
                            seconds=4.0)
    assert all(cost.mean[k] > 0 for k in ("add", "mul", "div", "sqrt", "cmp"))
    assert cost.window["mul"] > 10 * cost.mean["mul"]
