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

One seed draws one set of sensor errors and random motions, and the ratio of two filters'
errors on one recording spreads by a factor of about 1.4 from seed to seed; so by default
the suite runs :data:`SEEDS` seeds and reports, per scenario, the mean errors and the
geometric mean of the ratios with its standard error, the worst seed and on how many seeds
ours lost (:func:`seeds_rows`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from strapdown.ahrs import AhrsConfig
from strapdown.analysis.alignment import aligned_errors
from strapdown.analysis.broad import broad_errors
from strapdown.apps.ahrs_benchmark import KIND, FilterName, _available, config_note, run_filter
from strapdown.io.broad import BroadTrial
from strapdown.io.files import markdown_table
from strapdown.io.report import Report
from strapdown.truth.scenarios import Scenario, SimulatedRecording, record, suite

__all__ = ["FILTERS", "PAIRS", "SEEDS", "SETTLE_S", "SHORT_S", "evaluate", "generalisation",
           "ratio_cell", "ratios", "rows", "seeds_rows", "summary_table", "trial"]

#: The compared filters, causal then acausal, each beside its VQF.
FILTERS: tuple[FilterName, ...] = ("strapdown EKF", "VQF", "strapdown EKF offline",
                                   "offlineVQF")
#: Errors are taken from this time on (s): the filters' start-up is not scored.
SETTLE_S = 5.0
#: Length of the short versions (s), for quick checks.
SHORT_S = 12.0
#: Seeds run by default (0 … SEEDS − 1). Over five seeds the geometric mean of a ratio moved
#: by ±15 % with the seeds drawn (the causal hand-held: 1.29 over seeds 0–4, 1.01 over 0–19).
SEEDS = 20
#: Each of ours with the VQF of the same kind: causal, then acausal.
PAIRS = (("strapdown EKF", "VQF"), ("strapdown EKF offline", "offlineVQF"))


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


def _header() -> list[str]:
    """The per-scenario tables' header: each filter with its kind, then the two ratios."""
    return ["scenario"] + [f"{f} ({KIND[f]})" for f in FILTERS] + [
        "ours/VQF causal", "ours/VQF offline"]


def _mean_cell(errors: Sequence[dict]) -> str:
    """``total / inclination`` (°), each the mean over ``errors`` (``broad_errors``
    records); a dash for none."""
    if not errors:
        return "—"
    return (f"{np.mean([e['total_deg'] for e in errors]):.2f} / "
            f"{np.mean([e['inclination_deg'] for e in errors]):.2f}")


def rows(results: dict, names: Sequence[str]) -> tuple[list[str], list[list[str]]]:
    """The per-scenario table: total / inclination RMSE (°) of each filter, and ours/VQF of
    the same kind (total), one row per scenario and a row of means."""
    out = []
    for n in names:
        out.append([n] + [_mean_cell([results[(n, f)]] if (n, f) in results else [])
                          for f in FILTERS]
                   + [f"{_ratio(results, n, a, b):.2f}" for a, b in PAIRS])
    mean_cells = [_mean_cell([results[(n, f)] for n in names if (n, f) in results])
                  for f in FILTERS]
    mean_ratio = []
    for a, b in PAIRS:
        r = [_ratio(results, n, a, b) for n in names]
        mean_ratio.append(f"{np.exp(np.nanmean(np.log(r))):.2f} (geo.)" if r else "—")
    out.append(["**mean**", *mean_cells, *mean_ratio])
    return _header(), out


def ratios(per_seed: Mapping[int, dict], name: str, ours: str, peer: str) -> list[float]:
    """Ours over ``peer`` (total RMSE) on scenario ``name``, one per seed where both ran."""
    return [r[(name, ours)]["total_deg"] / r[(name, peer)]["total_deg"]
            for r in per_seed.values() if (name, ours) in r and (name, peer) in r]


def ratio_cell(rs: Sequence[float]) -> str:
    """``geo ±se% (worst; lost/n)``: the geometric mean of the ratios, its standard error
    (of the mean of the logs, in per cent; none for one seed), the worst ratio, and on how
    many seeds ours lost."""
    if not rs:
        return "—"
    lr = np.log(np.asarray(rs, dtype=float))
    se = (f" ±{100 * math.expm1(float(np.std(lr, ddof=1)) / math.sqrt(lr.size)):.0f}%"
          if lr.size > 1 else "")
    return (f"{math.exp(lr.mean()):.2f}{se} ({max(rs):.2f}; "
            f"{sum(r > 1 for r in rs)}/{len(rs)})")


def seeds_rows(per_seed: Mapping[int, dict], names: Sequence[str]
               ) -> tuple[list[str], list[list[str]]]:
    """The per-scenario table over seeds (``per_seed``: :func:`evaluate`'s results by seed):
    each filter's mean total / inclination RMSE (°) over the seeds, and each ratio of ours
    over the VQF of the same kind as :func:`ratio_cell`."""
    out = []
    for n in names:
        cells = [n] + [_mean_cell([r[(n, f)] for r in per_seed.values() if (n, f) in r])
                       for f in FILTERS]
        out.append(cells + [ratio_cell(ratios(per_seed, n, a, b)) for a, b in PAIRS])
    return _header(), out


def summary_table(results: dict, names: Sequence[str]) -> str:
    """:func:`rows` as a Markdown table."""
    return markdown_table(*rows(results, names))


def generalisation(out: str | os.PathLike[str], *, seeds: Sequence[int] = range(SEEDS),
                   short: bool = False, config: AhrsConfig | None = None,
                   progress: Callable[[str], None] | None = None) -> dict[int, dict]:
    """Run :func:`evaluate` on the suite for each of ``seeds`` and write ``report.md`` and
    the tables to ``out``; returns the results by seed. ``config``: our filters' options
    (default :class:`~strapdown.ahrs.AhrsConfig`), named in the report.

    One seed: ``generalisation.csv``/``.md``, that seed's per-scenario table (:func:`rows`).
    Several: ``generalisation.csv``/``.md``, the table over the seeds (:func:`seeds_rows`),
    ``ratios.csv``/``.md``, every seed's ratios, and ``ratios.png``, their spread.
    ``errors.csv``/``.md``: every filter's total, heading and inclination RMSE, long form."""
    seeds = [int(s) for s in seeds]
    if not seeds or len(set(seeds)) != len(seeds):
        raise ValueError(f"seeds must be distinct and at least one, got {seeds}")
    rep = Report.begin(out, progress)
    per_seed: dict[int, dict] = {}
    for seed in seeds:
        scenarios = suite(seed)
        say = rep.say if len(seeds) == 1 else (lambda m, s=seed: rep.say(f"seed {s}: {m}"))
        per_seed[seed] = evaluate(scenarios, seed=seed, duration_s=SHORT_S if short else None,
                                  config=config, progress=say)
    names = [s.name for s in scenarios]
    if len(seeds) == 1:
        header, body = rows(per_seed[seeds[0]], names)
    else:
        header, body = seeds_rows(per_seed, names)
    table = rep.table("generalisation", header, body)
    long = rep.table("errors", ["seed", "scenario", "filter", "kind", "total (°)",
                                "heading (°)", "inclination (°)"],
                     [[seed, n, f, KIND[f], f"{e['total_deg']:.3f}", f"{e['heading_deg']:.3f}",
                       f"{e['inclination_deg']:.3f}"]
                      for seed, res in per_seed.items() for (n, f), e in res.items()])
    missing = [f for f in FILTERS if _available(f) is not None]
    which = (f"Seed {seeds[0]}" if len(seeds) == 1 else
             f"Seeds {_seed_list(seeds)} ({len(seeds)})")
    md = ["# AHRS generalisation suite: simulated recordings with truth\n\n",
          f"{which}{', short versions (' + f'{SHORT_S:g}' + ' s)' if short else ''}. "
          "Metric: BROAD's (total / inclination RMSE, degrees, no alignment: the truth is "
          f"in the estimates' magnetic ENU frame) from {SETTLE_S:g} s on. Ratio: ours over "
          "the VQF of the same kind, total RMSE. Our filters with "
          f"{config_note(config)}; VQF with its defaults.\n\n"]
    if missing:
        md.append("Not run: " + ", ".join(f"{f} ({_available(f)})" for f in missing) + "\n\n")
    md.append("## Scenarios\n\n" + "".join(f"- `{s.name}` — {s.describe()}\n"
                                           for s in scenarios))
    if len(seeds) > 1:
        md.append("\nThe motions' random parts and the sensor errors are drawn per seed; "
                  "described above is the last seed's.\n")
    md.append("\n## Total / inclination RMSE (°)\n\n")
    if len(seeds) == 1:
        md.append("Mean row: mean errors, geometric mean of the ratios. One seed draws one "
                  "set of sensor errors: a ratio on one recording spreads by a factor of "
                  "about 1.4 from seed to seed, so run several (the default) to rank the "
                  "filters.\n\n")
    else:
        md.append("Cells: mean over the seeds. Ratios: geometric mean over the seeds "
                  "± its standard error (of the mean of the logs), then the worst seed and "
                  "on how many seeds ours lost.\n\n")
    md.append(table)
    if len(seeds) > 1:
        per = rep.table("ratios", ["seed", "scenario", "ours/VQF causal", "ours/VQF offline"],
                        [[seed, n] + [_fmt_ratio(res, n, a, b) for a, b in PAIRS]
                         for seed, res in per_seed.items() for n in names])
        md.append("\n![ours over VQF per seed](" + rep.figure("ratios.png", _ratio_figure(
            per_seed, names)) + ")\n")
        md.append("\n## Every seed's ratios\n\n" + per)
    md.append("\n## Every filter: total, heading, inclination\n\n" + long)
    md.append(f"\nRun time {rep.elapsed():.0f} s.\n")
    rep.write("".join(md))
    return per_seed


def _seed_list(seeds: Sequence[int]) -> str:
    """``0–19`` for a run of consecutive seeds, else the seeds joined by commas."""
    if list(seeds) == list(range(seeds[0], seeds[0] + len(seeds))):
        return f"{seeds[0]}–{seeds[-1]}"
    return ", ".join(map(str, seeds))


def _fmt_ratio(results: dict, name: str, ours: str, peer: str) -> str:
    r = _ratio(results, name, ours, peer)
    return "—" if math.isnan(r) else f"{r:.3f}"


def _ratio_figure(per_seed: Mapping[int, dict], names: Sequence[str]):
    """Each scenario's ratios, one dot per seed, causal and offline side by side, the
    geometric mean a bar; log scale, 1 marked."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.0, 4.2))
    for j, ((a, b), colour, label) in enumerate(zip(PAIRS, ("C0", "C1"),
                                                    ("causal", "offline"), strict=True)):
        for i, n in enumerate(names):
            rs = ratios(per_seed, n, a, b)
            if not rs:
                continue
            x = i + (j - 0.5) * 0.3
            ax.plot(np.full(len(rs), x), rs, ".", color=colour, alpha=0.5,
                    label=label if i == 0 else None)
            g = math.exp(float(np.mean(np.log(rs))))
            ax.plot([x - 0.12, x + 0.12], [g, g], "-", color=colour, lw=2.5)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right")
    ax.set_ylabel("ours / VQF of the same kind (total RMSE)")
    ax.set_title(f"{len(per_seed)} seeds; bars: geometric means")
    ax.legend()
    return fig
