"""Reading IMU logs and writing attitude, with validation that names the row.

Formats (by suffix): CSV with a header row (columns mapped by name, default
``t,gx,gy,gz``), NumPy ``.npy`` (``(n, 4)`` ``[t, gx, gy, gz]``) and ``.npz``
(arrays ``t`` and ``gyro``), HDF5 ``.h5``/``.hdf5`` (datasets ``t`` and
``gyro``, or BROAD's ``imu_gyr`` with a ``sampling_rate``; needs the ``hdf5``
extra), MATLAB ``.mat`` (PSINS ``[wm vm t]`` — increments in columns 1–3, time
last — or BROAD ``imu_gyr`` with ``sampling_rate``).

Every log declares what it holds: rates or increments, and the unit
(``rad/s``/``deg/s`` for rates, ``rad``/``deg`` for increments), either by
argument or — for CSV — by the header convention ``gx[deg/s]`` (a unit in
brackets after a column name; a declared unit that contradicts the header is
an error). A plausibility check warns when magnitudes suggest the other unit
(a rate above :data:`RATE_PLAUSIBLE_MAX` rad/s declared as rad/s is more likely
deg/s). Validation raises on NaN or infinity, duplicated or non-monotonic time
stamps (with the row number, counting the first data row as 1), reports gaps
larger than ``gap_tolerance`` sample intervals (or raises, ``on_gap="error"``;
:meth:`ImuLog.segments` splits at them) and reports rows at or above a
declared saturation level.
"""

from __future__ import annotations

import csv
import io as _io
import itertools
import os
import re
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.kinds import INPUT_KINDS, InputKind
from strapdown._core.validation import first_bad_step
from strapdown.io.files import atomic_path

__all__ = [
    "GAP_POLICIES",
    "INCREMENT_UNITS",
    "RATE_PLAUSIBLE_MAX",
    "RATE_UNITS",
    "GapPolicy",
    "GyroUnit",
    "ImuLog",
    "IncrementUnit",
    "RateUnit",
    "UnitWarning",
    "check_rows",
    "csv_columns",
    "read_imu",
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
    """

    t: NDArray[np.float64]
    data: NDArray[np.float64]
    kind: InputKind
    h: float
    gaps: list[int] = field(default_factory=list)
    saturated: list[int] = field(default_factory=list)

    def segments(self) -> list[slice]:
        """Index ranges between gaps: each a gap-free run of samples.

        A gap reported at data row ``r`` (1-based) starts a new segment at index ``r − 1``.
        """
        edges = [0, *(r - 1 for r in self.gaps), self.t.size]
        return [slice(a, b) for a, b in itertools.pairwise(edges)]


_UNIT = re.compile(r"^\s*([^\[\]]*?)\s*\[\s*([^\[\]]+?)\s*\]\s*$")


def _split_header(cells):
    """Column names and the units the header declares (``gx[deg/s]`` → ``gx``, ``deg/s``)."""
    names, units = [], {}
    for c in cells:
        m = _UNIT.match(c)
        if m:
            names.append(m.group(1))
            units[m.group(1)] = m.group(2)
        else:
            names.append(c.strip())
    return names, units


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
    raw, units, _ = csv_columns(path, columns)
    axis_units = {units[c] for c in columns[1:] if c in units}
    if len(axis_units) > 1:
        raise ValueError(f"{path}: the header gives the axes different units {sorted(axis_units)}")
    return raw, (axis_units.pop() if axis_units else None)


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
                          suggestion: str = "degrees") -> None:
    """Warn when rates (rad/s) declared in radians have magnitudes that suggest degrees."""
    big = float(np.percentile(np.linalg.norm(rate, axis=1), 99))
    if not declared.startswith("deg") and big > RATE_PLAUSIBLE_MAX:
        warnings.warn(f"{path}: 99th-percentile rate {big:.0f} rad/s is implausible; the log is "
                      f"more likely in {suggestion} (declared {declared})", UnitWarning,
                      stacklevel=3)


def _load_hdf5(path: Path, sample_rate_hz):
    try:
        import h5py
    except ImportError:
        raise ValueError(f"{path}: reading HDF5 needs h5py: pip install 'strapdown[hdf5]'"
                         ) from None
    with h5py.File(path, "r") as f:
        if "gyro" in f and "t" in f:
            return np.asarray(f["t"], float), np.asarray(f["gyro"], float)
        if "imu_gyr" in f:
            g = np.asarray(f["imu_gyr"], float)
            fs = f.attrs.get("sampling_rate", None)
            if fs is None and "sampling_rate" in f:
                fs = np.asarray(f["sampling_rate"])
            fs = float(np.squeeze(fs)) if fs is not None else sample_rate_hz
            if not fs:
                raise ValueError(f"{path}: no sampling_rate; pass --sample-rate-hz")
            return np.arange(g.shape[0]) / fs, g
        raise ValueError(f"{path}: HDF5 logs need datasets 't' and 'gyro' (or BROAD's "
                         f"'imu_gyr'); found {sorted(f.keys())}")


def _load(path: Path, columns, sample_rate_hz):
    """``(t, gyro, header_units)`` from any supported file."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        arr, units = _load_csv(path, columns)
        return arr[:, 0], arr[:, 1:4], units
    if suffix in (".h5", ".hdf5"):
        return (*_load_hdf5(path, sample_rate_hz), None)
    if suffix == ".npy":
        arr = np.load(path, mmap_mode="r")
        if arr.ndim != 2 or arr.shape[1] != 4:
            raise ValueError(f"{path}: .npy logs must be (n, 4) [t, gx, gy, gz], got {arr.shape}")
        return np.asarray(arr[:, 0], float), np.asarray(arr[:, 1:], float), None
    if suffix == ".npz":
        with np.load(path) as z:
            if "gyro" not in z or "t" not in z:
                raise ValueError(f"{path}: .npz logs need arrays 't' and 'gyro'")
            return np.asarray(z["t"], float), np.asarray(z["gyro"], float), None
    if suffix == ".mat":
        from scipy.io import loadmat

        m = loadmat(path)
        if "imu_gyr" in m:  # BROAD
            g = np.asarray(m["imu_gyr"], float)
            fs = float(np.squeeze(m["sampling_rate"])) if "sampling_rate" in m else sample_rate_hz
            if not fs:
                raise ValueError(f"{path}: no sampling_rate; pass --sample-rate-hz")
            return np.arange(g.shape[0]) / fs, g, None
        for key in ("avp_imu", "imu", "wvt"):  # PSINS-style [wm vm t]
            if key in m:
                a = np.asarray(m[key], float)
                if a.ndim != 2 or a.shape[1] < 7:
                    raise ValueError(f"{path}: '{key}' must be [wm vm t] with ≥ 7 columns")
                return a[:, -1], a[:, 0:3], None
        keys = [k for k in m if not k.startswith("__")]
        raise ValueError(f"{path}: no 'imu_gyr' (BROAD) or 'imu' [wm vm t] (PSINS) variable; "
                         f"found {keys}")
    raise ValueError(f"{path}: unsupported format {suffix!r} (use .csv, .npy, .npz, .h5 or "
                     ".mat)")


def read_imu(path: str | os.PathLike[str], *, kind: InputKind, units: GyroUnit | None,
             columns: Sequence[str] = ("t", "gx", "gy", "gz"),
             sample_rate_hz: float | None = None, gap_tolerance: float = 1.5,
             on_gap: GapPolicy = "report", saturation: float | None = None) -> ImuLog:
    """Read and validate a gyro log (see the module docstring).

    Parameters
    ----------
    kind : {"rate", "increment"}
    units : {"rad/s", "deg/s"} for rates, {"rad", "deg"} for increments, or None
        None takes the unit from a CSV header (``gx[deg/s]``); it is an error
        when the file declares none.
    columns : four CSV column names (time, x, y, z)
    sample_rate_hz : float, optional
        Required when the file carries no time (BROAD without sampling_rate).
    gap_tolerance : float
        Intervals longer than this many median intervals are gaps.
    on_gap : {"report", "error"}
        Report gaps in :attr:`ImuLog.gaps` (split with :meth:`ImuLog.segments`)
        or raise at the first.
    saturation : float, optional
        Sensor range in the declared unit (per axis); rows with a component at
        or above it are listed in :attr:`ImuLog.saturated`.
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
    if len(columns) != 4:
        raise ValueError(f"columns must name time and three axes, got {columns}")
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    t, g, header_units = _load(path, list(columns), sample_rate_hz)
    if header_units is not None:
        if header_units not in allowed:
            raise ValueError(f"{path}: the header declares {header_units!r}; a {kind} log "
                             f"needs one of {allowed}")
        if units is not None and units != header_units:
            raise ValueError(f"{path}: declared units {units!r} contradict the header's "
                             f"{header_units!r}")
        units = header_units
    if units is None:
        raise ValueError(f"{path}: no units declared; pass --units or write them in the header "
                         f"(e.g. gx[{allowed[0]}])")
    if g.ndim != 2 or g.shape[1] != 3 or t.shape[0] != g.shape[0]:
        raise ValueError(f"{path}: expected n times and (n, 3) gyro values, got {t.shape}, "
                         f"{g.shape}")
    if t.size < 2:
        raise ValueError(f"{path}: {t.size} samples; at least 2 are needed")
    check_rows(path, t, [(None, [t, g])])
    d = np.diff(t)
    h = float(np.median(d))
    gaps = [int(i) + 2 for i in np.flatnonzero(d > gap_tolerance * h)]
    if gaps and on_gap == "error":
        r = gaps[0]
        raise ValueError(f"{path}: gap of {d[r - 2]:.6g} s ({d[r - 2] / h:.1f} sample intervals) "
                         f"before data row {r}")
    saturated = []
    if saturation is not None:
        saturated = [int(i) + 1 for i in np.flatnonzero(np.any(np.abs(g) >= saturation, axis=1))]
    scale = _DEG if units.startswith("deg") else 1.0
    g = g * scale
    rate = g if kind == "rate" else g / h
    warn_implausible_rate(path, rate, units)
    big = float(np.percentile(np.linalg.norm(rate, axis=1), 99))
    if units.startswith("deg") and big < 1e-3 * _DEG and big > 0:
        warnings.warn(f"{path}: 99th-percentile rate {big / _DEG:.2e} °/s is implausibly small; "
                      f"the log is more likely in radians (declared {units})", UnitWarning,
                      stacklevel=2)
    return ImuLog(np.asarray(t, float), np.ascontiguousarray(g), kind, h, gaps, saturated)


def write_attitude(path: str | os.PathLike[str], t: ArrayLike, q: NDArray[np.float64], *,
                   extra: dict[str, ArrayLike] | None = None) -> Path:
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
