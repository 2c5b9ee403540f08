"""benchmarks/ahrs_repoimu.py's loader: a RepoIMU CSV (two header rows, one row per optical
frame, the IMU's samples held over the frames) becomes a clean uniform record."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

_SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "ahrs_repoimu.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("ahrs_repoimu_bench", _SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _write(path: Path, frames: list[tuple[float, list[float], list[float]]]) -> Path:
    """Rows ``t;qw;qx;qy;qz;ax;ay;az;gx;gy;gz;mx;my;mz`` under RepoIMU's two header rows."""
    lines = ["Time;Vicon Orientation;;;;IMU Acceleration;;;IMU Gyroscope;;;IMU Magnetometer;;",
             "s;W;X;Y;Z;X;Y;Z;X;Y;Z;X;Y;Z"]
    for t, q, imu in frames:
        lines.append(";".join(f"{x:.10g}" for x in [t, *q, *imu]))
    path.write_text("\n".join(lines) + "\n")
    return path


def _frames():
    """Three IMU samples held over frames at 0/0.01/0.02, 0.03/0.04, 0.05 … 0.07 s (an
    uneven arrival), the optical quaternion changing every frame (not unit length)."""
    samples = [[0.0, 0.0, 9.8, 0.1, 0.0, 0.0, 0.3, 0.0, 0.5],
               [0.1, 0.0, 9.8, 0.3, 0.0, 0.0, 0.3, 0.1, 0.5],
               [0.2, 0.0, 9.8, 0.5, 0.0, 0.0, 0.3, 0.2, 0.5]]
    which = [0, 0, 0, 1, 1, 2, 2, 2]
    return [(0.01 * k, [2.0, 0.0, 0.0, 0.02 * k], samples[s]) for k, s in enumerate(which)]


def test_held_rows_collapse_onto_a_uniform_grid(tmp_path, bench):
    r = bench.load(_write(tmp_path / "p.csv", _frames()))
    # kept: the first frame of each sample, at 0, 0.03, 0.05 s; the grid's period is the mean
    assert r["h"] == pytest.approx(0.025, abs=1e-12)
    np.testing.assert_allclose(r["t"], [0.0, 0.025, 0.05], atol=1e-12)
    np.testing.assert_allclose(r["gyro"][:, 0], [0.1, 0.3, 0.5])
    np.testing.assert_allclose(r["acc"][:, 0], [0.0, 0.1, 0.2])
    np.testing.assert_allclose(r["mag"][:, 2], [0.5, 0.5, 0.5])
    # the reference at each kept frame, normalised
    q = np.array([[2.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.06], [2.0, 0.0, 0.0, 0.10]])
    np.testing.assert_allclose(r["q_ref"], q / np.linalg.norm(q, axis=1, keepdims=True))


def test_resample_interpolates_from_the_frames_stamps(tmp_path, bench):
    r = bench.load(_write(tmp_path / "p.csv", _frames()), timing="resample")
    # the grid point 0.025 s lies between the samples stamped 0 and 0.03 s
    np.testing.assert_allclose(r["gyro"][:, 0], [0.1, 0.1 + 0.2 * 0.025 / 0.03, 0.5])
    np.testing.assert_allclose(np.linalg.norm(r["q_ref"], axis=1), 1.0)


def test_an_unknown_timing_is_refused(tmp_path, bench):
    with pytest.raises(ValueError, match="timing must be"):
        bench.load(_write(tmp_path / "p.csv", _frames()), timing="stamps")
