"""One convention for logs: time-column names, header units (and their spellings), the
units of known formats taken from the file, contradictions and the unit check as an error."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.io import savemat

from strapdown.io import UnitWarning, read_imu
from strapdown.io.readers import canonical_unit, default_columns
from strapdown.truth.motions import SpinConing

T = np.arange(200) / 1000.0
W = SpinConing(0.05, 2 * math.pi, 20.0).rate(T)


def _csv(path, header, t, g):
    with open(path, "w") as f:
        f.write(header + "\n")
        for ti, gi in zip(t, g, strict=True):
            f.write(",".join(repr(float(v)) for v in (ti, *gi)) + "\n")
    return path


@pytest.mark.parametrize(("header", "scale"), [
    ("time,gx,gy,gz", 1.0), ("timestamp,gx,gy,gz", 1.0), ("time_s,gx,gy,gz", 1.0),
    ("t[s],gx,gy,gz", 1.0), ("Time,GX,GY,GZ", 1.0), ("t[ms],gx,gy,gz", 1e-3),
    ("time_us,wx,wy,wz", 1e-6), ("seconds,gyro_x,gyro_y,gyro_z", 1.0),
])
def test_time_and_axis_columns_are_recognised(tmp_path, header, scale):
    path = _csv(tmp_path / "log.csv", header, T / scale, W)
    log = read_imu(path, kind="rate", units="rad/s")
    assert np.allclose(log.t, T, rtol=1e-15, atol=1e-18) and np.array_equal(log.data, W)


def test_ambiguous_or_missing_time_column_is_an_error(tmp_path):
    path = _csv(tmp_path / "two.csv", "t,gx,gy,gz", T, W)
    with open(path) as f:
        rows = f.read().splitlines()
    (tmp_path / "two.csv").write_text("\n".join([rows[0] + ",time"]
                                                + [r + ",0" for r in rows[1:]]) + "\n")
    with pytest.raises(ValueError, match=r"several time columns \['t', 'time'\]"):
        read_imu(path, kind="rate", units="rad/s")
    path = _csv(tmp_path / "none.csv", "clock,gx,gy,gz", T, W)
    with pytest.raises(ValueError, match="no time column in the header"):
        read_imu(path, kind="rate", units="rad/s")
    with pytest.raises(ValueError, match="time column 'clock' is in 'min'"):
        read_imu(_csv(tmp_path / "min.csv", "clock[min],gx,gy,gz", T, W), kind="rate",
                 units="rad/s", columns=("clock", "gx", "gy", "gz"))


def test_header_unit_spellings(tmp_path):
    assert canonical_unit("°/s") == "deg/s" and canonical_unit("m/s²") == "m/s2"
    assert canonical_unit("rad/s") == "rad/s"
    path = _csv(tmp_path / "log.csv", "t,gx[°/s],gy[°/s],gz[°/s]", T, np.degrees(W))
    assert np.allclose(read_imu(path, kind="rate", units=None).data, W, rtol=1e-14)
    cols, mag = default_columns(path, [("gyro", (("gx", "gy", "gz"),))],
                                optional=(("mx", "my", "mz"),))
    assert cols == ["t", "gx", "gy", "gz"] and mag == []


def _broad(path, gyro, fs=100.0):
    n = gyro.shape[0]
    savemat(path, {"imu_gyr": gyro, "imu_acc": np.tile([0, 0, 9.81], (n, 1)),
                   "imu_mag": np.tile([20.0, 0, -40], (n, 1)), "opt_quat": np.tile(
                       [1.0, 0, 0, 0], (n, 1)), "movement": np.ones((n, 1)),
                   "sampling_rate": np.array([[fs]])})
    return path


def test_broad_units_come_from_the_file(tmp_path):
    path = _broad(tmp_path / "trial.mat", W)
    log = read_imu(path, kind="rate", units=None)
    assert log.units == "rad/s" and np.array_equal(log.data, W)
    assert np.allclose(log.t, np.arange(W.shape[0]) / 100.0)
    with pytest.raises(ValueError, match=r"contradict the file's 'rad/s' \(BROAD stores "
                       r"imu_gyr in rad/s\)"):
        read_imu(path, kind="rate", units="deg/s")
    with pytest.raises(ValueError, match="BROAD's imu_gyr holds rates; pass --rates"):
        read_imu(path, kind="increment", units=None)
    with pytest.raises(ValueError, match="states a sampling rate of 100 Hz, not the 200 Hz"):
        read_imu(path, kind="rate", units=None, sample_rate_hz=200.0)


def test_psins_layout_holds_increments(tmp_path):
    n = 20
    savemat(tmp_path / "imu.mat", {"imu": np.column_stack(
        [np.full((n, 3), 1e-4), np.zeros((n, 3)), np.arange(1, n + 1) * 0.01])})
    with pytest.raises(ValueError, match=r"PSINS-style 'imu' \[wm vm t\] holds increments; "
                       "pass --increments"):
        read_imu(tmp_path / "imu.mat", kind="rate", units="rad/s")


def test_unit_check_can_be_an_error(tmp_path):
    # deg/s declared as rad/s: ~1150 "rad/s", 1.15 rad a sample (integrable, implausible)
    path = _csv(tmp_path / "log.csv", "t,gx,gy,gz", T, np.degrees(W))
    with pytest.warns(UnitWarning, match="more likely in degrees"):
        read_imu(path, kind="rate", units="rad/s")
    with pytest.raises(ValueError, match=r"more likely in degrees .* --accept-unit-warning"):
        read_imu(path, kind="rate", units="rad/s", unit_check="error")
    tiny = _csv(tmp_path / "tiny.csv", "t,gx,gy,gz", T, W * 1e-6)
    with pytest.raises(ValueError, match="implausibly small; the log is more likely in radians"):
        read_imu(tiny, kind="rate", units="deg/s", unit_check="error")


def test_sample_rate_of_a_stamped_log_is_its_nominal_period(tmp_path):
    path = _csv(tmp_path / "log.csv", "t,gx,gy,gz", T, W)
    log = read_imu(path, kind="rate", units="rad/s", sample_rate_hz=1000.0)
    assert log.nominal_period == 1e-3
    assert read_imu(path, kind="rate", units="rad/s").nominal_period is None
    with pytest.raises(ValueError, match="sample rate must be positive"):
        read_imu(path, kind="rate", units="rad/s", sample_rate_hz=-1.0)
