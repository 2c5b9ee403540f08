"""The AHRS generalisation suite: our filter and VQF on simulated recordings with truth.

Every scenario of :func:`strapdown.truth.scenarios.suite` (pendulums, a turning vehicle, a
loitering aircraft, spin-coning, hand-held shaking, a steel door frame, stationary rests) is
sampled once (:func:`strapdown.truth.scenarios.record`, sensor errors from ``seed``) and
given, as the same arrays, to the filters of :mod:`strapdown.apps.ahrs_benchmark` with the
conventions of its BROAD benchmark (:func:`~strapdown.apps.ahrs_benchmark.run_filter`):

- ``strapdown EKF`` (causal) and ``strapdown EKF offline`` (acausal), their defaults;
- ``VQF`` (causal, ``vqf.VQF(Ts).updateBatch``, 9D) and ``offlineVQF`` (acausal).

Metric: BROAD's (:func:`strapdown.analysis.broad.broad_errors`): total, heading and
inclination RMSE (degrees) of ``q_est ⊗ q_true*``, nothing aligned — the truth is in the
same magnetic ENU frame as the estimates (the field points north, no declination) — over
the samples from :data:`SETTLE_S` on. The ratio is ours over the VQF of the same kind.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence

import numpy as np

from strapdown.ahrs import AhrsConfig
from strapdown.analysis.alignment import aligned_errors
from strapdown.analysis.broad import broad_errors
from strapdown.apps.ahrs_benchmark import KIND, FilterName, _available, config_note, run_filter
from strapdown.io.broad import BroadTrial
from strapdown.io.report import Report
from strapdown.truth.scenarios import Scenario, SimulatedRecording, record, suite

__all__ = ["FILTERS", "SETTLE_S", "SHORT_S", "evaluate", "generalisation", "rows",
           "summary_table", "trial"]

#: The compared filters, causal then acausal, each beside its VQF.
FILTERS: tuple[FilterName, ...] = ("strapdown EKF", "VQF", "strapdown EKF offline",
                                   "offlineVQF")
#: Errors are taken from this time on (s): the filters' start-up is not scored.
SETTLE_S = 5.0
#: Length of the short versions (s), for quick checks.
SHORT_S = 12.0
_PAIRS = (("strapdown EKF", "VQF"), ("strapdown EKF offline", "offlineVQF"))


def trial(rec: SimulatedRecording, settle_s: float = SETTLE_S) -> BroadTrial:
    """A recording as the BROAD benchmark's trial: its arrays, the truth as the reference,
    "movement" from ``settle_s`` on."""
    return BroadTrial(rec.name, rec.t, np.ascontiguousarray(rec.gyro),
                      np.ascontiguousarray(rec.acc), np.ascontiguousarray(rec.mag),
                      rec.q_n_b, rec.t >= settle_s)


def evaluate(scenarios: Sequence[Scenario] | None = None, *, seed: int = 0,
             duration_s: float | None = None, filters: Sequence[FilterName] = FILTERS,
             progress: Callable[[str], None] | None = None, aligned: bool = False,
             alter: Callable[[SimulatedRecording, int], SimulatedRecording] | None = None,
             config: AhrsConfig | None = None) -> dict:
    """Each filter on each scenario: ``{(scenario, filter): broad_errors(...)}``.

    ``duration_s`` shortens every recording (e.g. :data:`SHORT_S`); a filter whose package
    is missing is skipped (its entries absent). ``aligned``: scored instead after fitting
    a constant world and body rotation to each estimate
    (:func:`strapdown.analysis.alignment.aligned_errors`, the metric of the issue's
    held-back recordings), which forgives a constant offset but not a drift. ``alter(rec,
    k)`` replaces each recording (``k`` its index in the suite) before the filters run: a
    sensor error the suite does not model, such as an uncalibrated magnetometer.
    ``config``: our filters' options (default :class:`~strapdown.ahrs.AhrsConfig`)."""
    scenarios = suite(seed) if scenarios is None else scenarios
    say = progress or (lambda _m: None)
    ran = [f for f in filters if _available(f) is None]
    out: dict = {}
    for k, sc in enumerate(scenarios):
        dur = None if duration_s is None else min(duration_s, sc.duration_s)
        rec = record(sc, np.random.SeedSequence([seed, k]), duration_s=dur)
        if alter is not None:
            rec = alter(rec, k)
        tr = trial(rec)
        for f in ran:
            say(f"{sc.name}: {f}")
            q = run_filter(f, tr, config=config)
            out[(sc.name, f)] = (aligned_errors if aligned else broad_errors)(
                q, rec.q_n_b, tr.movement)
    return out


def _ratio(results: dict, name: str, ours: str, peer: str, key: str = "total_deg") -> float:
    if (name, ours) not in results or (name, peer) not in results:
        return math.nan
    return results[(name, ours)][key] / results[(name, peer)][key]


def rows(results: dict, names: Sequence[str]) -> tuple[list[str], list[list[str]]]:
    """The per-scenario table: total / inclination RMSE (°) of each filter, and ours/VQF of
    the same kind (total), one row per scenario and a row of means."""
    header = ["scenario"] + [f"{f} ({KIND[f]})" for f in FILTERS] + [
        "ours/VQF causal", "ours/VQF offline"]

    def cell(n: str, f: str) -> str:
        e = results.get((n, f))
        return "—" if e is None else f"{e['total_deg']:.2f} / {e['inclination_deg']:.2f}"

    out = []
    for n in names:
        out.append([n] + [cell(n, f) for f in FILTERS]
                   + [f"{_ratio(results, n, a, b):.2f}" for a, b in _PAIRS])
    means = {f: [results[(n, f)] for n in names if (n, f) in results] for f in FILTERS}
    mean_cells = [f"{np.mean([e['total_deg'] for e in v]):.2f} / "
                  f"{np.mean([e['inclination_deg'] for e in v]):.2f}" if v else "—"
                  for v in means.values()]
    mean_ratio = []
    for a, b in _PAIRS:
        r = [_ratio(results, n, a, b) for n in names]
        mean_ratio.append(f"{np.exp(np.nanmean(np.log(r))):.2f} (geo.)" if r else "—")
    out.append(["**mean**", *mean_cells, *mean_ratio])
    return header, out


def summary_table(results: dict, names: Sequence[str]) -> str:
    """:func:`rows` as a Markdown table."""
    header, body = rows(results, names)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in body]
    return "\n".join(lines) + "\n"


def generalisation(out: str | os.PathLike[str], *, seed: int = 0, short: bool = False,
                   config: AhrsConfig | None = None,
                   progress: Callable[[str], None] | None = None) -> dict:
    """Run :func:`evaluate` on the suite and write ``report.md`` and the tables
    (``generalisation.csv``/``.md``: per scenario; ``errors.csv``/``.md``: long form) to
    ``out``; returns the results. ``config``: our filters' options (default
    :class:`~strapdown.ahrs.AhrsConfig`), named in the report."""
    rep = Report.begin(out, progress)
    scenarios = suite(seed)
    results = evaluate(scenarios, seed=seed, duration_s=SHORT_S if short else None,
                       config=config, progress=rep.say)
    names = [s.name for s in scenarios]
    header, body = rows(results, names)
    table = rep.table("generalisation", header, body)
    long = rep.table("errors", ["scenario", "filter", "kind", "total (°)", "heading (°)",
                                "inclination (°)"],
                     [[n, f, KIND[f], f"{e['total_deg']:.3f}", f"{e['heading_deg']:.3f}",
                       f"{e['inclination_deg']:.3f}"]
                      for (n, f), e in results.items()])
    missing = [f for f in FILTERS if _available(f) is not None]
    md = ["# AHRS generalisation suite: simulated recordings with truth\n\n",
          f"Seed {seed}{', short versions (' + str(SHORT_S) + ' s)' if short else ''}. "
          "Metric: BROAD's (total / inclination RMSE, degrees, no alignment: the truth is "
          f"in the estimates' magnetic ENU frame) from {SETTLE_S:g} s on. Ratio: ours over "
          "the VQF of the same kind, total RMSE (mean row: geometric mean). Our filters with "
          f"{config_note(config)}; VQF with its defaults.\n\n"]
    if missing:
        md.append("Not run: " + ", ".join(f"{f} ({_available(f)})" for f in missing) + "\n\n")
    md.append("## Scenarios\n\n" + "".join(f"- `{s.name}` — {s.describe()}\n"
                                           for s in scenarios))
    md.append("\n## Total / inclination RMSE (°)\n\n" + table)
    md.append("\n## Every filter: total, heading, inclination\n\n" + long)
    md.append(f"\nRun time {rep.elapsed():.0f} s.\n")
    rep.write("".join(md))
    return results
