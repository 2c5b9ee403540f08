"""Reading IMU logs and writing attitude, with validation that names the row.

Formats (by suffix): CSV with a header row, NumPy ``.npy`` (``(n, 4)``
``[t, gx, gy, gz]``) and ``.npz`` (arrays ``t`` and ``gyro``), HDF5 ``.h5``/``.hdf5``
(datasets ``t`` and ``gyro``, or BROAD's ``imu_gyr`` with a ``sampling_rate``; needs the
``hdf5`` extra), MATLAB ``.mat`` (PSINS ``[wm vm t]`` — increments in columns 1–3, time
last — or BROAD ``imu_gyr`` with ``sampling_rate``).

CSV columns are mapped by name: given (``--columns time,wx,wy,wz``), or found in the
header — the time column among :data:`TIME_COLUMNS` (``t``, ``time``, ``timestamp``,
``time_s`` …, case-insensitive), the axes among :data:`GYRO_COLUMNS` (``gx,gy,gz``,
``wx,wy,wz`` …). A time column in other units than seconds says so (``t[ms]``, ``time_us``).

Every log declares what it holds: rates or increments, and the unit (``rad/s``/``deg/s``
for rates, ``rad``/``deg`` for increments), by argument or by the file: a CSV header's
convention ``gx[deg/s]`` (a unit in brackets after a column name; ``°/s`` and other
spellings in :data:`UNIT_SPELLINGS` accepted) or a format whose unit is known (BROAD
stores rad/s). A declared unit that contradicts the file's, or a kind that contradicts a
known format's (BROAD holds rates, PSINS increments), is an error. A plausibility check
warns — or, ``unit_check="error"`` (the command line's default), fails — when magnitudes
suggest the other unit (a rate above :data:`RATE_PLAUSIBLE_MAX` rad/s declared as rad/s is
more likely deg/s). Validation raises on NaN or infinity, duplicated or non-monotonic time
stamps (with the row number, counting the first data row as 1), reports gaps larger than
``gap_tolerance`` sample intervals (or raises, ``on_gap="error"``; :meth:`ImuLog.segments`
splits at them) and reports rows at or above a declared saturation level.
"""

from __future__ import annotations

import csv
import io as _io
import itertools
import math
import os
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.kinds import INPUT_KINDS, InputKind
from strapdown._core.validation import first_bad_step
from strapdown.io.files import atomic_path

__all__ = [
    "ACC_COLUMNS",
    "GAP_POLICIES",
    "GYRO_COLUMNS",
    "INCREMENT_UNITS",
    "MAG_COLUMNS",
    "RATE_PLAUSIBLE_MAX",
    "RATE_UNITS",
    "TIME_COLUMNS",
    "TIME_UNITS",
    "UNIT_ACTIONS",
    "UNIT_SPELLINGS",
    "GapPolicy",
    "GyroUnit",
    "ImuLog",
    "IncrementUnit",
    "RateUnit",
    "UnitAction",
    "UnitWarning",
    "canonical_unit",
    "check_rows",
    "csv_columns",
    "csv_header",
    "default_columns",
    "read_imu",
    "time_scale",
    "warn_implausible_rate",
    "write_attitude",
]

#: Largest body rate (rad/s) considered plausible when a log says rad/s (~2000 °/s × 1.75;
#: spinning shells reach 20 r/s ≈ 126 rad/s, so only beyond 200 rad/s do we suspect deg/s).
RATE_PLAUSIBLE_MAX = 200.0
_DEG = np.pi / 180.0

#: Units of a rate log.
RateUnit = Literal["rad/s", "deg/s"]
#: Units of an increment log.
IncrementUnit = Literal["rad", "deg"]
#: Any gyro-log unit (a rate log takes a :data:`RateUnit`, an increment log an
#: :data:`IncrementUnit`).
GyroUnit = Literal[RateUnit, IncrementUnit]
#: What :func:`read_imu` does at a gap: list it in :attr:`ImuLog.gaps`, or raise.
GapPolicy = Literal["report", "error"]
RATE_UNITS: tuple[RateUnit, ...] = get_args(RateUnit)
INCREMENT_UNITS: tuple[IncrementUnit, ...] = get_args(IncrementUnit)
GAP_POLICIES: tuple[GapPolicy, ...] = get_args(GapPolicy)
#: What magnitudes that suggest the other unit do: a :class:`UnitWarning`, or an error.
UnitAction = Literal["warn", "error"]
UNIT_ACTIONS: tuple[UnitAction, ...] = get_args(UnitAction)


class UnitWarning(UserWarning):
    """Magnitudes in a log suggest a unit other than the one declared."""


@dataclass(frozen=True)
class ImuLog:
    """A validated gyro log in SI units.

    Attributes
    ----------
    t : ndarray (n,)
        Sample times (s): rate sample times, or increment interval end times.
    data : ndarray (n, 3)
        Rates (rad/s) or increments (rad).
    kind : {"rate", "increment"}
    h : float
        Median sample interval (s).
    gaps : list of int
        Rows (1-based) whose interval exceeds the gap tolerance.
    saturated : list of int
        Rows (1-based) with a component at or above the declared saturation.
    units : str or None
        The unit the file was in (declared or the file's own), before conversion to SI.
    nominal_period : float or None
        The sensor's period (s) when a sample rate was given for a stamped log
        (``1 / sample_rate_hz``); None: the period comes from the stamps.
    """

    t: NDArray[np.float64]
    data: NDArray[np.float64]
    kind: InputKind
    h: float
    gaps: list[int] = field(default_factory=list)
    saturated: list[int] = field(default_factory=list)
    units: str | None = None
    nominal_period: float | None = None

    def segments(self) -> list[slice]:
        """Index ranges between gaps: each a gap-free run of samples.

        A gap reported at data row ``r`` (1-based) starts a new segment at index ``r − 1``.
        """
        edges = [0, *(r - 1 for r in self.gaps), self.t.size]
        return [slice(a, b) for a, b in itertools.pairwise(edges)]


_UNIT = re.compile(r"^\s*([^\[\]]*?)\s*\[\s*([^\[\]]+?)\s*\]\s*$")
_TIME_NAME = re.compile(r"^(?:t|time|timestamp|stamp)(?:_(s|sec|ms|us|µs|ns))?$|^(sec|seconds)$",
                        re.IGNORECASE)

#: Time-column names recognised (case-insensitive) when no columns are given: ``t``,
#: ``time``, ``timestamp``, ``stamp``, alone or with a unit suffix (``time_s``, ``t_ms``),
#: ``sec``, ``seconds``; a unit in brackets (``t[s]``, ``time[ms]``) works as well.
TIME_COLUMNS = ("t", "time", "timestamp", "stamp", "time_s", "t_ms", "sec", "seconds")
#: Time units (bracketed or as a name suffix) and their factor to seconds; none: seconds.
TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9}
#: Gyro axis columns recognised (case-insensitive, first match) when no columns are given.
GYRO_COLUMNS = (("gx", "gy", "gz"), ("wx", "wy", "wz"), ("gyro_x", "gyro_y", "gyro_z"),
                ("gyr_x", "gyr_y", "gyr_z"), ("omega_x", "omega_y", "omega_z"))
#: Accelerometer axis columns recognised when no columns are given.
ACC_COLUMNS = (("ax", "ay", "az"), ("acc_x", "acc_y", "acc_z"), ("accel_x", "accel_y", "accel_z"))
#: Magnetometer axis columns recognised when no columns are given.
MAG_COLUMNS = (("mx", "my", "mz"), ("mag_x", "mag_y", "mag_z"))
#: Other spellings of units accepted in a header, and the unit they mean.
UNIT_SPELLINGS = {"°/s": "deg/s", "dps": "deg/s", "deg/sec": "deg/s", "rad/sec": "rad/s",
                  "°": "deg", "m/s^2": "m/s2", "m/s²": "m/s2", "m s^-2": "m/s2"}


def canonical_unit(unit: str) -> str:
    """A header's unit in the spelling the readers use (``°/s`` → ``deg/s``, ``m/s²`` →
    ``m/s2``); units without another spelling are returned unchanged."""
    u = unit.strip()
    return UNIT_SPELLINGS.get(u, UNIT_SPELLINGS.get(u.lower(), u))


def _split_header(cells):
    """Column names and the units the header declares (``gx[deg/s]`` → ``gx``, ``deg/s``)."""
    names, units = [], {}
    for c in cells:
        m = _UNIT.match(c)
        if m:
            names.append(m.group(1))
            units[m.group(1)] = canonical_unit(m.group(2))
        else:
            names.append(c.strip())
    return names, units


def csv_header(path: str | os.PathLike[str]) -> tuple[list[str], dict[str, str]]:
    """The column names of a CSV's header row and the units it declares by name."""
    path = Path(path)
    with open(path, newline="", encoding="utf-8") as f:
        try:
            return _split_header(next(csv.reader(f)))
        except StopIteration:
            raise ValueError(f"{path}: empty file") from None


def default_columns(path: str | os.PathLike[str],
                    axes: Sequence[tuple[str, Sequence[tuple[str, str, str]]]],
                    optional: Sequence[tuple[str, str, str]] = ()) -> tuple[list[str], list[str]]:
    """The columns a header names without ``--columns``: ``([time, *axes], optional)``.

    The time column is the one header name among :data:`TIME_COLUMNS` (case-insensitive,
    unit suffixes allowed); each ``(label, candidates)`` of ``axes`` takes the first of its
    candidate triples the header has, ``optional`` likewise (``[]`` when it has none).
    Errors name what is missing or ambiguous and the header.
    """
    names, _ = csv_header(path)
    times = [n for n in names if _TIME_NAME.match(n)]
    if len(times) != 1:
        what = "no time column" if not times else f"several time columns {times}"
        raise ValueError(f"{path}: {what} in the header {names} (recognised: "
                         f"{', '.join(TIME_COLUMNS)}, optionally with a unit, t[ms]); name the "
                         "columns with --columns")
    lower = {n.lower(): n for n in names}

    def triple(candidates):
        for c in candidates:
            if all(a in lower for a in c):
                return [lower[a] for a in c]
        return []

    cols = times[:]
    for label, candidates in axes:
        found = triple(candidates)
        if not found:
            raise ValueError(f"{path}: no {label} columns in the header {names} (recognised: "
                             f"{'; '.join(','.join(c) for c in candidates)}); name the columns "
                             "with --columns")
        cols += found
    return cols, triple(optional)


def time_scale(path: str | os.PathLike[str], name: str, units: dict[str, str]) -> float:
    """Factor to seconds of the time column ``name``: its bracketed unit, else its name's
    suffix (``time_ms``), else seconds. An unknown unit is an error."""
    m = _TIME_NAME.match(name)
    unit = units.get(name) or (m.group(1) if m and m.group(1) else None)
    if unit is None:
        return 1.0
    if unit not in TIME_UNITS:
        raise ValueError(f"{path}: time column {name!r} is in {unit!r}; known time units are "
                         f"{', '.join(TIME_UNITS)}")
    return TIME_UNITS[unit]


def csv_columns(path: str | os.PathLike[str], columns: Sequence[str],
                optional: Sequence[str] = ()) -> tuple[NDArray[np.float64], dict[str, str], bool]:
    """Named columns of a CSV log with a header row.

    Returns ``(values, units, have_optional)``: ``values`` holds ``columns``
    followed by ``optional`` when every optional column is present, ``units``
    the header's bracketed units by column name (``gx[deg/s]``). Errors name
    missing columns, a file without data rows, unreadable numbers and rows
    whose field count differs from the header's.
    """
    path = Path(path)
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        try:
            header, units = _split_header(next(reader))
        except StopIteration:
            raise ValueError(f"{path}: empty file") from None
        missing = [c for c in columns if c not in header]
        if missing:
            raise ValueError(f"{path}: columns {missing} not in the header {header}; map them "
                             "with --columns")
        have_optional = bool(optional) and all(c in header for c in optional)
        wanted = list(columns) + (list(optional) if have_optional else [])
        idx = [header.index(c) for c in wanted]
        text = f.read()
    if not text.strip():
        raise ValueError(f"{path}: no data rows")
    try:
        raw = np.loadtxt(_io.StringIO(text), delimiter=",", ndmin=2, dtype=np.float64)
    except ValueError as exc:
        raise ValueError(f"{path}: unreadable number ({exc})") from exc
    if raw.shape[1] != len(header):
        raise ValueError(f"{path}: rows have {raw.shape[1]} fields, the header {len(header)}")
    return raw[:, idx], units, have_optional


def _load_csv(path: Path, columns):
    """``(t [s], axes, header unit of the axes)``; ``columns`` None: :func:`default_columns`."""
    if columns is None:
        columns, _ = default_columns(path, [("gyro", GYRO_COLUMNS)])
    raw, units, _ = csv_columns(path, columns)
    axis_units = {units[c] for c in columns[1:] if c in units}
    if len(axis_units) > 1:
        raise ValueError(f"{path}: the header gives the axes different units {sorted(axis_units)}")
    scale = time_scale(path, columns[0], units)
    t = raw[:, 0] * scale if scale != 1.0 else raw[:, 0]
    return t, raw[:, 1:4], (axis_units.pop() if axis_units else None)


def check_rows(path: str | os.PathLike[str], t: NDArray[np.float64],
               groups: Iterable[tuple[str | None, Iterable[ArrayLike]]]) -> None:
    """Raise on the first non-finite row of each group and on a bad time step.

    ``groups``: ``(label, arrays)`` pairs checked in order; a row is bad when
    any array of the group is not finite there. Rows count from 1 (the first
    data row); ``label`` None gives "NaN or infinity in data row r".
    """
    for label, arrays in groups:
        bad = np.zeros(t.shape[0], bool)
        for a in arrays:
            a = np.asarray(a)
            bad |= ~np.isfinite(a) if a.ndim == 1 else ~np.all(np.isfinite(a), axis=1)
        if np.any(bad):
            where = "" if label is None else f" the {label} at"
            raise ValueError(f"{path}: NaN or infinity in{where} data row "
                             f"{int(np.argmax(bad)) + 1}")
    fault = first_bad_step(np.diff(t))
    if fault is not None:
        i, what = fault
        raise ValueError(f"{path}: {what} time stamp in data row {i + 2} (t = {t[i + 1]!r} "
                         f"after {t[i]!r})")


def warn_implausible_rate(path: str | os.PathLike[str], rate: NDArray[np.float64], declared: str,
                          suggestion: str = "degrees", *, action: UnitAction = "warn") -> None:
    """Judge rates (rad/s) against the declared unit: a 99th-percentile rate above
    :data:`RATE_PLAUSIBLE_MAX` rad/s declared in radians is more likely degrees, one below
    1e-3 °/s declared in degrees more likely radians.

    ``action="warn"`` issues a :class:`UnitWarning`; ``"error"`` raises ValueError saying
    how to accept the units (``--accept-unit-warning``).
    """
    if action not in UNIT_ACTIONS:
        raise ValueError(f"action must be one of {', '.join(UNIT_ACTIONS)}, got {action!r}")
    if rate.shape[0] == 0:
        return
    big = float(np.percentile(np.linalg.norm(rate, axis=1), 99))
    msg = None
    if not declared.startswith("deg") and big > RATE_PLAUSIBLE_MAX:
        msg = (f"{path}: 99th-percentile rate {big:.0f} rad/s is implausible; the log is "
               f"more likely in {suggestion} (declared {declared})")
    elif declared.startswith("deg") and 0 < big < 1e-3 * _DEG:
        msg = (f"{path}: 99th-percentile rate {big / _DEG:.2e} °/s is implausibly small; the "
               f"log is more likely in radians (declared {declared})")
    if msg is None:
        return
    if action == "error":
        raise ValueError(f"{msg}; nothing computed. If the declared units are right, pass "
                         "--accept-unit-warning")
    warnings.warn(msg, UnitWarning, stacklevel=3)


@dataclass(frozen=True)
class _Source:
    """What a file gave: stamps (s), gyro values, and what it says of itself."""

    t: NDArray[np.float64]
    gyro: NDArray[np.float64]
    units: str | None = None  # unit the file declares (header, known format)
    whose: str = "the header's"  # for "contradict {whose} 'rad/s'{note}"
    note: str = ""
    kind: InputKind | None = None  # what a known format holds
    what: str = ""  # the format, for messages


def _broad_source(path: Path, g, fs, sample_rate_hz) -> _Source:
    """BROAD's ``imu_gyr`` (rad/s) at its ``sampling_rate`` (or the one given)."""
    if fs is not None and sample_rate_hz is not None and not math.isclose(
            fs, sample_rate_hz, rel_tol=1e-9):
        raise ValueError(f"{path}: the file states a sampling rate of {fs:g} Hz, not the "
                         f"{sample_rate_hz:g} Hz given")
    fs = fs if fs is not None else sample_rate_hz
    if not fs:
        raise ValueError(f"{path}: no sampling_rate; pass --sample-rate-hz")
    return _Source(np.arange(g.shape[0]) / fs, g, "rad/s", "the file's",
                   " (BROAD stores imu_gyr in rad/s)", "rate", "BROAD's imu_gyr")


def _load_hdf5(path: Path, sample_rate_hz) -> _Source:
    try:
        import h5py
    except ImportError:
        raise ValueError(f"{path}: reading HDF5 needs h5py: pip install 'strapdown[hdf5]'"
                         ) from None
    with h5py.File(path, "r") as f:
        if "gyro" in f and "t" in f:
            return _Source(np.asarray(f["t"], float), np.asarray(f["gyro"], float))
        if "imu_gyr" in f:
            g = np.asarray(f["imu_gyr"], float)
            fs = f.attrs.get("sampling_rate", None)
            if fs is None and "sampling_rate" in f:
                fs = np.asarray(f["sampling_rate"])
            return _broad_source(path, g, None if fs is None else float(np.squeeze(fs)),
                                 sample_rate_hz)
        raise ValueError(f"{path}: HDF5 logs need datasets 't' and 'gyro' (or BROAD's "
                         f"'imu_gyr'); found {sorted(f.keys())}")


def _load_mat(path: Path, sample_rate_hz) -> _Source:
    from scipy.io import loadmat

    m = loadmat(path)
    if "imu_gyr" in m:  # BROAD
        fs = float(np.squeeze(m["sampling_rate"])) if "sampling_rate" in m else None
        return _broad_source(path, np.asarray(m["imu_gyr"], float), fs, sample_rate_hz)
    for key in ("avp_imu", "imu", "wvt"):  # PSINS-style [wm vm t]
        if key in m:
            a = np.asarray(m[key], float)
            if a.ndim != 2 or a.shape[1] < 7:
                raise ValueError(f"{path}: '{key}' must be [wm vm t] with ≥ 7 columns")
            return _Source(a[:, -1], a[:, 0:3], kind="increment",
                           what=f"PSINS-style '{key}' [wm vm t]")
    keys = [k for k in m if not k.startswith("__")]
    raise ValueError(f"{path}: no 'imu_gyr' (BROAD) or 'imu' [wm vm t] (PSINS) variable; "
                     f"found {keys}")


def _load(path: Path, columns, sample_rate_hz) -> _Source:
    """Stamps, gyro values and what the file says of itself, from any supported file."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        t, g, units = _load_csv(path, columns)
        return _Source(t, g, units)
    if suffix in (".h5", ".hdf5"):
        return _load_hdf5(path, sample_rate_hz)
    if suffix == ".npy":
        arr = np.load(path, mmap_mode="r")
        if arr.ndim != 2 or arr.shape[1] != 4:
            raise ValueError(f"{path}: .npy logs must be (n, 4) [t, gx, gy, gz], got {arr.shape}")
        return _Source(np.asarray(arr[:, 0], float), np.asarray(arr[:, 1:], float))
    if suffix == ".npz":
        with np.load(path) as z:
            if "gyro" not in z or "t" not in z:
                raise ValueError(f"{path}: .npz logs need arrays 't' and 'gyro'")
            return _Source(np.asarray(z["t"], float), np.asarray(z["gyro"], float))
    if suffix == ".mat":
        return _load_mat(path, sample_rate_hz)
    raise ValueError(f"{path}: unsupported format {suffix!r} (use .csv, .npy, .npz, .h5 or "
                     ".mat)")


def _declared_units(path: Path, src: _Source, kind: InputKind, units: str | None) -> str:
    """The log's unit: the file's own (header, known format) or the declared one; a
    contradiction, a unit of the other kind or none at all is an error."""
    allowed: tuple[GyroUnit, ...] = RATE_UNITS if kind == "rate" else INCREMENT_UNITS
    if src.kind is not None and src.kind != kind:
        holds = "rates" if src.kind == "rate" else "increments"
        raise ValueError(f"{path}: {src.what} holds {holds}; pass "
                         f"--{'rates' if src.kind == 'rate' else 'increments'}")
    if src.units is not None:
        if src.units not in allowed:
            raise ValueError(f"{path}: the header declares {src.units!r}; a {kind} log "
                             f"needs one of {allowed}")
        if units is not None and units != src.units:
            raise ValueError(f"{path}: declared units {units!r} contradict {src.whose} "
                             f"{src.units!r}{src.note}")
        return src.units
    if units is None:
        raise ValueError(f"{path}: no units declared; pass --units or write them in the header "
                         f"(e.g. gx[{allowed[0]}])")
    return units


def read_imu(path: str | os.PathLike[str], *, kind: InputKind, units: GyroUnit | None,
             columns: Sequence[str] | None = None,
             sample_rate_hz: float | None = None, gap_tolerance: float = 1.5,
             on_gap: GapPolicy = "report", saturation: float | None = None,
             unit_check: UnitAction = "warn") -> ImuLog:
    """Read and validate a gyro log (see the module docstring).

    Parameters
    ----------
    kind : {"rate", "increment"}
    units : {"rad/s", "deg/s"} for rates, {"rad", "deg"} for increments, or None
        None takes the unit from the file: a CSV header (``gx[deg/s]``) or a format whose
        unit is known (BROAD: rad/s); it is an error when the file declares none, and when
        a declared unit contradicts the file's.
    columns : four CSV column names (time, x, y, z), optional
        Default: the header's time column (:data:`TIME_COLUMNS`) and gyro axes
        (:data:`GYRO_COLUMNS`).
    sample_rate_hz : float, optional
        The sensor's rate: required when the file carries no time (BROAD without
        sampling_rate); for stamped logs the nominal period ``1 / sample_rate_hz``
        (:attr:`ImuLog.nominal_period`, also the gap threshold's unit).
    gap_tolerance : float
        Intervals longer than this many nominal (or median) intervals are gaps.
    on_gap : {"report", "error"}
        Report gaps in :attr:`ImuLog.gaps` (split with :meth:`ImuLog.segments`)
        or raise at the first.
    saturation : float, optional
        Sensor range in the declared unit (per axis); rows with a component at
        or above it are listed in :attr:`ImuLog.saturated`.
    unit_check : {"warn", "error"}
        What magnitudes that suggest the other unit do (:func:`warn_implausible_rate`).
    """
    path = Path(path)
    if kind not in INPUT_KINDS:
        raise ValueError(f"kind must be 'rate' or 'increment', got {kind!r}")
    allowed: tuple[GyroUnit, ...] = RATE_UNITS if kind == "rate" else INCREMENT_UNITS
    if units is not None and units not in allowed:
        raise ValueError(f"{kind} units must be one of {allowed}, got {units!r}")
    if on_gap not in GAP_POLICIES:
        raise ValueError(f"on_gap must be 'report' or 'error', got {on_gap!r}")
    if not gap_tolerance > 1:
        raise ValueError(f"gap_tolerance is in sample intervals and must exceed 1, got "
                         f"{gap_tolerance}")
    if saturation is not None and not saturation > 0:
        raise ValueError(f"saturation must be positive, got {saturation}")
    if sample_rate_hz is not None and not (sample_rate_hz > 0 and math.isfinite(sample_rate_hz)):
        raise ValueError(f"the sample rate must be positive and finite, got {sample_rate_hz}")
    if columns is not None and len(columns) != 4:
        raise ValueError(f"columns must name time and three axes, got {columns}")
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    src = _load(path, None if columns is None else list(columns), sample_rate_hz)
    unit = _declared_units(path, src, kind, units)
    t, g = src.t, src.gyro
    if g.ndim != 2 or g.shape[1] != 3 or t.shape[0] != g.shape[0]:
        raise ValueError(f"{path}: expected n times and (n, 3) gyro values, got {t.shape}, "
                         f"{g.shape}")
    if t.size < 2:
        raise ValueError(f"{path}: {t.size} samples; at least 2 are needed")
    check_rows(path, t, [(None, [t, g])])
    d = np.diff(t)
    h = float(np.median(d))
    stamped = src.what != "BROAD's imu_gyr"  # BROAD's times come from its rate
    nominal = 1.0 / sample_rate_hz if sample_rate_hz is not None and stamped else None
    unit_h = nominal or h
    gaps = [int(i) + 2 for i in np.flatnonzero(d > gap_tolerance * unit_h)]
    if gaps and on_gap == "error":
        r = gaps[0]
        raise ValueError(f"{path}: gap of {d[r - 2]:.6g} s ({d[r - 2] / unit_h:.1f} sample "
                         f"intervals) before data row {r}")
    saturated = []
    if saturation is not None:
        saturated = [int(i) + 1 for i in np.flatnonzero(np.any(np.abs(g) >= saturation, axis=1))]
    scale = _DEG if unit.startswith("deg") else 1.0
    g = g * scale
    warn_implausible_rate(path, g if kind == "rate" else g / h, unit, action=unit_check)
    return ImuLog(np.asarray(t, float), np.ascontiguousarray(g), kind, h, gaps, saturated,
                  unit, nominal)


def write_attitude(path: str | os.PathLike[str], t: ArrayLike, q: NDArray[np.float64], *,
                   extra: Mapping[str, ArrayLike] | None = None) -> Path:
    """Write ``t, qw, qx, qy, qz`` (+ extra columns) atomically as CSV or ``.npz``."""
    path = Path(path)
    # Any: np.savez's column keywords share its signature with allow_pickle: bool
    cols: dict[str, Any] = {"t": np.asarray(t), "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2],
                            "qz": q[:, 3]}
    cols.update(extra or {})
    if path.suffix.lower() == ".npz":
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, **cols)
        return path
    if path.suffix.lower() != ".csv":
        raise ValueError(f"{path}: output must be .csv or .npz")
    names = list(cols)
    table = np.column_stack([np.asarray(cols[k], float) for k in names])
    with atomic_path(path) as tmp:
        np.savetxt(tmp, table, delimiter=",", header=",".join(names), comments="",
                   fmt="%.17g")
    return path
