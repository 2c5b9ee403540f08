"""``strapdown benchmark-ahrs DIR``: our AHRS against the open peers on BROAD trials.

Runs, on every BROAD trial (``*.mat``) in a directory and in the same run, each
labelled **causal** (the estimate at a sample uses that sample and earlier ones
only, as a real-time filter) or **acausal** (it also uses later samples: post-processing):

- ``strapdown EKF`` (causal) — :func:`strapdown.ahrs.ekf` with its defaults;
- ``strapdown EKF offline`` (acausal) — :func:`strapdown.ahrs.offline_ekf`, the same
  filter run forward and backward and combined (``strapdown ahrs --offline``);
- ``VQF`` (causal) — Laidig & Seel's VQF in real time, ``vqf.VQF(Ts).updateBatch``
  with the package's defaults (9D quaternion);
- ``offlineVQF`` (acausal) — ``vqf.offlineVQF``, VQF's forward–backward offline variant;
- ``Fusion`` (causal) — x-io's Fusion AHRS (package ``imufusion``) with its
  documented example settings (gain 0.5, acceleration and magnetic rejection
  10°, recovery 5 s, gyro range 2000 °/s, its gyro-offset estimator), ENU;

and our filter's ablations for the gating study: ``strapdown EKF, no gating``
(innovation gating and magnetic-disturbance rejection off) and the paper's raw
accelerometer model with and without gating.

The peers are an optional extra (``pip install 'strapdown[bench]'``); a
missing peer is reported as missing, never silently dropped. Metrics are
BROAD's as published (:func:`strapdown.analysis.broad.broad_errors`, no heading
offset removed): total, heading and inclination RMSE over movement phases, in
degrees, one estimate per sample; ``heading_offset_removed`` adds the total
error after removing a constant heading offset as an extra, labelled column
(not BROAD's metric). Throughput is samples per second of each filter's run
(ours after its compiled kernel is loaded; Fusion's API is one Python call per
sample). Writes ``errors.csv``/``.md`` (long form), ``total.csv``/``.md`` (one
row per trial), ``summary.csv``/``.md`` (means), ``errors.png`` and ``report.md``.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import fields, replace
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
from strapdown.analysis.broad import broad_errors
from strapdown.io.broad import BroadTrial, read_broad
from strapdown.io.report import Report

__all__ = ["ABLATIONS", "COMPARED", "FILTERS", "KIND", "FilterName", "benchmark", "config_note",
           "mean_of", "mean_total", "run_filter"]

#: The filters (see the module docstring): the compared ones first, then the ablations.
FilterName = Literal["strapdown EKF", "strapdown EKF offline", "VQF", "offlineVQF", "Fusion",
                     "strapdown EKF, no gating", "strapdown EKF, raw acc",
                     "strapdown EKF, raw acc, no gating"]
FILTERS: tuple[FilterName, ...] = get_args(FilterName)
COMPARED: tuple[FilterName, ...] = ("strapdown EKF", "strapdown EKF offline", "VQF",
                                    "offlineVQF", "Fusion")
ABLATIONS: tuple[FilterName, ...] = tuple(f for f in FILTERS if f not in COMPARED)
#: causal or acausal (uses later samples).
KIND: dict[FilterName, str] = {f: "acausal" if "offline" in f else "causal" for f in FILTERS}
#: The VQF variant of the same kind, for the per-trial ratio.
_SAME_KIND_VQF = {"causal": "VQF", "acausal": "offlineVQF"}
#: AhrsConfig fields of our filter's variants.
_OURS: dict[FilterName, dict[str, Any]] = {
    "strapdown EKF": {}, "strapdown EKF, no gating": {"gating": False},
    "strapdown EKF, raw acc": {"acc_model": "raw"},
    "strapdown EKF, raw acc, no gating": {"acc_model": "raw", "gating": False}}
_PEER_MODULE = {"VQF": "vqf", "offlineVQF": "vqf", "Fusion": "imufusion"}


def vqf_attitude(gyro: ArrayLike, acc: ArrayLike, mag: ArrayLike | None, h: float, *,
                 offline: bool = False) -> NDArray[np.float64]:
    """VQF's estimate with its defaults, q_ENU_b at every sample: ``VQF(h).updateBatch``
    (``offline=False``) or ``offlineVQF``; 9D with a magnetometer, 6D with ``mag=None``.
    The one place the benchmarks call VQF (BROAD, the generalisation suite, OpenAXES, the
    tuning studies)."""
    import vqf

    g, a = np.ascontiguousarray(gyro, float), np.ascontiguousarray(acc, float)
    m = None if mag is None else np.ascontiguousarray(mag, float)
    if offline:
        out = vqf.offlineVQF(g, a, m, h, {})
    else:
        out = vqf.VQF(h).updateBatch(g, a) if m is None else vqf.VQF(h).updateBatch(g, a, m)
    return np.asarray(out["quat6D" if m is None else "quat9D"])


def _vqf(tr: BroadTrial) -> NDArray[np.float64]:
    return vqf_attitude(tr.gyro, tr.acc, tr.mag, tr.h)


def _offline_vqf(tr: BroadTrial) -> NDArray[np.float64]:
    return vqf_attitude(tr.gyro, tr.acc, tr.mag, tr.h, offline=True)


def _fusion(tr: BroadTrial) -> NDArray[np.float64]:
    import imufusion

    fs = 1.0 / tr.h
    st = imufusion.AhrsSettings()
    st.convention = imufusion.CONVENTION_ENU
    st.gain = 0.5
    st.gyroscope_range = 2000.0
    st.acceleration_rejection = 10.0
    st.magnetic_rejection = 10.0
    st.rejection_timeout = int(5 * fs)
    st.sample_rate = fs
    ahrs = imufusion.Ahrs()
    ahrs.set_settings(st)
    ahrs.set_sample_period(tr.h)
    bs = imufusion.BiasSettings()
    bs.sample_rate = fs
    bias = imufusion.Bias()
    bias.set_settings(bs)
    gyr = np.degrees(tr.gyro)
    acc = tr.acc / 9.80665
    q = np.empty((tr.t.size, 4))
    for i in range(tr.t.size):  # the peer's API is per sample
        ahrs.update(bias.update(gyr[i]), acc[i], tr.mag[i])
        q[i] = ahrs.get_quaternion()
    return q


def run_filter(name: FilterName, tr: BroadTrial, *, algorithm: str = "rate-single",
               config: AhrsConfig | None = None) -> NDArray[np.float64]:
    """One filter on one trial: q_ENU_b at every sample, shape (n, 4). ``config``: our
    filters' options (default :class:`AhrsConfig`), under each variant's own changes."""
    base = config or AhrsConfig()
    if name in _OURS:
        return ekf(tr.t, tr.gyro, tr.acc, tr.mag, algorithm=algorithm,
                   config=replace(base, **_OURS[name])).q
    if name == "strapdown EKF offline":
        return offline_ekf(tr.t, tr.gyro, tr.acc, tr.mag, algorithm=algorithm,
                           config=base).q
    peers: dict[str, Callable[[BroadTrial], NDArray[np.float64]]] = {
        "VQF": _vqf, "offlineVQF": _offline_vqf, "Fusion": _fusion}
    if name not in peers:
        raise ValueError(f"unknown filter {name!r}; choose one of {', '.join(FILTERS)}")
    return peers[name](tr)


def config_note(config: AhrsConfig | None) -> str:
    """How a report names our filters' options: ``"their defaults"``, or the fields of
    ``config`` that differ from :class:`AhrsConfig`'s defaults, ``"field=value"`` each."""
    if config is None:
        return "their defaults"
    base = AhrsConfig()
    changed = [f"{f.name}={getattr(config, f.name)!r}" for f in fields(AhrsConfig)
               if getattr(config, f.name) != getattr(base, f.name)]
    return "their defaults" if not changed else "their defaults but " + ", ".join(changed)


def _available(name: str) -> str | None:
    """None if the filter can run, else why not."""
    mod = _PEER_MODULE.get(name)
    if mod is None:
        return None
    try:
        __import__(mod)
    except ImportError:
        return f"{mod} not installed (pip install 'strapdown[bench]')"
    return None


def _warm_up(tr: BroadTrial, algorithm: str) -> None:
    """Load our compiled kernel before anything is timed."""
    n = min(tr.t.size, 400)
    ekf(tr.t[:n], tr.gyro[:n], tr.acc[:n], tr.mag[:n], algorithm=algorithm)


def _run_all(files: list[Path], ran: list[FilterName], rep: Report, algorithm: str,
             heading_offset_removed: bool, config: AhrsConfig | None) -> tuple[dict, dict]:
    """Every filter on every trial: ``({(trial, filter): errors}, {filter: [samples, s]})``."""
    results: dict = {}
    timing = {f: [0, 0.0] for f in ran}
    for k, path in enumerate(files):
        tr = read_broad(path)
        if k == 0:
            _warm_up(tr, algorithm)
        for f in ran:
            rep.say(f"{tr.name}: {f}")
            tic = time.perf_counter()
            q = run_filter(f, tr, algorithm=algorithm, config=config)
            timing[f][1] += time.perf_counter() - tic
            timing[f][0] += tr.t.size
            if q.shape != (tr.t.size, 4):
                raise ValueError(f"{f} gave {q.shape[0]} estimates for {tr.t.size} samples")
            results[(tr.name, f)] = broad_errors(q, tr.q_ref, tr.movement,
                                                 remove_heading_offset=heading_offset_removed)
    return results, timing


def mean_of(results: dict, name: str, key: str = "total_deg") -> float:
    """Mean of one metric of one filter over the trials in ``results`` (NaN if it did not run)."""
    v = [e[key] for (_, f), e in results.items() if f == name]
    return float(np.mean(v)) if v else math.nan


def mean_total(results: dict, name: str) -> float:
    """Mean total RMSE of one filter over the trials in ``results``."""
    return mean_of(results, name)


def _long_table(rep: Report, names: list[str], ran: list[FilterName], results: dict,
                offset: bool) -> str:
    header = ["trial", "filter", "kind", "total (°)", "heading (°)", "inclination (°)"]
    if offset:
        header.append("total, heading offset removed (°; not BROAD's metric)")
    rows = []
    for n in names:
        for f in ran:
            e = results[(n, f)]
            row = [n, f, KIND[f], f"{e['total_deg']:.3f}", f"{e['heading_deg']:.3f}",
                   f"{e['inclination_deg']:.3f}"]
            if offset:
                row.append(f"{e['total_offset_removed_deg']:.3f}")
            rows.append(row)
    return rep.table("errors", header, rows)


def _wide_table(rep: Report, names: list[str], ran: list[FilterName], results: dict) -> str:
    """Total / heading / inclination per trial, one column group per compared filter."""
    shown = [f for f in COMPARED if f in ran]
    header = ["trial"] + [f"{f} ({KIND[f]})" for f in shown]
    rows = [[n] + [f"{results[(n, f)]['total_deg']:.2f} / {results[(n, f)]['heading_deg']:.2f}"
                   f" / {results[(n, f)]['inclination_deg']:.2f}" for f in shown] for n in names]
    rows.append(["**mean**"] + [f"**{mean_of(results, f):.3f} / "
                                f"{mean_of(results, f, 'heading_deg'):.3f} / "
                                f"{mean_of(results, f, 'inclination_deg'):.3f}**" for f in shown])
    return rep.table("total", header, rows)


def _worst_ratio(results: dict, names: list[str], f: FilterName) -> str:
    """Largest per-trial ratio of f's total RMSE to the VQF variant of its kind."""
    ref = _SAME_KIND_VQF[KIND[f]]
    if f == ref or (names[0], ref) not in results:
        return "—"
    r = [results[(n, f)]["total_deg"] / results[(n, ref)]["total_deg"] for n in names]
    i = int(np.argmax(r))
    return f"{r[i]:.2f} ({names[i][:2]}) vs {ref}"


def _summary(rep: Report, names: list[str], ran: list[FilterName], results: dict,
             timing: dict) -> str:
    rows = []
    for f in ran:
        tot = [results[(n, f)]["total_deg"] for n in names]
        samples, sec = timing[f]
        rows.append([f, KIND[f], f"{np.mean(tot):.3f}", f"{mean_of(results, f, 'heading_deg'):.3f}",
                     f"{mean_of(results, f, 'inclination_deg'):.3f}",
                     f"{min(tot):.3f} … {max(tot):.3f}", _worst_ratio(results, names, f),
                     f"{samples / sec:.3g}" if sec > 0 else "—"])
    return rep.table("summary", ["filter", "kind", "mean total (°)", "mean heading (°)",
                                 "mean inclination (°)", "range of total (°)",
                                 "worst trial / same-kind VQF", "samples/s"], rows)


def _gating_study(names: list[str], results: dict) -> str:
    """What the gating does on the disturbed trials (both accelerometer models)."""
    disturbed = [n for n in names if "disturbed" in n and "undisturbed" not in n]
    if not disturbed or (disturbed[0], "strapdown EKF, no gating") not in results:
        return ""
    lines = []
    for n in disturbed:
        for model, on, off in (("low-pass model", "strapdown EKF", "strapdown EKF, no gating"),
                               ("raw model", "strapdown EKF, raw acc",
                                "strapdown EKF, raw acc, no gating")):
            a = results[(n, on)]["total_deg"]
            b = results[(n, off)]["total_deg"]
            lines.append(f"- {n}, {model}: {a:.3f}° with gating, {b:.3f}° without "
                         f"(gating changes the error by {(a - b) / b * 100:+.1f} %)")
    return ("\n## What the gating does on the disturbed trials\n\n" + "\n".join(lines)
            + "\n\nTapping disturbs the accelerometer with short spikes; the default model "
            "averages the specific force in the reference frame over seconds, so gating has "
            "little left to do there, while the paper's raw model takes every sample and needs "
            "the gate. A magnet disturbs the magnetometer for seconds to minutes: the norm/dip "
            "checks and the heading gate keep it out of the heading.\n")


def _chart(rep: Report, names: list[str], ran: list[FilterName], results: dict) -> str:
    shown = [f for f in COMPARED if f in ran]
    fig, axes = rep.plt.subplots(3, 1, figsize=(11, 9), sharex=True)
    width = 0.8 / max(len(shown), 1)
    x = np.arange(len(names))
    for ax, key, label in zip(axes, ("total_deg", "heading_deg", "inclination_deg"),
                              ("total", "heading", "inclination"), strict=True):
        for i, f in enumerate(shown):
            ax.bar(x + (i - (len(shown) - 1) / 2) * width, [results[(n, f)][key] for n in names],
                   width, label=f"{f} ({KIND[f]})", hatch="//" if KIND[f] == "acausal" else None)
        ax.set_ylabel(f"{label} RMSE (°)")
        ax.grid(axis="y", alpha=0.3)
    axes[0].set_title("BROAD trials: RMSE over movement phases (BROAD's metric)")
    axes[0].legend(fontsize=8, ncol=len(shown))
    axes[-1].set_xticks(x, [n[:2] + " " + n[3:].replace("_", " ")[:24] for n in names],
                        rotation=30, ha="right", fontsize=7)
    return f"\n![errors]({rep.figure('errors.png', fig)})\n"


def benchmark(directory: str | os.PathLike[str], out: str | os.PathLike[str], *,
              algorithm: str = "rate-single", heading_offset_removed: bool = False,
              config: AhrsConfig | None = None,
              progress: Callable[[str], None] | None = None) -> dict:
    """Run every filter on every trial; returns ``{(trial, filter): errors}`` (the keys of
    :func:`strapdown.analysis.broad.broad_errors`, plus ``samples_per_s``) and writes the
    report to ``out``. ``config``: our filters' options (default :class:`AhrsConfig`; the
    ablations change theirs on top of it), named in the report (:func:`config_note`)."""
    from strapdown.io.broad import broad_hint

    if not str(directory):  # "$STRAPDOWN_BROAD" with the variable unset
        raise ValueError(f"no directory of BROAD trials given; {broad_hint()}")
    directory = Path(directory)
    if not directory.is_dir():
        raise ValueError(f"{directory}: not a directory; {broad_hint()}")
    files = sorted(directory.glob("*.mat"))
    if not files:
        raise ValueError(f"{directory}: no BROAD trials (*.mat); {broad_hint()}")
    rep = Report.begin(out, progress)
    missing = {f: why for f in FILTERS if (why := _available(f))}
    ran = [f for f in FILTERS if f not in missing]
    results, timing = _run_all(files, ran, rep, algorithm, heading_offset_removed,
                               config)
    names = [p.stem for p in files]
    md = ["# AHRS on BROAD: strapdown's EKF against VQF and Fusion\n\n",
          "Data: BROAD (Laidig, Caruso, Cereatti & Seel, Data 6(7), 2021; CC BY 4.0), "
          f"{len(names)} trials. Metrics: BROAD's as published (broad_utils.calculateRMSE): "
          "RMSE over movement phases of the error quaternion q_imu ⊗ q_opt*, one estimate per "
          "sample, no heading offset removed (the optical reference is in the magnetic ENU "
          "frame); total, heading (rotation about the vertical) and inclination (the rest), "
          "degrees. Causal: the estimate at a sample uses no later sample (real time); "
          f"acausal: post-processing. Our propagation: {algorithm}; our filters with "
          f"{config_note(config)}; VQF with its defaults.\n\n"]
    if missing:
        md.append("Not run: " + "; ".join(f"{k} — {v}" for k, v in missing.items()) + "\n\n")
    md.append("## Mean over the trials\n\n" + _summary(rep, names, ran, results, timing))
    md.append("\n## Per trial: total / heading / inclination RMSE (°)\n\n"
              + _wide_table(rep, names, ran, results))
    md.append("\n## Every filter and ablation\n\n"
              + _long_table(rep, names, ran, results, heading_offset_removed))
    md.append(_gating_study(names, results))
    md.append(_chart(rep, names, ran, results))
    md.append(f"\nRun time {rep.elapsed():.0f} s.\n")
    rep.write("".join(md))
    for (_, f), e in results.items():
        e["samples_per_s"] = timing[f][0] / timing[f][1] if timing[f][1] > 0 else math.nan
    return results
