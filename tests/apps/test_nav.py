"""`strapdown nav`: an Earth flight's ideal log through the command line, against the truth
and the library; the rate-to-increment quadrature; streaming; bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.io import savemat

from strapdown.apps import nav as nav_app
from strapdown.apps.nav import NAV_COLUMNS, increments_from_rates
from strapdown.cli import main
from strapdown.navigation import navigate
from strapdown.truth import earth
from strapdown.truth.trajectory import EarthFlight, EarthSegment

H = 0.01
_FLIGHT = EarthFlight([EarthSegment(8.0), EarthSegment(12.0, 4.0, 6.0)], lat_deg=52.0,
                      lon_deg=-3.0, height=350.0, speed=80.0, heading_deg=20.0, ramp=4.0)


@pytest.fixture(scope="module")
def flight():
    edges = np.arange(round(_FLIGHT.duration / H) + 1) * H
    g, a = _FLIGHT.increments(edges)
    s0 = _FLIGHT.state(np.array([0.0]))
    return edges, g, a, s0


def _write_csv(path, names, t, *cols):
    table = np.column_stack([t, *cols])
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in table:
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def _init_args(s0, lat=52.0):
    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.rotation.euler import euler_zyx_from_dcm

    ypr = np.degrees(euler_zyx_from_dcm(dcm_from_quat(s0.q[0])))
    return ["--init-lat", repr(lat), "--init-lon", "-3.0", "--init-height", "350.0",
            "--init-velocity", *map(repr, s0.velocity[0].tolist()),
            "--init-attitude", *map(repr, [float(x) for x in ypr])]


def _read_out(path):
    with open(path) as f:
        assert f.readline().strip() == ",".join(NAV_COLUMNS)
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def _position_error(rows):
    tr = _FLIGHT.state(rows[:, 0])
    rn, re = earth.radii(tr.lat, tr.height)
    return np.stack([(np.radians(rows[:, 1]) - tr.lat) * rn,
                     (np.radians(rows[:, 2]) - tr.lon) * re * np.cos(tr.lat),
                     rows[:, 3] - tr.height], axis=-1), rows[:, 4:7] - tr.velocity


def test_increment_log_through_the_cli_equals_the_library_and_the_truth(tmp_path, flight,
                                                                        capsys):
    edges, g, a, s0 = flight
    log = tmp_path / "log.csv"
    _write_csv(log, ["t", "gx[rad]", "gy[rad]", "gz[rad]", "ax[m/s]", "ay[m/s]", "az[m/s]"],
               edges[1:], g, a)
    out = tmp_path / "nav.csv"
    assert main(["nav", "--imu", str(log), "--increments", *_init_args(s0), "--subsamples",
                 "2", "--out", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    rows = _read_out(out)
    # the initial state (at the first stamp - h), then one row per update
    assert rows.shape == (g.shape[0] // 2 + 1, len(NAV_COLUMNS))
    # the library on the same increments; the initial attitude went through yaw/pitch/roll
    # in decimal, so agreement is to round-off, not bit for bit
    sol = navigate(g, a, 2, h=H, lat=math.radians(52.0), lon=math.radians(-3.0), height=350.0,
                   v0=s0.velocity[0], q0=s0.q[0])
    assert np.allclose(rows[:, 0], sol.t, rtol=0, atol=1e-12)
    assert np.allclose(np.radians(rows[:, 1:3]), np.column_stack([sol.lat, sol.lon]),
                       rtol=0, atol=1e-14)
    assert np.allclose(rows[:, 4:7], sol.v, rtol=0, atol=1e-12)
    assert np.allclose(rows[:, 7:11], sol.q, rtol=0, atol=1e-14)
    # ideal increments at 100 Hz, 20 s with a turn and a climb: 2.4e-6 m, 3.1e-7 m/s
    dp, dv = _position_error(rows)
    assert np.max(np.abs(dp)) < 2e-5 and np.max(np.abs(dv)) < 2e-6


def test_rate_log_in_deg_s_and_g_navigates_like_the_increments(tmp_path, flight):
    edges, _, _, s0 = flight
    w, f = _FLIGHT.sensed(edges)  # exact rates and specific force at the sample times
    log = tmp_path / "rates.csv"
    _write_csv(log, ["time", "gx[deg/s]", "gy[deg/s]", "gz[deg/s]", "ax[g]", "ay[g]", "az[g]"],
               edges, np.degrees(w), f / 9.80665)
    out = tmp_path / "nav.csv"
    assert main(["nav", "--imu", str(log), *_init_args(s0), "--structure", "single-chain",
                 "--out", str(out), "--no-progress"]) == 0
    rows = _read_out(out)
    # the initial state at the first sample's stamp, then one row per sample interval
    assert rows.shape[0] == edges.size and rows[0, 0] == 0.0
    assert rows[1, 0] == pytest.approx(H)
    # the rates through the four-sample cubic quadrature (exact for cubics; the smooth
    # ramps have no kinks), single chain N = 3: 3.4e-7 m, 1.3e-7 m/s
    dp, dv = _position_error(rows)
    assert np.max(np.abs(dp)) < 5e-6 and np.max(np.abs(dv)) < 2e-6


@pytest.mark.parametrize(("algorithm", "updates", "left"), [("rate-single", 2000, 0),
                                                            ("rate-three", 666, 2)])
def test_rate_log_with_a_rate_family_navigates_like_the_library(tmp_path, flight, capsys,
                                                               algorithm, updates, left):
    """--algorithm: the rate family's velocity counterpart on the samples themselves
    (navigate_rates), its update period, the tail it cannot use counted; the library's
    numbers to round-off (the initial attitude went through yaw/pitch/roll)."""
    edges, _, _, s0 = flight
    w, f = _FLIGHT.sensed(edges)
    log = tmp_path / "rates.csv"
    _write_csv(log, ["t", "gx[rad/s]", "gy[rad/s]", "gz[rad/s]", "ax[m/s^2]", "ay[m/s^2]",
                     "az[m/s^2]"], edges, w, f)
    out = tmp_path / "nav.csv"
    assert main(["nav", "--imu", str(log), *_init_args(s0), "--algorithm", algorithm,
                 "--out", str(out), "--no-progress"]) == 0
    assert ("trailing sample(s)" in capsys.readouterr().err) is bool(left)
    rows = _read_out(out)
    assert rows.shape[0] == updates + 1 and rows[0, 0] == 0.0
    meta = json.loads((tmp_path / "nav.csv.meta.json").read_text())
    assert meta["algorithm"] == algorithm and meta["trailing_samples_dropped"] == left
    from strapdown.navigation import navigate_rates

    sol = navigate_rates(w, f, td=H, lat=math.radians(52.0), lon=math.radians(-3.0),
                         height=350.0, v0=s0.velocity[0], q0=s0.q[0], algorithm=algorithm)
    assert np.allclose(rows[:, 0], sol.t, rtol=0, atol=1e-12)
    assert np.allclose(rows[:, 4:7], sol.v, rtol=0, atol=1e-9)
    dp, dv = _position_error(rows)
    assert np.max(np.abs(dp)) < 1e-3 and np.max(np.abs(dv)) < 1e-3
    if left:
        _fails(capsys, tmp_path, ["nav", "--imu", str(log), *_init_args(s0), "--algorithm",
                                  algorithm, "--trailing", "error", "--out",
                                  str(tmp_path / "x.csv")], "after the last whole update")
    _fails(capsys, tmp_path, ["nav", "--imu", str(log), "--increments", *_init_args(s0),
                              "--algorithm", algorithm, "--out", str(tmp_path / "y.csv")],
           "it navigates rate logs")


def test_increments_from_rates_is_exact_for_cubics():
    rng = np.random.default_rng(7)
    c = rng.normal(size=(4, 3))
    h = 0.1
    t = np.arange(9) * h + 0.3
    w = sum(c[k] * t[:, None] ** k for k in range(4))
    prim = sum(c[k] * t[:, None] ** (k + 1) / (k + 1) for k in range(4))
    got = increments_from_rates(w, h)
    assert np.allclose(got[1:-1], np.diff(prim, axis=0)[1:-1], rtol=0, atol=1e-14)
    # the end intervals use the quadratic: exact for quadratics only
    w2 = sum(c[k] * t[:, None] ** k for k in range(3))
    p2 = sum(c[k] * t[:, None] ** (k + 1) / (k + 1) for k in range(3))
    assert np.allclose(increments_from_rates(w2, h), np.diff(p2, axis=0), rtol=0, atol=1e-14)
    assert np.allclose(increments_from_rates(w2[:2], h), 0.5 * h * (w2[0] + w2[1]))


@pytest.mark.parametrize("structure", ["conventional", "single-chain"])
def test_streamed_output_equals_one_chunk(tmp_path, flight, monkeypatch, structure):
    edges, g, a, s0 = flight
    data = tmp_path / "log.npz"
    np.savez(data, t=edges[1:], gyro=g, accel=a)
    args = ["nav", "--imu", str(data), "--increments", "--units", "rad", "--acc-units", "m/s",
            *_init_args(s0), "--structure", structure, "--subsamples", "3", "--trailing",
            "drop"]  # 2000 increments: 2 short of a conventional update of 3
    assert main([*args, "--out", str(tmp_path / "one.npz")]) == 0
    monkeypatch.setattr(nav_app, "CHUNK", 101)
    assert main([*args, "--out", str(tmp_path / "many.csv")]) == 0
    one = np.load(tmp_path / "one.npz")
    many = np.loadtxt(tmp_path / "many.csv", delimiter=",", skiprows=1)
    assert np.array_equal(np.column_stack([one[k] for k in NAV_COLUMNS]), many)


def test_psins_mat_increments(tmp_path, flight):
    edges, g, a, s0 = flight
    savemat(tmp_path / "imu.mat", {"imu": np.column_stack([g, a, edges[1:]])})
    out = tmp_path / "nav.csv"
    assert main(["nav", "--imu", str(tmp_path / "imu.mat"), "--increments", "--units", "rad",
                 *_init_args(s0), "--out", str(out)]) == 0
    dp, _ = _position_error(_read_out(out))
    assert np.max(np.abs(dp)) < 1e-3


def _fails(capsys, tmp_path, argv, message):
    before = sorted(tmp_path.iterdir())
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    assert sorted(tmp_path.iterdir()) == before  # nothing written


def test_bad_input_exits_2_and_writes_nothing(tmp_path, flight, capsys):
    edges, _, _, s0 = flight
    w, f = _FLIGHT.sensed(edges)
    gyro_only = tmp_path / "gyro.csv"
    _write_csv(gyro_only, ["t", "gx[rad/s]", "gy[rad/s]", "gz[rad/s]"], edges, w)
    in_g = tmp_path / "in_g.csv"
    _write_csv(in_g, ["t", "gx[rad/s]", "gy[rad/s]", "gz[rad/s]", "ax[m/s^2]", "ay[m/s^2]",
                      "az[m/s^2]"], edges, w, f / 9.80665)
    good = tmp_path / "good.csv"
    _write_csv(good, ["t", "gx[rad/s]", "gy[rad/s]", "gz[rad/s]", "ax[m/s²]", "ay[m/s²]",
                      "az[m/s²]"], edges, w, f)
    out = str(tmp_path / "nav.csv")
    init = _init_args(s0)
    _fails(capsys, tmp_path, ["nav", "--imu", str(gyro_only), *init, "--out", out],
           "no accelerometer columns")
    _fails(capsys, tmp_path, ["nav", "--imu", str(in_g), *init, "--out", out],
           "more likely in g")
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *_init_args(s0, 95.0), "--out", out],
           "latitude must lie within ±90°, got 95.0°")
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *_init_args(s0, -90.0), "--out", out],
           "within ±90°")
    bad_lon = [*init]
    bad_lon[bad_lon.index("--init-lon") + 1] = "nan"
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *bad_lon, "--out", out],
           "initial longitude must be finite")
    bad_v = [*init]
    bad_v[bad_v.index("--init-velocity") + 2] = "inf"
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *bad_v, "--out", out],
           "initial velocity (VN VE VD) must be finite")
    bad_att = [*init]
    bad_att[bad_att.index("--init-attitude") + 3] = "nan"
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *bad_att, "--out", out],
           "initial attitude (YAW PITCH ROLL) must be finite")
    _fails(capsys, tmp_path, ["nav", "--imu", str(good), *init, "--acc-units", "g", "--out",
                              out], "contradict the file's 'm/s2'")
    # the accepted unit warning runs (and says so)
    assert main(["nav", "--imu", str(in_g), *init, "--accept-unit-warning", "--out", out]) == 0
    assert "warning:" in capsys.readouterr().err
