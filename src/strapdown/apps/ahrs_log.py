"""``strapdown ahrs``: the AHRS filter over a recording, written atomically with its metadata.

Inputs: a BROAD ``.mat`` trial (gyro rad/s, accelerometer m/s², magnetometer µT, as
the format stores them), or a CSV with a header naming time, gyro, accelerometer and
(optionally) magnetometer columns — found by name (time ``t``, ``time``, ``timestamp``
…, axes ``gx,gy,gz``, ``ax,ay,az``, ``mx,my,mz`` and the spellings in
:mod:`strapdown.io.readers`) or mapped with ``columns``. Units as ``run`` takes them:
from the header (``gx[deg/s]``, ``ax[g]``, ``t[ms]``) or declared (gyro ``rad/s`` or
``deg/s``, accelerometer ``m/s2`` or ``g``; the magnetometer in any unit); one the file
contradicts, or none at all, is an error.

Validation names the row of a NaN, a duplicated or non-monotonic time stamp; jittered
stamps run on their nominal period (or resampled, ``resample``; see
:func:`strapdown.algorithms.rate.check_rate_record`); gaps fail or split the recording
(``on_gap``: each segment filtered from the previous one's last attitude and bias). A
gyro whose magnitudes suggest deg/s declared as rad/s is an error unless accepted; an
accelerometer whose norm is not about g is an error. Without magnetometer columns the
filter runs in its documented degraded mode: no heading (the gyro's integral from yaw
0), said on stderr and in the metadata.

A diverged filter — a non-finite or non-unit quaternion, a non-finite covariance, a gyro
bias estimate above :data:`BIAS_LIMIT` rad/s — is an error at the output stage and
nothing is written.

Output: ``t,qw,qx,qy,qz`` (q_n_b, n = ENU by default or NED) and the estimated gyro bias
``bias_x,bias_y,bias_z`` (rad/s) (+ ``segment`` when split), as CSV or ``.npz``, plus
``OUT.meta.json`` (frame, heading observed, algorithm, measurement usage, units, time
base and jitter, gaps, warnings, version), the two written together
(:mod:`strapdown.apps._logs`). The input is never overwritten.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from strapdown._core.errors import InputError, shown
from strapdown.ahrs import AhrsConfig, AhrsResult, MeasurementFlag, ekf, offline_ekf
from strapdown.algorithms.rate import resample_uniform
from strapdown.apps._logs import JitterSummary, output_with_sidecar, rate_records, unit_action
from strapdown.io import (
    UnitWarning,
    csv_columns,
    warn_implausible_rate,
    write_attitude,
)
from strapdown.io.readers import (
    ACC_COLUMNS,
    GYRO_COLUMNS,
    MAG_COLUMNS,
    ImuLog,
    UnitAction,
    check_distinct_columns,
    check_finite_rows,
    check_motion,
    check_read_options,
    default_columns,
    input_file,
    read_time_base,
    time_scale,
)
from strapdown.io.timing import (
    BRIDGE_MAX_S,
    JITTER_TOLERANCE,
    DuplicatePolicy,
    HeldPolicy,
    Timing,
    TimingMode,
)
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.euler import euler_zyx_from_dcm

__all__ = ["ACC_LIMIT", "ACC_UNITS", "BIAS_LIMIT", "DEFAULT_COLUMNS", "GYRO_UNITS", "MAG_LIMIT",
           "AhrsLog", "read_ahrs_log", "run_ahrs"]

#: The column layout of an AHRS CSV written without a mapping (any recognised names work).
DEFAULT_COLUMNS = ("t", "gx", "gy", "gz", "ax", "ay", "az", "mx", "my", "mz")
#: Largest accelerometer norm accepted (m/s², 1000 g): no accelerometer reads more.
ACC_LIMIT = 1000 * 9.80665
#: Largest magnetometer norm accepted, in the file's unit (any: µT, nT, gauss).
MAG_LIMIT = 1e12
#: Largest plausible gyro-bias estimate (rad/s, ≈ 57 °/s): beyond it the filter diverged.
BIAS_LIMIT = 1.0
GYRO_UNITS = ("rad/s", "deg/s")
ACC_UNITS = ("m/s2", "g")
_BROAD_UNITS = {"gyro": "rad/s", "accelerometer": "m/s2"}


@dataclass(frozen=True)
class AhrsLog:
    """A validated IMU recording in SI units (``mag`` None when absent)."""

    t: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray
    mag: np.ndarray | None
    gyro_units: str = "rad/s"
    acc_units: str = "m/s2"
    gaps: list[int] = field(default_factory=list)
    nominal_period: float | None = None
    timing: Timing | None = None
    inferred: dict[str, str] = field(default_factory=dict)


def _unit(path: Path, what: str, option: str, allowed, declared, found, whose) -> str:
    """The unit of one sensor: the file's (header, format) or the declared one."""
    if found is not None:
        if found not in allowed:
            raise InputError(f"{path}: the {what} is in {found!r}; use one of {allowed}")
        if declared is not None and declared != found:
            raise InputError(f"{path}: declared {what} units {declared!r} contradict {whose[0]} "
                             f"{found!r}{whose[1]}")
        return found
    if declared is None:
        raise InputError(f"{path}: no {what} units declared; pass {option} "
                         f"({' or '.join(allowed)}) or write them in the header "
                         f"(e.g. {'gx[deg/s]' if what == 'gyro' else 'ax[g]'})")
    if declared not in allowed:
        raise InputError(f"{what} units must be one of {allowed}, got {declared!r}")
    return declared


def _csv(path: Path, columns, delimiter: str | None):
    """``(t [s], gyro, acc, mag or None, header units of gyro and acc)``."""
    if columns is None:
        axes, mag = default_columns(path, [("gyro", GYRO_COLUMNS),
                                           ("accelerometer", ACC_COLUMNS)], optional=MAG_COLUMNS,
                                    delimiter=delimiter)
        columns = axes + mag
    elif len(columns) not in (7, 10):
        raise InputError(f"columns must name t, 3 gyro, 3 accelerometer and optionally 3 "
                         f"magnetometer columns (names or 0-based indices), got {len(columns)}")
    check_distinct_columns(columns)
    raw, units, have_mag = csv_columns(path, list(columns[:7]), optional=list(columns[7:10]),
                                       delimiter=delimiter)
    found = {}
    for what, cols in (("gyro", columns[1:4]), ("accelerometer", columns[4:7])):
        us = {units[c] for c in cols if c in units}
        if len(us) > 1:
            raise InputError(f"{path}: the header gives the {what} axes different units "
                             f"{sorted(us)}")
        found[what] = us.pop() if us else None
    scale = time_scale(path, columns[0], units)
    return raw[:, 0], scale, raw[:, 1:4], raw[:, 4:7], raw[:, 7:10] if have_mag else None, found


def _source(path: Path, columns, sample_rate_hz: float | None, delimiter: str | None):
    """``(stamps, seconds per stamp unit, gyro, acc, mag, units found, whose, nominal
    period)`` of a BROAD .mat or a CSV."""
    if path.suffix.lower() == ".mat":
        from strapdown.io.broad import read_broad

        tr = read_broad(path)
        if sample_rate_hz is not None and not np.isclose(1 / tr.h, sample_rate_hz, rtol=1e-6):
            raise InputError(f"{path}: the file states a sampling rate of {1 / tr.h:g} Hz, not "
                             f"the {sample_rate_hz:g} Hz given")
        whose = ("the file's", " (BROAD stores the gyro in rad/s, the accelerometer in m/s²)")
        return tr.t, 1.0, tr.gyro, tr.acc, tr.mag, _BROAD_UNITS, whose, None
    if path.suffix.lower() in (".csv", ".txt", ".tsv"):
        t, scale, g, a, m, found = _csv(path, columns, delimiter)
        nominal = None if sample_rate_hz is None else 1.0 / sample_rate_hz
        return t, scale, g, a, m, found, ("the header's", ""), nominal
    raise InputError(f"{path}: unsupported format {shown(path.suffix, 20)} (use a BROAD .mat or "
                     "a CSV)")


def _check_range(path: Path, what: str, values: np.ndarray, limit: float, unit: str) -> None:
    """Raise at the first row whose norm exceeds ``limit`` (no sensor reads that)."""
    norm = np.hypot(np.hypot(values[:, 0], values[:, 1]), values[:, 2])
    bad = ~(norm <= limit)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{path}: the {what} in data row {i + 1} has norm {norm[i]:.4g} "
                         f"{unit}, beyond any sensor's range ({limit:g} {unit}); check the "
                         "units and the columns")


def read_ahrs_log(path, *, gyro_units: str | None = None, acc_units: str | None = None,
                  columns=None, use_magnetometer: bool = True,
                  sample_rate_hz: float | None = None, gap_tolerance: float = 1.5,
                  unit_check: UnitAction = "warn", delimiter: str | None = None,
                  timing_mode: TimingMode = "auto", jitter_tolerance: float = JITTER_TOLERANCE,
                  held: HeldPolicy = "auto", duplicates: DuplicatePolicy = "error") -> AhrsLog:
    """Read and validate a recording (see the module docstring).

    Every problem is an :class:`~strapdown.InputError` naming the file: besides the checks
    ``run`` makes (:func:`strapdown.io.read_imu`: finite rows, time steps, no sample turning
    the body by more than π), an accelerometer norm above :data:`ACC_LIMIT` m/s² or a
    magnetometer norm above :data:`MAG_LIMIT` (its own unit) is refused.

    Units the file does not declare are inferred where the data decide
    (:func:`infer_acc_units`: a median norm near 9.8 is m/s², near 1 is g;
    :func:`infer_gyro_units`: the magnetometer's rotation against the gyro's) and listed
    in :attr:`AhrsLog.inferred`. The time base is :func:`strapdown.io.timing.reconstruct`'s
    (held rows, duplicated stamps, the fitted clock): ``timing_mode``, ``jitter_tolerance``,
    ``held`` and ``duplicates`` as for :func:`strapdown.io.read_imu`.
    """
    check_read_options(kind="rate", units=None, gap_tolerance=gap_tolerance, on_gap="report",
                       saturation=None, sample_rate_hz=sample_rate_hz)
    path = input_file(path, "recording")
    raw, scale, g, a, m, found, whose, nominal = _source(path, columns, sample_rate_hz,
                                                         delimiter)
    if raw.size < 2:
        raise InputError(f"{path}: {raw.size} samples; at least 2 are needed")
    check_finite_rows(path, [("time", [raw]), ("gyro", [g]), ("accelerometer", [a]),
                             *((("magnetometer", [m]),) if m is not None else ())])
    values = np.column_stack([g, a] + ([m] if m is not None else []))
    timing, t, t_rel = read_time_base(path, raw, scale, values, period=nominal,
                                      timing_mode=timing_mode, held=held,
                                      duplicates=duplicates,
                                      jitter_tolerance=jitter_tolerance,
                                      fit=path.suffix.lower() != ".mat")
    keep = timing.cleaning.keep
    if keep.size < raw.size:
        g, a = g[keep], a[keep]
        m = None if m is None else m[keep]
    inferred: dict[str, str] = {}
    if found["accelerometer"] is None and acc_units is None:
        acc_units = infer_acc_units(path, a)
        inferred["accelerometer"] = acc_units
    if found["gyro"] is None and gyro_units is None and m is not None and use_magnetometer:
        gyro_units = infer_gyro_units(path, t_rel, g, m)
        inferred["gyro"] = gyro_units
    gu = _unit(path, "gyro", "--gyro-units", GYRO_UNITS, gyro_units, found["gyro"], whose)
    au = _unit(path, "accelerometer", "--acc-units", ACC_UNITS, acc_units,
               found["accelerometer"], whose)
    if gu == "deg/s":
        g = np.radians(g)
    if au == "g":
        a = a * 9.80665
    warn_implausible_rate(path, g, gu, suggestion="deg/s", action=unit_check)
    if m is not None and use_magnetometer:
        _check_gyro_scale(path, t_rel, g, m, gu, unit_check)
    unit_h = nominal or timing.sample_period(t_rel)
    check_motion(path, g, "rate", unit_h)
    _check_range(path, "accelerometer", a, ACC_LIMIT, "m/s²")
    if m is not None:
        _check_range(path, "magnetometer", m, MAG_LIMIT, "(its unit)")
    if m is not None and not np.any(m):
        use_magnetometer = False
    gaps = timing.gap_rows(t_rel, unit_h, gap_tolerance)
    return AhrsLog(t, np.ascontiguousarray(g), np.ascontiguousarray(a),
                   None if (m is None or not use_magnetometer) else np.ascontiguousarray(m),
                   gu, au, gaps, nominal, timing, inferred)


#: Accelerometer norms (median over the recording) that decide its unit: within these
#: bounds of 9.80665 m/s² it is m/s², of 1 it is g (a body that is not in free fall or
#: under sustained thrust reads about gravity on average).
ACC_NORM_BOUNDS = (0.7, 1.3)


def infer_acc_units(path: Path, acc: np.ndarray) -> str:
    """``m/s2`` or ``g`` from the accelerometer's median norm (:data:`ACC_NORM_BOUNDS`),
    else an error asking for ``--acc-units``."""
    norm = float(np.median(np.linalg.norm(acc, axis=1)))
    lo, hi = ACC_NORM_BOUNDS
    if lo * 9.80665 <= norm <= hi * 9.80665:
        return "m/s2"
    if lo <= norm <= hi:
        return "g"
    raise InputError(f"{path}: the accelerometer's median norm is {norm:.4g}, neither about "
                     "9.8 (m/s²) nor about 1 (g); pass --acc-units (m/s2 or g) if it is "
                     "specific force, and check the columns")


def infer_gyro_units(path: Path, t: np.ndarray, gyro: np.ndarray, field: np.ndarray) -> str:
    """``rad/s`` or ``deg/s`` when the magnetometer's rotation decides (:func:`gyro_scale`
    ≈ 1 read as rad/s, ≈ π/180 as deg/s), else an error asking for ``--gyro-units``."""
    s = gyro_scale(t, gyro, field)
    lo, hi = GYRO_SCALE_LIMITS
    if s is not None and lo <= s <= hi:
        return "rad/s"
    if s is not None and lo <= s * 180.0 / np.pi <= hi:
        return "deg/s"
    why = ("the recording turns too little to tell" if s is None
           else f"the magnetometer turns {s:.3g} times as fast as the gyro read as rad/s")
    raise InputError(f"{path}: no gyro units declared and the data do not decide ({why}); "
                     "pass --gyro-units (rad/s or deg/s) or write them in the header "
                     "(gx[deg/s])")


#: Gyro scale against the magnetometer outside which the declared unit is judged wrong: a
#: factor 180/π off gives 0.017 or 57; a correct unit gives about 1 (noise, disturbances).
GYRO_SCALE_LIMITS = (0.2, 5.0)


def gyro_scale(t: np.ndarray, gyro: np.ndarray, field: np.ndarray) -> float | None:
    """The scale ``s`` that best explains the body-frame field's change by the gyro:
    ``Δm ≈ s · (−ω × m) Δt`` (a constant field seen from a rotating body), least squares
    over the record; ``None`` when neither the gyro nor the field shows a radian of rotation
    in all (nothing to judge). ``s ≈ 1`` for consistent units, ``π/180`` for a gyro
    in deg/s read as rad/s."""
    dt = np.diff(t)[:, None]
    w = 0.5 * (gyro[:-1] + gyro[1:])
    mid = 0.5 * (field[:-1] + field[1:])
    pred = -np.cross(w, mid) * dt
    dm = np.diff(field, axis=0)
    if dt.size:  # intervals across a gap: the linearised rotation does not hold there
        ok = dt[:, 0] <= 1.5 * float(np.median(dt))
        dt, w, mid, pred, dm = dt[ok], w[ok], mid[ok], pred[ok], dm[ok]
    den = float(np.sum(pred * pred))
    norm = np.linalg.norm(mid, axis=1)
    if not np.all(norm > 0):
        return None
    said = float(np.sum(np.linalg.norm(w, axis=1) * dt[:, 0]))  # what the gyro says (rad)
    seen = float(np.sum(np.linalg.norm(dm, axis=1) / norm))  # what the field shows (rad)
    if max(said, seen) < 1.0 or not den > 0:
        return None
    return float(np.sum(dm * pred) / den)


def _check_gyro_scale(path: Path, t: np.ndarray, g: np.ndarray, m: np.ndarray, gu: str,
                      unit_check: UnitAction) -> None:
    """A gyro whose rotation the magnetometer does not see (see :func:`gyro_scale`) is in
    other units than declared: an error (or a warning when accepted)."""
    s = gyro_scale(t, g, m)
    lo, hi = GYRO_SCALE_LIMITS
    if s is None or lo <= s <= hi:
        return
    other = "deg/s" if s < lo else "rad/s"
    msg = (f"{path}: the magnetometer turns {s:.3g} times as fast as the gyro says; the gyro "
           f"is more likely in {other} (declared {gu})")
    if unit_check == "error":
        raise InputError(f"{msg}; nothing computed. If the declared units are right, pass "
                         "--accept-unit-warning")
    warnings.warn(msg, UnitWarning, stacklevel=3)


def _check_output(res: AhrsResult, gyro_units: str) -> None:
    """Raise when the filter diverged (see the module docstring), naming where."""
    bad = (~np.all(np.isfinite(res.q), axis=1)
           | (np.abs(np.linalg.norm(res.q, axis=1) - 1.0) > 1e-6)
           | ~np.all(np.isfinite(res.gyro_bias), axis=1)
           | (np.linalg.norm(np.nan_to_num(res.gyro_bias, nan=np.inf), axis=1) > BIAS_LIMIT)
           | ~np.all(np.isfinite(res.attitude_sigma), axis=1))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"the filter diverged at output row {i + 1} (t = {float(res.t[i]):.6g} "
                         f"s): quaternion {res.q[i].tolist()}, gyro bias "
                         f"{res.gyro_bias[i].tolist()} rad/s (limit {BIAS_LIMIT:g}); nothing "
                         f"written. Are the gyro units right (declared {gyro_units})?")


def _merge(parts: list[AhrsResult], starts: list[int]) -> AhrsResult:
    """One result from the segments': every per-output array concatenated, the sample
    indices offset to the whole recording, the gyro's clipped and recovered samples
    summed."""
    if len(parts) == 1:
        return parts[0]
    cat: dict[str, Any] = {}
    for f in dataclasses.fields(parts[0]):
        first = getattr(parts[0], f.name)
        if isinstance(first, np.ndarray) and first.shape[:1] == parts[0].t.shape:
            cat[f.name] = np.concatenate([getattr(p, f.name) for p in parts])
    cat["index"] = np.concatenate([p.index + s for p, s in zip(parts, starts, strict=True)])
    for name in ("gyro_clipped", "gyro_recovered"):  # counts over the whole recording
        cat[name] = sum(getattr(p, name) for p in parts)
    return dataclasses.replace(parts[0], **cat)


def _select(res: AhrsResult, rows: np.ndarray, t: np.ndarray) -> AhrsResult:
    """The rows ``rows`` of a result over a bridged grid, at the times ``t``."""
    cut: dict[str, Any] = {}
    n = res.t.size
    for f in dataclasses.fields(res):
        v = getattr(res, f.name)
        if isinstance(v, np.ndarray) and v.shape[:1] == (n,):
            cut[f.name] = v[rows]
    cut["t"] = t
    cut["index"] = np.arange(rows.size)
    return dataclasses.replace(res, **cut)


def _run_filter(imu: Path, offline: bool, *args: Any, **kwargs: Any) -> AhrsResult:
    """:func:`~strapdown.ahrs.ekf` (``offline``: :func:`~strapdown.ahrs.offline_ekf`); the
    filter's own input checks (too few samples, an accelerometer that is not specific
    force …) are refusals of this recording, an :class:`~strapdown.InputError` naming it."""
    try:
        return (offline_ekf if offline else ekf)(*args, **kwargs)
    except InputError:
        raise
    except ValueError as exc:
        raise InputError(f"{imu}: {exc}") from None


def _bridge(imu: Path, log: AhrsLog, algorithm: str, frame: str,
            config: AhrsConfig | None, offline: bool) -> AhrsResult:
    """The filter over the fitted clock's full grid, missing samples interpolated, its
    outputs at the recorded samples (at their clock times)."""
    timing = log.timing
    assert timing is not None and timing.clock is not None
    clock = timing.clock
    gap = clock.longest_gap()
    if gap is not None and gap[1] * clock.period > BRIDGE_MAX_S:
        raise InputError(f"{imu}: a gap of {gap[1]} missing samples "
                         f"({gap[1] * clock.period:.3g} s) before data row "
                         f"{int(timing.rows[gap[0]])}, longer than the {BRIDGE_MAX_S:g} s the "
                         "filter bridges; pass --on-gap split (each segment filtered from "
                         "the previous one's last attitude)")
    origin = timing.base.origin
    uniform = clock.kind == "uniform" and gap is None and log.nominal_period is None
    if uniform:
        t_grid = log.t
        gyro, acc, mag = log.gyro, log.acc, log.mag
    else:
        full, (gyro_b, acc_b, mag) = clock.bridge(log.gyro, log.acc, log.mag)
        assert gyro_b is not None and acc_b is not None
        gyro, acc = gyro_b, acc_b
        t_grid = origin + clock.uniform_times(full)
    r = _run_filter(imu, offline, t_grid, gyro, acc, mag, algorithm=algorithm, config=config,
                    frame=frame)
    _check_output(r, log.gyro_units)
    if uniform:
        return r
    return _select(r, clock.ticks, origin + clock.times())


def _filter(imu: Path, log: AhrsLog, algorithm: str, frame: str, config: AhrsConfig | None,
            split: bool, resample: bool, offline: bool = False):
    """The filter (``offline``: :func:`~strapdown.ahrs.offline_ekf`, acausal) over the
    recording; ``(result, segment per output, time base)``.

    Samples on the fitted sensor clock (:attr:`strapdown.io.timing.Timing.on_clock`) run on
    its grid, gaps up to :data:`strapdown.io.timing.BRIDGE_MAX_S` bridged
    (:func:`_bridge`) unless ``split``;
    otherwise (``resample``, irregular sampling, ``--timing stamps``, ``split``) each
    gap-free segment runs on its uniform record (:func:`strapdown.apps._logs.rate_records`),
    from the previous segment's last attitude and bias.
    """
    glog = ImuLog(log.t, log.gyro, "rate", float(np.median(np.diff(log.t))), log.gaps, [],
                  "rad/s", log.nominal_period, log.timing)
    timing = log.timing
    if not split and not resample and timing is not None and timing.on_clock:
        r = _bridge(imu, log, algorithm, frame, config, offline)
        clock = timing.clock
        assert clock is not None
        base = JitterSummary(clock.period, clock.residual_max / clock.period, False, 1, timing)
        return r, np.zeros(r.t.size), base
    recs, base = rate_records(imu, glog, split=split, min_samples=4, resample=resample)
    cuts = glog.segments() if split else [slice(0, log.t.size)]
    parts, seg = [], []
    q0 = b0 = None
    for k, (rec, c) in enumerate(zip(recs, cuts, strict=True)):
        acc, mag = log.acc[c], None if log.mag is None else log.mag[c]
        if rec.stamps is not None and rec.resampled:
            acc = resample_uniform(rec.stamps, acc, rec.t)
            mag = None if mag is None else resample_uniform(rec.stamps, mag, rec.t)
        r = _run_filter(imu, offline, rec.t, rec.omega, acc, mag, algorithm=algorithm,
                        config=config, frame=frame, q0=q0, gyro_bias0=b0)
        _check_output(r, log.gyro_units)
        parts.append(r)
        seg.append(np.full(r.t.size, float(k)))
        q0, b0 = r.q[-1], r.gyro_bias[-1]
    return _merge(parts, [c.start for c in cuts]), np.concatenate(seg), base


def run_ahrs(imu, out, *, algorithm: str = "rate-single", frame: str = "ENU",
             config: AhrsConfig | None = None, gyro_units: str | None = None,
             acc_units: str | None = None, columns=None, use_magnetometer: bool = True,
             sample_rate_hz: float | None = None, on_gap: str = "report",
             gap_tolerance: float = 1.5, resample: bool = False,
             accept_unit_warning: bool = False, delimiter: str | None = None,
             offline: bool = False, timing: TimingMode = "auto",
             jitter_tolerance: float = JITTER_TOLERANCE, held: HeldPolicy = "auto",
             duplicates: DuplicatePolicy = "error") -> tuple[AhrsResult, dict[str, Any]]:
    """Filter a recording and write the attitude, biases and metadata atomically.

    ``offline``: post-processing with :func:`~strapdown.ahrs.offline_ekf` — the filter run
    forward and backward and the two combined, acausal (every estimate uses the whole
    recording); the metadata's ``mode`` says which.

    ``on_gap``: ``"report"`` bridges gaps of up to
    :data:`strapdown.io.timing.BRIDGE_MAX_S` on the sensor's fitted clock (reported;
    longer ones are an error), ``"split"`` filters each gap-free segment from the previous
    one's last attitude and bias (covariance reset; the motion during the gap is not
    observed), ``"error"`` fails at a gap. ``timing``,
    ``jitter_tolerance``, ``held``, ``duplicates``: the time base
    (:func:`read_ahrs_log`); ``resample`` is ``timing="resample"``: gyro, accelerometer
    and magnetometer interpolated onto the uniform grid. ``delimiter``: a CSV's (default:
    detected). Anything wrong with the input is an :class:`~strapdown.InputError`.

    Output columns: ``t`` (each sample's time on the fitted clock, in the file's time
    base), ``qw,qx,qy,qz``, ``yaw_deg,pitch_deg,roll_deg`` (z-y-x of the same q_n_b),
    ``bias_x,bias_y,bias_z`` (rad/s) (+ ``segment`` when split).
    """
    imu, out = Path(imu), Path(out)
    if out.resolve() == imu.resolve():
        raise InputError("--out must not be the input file")
    if out.suffix.lower() not in (".csv", ".npz"):
        raise InputError(f"{out}: output must be .csv or .npz")
    if on_gap not in ("report", "error", "split"):
        raise InputError(f"on_gap must be report, error or split, got {shown(on_gap, 20)}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = read_ahrs_log(imu, gyro_units=gyro_units, acc_units=acc_units, columns=columns,
                            use_magnetometer=use_magnetometer, sample_rate_hz=sample_rate_hz,
                            gap_tolerance=gap_tolerance,
                            unit_check=unit_action(accept_unit_warning), delimiter=delimiter,
                            timing_mode="resample" if resample else timing,
                            jitter_tolerance=jitter_tolerance, held=held,
                            duplicates=duplicates)
        if log.gaps and on_gap == "error":
            r = log.gaps[0]
            i = int(np.searchsorted(log.timing.rows, r)) if log.timing is not None else r - 1
            raise InputError(f"{imu}: gap of {log.t[i] - log.t[i - 1]:.6g} s before data "
                             f"row {r} (--on-gap error); the default --on-gap report bridges "
                             f"gaps up to {BRIDGE_MAX_S:g} s, --on-gap split runs each segment")
        res, seg, base = _filter(imu, log, algorithm, frame, config, on_gap == "split",
                                 resample or timing == "resample", offline)
        yaw, pitch, roll = euler_zyx_from_dcm(dcm_from_quat(res.q))
        extra = {"yaw_deg": np.degrees(yaw), "pitch_deg": np.degrees(pitch),
                 "roll_deg": np.degrees(roll), "bias_x": res.gyro_bias[:, 0],
                 "bias_y": res.gyro_bias[:, 1], "bias_z": res.gyro_bias[:, 2]}
        if on_gap == "split":
            extra["segment"] = seg
        origin = log.timing.base.origin_text if log.timing is not None else None
        with output_with_sidecar(out) as paired:
            write_attitude(paired.path, res.t, res.q, extra=extra, time_origin=origin)
            paired.meta = _metadata(imu, log, res, algorithm, frame, base, on_gap,
                                    [str(w.message) for w in caught])
    return res, paired.meta


def _metadata(imu: Path, log: AhrsLog, res: AhrsResult, algorithm: str, frame: str, base,
              on_gap: str, caught: list[str]) -> dict[str, Any]:
    from strapdown import __version__

    return {
        "input": str(imu), "frame": frame, "quaternion": "q_n_b, Hamilton, scalar first",
        "heading_observed": res.heading_observed,
        "heading": ("magnetic" if res.config.declination_deg == 0 else "true")
        if res.heading_observed else "not observed (no magnetometer): gyro integral from yaw 0",
        "algorithm": algorithm, "samples": int(log.t.size), "outputs": int(res.t.size),
        "mode": ("offline (acausal: forward and backward passes combined)" if res.smoothed
                 else "causal (real-time filter)"),
        "accelerometer_used": res.fraction(MeasurementFlag.ACC_USED),
        "magnetometer_used": (res.fraction(MeasurementFlag.MAG_USED) if res.heading_observed
                              else 0.0),
        "rest_updates": res.fraction(MeasurementFlag.REST),
        "start": ("still" if res.start_still else "in motion (the initial window is not still: "
                  "moving_start_window_s averaged along the gyro, wider initial uncertainty, "
                  "gravity's norm nominal until the first rest)"),
        "mag_hard_iron_subtracted": (None if res.mag_offset is None
                                     else [float(x) for x in res.mag_offset]),
        "gyro_at_range": {"samples": res.gyro_clipped,
                          "recovered_from_field": res.gyro_recovered},
        "gyro_units": log.gyro_units, "acc_units": log.acc_units,
        "units_inferred": log.inferred, **base.to_dict(),
        "columns": ["t", "qw", "qx", "qy", "qz", "yaw_deg", "pitch_deg", "roll_deg", "bias_x",
                    "bias_y", "bias_z", *(["segment"] if on_gap == "split" else [])],
        "euler": "yaw_deg, pitch_deg, roll_deg: z-y-x angles of q_n_b (deg)",
        "time_base": base.describe(), "on_gap": on_gap,
        "gaps": {"count": len(log.gaps), "first_rows": log.gaps[:100]},
        "warnings": caught, "version": __version__,
        "config": asdict(res.config),
    }
