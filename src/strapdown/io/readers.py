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
A UTF-8 byte-order mark, CRLF line ends and ``;``, tab or ``|`` delimiters (given, or
detected from the header row: :data:`DELIMITERS`) are read as plainly as commas.

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

Anything wrong with a file or an option is an :class:`~strapdown.InputError` (a
``ValueError``) naming the file and what was expected, its message bounded in length. The
binary formats are read by :mod:`strapdown.io.containers`, which validates their structure
before decoding anything and checks declared sizes against the file and the memory budget
(:mod:`strapdown._core.limits`). Physical limits apply to every route: time steps of at
least :data:`MIN_PERIOD`, a sample period up to :data:`MAX_PERIOD`, and no sample turning
the body by more than :data:`MAX_SAMPLE_ANGLE` (π).
"""

from __future__ import annotations

import csv
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

from strapdown._core.errors import InputError, shown
from strapdown._core.kinds import INPUT_KINDS, InputKind
from strapdown._core.limits import check_bytes
from strapdown._core.validation import first_bad_step
from strapdown.io.containers import open_npy, read_hdf5, read_mat, read_npz
from strapdown.io.files import atomic_path, write_csv_rows
from strapdown.io.timing import (
    JITTER_TOLERANCE,
    DuplicatePolicy,
    HeldPolicy,
    Timing,
    TimingMode,
    format_times,
    reconstruct,
    relative_times,
)

__all__ = [
    "ACC_COLUMNS",
    "DELIMITERS",
    "GAP_POLICIES",
    "GYRO_COLUMNS",
    "INCREMENT_UNITS",
    "MAG_COLUMNS",
    "MAX_HEADER_CHARS",
    "MAX_PERIOD",
    "MAX_SAMPLE_ANGLE",
    "MIN_PERIOD",
    "PSINS_VARIABLES",
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
    "check_distinct_columns",
    "check_finite_rows",
    "check_motion",
    "check_read_options",
    "check_rows",
    "check_steps",
    "column_index",
    "csv_columns",
    "csv_header",
    "default_columns",
    "file_rate",
    "input_file",
    "log_kind",
    "npy_log",
    "read_imu",
    "read_time_base",
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
    timing : Timing or None
        The time base (:mod:`strapdown.io.timing`): rows dropped or collapsed, the fitted
        clock, how the stamps are taken; ``t`` and ``data`` hold the samples kept.
    """

    t: NDArray[np.float64]
    data: NDArray[np.float64]
    kind: InputKind
    h: float
    gaps: list[int] = field(default_factory=list)
    saturated: list[int] = field(default_factory=list)
    units: str | None = None
    nominal_period: float | None = None
    timing: Timing | None = None

    def segments(self) -> list[slice]:
        """Index ranges between gaps: each a gap-free run of samples.

        A gap reported at data row ``r`` (1-based) starts a new segment at that row's sample.
        """
        edges = [0, *(self.index_of_row(r) for r in self.gaps), self.t.size]
        return [slice(a, b) for a, b in itertools.pairwise(edges)]

    def index_of_row(self, row: int) -> int:
        """The sample index of data row ``row`` (1-based; rows dropped or collapsed by the
        time base do not count)."""
        if self.timing is None:
            return row - 1
        return int(np.searchsorted(self.timing.rows, row))


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


#: Delimiters a CSV may use: given (``--delimiter``) or detected from the header row (the
#: first of these it contains; none: a single column).
DELIMITERS = (",", ";", "\t", "|")
#: Longest header row read (characters): a longer first line is not a CSV header.
MAX_HEADER_CHARS = 65536


def _delimiter(path: Path, line: str, given: str | None) -> str:
    if given is not None:
        d = {"tab": "\t", "\\t": "\t", "comma": ",", "semicolon": ";"}.get(given, given)
        if d not in DELIMITERS:
            raise InputError(f"--delimiter must be one of , ; tab |, got {shown(given, 20)}")
        return d
    return next((d for d in DELIMITERS if d in line), ",")


def _bad_bytes(exc: UnicodeDecodeError) -> str:
    return f"bytes {shown(exc.object[exc.start:exc.start + 8], 40)}"


def _header_line(path: Path, f, delimiter: str | None) -> tuple[list[str], str]:
    """The header row's cells and the delimiter, from a text file opened by :func:`_text`."""
    try:
        line = f.readline(MAX_HEADER_CHARS + 1)
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text ({_bad_bytes(exc)}); expected a CSV log"
                         ) from None
    if not line.strip():
        raise InputError(f"{path}: {'empty file' if not line else 'the header row is empty'}; "
                         "expected a CSV with a header row")
    if len(line) > MAX_HEADER_CHARS:
        raise InputError(f"{path}: the header row is longer than {MAX_HEADER_CHARS} characters; "
                         "expected a CSV with a header row")
    d = _delimiter(path, line, delimiter)
    return _cells(path, line, d), d


def _cells(path: Path, line: str, d: str) -> list[str]:
    try:
        return next(csv.reader([line.rstrip("\r\n")], delimiter=d))
    except (csv.Error, StopIteration) as exc:
        raise InputError(f"{path}: unreadable header row ({exc})") from None


#: Units a second header row may hold (besides time units, gyro units and the spellings of
#: :data:`UNIT_SPELLINGS`): a cell of that row that is one of them is the column's unit; any
#: other cell names the column within the group above it.
HEADER_UNITS = frozenset({"rad/s", "deg/s", "rad", "deg", "m/s2", "g", "m/s", "ut", "µt",
                          "nt", "gauss", "mg", "a.u.", "au", "counts", "lsb"})


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _is_unit(cell: str) -> bool:
    c = canonical_unit(cell.strip().strip("[]()"))
    return c in TIME_UNITS or c.lower() in HEADER_UNITS


def _second_row(path: Path, f, d: str, first: list[str]) -> list[str] | None:
    """The second header row's cells when the line after the header is one (a row of the
    header's width none of whose cells is a number, e.g. units ``s;W;X;Y;Z``); the file
    position is left after it, else where it was."""
    pos = f.tell()
    try:
        line = f.readline(MAX_HEADER_CHARS + 1)
    except UnicodeDecodeError:
        f.seek(pos)
        return None
    cells = _cells(path, line, d) if line.strip() else []
    if not cells or any(_is_number(c) for c in cells if c.strip()) or len(cells) != len(first):
        f.seek(pos)
        return None
    return cells


def _merge_rows(first: list[str], second: list[str] | None) -> tuple[list[str], dict[str, str]]:
    """Column names and units of one or two header rows.

    The first row's names and bracketed units (``gx[deg/s]``); with a second row, a group
    name spans the empty cells to its right, and each second-row cell is the column's unit
    when it is one (``s``, ``rad/s``, ``m/s^2``) or else its name within the group
    (``IMU Gyroscope`` over ``X`` → ``IMU Gyroscope X``).
    """
    names, units = _split_header(first)
    if second is None:
        return names, units
    group = ""
    out: list[str] = []
    for j, (name, cell) in enumerate(zip(names, second, strict=True)):
        group = name or group
        sub = cell.strip()
        if sub and not _is_unit(sub):
            full = f"{group} {sub}".strip()
        else:
            full = name or f"{group} {j}".strip()
            if sub:
                units[full] = canonical_unit(sub.strip("[]()"))
        out.append(full)
    return out, units


def _text(path: Path):
    """``path`` opened as UTF-8 text: a byte-order mark skipped, CRLF and CR read as LF."""
    return open(path, encoding="utf-8-sig", newline=None)


def csv_header(path: str | os.PathLike[str], *, delimiter: str | None = None
               ) -> tuple[list[str], dict[str, str]]:
    """The column names of a CSV's header and the units it declares by name.

    ``delimiter``: one of :data:`DELIMITERS` (``"tab"`` for a tab), or None to take the
    first of them the header row contains. A UTF-8 byte-order mark and CRLF line ends are
    read as plain text. A second header row (a line with cells that are not numbers) is
    read too: its units (``s``, ``rad/s`` …) are the columns' units, its other cells name
    the columns within the group names of the first row, whose empty cells continue the
    group to their left (:func:`_merge_rows`).
    """
    path = Path(path)
    with _text(path) as f:
        cells, d = _header_line(path, f, delimiter)
        second = _second_row(path, f, d, cells)
    return _merge_rows(cells, second)


def default_columns(path: str | os.PathLike[str],
                    axes: Sequence[tuple[str, Sequence[tuple[str, str, str]]]],
                    optional: Sequence[tuple[str, str, str]] = (), *,
                    delimiter: str | None = None) -> tuple[list[str], list[str]]:
    """The columns a header names without ``--columns``: ``([time, *axes], optional)``.

    The time column is the one header name among :data:`TIME_COLUMNS` (case-insensitive,
    unit suffixes allowed); each ``(label, candidates)`` of ``axes`` takes the first of its
    candidate triples the header has, ``optional`` likewise (``[]`` when it has none).
    Errors name what is missing or ambiguous and the header.
    """
    names, _ = csv_header(path, delimiter=delimiter)
    times = [n for n in names if _TIME_NAME.match(n)]
    if len(times) != 1:
        what = "no time column" if not times else f"several time columns {shown(times, 80)}"
        raise InputError(f"{path}: {what} in the header {shown(names, 160)} (recognised: "
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
            raise InputError(f"{path}: no {label} columns in the header {shown(names, 160)} "
                             f"(recognised: {'; '.join(','.join(c) for c in candidates)}); "
                             "name the columns with --columns")
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
        raise InputError(f"{path}: time column {shown(name, 40)} is in {shown(unit, 40)}; known "
                         f"time units are {', '.join(TIME_UNITS)}")
    return TIME_UNITS[unit]


def _csv_budget(path: Path, ncols: int) -> None:
    """Refuse a CSV whose values would exceed the memory budget (rows estimated from the
    mean length of the first 64 kiB of lines)."""
    size = path.stat().st_size
    with open(path, "rb") as f:
        sample = f.read(65536)
    mean = len(sample) / max(sample.count(b"\n"), 1)
    check_bytes(path, int(size / mean + 1) * ncols * 8, "its values")


def column_index(header: Sequence[str], selector: str | int) -> int | None:
    """The index of a column given by name, or by 0-based index (an int or a string of
    digits); None when the header has no such column."""
    if isinstance(selector, int) or (isinstance(selector, str) and selector.strip().isdigit()):
        i = int(selector)
        return i if 0 <= i < len(header) else None
    return header.index(selector) if selector in header else None


def csv_columns(path: str | os.PathLike[str], columns: Sequence[str],
                optional: Sequence[str] = (), *, delimiter: str | None = None
                ) -> tuple[NDArray[np.float64], dict[str, str], bool]:
    """Columns of a CSV log with a header row, by name or by 0-based index.

    Returns ``(values, units, have_optional)``: ``values`` holds ``columns``
    followed by ``optional`` when every optional column is present, ``units``
    the header's units by column name (``gx[deg/s]``, or a second header row) and by
    each selector given (so an index ``"8"`` finds its column's unit). Errors name
    missing columns, a file without data rows, unreadable numbers and rows
    whose field count differs from the header's. ``delimiter``: as :func:`csv_header`.
    """
    path = Path(path)
    with _text(path) as f:
        cells, d = _header_line(path, f, delimiter)
        second = _second_row(path, f, d, cells)
        header, units = _merge_rows(cells, second)
        missing = [c for c in columns if column_index(header, c) is None]
        if missing:
            raise InputError(f"{path}: columns {shown(missing, 100)} not in the header "
                             f"{shown(header, 160)} ({len(header)} columns, 0-based indices "
                             f"0-{len(header) - 1}); map them with --columns")
        have_optional = bool(optional) and all(column_index(header, c) is not None
                                               for c in optional)
        wanted = list(columns) + (list(optional) if have_optional else [])
        idx = [int(column_index(header, c) or 0) for c in wanted]  # every one found above
        for sel, i in zip(wanted, idx, strict=True):
            if header[i] in units:
                units[str(sel)] = units[header[i]]
        used = sorted(set(idx))
        _csv_budget(path, len(used))
        if len(used) == len(header):
            raw = _csv_values(path, f, d, len(header))
            return raw[:, idx], units, have_optional
        # other columns (a lab file's reference, with empty cells where the optical system
        # lost the body) are not read, so they cannot refuse the log
        raw = _csv_values(path, f, d, len(header), usecols=used)
        where = {c: j for j, c in enumerate(used)}
    return raw[:, [where[i] for i in idx]], units, have_optional


def _csv_values(path: Path, f, delimiter: str, ncols: int,
                usecols: Sequence[int] | None = None) -> NDArray[np.float64]:
    """The data rows after the header, as numbers (every row with the header's fields; with
    ``usecols``, those columns of every row)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            raw = np.loadtxt(f, delimiter=delimiter, ndmin=2, dtype=np.float64,
                             usecols=usecols)
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text ({_bad_bytes(exc)}); expected numbers"
                         ) from None
    except (ValueError, IndexError) as exc:
        raise InputError(f"{path}: unreadable number ({shown(str(exc), 160)}); expected "
                         f"{ncols} numbers separated by {delimiter!r} in every data row"
                         ) from None
    if raw.size == 0:
        raise InputError(f"{path}: no data rows")
    if usecols is None and raw.shape[1] != ncols:
        raise InputError(f"{path}: rows have {raw.shape[1]} fields, the header {ncols}")
    return raw


def _load_csv(path: Path, columns, delimiter: str | None):
    """``(t in its own unit, axes, header unit of the axes, seconds per unit of t)``;
    ``columns`` None: :func:`default_columns`."""
    if columns is None:
        columns, _ = default_columns(path, [("gyro", GYRO_COLUMNS)], delimiter=delimiter)
    raw, units, _ = csv_columns(path, columns, delimiter=delimiter)
    axis_units = {units[c] for c in columns[1:] if c in units}
    if len(axis_units) > 1:
        raise InputError(f"{path}: the header gives the axes different units "
                         f"{shown(sorted(axis_units), 80)}")
    scale = time_scale(path, columns[0], units)
    return raw[:, 0], raw[:, 1:4], (axis_units.pop() if axis_units else None), scale


#: Shortest time step accepted (s): an IMU samples at most at 1 GHz.
MIN_PERIOD = 1e-9
#: Longest median sample period accepted (s, about a day).
MAX_PERIOD = 1e5
#: Largest rotation in one sample (rad): beyond π the samples cannot resolve the motion
#: (Nyquist), and the units or the sample rate are wrong.
MAX_SAMPLE_ANGLE = math.pi


def check_rows(path: str | os.PathLike[str], t: NDArray[np.float64],
               groups: Iterable[tuple[str | None, Iterable[ArrayLike]]]) -> None:
    """Raise on the first non-finite row of each group and on a bad time step.

    ``groups``: ``(label, arrays)`` pairs checked in order; a row is bad when
    any array of the group is not finite there. Rows count from 1 (the first
    data row); ``label`` None gives "NaN or infinity in data row r". Time steps must be
    positive, finite and at least :data:`MIN_PERIOD`.
    """
    for label, arrays in groups:
        bad = np.zeros(t.shape[0], bool)
        for a in arrays:
            a = np.asarray(a)
            bad |= ~np.isfinite(a) if a.ndim == 1 else ~np.all(np.isfinite(a), axis=1)
        if np.any(bad):
            where = "" if label is None else f" the {label} at"
            raise InputError(f"{path}: NaN or infinity in{where} data row "
                             f"{int(np.argmax(bad)) + 1}")
    with np.errstate(over="ignore", invalid="ignore"):  # an overflowing step is reported
        d = np.diff(t)
    check_steps(path, d, t)


def check_steps(path: str | os.PathLike[str], d: NDArray[np.float64], t: NDArray[np.float64],
                first_row: int = 1) -> None:
    """Raise on the first time step ``d = diff(t)`` that is not positive, overflows or is
    shorter than :data:`MIN_PERIOD`; ``first_row`` is the data row of ``t[0]``."""
    fault = first_bad_step(d)
    if fault is not None:
        i, what = fault
        raise InputError(f"{path}: {what} time stamp in data row {i + first_row + 1} (t = "
                         f"{float(t[i + 1])!r} after {float(t[i])!r})")
    bad = ~np.isfinite(d) | (d < MIN_PERIOD)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{path}: time step of {float(d[i])!r} s before data row "
                         f"{i + first_row + 1}; "
                         f"steps must be finite and at least {MIN_PERIOD:g} s (check the time "
                         "unit)")


def check_motion(path: str | os.PathLike[str], values: NDArray[np.float64], kind: InputKind,
                 h: float, first_row: int = 1) -> None:
    """Raise when a sample turns the body by more than :data:`MAX_SAMPLE_ANGLE` (rates in
    rad/s times the period ``h``, or increments in rad): such a log cannot be integrated
    (the units or the sample rate are wrong)."""
    if not MIN_PERIOD <= h <= MAX_PERIOD:
        raise InputError(f"{path}: a sample period of {h:.15g} s; it must lie between "
                         f"{MIN_PERIOD:g} and {MAX_PERIOD:g} s (check the time unit)")
    if values.shape[0] == 0:
        return
    v = np.abs(values) * (h if kind == "rate" else 1.0)
    angle = np.hypot(np.hypot(v[:, 0], v[:, 1]), v[:, 2])  # no overflow before the limit
    bad = ~(angle <= MAX_SAMPLE_ANGLE)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{path}: data row {i + first_row} turns the body by {angle[i]:.4g} rad "
                         f"in one sample (at most π); check the units and the sample rate")


def warn_implausible_rate(path: str | os.PathLike[str], rate: NDArray[np.float64], declared: str,
                          suggestion: str = "degrees", *, action: UnitAction = "warn") -> None:
    """Judge rates (rad/s) against the declared unit: a 99th-percentile rate above
    :data:`RATE_PLAUSIBLE_MAX` rad/s declared in radians is more likely degrees, one below
    1e-3 °/s declared in degrees more likely radians.

    ``action="warn"`` issues a :class:`UnitWarning`; ``"error"`` raises an
    :class:`~strapdown.InputError` saying how to accept the units (``--accept-unit-warning``).
    """
    if action not in UNIT_ACTIONS:
        raise InputError(f"action must be one of {', '.join(UNIT_ACTIONS)}, got "
                         f"{shown(action, 20)}")
    if rate.shape[0] == 0:
        return
    with np.errstate(over="ignore", invalid="ignore"):
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
        raise InputError(f"{msg}; nothing computed. If the declared units are right, pass "
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
    scale: float = 1.0  # seconds per unit of t (t[ms]: 1e-3), applied by read_imu


def file_rate(path: str | os.PathLike[str], value: ArrayLike | None) -> float | None:
    """A sampling rate a file states (one positive finite number, any shape of one
    element), or None when it states none."""
    if value is None:
        return None
    a = np.asarray(value)
    if a.size != 1 or a.dtype.kind not in "biuf":
        raise InputError(f"{path}: sampling_rate must be one number, got {a.dtype.name} of "
                         f"shape {a.shape}")
    fs = float(a.reshape(()))
    if not 1 / MAX_PERIOD <= fs <= 1 / MIN_PERIOD:
        raise InputError(f"{path}: sampling_rate must be positive and finite, between "
                         f"{1 / MAX_PERIOD:g} and {1 / MIN_PERIOD:g} Hz, got {fs!r}")
    return fs


def _broad_source(path: Path, g, fs, sample_rate_hz) -> _Source:
    """BROAD's ``imu_gyr`` (rad/s) at its ``sampling_rate`` (or the one given)."""
    if fs is not None and sample_rate_hz is not None and not math.isclose(
            fs, sample_rate_hz, rel_tol=1e-9):
        raise InputError(f"{path}: the file states a sampling rate of {fs:g} Hz, not the "
                         f"{sample_rate_hz:g} Hz given")
    fs = fs if fs is not None else sample_rate_hz
    if not fs:
        raise InputError(f"{path}: no sampling_rate; pass --sample-rate-hz")
    return _Source(np.arange(g.shape[0]) / fs, g, "rad/s", "the file's",
                   " (BROAD stores imu_gyr in rad/s)", "rate", "BROAD's imu_gyr")


def _load_hdf5(path: Path, sample_rate_hz) -> _Source:
    c = read_hdf5(path, ["t", "gyro", "imu_gyr", "sampling_rate"], ["sampling_rate"])
    a = c.arrays
    if "gyro" in a and "t" in a:
        return _Source(a["t"], a["gyro"])
    if "imu_gyr" in a:
        fs = c.attrs.get("sampling_rate", a.get("sampling_rate"))
        return _broad_source(path, a["imu_gyr"], file_rate(path, fs), sample_rate_hz)
    raise InputError(f"{path}: HDF5 logs need datasets 't' and 'gyro' (or BROAD's 'imu_gyr'); "
                     f"found {c.found()}")


def _load_mat(path: Path, sample_rate_hz) -> _Source:
    c = read_mat(path, ["imu_gyr", "sampling_rate", *PSINS_VARIABLES])
    m = c.arrays
    if "imu_gyr" in m:  # BROAD
        return _broad_source(path, m["imu_gyr"], file_rate(path, m.get("sampling_rate")),
                             sample_rate_hz)
    for key in PSINS_VARIABLES:  # PSINS-style [wm vm t]
        if key in m:
            a = m[key]
            if a.ndim != 2 or a.shape[1] < 7:
                raise InputError(f"{path}: '{key}' must be [wm vm t] with ≥ 7 columns, got "
                                 f"shape {a.shape}")
            return _Source(a[:, -1], a[:, 0:3], kind="increment",
                           what=f"PSINS-style '{key}' [wm vm t]")
    raise InputError(f"{path}: no 'imu_gyr' (BROAD) or 'imu' [wm vm t] (PSINS) variable; "
                     f"found {c.found()}")


#: MATLAB variables read as PSINS ``[wm vm t]`` logs, in order of preference.
PSINS_VARIABLES = ("avp_imu", "imu", "wvt")


def npy_log(path: str | os.PathLike[str]) -> NDArray[Any]:
    """An ``(n, 4)`` ``[t, gx, gy, gz]`` ``.npy`` log, memory-mapped (any real dtype)."""
    arr = open_npy(path)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise InputError(f"{path}: .npy logs must be (n, 4) [t, gx, gy, gz], got shape "
                         f"{arr.shape}")
    return arr


def _load(path: Path, columns, sample_rate_hz, delimiter) -> _Source:
    """Stamps, gyro values and what the file says of itself, from any supported file."""
    suffix = path.suffix.lower()
    if suffix in (".csv", ".txt", ".tsv"):
        t, g, units, scale = _load_csv(path, columns, delimiter)
        return _Source(t, g, units, scale=scale)
    if suffix in (".h5", ".hdf5"):
        return _load_hdf5(path, sample_rate_hz)
    if suffix == ".npy":
        arr = npy_log(path)
        check_bytes(path, arr.shape[0] * 32, "the log as float64")
        with np.errstate(over="ignore"):  # float128 beyond float64: infinity, refused by row
            return _Source(np.asarray(arr[:, 0], float), np.asarray(arr[:, 1:], float))
    if suffix == ".npz":
        z = read_npz(path, ["t", "gyro"])
        if "gyro" not in z.arrays or "t" not in z.arrays:
            raise InputError(f"{path}: .npz logs need arrays 't' and 'gyro'; found {z.found()}")
        with np.errstate(over="ignore"):  # float128 beyond float64: refused by row
            return _Source(z.arrays["t"].astype(float), z.arrays["gyro"].astype(float))
    if suffix == ".mat":
        return _load_mat(path, sample_rate_hz)
    raise InputError(f"{path}: unsupported format {shown(suffix, 20)} (use .csv, .npy, .npz, "
                     ".h5 or .mat)")


def _declared_units(path: Path, src: _Source, kind: InputKind, units: str | None) -> str:
    """The log's unit: the file's own (header, known format) or the declared one; a
    contradiction, a unit of the other kind or none at all is an error."""
    allowed: tuple[GyroUnit, ...] = RATE_UNITS if kind == "rate" else INCREMENT_UNITS
    if src.kind is not None and src.kind != kind:
        holds = "rates" if src.kind == "rate" else "increments"
        raise InputError(f"{path}: {src.what} holds {holds}; pass "
                         f"--{'rates' if src.kind == 'rate' else 'increments'}")
    if src.units is not None:
        if src.units not in allowed:
            raise InputError(f"{path}: the header declares {shown(src.units, 30)}; a {kind} log "
                             f"needs one of {allowed}")
        if units is not None and units != src.units:
            raise InputError(f"{path}: declared units {units!r} contradict {src.whose} "
                             f"{src.units!r}{src.note}")
        return src.units
    if units is None:
        raise InputError(f"{path}: no units declared; pass --units or write them in the header "
                         f"(e.g. gx[{allowed[0]}])")
    return units


def check_read_options(*, kind: object, units: object, gap_tolerance: object, on_gap: object,
                       saturation: object, sample_rate_hz: object,
                       columns: Sequence[str] | None = None, kind_optional: bool = False
                       ) -> None:
    """The reading options every input route shares (:func:`read_imu`, the streamed
    ``.npy`` path of ``strapdown run``), checked before any file is opened."""
    if kind not in INPUT_KINDS and not (kind_optional and kind is None):
        raise InputError(f"kind must be 'rate' or 'increment', got {shown(kind, 20)}")
    allowed: tuple[GyroUnit, ...] = (RATE_UNITS if kind == "rate" else INCREMENT_UNITS
                                     if kind == "increment" else RATE_UNITS + INCREMENT_UNITS)
    if units is not None and units not in allowed:
        raise InputError(f"{kind} units must be one of {allowed}, got {shown(units, 20)}")
    if on_gap not in GAP_POLICIES:
        raise InputError(f"on_gap must be 'report' or 'error', got {shown(on_gap, 20)}")
    if not 1 < _as_float(gap_tolerance) < math.inf:
        raise InputError(f"gap_tolerance is in sample intervals and must be finite and exceed "
                         f"1, got {shown(gap_tolerance, 20)}")
    if saturation is not None and not 0 < _as_float(saturation) < math.inf:
        raise InputError(f"saturation must be positive and finite, got {shown(saturation, 20)}")
    if sample_rate_hz is not None and not (1 / MAX_PERIOD <= _as_float(sample_rate_hz)
                                           <= 1 / MIN_PERIOD):
        raise InputError(f"the sample rate must be positive and finite, between "
                         f"{1 / MAX_PERIOD:g} and {1 / MIN_PERIOD:g} Hz, got "
                         f"{shown(sample_rate_hz, 20)}")
    if columns is not None and len(columns) != 4:
        raise InputError(f"columns must name time and three axes, got {shown(columns, 80)}")
    check_distinct_columns(columns)


def check_distinct_columns(columns: Sequence[str] | None) -> None:
    """Raise when a column is named twice (``--columns t,t,t,t`` would integrate the time
    column as the gyro)."""
    if columns is None:
        return
    seen: dict[str, int] = {}
    for i, c in enumerate(columns):
        key = str(c).strip()
        if key in seen:
            raise InputError(f"--columns names {shown(key, 40)} twice (positions {seen[key] + 1} "
                             f"and {i + 1}); each of time and the axes needs its own column")
        seen[key] = i


def _as_float(x: object) -> float:
    """``x`` as a float when it is a real number (not a bool), else NaN (fails every bound)."""
    if isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool):
        return float(x)
    return math.nan


def input_file(path: str | os.PathLike[str], what: str = "file") -> Path:
    """``path`` as a Path, an :class:`~strapdown.InputError` unless it is an existing
    regular file (a directory or a missing file is the user's mistake)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a directory; expected a {what}")
    if not path.is_file():
        raise InputError(f"{path}: no such {what}")
    return path


def read_imu(path: str | os.PathLike[str], *, kind: InputKind | None, units: GyroUnit | None,
             columns: Sequence[str] | None = None,
             sample_rate_hz: float | None = None, gap_tolerance: float = 1.5,
             on_gap: GapPolicy = "report", saturation: float | None = None,
             unit_check: UnitAction = "warn", delimiter: str | None = None,
             timing_mode: TimingMode = "auto", jitter_tolerance: float = JITTER_TOLERANCE,
             held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error") -> ImuLog:
    """Read and validate a gyro log (see the module docstring).

    Parameters
    ----------
    kind : {"rate", "increment"} or None
        None: from a known format, or from the header's unit (``gx[rad/s]``: rates,
        ``gx[rad]``: increments); an error when neither says.
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
    delimiter : str, optional
        A CSV's delimiter (:data:`DELIMITERS`); default: detected from the header row.
    timing_mode : {"auto", "nominal", "stamps", "resample"}
        How the stamps are taken (:data:`strapdown.io.timing.TimingMode`): the sensor's
        clock is fitted to them (:func:`strapdown.io.timing.reconstruct`) and recorded in
        :attr:`ImuLog.timing`; with the samples on that clock a gap is whole missing
        periods, otherwise an interval over ``gap_tolerance`` periods.
    jitter_tolerance : float
        Largest stamp residual (periods, 99th percentile) that is noise on the clock.
    held : {"auto", "collapse", "keep"}
        Held samples (rows repeating the previous sample): collapsed when the clock
        confirms them, always, or never (:func:`strapdown.io.timing.clean_rows`).
    duplicates : {"error", "first", "last"}
        A duplicated stamp with different values: an error naming the rows, or keep one.

    Raises
    ------
    InputError
        For anything wrong with the file or the options, naming the file and what was
        expected (:mod:`strapdown.io.containers` for the binary formats). A sample turning
        the body by more than π (:func:`check_motion`) or time steps under
        :data:`MIN_PERIOD` are errors too.
    """
    check_read_options(kind=kind, units=units, gap_tolerance=gap_tolerance, on_gap=on_gap,
                       saturation=saturation, sample_rate_hz=sample_rate_hz, columns=columns,
                       kind_optional=True)
    path = input_file(path, "log file")
    src = _load(path, None if columns is None else list(columns), sample_rate_hz, delimiter)
    kind = _log_kind(path, src, kind)
    unit = _declared_units(path, src, kind, units)
    raw, g = src.t, src.gyro
    if raw.ndim != 1 or g.ndim != 2 or g.shape[1] != 3 or raw.shape[0] != g.shape[0]:
        raise InputError(f"{path}: expected n times of shape (n,) and gyro values of shape "
                         f"(n, 3), got {raw.shape} and {g.shape}")
    if raw.size < 2:
        raise InputError(f"{path}: {raw.size} samples; at least 2 are needed")
    check_finite_rows(path, [(None, [raw, g])])
    stamped = src.what != "BROAD's imu_gyr"  # BROAD's times come from its rate
    nominal = 1.0 / sample_rate_hz if sample_rate_hz is not None and stamped else None
    timing, t, t_rel = read_time_base(path, raw, src.scale, g, period=nominal,
                                      timing_mode=timing_mode, held=held,
                                      duplicates=duplicates,
                                      jitter_tolerance=jitter_tolerance, fit=stamped)
    keep = timing.cleaning.keep
    if keep.size < raw.size:
        g = g[keep]
    d = np.diff(t_rel)
    check_steps(path, d, t_rel)
    h = timing.sample_period(t_rel)
    unit_h = nominal or h
    gaps = timing.gap_rows(t_rel, unit_h, gap_tolerance)
    if gaps and on_gap == "error":
        i = int(np.searchsorted(timing.rows, gaps[0]))
        raise InputError(f"{path}: gap of {d[i - 1]:.6g} s ({d[i - 1] / unit_h:.1f} sample "
                         f"intervals) before data row {gaps[0]}")
    saturated = []
    if saturation is not None:
        saturated = [int(timing.rows[i]) for i in
                     np.flatnonzero(np.any(np.abs(g) >= saturation, axis=1))]
    scale = _DEG if unit.startswith("deg") else 1.0
    g = g * scale
    with np.errstate(over="ignore"):  # an overflowing rate is refused by check_motion
        rate = g if kind == "rate" else g / h
    warn_implausible_rate(path, rate, unit, action=unit_check)
    check_motion(path, g, kind, unit_h)
    return ImuLog(np.asarray(t, float), np.ascontiguousarray(g), kind, h, gaps, saturated,
                  unit, nominal, timing)


#: Stamps whose first value exceeds this (s, about 11.6 days) are epoch-like: the samples'
#: times are formed as origin + exact relative time (float64 holds 1.7e9 s to 2.4e-7 s).
EPOCH_LIKE_S = 1e6


def check_stamp_steps(path: str | os.PathLike[str], raw: NDArray[np.float64],
                      scale: float) -> None:
    """Raise on a time step that overflows or is positive but under :data:`MIN_PERIOD`
    (duplicated and decreasing stamps are judged later, with the rows' values)."""
    with np.errstate(over="ignore", invalid="ignore"):
        d = np.diff(raw) * scale
    bad = ~np.isfinite(d) | ((d > 0) & (d < MIN_PERIOD))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{path}: time step of {float(d[i])!r} s before data row {i + 2}; "
                         f"steps must be finite and at least {MIN_PERIOD:g} s (check the time "
                         "unit)")


def read_time_base(path: str | os.PathLike[str], raw: NDArray[np.float64], scale: float,
                   values: NDArray[np.float64], *, period: float | None,
                   timing_mode: TimingMode, held: HeldPolicy, duplicates: DuplicatePolicy,
                   jitter_tolerance: float, fit: bool = True
                   ) -> tuple[Timing, NDArray[np.float64], NDArray[np.float64]]:
    """A recording's time base from its stamps ``raw`` (in units of ``scale`` seconds,
    finite) and sensor columns ``values``: ``(timing, t, t_rel)``, the times of the samples
    kept (:func:`strapdown.io.timing.reconstruct`) in seconds as read — or, for epoch-like
    stamps (:data:`EPOCH_LIKE_S`), as the origin plus the exact relative times, since only
    those keep the intervals — and relative to the first stamp.

    Raises on a step that overflows or is positive but under :data:`MIN_PERIOD`, on what
    :func:`~strapdown.io.timing.reconstruct` refuses, and when fewer than 2 distinct samples
    remain.
    """
    check_stamp_steps(path, raw, scale)
    base = relative_times(raw, scale)
    timing = reconstruct(path, base, values, period=period, mode=timing_mode, held=held,
                         duplicates=duplicates, jitter_tolerance=jitter_tolerance, fit=fit)
    keep = timing.cleaning.keep
    if keep.size < 2:
        raise InputError(f"{path}: {keep.size} distinct samples; at least 2 are needed")
    t_rel = base.t[keep]
    t = base.origin + t_rel if abs(base.origin) >= EPOCH_LIKE_S else raw[keep] * scale
    return timing, t, t_rel


def _log_kind(path: Path, src: _Source, kind: InputKind | None) -> InputKind:
    """The kind given, else the one a known format holds or the header's unit says
    (``gx[rad/s]``: rates, ``gx[rad]``: increments); else an error asking for it."""
    if kind is not None:
        return kind
    if src.kind is not None:
        return src.kind
    if src.units in RATE_UNITS:
        return "rate"
    if src.units in INCREMENT_UNITS:
        return "increment"
    raise InputError(f"{path}: does the log hold rates or increments? Its header does not say "
                     "(a unit such as gx[rad/s] or gx[rad] would); pass --rates or --increments")


def log_kind(path: str | os.PathLike[str], columns: Sequence[str] | None = None, *,
             delimiter: str | None = None) -> InputKind | None:
    """What a CSV log's header says it holds (rates for ``gx[rad/s]``, increments for
    ``gx[rad]``), None when it does not say or the file is not a CSV."""
    path = Path(path)
    if path.suffix.lower() not in (".csv", ".txt", ".tsv") or not path.is_file():
        return None
    try:
        if columns is None:
            columns, _ = default_columns(path, [("gyro", GYRO_COLUMNS)], delimiter=delimiter)
        _, units = csv_header(path, delimiter=delimiter)
    except InputError:
        return None
    names, _ = csv_header(path, delimiter=delimiter)
    found = set()
    for c in columns[1:]:
        i = column_index(names, c)
        if i is not None and names[i] in units:
            found.add(units[names[i]])
    if found and found <= set(RATE_UNITS):
        return "rate"
    if found and found <= set(INCREMENT_UNITS):
        return "increment"
    return None


def check_finite_rows(path: str | os.PathLike[str],
                      groups: Iterable[tuple[str | None, Iterable[ArrayLike]]]) -> None:
    """Raise on the first non-finite row of each group (see :func:`check_rows`)."""
    for label, arrays in groups:
        bad: NDArray[np.bool_] | None = None
        for a in arrays:
            a = np.asarray(a)
            b = ~np.isfinite(a) if a.ndim == 1 else ~np.all(np.isfinite(a), axis=1)
            bad = b if bad is None else bad | b
        if bad is not None and np.any(bad):
            where = "" if label is None else f" the {label} at"
            raise InputError(f"{path}: NaN or infinity in{where} data row "
                             f"{int(np.argmax(bad)) + 1}")


def write_attitude(path: str | os.PathLike[str], t: ArrayLike, q: NDArray[np.float64], *,
                   extra: Mapping[str, ArrayLike] | None = None,
                   time_origin: str | None = None) -> Path:
    """Write ``t, qw, qx, qy, qz`` (+ extra columns) atomically as CSV or ``.npz``.

    ``time_origin``: the first stamp exactly (:attr:`strapdown.io.timing.TimeBase.origin_text`);
    for epoch-like stamps (beyond :data:`EPOCH_LIKE_S`) a CSV's times are then written as
    that decimal plus the relative time to the microsecond (``1733119200.123``, not the
    binary ``1733119200.1230001``). A non-finite value anywhere is an
    :class:`~strapdown.InputError` and nothing is written.
    """
    path = Path(path)
    # Any: np.savez's column keywords share its signature with allow_pickle: bool
    cols: dict[str, Any] = {"t": np.asarray(t), "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2],
                            "qz": q[:, 3]}
    cols.update(extra or {})
    for name, col in cols.items():
        bad = ~np.isfinite(np.asarray(col, float))
        if np.any(bad):
            i = int(np.argmax(bad.reshape(bad.shape[0], -1).any(axis=1)))
            raise InputError(f"{path}: {name} is NaN or infinite from output row {i + 1}; "
                             "nothing written")
    if path.suffix.lower() == ".npz":
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, **cols)
        return path
    if path.suffix.lower() != ".csv":
        raise InputError(f"{path}: output must be .csv or .npz")
    names = list(cols)
    table = np.column_stack([np.asarray(cols[k], float) for k in names])
    epoch = time_origin is not None and abs(float(time_origin)) >= EPOCH_LIKE_S
    with atomic_path(path) as tmp:
        if not epoch:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(",".join(names) + "\n")
                write_csv_rows(f, table)
            return path
        assert time_origin is not None
        times = format_times(time_origin, table[:, 0] - float(time_origin), decimals=6)
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(",".join(names) + "\n")
            for text, row in zip(times, table[:, 1:].tolist(), strict=True):
                f.write(text + "," + ",".join(repr(v) for v in row) + "\n")
    return path
