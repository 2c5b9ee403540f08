"""``strapdown ahrs``: the AHRS filter over a recording, written atomically.

Inputs: a BROAD ``.mat`` trial, or a CSV with a header naming time, gyro,
accelerometer and (optionally) magnetometer columns — default
``t,gx,gy,gz,ax,ay,az,mx,my,mz`` — in declared units (gyro ``rad/s`` or
``deg/s``, accelerometer ``m/s2`` or ``g``; the magnetometer in any unit).
Validation names the row of a NaN, a duplicated or non-monotonic time stamp
and non-uniform sampling; a gyro whose magnitudes suggest deg/s declared as
rad/s warns; an accelerometer whose norm is not about g (m/s² declared, g
given) is an error. Without magnetometer columns the filter runs in its
documented degraded mode: no heading (the gyro's integral from yaw 0), said
on stderr and in the metadata.

Output: ``t,qw,qx,qy,qz`` (q_n_b, n = ENU by default or NED) and the
estimated gyro bias ``bias_x,bias_y,bias_z`` (rad/s), as CSV or ``.npz``,
plus ``OUT.meta.json`` (frame, heading observed, algorithm, measurement
usage). The input is never overwritten.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from strapdown.ahrs import AhrsConfig, AhrsResult, MeasurementFlag, ekf
from strapdown.io import check_rows, csv_columns, warn_implausible_rate, write_attitude
from strapdown.io.files import write_text

__all__ = ["AhrsLog", "read_ahrs_log", "run_ahrs"]

DEFAULT_COLUMNS = ("t", "gx", "gy", "gz", "ax", "ay", "az", "mx", "my", "mz")


@dataclass(frozen=True)
class AhrsLog:
    """A validated IMU recording in SI units (``mag`` None when absent)."""

    t: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray
    mag: np.ndarray | None


def _csv(path: Path, columns):
    raw, units, have_mag = csv_columns(path, columns[:7], optional=columns[7:10])
    if units:
        raise ValueError(f"{path}: units in the header ({units}) are not read for AHRS logs; "
                         "name the columns plainly and declare --gyro-units/--acc-units")
    m = raw[:, 7:10] if have_mag else None
    return raw[:, 0], raw[:, 1:4], raw[:, 4:7], m


def read_ahrs_log(path, *, gyro_units: str = "rad/s", acc_units: str = "m/s2",
                  columns=DEFAULT_COLUMNS, use_magnetometer: bool = True) -> AhrsLog:
    """Read and validate a recording (see the module docstring)."""
    path = Path(path)
    if gyro_units not in ("rad/s", "deg/s"):
        raise ValueError(f"gyro units must be rad/s or deg/s, got {gyro_units!r}")
    if acc_units not in ("m/s2", "g"):
        raise ValueError(f"accelerometer units must be m/s2 or g, got {acc_units!r}")
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    if path.suffix.lower() == ".mat":
        from strapdown.io.broad import read_broad

        tr = read_broad(path)
        t, g, a, m = tr.t, tr.gyro, tr.acc, tr.mag
    elif path.suffix.lower() == ".csv":
        if len(columns) not in (7, 10):
            raise ValueError(f"columns must name t, 3 gyro, 3 accelerometer and optionally 3 "
                             f"magnetometer columns, got {len(columns)}")
        t, g, a, m = _csv(path, list(columns))
    else:
        raise ValueError(f"{path}: unsupported format (use a BROAD .mat or a CSV)")
    check_rows(path, t, [("time", [t]), ("gyro", [g]), ("accelerometer", [a]),
                         *((("magnetometer", [m]),) if m is not None else ())])
    if gyro_units == "deg/s":
        g = np.radians(g)
    if acc_units == "g":
        a = a * 9.80665
    warn_implausible_rate(path, g, gyro_units, suggestion="deg/s")
    if m is not None and not np.any(m):
        m = None
    return AhrsLog(t, np.ascontiguousarray(g), np.ascontiguousarray(a),
                   None if (m is None or not use_magnetometer) else np.ascontiguousarray(m))


def run_ahrs(imu, out, *, algorithm: str = "rate-single", frame: str = "ENU",
             config: AhrsConfig | None = None, gyro_units: str = "rad/s",
             acc_units: str = "m/s2", columns=DEFAULT_COLUMNS,
             use_magnetometer: bool = True) -> tuple[AhrsResult, dict]:
    """Filter a recording and write the attitude, biases and metadata atomically."""
    imu, out = Path(imu), Path(out)
    if out.resolve() == imu.resolve():
        raise ValueError("--out must not be the input file")
    if out.suffix.lower() not in (".csv", ".npz"):
        raise ValueError(f"{out}: output must be .csv or .npz")
    log = read_ahrs_log(imu, gyro_units=gyro_units, acc_units=acc_units, columns=columns,
                        use_magnetometer=use_magnetometer)
    res = ekf(log.t, log.gyro, log.acc, log.mag, algorithm=algorithm, config=config,
              frame=frame)
    write_attitude(out, res.t, res.q, extra={"bias_x": res.gyro_bias[:, 0],
                                            "bias_y": res.gyro_bias[:, 1],
                                            "bias_z": res.gyro_bias[:, 2]})
    meta = {
        "input": str(imu), "frame": frame, "quaternion": "q_n_b, Hamilton, scalar first",
        "heading_observed": res.heading_observed,
        "heading": ("magnetic" if res.config.declination_deg == 0 else "true")
        if res.heading_observed else "not observed (no magnetometer): gyro integral from yaw 0",
        "algorithm": algorithm, "samples": int(log.t.size), "outputs": int(res.t.size),
        "accelerometer_used": res.fraction(MeasurementFlag.ACC_USED),
        "magnetometer_used": (res.fraction(MeasurementFlag.MAG_USED) if res.heading_observed
                              else 0.0),
        "rest_updates": res.fraction(MeasurementFlag.REST),
        "config": asdict(res.config),
    }
    write_text(out.with_name(out.name + ".meta.json"), json.dumps(meta, indent=2))
    return res, meta
