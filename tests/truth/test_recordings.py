"""The recording generator (issue 24): its files are what phones, rounding loggers and lab
loggers write, and its truth is exact — consistent with the gyro it writes."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.error import attitude_error_angle
from strapdown.rotation.quaternion import quat_from_rotvec, quat_multiply
from strapdown.truth import recordings as R


def _csv(path, delimiter=",", skip=1):
    return np.loadtxt(path, delimiter=delimiter, skiprows=skip, ndmin=2)


def _integrate(q0, theta):
    """Attitudes after each rotation vector, one exponential per step."""
    out = np.empty((theta.shape[0] + 1, 4))
    out[0] = q0
    dq = quat_from_rotvec(theta)
    for k in range(theta.shape[0]):
        out[k + 1] = quat_multiply(out[k], dq[k])
    return out


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("recordings")
    return (d, R.phone_recording(d), R.rounded_gyro_log(d), R.lab_recording(d))


def test_hand_held_motion_rests_then_turns_like_a_hand():
    body = R.hand_held(3)
    t = np.arange(0.0, 40.0, 0.01)
    w = np.degrees(np.linalg.norm(body.rate(t), axis=-1))
    rest = t < body.rest_s
    assert np.all(w[rest] == 0) and np.all(np.ptp(body.attitude(t[rest]), axis=0) == 0)
    assert 30 < w.max() < 120  # tens of deg/s
    assert np.all(np.degrees(np.abs(body.rate(t))).max(axis=0) > 15)  # all three axes
    tilt = np.degrees(np.arccos(dcm_from_quat(body.attitude(t))[:, 2, 2]))
    assert 25 < tilt.max() < 45
    f = body.specific_force(t)
    assert np.allclose(f[rest], dcm_from_quat(body.attitude(t[rest]))[:, 2, :] * R.G)
    assert np.all(np.abs(np.linalg.norm(f, axis=-1) - R.G) < 0.6)  # small translation
    q = body.attitude(t)
    assert np.allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-14)


def test_integrating_the_exact_rates_reproduces_the_attitude():
    body = R.hand_held(0)
    edges = np.arange(0.0, 20.0 + 1e-9, 1e-3)
    q = _integrate(body.attitude(edges[0]), body.motion.increments(edges))
    assert attitude_error_angle(q, body.attitude(edges)).max() < 1e-6


def test_phone_log_has_jittered_integer_ms_epoch_stamps_and_a_dropped_burst(files):
    rec = files[1]
    raw, exact = _csv(rec.path), _csv(rec.exact_path)
    header = rec.path.read_text().splitlines()[0]
    assert header == "timestamp_ms,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z"
    assert rec.exact_path.read_text().splitlines()[0] == header
    assert np.array_equal(raw[:, 1:], exact[:, 1:])  # the same samples
    stamps = raw[:, 0]
    assert np.all(stamps == np.round(stamps)) and np.all(np.diff(stamps) > 0)
    assert abs(stamps[0] - 1733119200123) <= 1
    off = stamps - exact[:, 0]
    assert np.abs(off).max() <= 1.5 and np.abs(off).max() > 0.9 and abs(off.mean()) < 0.05
    np.testing.assert_allclose(exact[:, 0] / 1e3, rec.t, rtol=0, atol=1e-6)
    steps = np.diff(exact[:, 0]) / 5.0
    big = np.flatnonzero(steps > 1.5)
    assert big.size == 1 and round(steps[big[0]]) == 11  # 10 samples missing
    assert 0.4 < big[0] / steps.size < 0.6  # in the middle
    assert np.allclose(steps[steps < 1.5], 1.0, atol=1e-3)
    acc = np.linalg.norm(raw[:, 4:7], axis=1)
    mag = np.linalg.norm(raw[:, 7:10], axis=1)
    assert abs(np.median(acc) - 9.81) < 0.1 and abs(np.median(mag) - 49.2) < 1.0


def test_noise_free_phone_gyro_reproduces_its_truth(tmp_path):
    """The file's gyro (deg/s, the mean rate over the period ending at each stamp) times
    the period, integrated, is the truth: the columns, units and convention are right."""
    rec = R.phone_recording(tmp_path, noise=False, drop=(0, 0), duration_s=20.0)
    data = _csv(rec.exact_path)
    h = np.diff(data[:, 0]).mean() / 1e3
    q = _integrate(rec.q_n_b[0], np.radians(data[1:, 1:4]) * h)
    assert np.degrees(attitude_error_angle(q, rec.q_n_b)).max() < 0.01
    c_n_b = dcm_from_quat(rec.q_n_b)  # the field in µT, the specific force in m/s²
    np.testing.assert_allclose(data[:, 7:10], R.EARTH_FIELD_UT @ c_n_b, atol=1e-5)
    np.testing.assert_allclose(data[:, 4:7], rec.body.specific_force(rec.t - rec.t_start),
                               atol=1e-5)


def test_rounded_log_stamps_are_whole_ms_of_a_regular_400_hz_clock(files):
    rec = files[2]
    raw, exact = _csv(rec.path), _csv(rec.exact_path)
    assert rec.path.read_text().splitlines()[0] == "t,gx,gy,gz"
    np.testing.assert_array_equal(raw[:5, 0], [0.0, 0.002, 0.005, 0.008, 0.010])
    assert np.array_equal(raw[:, 1:], exact[:, 1:])
    assert np.allclose(raw[:, 0] * 1e3, np.round(raw[:, 0] * 1e3), atol=1e-9)
    np.testing.assert_allclose(exact[:, 0], np.arange(raw.shape[0]) * 0.0025, atol=1e-9)
    assert np.abs(raw[:, 0] - exact[:, 0]).max() == pytest.approx(0.0005, abs=1e-9)
    assert set(np.round(np.diff(raw[:, 0]) * 1e3).astype(int)) == {2, 3}


def test_noise_free_rounded_log_integrates_to_its_truth(tmp_path):
    rec = R.rounded_gyro_log(tmp_path, noise=False, duration_s=10.0)
    data = _csv(rec.exact_path)
    w = np.radians(data[:, 1:4])
    q = _integrate(rec.q_n_b[0], 0.5 * (w[1:] + w[:-1]) * 0.0025)  # point rates: trapezoid
    assert np.degrees(attitude_error_angle(q, rec.q_n_b)).max() < 0.01


def _lab_rows(path):
    lines = path.read_text().splitlines()
    return lines[:2], [ln.split(";") for ln in lines[2:]]


def test_lab_file_holds_repeats_duplicates_and_gaps(files):
    lab = files[3]
    head, rows = _lab_rows(lab.path)
    assert head == ["Time;Vicon Orientation;;;;IMU Acceleration;;;IMU Gyroscope;;;"
                    "IMU Magnetometer;;", "s;W;X;Y;Z;X;Y;Z;X;Y;Z;X;Y;Z"]
    assert all(len(r) == 14 for r in rows)
    t_ms = np.array([round(float(r[0]) * 1e3) for r in rows])
    assert all(r[0] == f"{ms / 1e3:.3f}" for r, ms in zip(rows, t_ms, strict=True))
    steps = np.diff(t_ms)
    dup = np.flatnonzero(steps == 0)
    assert dup.size == 3 and all(rows[i] == rows[i + 1] for i in dup)  # the same row twice
    gaps = steps[steps > 12]
    assert 1 <= gaps.size <= 5 and gaps.max() <= 190 and gaps.max() >= 150
    assert set(steps[(steps > 0) & (steps <= 12)]) == {10, 11, 12}
    distinct = [r for i, r in enumerate(rows) if i == 0 or rows[i - 1] != r]
    held = np.mean([a[5:] == b[5:] for a, b in itertools.pairwise(distinct)])
    assert 0.40 < held < 0.47 and held == pytest.approx(lab.held_fraction, abs=2e-3)
    # the reference is the truth at the stamps, with a little optical noise
    data = np.array(distinct, dtype=float)
    q_ref = data[:, 1:5]
    np.testing.assert_array_equal(data[:, 0], lab.t)
    err = np.degrees(attitude_error_angle(q_ref, lab.q_n_b))
    assert 0.05 < np.sqrt(np.mean(err ** 2)) < 0.5
    # --columns 0,8,9,10,5,6,7,11,12,13: time, gyro (rad/s), acc (m/s²), field
    sel = data[:, [0, 8, 9, 10, 5, 6, 7, 11, 12, 13]]
    assert abs(np.median(np.linalg.norm(sel[:, 4:7], axis=1)) - 9.81) < 0.1
    assert np.abs(sel[:, 1:4]).max() < 2.5  # rad/s
    assert abs(np.median(np.linalg.norm(sel[:, 7:10], axis=1)) - 0.492) < 0.02


def test_lab_cleaned_twin_is_one_row_per_imu_sample_on_the_fitted_clock(files):
    lab = files[3]
    lines = lab.cleaned_path.read_text().splitlines()
    assert lines[0] == ("t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s2],ay[m/s2],az[m/s2],"
                        "mx,my,mz")
    clean = _csv(lab.cleaned_path)
    _, rows = _lab_rows(lab.path)
    raw = np.array(rows, dtype=float)
    first = np.concatenate([[True], np.any(raw[1:, 5:] != raw[:-1, 5:], axis=1)])
    samples = raw[first]
    assert samples.shape[0] == clean.shape[0] == lab.imu_index.size
    np.testing.assert_array_equal(clean[:, 1:], samples[:, [8, 9, 10, 5, 6, 7, 11, 12, 13]])
    # the time column is a straight line in the IMU sample index, through the first stamps
    k = lab.imu_index
    fit = np.polyval(np.polyfit(k, clean[:, 0], 1), k)
    assert np.abs(clean[:, 0] - fit).max() < 2e-6
    resid = samples[:, 0] - clean[:, 0]
    assert np.abs(resid).max() < 0.015 and abs(resid.mean()) < 1e-4
    assert np.polyfit(k, clean[:, 0], 1)[0] == pytest.approx(1 / 51.0, rel=1e-3)
    # the gaps stay gaps: whole IMU periods missing
    assert set(np.diff(k)) - {1} and np.diff(k).max() <= 10
    # against the true sample times the fitted clock is late by the latency and about half
    # a logger step, nothing more
    lag = clean[:, 0] - lab.imu_t
    assert 0.002 < lag.mean() < 0.012 and np.ptp(lag) < 1e-3


@pytest.mark.parametrize("make", [R.phone_recording, R.rounded_gyro_log, R.lab_recording])
def test_a_seed_writes_the_same_bytes(tmp_path, make):
    a = make(tmp_path / "a", seed=5, duration_s=15.0)
    b = make(tmp_path / "b", seed=np.random.default_rng(5), duration_s=15.0)
    c = make(tmp_path / "c", seed=6, duration_s=15.0)
    for name in ("path", "exact_path", "cleaned_path"):
        if hasattr(a, name):
            pa, pb, pc = getattr(a, name), getattr(b, name), getattr(c, name)
            assert pa.read_bytes() == pb.read_bytes() != pc.read_bytes()
    np.testing.assert_array_equal(a.q_n_b, b.q_n_b)
