"""`strapdown run` on a new user's log: defaults that follow the log, options that do not
apply are errors, no silent wrong answer, and the metadata sidecar written with the output."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.io import savemat

from strapdown.algorithms.rate import rate_attitude
from strapdown.apps.run import run_log
from strapdown.cli import main
from strapdown.truth.motions import SpinConing

M = SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(720.0))
T = np.arange(601) / 1000.0


def _write(path, header, t, g):
    np.savetxt(path, np.column_stack([t, g]), delimiter=",", header=header, comments="",
               fmt="%.17g")
    return path


def _fails(capsys, args, message, tmp_path, keep):
    """The command exits 2 with ``message`` on stderr and leaves only ``keep`` behind."""
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(keep)


def test_plain_time_csv_with_rates_alone_runs_rate_three(tmp_path, capsys):
    log = _write(tmp_path / "log.csv", "time,gx,gy,gz", T, np.degrees(M.rate(T)))
    out = tmp_path / "att.csv"
    assert main(["run", "--imu", str(log), "--rates", "--units", "deg/s", "--angles", "none",
                 "--out", str(out)]) == 0
    assert "(rate-three; clock 1000 Hz fitted (uniform stamps)" in capsys.readouterr().out
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    ref = rate_attitude(T, np.radians(np.degrees(M.rate(T))), algorithm="rate-three")
    assert np.array_equal(got[:, 1:5], ref.q) and np.array_equal(got[:, 0], ref.t)


def test_increments_default_to_rotvec(tmp_path):
    h = 1e-3
    edges = np.arange(301) * h
    np.save(tmp_path / "inc.npy", np.column_stack([edges[1:], M.increments(edges)]))
    meta = run_log(tmp_path / "inc.npy", tmp_path / "a.csv", kind="increment", units="rad")
    assert meta["algorithm"] == "rotvec:N=3" and meta["update_period_s"] == pytest.approx(3 * h)


@pytest.mark.parametrize(("extra", "message"), [
    (["--algorithm", "rate-single", "--subsamples", "3"],
     "--subsamples does not apply to rate-single"),
    (["--subsamples", "2"], "--subsamples does not apply to rate-three"),
    (["--algorithm", "rk4", "--coefficients", "paper"], "rk4 has no coefficients"),
])
def test_options_that_do_not_apply_are_errors(tmp_path, capsys, extra, message):
    log = _write(tmp_path / "log.csv", "t,gx,gy,gz", T, M.rate(T))
    _fails(capsys, ["run", "--imu", str(log), "--rates", "--units", "rad/s", *extra, "--out",
                    str(tmp_path / "a.csv")], message, tmp_path, ["log.csv"])


def test_resample_is_for_rate_logs(tmp_path, capsys):
    np.save(tmp_path / "inc.npy", np.zeros((10, 4)) + np.arange(1, 11)[:, None] * [1, 0, 0, 0])
    _fails(capsys, ["run", "--imu", str(tmp_path / "inc.npy"), "--increments", "--units", "rad",
                    "--resample", "--out", str(tmp_path / "a.csv")],
           "--resample applies to rate logs", tmp_path, ["inc.npy"])


def test_unit_warning_is_an_error_unless_accepted(tmp_path, capsys):
    log = _write(tmp_path / "log.csv", "t,gx,gy,gz", T, np.tile([0, 0, 900.0], (T.size, 1)))
    out = tmp_path / "a.csv"
    _fails(capsys, ["run", "--imu", str(log), "--rates", "--units", "rad/s", "--out", str(out)],
           "more likely in degrees (declared rad/s); nothing computed. If the declared units "
           "are right, pass --accept-unit-warning", tmp_path, ["log.csv"])
    assert main(["run", "--imu", str(log), "--rates", "--units", "rad/s",
                 "--accept-unit-warning", "--out", str(out)]) == 0
    assert "warning: " in capsys.readouterr().err
    meta = json.loads((tmp_path / "a.csv.meta.json").read_text())
    assert any("more likely in degrees" in w for w in meta["warnings"])


def test_rate_beyond_any_integrable_motion_fails_and_writes_nothing(tmp_path, capsys):
    # 1e300 rad/s used to overflow the RK4 step (an inf/NaN attitude, refused at the output);
    # it is now refused as input: 1e297 rad in one sample, the limit is π
    log = _write(tmp_path / "log.csv", "t,gx,gy,gz", T[:20], np.tile([1e300, 0, 0], (20, 1)))
    _fails(capsys, ["run", "--imu", str(log), "--rates", "--units", "rad/s", "--algorithm",
                    "rk4", "--accept-unit-warning", "--out", str(tmp_path / "a.csv")],
           "data row 1 turns the body by 1e+297 rad in one sample (at most π)", tmp_path,
           ["log.csv"])


def _broad(path, gyro, fs):
    n = gyro.shape[0]
    savemat(path, {"imu_gyr": gyro, "imu_acc": np.tile([0, 0, 9.81], (n, 1)),
                   "imu_mag": np.tile([20.0, 0, -40], (n, 1)),
                   "opt_quat": np.tile([1.0, 0, 0, 0], (n, 1)), "movement": np.ones((n, 1)),
                   "sampling_rate": np.array([[fs]])})
    return path


def test_broad_mat_runs_without_units_and_a_contradiction_fails(tmp_path, capsys):
    mat = _broad(tmp_path / "trial.mat", M.rate(T), 1000.0)
    assert main(["run", "--imu", str(mat), "--rates", "--out", str(tmp_path / "a.csv")]) == 0
    assert json.loads((tmp_path / "a.csv.meta.json").read_text())["units"] == "rad/s"
    _fails(capsys, ["run", "--imu", str(mat), "--rates", "--units", "deg/s", "--out",
                    str(tmp_path / "b.csv")],
           "declared units 'deg/s' contradict the file's 'rad/s' (BROAD stores imu_gyr in "
           "rad/s)", tmp_path, ["trial.mat", "a.csv", "a.csv.meta.json"])


def test_sidecar_records_the_run(tmp_path):
    log = _write(tmp_path / "log.csv", "t[s],gx[deg/s],gy[deg/s],gz[deg/s]", T,
                 np.degrees(M.rate(T)))
    meta = run_log(log, tmp_path / "a.npz", kind="rate", units=None, algorithm="rk4",
                   angles="cone", saturation=5000.0)
    from strapdown import __version__

    assert json.loads((tmp_path / "a.npz.meta.json").read_text()) == meta
    assert meta["input"] == str(log) and meta["algorithm"] == "rk4"
    assert meta["units"] == "deg/s" and meta["kind"] == "rate"
    assert meta["samples"] == 601 and meta["outputs"] == 301
    assert meta["update_period_s"] == pytest.approx(2e-3) and meta["sample_period_s"] == 1e-3
    assert meta["jitter_periods"] < 1e-9 and meta["resampled"] is False
    assert meta["gaps"] == {"count": 0, "first_rows": []} and meta["segments"] == 1
    assert meta["saturation"] == 5000.0 and meta["saturated"]["count"] == 0
    assert meta["columns"] == ["t", "qw", "qx", "qy", "qz", "delta1_deg", "delta2_deg",
                               "delta3_deg"]
    assert meta["warnings"] == [] and meta["version"] == __version__
    with np.load(tmp_path / "a.npz") as z:
        assert list(z.keys()) == meta["columns"] and z["t"].size == meta["outputs"]


def test_a_failure_leaves_neither_file_and_a_stale_sidecar_never_survives(tmp_path,
                                                                          monkeypatch):
    import strapdown.apps._logs as logs

    log = _write(tmp_path / "log.csv", "t,gx,gy,gz", T, M.rate(T))
    out = tmp_path / "a.csv"
    run_log(log, out, kind="rate", units="rad/s")
    first = out.read_bytes()
    (tmp_path / "a.csv.meta.json").write_text("{}")  # stale
    run_log(log, out, kind="rate", units="rad/s", algorithm="rate-single")
    assert json.loads((tmp_path / "a.csv.meta.json").read_text())["algorithm"] == "rate-single"
    second = out.read_bytes()
    assert second != first

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(logs.json, "dumps", broken)  # the sidecar cannot be written
    with pytest.raises(OSError, match="disk full"):
        run_log(log, tmp_path / "b.csv", kind="rate", units="rad/s")
    with pytest.raises(OSError, match="disk full"):
        run_log(log, out, kind="rate", units="rad/s", algorithm="rk4")
    assert out.read_bytes() == second  # the previous pair is untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "a.csv.meta.json", "log.csv"]


def test_sample_rate_applies_to_csv_logs(tmp_path, capsys):
    # a rate CSV: the nominal period of its stamps, checked against them
    log = _write(tmp_path / "log.csv", "t,gx,gy,gz", T, M.rate(T))
    meta = run_log(log, tmp_path / "a.csv", kind="rate", units="rad/s", sample_rate_hz=1000.0)
    assert meta["sample_period_s"] == 1e-3
    _fails(capsys, ["run", "--imu", str(log), "--rates", "--units", "rad/s", "--sample-rate-hz",
                    "1010", "--out", str(tmp_path / "b.csv")],
           "the time stamps are not at the given sample period", tmp_path,
           ["log.csv", "a.csv", "a.csv.meta.json"])
    # an increment CSV: the increment interval
    h = 2e-3
    edges = np.arange(301) * h
    inc = _write(tmp_path / "inc.csv", "t,gx,gy,gz", edges[1:], M.increments(edges))
    meta = run_log(inc, tmp_path / "c.csv", kind="increment", units="rad",
                   sample_rate_hz=500.0)
    assert meta["sample_period_s"] == h and meta["update_period_s"] == pytest.approx(3 * h)
