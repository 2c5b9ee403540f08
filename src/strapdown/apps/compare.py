"""Several algorithms side by side, on one reference motion or on one log.

An algorithm is named by a *spec*: the algorithm, then ``key=value`` options
separated by colons — ``rotvec:N=3:structure=realtime``, ``rate-three:
structure=sliding``, ``rk4:rk4_step=td-interp``, ``miller:step=0.01``. The keys
are :class:`~strapdown.analysis.evaluate.EvaluationConfig` fields (``N`` is short for
``subsamples``); an unknown key is an error that lists the known ones.

On a motion, errors are against the exact truth. On a log there is no truth
unless one is given (a ``t,qw,qx,qy,qz`` file); otherwise the first spec is
the reference and the others are reported relative to it. Either way the
reference is interpolated (slerp) to each algorithm's output times and only
times inside the reference's span are compared.

Output (a directory): ``error_vs_time.png``, ``summary.csv`` and ``summary.md``.
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

from strapdown._core.kinds import InputKind
from strapdown.algorithms.spec import AlgorithmSpec, parse_spec
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.io.readers import GyroUnit
from strapdown.io.report import Report

__all__ = ["AlgorithmRun", "compare_log", "compare_motion"]

@dataclass(frozen=True)
class AlgorithmRun:
    """One algorithm's error history and summary (rad, s)."""

    label: str
    t: NDArray[np.float64]
    angle: NDArray[np.float64]
    summary: dict[str, object]


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
        raise ValueError("give at least one algorithm spec")
    runs = []
    for spec in specs:
        cfg = dataclasses.replace(base, **parse_spec(spec))
        ev = evaluate(cfg)
        d = ev.to_dict()
        ratio = (d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"]
                 if d["predicted_drift_rad_s"] and d["cone_axis_drift_rad_s"] is not None
                 else None)
        runs.append(AlgorithmRun(spec, ev.t, ev.angle, _summary_row(
            spec, ev.t, ev.angle, ev.update_period,
            {"cone_axis_drift_rad_s": d["cone_axis_drift_rad_s"],
             "predicted_drift_rad_s": d["predicted_drift_rad_s"], "measured_over_law": ratio})))
    title = (f"{base.motion}, half angle {base.half_angle_deg}°, cone {base.cone_rate_hz} Hz, "
             f"spin {base.spin_rate_dps} °/s, {base.sample_rate_hz:g} Hz gyro")
    _write(out, runs, title, "error against the exact truth", progress)
    return runs


def _read_truth(path: str | os.PathLike[str]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    path = Path(path)
    if path.suffix.lower() == ".npz":
        with np.load(path) as z:
            missing = [k for k in ("t", "qw", "qx", "qy", "qz") if k not in z]
            if missing:
                raise ValueError(f"{path}: truth needs arrays t, qw, qx, qy, qz; missing "
                                 f"{missing}")
            return np.asarray(z["t"], float), np.column_stack(
                [np.asarray(z[k], float) for k in ("qw", "qx", "qy", "qz")])
    with open(path, encoding="utf-8") as f:
        header = [c.strip() for c in f.readline().split(",")]
    missing = [k for k in ("t", "qw", "qx", "qy", "qz") if k not in header]
    if missing:
        raise ValueError(f"{path}: truth needs columns t, qw, qx, qy, qz; missing {missing}")
    arr = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    cols = [header.index(k) for k in ("t", "qw", "qx", "qy", "qz")]
    return arr[:, cols[0]], arr[:, cols[1:]]


def _errors_against(t_ref: NDArray[np.float64], q_ref: NDArray[np.float64],
                    t: NDArray[np.float64], q: NDArray[np.float64]
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Angle between ``q`` and the reference slerped to ``t`` (inside the reference span)."""
    from scipy.spatial.transform import Slerp

    from strapdown.rotation.error import attitude_error_angle
    from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat

    inside = (t >= t_ref[0]) & (t <= t_ref[-1])
    if not np.any(inside):
        return t[:0], np.empty(0)
    ref = quat_from_scipy(Slerp(t_ref, scipy_from_quat(q_ref))(t[inside]))
    return t[inside], attitude_error_angle(q[inside], ref)


def _run_on_log(log, fields, q0):
    spec = AlgorithmSpec(**fields)
    if spec.family.stepped:
        raise ValueError(f"{spec.algorithm} runs on reference motions only (its input is the "
                         "Krylov model's increments at thirds or halves of a step); use rotvec "
                         "or a rate algorithm on a log")
    return spec.run(log, q0=q0), spec.update_period(log.h)


def compare_log(imu: str | os.PathLike[str], specs: Iterable[str], out: str | os.PathLike[str],
                *, kind: InputKind, units: GyroUnit | None,
                columns: Sequence[str] = ("t", "gx", "gy", "gz"),
                sample_rate_hz: float | None = None, truth: str | os.PathLike[str] | None = None,
                progress: Callable[[str], None] | None = None) -> list[AlgorithmRun]:
    """Run every spec on one gyro log and compare them (see the module docstring)."""
    from strapdown.io import read_imu

    specs = list(specs)
    if not specs:
        raise ValueError("give at least one algorithm spec")
    fields = [parse_spec(s) for s in specs]
    log = read_imu(imu, kind=kind, units=units, columns=columns, sample_rate_hz=sample_rate_hz)
    q0 = None
    if truth is not None:
        t_ref, q_ref = _read_truth(truth)
        from scipy.spatial.transform import Slerp

        from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat

        t_start = float(log.t[0]) - (log.h if kind == "increment" else 0.0)
        if not t_ref[0] <= t_start <= t_ref[-1]:
            raise ValueError(f"{truth}: covers t = {t_ref[0]}…{t_ref[-1]} s, not the log's start "
                             f"{t_start} s")
        q0 = quat_from_scipy(Slerp(t_ref, scipy_from_quat(q_ref))([t_start]))[0]
    sols = [_run_on_log(log, f, q0) for f in fields]
    if truth is None:
        t_ref, q_ref = sols[0][0].t, sols[0][0].q
        what = f"difference from {specs[0]} (no truth given)"
    else:
        what = f"error against {Path(truth).name}"
    runs = []
    for spec, (sol, period) in zip(specs, sols, strict=True):
        t, ang = _errors_against(t_ref, q_ref, sol.t, sol.q)
        runs.append(AlgorithmRun(spec, t, ang, _summary_row(spec, t, ang, period)))
    _write(out, runs, f"{Path(imu).name}: {log.t.size} {kind} samples at {1 / log.h:g} Hz",
           what, progress)
    return runs


def _write(out, runs, title, what, progress) -> None:
    rep = Report.begin(out, progress)
    fig, ax = rep.plt.subplots(figsize=(8, 4.5))
    for r in runs:
        if r.angle.size and np.any(r.angle > 0):
            ax.semilogy(r.t, np.where(r.angle > 0, r.angle, np.nan), lw=0.8, label=r.label)
        else:
            ax.plot([], [], label=f"{r.label} (identically zero)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("attitude error angle (rad)")
    ax.set_title(f"{title}\n{what}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    rep.figure("error_vs_time.png", fig)
    header = list(runs[0].summary)
    for r in runs[1:]:
        header += [k for k in r.summary if k not in header]

    def cell(v):
        if v is None or (isinstance(v, float) and math.isnan(v)):
            return ""
        return f"{v:.6e}" if isinstance(v, float) else v

    rows = [[cell(r.summary.get(k)) for k in header] for r in runs]
    rep.table("summary", header, rows)
    rep.say(f"wrote {rep.out}/summary.md, summary.csv, error_vs_time.png ({what})")
