"""`strapdown nav`'s output and the public navigation API (issue 26, item 4): Euler angles
beside the quaternion, the initial-state row (bit for bit the library's row 0), the warning
on a duplicated first increment row, the trailing partial update, ``--gravity``,
``import strapdown``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from strapdown.apps.nav import NAV_COLUMNS
from strapdown.cli import main
from strapdown.navigation import navigate
from strapdown.rotation.dcm import dcm_from_quat, quat_from_dcm
from strapdown.rotation.euler import dcm_from_euler_zyx, euler_zyx_from_dcm
from strapdown.truth.trajectory import EarthFlight, EarthSegment

H = 0.01
_FLIGHT = EarthFlight([EarthSegment(2.0), EarthSegment(3.0, 4.0, 6.0)], lat_deg=52.0,
                      lon_deg=-3.0, height=350.0, speed=80.0, heading_deg=20.0, ramp=1.0)
YPR = (20.0, 1.5, -2.0)
INIT = ["--init-lat", "52", "--init-lon", "-3", "--init-height", "350", "--init-velocity",
        "75", "27", "0", "--init-attitude", *map(str, YPR)]
INC = ["t", "gx[rad]", "gy[rad]", "gz[rad]", "ax[m/s]", "ay[m/s]", "az[m/s]"]


@pytest.fixture(scope="module")
def flight():
    edges = np.arange(round(_FLIGHT.duration / H) + 1) * H  # 500 increments
    g, a = _FLIGHT.increments(edges)
    return edges, g, a


def _write_csv(path, names, t, *cols):
    table = np.column_stack([t, *cols])
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in table:
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    return str(path)


def _nav(tmp_path, log, *extra, out="nav.npz"):
    path = tmp_path / out
    code = main(["nav", "--imu", log, "--increments", *INIT, "--no-progress", *extra, "--out",
                 str(path)])
    assert code == 0
    return path, json.loads((tmp_path / f"{out}.meta.json").read_text())


def test_columns_put_euler_angles_after_the_quaternion():
    assert NAV_COLUMNS[7:] == ("qw", "qx", "qy", "qz", "yaw_deg", "pitch_deg", "roll_deg")


@pytest.mark.parametrize("structure", ["conventional", "single-chain"])
def test_initial_row_and_updates_equal_the_library_bit_for_bit(tmp_path, flight, structure):
    edges, g, a = flight
    log = _write_csv(tmp_path / "log.csv", INC, edges[1:] + 5.0, g, a)
    path, meta = _nav(tmp_path, log, "--structure", structure, "--subsamples", "2")
    z = np.load(path)
    q0 = quat_from_dcm(dcm_from_euler_zyx(*np.radians(YPR)))
    sol = navigate(g, a, 2, h=H, lat=math.radians(52.0), lon=math.radians(-3.0), height=350.0,
                   v0=[75.0, 27.0, 0.0], q0=q0, structure=structure,
                   t0=float(edges[1] + 5.0) - H)
    # row 0 the initial state at the first stamp - h, then the updates: all bit for bit
    assert z["t"][0] == (edges[1] + 5.0) - H and meta["t0_s"] == z["t"][0]
    lib = np.column_stack([sol.t, np.degrees(sol.lat), np.degrees(sol.lon), sol.height,
                           sol.v, sol.q])
    assert np.array_equal(np.column_stack([z[k] for k in NAV_COLUMNS[:11]]), lib)
    assert meta["rows"] == meta["outputs"] + 1 == z["t"].size
    # the Euler angles are the quaternion's z-y-x angles; row 0 the attitude given
    ypr = np.degrees(np.column_stack(euler_zyx_from_dcm(dcm_from_quat(sol.q))))
    assert np.array_equal(np.column_stack([z["yaw_deg"], z["pitch_deg"], z["roll_deg"]]), ypr)
    assert np.allclose(ypr[0], YPR, rtol=0, atol=1e-12)


def test_rate_log_starts_at_its_first_stamp(tmp_path, flight):
    edges, _, _ = flight
    w, f = _FLIGHT.sensed(edges)
    log = _write_csv(tmp_path / "rates.csv", ["t", "gx[rad/s]", "gy[rad/s]", "gz[rad/s]",
                                              "ax[m/s^2]", "ay[m/s^2]", "az[m/s^2]"],
                     edges + 3.0, w, f)  # 501 samples: 500 intervals
    out = tmp_path / "nav.csv"
    assert main(["nav", "--imu", log, *INIT, "--subsamples", "2", "--no-progress", "--out",
                 str(out)]) == 0
    with open(out) as fh:
        assert fh.readline().strip() == ",".join(NAV_COLUMNS)
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert rows.shape == (251, 14) and rows[0, 0] == 3.0 and rows[1, 0] == pytest.approx(3.02)
    # the state given (degrees through radians and back: to round-off)
    assert np.allclose(rows[0, 1:7], [52.0, -3.0, 350.0, 75.0, 27.0, 0.0], rtol=1e-15, atol=0)


def test_a_duplicated_first_increment_row_warns(tmp_path, flight, capsys):
    edges, g, a = flight
    dup_g, dup_a = np.vstack([g[:1], g]), np.vstack([a[:1], a])
    t = np.arange(1, dup_g.shape[0] + 1) * H  # the copy at its own stamp
    log = _write_csv(tmp_path / "dup.csv", INC, t, dup_g, dup_a)
    _, meta = _nav(tmp_path, log, "--trailing", "drop")
    err = capsys.readouterr().err
    assert "warning:" in err and "first two increment rows" in err and "identical" in err
    assert any("duplicated first row" in w for w in meta["warnings"])
    # the same log without the copy: no warning
    clean = _write_csv(tmp_path / "clean.csv", INC, edges[1:], g, a)
    _, meta = _nav(tmp_path, clean, out="clean.npz")
    assert "identical" not in capsys.readouterr().err and not meta["warnings"]


def test_identical_rows_of_a_steady_start_do_not_warn(tmp_path, capsys):
    """A noiseless body at rest: every row equal because the motion is constant."""
    n = 40
    g = np.tile([1e-7, 0.0, -1e-7], (n, 1))
    a = np.tile([0.0, 0.0, -9.81 * H], (n, 1))
    log = _write_csv(tmp_path / "rest.csv", INC, np.arange(1, n + 1) * H, g, a)
    _, meta = _nav(tmp_path, log)
    assert "identical" not in capsys.readouterr().err and not meta["warnings"]


def test_a_trailing_partial_update_is_dropped_and_said_or_an_error(tmp_path, flight, capsys):
    edges, g, a = flight
    log = _write_csv(tmp_path / "log.csv", INC, edges[1:], g, a)  # 500 increments
    before = sorted(tmp_path.iterdir())
    with pytest.raises(SystemExit) as exc:
        main(["nav", "--imu", log, "--increments", *INIT, "--subsamples", "3", "--trailing",
              "error", "--out", str(tmp_path / "n.csv")])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and err.count("\n") == 1
    assert "leave 2 sample(s)" in err and "N = 3" in err and "--trailing drop" in err
    assert sorted(tmp_path.iterdir()) == before  # nothing written
    path, meta = _nav(tmp_path, log, "--subsamples", "3")  # the default drops, and says so
    assert meta["trailing_samples_dropped"] == 2 and meta["outputs"] == 166
    assert meta["trailing"] == "drop"
    assert np.load(path)["t"].size == 167
    assert "2 trailing sample(s)" in capsys.readouterr().err
    # whole updates, and the single chain (an update every sample), leave nothing
    for extra in (["--subsamples", "4"], ["--structure", "single-chain", "--subsamples", "3"]):
        _, meta = _nav(tmp_path, log, *extra)
        assert meta["trailing_samples_dropped"] == 0 and meta["trailing"] == "drop"


def test_help_states_the_output_conventions(capsys):
    with pytest.raises(SystemExit):
        main(["nav", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for phrase in ("yaw_deg,pitch_deg,roll_deg", "Row 0 is the initial state",
                   "first stamp - h for increments", "end of its interval", "--trailing",
                   "duplicated first row", "over the interval that ends at its stamp",
                   "--gravity {wgs84,linear}", "linear height correction"):
        assert phrase in text, phrase


def test_gravity_model_is_the_library_s_and_recorded(tmp_path, flight):
    edges, g, a = flight
    log = _write_csv(tmp_path / "log.csv", INC, edges[1:], g, a)
    wgs, meta = _nav(tmp_path, log, "--subsamples", "2")
    lin, meta_lin = _nav(tmp_path, log, "--subsamples", "2", "--gravity", "linear",
                         out="lin.npz")
    assert meta["gravity"] == "wgs84" and meta_lin["gravity"] == "linear"
    q0 = quat_from_dcm(dcm_from_euler_zyx(*np.radians(YPR)))
    sol = navigate(g, a, 2, h=H, lat=math.radians(52.0), lon=math.radians(-3.0), height=350.0,
                   v0=[75.0, 27.0, 0.0], q0=q0, t0=0.0, gravity="linear")
    got = np.load(lin)
    assert np.array_equal(got["height_m"], sol.height) and np.array_equal(got["vd"], sol.v[:, 2])
    # at 350 m the linear correction lacks 3 h²/a² γ0 = 8.9e-8 m/s²: after 5 s the vertical
    # velocities differ by about that times 5 s
    dvd = np.load(wgs)["vd"][-1] - got["vd"][-1]
    assert 0.8 * 4.4e-7 < dvd < 1.2 * 4.4e-7


def test_import_strapdown_exposes_the_navigation():
    import strapdown
    from strapdown import navigation

    assert strapdown.navigate is navigation.navigate
    assert strapdown.NavStream is navigation.NavStream
    assert strapdown.NavSolution is navigation.NavSolution
    assert {"navigate", "NavStream", "NavSolution"} <= set(strapdown.__all__)
    assert "t₀ = t_1 − h" in (strapdown.__doc__ or "")
