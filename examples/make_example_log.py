"""Example logs for the README and the tutorial, written into the current directory.

Always: ``gyro.csv``, a 4 s, 1 kHz gyro log of spin (720 °/s) with 2° coning at 3 Hz in deg/s
with the units in its header (``t[s],gx[deg/s],gy[deg/s],gz[deg/s]``), and ``truth.csv``,
the exact attitude at the same times (``t,qw,qx,qy,qz``, q_n_b). On request, the same motion
in the other layouts the documentation uses:

``--increments FILE.npy``
    exact angular increments, an (n, 4) array ``[t, dθx, dθy, dθz]``: t is the end of each
    interval (s), the increments are in rad (no units in the file: pass ``--units rad``).
``--plain FILE.csv``
    rates with a plain header ``time,wx,wy,wz`` (deg/s; pass ``--units`` and ``--columns``).
``--gaps FILE.csv``
    ``gyro.csv`` with two stretches of rows missing (50 ms at 1.5 s, 20 ms at 3 s).
``--imu9 FILE.csv``
    a 20 s, 200 Hz gyro + accelerometer + magnetometer recording for ``strapdown ahrs``:
    ``t,gx,gy,gz,ax,ay,az,mx,my,mz`` in deg/s, g and µT, of a slowly coning and spinning
    body at rest otherwise (gravity and a magnetic field only, in ENU).
``--nav FILE.csv``
    a 2 min, 100 Hz gyro + accelerometer log for ``strapdown nav``: rates and specific
    force (``t,gx[deg/s],gy[deg/s],gz[deg/s],ax[m/s^2],ay[m/s^2],az[m/s^2]``, body FRD) of
    a flight over the WGS-84 Earth from 45° N, 7° E, 300 m, heading 30° at 60 m/s (VN VE VD
    = 51.96 30 0), level: 30 s straight, a 3 °/s turn, a 4° climb.

Usage: ``python examples/make_example_log.py [--increments flight.npy] [--plain log.csv]
[--gaps gappy.csv] [--imu9 recording.csv] [--nav nav-log.csv]``.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from strapdown.rotation.dcm import dcm_from_quat
from strapdown.truth import sensors
from strapdown.truth.motions import SpinConing

RATE_HZ = 1000.0
SAMPLES = 4001  # 4 s at 1 kHz, t = 0 … 4 s


def _motion() -> SpinConing:
    return SpinConing(half_angle=math.radians(2.0), cone_rate=2 * math.pi * 3,
                      spin_rate=math.radians(720))


def _csv(path: str, table: np.ndarray, header: str, fmt: str = "%.10g") -> None:
    np.savetxt(path, table, delimiter=",", fmt=fmt, header=header, comments="")


def gyro_and_truth(m: SpinConing) -> None:
    """``gyro.csv`` (deg/s, header units) and ``truth.csv``."""
    t = np.arange(SAMPLES) / RATE_HZ
    _csv("gyro.csv", np.column_stack([t, np.degrees(m.rate(t))]),
         "t[s],gx[deg/s],gy[deg/s],gz[deg/s]")
    _csv("truth.csv", np.column_stack([t, m.attitude(t)]), "t,qw,qx,qy,qz", fmt="%.17g")


def increments(m: SpinConing, path: str) -> None:
    """Exact increments over each 1 ms interval ending at t (rad), as (n, 4) ``.npy``."""
    rec = sensors.increments(m, 1.0 / RATE_HZ, SAMPLES - 1)  # edges 0 … 4 s
    np.save(path, np.column_stack([rec.t[1:], rec.data]))


def plain(m: SpinConing, path: str) -> None:
    """Rates in deg/s under a header without units: ``time,wx,wy,wz``."""
    t = np.arange(SAMPLES) / RATE_HZ
    _csv(path, np.column_stack([t, np.degrees(m.rate(t))]), "time,wx,wy,wz")


def gaps(m: SpinConing, path: str) -> None:
    """``gyro.csv`` without rows 1500–1549 and 3000–3019 (two logging dropouts)."""
    t = np.arange(SAMPLES) / RATE_HZ
    keep = np.ones(SAMPLES, bool)
    keep[1500:1550] = keep[3000:3020] = False
    _csv(path, np.column_stack([t, np.degrees(m.rate(t))])[keep],
         "t[s],gx[deg/s],gy[deg/s],gz[deg/s]")


def imu9(path: str) -> None:
    """Gyro, accelerometer and magnetometer of a body coning at 0.5 Hz (10°) and spinning at
    20 °/s, otherwise at rest: specific force = gravity, field 20 µT north, 40 µT down."""
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    t = np.arange(4001) / 200.0
    c = dcm_from_quat(m.attitude(t))  # C_n_b: body axes in ENU
    acc_g = np.einsum("nji,j->ni", c, [0.0, 0.0, 1.0])  # g, up in ENU
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0])  # µT
    _csv(path, np.column_stack([t, np.degrees(m.rate(t)), acc_g, mag]),
         "t,gx,gy,gz,ax,ay,az,mx,my,mz")


def nav_log(path: str) -> None:
    """An Earth flight's ideal rates and specific force at 100 Hz (see the module docstring)."""
    from strapdown.truth.trajectory import EarthFlight, EarthSegment

    fl = EarthFlight([EarthSegment(30.0), EarthSegment(45.0, 3.0), EarthSegment(45.0, 0.0, 4.0)],
                     lat_deg=45.0, lon_deg=7.0, height=300.0, speed=60.0, heading_deg=30.0)
    t = np.arange(12001) / 100.0
    w, f = fl.sensed(t)
    _csv(path, np.column_stack([t, np.degrees(w), f]),
         "t,gx[deg/s],gy[deg/s],gz[deg/s],ax[m/s^2],ay[m/s^2],az[m/s^2]", fmt="%.17g")


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    p.add_argument("--increments", metavar="FILE.npy", help="also write exact increments")
    p.add_argument("--plain", metavar="FILE.csv", help="also write rates under time,wx,wy,wz")
    p.add_argument("--gaps", metavar="FILE.csv", help="also write the rate log with two gaps")
    p.add_argument("--imu9", metavar="FILE.csv", help="also write a 9-axis AHRS recording")
    p.add_argument("--nav", metavar="FILE.csv", help="also write an Earth flight's nav log")
    a = p.parse_args(argv)
    m = _motion()
    gyro_and_truth(m)
    written = ["gyro.csv", "truth.csv"]
    for path, write in ((a.increments, increments), (a.plain, plain), (a.gaps, gaps)):
        if path:
            write(m, path)
            written.append(path)
    if a.imu9:
        imu9(a.imu9)
        written.append(a.imu9)
    if a.nav:
        nav_log(a.nav)
        written.append(a.nav)
    print("wrote " + ", ".join(written))


if __name__ == "__main__":
    main()
