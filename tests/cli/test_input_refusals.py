"""What the fuzz campaign of issue 24 (item 9) found accepted or refused badly: each case
now ends in one line on stderr naming the file (and the row, where there is one), exit
status 2 and nothing written — or in a correct result — and no numpy RuntimeWarning or
matplotlib warning reaches the terminal."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

from cli_helpers import exit_of
from strapdown.apps import sweep as sweep_app
from strapdown.cli import main
from strapdown.truth.motions import SpinConing

#: The tutorial's motion: spin 720 °/s with 2° coning at 3 Hz.
MOTION = SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(720.0))
NAV_HEADER = "t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s^2],ay[m/s^2],az[m/s^2]"
STATUS = re.compile(r"^\d+ cases.*: \d+ already done, \d+ to run")


def _csv(path, header, *cols):
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="",
               fmt="%.17g")
    return str(path)


def _refused(capsys, tmp_path, args, *needles, keep=None) -> str:
    """Exit status 2 with one line on stderr holding every needle, no warning on the way,
    and only ``keep`` (default: what was there before) in ``tmp_path``."""
    before = sorted(p.name for p in tmp_path.iterdir()) if keep is None else sorted(keep)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code, err = exit_of(capsys, *args)
    assert code == 2, err
    lines = [ln for ln in err.splitlines()  # the compile notice, a sweep's status line
             if not ln.startswith("compiling the numba") and not STATUS.match(ln)]
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], lines[0]
    loud = [str(w.message) for w in caught if issubclass(w.category, (RuntimeWarning,
                                                                        UserWarning))]
    assert not loud, loud
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    return lines[0]


@pytest.fixture
def gyro_log(tmp_path):
    """2 s of the tutorial's motion at 1 kHz (rad/s) and its exact attitude."""
    t = np.arange(2001) * 1e-3
    return _csv(tmp_path / "gyro.csv", "t,gx[rad/s],gy[rad/s],gz[rad/s]", t,
                MOTION.rate(t)), t, MOTION.attitude(t)


def test_compare_truth_in_ms_under_plain_t_is_refused(tmp_path, capsys, gyro_log):
    """Item 1: before, 0.198 rad "error" of an exact algorithm; now the unit is named."""
    log, t, q = gyro_log
    truth = _csv(tmp_path / "truth.csv", "t,qw,qx,qy,qz", t * 1000, q)
    msg = _refused(capsys, tmp_path, ["compare", "--imu", log, "--rates", "--truth", truth,
                                      "--algorithms", "rate-three", "--out",
                                      str(tmp_path / "cmp")],
                   "truth.csv", "likely in ms", "t[ms]")
    assert "nothing computed" in msg
    # declared, the same file gives the algorithm's own error
    declared = _csv(tmp_path / "truth_ms.csv", "t[ms],qw,qx,qy,qz", t * 1000, q)
    assert main(["compare", "--imu", log, "--rates", "--truth", declared, "--algorithms",
                 "rate-three", "--out", str(tmp_path / "ok")]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if "rate-three" in ln)
    assert float(line.split()[2]) < 1e-8
    # a truth in seconds sampled 10× slower than the log is not mistaken for one in ms
    slow = _csv(tmp_path / "truth_slow.csv", "t,qw,qx,qy,qz", t[::10], q[::10])
    assert main(["compare", "--imu", log, "--rates", "--truth", slow, "--algorithms",
                 "rate-three", "--out", str(tmp_path / "slow")]) == 0


def test_nav_overflowing_specific_force_names_file_and_row(tmp_path, capsys):
    """Item 2: ax = 1e308 printed RuntimeWarnings, then a refusal naming no file or row."""
    n = 400
    t = np.arange(n) * 0.01
    acc = np.tile([0.0, 0.0, -9.80665], (n, 1))
    acc[100, 0] = 1e308
    log = _csv(tmp_path / "nav.csv", NAV_HEADER, t, np.zeros((n, 3)), acc)
    _refused(capsys, tmp_path, ["nav", "--imu", log, "--init-lat", "45", "--init-lon", "7",
                                "--init-height", "100", "--out", str(tmp_path / "n.csv")],
             "nav.csv: data row 101", "specific force")


def test_values_beyond_float64_are_refused_without_warnings(tmp_path, capsys, gyro_log):
    """Item 3: compare --truth with quaternions × 1e300, advise and run on a float128 .npy
    holding 1e311, advise --psd with 1e308 (it ended in matplotlib's "Data cannot be
    log-scaled")."""
    log, t, q = gyro_log
    big = _csv(tmp_path / "truth.csv", "t,qw,qx,qy,qz", t, q * 1e300)
    _refused(capsys, tmp_path, ["compare", "--imu", log, "--rates", "--truth", big,
                                "--algorithms", "rate-three", "--out", str(tmp_path / "c")],
             "truth.csv: truth row 1 is not a unit quaternion (norm 1e+300)")
    arr = np.zeros((2000, 4), dtype=np.longdouble)
    arr[:, 0] = np.arange(2000) * 1e-3
    arr[500, 2] = np.longdouble("1e311")
    with np.errstate(over="ignore"):
        narrow = np.asarray(arr[500, 2], np.float64)
    if not np.isinf(narrow):  # pragma: no cover
        pytest.skip("long double is float64 on this platform")
    np.save(tmp_path / "wide.npy", arr)
    wide = str(tmp_path / "wide.npy")
    _refused(capsys, tmp_path, ["advise", "--imu", wide, "--rates", "--units", "rad/s",
                                "--figure", str(tmp_path / "a.png")],
             "wide.npy: NaN or infinity in data row 501")
    # run reads .npy logs in readers.py (not this change's): it must stay as quiet
    _refused(capsys, tmp_path, ["run", "--imu", wide, "--rates", "--units", "rad/s",
                                "--out", str(tmp_path / "r.csv")],
             "wide.npy: NaN or infinity in data row 501")
    f = np.linspace(1.0, 400.0, 50)
    psd = _csv(tmp_path / "psd.csv", "f_hz,im_gyz,im_gzx,im_gxy", f, np.full((50, 3), 1e308))
    _refused(capsys, tmp_path, ["advise", "--psd", psd, "--sample-rate-hz", "1000",
                                "--figure", str(tmp_path / "a.png")],
             "psd.csv: data row 1 (im_gyz = 1e+308)", "rad²/s²/Hz")


def test_advise_names_the_file_of_a_short_log_and_of_a_bad_psd(tmp_path, capsys):
    """Item 4: a short log, a non-UTF-8 PSD (a raw codec error) and a missing one (74)."""
    t = np.arange(20) * 1e-3
    short = _csv(tmp_path / "short.csv", "t,gx[rad/s],gy[rad/s],gz[rad/s]", t,
                 np.zeros((20, 3)))
    _refused(capsys, tmp_path, ["advise", "--imu", short, "--rates", "--figure",
                                str(tmp_path / "a.png")],
             "short.csv: 20 samples", "--no-verify")
    bad = tmp_path / "psd.csv"
    bad.write_bytes(b"f_hz,im_gyz,im_gzx,im_gxy\n1,0,0,0\n\xff\xfe,1,1,1\n")
    _refused(capsys, tmp_path, ["advise", "--psd", str(bad), "--sample-rate-hz", "1000",
                                "--figure", str(tmp_path / "a.png")],
             "psd.csv: not UTF-8 text", "data row 2")
    _refused(capsys, tmp_path, ["advise", "--psd", str(tmp_path / "none.csv"),
                                "--sample-rate-hz", "1000", "--figure",
                                str(tmp_path / "a.png")],
             "none.csv: no such PSD file")


@pytest.mark.parametrize(("option", "needle"), [
    (["--init-height=-1e7"], "initial height must lie within -20000…1e+06 m"),
    (["--init-height=nan"], "initial height must be finite"),
    (["--init-lon", "1e308"], "initial longitude must lie within ±360°"),
    (["--init-attitude", "1e308", "0", "0"], "angles must lie within ±360°"),
    (["--init-attitude", "0", "-361", "0"], "angles must lie within ±360°"),
])
def test_nav_initial_state_and_ahrs_declination_are_bounded(tmp_path, capsys, option,
                                                            needle):
    """Item 5: nav's initial height, longitude and attitude, ahrs's declination."""
    n = 200
    t = np.arange(n) * 0.01
    log = _csv(tmp_path / "nav.csv", NAV_HEADER, t, np.zeros((n, 3)),
               np.tile([0.0, 0.0, -9.80665], (n, 1)))
    base = ["nav", "--imu", log, "--init-lat", "45", "--out", str(tmp_path / "n.csv")]
    place = ["--init-lon", "7", "--init-height", "0"]
    _refused(capsys, tmp_path, [*base, *place, *option], needle)
    for declination in ("1e308", "-180.5", "nan"):
        _refused(capsys, tmp_path, ["ahrs", "--imu", log, "--declination-deg", declination,
                                    "--out", str(tmp_path / "a.csv")],
                 "--declination-deg must lie within ±180°")
    # the bounds' ends are accepted: a longitude in the 0…360° convention, a 300 km height
    assert main([*base, "--init-lon", "350", "--init-height", "3e5", "--trailing",
                 "drop"]) == 0  # 200 samples: 199 intervals, one short of an update


SCENARIO = """algorithms = ["rotvec:N=2"]
seed = 1
[motion]
motion = "{motion}"
[sensor]
sample_rate_hz = 1000.0
duration = 0.05
[gyro]
bias = {bias}
"""


@pytest.mark.parametrize(("motion", "bias", "needle"), [
    ("spin", "0.0", "pure spin needs a non-zero spin_rate_dps"),
    ("coning", "-1e308", "gyro bias turns the body by 1e+305 rad per sample"),
    ("coning", "4000.0", "at most π (Nyquist)"),
])
def test_a_scenario_that_validates_runs(tmp_path, capsys, monkeypatch, motion, bias, needle):
    """Item 6: such scenarios passed validation, failed when run and left an empty
    OUT/cases/; now validation refuses them, and a sweep that fails when run removes the
    directories it made."""
    scn = tmp_path / "s.toml"
    scn.write_text(SCENARIO.format(motion=motion, bias=bias))
    out = tmp_path / "out"
    _refused(capsys, tmp_path, ["sweep", str(scn), "--out", str(out), "--workers", "1"],
             "s.toml: case 0", needle)
    with pytest.raises(ValueError, match=re.escape(needle)):
        sweep_app.load_scenario(scn)
    # a bias within π per sample validates and runs
    scn.write_text(SCENARIO.format(motion="coning", bias="3000.0"))
    assert main(["sweep", str(scn), "--out", str(out), "--workers", "1", "--format",
                 "csv"]) == 0
    assert (out / "results.csv").is_file()

    def fails(case):
        raise ValueError("q_est contains NaN or infinity")

    monkeypatch.setattr(sweep_app, "case_metrics", fails)
    fresh = tmp_path / "fresh" / "out"
    _refused(capsys, tmp_path, ["sweep", str(scn), "--out", str(fresh), "--workers", "1"],
             "q_est contains NaN")
    assert not (tmp_path / "fresh").exists()
