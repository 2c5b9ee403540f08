"""``strapdown nav``: position, velocity and attitude on the WGS-84 Earth from a gyro and
accelerometer log, streamed, written atomically.

A nav log holds a time column and gyro and accelerometer axes: a CSV with a header
(``t,gx,gy,gz,ax,ay,az``, the names and units of :mod:`strapdown.io.readers`, e.g.
``gx[deg/s]``, ``ax[m/s^2]``), an ``.npz`` or HDF5 file with arrays ``t``, ``gyro`` and
``accel``, or a ``.mat`` file (PSINS ``[wm vm t]`` increments, BROAD ``imu_gyr``/``imu_acc``
rates). Rates (gyro rad/s or deg/s, accelerometer m/s² or g) are turned into increments
over the sample intervals by the cubic through four neighbouring samples
(:func:`increments_from_rates`); increment logs (``--increments``) hold rad (or deg) and
m/s. The gyro is read by :func:`strapdown.io.read_imu` (its columns, units, row checks and
gap detection); the accelerometer by the small reader here, on the same helpers
(:func:`~strapdown.io.readers.csv_columns`, :func:`~strapdown.io.readers.check_rows`),
because ``read_imu`` reads gyro axes only.

Validation: a log without accelerometer columns, a unit the file contradicts, NaN or
infinity (row named), gaps and non-uniform stamps are errors; so is a specific force beyond
:data:`MAX_SPECIFIC_FORCE` (row named; increments: over their interval) and an
accelerometer whose median norm suggests the other unit (≈ 1 declared as m/s²: the log is
in g — gravity alone gives 9.8 m/s² — or ≈ 9.8 declared as g) unless
``accept_unit_warning``. The initial state is checked before the log is read: everything
finite, latitude within ±90°, longitude within ±:data:`MAX_LONGITUDE_DEG` (either
convention, −180…180° or 0…360°; the output continues from the value given), height within
:data:`HEIGHT_RANGE_M` (the deepest ocean trench to 1000 km: the second-order height
correction of normal gravity stays within 2 % of the inverse-square law there, and is wrong
beyond), Euler angles within ±360°.

Trailing samples: the conventional structure updates every N samples; increments that do
not fill the last update (fewer than N left at the end) are dropped and counted in the
summary, and the command line says so on stderr (``trailing="drop"``, the default: a
rate log of n samples gives n − 1 increments, so half of all logs leave one), or they
are an error naming how many are left (``trailing="error"``, ``--trailing error``). They
were dropped silently before. The single chain updates every sample and never leaves any.

Gravity: WGS-84 normal gravity (Somigliana) with the second-order height correction
(``gravity="wgs84"``, ``--gravity wgs84``, the default) or its linear term only
(``"linear"``), as :func:`strapdown.navigation.earth.navigate`.

A duplicated first row: an increment log whose first two rows hold identical values (at
different stamps: a common simulator export repeats the first row, and the extra
increment costs 145 m in 10 min on a manoeuvre) warns (:class:`DuplicateRowWarning`, in
the summary's warnings and on stderr). A log whose first rows are all equal (a body at
rest or in steady motion, simulated without noise) is not flagged: the rows agree because
the motion does, so only rows 0 and 1 equal with row 2 different warn.

Output: ``t,lat_deg,lon_deg,height_m,vn,ve,vd,qw,qx,qy,qz,yaw_deg,pitch_deg,roll_deg``
(NED, ``q_n_b`` Hamilton, scalar first, and its z-y-x Euler angles of the body in NED,
pitch within ±90°, roll 0 at gimbal lock), CSV or ``.npz``. Row 0 is the initial state
(as :func:`~strapdown.navigation.earth.navigate`'s :class:`NavSolution` has), at
``t0``: for increments the start of the first interval, the first stamp − h (each
increment's stamp is the end of its interval); for rates the first sample's stamp. Then
one row per update, ``t`` the end of the update. The navigation runs in chunks through
:class:`strapdown.navigation.earth.NavStream` (bit for bit the one-shot
:func:`~strapdown.navigation.earth.navigate`), each written as it completes to a
temporary file renamed over the target at the end, so nothing is written on failure.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray
from tqdm import tqdm

from strapdown._core.errors import InputError
from strapdown._core.kinds import InputKind
from strapdown.algorithms.rate import JITTER_TOLERANCE as STAMP_TOLERANCE
from strapdown.algorithms.velocity import NavStructure
from strapdown.io import read_imu
from strapdown.io.containers import read_hdf5, read_mat, read_npz
from strapdown.io.files import write_csv_rows
from strapdown.io.readers import (
    ACC_COLUMNS,
    GYRO_COLUMNS,
    PSINS_VARIABLES,
    GyroUnit,
    UnitAction,
    UnitWarning,
    canonical_unit,
    check_rows,
    csv_columns,
    csv_header,
    default_columns,
)
from strapdown.io.timing import (
    BRIDGE_MAX_S,
    JITTER_TOLERANCE,
    DuplicatePolicy,
    HeldPolicy,
    Timing,
    TimingMode,
)
from strapdown.navigation import (
    TRAILING_POLICIES,
    NavSolution,
    NavStream,
    TrailingPolicy,
)
from strapdown.rotation.dcm import dcm_from_quat, quat_from_dcm
from strapdown.rotation.euler import dcm_from_euler_zyx, euler_zyx_from_dcm
from strapdown.truth.earth import GRAVITY_MODELS, GravityModel

__all__ = ["ACC_UNITS", "HEIGHT_RANGE_M", "MAX_ANGLE_DEG", "MAX_LONGITUDE_DEG",
           "MAX_SPECIFIC_FORCE", "NAV_COLUMNS", "TRAILING_POLICIES", "AccUnit",
           "DuplicateRowWarning", "NavLog", "TrailingPolicy", "increments_from_rates",
           "navigate_log", "read_nav_log"]

#: Accelerometer units: specific force (m/s², g) for rate logs, velocity increments (m/s).
AccUnit = Literal["m/s2", "g", "m/s"]
ACC_UNITS: tuple[AccUnit, ...] = get_args(AccUnit)
_ACC_ALLOWED: dict[InputKind, tuple[AccUnit, ...]] = {"rate": ("m/s2", "g"),
                                                      "increment": ("m/s",)}
#: Output columns: row 0 the initial state, then one row per update; the Euler angles
#: (z-y-x of ``q_n_b`` in NED, deg) follow the quaternion.
NAV_COLUMNS = ("t", "lat_deg", "lon_deg", "height_m", "vn", "ve", "vd", "qw", "qx", "qy", "qz",
               "yaw_deg", "pitch_deg", "roll_deg")
G0 = 9.80665
CHUNK = 1 << 15
#: Largest specific force accepted (m/s², about 10⁶ g: beyond any accelerometer's range,
#: shock-hardened ones included); more is a unit or a file error.
MAX_SPECIFIC_FORCE = 1e7
#: Initial heights accepted (m above the WGS-84 ellipsoid; see the module docstring).
HEIGHT_RANGE_M = (-2.0e4, 1.0e6)
#: Largest initial longitude magnitude (deg): −180…180° and 0…360° both accepted.
MAX_LONGITUDE_DEG = 360.0
#: Largest initial Euler angle magnitude (deg).
MAX_ANGLE_DEG = 360.0


class DuplicateRowWarning(UserWarning):
    """An increment log whose first two rows hold identical values (a duplicated first row)."""


@dataclass(frozen=True)
class NavLog:
    """A validated nav log in SI units on a uniform time base.

    ``t`` (n,) stamps (s: rate sample times, or increment interval ends); ``gyro``,
    ``accel`` (n, 3) rates (rad/s, m/s²) or increments (rad, m/s); ``h`` the sample period;
    ``units`` and ``acc_units`` what the file was in.
    """

    t: NDArray[np.float64]
    gyro: NDArray[np.float64]
    accel: NDArray[np.float64]
    kind: InputKind
    h: float
    units: str | None
    acc_units: str
    timing: Timing | None = None
    bridged: int = 0  # samples interpolated over gaps


def _csv_accel(path: Path, columns: Sequence[str] | None) -> tuple[NDArray[np.float64],
                                                                     str | None]:
    names, _ = csv_header(path)
    if columns is None:
        cols, _ = default_columns(path, [("gyro", GYRO_COLUMNS), ("accelerometer", ACC_COLUMNS)])
        acc = cols[4:7]
    else:
        acc = list(columns[4:7])
        missing = [c for c in acc if c not in names]
        if missing:
            raise InputError(f"{path}: no accelerometer columns {missing} in the header {names}")
    raw, units, _ = csv_columns(path, acc)
    found = {units[c] for c in acc if c in units}
    if len(found) > 1:
        raise InputError(f"{path}: the header gives the accelerometer axes different units "
                         f"{sorted(found)}")
    return raw, (found.pop() if found else None)


def _accel_source(path: Path, columns: Sequence[str] | None
                  ) -> tuple[NDArray[np.float64], str | None]:
    """The accelerometer values of any supported file and the unit it states (or None)."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return _csv_accel(path, columns)
    if suffix == ".npz":
        z = read_npz(path, ["accel"])
        if "accel" not in z.arrays:
            raise InputError(f"{path}: no accelerometer array 'accel' (found {z.found()})")
        return z.arrays["accel"].astype(float), None
    if suffix in (".h5", ".hdf5"):
        c = read_hdf5(path, ["accel", "imu_acc"])
        for key, unit in (("accel", None), ("imu_acc", "m/s2")):
            if key in c.arrays:
                return c.arrays[key], unit
        raise InputError(f"{path}: no accelerometer dataset 'accel' (or BROAD's 'imu_acc'); "
                         f"found {c.found()}")
    if suffix == ".mat":
        m = read_mat(path, ["imu_acc", *PSINS_VARIABLES])
        if "imu_acc" in m.arrays:  # BROAD: m/s²
            return m.arrays["imu_acc"], "m/s2"
        for key in PSINS_VARIABLES:  # PSINS [wm vm t]: vm in m/s
            if key in m.arrays:
                return m.arrays[key][:, 3:6], "m/s"
        raise InputError(f"{path}: no accelerometer ('imu_acc' or PSINS [wm vm t]); found "
                         f"{m.found()}")
    raise InputError(f"{path}: nav logs are .csv, .npz, .h5/.hdf5 or .mat, not {suffix!r}")


def _acc_unit(path: Path, kind: InputKind, declared: str | None, stated: str | None) -> str:
    allowed = _ACC_ALLOWED[kind]
    if stated is not None:
        stated = canonical_unit(stated)
        if stated not in allowed:
            raise InputError(f"{path}: the accelerometer is in {stated!r}; a {kind} log needs "
                             f"one of {allowed}")
        if declared is not None and declared != stated:
            raise InputError(f"{path}: declared accelerometer units {declared!r} contradict "
                             f"the file's {stated!r}")
        return stated
    if declared is None:
        raise InputError(f"{path}: no accelerometer units declared; pass --acc-units or write "
                         f"them in the header (e.g. ax[{'m/s^2' if kind == 'rate' else 'm/s'}])")
    if declared not in allowed:
        raise InputError(f"{path}: accelerometer units {declared!r} do not fit a {kind} log; "
                         f"use one of {allowed}")
    return declared


def _check_acc_magnitude(path: Path, f: NDArray[np.float64], unit: str,
                         action: UnitAction) -> None:
    """A median specific-force norm (in the declared unit) that suggests the other unit."""
    med = float(np.median(np.linalg.norm(f, axis=1)))
    msg = None
    if unit != "g" and 0.3 < med < 3.0:
        msg = (f"{path}: median accelerometer norm {med:.3g} m/s² is implausible (gravity "
               f"alone gives 9.8); the log is more likely in g (declared {unit})")
    elif unit == "g" and 3.0 < med < 30.0:
        msg = (f"{path}: median accelerometer norm {med:.3g} g is implausible; the log is "
               "more likely in m/s² (declared g)")
    if msg is None:
        return
    if action == "error":
        raise InputError(f"{msg}; nothing computed. If the declared units are right, pass "
                         "--accept-unit-warning")
    warnings.warn(msg, UnitWarning, stacklevel=3)


def _check_acc_range(path: Path, acc: NDArray[np.float64], unit: str, h: float) -> None:
    """Refuse a sample whose specific force (increments: over their interval ``h``) exceeds
    :data:`MAX_SPECIFIC_FORCE`, naming its data row (no overflow on the way)."""
    scale = {"g": G0, "m/s2": 1.0, "m/s": 1.0 / h}[unit]
    a = np.abs(acc)
    norm = np.hypot(np.hypot(a[:, 0], a[:, 1]), a[:, 2])  # finite up to 1.7e308
    with np.errstate(over="ignore"):
        bad = ~(norm * scale <= MAX_SPECIFIC_FORCE)
    if np.any(bad):
        i = int(np.argmax(bad))
        what = "specific force" if unit != "m/s" else "velocity increment"
        over = f" over its {h:.3g} s interval" if unit == "m/s" else ""
        raise InputError(f"{path}: data row {i + 1}: accelerometer {what} of {norm[i]:.4g} "
                         f"{unit}{over} exceeds {MAX_SPECIFIC_FORCE:.0e} m/s² (about 10⁶ g); "
                         "check the accelerometer units and the file")


def _uniform_period(path: Path, t: NDArray[np.float64], nominal: float | None) -> float:
    """The sample period of stamps taken as the sample times (``--timing stamps``); stamps
    straying over 0.1 period from the uniform grid are an error (the navigation needs a fixed
    interval)."""
    k = np.arange(t.size)
    td = nominal if nominal is not None else float((t[-1] - t[0]) / (t.size - 1))
    resid = (t - t[0]) - k * td
    resid -= resid.mean()
    worst = int(np.argmax(np.abs(resid)))
    if abs(resid[worst]) > STAMP_TOLERANCE * td:
        raise InputError(f"{path}: time stamps not uniform: data row {worst + 1} lies "
                         f"{abs(resid[worst]) / td:.3g} periods off the grid of period "
                         f"{td:.9g} s; navigation needs uniformly sampled logs")
    return td


def read_nav_log(path: str | os.PathLike[str], *, kind: InputKind = "rate",
                 units: GyroUnit | None = None, acc_units: AccUnit | None = None,
                 columns: Sequence[str] | None = None, sample_rate_hz: float | None = None,
                 unit_check: UnitAction = "error", on_gap: NavGapPolicy = "error",
                 timing: TimingMode = "auto", jitter_tolerance: float = JITTER_TOLERANCE,
                 held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error") -> NavLog:
    """Read and validate a nav log (see the module docstring).

    Parameters
    ----------
    kind : {"rate", "increment"}
    units : gyro units (as :func:`strapdown.io.read_imu`), None: the file's
    acc_units : {"m/s2", "g"} for rates, {"m/s"} for increments; None: the file's
    columns : seven CSV names (time, gyro x y z, accelerometer x y z), optional
    sample_rate_hz : float, optional
        The sensor's rate (needed where the file carries none).
    unit_check : {"warn", "error"}
        What magnitudes that suggest the other unit do (gyro and accelerometer).
    on_gap : {"error", "report"}
        A gap (samples missing on the sensor's fitted clock): an error, or bridged by
        linear interpolation of both sensors when no longer than
        :data:`strapdown.io.timing.BRIDGE_MAX_S` (reported; the navigation error grows with
        what the gap hides).
    timing, jitter_tolerance, held, duplicates
        The time base, as for :func:`strapdown.io.read_imu` (``timing="resample"``
        interpolates both sensors onto a uniform grid, a cubic spline).
    """
    path = Path(path)
    if on_gap not in NAV_GAP_POLICIES:
        raise InputError(f"on_gap must be one of {', '.join(NAV_GAP_POLICIES)}, got "
                         f"{on_gap!r}")
    if columns is not None and len(columns) != 7:
        raise InputError(f"columns must name time, three gyro and three accelerometer axes, "
                         f"got {len(columns)}: {list(columns)}")
    if acc_units is not None and acc_units not in ACC_UNITS:
        raise InputError(f"accelerometer units must be one of {ACC_UNITS}, got {acc_units!r}")
    if path.suffix.lower() == ".npy":
        raise InputError(f"{path}: .npy logs hold a gyro only; a nav log is .csv, .npz, "
                         ".h5/.hdf5 or .mat")
    with np.errstate(over="ignore", invalid="ignore"):  # values beyond float64 (a float128
        log = read_imu(path, kind=kind, units=units,  # file) read as infinity, refused
                       columns=None if columns is None else list(columns[:4]),  # by row
                       sample_rate_hz=sample_rate_hz, on_gap="report", unit_check=unit_check,
                       timing_mode=timing, jitter_tolerance=jitter_tolerance, held="keep",
                       duplicates=duplicates)
        acc, stated = _accel_source(path, columns)
    keep = log.timing.cleaning.keep if log.timing is not None else None
    if acc.ndim != 2 or acc.shape[1:] != (3,) or (
            acc.shape[0] != (log.timing.base.t.size if log.timing is not None
                             else log.data.shape[0])):
        raise InputError(f"{path}: {log.data.shape[0]} gyro samples but accelerometer values of "
                         f"shape {acc.shape}")
    if keep is not None and keep.size < acc.shape[0]:
        acc = acc[keep]
    check_rows(path, log.t, [("accelerometer", [acc])])
    unit = _acc_unit(path, kind, acc_units, stated)
    t, gyro, acc, h, bridged = _nav_grid(path, log, acc, on_gap)
    _check_acc_range(path, acc, unit, h)
    _check_acc_magnitude(path, acc if kind == "rate" else acc / h, unit, unit_check)
    if kind == "increment":
        _check_first_rows(path, t, gyro, acc)
    si = acc * G0 if unit == "g" else acc
    return NavLog(t, gyro, np.ascontiguousarray(si), kind, h, log.units, unit, log.timing,
                  bridged)


def _check_first_rows(path: Path, t: NDArray[np.float64], gyro: NDArray[np.float64],
                      acc: NDArray[np.float64]) -> None:
    """Warn when the first two increment rows are identical and the third is not (a
    duplicated first row; see the module docstring)."""
    if t.size < 2:
        return

    def same(i: int, j: int) -> bool:
        return bool(np.array_equal(gyro[i], gyro[j]) and np.array_equal(acc[i], acc[j]))

    if same(0, 1) and (t.size < 3 or not same(1, 2)):
        warnings.warn(f"{path}: the first two increment rows (t = {t[0]:.9g} s and "
                      f"{t[1]:.9g} s) hold identical values: a duplicated first row (a common "
                      "simulator export) adds an interval of motion that is not there (145 m "
                      "in 10 min on a manoeuvre); drop the first row if it is a copy",
                      DuplicateRowWarning, stacklevel=3)


#: What ``nav`` does at a gap: fail, or bridge it (up to
#: :data:`strapdown.io.timing.BRIDGE_MAX_S`).
NavGapPolicy = Literal["error", "report"]
NAV_GAP_POLICIES: tuple[NavGapPolicy, ...] = get_args(NavGapPolicy)
def _nav_grid(path: Path, log, acc: NDArray[np.float64], on_gap: str):
    """``(t, gyro, acc, h, bridged)`` on a uniform grid: the fitted sensor clock (gaps
    bridged by linear interpolation), a uniform-stamp check (``timing="stamps"``), or both
    sensors resampled onto a uniform grid (``resample``, irregular sampling)."""
    timing = log.timing
    clock = None if timing is None else timing.clock
    if clock is None or timing.mode == "stamps":
        return log.t, log.data, acc, _uniform_period(path, log.t, log.nominal_period), 0
    p = clock.period
    if timing.on_clock:
        gap = clock.longest_gap()
        if gap is not None and (on_gap == "error" or gap[1] * p > BRIDGE_MAX_S):
            raise InputError(
                f"{path}: a gap of {gap[1]} missing samples ({gap[1] * p:.3g} s) "
                f"before data row {int(timing.rows[gap[0]])}; " + (
                    "--on-gap report bridges gaps up to "
                    f"{BRIDGE_MAX_S:g} s by interpolation" if on_gap == "error" else
                    f"longer than the {BRIDGE_MAX_S:g} s --on-gap report bridges; split the "
                    "log at the gap"))
        if clock.kind == "uniform" and gap is None and log.nominal_period is None:
            return log.t, log.data, acc, p, 0
        full, (gyro, acc_b) = clock.bridge(log.data, acc)
        assert gyro is not None and acc_b is not None
        t = float(log.t[0]) + (clock.uniform_times(full)
                               - clock.uniform_times(clock.ticks[:1])[0])
        return t, gyro, acc_b, p, clock.missing
    from strapdown.algorithms.rate import resample_uniform

    grid, step = clock.resample_grid(log.t)
    return (grid, resample_uniform(log.t, log.data, grid), resample_uniform(log.t, acc, grid),
            step, 0)


def increments_from_rates(w: ArrayLike, h: float) -> NDArray[np.float64]:
    """Increments over the ``n − 1`` intervals between ``n`` uniform samples ``w`` (n, 3).

    Interior intervals integrate the cubic through the four neighbouring samples,
    ``h/24 (−w_{k−2} + 13 w_{k−1} + 13 w_k − w_{k+1})``; the first and last the quadratic
    through three, ``h/12 (5 w_0 + 8 w_1 − w_2)`` and its mirror; two samples, the
    trapezoid. Exact for cubics (quadratics at the ends).
    """
    w = np.asarray(w, dtype=np.float64)
    n = w.shape[0]
    if n < 2:
        raise InputError(f"rates give increments between samples: need at least 2, got {n}")
    if n == 2:
        return 0.5 * h * (w[:1] + w[1:])
    out = np.empty((n - 1, 3))
    out[0] = h / 12 * (5 * w[0] + 8 * w[1] - w[2])
    out[-1] = h / 12 * (-w[-3] + 8 * w[-2] + 5 * w[-1])
    if n > 3:
        out[1:-1] = h / 24 * (-w[:-3] + 13 * w[1:-2] + 13 * w[2:-1] - w[3:])
    return out


def _initial_state(lat_deg: float, lon_deg: float, height: float,
                   velocity: ArrayLike | None, attitude_deg: ArrayLike | None
                   ) -> tuple[float, float, float, NDArray[np.float64], NDArray[np.float64]]:
    """(lat, lon rad, height, v NED, q_n_b) from the command line's initial state."""
    for name, c in (("latitude", lat_deg), ("longitude", lon_deg), ("height", height)):
        if not math.isfinite(c):
            raise InputError(f"initial {name} must be finite, got {c}")
    if not abs(lat_deg) < 90.0:
        raise InputError(f"initial latitude must lie within ±90°, got {lat_deg}°")
    if not abs(lon_deg) <= MAX_LONGITUDE_DEG:
        raise InputError(f"initial longitude must lie within ±{MAX_LONGITUDE_DEG:g}° "
                         f"(−180…180° or 0…360°), got {lon_deg:g}°")
    lo, hi = HEIGHT_RANGE_M
    if not lo <= height <= hi:
        raise InputError(f"initial height must lie within {lo:g}…{hi:g} m above the WGS-84 "
                         f"ellipsoid (the normal gravity model's range), got {height:g} m")
    v = np.zeros(3) if velocity is None else np.asarray(velocity, dtype=np.float64)
    ypr = np.zeros(3) if attitude_deg is None else np.asarray(attitude_deg, dtype=np.float64)
    for name, x in (("velocity (VN VE VD)", v), ("attitude (YAW PITCH ROLL)", ypr)):
        if x.shape != (3,):
            raise InputError(f"initial {name} needs three values, got {x.size}")
        if not np.all(np.isfinite(x)):
            raise InputError(f"initial {name} must be finite, got {x.tolist()}")
    if not np.all(np.abs(ypr) <= MAX_ANGLE_DEG):
        raise InputError(f"initial attitude (YAW PITCH ROLL) angles must lie within "
                         f"±{MAX_ANGLE_DEG:g}°, got {ypr.tolist()}")
    q = quat_from_dcm(dcm_from_euler_zyx(*np.radians(ypr)))
    return math.radians(lat_deg), math.radians(lon_deg), float(height), v, q


def _rows(t, lat, lon, height, v, q) -> NDArray[np.float64]:
    """Output rows (:data:`NAV_COLUMNS`) of states given as arrays (one per row)."""
    ypr = (np.column_stack(euler_zyx_from_dcm(dcm_from_quat(q))) if len(t)
           else np.zeros((0, 3)))
    return np.column_stack([t, np.degrees(lat), np.degrees(lon), height, v, q,
                            np.degrees(ypr)])


def _check_out(imu: Path, out: Path) -> None:
    if out.resolve() == imu.resolve():
        raise InputError("--out must not be the input file")
    if out.suffix.lower() not in (".csv", ".npz"):
        raise InputError(f"{out}: output must be .csv or .npz")


def navigate_log(imu: str | os.PathLike[str], out: str | os.PathLike[str], *, lat_deg: float,
                 lon_deg: float, height: float, velocity: ArrayLike | None = None,
                 attitude_deg: ArrayLike | None = None, kind: InputKind = "rate",
                 units: GyroUnit | None = None, acc_units: AccUnit | None = None,
                 columns: Sequence[str] | None = None, sample_rate_hz: float | None = None,
                 subsamples: int = 3, structure: NavStructure = "conventional",
                 sculling: bool = True,
                 accept_unit_warning: bool = False, progress: bool = False,
                 on_gap: NavGapPolicy = "error", timing: TimingMode = "auto",
                 jitter_tolerance: float = JITTER_TOLERANCE, held: HeldPolicy = "auto",
                 duplicates: DuplicatePolicy = "error",
                 trailing: TrailingPolicy = "drop", gravity: GravityModel = "wgs84",
                 algorithm: str | None = None) -> dict[str, Any]:
    """Navigate a log and write the initial state and one row per update (see the module
    docstring).

    Parameters
    ----------
    lat_deg, lon_deg, height : float
        Initial position (°, °, m above the WGS-84 ellipsoid).
    velocity : (VN, VE, VD) m/s, optional (default at rest)
    attitude_deg : (yaw, pitch, roll) °, z-y-x in NED, optional (default level, north)
    subsamples, structure, sculling
        As :func:`strapdown.navigation.earth.navigate`.
    accept_unit_warning : bool
        Magnitudes that suggest other units than declared warn instead of failing.
    progress : bool
        A progress bar on stderr.
    on_gap, timing, jitter_tolerance, held, duplicates
        The gap policy and the time base (:func:`read_nav_log`).
    trailing : {"drop", "error"}
        Fewer than N samples left after the last whole conventional update: navigated
        without (counted in the summary; default), or an error naming them.
    gravity : {"wgs84", "linear"}
        Normal gravity's height correction (:func:`strapdown.truth.earth.gravity`).
    algorithm : str, optional
        Rate logs only: a registered rate-input family with a velocity counterpart
        (:func:`strapdown.algorithms.velocity.rate_velocity_algorithms`), whose window turns
        the rate and specific-force samples into the update's increments
        (:func:`strapdown.navigation.earth.navigate_rates`); ``subsamples`` and
        ``structure`` are then not used. None (default): the rates are integrated to
        increments for the N-subsample update.

    Returns
    -------
    dict
        A summary (also written beside ``out`` as ``OUT.meta.json``): samples,
        outputs (updates; the file holds one more row, the initial state), sample period,
        units, the time base (the fitted clock and its residuals), bridged samples,
        trailing samples dropped, warnings.
    """
    imu_path, out_path = Path(imu), Path(out)
    _check_out(imu_path, out_path)
    if trailing not in TRAILING_POLICIES:
        raise InputError(f"trailing must be one of {', '.join(TRAILING_POLICIES)}, got "
                         f"{trailing!r}")
    if gravity not in GRAVITY_MODELS:
        raise InputError(f"gravity must be one of {', '.join(GRAVITY_MODELS)}, got "
                         f"{gravity!r}")
    if algorithm is not None and kind != "rate":
        raise InputError("--algorithm names a rate-input velocity algorithm: it navigates rate "
                         "logs (--rates), not increments")
    lat, lon, hgt, v0, q0 = _initial_state(lat_deg, lon_deg, height, velocity, attitude_deg)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = read_nav_log(imu_path, kind=kind, units=units, acc_units=acc_units,
                           columns=columns, sample_rate_hz=sample_rate_hz,
                           unit_check="warn" if accept_unit_warning else "error",
                           on_gap=on_gap, timing=timing, jitter_tolerance=jitter_tolerance,
                           held=held, duplicates=duplicates)
    stream: NavStream | _RateRun
    if algorithm is not None:
        stream = _RateRun(log, algorithm, lat=lat, lon=lon, height=hgt, v0=v0, q0=q0,
                          sculling=sculling, gravity=gravity)
        g, a, t0, left = log.gyro, log.accel, stream.t0, stream.left
        if left and trailing == "error":
            raise InputError(f"the log's {g.shape[0]} samples leave {left} after the last "
                             f"whole update of {algorithm} (--trailing error); nothing written")
    else:
        if kind == "rate":
            g, a = (increments_from_rates(log.gyro, log.h),
                    increments_from_rates(log.accel, log.h))
            t0 = float(log.t[0])
        else:
            g, a, t0 = log.gyro, log.accel, float(log.t[0]) - log.h
        stream = NavStream(subsamples, h=log.h, lat=lat, lon=lon, height=hgt, v0=v0, q0=q0,
                           structure=structure, t0=t0, sculling=sculling, gravity=gravity)
        left = _trailing(g.shape[0], stream, trailing)
    first = _rows(np.array([t0]), np.array([lat]), np.array([lon]), np.array([hgt]),
                  v0[None, :], (q0 / np.linalg.norm(q0))[None, :])  # as navigate's row 0
    from strapdown import __version__
    from strapdown.apps._logs import output_with_sidecar

    with output_with_sidecar(out_path) as paired:
        n_out = _stream_to(paired.path, stream, g, a, progress, first)
        paired.meta = {
            "input": str(imu_path), "samples": int(log.t.size), "outputs": n_out,
            "rows": n_out + 1, "sample_period_s": log.h,
            "update_period_s": stream.update_period, "t0_s": t0,
            "units": log.units, "acc_units": log.acc_units, "columns": list(NAV_COLUMNS),
            "frame": "NED; q_n_b Hamilton, scalar first; yaw, pitch, roll z-y-x of q_n_b "
                     "(deg); row 0: the initial state at t0 (increments: first stamp - h, "
                     "rates: first stamp); t: end of each update interval",
            "trailing": trailing, "trailing_samples_dropped": left, "gravity": gravity,
            "on_gap": on_gap, "bridged_samples": log.bridged,
            "timing": None if log.timing is None else log.timing.to_dict(),
            "time_base": None if log.timing is None else log.timing.describe(),
            "warnings": [str(w.message) for w in caught], "version": __version__,
            **({} if algorithm is None else {"algorithm": algorithm})}
    return paired.meta


class _RateRun:
    """A rate log navigated whole by a rate-input family's velocity counterpart
    (:func:`~strapdown.navigation.earth.navigate_rates`), fed as :class:`NavStream` is:
    its updates come with the first chunk."""

    def __init__(self, log: NavLog, algorithm: str, **kw: Any):
        from strapdown.algorithms.velocity import _rate_spec
        from strapdown.navigation import navigate_rates

        try:
            spec = _rate_spec(None, algorithm)
        except ValueError as e:
            raise InputError(str(e)) from None
        vel = spec.family.velocity(spec)
        assert vel is not None  # _rate_spec: a velocity counterpart
        k = log.gyro.shape[0]
        if k < vel.min_samples:
            raise InputError(f"{algorithm} needs at least {vel.min_samples} samples, the log "
                             f"has {k}; nothing written")
        self.h, self.n, self._structure = log.h, vel.n, vel.structure
        self.update_period = vel.update_period(log.h)
        self.left = (k - vel.min_samples) % vel.n
        sol = navigate_rates(log.gyro, log.accel, td=log.h, algorithm=algorithm,
                             t0=float(log.t[0]), **kw)
        self._sol: NavSolution | None = sol
        self.t0 = float(sol.t[0])

    def feed(self, gyro: NDArray[np.float64], accel: NDArray[np.float64]) -> NavSolution:
        """Every update on the first call, none after."""
        sol, self._sol = self._sol, None
        if sol is None:
            z = np.empty((0, 3))
            return NavSolution(np.empty(0), z[:, 0], z[:, 0], z[:, 0], z, np.empty((0, 4)),
                               self._structure, self.n, self.update_period)
        return NavSolution(sol.t[1:], sol.lat[1:], sol.lon[1:], sol.height[1:], sol.v[1:],
                           sol.q[1:], sol.structure, sol.n, sol.update_period)


def _trailing(k: int, stream: NavStream, policy: TrailingPolicy) -> int:
    """The samples left after the last whole update of ``k`` increments (the conventional
    structure's partial update); an error when ``policy == "error"``."""
    per = round(stream.update_period / stream.h)  # samples per update: N, or 1 (every sample)
    left = k % per
    if left and k >= per and policy == "error":  # shorter than one update: no update at all
        raise InputError(f"the log's {k} increments leave {left} sample(s) after the last "
                         f"whole update of N = {per} ({left * stream.h:.6g} s at its end) "
                         "(--trailing error); the default --trailing drop navigates without "
                         "them (or use --structure single-chain, which updates every "
                         "sample); nothing written")
    return left


def _stream_to(out: Path, stream: NavStream | _RateRun, g: NDArray[np.float64],
               a: NDArray[np.float64], progress: bool, first: NDArray[np.float64]) -> int:
    """Write the initial-state row ``first``, then feed the increments in chunks, writing
    each chunk's rows as they come; returns the number of updates."""
    csv_out = out.suffix.lower() == ".csv"
    parts, n_out = [], 0
    tmp = out  # a temporary path beside the target (output_with_sidecar renames it)
    with open(tmp, "w", encoding="utf-8") as f, \
            tqdm(total=g.shape[0], disable=not progress, unit="sample", unit_scale=True,
                 file=sys.stderr) as bar:
        if csv_out:
            f.write(",".join(NAV_COLUMNS) + "\n")
            write_csv_rows(f, first)
        else:
            parts.append(first)
        for s in range(0, g.shape[0], CHUNK):
            sol = stream.feed(g[s:s + CHUNK], a[s:s + CHUNK])
            bar.update(min(CHUNK, g.shape[0] - s))
            rows = _rows(sol.t, sol.lat, sol.lon, sol.height, sol.v, sol.q)
            if not np.all(np.isfinite(rows)):
                i = int(np.argmax(~np.all(np.isfinite(rows), axis=1)))
                raise InputError(f"the navigation diverged (NaN or infinity) at t = "
                                 f"{rows[i, 0]:.6g} s; nothing written")
            n_out += rows.shape[0]
            if csv_out:
                write_csv_rows(f, rows)
            else:
                parts.append(rows)
        if n_out == 0:
            raise InputError(f"{stream.n} subsamples per update need at least {stream.n} "
                             f"intervals, the log has {g.shape[0]}; nothing written")
        if not csv_out:
            f.close()
            table = np.concatenate(parts)
            # Any: np.savez's column keywords share its signature with allow_pickle: bool
            cols: dict[str, Any] = {k: table[:, i] for i, k in enumerate(NAV_COLUMNS)}
            with open(tmp, "wb") as fb:
                np.savez(fb, **cols)
    return n_out
