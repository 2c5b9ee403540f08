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

Usage: ``python examples/make_example_log.py [--increments flight.npy] [--plain log.csv]
[--gaps gappy.csv] [--imu9 recording.csv]``.
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


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    p.add_argument("--increments", metavar="FILE.npy", help="also write exact increments")
    p.add_argument("--plain", metavar="FILE.csv", help="also write rates under time,wx,wy,wz")
    p.add_argument("--gaps", metavar="FILE.csv", help="also write the rate log with two gaps")
    p.add_argument("--imu9", metavar="FILE.csv", help="also write a 9-axis AHRS recording")
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
    print("wrote " + ", ".join(written))


if __name__ == "__main__":
    main()
