"""The time base as every log command takes it: the fitted clock and its residuals in the
sidecars of run, ahrs and nav, the kind from the header's unit, columns by index, nav's
gap options, and refusals that name the option that gets past them."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from strapdown.cli import main
from strapdown.truth.motions import ClassicalConing

CONE = ClassicalConing(math.radians(1.0), 2 * math.pi * 2.0)


def _rate_csv(path, t, w, header="t,gx[rad/s],gy[rad/s],gz[rad/s]", fmt="%.17g"):
    np.savetxt(path, np.column_stack([t, w]), delimiter=",", header=header, comments="",
               fmt=fmt)
    return str(path)


def test_run_sidecar_carries_the_clock_and_its_residuals(tmp_path, capsys):
    """400 Hz stamps rounded to whole ms: the clock is fitted, the stamps classified as
    quantised, the residuals (≤ half a ms) recorded; the kind comes from the header."""
    k = np.arange(4000)
    t = np.rint(k * 2.5) / 1000.0
    log = _rate_csv(tmp_path / "r.csv", t, CONE.rate(k * 2.5e-3), fmt="%.6f")
    assert main(["run", "--imu", log, "--out", str(tmp_path / "o.csv")]) == 0
    meta = json.loads((tmp_path / "o.csv.meta.json").read_text())
    clock = meta["timing"]["clock"]
    assert meta["kind"] == "rate"
    assert clock["kind"] == "quantised" and clock["stamp_tick_s"] == pytest.approx(1e-3)
    assert clock["rate_hz"] == pytest.approx(400.0, rel=1e-6)
    assert 0.4e-3 < clock["residual_max_s"] <= 0.501e-3
    assert "stamps rounded to 1 ms" in capsys.readouterr().out


def test_run_columns_by_index_and_a_unit_row(tmp_path):
    t = np.arange(2000) * 1e-3
    w = CONE.rate(t)
    path = tmp_path / "lab.csv"
    with open(path, "w") as f:
        f.write("Time;Other;IMU Gyroscope;;\n")
        f.write("s;x;rad/s;rad/s;rad/s\n")
        np.savetxt(f, np.column_stack([t, np.zeros_like(t), w]), delimiter=";", fmt="%.17g")
    assert main(["run", "--imu", str(path), "--columns", "0,2,3,4", "--angles", "none",
                 "--out", str(tmp_path / "a.csv")]) == 0
    plain = _rate_csv(tmp_path / "plain.csv", t, w)
    assert main(["run", "--imu", plain, "--angles", "none", "--out",
                 str(tmp_path / "b.csv")]) == 0
    a = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    b = np.loadtxt(tmp_path / "b.csv", delimiter=",", skiprows=1)
    assert np.array_equal(a, b)


def test_run_refuses_the_time_column_as_a_gyro(tmp_path, capsys):
    t = np.arange(100) * 1e-2
    log = _rate_csv(tmp_path / "r.csv", t, np.zeros((100, 3)))
    with pytest.raises(SystemExit) as exc:
        main(["run", "--imu", log, "--columns", "t,t,t,t", "--out", str(tmp_path / "o.csv")])
    assert exc.value.code == 2
    assert "names 't' twice" in capsys.readouterr().err


def test_a_kind_the_header_does_not_say_is_asked_for(tmp_path, capsys):
    t = np.arange(100) * 1e-2
    log = _rate_csv(tmp_path / "r.csv", t, np.zeros((100, 3)), header="t,gx,gy,gz")
    with pytest.raises(SystemExit):
        main(["run", "--imu", log, "--units", "rad/s", "--out", str(tmp_path / "o.csv")])
    assert "pass --rates or --increments" in capsys.readouterr().err


def test_stamps_mode_refuses_jitter_and_names_the_options_that_help(tmp_path, capsys):
    rng = np.random.default_rng(7)
    t = np.arange(2000) * 1e-3 + rng.uniform(-2e-4, 2e-4, 2000)
    log = _rate_csv(tmp_path / "r.csv", t, CONE.rate(np.arange(2000) * 1e-3))
    with pytest.raises(SystemExit):
        main(["run", "--imu", log, "--timing", "stamps", "--out", str(tmp_path / "o.csv")])
    err = capsys.readouterr().err
    assert "--timing auto" in err and "--timing resample" in err
    assert "--on-gap" not in err  # no gap here: that option cannot help
    assert main(["run", "--imu", log, "--out", str(tmp_path / "o.csv")]) == 0


def _nav_csv(path, t, n):
    g = np.zeros((n, 3))
    a = np.tile([0.0, 0.0, -9.80665], (n, 1))  # NED body level at rest: specific force up
    np.savetxt(path, np.column_stack([t, g, a]), delimiter=",", comments="",
               header="t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s2],ay[m/s2],az[m/s2]",
               fmt="%.17g")
    return str(path)


def test_nav_gap_options_and_sidecar(tmp_path, capsys):
    k = np.delete(np.arange(1000), np.arange(400, 420))  # 20 samples (0.2 s) missing
    log = _nav_csv(tmp_path / "n.csv", k * 0.01, k.size)
    init = ["--init-lat", "45", "--init-lon", "7", "--init-height", "300"]
    with pytest.raises(SystemExit):
        main(["nav", "--imu", log, *init, "--out", str(tmp_path / "o.csv")])
    assert "--on-gap report bridges gaps up to 1 s" in capsys.readouterr().err
    assert not (tmp_path / "o.csv").exists()
    assert main(["nav", "--imu", log, *init, "--on-gap", "report", "--trailing", "drop",
                 "--out", str(tmp_path / "o.csv")]) == 0  # 1000 samples: 999 intervals
    assert "20 missing sample(s) bridged" in capsys.readouterr().err
    meta = json.loads((tmp_path / "o.csv.meta.json").read_text())
    assert meta["bridged_samples"] == 20
    assert meta["timing"]["clock"]["missing_samples"] == 20
    assert meta["timing"]["clock"]["rate_hz"] == pytest.approx(100.0)


def test_empty_cells_in_columns_not_read_do_not_refuse_the_log(tmp_path):
    """A lab file whose reference columns are empty where the optical system lost the body:
    only the columns named are read."""
    t = np.arange(2000) * 1e-3
    w = CONE.rate(t)
    rows = [f"{a!r};{'' if k % 7 == 0 else '0.5'};{b!r};{c!r};{d!r}"
            for k, (a, (b, c, d)) in enumerate(zip(t.tolist(), w.tolist(), strict=True))]
    path = tmp_path / "lab.csv"
    path.write_text("Time;Vicon;IMU Gyroscope;;\ns;W;rad/s;rad/s;rad/s\n" + "\n".join(rows) + "\n")
    assert main(["run", "--imu", str(path), "--columns", "0,2,3,4", "--angles", "none",
                 "--out", str(tmp_path / "a.csv")]) == 0
    plain = _rate_csv(tmp_path / "plain.csv", t, w)
    assert main(["run", "--imu", plain, "--angles", "none", "--out",
                 str(tmp_path / "b.csv")]) == 0
    assert np.array_equal(np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1),
                          np.loadtxt(tmp_path / "b.csv", delimiter=",", skiprows=1))


def test_every_command_help_points_to_the_conventions_page(capsys):
    from strapdown.cli import COMMANDS

    names = [c.__name__.rsplit(".", 1)[-1].replace("_", "-") for c in COMMANDS]
    for name in names:
        with pytest.raises(SystemExit):
            main([name, "--help"])
        assert "docs/conventions.md" in capsys.readouterr().out, name


def test_ahrs_refuses_too_few_samples_naming_the_file(tmp_path):
    """Three rows (found by the fuzz campaign): the filter's own check, an InputError that
    names the recording, on the bridged route as on the segment route."""
    from strapdown import InputError
    from strapdown.apps.ahrs_log import run_ahrs

    path = tmp_path / "three.csv"
    path.write_text("t,gx,gy,gz,ax,ay,az,mx,my,mz\n0,0,0,0,0,0,9.8,20,0,-40\n"
                    "0.01,0,0,0,0,0,9.8,20,1,-40\n0.02,0,0,0.01,0,0,9.8,20,0,-40\n")
    for on_gap in ("report", "split"):
        with pytest.raises(InputError, match=r"three\.csv.*3 samples.* at least 4"):
            run_ahrs(path, tmp_path / "o.csv", gyro_units="rad/s", on_gap=on_gap)
    assert not (tmp_path / "o.csv").exists()
