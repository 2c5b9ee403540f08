"""The OpenAXES robot recordings as a benchmark: our AHRS and VQF's 6-axis filter.

Data: Webering, Fahnemann & Stanislawski (2023), the OpenAXES example robot data set, as
re-packaged (synchronised to the reference) with the supplementary material of Bachhuber
et al. (2024), RING (:mod:`strapdown.io.openaxes`): an industrial robot moves two IMUs along
circles and triangles at four speeds, 125 Hz, no magnetometer. On every recording, from the
same arrays:

- ``strapdown EKF`` (causal) and ``strapdown EKF offline`` (acausal):
  :func:`strapdown.ahrs.ekf` and :func:`strapdown.ahrs.offline_ekf` with their defaults,
  no magnetometer;
- ``VQF`` (causal, ``vqf.VQF(Ts).updateBatch(gyr, acc)["quat6D"]``) and ``offlineVQF``
  (acausal, ``vqf.offlineVQF(gyr, acc, None, Ts, {})["quat6D"]``), their defaults.

Metric (:func:`strapdown.analysis.alignment.aligned_errors`): the reference is the link's
attitude in the robot's base frame, neither the IMU's axes nor ENU, so one constant world
and one constant body rotation are fitted to *each estimate* (the same least-squares fit
for every filter) over the samples from :data:`SETTLE_S` on, and the RMSE of what is left
is taken over the same samples: total angle and inclination (the tilt between the two
vertical axes), degrees. Without a magnetometer the heading drifts; what a constant world
rotation cannot remove of that drift stays in the total.

Suspect recordings (reported apart, out of the medians): the two the data set's notes name
(:data:`strapdown.io.openaxes.SUSPECT`) and any whose gyro does not see the reference's
motion (:func:`strapdown.io.openaxes.rate_agreement` below :data:`RATE_AGREEMENT_MIN`).
The medians are also given over the notes' split alone, for comparison.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from strapdown.ahrs import AccelerometerUnusedWarning, AhrsConfig, ekf, offline_ekf
from strapdown.analysis.alignment import aligned_errors
from strapdown.apps.ahrs_benchmark import KIND, FilterName, _available, config_note, vqf_attitude
from strapdown.io.openaxes import (
    SUSPECT,
    OpenAxesRecording,
    list_openaxes,
    rate_agreement,
    read_openaxes,
)
from strapdown.io.report import Report

__all__ = ["FILTERS", "RATE_AGREEMENT_MIN", "SETTLE_S", "evaluate", "openaxes", "rows",
           "run_filter", "summary_table", "suspect_reason"]

#: The compared filters, causal then acausal, each beside its VQF.
FILTERS: tuple[FilterName, ...] = ("strapdown EKF", "VQF", "strapdown EKF offline",
                                   "offlineVQF")
#: The fit and the errors use the samples from this time on (s).
SETTLE_S = 5.0
#: A recording whose gyro and reference rates correlate less than this is suspect.
RATE_AGREEMENT_MIN = 0.9
_PAIRS = (("strapdown EKF", "VQF"), ("strapdown EKF offline", "offlineVQF"))


def run_filter(name: FilterName, rec: OpenAxesRecording, *,
               config: AhrsConfig | None = None) -> NDArray[np.float64]:
    """One filter on one recording, 6-axis: its attitude at every sample, (n, 4). ``config``:
    our filters' options (default :class:`~strapdown.ahrs.AhrsConfig`)."""
    if name == "strapdown EKF":
        return ekf(rec.t, rec.gyro, rec.acc, config=config).q
    if name == "strapdown EKF offline":
        return offline_ekf(rec.t, rec.gyro, rec.acc, config=config).q
    if name in ("VQF", "offlineVQF"):
        return vqf_attitude(rec.gyro, rec.acc, None, rec.h, offline=name == "offlineVQF")
    raise ValueError(f"unknown filter {name!r}; choose one of {', '.join(FILTERS)}")


def suspect_reason(rec: OpenAxesRecording) -> str | None:
    """Why a recording is reported apart (None: it is not)."""
    r = rate_agreement(rec)
    why = []
    if rec.suspect:
        why.append("named by the data set's notes")
    if not r >= RATE_AGREEMENT_MIN:
        why.append(f"gyro and reference rates correlate {r:.2f}")
    return "; ".join(why) or None


def evaluate(directory: str | os.PathLike[str], *, names: Sequence[str] | None = None,
             filters: Sequence[FilterName] = FILTERS, settle_s: float = SETTLE_S,
             config: AhrsConfig | None = None,
             progress: Callable[[str], None] | None = None) -> tuple[dict, dict]:
    """Each filter on each recording of ``directory`` (or those of ``names``); ``config``:
    our filters' options (default :class:`~strapdown.ahrs.AhrsConfig`).

    Returns ``(results, suspects)``: ``{(recording, filter): aligned_errors(...)}``, each
    with ``"accelerometer_unused"``: whether the filter warned
    :class:`~strapdown.ahrs.AccelerometerUnusedWarning` (a filter whose package is missing
    is skipped) and ``{recording: suspect_reason}`` in the
    recordings' order."""
    say = progress or (lambda _m: None)
    found = list_openaxes(directory)
    if names is not None:
        known = {f"{d.name}-{link}" for d, link in found}
        unknown = [n for n in names if n not in known]
        if unknown:
            raise ValueError(f"no recordings {unknown} in {directory}; it holds "
                             f"{', '.join(sorted(known))}")
        found = [(d, link) for d, link in found if f"{d.name}-{link}" in names]
    ran = [f for f in filters if _available(f) is None]
    results: dict = {}
    suspects: dict = {}
    for d, link in found:
        rec = read_openaxes(d, link)
        suspects[rec.name] = suspect_reason(rec)
        mask = rec.t >= settle_s
        for f in ran:
            say(f"{rec.name}: {f}")
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", AccelerometerUnusedWarning)
                q = run_filter(f, rec, config=config)
            e = aligned_errors(q, rec.q_ref, mask)
            e["accelerometer_unused"] = any(
                issubclass(w.category, AccelerometerUnusedWarning) for w in caught)
            for w in caught:  # any other warning is the caller's, as before
                if not issubclass(w.category, AccelerometerUnusedWarning):
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            results[(rec.name, f)] = e
    return results, suspects


def _cell(results: dict, n: str, f: str) -> str:
    e = results.get((n, f))
    return "—" if e is None else f"{e['total_deg']:.2f} / {e['inclination_deg']:.2f}"


def _ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}" if b > 0 and math.isfinite(a / b) else "—"


def _median(results: dict, names: Sequence[str], f: str, key: str) -> float:
    v = [results[(n, f)][key] for n in names if (n, f) in results]
    return float(np.median(v)) if v else math.nan


def _median_row(results: dict, names: Sequence[str], label: str) -> list[str]:
    med: dict[tuple[str, str], float] = {(f, k): _median(results, names, f, k) for f in FILTERS
           for k in ("total_deg", "inclination_deg")}
    cells = [f"{med[(f, 'total_deg')]:.2f} / {med[(f, 'inclination_deg')]:.2f}"
             for f in FILTERS]
    ratios = [" / ".join(_ratio(med[(a, k)], med[(b, k)])
                         for k in ("total_deg", "inclination_deg")) for a, b in _PAIRS]
    return [label, *cells, *ratios]


def _worse_row(results: dict, names: Sequence[str]) -> list[str]:
    out = []
    for a, b in _PAIRS:
        both = [n for n in names if (n, a) in results and (n, b) in results]
        counts = [sum(results[(n, a)][k] > results[(n, b)][k] for n in both)
                  for k in ("total_deg", "inclination_deg")]
        out.append(f"{counts[0]} / {counts[1]} of {len(both)}")
    return ["**ours worse on**", *([""] * len(FILTERS)), *out]


def rows(results: dict, suspects: dict) -> tuple[list[str], list[list[str]]]:
    """The per-recording table: total / inclination RMSE (°) of each filter and ours/VQF of
    the same kind (total / inclination); the medians over the recordings not suspect (ratio
    of the medians), also over the data set's own split; how many recordings ours is worse
    on; then the suspect recordings."""
    header = ["recording"] + [f"{f} ({KIND[f]})" for f in FILTERS] + [
        "ours/VQF causal", "ours/VQF offline"]

    def row(n: str, label: str) -> list[str]:
        ratios = [" / ".join(_ratio(results[(n, a)][k], results[(n, b)][k])
                             if (n, a) in results and (n, b) in results else "—"
                             for k in ("total_deg", "inclination_deg")) for a, b in _PAIRS]
        return [label, *[_cell(results, n, f) for f in FILTERS], *ratios]

    good = [n for n, why in suspects.items() if why is None]
    notes = [n for n in suspects if n not in SUSPECT]
    body = [row(n, n) for n in good]
    body.append(_median_row(results, good, f"**median ({len(good)})**"))
    if len(notes) != len(good):
        body.append(_median_row(results, notes, f"median ({len(notes)}: the notes' split)"))
    body.append(_worse_row(results, good))
    body += [row(n, f"{n} (suspect)") for n, why in suspects.items() if why is not None]
    return header, body


def summary_table(results: dict, suspects: dict) -> str:
    """:func:`rows` as a Markdown table."""
    header, body = rows(results, suspects)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in body]
    return "\n".join(lines) + "\n"


def openaxes(directory: str | os.PathLike[str], out: str | os.PathLike[str], *,
             names: Sequence[str] | None = None, config: AhrsConfig | None = None,
             progress: Callable[[str], None] | None = None) -> tuple[dict, dict]:
    """Run :func:`evaluate` and write ``report.md`` and the tables (``openaxes.csv``/``.md``:
    per recording; ``errors.csv``/``.md``: every filter, total / heading / inclination, the
    fit's Newton steps) to ``out``; returns what :func:`evaluate` returns."""
    rep = Report.begin(out, progress)
    results, suspects = evaluate(directory, names=names, config=config, progress=rep.say)
    header, body = rows(results, suspects)
    table = rep.table("openaxes", header, body)
    long = rep.table("errors", ["recording", "filter", "kind", "total (°)", "heading (°)",
                                "inclination (°)", "fit steps"],
                     [[n, f, KIND[f], f"{e['total_deg']:.3f}", f"{e['heading_deg']:.3f}",
                       f"{e['inclination_deg']:.3f}", str(e["iterations"])]
                      for (n, f), e in results.items()])
    missing = [f for f in FILTERS if _available(f) is not None]
    md = ["# AHRS on the OpenAXES robot recordings (6-axis)\n\n",
          f"Data: {Path(directory)} — Webering, Fahnemann & Stanislawski (2023), OpenAXES "
          "example robot data set, as re-packaged with the supplementary material of "
          "Bachhuber et al. (2024), RING; 125 Hz, no magnetometer. Metric: a constant world "
          "and a constant body rotation fitted to each estimate (least squares, the same for "
          "every filter), then "
          f"total / inclination RMSE (degrees) from {SETTLE_S:g} s on. Ratios: ours over the "
          "VQF of the same kind (median rows: ratio of the medians). Our filters with "
          f"{config_note(config)}; VQF's 6-axis filter with its defaults.\n\n"]
    if missing:
        md.append("Not run: " + ", ".join(f"{f} ({_available(f)})" for f in missing) + "\n\n")
    md.append("## Total / inclination RMSE (°)\n\n" + table)
    md.append("\n## Suspect recordings (out of the medians)\n\n" + "".join(
        f"- `{n}`: {why}\n" for n, why in suspects.items() if why is not None))
    unused: dict[str, list[str]] = {}
    for (n, f), e in results.items():
        if e.get("accelerometer_unused"):
            unused.setdefault(n, []).append(f)
    if unused:
        md.append("\n## Accelerometer not used (`AccelerometerUnusedWarning`)\n\n"
                  "These recordings start in motion and no rest measured gravity's norm; "
                  "the accelerometer's norm lies beyond `acc_lowpass_norm_tol` from the "
                  "nominal g, so our filter skipped most accelerometer updates and its tilt "
                  "there is the gyro's alone:\n\n"
                  + "".join(f"- `{n}`: {', '.join(f)}\n" for n, f in unused.items()))
    md.append("\n## Every filter: total, heading, inclination\n\n" + long)
    md.append(f"\nRun time {rep.elapsed():.0f} s.\n")
    rep.write("".join(md))
    return results, suspects
