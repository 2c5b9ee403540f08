"""``strapdown run``: attitude from a user's gyro log, streamed, written atomically with its
metadata.

Increment logs run through :class:`strapdown.algorithms.streaming.RotvecStream` in chunks;
rate logs run on a uniform grid (jittered stamps: the nominal period, or resampled;
:func:`strapdown.algorithms.rate.check_rate_record`), a ``.npy`` rate log with uniform
stamps through :class:`~strapdown.algorithms.streaming.RateStream` in chunks (bit-identical
to the whole-record run; any other rate log is read whole). ``.npy`` logs are read chunk
by chunk from the file, so a log larger than memory streams in O(1) memory to a CSV
(``.npz`` output is assembled in memory). Output: ``t, qw, qx, qy, qz`` plus yaw/pitch/roll
(deg, z-y-x) or cone angles (deg), one row per attitude update (rate-three: every 3
samples, rk4: every 2), as CSV or ``.npz``, and ``OUT.meta.json`` beside it: input,
algorithm, initial attitude, samples, outputs, update and sample period, jitter, gaps,
saturation, peak rate and total rotation, warnings, version — written so that a failure
never leaves one without the other (:mod:`strapdown.apps._logs`).

Frame: ``q_n_b`` takes body vectors into frame n, the frame the initial attitude is given
in (``q0``; identity by default, so that n is the body frame at the first sample). The
peak rate is the largest ``|ω|`` of the input (increments: ``|θ|`` over the sample period);
the total rotation is the sum of the rotation angles between successive attitude outputs
(``Σ 2·atan2(|v|, |w|)`` of ``q_k⁻¹ ⊗ q_{k+1}``, a lower bound of ``∫|ω| dt``) — a log in
rad/s declared as deg/s shows as an implausibly slow, small motion. Nothing is written when
the input fails validation, when magnitudes suggest another unit than declared (unless
accepted) or when the result is not finite, and the input file is never overwritten.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray
from tqdm import tqdm

from strapdown._core.errors import InputError, shown
from strapdown._core.kinds import InputKind
from strapdown.algorithms.family import StructureName
from strapdown.algorithms.rate import UNIFORM_TOLERANCE
from strapdown.algorithms.rotvec import Rotvec
from strapdown.algorithms.spec import (
    AlgorithmName,
    AlgorithmSpec,
    CoefficientName,
    algorithms_taking,
)
from strapdown.algorithms.streaming import RateStream, RotvecStream
from strapdown.algorithms.structures import increment_structure
from strapdown.apps._logs import check_finite, output_with_sidecar, rate_records, unit_action
from strapdown.io import read_imu
from strapdown.io.files import write_csv_rows
from strapdown.io.readers import (
    EPOCH_LIKE_S,
    MAX_PERIOD,
    MAX_SAMPLE_ANGLE,
    MIN_PERIOD,
    RATE_PLAUSIBLE_MAX,
    GapPolicy,
    GyroUnit,
    check_distinct_columns,
    check_motion,
    check_read_options,
    check_steps,
    input_file,
    log_kind,
    npy_log,
    warn_implausible_rate,
)
from strapdown.io.timing import (
    JITTER_TOLERANCE,
    DuplicatePolicy,
    HeldPolicy,
    TimingMode,
    uniform_timing_record,
)
from strapdown.rotation.cone_angles import cone_angles_from_quat
from strapdown.rotation.dcm import dcm_from_quat, quat_from_dcm
from strapdown.rotation.euler import dcm_from_euler_zyx, euler_zyx_from_dcm

__all__ = ["ANGLES", "DEFAULT_ALGORITHM", "MAX_ANGLE_DEG", "RUN_GAP_POLICIES", "AngleOutput",
           "RunGapPolicy", "initial_attitude", "run_log"]

CHUNK = 1 << 16

#: Angles written beside the quaternion: yaw/pitch/roll (z-y-x), cone angles, or none.
AngleOutput = Literal["ypr", "cone", "none"]
ANGLES: tuple[AngleOutput, ...] = get_args(AngleOutput)
#: What ``run`` does at a gap: the reader's policies, or ``split`` (each gap-free segment
#: runs on its own).
RunGapPolicy = Literal[GapPolicy, "split"]
RUN_GAP_POLICIES: tuple[RunGapPolicy, ...] = get_args(RunGapPolicy)
#: The algorithm a log runs without --algorithm, by what it holds.
DEFAULT_ALGORITHM: dict[InputKind, AlgorithmName] = {"rate": "rate-three", "increment": "rotvec"}
#: Largest initial Euler angle magnitude (deg), as ``nav --init-attitude``.
MAX_ANGLE_DEG = 360.0
_DEG = math.pi / 180.0
#: Outputs per block of the total-rotation sum (a fixed blocking: the same sum however the
#: outputs arrive).
_SUM_BLOCK = 4096
#: The ``read`` options the streamed rate route reproduces; any other entry set to a value
#: other than None sends the log through :func:`strapdown.io.read_imu` (whole).
_STREAMED_READ = frozenset({"kind", "units", "columns", "sample_rate_hz", "gap_tolerance",
                            "on_gap", "saturation", "unit_check", "delimiter"})


def _angles(q: NDArray[np.float64], kind: AngleOutput) -> dict[str, NDArray[np.float64]]:
    if kind == "ypr":
        y, p, r = euler_zyx_from_dcm(dcm_from_quat(q))
        return {"yaw_deg": np.degrees(y), "pitch_deg": np.degrees(p), "roll_deg": np.degrees(r)}
    if kind == "cone":
        d1, d2, d3 = cone_angles_from_quat(q)
        return {"delta1_deg": np.degrees(d1), "delta2_deg": np.degrees(d2),
                "delta3_deg": np.degrees(d3)}
    return {}


def _rows(t: NDArray[np.float64], q: NDArray[np.float64],
          angles: AngleOutput) -> NDArray[np.float64]:
    cols = [t, q[:, 0], q[:, 1], q[:, 2], q[:, 3], *_angles(q, angles).values()]
    return np.column_stack(cols)


def _header(angles: AngleOutput) -> str:
    names = ["t", "qw", "qx", "qy", "qz", *_angles(np.array([[1.0, 0, 0, 0]]), angles)]
    return ",".join(names)


def initial_attitude(values: Sequence[float] | None) -> NDArray[np.float64] | None:
    """``q_n_b`` at the first sample from the command line's ``--init-attitude``.

    Three numbers are yaw, pitch, roll (deg, z-y-x, as ``nav --init-attitude``), four a
    quaternion ``w x y z`` (Hamilton, scalar first; normalised). None: identity.

    Raises
    ------
    InputError
        Another count, a non-finite value, an angle beyond ±:data:`MAX_ANGLE_DEG` or a
        zero quaternion.
    """
    if values is None:
        return None
    v = np.asarray(values, dtype=np.float64).ravel()
    if v.size not in (3, 4):
        raise InputError(f"--init-attitude takes 3 numbers (yaw pitch roll, deg) or 4 (a "
                         f"quaternion w x y z), got {v.size}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"--init-attitude must be finite, got {v.tolist()}")
    if v.size == 3:
        if not np.all(np.abs(v) <= MAX_ANGLE_DEG):
            raise InputError(f"--init-attitude angles (YAW PITCH ROLL) must lie within "
                             f"±{MAX_ANGLE_DEG:g}°, got {v.tolist()}")
        return quat_from_dcm(dcm_from_euler_zyx(*np.radians(v)))
    return _unit_quaternion(v)


def _unit_quaternion(q0: ArrayLike) -> NDArray[np.float64]:
    """``q0`` as a finite unit quaternion (4,); an InputError otherwise."""
    try:
        q = np.asarray(q0, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"the initial attitude q0 must be 4 numbers, got {shown(q0, 40)}"
                         ) from None
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise InputError(f"the initial attitude q0 must be 4 finite numbers (w x y z), got "
                         f"{shown(q0, 60)}")
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(q))
    if not 0 < norm < math.inf:
        raise InputError(f"the initial attitude quaternion must have a finite non-zero norm, "
                         f"got {q.tolist()}")
    return q / norm


@dataclass
class _Motion:
    """What the log did, for the summary: the peak rate (rad/s) and the total rotation (rad),
    the sum of the rotation angles between successive attitude outputs.

    The sum runs over fixed blocks of :data:`_SUM_BLOCK` angles, so the streamed and the
    whole-record routes give the same value to the last bit however the outputs arrive.
    """

    peak: float = 0.0
    total: float = 0.0
    _last: NDArray[np.float64] | None = None
    _pending: NDArray[np.float64] = field(default_factory=lambda: np.empty(0))

    def rates(self, w: NDArray[np.float64]) -> None:
        """Take rate (rad/s) samples ``(m, 3)`` into the peak."""
        if w.shape[0]:
            with np.errstate(over="ignore"):
                self.peak = max(self.peak, float(np.max(np.linalg.norm(w, axis=1))))

    def attitudes(self, q: NDArray[np.float64]) -> None:
        """Take the next attitude outputs ``(m, 4)`` into the total rotation."""
        if not q.shape[0]:
            return
        if self._last is None:
            a, b = q[:-1], q[1:]
        else:
            a, b = np.concatenate([self._last[None], q[:-1]]), q
        self._last = q[-1].copy()
        # q_a⁻¹ ⊗ q_b: scalar a·b, vector a0 b_v − b0 a_v − a_v × b_v
        w = np.sum(a * b, axis=1)
        v = a[:, :1] * b[:, 1:] - b[:, :1] * a[:, 1:] - np.cross(a[:, 1:], b[:, 1:])
        ang = 2.0 * np.arctan2(np.linalg.norm(v, axis=1), np.abs(w))
        pend = np.concatenate([self._pending, ang])
        full = pend.size - pend.size % _SUM_BLOCK
        for i in range(0, full, _SUM_BLOCK):
            self.total += float(np.add.reduce(pend[i:i + _SUM_BLOCK]))
        self._pending = pend[full:]

    def to_dict(self) -> dict[str, float]:
        total = self.total + float(np.add.reduce(self._pending))
        return {"peak_rate_deg_s": math.degrees(self.peak),
                "total_rotation_deg": math.degrees(total)}


def _npy_blocks(arr: NDArray[Any], bounds: Sequence[tuple[int, int]] | None = None
                ) -> Iterator[tuple[int, NDArray[np.float64]]]:
    """``(first row, rows as float64)`` of an ``(n, 4)`` ``.npy`` log for each ``(start,
    stop)`` of ``bounds`` (default: blocks of :data:`CHUNK` rows), read from the file rather
    than through its memory map: a mapping's pages stay resident once touched, so reading a
    log through it grows the process by the whole file."""
    n = arr.shape[0]
    if bounds is None:
        bounds = [(s, min(s + CHUNK, n)) for s in range(0, n, CHUNK)]
    filename = getattr(arr, "filename", None)
    if filename is None:  # not a memory map (an empty array): rows in memory
        for s, e in bounds:
            yield s, np.array(arr[s:e], dtype=np.float64)
        return
    item, offset = arr.dtype.itemsize, int(getattr(arr, "offset", 0))
    fortran = arr.flags.f_contiguous and not arr.flags.c_contiguous
    with open(filename, "rb") as f:
        for s, e in bounds:
            m = e - s
            if fortran:  # column by column
                block = np.empty((m, 4), dtype=arr.dtype)
                for j in range(4):
                    f.seek(offset + (j * n + s) * item)
                    block[:, j] = np.fromfile(f, dtype=arr.dtype, count=m)
            else:
                f.seek(offset + s * 4 * item)
                block = np.fromfile(f, dtype=arr.dtype, count=4 * m).reshape(m, 4)
            yield s, np.asarray(block, dtype=np.float64)


def _npy_chunks(path: Path, arr: NDArray[Any], units: GyroUnit, read: dict[str, Any],
                gaps: list[int], saturated: list[int]
                ) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Validated (t, increments) chunks of an (n, 4) .npy log, read chunk by chunk
    (:func:`_npy_blocks`).

    The checks of :func:`strapdown.io.read_imu`, chunk by chunk: finite rows, time steps
    (:func:`~strapdown.io.readers.check_steps`), no sample over π
    (:func:`~strapdown.io.readers.check_motion`). Gaps (intervals over ``gap_tolerance``
    times the nominal period, or the first interval — a streamed log has no median) and
    saturated rows are appended to ``gaps`` and ``saturated`` as the chunks go by;
    ``on_gap="error"`` raises at the first gap. The unit plausibility check
    (``read["unit_check"]``) judges the first chunk.
    """
    scale = np.pi / 180.0 if units == "deg" else 1.0
    last = None
    h = None if read["sample_rate_hz"] is None else 1.0 / read["sample_rate_hz"]
    for s, c in _npy_blocks(arr):
        bad = ~np.all(np.isfinite(c), axis=1)
        if np.any(bad):
            raise InputError(f"{path}: NaN or infinity in data row {s + int(np.argmax(bad)) + 1}")
        t = c[:, 0] if last is None else np.concatenate([[last], c[:, 0]])
        with np.errstate(over="ignore", invalid="ignore"):  # an overflowing step is reported
            d = np.diff(t)
        first = 1 if last is None else 0  # data row (1-based) of t[0] is s + first
        check_steps(path, d, t, s + first)
        if h is None and d.size:
            h = float(d[0])
        if h is not None:
            if last is None:
                with np.errstate(over="ignore"):  # refused by check_motion below
                    rate = c[:, 1:] * (scale / h)
                warn_implausible_rate(path, rate, units, action=read["unit_check"])
            check_motion(path, c[:, 1:] * scale, "increment", h, s + 1)
            for i in np.flatnonzero(d > read["gap_tolerance"] * h):
                row = s + int(i) + first + 1
                if read["on_gap"] == "error":
                    raise InputError(f"{path}: gap of {d[i]:.6g} s ({d[i] / h:.1f} sample "
                                     f"intervals) before data row {row}")
                gaps.append(row)
        if read["saturation"] is not None:
            hit = np.flatnonzero(np.any(np.abs(c[:, 1:]) >= read["saturation"], axis=1))
            saturated.extend(int(s + i + 1) for i in hit)
        last = c[-1, 0]
        yield c[:, 0], c[:, 1:] * scale


def _pairwise(lo: int, m: int, cap: int, leaves: list[tuple[int, int]]) -> Any:
    """The tree of numpy's pairwise summation of ``m`` values from ``lo`` down to pieces of
    at most ``cap`` (each summed by one ``np.add.reduce``, which sums a piece of that
    length in the same order): the leaves, left to right, are appended to ``leaves``."""
    if m <= cap:
        leaves.append((lo, lo + m))
        return len(leaves) - 1
    half = m // 2
    half -= half % 8
    return (_pairwise(lo, half, cap, leaves), _pairwise(lo + half, m - half, cap, leaves))


def _pairwise_sum(tree: Any, sums: list[np.float64]) -> np.float64:
    """The pairwise sum from the leaves' sums (:func:`_pairwise`)."""
    if isinstance(tree, int):
        return sums[tree]
    return _pairwise_sum(tree[0], sums) + _pairwise_sum(tree[1], sums)


@dataclass
class _RateScan:
    """A ``.npy`` rate log found to stream: what the run needs from the checking pass."""

    arr: NDArray[Any]
    td: float  # the whole-record run's period, (t[-1] − t[0]) / (n − 1)
    t0: float
    units: GyroUnit
    scale: float
    saturated: list[int]
    resid_sum: np.float64  # Σ (t_k − t_0 − k·td) in numpy's pairwise order (for the jitter)
    motion: _Motion


def _rate_scan(imu: Path, read: dict[str, Any], spec: AlgorithmSpec,
               resample: bool) -> _RateScan | None:
    """Whether a rate log streams: a ``.npy`` log whose stamps are uniform and that passes
    every check of :func:`strapdown.io.read_imu` and
    :func:`strapdown.algorithms.rate.check_rate_record` beyond doubt, in one pass over
    the file in blocks; None sends the log through the whole-record route, which then
    decides (and words any refusal) as it always has.

    Streamed: no ``--sample-rate-hz`` or ``--resample``, units declared, finite rows, time
    steps of at least ``MIN_PERIOD``, every interval within ``UNIFORM_TOLERANCE`` of
    ``(t[-1] − t[0]) / (n − 1)`` (the test of ``check_rate_record``; such stamps have no gap
    and lie on their own clock), stamps that are not epoch-like, no sample turning by
    near π, 99th-percentile rates certainly plausible for the declared unit, and repeated
    rows (held-sample candidates) in at most a tenth of the log, too few for the reader to
    collapse them. Bounds that hold for every interval hold for the reader's period.
    """
    if (imu.suffix.lower() != ".npy" or resample or read["sample_rate_hz"] is not None
            or read["units"] is None or read["kind"] != "rate"
            or any(v is not None for k, v in read.items() if k not in _STREAMED_READ)):
        return None
    try:
        arr = npy_log(imu)
    except InputError:
        return None
    n = arr.shape[0]
    if n < max(3, spec.min_samples):
        return None
    (_, first), (_, last) = _npy_blocks(arr, [(0, 1), (n - 1, n)])
    t0, tl = float(first[0, 0]), float(last[0, 0])
    if not (math.isfinite(t0) and math.isfinite(tl)) or abs(t0) >= EPOCH_LIKE_S:
        return None
    td = (tl - t0) / (n - 1)
    if not MIN_PERIOD <= td <= MAX_PERIOD:
        return None
    units: GyroUnit = read["units"]
    scale = _DEG if units.startswith("deg") else 1.0
    leaves: list[tuple[int, int]] = []
    tree = _pairwise(0, n, CHUNK, leaves)
    sums: list[np.float64] = []
    saturated: list[int] = []
    motion = _Motion()
    dmin, dmax = math.inf, -math.inf
    held = big = small = zero = 0
    prev: NDArray[np.float64] | None = None
    with np.errstate(over="ignore", invalid="ignore"):
        for lo, c in _npy_blocks(arr, leaves):
            if not np.all(np.isfinite(c)):
                return None
            rows = c if prev is None else np.concatenate([prev[None], c])
            d = np.diff(rows[:, 0])
            if d.size:
                if not np.all(d >= MIN_PERIOD):
                    return None
                dmin, dmax = min(dmin, float(d.min())), max(dmax, float(d.max()))
            held += int(np.count_nonzero(np.all(rows[1:, 1:] == rows[:-1, 1:], axis=1)))
            raw = c[:, 1:]
            if read["saturation"] is not None:
                hit = np.flatnonzero(np.any(np.abs(raw) >= read["saturation"], axis=1))
                saturated.extend(lo + int(i) + 1 for i in hit)
            g = raw * scale
            norm = np.linalg.norm(g, axis=1)
            big += int(np.count_nonzero(norm >= RATE_PLAUSIBLE_MAX))
            small += int(np.count_nonzero(norm <= 1e-3 * _DEG))
            zero += int(np.count_nonzero(norm == 0))
            motion.rates(g)
            resid = c[:, 0] - t0
            resid -= np.arange(lo, lo + c.shape[0], dtype=np.float64) * td
            sums.append(np.add.reduce(resid))
            prev = c[-1]
    tol = UNIFORM_TOLERANCE * td
    k = math.floor(0.99 * (n - 1))  # the 99th percentile's order statistic, ± 1
    plausible = (small <= k - 2 or zero >= k + 3) if scale != 1.0 else big <= n - k - 3
    margin = 1.0 + 1e-6
    if not (dmax - td <= tol and td - dmin <= tol and dmin >= MIN_PERIOD
            and dmax * margin <= MAX_PERIOD and dmax * margin <= read["gap_tolerance"] * dmin
            and motion.peak * dmax * margin <= MAX_SAMPLE_ANGLE and held <= 0.1 * n
            and plausible):
        return None
    return _RateScan(arr, td, t0, units, scale, saturated, _pairwise_sum(tree, sums), motion)


def _run_rates_streamed(imu: Path, tmp: Path, scan: _RateScan, spec: AlgorithmSpec,
                        angles: AngleOutput, q0: NDArray[np.float64] | None, split: bool,
                        progress: bool) -> dict[str, Any]:
    """Stream a checked ``.npy`` rate log (:func:`_rate_scan`) through :class:`RateStream`
    into ``tmp``, chunk by chunk; the jitter measured as
    :attr:`strapdown.algorithms.rate.RateRecord.jitter` measures it."""
    from strapdown.apps._logs import JitterSummary

    n = scan.arr.shape[0]
    stream = RateStream(spec, td=scan.td, t0=scan.t0, q0=q0)
    names = _header(angles).split(",") + (["segment"] if split else [])
    mean = scan.resid_sum / n  # as ndarray.mean: the pairwise sum over the count
    dev = 0.0
    with tqdm(total=n, disable=not progress, unit="sample", unit_scale=True,
              file=sys.stderr) as bar, _Output(tmp, names) as out:
        for s, c in _npy_blocks(scan.arr):
            resid = c[:, 0] - scan.t0
            resid -= np.arange(s, s + c.shape[0], dtype=np.float64) * scan.td
            resid -= mean
            dev = max(dev, float(np.max(np.abs(resid))))
            res = stream.feed(c[:, 1:] * scan.scale)
            bar.update(c.shape[0])
            if res.q.shape[0]:
                check_finite(f"{imu}: the {spec} attitude", res.t, res.q)
                rows = _rows(res.t, res.q, angles)
                if split:
                    rows = np.column_stack([rows, np.zeros(rows.shape[0])])
                out.write(rows)
                scan.motion.attitudes(res.q)
    base = JitterSummary(scan.td, float(np.float64(dev) / scan.td), False, 1)
    timing = uniform_timing_record(scan.td, repr(float(scan.t0)))
    return {"samples": n, "outputs": out.rows, "gaps": [], "saturated": scan.saturated,
            "units": scan.units, "columns": names, **base.to_dict(), "timing": timing,
            "time_base": timing["summary"], "motion": scan.motion.to_dict(), "streamed": True}


class _Output:
    """The attitude table written as it comes: CSV rows appended (``%.17g``, as
    :func:`strapdown.io.write_attitude`), ``.npz`` columns gathered and written at the end."""

    def __init__(self, path: Path, names: list[str]) -> None:
        self.path, self.names = path, names
        self.csv = path.suffix.lower() == ".csv"
        self.rows = 0
        self._parts: list[NDArray[np.float64]] = []
        self._f = open(path, "w", encoding="utf-8")  # closed by __exit__
        if self.csv:
            self._f.write(",".join(names) + "\n")

    def __enter__(self) -> _Output:
        return self

    def write(self, rows: NDArray[np.float64]) -> None:
        self.rows += rows.shape[0]
        if self.csv:
            write_csv_rows(self._f, rows)
        else:
            self._parts.append(rows)

    def __exit__(self, *exc: object) -> None:
        self._f.close()
        if self.csv or exc[0] is not None:
            return
        table = np.concatenate(self._parts) if self._parts else np.empty((0, len(self.names)))
        # Any: np.savez's column keywords share its signature with allow_pickle: bool
        columns: dict[str, Any] = {k: table[:, i] for i, k in enumerate(self.names)}
        with open(self.path, "wb") as f:
            np.savez(f, **columns)


def _spec(kind: InputKind, algorithm: AlgorithmName | None, structure: StructureName,
          subsamples: int | None, coefficients: CoefficientName | None) -> AlgorithmSpec:
    """The algorithm a log runs: by default rate-three for rates, rotvec for increments;
    options that do not apply to it are errors."""
    if kind not in ("rate", "increment"):
        raise InputError(f"kind must be 'rate' or 'increment', got {kind!r}")
    name: AlgorithmName = algorithm or DEFAULT_ALGORITHM[kind]
    spec = AlgorithmSpec(name, subsamples=3 if subsamples is None else subsamples,
                         coefficients=coefficients, structure=structure)
    if subsamples is not None and "subsamples" not in spec.family.options:
        raise InputError(f"--subsamples does not apply to {name} (only rotvec has subsamples "
                         "per update)")
    if spec.family.stepped:
        raise InputError(f"{name} runs on reference motions only (its input is the Krylov "
                         "model's increments at thirds or halves of a step)")
    if spec.input_kind == "increment" and kind != "increment":
        raise InputError(f"{name} takes increments (--increments); for rate logs use "
                         f"{', '.join(algorithms_taking('rate'))}")
    if spec.input_kind == "rate" and kind != "rate":
        raise InputError(f"{name} takes rate samples (--rates)")
    if not isinstance(spec.family, Rotvec) and spec.input_kind == "increment":
        raise InputError(f"{name} does not run on a log; use rotvec or "
                         f"{', '.join(algorithms_taking('rate'))}")
    return spec


def run_log(imu: str | os.PathLike[str], out: str | os.PathLike[str], *,
            kind: InputKind | None,
            units: GyroUnit | None, algorithm: AlgorithmName | None = None,
            structure: StructureName = "conventional", subsamples: int | None = None,
            coefficients: CoefficientName | None = None, columns: Sequence[str] | None = None,
            sample_rate_hz: float | None = None, angles: AngleOutput = "ypr",
            q0: ArrayLike | None = None, on_gap: RunGapPolicy = "report",
            gap_tolerance: float = 1.5, saturation: float | None = None,
            progress: bool = False, resample: bool = False,
            accept_unit_warning: bool = False, delimiter: str | None = None,
            timing: TimingMode = "auto", jitter_tolerance: float = JITTER_TOLERANCE,
            held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error") -> dict[str, Any]:
    """Process a log and write ``out`` with its metadata sidecar ``OUT.meta.json``.

    Returns the metadata (input, algorithm, initial attitude, samples, outputs, update and
    sample period, jitter, gaps, saturated rows, peak rate and total rotation, warnings,
    version).

    Parameters
    ----------
    kind : {"rate", "increment"} or None
        None: what the CSV header's unit says (``gx[rad/s]``: rates, ``gx[rad]``:
        increments; :func:`strapdown.io.readers.log_kind`), else an error.
    algorithm : str, optional
        Default: ``rate-three`` for rates, ``rotvec`` for increments.
    subsamples : int, optional
        N of ``rotvec`` (default 3); an error for algorithms without subsamples.
    columns : four CSV column names, optional
        Default: found in the header (:func:`strapdown.io.read_imu`).
    sample_rate_hz : float, optional
        The sensor's rate: the nominal period of a rate log's (jittered) stamps, the
        increment interval of an increment log, the time base of a log without stamps.
    q0 : array_like (4,), optional
        ``q_n_b`` at the first sample (w, x, y, z; normalised): the attitude of the body in
        the frame n the output is in. Default: identity — n is then the body frame at the
        first sample. :func:`initial_attitude` makes it from yaw/pitch/roll.
    on_gap : {"report", "error", "split"}
        ``split`` runs each gap-free segment separately (each starting from the
        previous segment's last attitude, no increment or rate spanning the gap)
        and adds a ``segment`` column. A rate log with a gap needs ``split``.
    saturation : float, optional
        Sensor range in the declared unit; saturated rows are reported.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    resample : bool
        Rate logs: interpolate jittered rates onto the uniform grid
        (:func:`strapdown.algorithms.rate.check_rate_record`) instead of taking them to lie
        on it.
    accept_unit_warning : bool
        Run although magnitudes suggest another unit than declared (else an error).
    delimiter : str, optional
        A CSV's delimiter (default: detected from its header row).
    timing, jitter_tolerance, held, duplicates
        The time base (:func:`strapdown.io.read_imu`; :mod:`strapdown.io.timing`): by
        default the samples lie on the sensor's clock fitted to the stamps, held rows are
        collapsed when that clock confirms them, a duplicated stamp with different values
        is an error. ``resample=True`` is ``timing="resample"``.

    Raises
    ------
    InputError
        Anything wrong with the log or the options (every route, the streamed ``.npy``
        too, by :func:`strapdown.io.read_imu`'s rules), or a non-finite or empty result.
    """
    imu_path, out_path = Path(imu), Path(out)
    kind = _checked_paths(imu_path, out_path, kind, angles, on_gap, columns, delimiter)
    resample = resample or timing == "resample"
    spec = _spec(kind, algorithm, structure, subsamples, coefficients)
    q_init = None if q0 is None else _unit_quaternion(q0)
    check_read_options(kind=kind, units=units, gap_tolerance=gap_tolerance, on_gap="report",
                       saturation=saturation, sample_rate_hz=sample_rate_hz, columns=columns)
    input_file(imu_path, "log file")
    if resample and kind != "rate":
        raise InputError("--resample applies to rate logs (--rates) only")
    read = {"kind": kind, "units": units, "columns": columns, "sample_rate_hz": sample_rate_hz,
            "gap_tolerance": gap_tolerance, "on_gap": "error" if on_gap == "error" else "report",
            "saturation": saturation, "unit_check": unit_action(accept_unit_warning),
            "delimiter": delimiter,
            **_time_base_options(timing, jitter_tolerance, held, duplicates)}
    split = on_gap == "split"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with output_with_sidecar(out_path) as paired:
            if spec.input_kind == "rate":
                res = _run_rates(imu_path, paired.path, read, spec, angles, q_init, split,
                                 resample, progress)
            else:
                res = _run_increments(imu_path, paired.path, read, spec, angles, q_init, split,
                                      progress)
            paired.meta = _metadata(imu_path, spec, res, on_gap, saturation,
                                    [str(w.message) for w in caught], q_init)
    return paired.meta


def _checked_paths(imu_path: Path, out_path: Path, kind: InputKind | None, angles: str,
                   on_gap: str, columns: Sequence[str] | None, delimiter: str | None
                   ) -> InputKind:
    """:func:`run_log`'s first checks (output path and format, angles, gap policy, columns);
    the log's kind, from its header when not given."""
    if out_path.resolve() == imu_path.resolve():
        raise InputError("--out must not be the input file")
    if out_path.suffix.lower() not in (".csv", ".npz"):
        raise InputError(f"{out_path}: output must be .csv or .npz")
    if angles not in ANGLES:
        raise InputError(f"angles must be ypr, cone or none, got {shown(angles, 20)}")
    if on_gap not in RUN_GAP_POLICIES:
        raise InputError(f"on_gap must be report, error or split, got {shown(on_gap, 20)}")
    check_distinct_columns(columns)
    if kind is None:
        kind = log_kind(imu_path, columns, delimiter=delimiter)
        if kind is None:
            raise InputError(f"{imu_path}: does the log hold rates or increments? Its header "
                             "does not say (a unit such as gx[rad/s] or gx[rad] would); pass "
                             "--rates or --increments")
    return kind


def _time_base_options(timing: TimingMode, jitter_tolerance: float, held: HeldPolicy,
                       duplicates: DuplicatePolicy) -> dict[str, Any]:
    """The time base's read options that are not the defaults (a log read with the defaults
    may stream: see _rate_scan)."""
    out: dict[str, Any] = {}
    for key, value, default in (("timing_mode", "auto" if timing == "resample" else timing,
                                 "auto"), ("jitter_tolerance", jitter_tolerance,
                                           JITTER_TOLERANCE), ("held", held, "auto"),
                                ("duplicates", duplicates, "error")):
        if value != default:
            out[key] = value
    return out


def _metadata(imu: Path, spec: AlgorithmSpec, res: dict[str, Any], on_gap: str,
              saturation: float | None, caught: list[str],
              q0: NDArray[np.float64] | None) -> dict[str, Any]:
    """The sidecar's record of a run (also what :func:`run_log` returns)."""
    from strapdown import __version__

    q = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else q0
    ypr = np.degrees(np.concatenate(euler_zyx_from_dcm(dcm_from_quat(q[None]))))

    def rows(found: list[int]) -> dict[str, Any]:
        return {"count": len(found), "first_rows": found[:100]}

    h = res["sample_period_s"]
    return {
        "input": str(imu), "kind": spec.input_kind, "units": res["units"],
        "algorithm": str(spec), "quaternion": "q_n_b, Hamilton, scalar first",
        "frame": "n: the frame of the initial attitude (identity by default: the body frame "
                 "at the first sample)",
        "initial_attitude": {"q_n_b": q.tolist(), "ypr_deg": ypr.tolist(),
                             "given": q0 is not None},
        "columns": res["columns"], "samples": res["samples"], "outputs": res["outputs"],
        "update_period_s": spec.update_period(h) if h else None, "sample_period_s": h,
        "jitter_periods": res.get("jitter_periods"), "resampled": res.get("resampled", False),
        "time_base": res.get("time_base"), "timing": res.get("timing"), "on_gap": on_gap,
        "gaps": rows(res["gaps"]),
        "segments": res["segments"], "saturation": saturation,
        "saturated": rows(res["saturated"]), **res["motion"],
        "total_rotation": "sum of the rotation angles between successive attitude outputs",
        "streamed": res["streamed"], "warnings": caught, "version": __version__,
    }


def _increment_segments(imu: Path, read: dict[str, Any], split: bool):
    """``(total, gaps, saturated, units, h, segments)``: the log's chunks per segment."""
    if imu.suffix.lower() == ".npy" and not split:
        if read["units"] is None:
            raise InputError(f"{imu}: .npy logs carry no units; pass --units")
        arr = npy_log(imu)
        total = arr.shape[0]
        if total < 2:
            raise InputError(f"{imu}: {total} samples; at least 2 are needed")
        gaps: list[int] = []
        saturated: list[int] = []
        segments: list[Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]] = [
            _npy_chunks(imu, arr, read["units"], read, gaps, saturated)]
        h_given = None if read["sample_rate_hz"] is None else 1.0 / read["sample_rate_hz"]
        return total, gaps, saturated, read["units"], h_given, segments
    log = read_imu(imu, **read)
    cuts = log.segments() if split else [slice(0, log.t.size)]
    segments = [((log.t[c][s:s + CHUNK], log.data[c][s:s + CHUNK])
                 for s in range(0, c.stop - c.start, CHUNK)) for c in cuts]
    return log.t.size, log.gaps, log.saturated, log.units, log.nominal_period, segments


def _run_increments(imu: Path, tmp: Path, read: dict[str, Any], spec: AlgorithmSpec,
                    angles: AngleOutput, q0: NDArray[np.float64] | None, split: bool,
                    progress: bool) -> dict[str, Any]:
    """Stream the increments through :class:`RotvecStream` into ``tmp`` (see run_log)."""
    assert isinstance(spec.family, Rotvec)
    structure = increment_structure(spec.structure)
    cs = spec.family.coefficient_set(spec)
    total, gaps, saturated, units, h_given, segments = _increment_segments(imu, read, split)
    names = _header(angles).split(",") + (["segment"] if split else [])
    n_in = 0
    q_last = q0
    h = h_given
    motion = _Motion()
    peak_increment = 0.0
    with tqdm(total=total, disable=not progress, unit="sample", unit_scale=True,
              file=sys.stderr) as bar, _Output(tmp, names) as out:
        for k, chunks in enumerate(segments):
            stream = None
            for t, th in chunks:
                if stream is None:
                    h = h_given or (float(t[1] - t[0]) if t.size > 1 else h or 1.0)
                    stream = RotvecStream(structure, cs, h=h, t0=float(t[0]) - h, q0=q_last)
                res = stream.feed(th)
                n_in += th.shape[0]
                bar.update(th.shape[0])
                if th.shape[0]:
                    with np.errstate(over="ignore"):
                        peak_increment = max(peak_increment,
                                             float(np.max(np.linalg.norm(th, axis=1))))
                if res.q.shape[0]:
                    check_finite(f"{imu}: the {spec} attitude", res.t, res.q)
                    rows = _rows(res.t, res.q, angles)
                    if split:
                        rows = np.column_stack([rows, np.full(rows.shape[0], float(k))])
                    out.write(rows)
                    motion.attitudes(res.q)
                    q_last = res.q[-1]
    if n_in == 0:
        raise InputError(f"{imu}: no samples")
    if out.rows == 0:
        raise InputError(f"{imu}: {n_in} samples give no attitude update with {spec} (it "
                         f"needs at least {spec.min_samples}); nothing written")
    motion.peak = peak_increment / h if h else 0.0
    return {"samples": n_in, "outputs": out.rows, "gaps": gaps, "saturated": saturated,
            "units": units, "columns": names, "sample_period_s": h,
            "segments": len(segments), "motion": motion.to_dict(),
            "streamed": imu.suffix.lower() == ".npy" and not split}


def _run_rates(imu: Path, tmp: Path, read: dict[str, Any], spec: AlgorithmSpec,
               angles: AngleOutput, q0: NDArray[np.float64] | None, split: bool,
               resample: bool, progress: bool = False) -> dict[str, Any]:
    """Run the rate algorithm over each gap-free record and write ``tmp`` (see run_log).

    A ``.npy`` log that :func:`_rate_scan` finds uniform and valid streams
    (:func:`_run_rates_streamed`, the same result to the last bit); any other is read whole
    and the progress bar advances by each record's samples as its run completes (a rate
    algorithm runs a whole record in one compiled call)."""
    from strapdown.io import write_attitude

    scan = _rate_scan(imu, read, spec, resample)
    if scan is not None:
        return _run_rates_streamed(imu, tmp, scan, spec, angles, q0, split, progress)
    log = read_imu(imu, **read)
    recs, base = rate_records(imu, log, split=split, min_samples=spec.min_samples,
                              resample=resample)
    ts, qs, segs = [], [], []
    q_last = q0
    with tqdm(total=int(log.t.size), disable=not progress, unit="sample", unit_scale=True,
              file=sys.stderr) as bar:
        for k, rec in enumerate(recs):
            sol = spec.run_rates(rec.t, rec.omega, q0=q_last)
            ts.append(sol.t)
            qs.append(sol.q)
            segs.append(np.full(sol.t.size, float(k)))
            q_last = sol.q[-1]
            bar.update(int(rec.t.size))
    t, q = np.concatenate(ts), np.concatenate(qs)
    check_finite(f"{imu}: the {spec} attitude", t, q)
    extra = _angles(q, angles)
    if split:
        extra["segment"] = np.concatenate(segs)
    write_attitude(tmp, t, q, extra=extra,
                   time_origin=None if log.timing is None else log.timing.base.origin_text)
    motion = _Motion()
    motion.rates(log.data)
    for sq in qs:  # each record starts where the previous ended: its first row repeats that
        motion.attitudes(sq)
    return {"samples": int(log.t.size), "outputs": int(t.size), "gaps": log.gaps,
            "saturated": log.saturated, "units": log.units,
            "columns": ["t", "qw", "qx", "qy", "qz", *extra], **base.to_dict(),
            "time_base": base.describe(), "motion": motion.to_dict(), "streamed": False}
