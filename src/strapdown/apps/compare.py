"""Several algorithms side by side, on one reference motion or on one log.

An algorithm is named by a *spec*: the algorithm, then ``key=value`` options
separated by colons — ``rotvec:N=3:structure=realtime``, ``rate-three:
structure=sliding``, ``rk4:rk4_step=td-interp``, ``miller:step=0.01``. The keys
are :class:`~strapdown.analysis.evaluate.EvaluationConfig` fields (``N`` is short for
``subsamples``); an unknown key is an error that lists the known ones.

On a motion, errors are against the exact truth. On a log with a truth file
(``t,qw,qx,qy,qz``: CSV, ``.npy`` of n × 5 or ``.npz``), the truth is slerped to
each algorithm's output times (only times inside its span; the table says whether
the outputs fall on truth samples or between them). Truth times are seconds unless a CSV
header declares their unit (``t[ms]``, ``t[us]``, ``t[ns]``); a truth whose times read in
seconds span about 10³, 10⁶ or 10⁹ times the log's, and read in that unit match the log's
span and sample rate, is refused (:func:`_check_time_base`): its times are in ms, µs or ns.

On a log without truth nothing is interpolated: two algorithms are compared only at
the output times they share (within 10⁻⁶ of a sample interval). The **reference** is
the algorithm with the finest output grid — it shares every output time of the
others when their grids are subsets of it — and among equally fine grids the one
closest to the others (smallest sum of its largest differences from each), then the
first in spec-text order. The choice depends on the specs, never on their order.
Interpolating a coarser reference instead would report its interpolation error
(4e-6 rad on the tutorial's log, 3 ms grid) as the algorithms' difference.
``differences.md``/``.csv`` give the largest difference of every pair at their
common times, whichever the reference.

Output (a directory): ``error_vs_time.png``, ``summary.csv`` and ``summary.md``
(plus ``differences.csv``/``.md`` without truth).

On the sculling motion (``motion="sculling"``, :mod:`strapdown.analysis.sculling`) the specs
are velocity algorithms — ``rotvec:N=…`` with ``structure=conventional`` or
``single-chain`` — and the figure is the velocity error's norm (m/s); the summary has the
rectified velocity-error rate along navigation z, the sculling law's and their ratio, and
the largest velocity and position errors.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError, shown
from strapdown._core.kinds import InputKind
from strapdown.algorithms.spec import AlgorithmSpec, parse_spec
from strapdown.analysis.evaluate import EvaluationConfig, evaluate, run_evaluation
from strapdown.apps._figures import plot_curves
from strapdown.io.files import write_text
from strapdown.io.readers import GyroUnit
from strapdown.io.report import Curve, Report

__all__ = ["AlgorithmRun", "compare_log", "compare_motion"]

@dataclass(frozen=True)
class AlgorithmRun:
    """One algorithm's error history and summary (rad, s)."""

    label: str
    t: NDArray[np.float64]
    angle: NDArray[np.float64]
    summary: dict[str, object]
    #: The error history's sawtooth period in outputs (interleaved chains; 1: smooth).
    period: int = 1


#: Times within this fraction of a sample interval are the same output time.
TIME_TOLERANCE = 1e-6
#: Differences from the reference up to this angle (rad, ~50 ε) are round-off.
ROUNDOFF_ANGLE = 1e-14
_ITSELF = "itself (the reference)"


def _summary_row(label, t, angle, update_period, extra=None) -> dict:
    row = {"algorithm": label, "update_period_s": update_period, "outputs": int(t.size),
           "max_error_rad": float(np.max(angle)) if angle.size else math.nan,
           "rms_error_rad": float(np.sqrt(np.mean(angle**2))) if angle.size else math.nan,
           "final_error_rad": float(angle[-1]) if angle.size else math.nan}
    row.update(extra or {})
    return row


def compare_motion(base: EvaluationConfig, specs: Iterable[str], out: str | os.PathLike[str], *,
                   progress: Callable[[str], None] | None = None) -> list[AlgorithmRun]:
    """Run every spec on ``base``'s motion and sensor; write the figure and tables to ``out``."""
    specs = list(specs)
    if not specs:
        raise InputError("give at least one algorithm spec")
    if base.kind.has_metric("velocity_error_rate_m_s2"):  # a velocity motion (sculling)
        return _compare_sculling(base, specs, out, progress)
    runs, notes = [], []
    for k, spec in enumerate(specs, start=1):
        if progress is not None:
            progress(f"[{k}/{len(specs)}] {spec}")
        cfg = base.with_spec(spec)
        ev = evaluate(cfg)
        d = ev.to_dict()
        runs.append(AlgorithmRun(spec, ev.t, ev.angle, _summary_row(
            spec, ev.t, ev.angle, ev.update_period,
            {"cone_axis_drift_rad_s": d["cone_axis_drift_rad_s"],
             "predicted_drift_rad_s": d["predicted_drift_rad_s"],
             "measured_over_law": d["measured_over_law"], "law_status": d["law_status"]}),
            _chains(ev.chain)))
        if d["law_note"]:
            where = " (--precision: strapdown evaluate)" if "--precision" in d["law_note"] else ""
            notes.append(f"- {spec}: {d['law_status']} — {d['law_note']}{where}")
    title = (f"{base.motion}, half angle {base.half_angle_deg}°, cone {base.cone_rate_hz} Hz, "
             f"spin {base.spin_rate_dps} °/s, {base.sample_rate_hz:g} Hz gyro")
    _write(out, runs, title, "error against the exact truth", progress,
           ylabel="attitude error angle (rad)", notes=notes)
    return runs


def _compare_sculling(base: EvaluationConfig, specs: list[str], out: str | os.PathLike[str],
                      progress: Callable[[str], None] | None) -> list[AlgorithmRun]:
    """:func:`compare_motion` on the sculling motion: velocity algorithms, velocity errors."""
    runs = []
    for k, spec in enumerate(specs, start=1):
        if progress is not None:
            progress(f"[{k}/{len(specs)}] {spec}")
        ev = run_evaluation(base.with_spec(spec))
        d = ev.to_dict()
        pred = d["predicted_velocity_error_rate_m_s2"]
        dv = np.linalg.norm(ev.dv, axis=1)  # type: ignore[union-attr]
        runs.append(AlgorithmRun(spec, ev.t, dv, {
            "algorithm": spec, "update_period_s": d["update_period_s"], "outputs": int(dv.size),
            "velocity_error_rate_z_m_s2": d["velocity_error_rate_m_s2"][2],
            "predicted_velocity_error_rate_z_m_s2": None if pred is None else pred[2],
            "velocity_rate_over_law": d["velocity_rate_over_law"],
            "max_velocity_error_m_s": d["max_velocity_error_m_s"],
            "max_position_error_m": d["max_position_error_m"]}))
    title = (f"sculling, θ0 {base.angle_amplitude_deg}°, A {base.accel_amplitude} m/s², "
             f"{base.frequency_hz} Hz, ψ {base.phase_deg}°, {base.sample_rate_hz:g} Hz sensors")
    _write(out, runs, title, "velocity error against the exact truth", progress,
           ylabel="velocity error |δv| (m/s)")
    return runs


def _chains(chain: NDArray[np.int_]) -> int:
    """Number of interleaved chains of a solution (its error's sawtooth period)."""
    return int(np.unique(chain).size) if chain.size else 1


_TRUTH_COLUMNS = ("t", "qw", "qx", "qy", "qz")
_TRUTH_FORMATS = "CSV with columns t,qw,qx,qy,qz, .npy of shape (n, 5) or .npz with t,qw,qx,qy,qz"


def _read_truth(path: str | os.PathLike[str], delimiter: str | None = None
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(t, q)`` of a truth file (:data:`_TRUTH_FORMATS`), checked by :func:`_check_truth`;
    binary files are read by :mod:`strapdown.io.containers` (structure validated first);
    values beyond float64 (a float128 ``.npy``) read as infinity and are refused with their
    row."""
    from strapdown.io.readers import input_file

    path = input_file(path, "truth file")
    with np.errstate(over="ignore", invalid="ignore"):  # overflowing values: refused below
        t, q = _truth_values(path, delimiter)
    _check_truth(path, t, q)
    return t, q


def _truth_values(path: Path, delimiter: str | None
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The truth file's times (s) and quaternions as float64, unchecked."""
    from strapdown.io.containers import open_npy, read_npz
    from strapdown.io.readers import csv_columns, time_scale

    suffix = path.suffix.lower()
    if suffix == ".npz":
        z = read_npz(path, _TRUTH_COLUMNS)
        missing = [k for k in _TRUTH_COLUMNS if k not in z.arrays]
        if missing:
            raise InputError(f"{path}: truth needs arrays t, qw, qx, qy, qz; missing {missing} "
                             f"(found {z.found()})")
        cols = [z.arrays[k].astype(float).ravel() for k in _TRUTH_COLUMNS]
        if len({c.size for c in cols}) != 1:
            raise InputError(f"{path}: arrays t, qw, qx, qy, qz differ in length "
                             f"{[c.size for c in cols]}")
        t, q = cols[0], np.column_stack(cols[1:])
    elif suffix == ".npy":
        arr = open_npy(path)
        if arr.ndim != 2 or arr.shape[1] != 5:
            raise InputError(f"{path}: a .npy truth is a numeric array of shape (n, 5) with "
                             f"columns t, qw, qx, qy, qz; got {arr.dtype} {arr.shape}")
        t, q = np.asarray(arr[:, 0], float), np.asarray(arr[:, 1:], float)
    elif suffix in (".csv", ".txt", ".tsv"):
        raw, units, _ = csv_columns(path, _TRUTH_COLUMNS, delimiter=delimiter)
        t = raw[:, 0] * time_scale(path, "t", units)
        q = raw[:, 1:5]
    else:
        raise InputError(f"{path}: unknown truth format {shown(path.suffix, 20)}; truth must "
                         f"be {_TRUTH_FORMATS}")
    return t, q


def _check_truth(path: Path, t: NDArray[np.float64], q: NDArray[np.float64]) -> None:
    """Two or more rows, finite, strictly increasing times, unit quaternions (±1e-3)."""
    if t.size < 2:
        raise InputError(f"{path}: truth needs at least two rows, has {t.size}")
    bad = np.flatnonzero(~(np.isfinite(t) & np.all(np.isfinite(q), axis=1)))
    if bad.size:
        raise InputError(f"{path}: NaN or infinity in truth row {bad[0] + 1}")
    with np.errstate(over="ignore"):  # an overflowing step is still an increase
        step = np.flatnonzero(~(np.diff(t) > 0))
    if step.size:
        raise InputError(f"{path}: truth times must increase strictly; row {step[0] + 2} "
                         f"(t = {t[step[0] + 1]!r}) does not")
    big = np.max(np.abs(q), axis=1)  # the norm without overflow (quaternions × 1e300)
    scale = np.where(big > 0, big, 1.0)
    norm = big * np.linalg.norm(q / scale[:, None], axis=1)
    off = np.flatnonzero(np.abs(norm - 1.0) > 1e-3)
    if off.size:
        raise InputError(f"{path}: truth row {off[0] + 1} is not a unit quaternion (norm "
                         f"{norm[off[0]]:.6g}); columns are qw, qx, qy, qz (scalar first)")


def _inside(t: NDArray[np.float64], t_ref: NDArray[np.float64], tol: float
            ) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Which ``t`` lie in ``t_ref``'s span (``tol`` s of slack), and ``t`` clipped into it."""
    inside = (t >= t_ref[0] - tol) & (t <= t_ref[-1] + tol)
    return inside, np.clip(t[inside], t_ref[0], t_ref[-1])


def _errors_against(t_ref: NDArray[np.float64], q_ref: NDArray[np.float64],
                    t: NDArray[np.float64], q: NDArray[np.float64], tol: float = 0.0
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Angle between ``q`` and the reference slerped to ``t`` (inside the reference span)."""
    from scipy.spatial.transform import Slerp

    from strapdown.rotation.error import attitude_error_angle
    from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat

    inside, tc = _inside(t, t_ref, tol)
    if not np.any(inside):
        return t[:0], np.empty(0)
    ref = quat_from_scipy(Slerp(t_ref, scipy_from_quat(q_ref))(tc))
    return t[inside], attitude_error_angle(q[inside], ref)


def _common_times(ta: NDArray[np.float64], tb: NDArray[np.float64], tol: float
                  ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Indices ``(ia, ib)`` with ``|ta[ia] − tb[ib]| <= tol``: the output times both share."""
    if ta.size == 0 or tb.size == 0:
        return np.empty(0, np.intp), np.empty(0, np.intp)
    j = np.searchsorted(ta, tb).clip(0, ta.size - 1)
    left = (j - 1).clip(0)
    j = np.where(np.abs(ta[left] - tb) < np.abs(ta[j] - tb), left, j)  # the nearest ta
    ok = np.abs(ta[j] - tb) <= tol
    return j[ok].astype(np.intp), np.flatnonzero(ok).astype(np.intp)


def _log_spec(fields) -> AlgorithmSpec:
    spec = AlgorithmSpec(**fields)
    if spec.family.stepped:
        raise InputError(f"{spec.algorithm} runs on reference motions only (its input is the "
                         "Krylov model's increments at thirds or halves of a step); use rotvec "
                         "or a rate algorithm on a log")
    return spec


def _run_on_log(segments, fields, q0):
    """Run one spec over the log's gap-free segments (each from the previous one's last
    attitude); ``(solution, update period)``."""
    spec = _log_spec(fields)
    sols = []
    for seg in segments:
        sols.append(spec.run(seg, q0=q0))
        q0 = sols[-1].q[-1]
    sol = sols[0] if len(sols) == 1 else dataclasses.replace(
        sols[0], t=np.concatenate([s.t for s in sols]), q=np.concatenate([s.q for s in sols]),
        chain=np.concatenate([s.chain for s in sols]))
    from strapdown.apps._logs import check_finite

    check_finite(f"the {spec} attitude", sol.t, sol.q)
    return sol, spec.update_period(segments[0].h)


def compare_log(imu: str | os.PathLike[str], specs: Iterable[str], out: str | os.PathLike[str],
                *, kind: InputKind, units: GyroUnit | None,
                columns: Sequence[str] | None = None,
                sample_rate_hz: float | None = None, truth: str | os.PathLike[str] | None = None,
                progress: Callable[[str], None] | None = None, on_gap: str = "report",
                gap_tolerance: float = 1.5, resample: bool = False,
                accept_unit_warning: bool = False,
                delimiter: str | None = None, note: Callable[[str], None] | None = None,
                timing: str = "auto",
                jitter_tolerance: float | None = None, held: str = "auto",
                duplicates: str = "error") -> list[AlgorithmRun]:
    """Run every spec on one gyro log and compare them (see the module docstring).

    The log is read as ``strapdown run`` reads it (:func:`strapdown.io.read_imu`; jittered
    rate stamps on their nominal period or ``resample``-d; ``on_gap="split"`` runs every
    spec over each gap-free segment from the previous one's last attitude; magnitudes that
    suggest another unit are an error unless ``accept_unit_warning``; ``delimiter``: the
    CSVs', default detected; ``note``: where the log's time base is said (default
    ``progress``); ``timing``, ``jitter_tolerance``, ``held``, ``duplicates``: the
    time base, :func:`strapdown.io.read_imu`'s). Anything wrong with the inputs is an
    :class:`~strapdown.InputError`.
    """
    from strapdown.apps._logs import log_segments, unit_action
    from strapdown.io import read_imu
    from strapdown.io.timing import JITTER_TOLERANCE

    specs = list(specs)
    if not specs:
        raise InputError("give at least one algorithm spec")
    fields = [parse_spec(s) for s in specs]
    if on_gap not in ("report", "error", "split"):
        raise InputError(f"on_gap must be report, error or split, got {shown(on_gap, 20)}")
    with np.errstate(over="ignore", invalid="ignore"):  # values beyond float64: refused
        log = read_imu(imu, kind=kind, units=units, columns=columns,  # with their row
                       sample_rate_hz=sample_rate_hz, gap_tolerance=gap_tolerance,
                       on_gap="error" if on_gap == "error" else "report",
                       unit_check=unit_action(accept_unit_warning), delimiter=delimiter,
                       timing_mode="auto" if timing == "resample" else timing,  # type: ignore[arg-type]
                       jitter_tolerance=jitter_tolerance or JITTER_TOLERANCE,
                       held=held, duplicates=duplicates)  # type: ignore[arg-type]
    resample = resample or timing == "resample"
    segments, base = log_segments(Path(imu), log, split=on_gap == "split", resample=resample,
                                  min_samples=max(_log_spec(f).min_samples for f in fields))
    h = segments[0].h
    tol = TIME_TOLERANCE * h
    title = f"{Path(imu).name}: {log.t.size} {kind} samples at {1 / h:g} Hz"

    def time_base() -> None:  # said once every algorithm has run, before anything is written
        say = note or progress  # the log's time base is a finding, said even without progress
        if base is not None and say is not None:
            say(f"{imu}: {log.t.size} rate samples, {base.describe()}")

    if truth is None:
        sols = [_run_on_log(segments, f, None) for f in fields]
        runs, what, ylabel, pairs = _against_reference(specs, sols, tol)
        time_base()
        _write(out, runs, title, what, progress, ylabel=ylabel, pairs=pairs)
        return runs
    t_ref, q_ref = _read_truth(truth, delimiter)
    _check_time_base(Path(truth), t_ref, log, delimiter)
    q0 = _truth_start(truth, t_ref, q_ref, log, tol)
    sols = [_run_on_log(segments, f, q0) for f in fields]
    name = Path(truth).name
    runs = []
    for spec, (sol, period) in zip(specs, sols, strict=True):
        t, ang = _errors_against(t_ref, q_ref, sol.t, sol.q, tol)
        on = _common_times(t_ref, t, tol)[1].size
        where = "at its samples" if on == t.size else f"slerped, {t.size - on} outputs between"
        runs.append(AlgorithmRun(spec, t, ang, _summary_row(
            spec, t, ang, period, {"compared_outputs": int(t.size),
                                   "reference": f"{name} ({where})"}), _chains(sol.chain)))
    time_base()
    _write(out, runs, title, f"error against {name}", progress,
           ylabel=f"attitude error against {name} (rad)")
    return runs


#: Time units a truth's plain ``t`` may be in by mistake, and their factor to seconds.
_TIME_SLIPS = (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))


def _covered(a0: float, a1: float, b0: float, b1: float) -> float:
    """The fraction of the span ``b0…b1`` that ``a0…a1`` covers."""
    return max(0.0, min(a1, b1) - max(a0, b0)) / (b1 - b0)


def _check_time_base(path: Path, t_ref: NDArray[np.float64], log,
                     delimiter: str | None) -> None:
    """Refuse a truth whose undeclared times are in ms, µs or ns instead of seconds.

    With a factor ``s`` of :data:`_TIME_SLIPS` the truth is taken for one in that unit when
    its times times ``s`` cover at least half the log's span, its sample period times ``s``
    is closer to the log's than its period read in seconds (in ratio), and read in seconds
    the truth spans at least 100 times the log or covers less than half of it. A CSV
    header that declares the unit (``t[s]``, ``t[ms]``) is taken as it says.
    """
    if path.suffix.lower() in (".csv", ".txt", ".tsv"):
        from strapdown.io.readers import csv_header

        if "t" in csv_header(path, delimiter=delimiter)[1]:
            return
    lo = float(log.t[0]) - (log.h if log.kind == "increment" else 0.0)
    hi = float(log.t[-1])
    t0, t1 = float(t_ref[0]), float(t_ref[-1])
    with np.errstate(over="ignore"):
        period = float(np.median(np.diff(t_ref)))
    if not (hi > lo and log.h > 0 and math.isfinite(t1 - t0) and math.isfinite(period)):
        return
    raw = _covered(t0, t1, lo, hi)
    if not ((t1 - t0) >= 100 * (hi - lo) or raw < 0.5):
        return
    for unit, s in _TIME_SLIPS:
        if (_covered(s * t0, s * t1, lo, hi) >= 0.5
                and abs(math.log(s * period / log.h)) < abs(math.log(period / log.h))):
            declare = (f"declare it in the header (t[{unit}]; t[s] if it is seconds)"
                       if path.suffix.lower() in (".csv", ".txt", ".tsv")
                       else "write its t in seconds")
            raise InputError(
                f"{path}: truth times {t0:.6g}…{t1:.6g} (period {period:.3g}) do not fit the "
                f"log's {lo:.6g}…{hi:.6g} s (period {log.h:.3g} s) as seconds, but do as "
                f"{unit}: the truth's time column is likely in {unit}; {declare}; nothing "
                "computed")


def _truth_start(truth, t_ref: NDArray[np.float64], q_ref: NDArray[np.float64], log,
                 tol: float) -> NDArray[np.float64]:
    """The truth's attitude at the log's start; a start outside the truth's span by no more
    than ``tol`` (round-off of ``t[0] − h``: −4.3e-19 s against 0) counts as its end."""
    from scipy.spatial.transform import Slerp

    from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat

    t_start = float(log.t[0]) - (log.h if log.kind == "increment" else 0.0)
    if not t_ref[0] - tol <= t_start <= t_ref[-1] + tol:
        raise InputError(f"{truth}: covers t = {t_ref[0]!r}…{t_ref[-1]!r} s, not the log's "
                         f"start {t_start!r} s")
    t_start = min(max(t_start, float(t_ref[0])), float(t_ref[-1]))
    return quat_from_scipy(Slerp(t_ref, scipy_from_quat(q_ref))([t_start]))[0]


def _pair_differences(labels, sols, tol: float) -> dict[tuple[int, int], tuple]:
    """Every pair's difference angle at the output times both share: ``(ia, ib, angle)``.

    The angle is taken in spec-text order (the smaller label's attitude first), so that
    not even its round-off depends on the order the specs were given in.
    """
    from strapdown.rotation.error import attitude_error_angle

    out = {}
    for a in range(len(sols)):
        for b in range(a + 1, len(sols)):
            sa, sb = sols[a][0], sols[b][0]
            ia, ib = _common_times(sa.t, sb.t, tol)
            qa, qb = sa.q[ia], sb.q[ib]
            out[a, b] = (ia, ib, attitude_error_angle(qa, qb) if labels[a] <= labels[b]
                         else attitude_error_angle(qb, qa))
    return out


def _choose_reference(labels, periods, pairs) -> int:
    """Finest output grid; then closest to the others; then spec text (module docstring)."""
    def largest(a, b):
        ang = pairs[min(a, b), max(a, b)][2]
        return float(ang.max()) if ang.size else math.inf

    finest = min(periods)
    candidates = [i for i, p in enumerate(periods) if math.isclose(p, finest, rel_tol=1e-9)]
    return min(candidates, key=lambda i: (
        math.fsum(largest(i, j) for j in range(len(labels)) if j != i), labels[i]))


def _against_reference(specs, sols, tol):
    """Runs as differences from the chosen reference at common output times (no truth)."""
    pairs = _pair_differences(specs, sols, tol)
    ref = _choose_reference(specs, [p for _, p in sols], pairs)
    runs = []
    for i, (spec, (sol, period)) in enumerate(zip(specs, sols, strict=True)):
        if i == ref:
            t, ang, chains = sol.t, np.zeros(sol.t.size), 1
            note = _ITSELF
        else:
            ia, ib, ang = pairs[min(i, ref), max(i, ref)]
            mine, theirs = (ia, ib) if i < ref else (ib, ia)
            t = sol.t[mine]
            pattern = sol.chain[mine] * (sols[ref][0].chains + 1) + sols[ref][0].chain[theirs]
            chains = int(np.unique(pattern).size) if pattern.size else 1
            note = f"{specs[ref]} at {t.size} of {sol.t.size} outputs"
        runs.append(AlgorithmRun(spec, t, ang, _summary_row(
            spec, t, ang, period, {"compared_outputs": int(t.size), "reference": note}),
            chains))
    what = (f"no truth given: difference from {specs[ref]} (the reference: finest output "
            "grid),\nat common output times only (no interpolation)")
    return runs, what, f"difference from {specs[ref]} (rad)", (specs, pairs)


def _write(out, runs, title, what, progress, *, ylabel: str, notes=(), pairs=None) -> None:
    rep = Report.begin(out, progress)
    fig, ax = rep.plt.subplots(figsize=(8, 4.5))
    plot_curves(ax, [_curve(r, pairs is not None) for r in runs], ylabel=ylabel)
    ax.set_title(f"{title}\n{what}", fontsize=9)
    rep.figure("error_vs_time.png", fig)
    header = list(runs[0].summary)
    for r in runs[1:]:
        header += [k for k in r.summary if k not in header]
    md = rep.table("summary", header, [[_cell(r.summary.get(k)) for k in header] for r in runs])
    if notes:
        write_text(rep.out / "summary.md", md + "\n" + "\n".join(notes) + "\n")
    files = "summary.md, summary.csv, error_vs_time.png"
    if pairs is not None:
        labels, diffs = pairs
        rows = [[a, *(("0" if a == b else _cell(_largest(diffs, i, j)))
                      for j, b in enumerate(labels))] for i, a in enumerate(labels)]
        rep.table("differences", ["largest difference (rad) at common output times", *labels],
                  rows)
        files += ", differences.md, differences.csv"
    rep.say(f"wrote {rep.out}/{files} ({what.replace(chr(10), ' ')})")


def _curve(r: AlgorithmRun, vs_reference: bool) -> Curve:
    """The figure's curve of a run; without truth the reference itself and differences at
    round-off level are listed in the legend, not drawn (they would stretch the axis)."""
    hidden = ""
    if vs_reference and r.summary.get("reference") == _ITSELF:
        hidden = "the reference"
    elif vs_reference and r.angle.size == 0:
        hidden = "no output time in common with the reference"
    elif vs_reference and float(r.angle.max()) <= ROUNDOFF_ANGLE:
        hidden = f"equal to the reference to round-off, at most {float(r.angle.max()):.1e} rad"
    return Curve(r.t, r.angle, r.label, r.period, hidden)


def _largest(diffs, i: int, j: int) -> float:
    ang = diffs[min(i, j), max(i, j)][2]
    return float(ang.max()) if ang.size else math.nan


def _cell(v):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    return f"{v:.6e}" if isinstance(v, float) else v
