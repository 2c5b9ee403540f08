"""Near a pole the north-pointing NED mechanisation is singular: a flight that reaches
89.9° is refused with one clear line, the Python API raises instead of returning NaN, and
latitude never leaves [−90°, 90°]."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.cli import main
from strapdown.navigation import POLE_LIMIT_DEG, NavStream, navigate

H = 0.01
G = 9.80665


def _level_flight(n):
    """Increments of a level body at rest in NED (specific force up): gyro zero (Earth rate
    is below the test's concern), accelerometer −g h on z."""
    return np.zeros((n, 3)), np.tile([0.0, 0.0, -G * H], (n, 1))


def test_a_start_near_the_pole_is_refused():
    g, a = _level_flight(10)
    with pytest.raises(ValueError, match=r"within 0\.1° of a pole"):
        navigate(g, a, 2, h=H, lat=math.radians(89.99999), lon=0.0, height=0.0)
    with pytest.raises(ValueError, match=r"within 0\.1° of a pole"):
        NavStream(2, h=H, lat=math.radians(-89.95), lon=0.0, height=0.0)


def test_a_flight_reaching_the_limit_is_refused_at_its_time():
    """Northward at 300 m/s from 89.85°: the limit (about 5.6 km on) is reached near 18.5 s."""
    g, a = _level_flight(3000)
    with pytest.raises(ValueError, match=r"reaches latitude 89\.9\d*° at t = 1\d\.\d+ s"):
        navigate(g, a, 2, h=H, lat=math.radians(89.85), lon=0.0, height=0.0,
                 v0=[300.0, 0.0, 0.0])
    stream = NavStream(2, h=H, lat=math.radians(89.85), lon=0.0, height=0.0,
                       v0=[300.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"within 0\.1° of a pole"):
        for s in range(0, 3000, 500):
            sol = stream.feed(g[s:s + 500], a[s:s + 500])
            assert np.all(np.abs(np.degrees(sol.lat)) <= POLE_LIMIT_DEG)


def test_mid_latitude_flight_is_unaffected():
    g, a = _level_flight(1000)
    sol = navigate(g, a, 2, h=H, lat=math.radians(45.0), lon=0.0, height=0.0,
                   v0=[300.0, 0.0, 0.0])
    assert np.all(np.isfinite(sol.lat)) and abs(math.degrees(sol.lat[-1]) - 45.0) < 0.1


def test_cli_refuses_in_one_line(tmp_path, capsys):
    n = 200
    t = np.arange(1, n + 1) * H
    np.savetxt(tmp_path / "n.csv", np.column_stack([t, np.zeros((n, 3)),
                                                   np.tile([0.0, 0.0, -G], (n, 1))]),
               delimiter=",", comments="",
               header="t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s2],ay[m/s2],az[m/s2]")
    with pytest.raises(SystemExit) as exc:
        main(["nav", "--imu", str(tmp_path / "n.csv"), "--init-lat", "89.99999",
              "--init-lon", "0", "--init-height", "0", "--out", str(tmp_path / "o.csv")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "of a pole" in err[0]
    assert not (tmp_path / "o.csv").exists()
