"""No silent wrong answer: every case exits 2, names the problem on one line of stderr and
writes nothing — units that contradict the file or the magnitudes, a diverged filter, a
sample rate export-c would have guessed — and the log conventions ``ahrs`` now shares
(header units, time-column names, gaps)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.io import savemat

from conftest import BROAD
from strapdown.cli import main
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.truth.motions import SpinConing

G_UP = np.array([0.0, 0.0, 9.80665])
M_N = np.array([0.0, 20.0, -40.0])
H = 0.01


def _fails(capsys, args, message, tmp_path, keep):
    """Exit status 2, ``message`` in the one stderr line, only ``keep`` in ``tmp_path``."""
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(keep)


def _imu(spin_dps, n=3000):
    """Gyro (rad/s), accelerometer (m/s²) and magnetometer of a spinning, coning body."""
    m = SpinConing(math.radians(20.0), 2 * math.pi * 0.3, math.radians(spin_dps))
    t = np.arange(n) * H
    c = dcm_from_quat(m.attitude(t))
    return (t, m.rate(t), np.einsum("nji,j->ni", c, G_UP), np.einsum("nji,j->ni", c, M_N))


def _csv(path, header, *cols):
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="",
               fmt="%.17g")
    return str(path)


PLAIN = "t,gx,gy,gz,ax,ay,az,mx,my,mz"


def test_ahrs_gyro_in_deg_s_declared_rad_s_fails(tmp_path, capsys):
    t, w, a, m = _imu(600.0)  # 99th percentile far above 200 "rad/s"
    log = _csv(tmp_path / "imu.csv", PLAIN, t, np.degrees(w), a, m)
    _fails(capsys, ["ahrs", "--imu", log, "--gyro-units", "rad/s", "--acc-units", "m/s2",
                    "--out", str(tmp_path / "a.csv")],
           "more likely in deg/s (declared rad/s); nothing computed", tmp_path, ["imu.csv"])


def test_ahrs_gyro_units_judged_against_the_magnetometer(tmp_path, capsys):
    # 90 °/s spin in deg/s declared rad/s: 91 "rad/s" passes the magnitude check, and the
    # filter no longer diverges on it — the magnetometer, which turns 57× slower than such a
    # gyro says, is what tells
    t, w, a, m = _imu(90.0)
    log = _csv(tmp_path / "imu.csv", PLAIN, t, np.degrees(w), a, m)
    _fails(capsys, ["ahrs", "--imu", log, "--gyro-units", "rad/s", "--acc-units", "m/s2",
                    "--out", str(tmp_path / "a.csv")],
           "the gyro is more likely in deg/s (declared rad/s)", tmp_path, ["imu.csv"])
    # the other way round: rad/s data declared deg/s
    log2 = _csv(tmp_path / "imu2.csv", PLAIN, t, w, a, m)
    _fails(capsys, ["ahrs", "--imu", log2, "--gyro-units", "deg/s", "--acc-units", "m/s2",
                    "--out", str(tmp_path / "a.csv")],
           "the gyro is more likely in rad/s (declared deg/s)", tmp_path,
           ["imu.csv", "imu2.csv"])
    # declared right, the same recording runs
    assert main(["ahrs", "--imu", log, "--gyro-units", "deg/s", "--acc-units", "m/s2",
                 "--out", str(tmp_path / "a.csv")]) == 0


@pytest.mark.skipif(BROAD is None, reason="BROAD trials not found (set STRAPDOWN_BROAD)")
def test_gyro_scale_separates_the_units_on_every_broad_trial():
    from strapdown.apps.ahrs_log import GYRO_SCALE_LIMITS, gyro_scale
    from strapdown.io.broad import read_broad

    lo, hi = GYRO_SCALE_LIMITS
    for f in sorted(BROAD.glob("*.mat")):
        tr = read_broad(f)
        assert lo <= gyro_scale(tr.t, tr.gyro, tr.mag) <= hi, f.name  # measured 0.90–0.99
        assert gyro_scale(tr.t, np.degrees(tr.gyro), tr.mag) < lo, f.name  # 0.016–0.017
        assert gyro_scale(tr.t, np.radians(tr.gyro), tr.mag) > hi, f.name  # 52–57


def test_diverged_filter_is_refused_at_the_output_stage():
    from strapdown.ahrs import ekf
    from strapdown.apps.ahrs_log import _check_output

    n = 200
    t = np.arange(n) / 100.0
    res = ekf(t, np.zeros((n, 3)), np.tile([0.0, 0.0, 9.80665], (n, 1)),
              np.tile([0.0, 20.0, -40.0], (n, 1)))
    res.q[50] = np.nan
    with pytest.raises(ValueError, match="the filter diverged at output row"):
        _check_output(res, "rad/s")


def _broad(path, n=600, fs=100.0):
    _, w, a, m = _imu(30.0, n)
    savemat(path, {"imu_gyr": w, "imu_acc": a, "imu_mag": m,
                   "opt_quat": np.tile([1.0, 0, 0, 0], (n, 1)), "movement": np.ones((n, 1)),
                   "sampling_rate": np.array([[fs]])})
    return str(path)


def test_ahrs_declared_unit_contradicting_broad_fails(tmp_path, capsys):
    mat = _broad(tmp_path / "trial.mat")
    _fails(capsys, ["ahrs", "--imu", mat, "--gyro-units", "deg/s", "--out",
                    str(tmp_path / "a.csv")],
           "declared gyro units 'deg/s' contradict the file's 'rad/s' (BROAD stores the gyro "
           "in rad/s", tmp_path, ["trial.mat"])
    _fails(capsys, ["ahrs", "--imu", mat, "--acc-units", "g", "--out", str(tmp_path / "a.csv")],
           "declared accelerometer units 'g' contradict the file's 'm/s2'", tmp_path,
           ["trial.mat"])
    assert main(["ahrs", "--imu", mat, "--gyro-units", "rad/s", "--out",
                 str(tmp_path / "a.csv")]) == 0
    meta = json.loads((tmp_path / "a.csv.meta.json").read_text())
    assert meta["gyro_units"] == "rad/s" and meta["acc_units"] == "m/s2"


def test_ahrs_takes_header_units_and_refuses_contradictions(tmp_path, capsys):
    t, w, a, m = _imu(30.0)
    flags = _csv(tmp_path / "plain.csv", PLAIN, t, np.degrees(w), a / 9.80665, m)
    header = _csv(tmp_path / "head.csv", "time,gx[deg/s],gy[deg/s],gz[deg/s],ax[g],ay[g],az[g],"
                  "mx[uT],my[uT],mz[uT]", t, np.degrees(w), a / 9.80665, m)
    assert main(["ahrs", "--imu", flags, "--gyro-units", "deg/s", "--acc-units", "g", "--out",
                 str(tmp_path / "f.csv")]) == 0
    assert main(["ahrs", "--imu", header, "--out", str(tmp_path / "h.csv")]) == 0
    assert (tmp_path / "f.csv").read_bytes() == (tmp_path / "h.csv").read_bytes()
    capsys.readouterr()  # the two runs' notes (this motion starts turning: a start in motion)
    keep = sorted(p.name for p in tmp_path.iterdir())
    _fails(capsys, ["ahrs", "--imu", header, "--gyro-units", "rad/s", "--out",
                    str(tmp_path / "x.csv")],
           "declared gyro units 'rad/s' contradict the header's 'deg/s'", tmp_path, keep)
    # without units the magnetometer decides the gyro's (its rotation against the gyro's)
    # and the norm the accelerometer's: the same result, each inference noted
    assert main(["ahrs", "--imu", flags, "--out", str(tmp_path / "i.csv")]) == 0
    assert (tmp_path / "i.csv").read_bytes() == (tmp_path / "f.csv").read_bytes()
    assert "gyro units inferred from the data: deg/s" in capsys.readouterr().err
    keep = sorted(p.name for p in tmp_path.iterdir())
    # without a magnetometer nothing decides the gyro's unit
    _fails(capsys, ["ahrs", "--imu", flags, "--no-mag", "--out", str(tmp_path / "x.csv")],
           "no gyro units declared; pass --gyro-units (rad/s or deg/s) or write them in the "
           "header (e.g. gx[deg/s])", tmp_path, keep)


def test_ahrs_gaps_fail_or_split(tmp_path, capsys):
    t, w, a, m = _imu(30.0)
    t = t.copy()
    t[1500:] += 1.5  # a 1.51 s gap before data row 1501: beyond what the filter bridges
    log = _csv(tmp_path / "imu.csv", PLAIN, t, w, a, m)
    units = ["--gyro-units", "rad/s", "--acc-units", "m/s2"]
    _fails(capsys, ["ahrs", "--imu", log, *units, "--out", str(tmp_path / "a.csv")],
           "a gap of 150 missing samples (1.5 s) before data row 1501, longer than the 1 s the "
           "filter bridges; pass --on-gap split", tmp_path, ["imu.csv"])
    _fails(capsys, ["ahrs", "--imu", log, *units, "--on-gap", "error", "--out",
                    str(tmp_path / "a.csv")], "gap of 1.51 s before data row 1501", tmp_path,
           ["imu.csv"])
    assert main(["ahrs", "--imu", log, *units, "--on-gap", "split", "--out",
                 str(tmp_path / "a.csv")]) == 0
    out = np.genfromtxt(tmp_path / "a.csv", delimiter=",", names=True)
    assert set(out["segment"]) == {0.0, 1.0}
    assert np.all(out["t"][out["segment"] == 1.0] >= t[1500])
    meta = json.loads((tmp_path / "a.csv.meta.json").read_text())
    assert meta["segments"] == 2 and meta["gaps"]["first_rows"] == [1501]


def test_ahrs_bridges_a_short_gap(tmp_path, capsys):
    """A 0.5 s gap is bridged on the fitted clock: one output per recorded sample, the
    attitude across the gap within the filter's own error of the gap-free run."""
    t, w, a, m = _imu(30.0)
    keep = np.r_[0:1500, 1550:t.size]  # 50 samples (0.5 s) missing
    units = ["--gyro-units", "rad/s", "--acc-units", "m/s2"]
    full = _csv(tmp_path / "full.csv", PLAIN, t, w, a, m)
    log = _csv(tmp_path / "gap.csv", PLAIN, t[keep], w[keep], a[keep], m[keep])
    assert main(["ahrs", "--imu", full, *units, "--out", str(tmp_path / "f.csv")]) == 0
    assert main(["ahrs", "--imu", log, *units, "--out", str(tmp_path / "g.csv")]) == 0
    assert "1 gap(s) (bridged), first at data row 1501" in capsys.readouterr().err
    f = np.loadtxt(tmp_path / "f.csv", delimiter=",", skiprows=1)[keep]
    g = np.loadtxt(tmp_path / "g.csv", delimiter=",", skiprows=1)
    assert np.array_equal(f[:, 0], g[:, 0])
    dot = np.abs(np.sum(f[:, 1:5] * g[:, 1:5], axis=1))
    assert np.degrees(2 * np.arccos(np.minimum(dot, 1.0))).max() < 1.0
    meta = json.loads((tmp_path / "g.csv.meta.json").read_text())
    assert meta["timing"]["clock"]["missing_samples"] == 50


@pytest.mark.parametrize("algorithm", ["rate-single", "rate-three", "rk4"])
def test_export_c_rate_algorithms_need_the_sample_rate(tmp_path, capsys, algorithm):
    _fails(capsys, ["export-c", "--algorithm", algorithm, "--out", str(tmp_path / "c")],
           f"{algorithm} bakes the sample period td into the code: pass --sample-rate-hz",
           tmp_path, [])
    assert main(["export-c", "--algorithm", algorithm, "--sample-rate-hz", "2000", "--out",
                 str(tmp_path / "c")]) == 0
    header = next((tmp_path / "c").glob("*.h")).read_text()
    assert "sampled every 0.0005 s" in header


def test_export_c_rotvec_needs_no_rate_and_options_that_do_not_apply_fail(tmp_path, capsys):
    assert main(["export-c", "--algorithm", "rotvec", "--out", str(tmp_path / "c")]) == 0
    assert (tmp_path / "c" / "sd_rotvec_conventional_n3.c").is_file()
    _fails(capsys, ["export-c", "--algorithm", "rotvec", "--sample-rate-hz", "1000", "--out",
                    str(tmp_path / "d")], "--sample-rate-hz does not apply to rotvec",
           tmp_path, ["c"])
    _fails(capsys, ["export-c", "--algorithm", "rk4", "--subsamples", "3", "--sample-rate-hz",
                    "1000", "--out", str(tmp_path / "d")], "--subsamples does not apply to rk4",
           tmp_path, ["c"])


def test_compare_refuses_implausible_units_and_unsplit_gaps(tmp_path, capsys):
    t = np.arange(400) / 1000.0
    w = np.tile([0.0, 0.0, 900.0], (t.size, 1))  # deg/s numbers declared as rad/s
    log = _csv(tmp_path / "log.csv", "time,gx,gy,gz", t, w)
    _fails(capsys, ["compare", "--imu", log, "--rates", "--units", "rad/s", "--algorithms",
                    "rk4", "--out", str(tmp_path / "cmp")],
           "more likely in degrees (declared rad/s)", tmp_path, ["log.csv"])
    assert main(["compare", "--imu", log, "--rates", "--units", "deg/s", "--algorithms", "rk4",
                 "rate-three", "--out", str(tmp_path / "cmp")]) == 0
    capsys.readouterr()
    tg = t.copy()
    tg[200:] += 0.05
    gap = _csv(tmp_path / "gap.csv", "time,gx,gy,gz", tg, w)
    keep = sorted(p.name for p in tmp_path.iterdir())
    _fails(capsys, ["compare", "--imu", gap, "--rates", "--units", "deg/s", "--algorithms",
                    "rk4", "--out", str(tmp_path / "cmp2")],
           "rate algorithms cannot bridge a gap: pass --on-gap split", tmp_path, keep)
    assert main(["compare", "--imu", gap, "--rates", "--units", "deg/s", "--on-gap", "split",
                 "--algorithms", "rk4", "rate-three", "--out", str(tmp_path / "cmp2")]) == 0
    capsys.readouterr()
    _fails(capsys, ["compare", "--algorithms", "rk4", "--on-gap", "split", "--out",
                    str(tmp_path / "cmp3")], "belong to --imu", tmp_path,
           [*keep, "cmp2"])


def test_ahrs_sample_rate_must_agree_with_the_stamps(tmp_path, capsys):
    t, w, a, m = _imu(30.0)
    log = _csv(tmp_path / "imu.csv", PLAIN, t, w, a, m)
    units = ["--gyro-units", "rad/s", "--acc-units", "m/s2"]
    _fails(capsys, ["ahrs", "--imu", log, *units, "--sample-rate-hz", "101", "--out",
                    str(tmp_path / "a.csv")], "the time stamps are not at the given sample "
           "period", tmp_path, ["imu.csv"])
    assert main(["ahrs", "--imu", log, *units, "--sample-rate-hz", "100", "--out",
                 str(tmp_path / "a.csv")]) == 0
    assert json.loads((tmp_path / "a.csv.meta.json").read_text())["sample_period_s"] == H


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # 1e300 overflows on purpose
def test_compare_refuses_a_rate_no_algorithm_can_integrate(tmp_path, capsys):
    # 1e300 rad/s used to reach the output check (a NaN rk4 attitude); it is refused as input
    t = np.arange(20) / 1000.0
    log = _csv(tmp_path / "log.csv", "t,gx,gy,gz", t, np.tile([1e300, 0, 0], (20, 1)))
    _fails(capsys, ["compare", "--imu", log, "--rates", "--units", "rad/s",
                    "--accept-unit-warning", "--algorithms", "rk4", "--out",
                    str(tmp_path / "cmp")],
           "data row 1 turns the body by 1e+297 rad in one sample (at most π)", tmp_path,
           ["log.csv"])
