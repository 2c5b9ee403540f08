"""The AHRS generalisation suite over several seeds: our filter and VQF on simulated recordings.

Usage: ``python benchmarks/ahrs_generalisation.py [--seeds 0 1 … 19] [--aligned]
[--hard-iron F --soft-iron F] [--gyro-scale SD --gyro-misalignment SD]
[--acc-scale SD --acc-misalignment SD] [--acc-sample interval] [--gyro-clip F]
[--set FIELD=VALUE ...] [--out reports/ahrs_generalisation.json]``.

Each seed draws the sensor errors and the random parts of the motions
(:func:`strapdown.truth.scenarios.suite`, :func:`~strapdown.truth.scenarios.record`); each
scenario is run by ``strapdown EKF`` and ``VQF`` (causal), ``strapdown EKF offline`` and
``offlineVQF`` (acausal), scored by BROAD's metric from 5 s on
(:func:`strapdown.apps.ahrs_generalisation.evaluate`); with ``--aligned``, after fitting a
constant world and body rotation to each estimate instead (the metric of the issue's held-back
recordings). Prints, per scenario, the mean over the seeds of total / inclination RMSE and
the geometric mean of ours/VQF (total) with its standard error, the worst seed's ratio and
the number of seeds on which ours lost, as ``strapdown benchmark-ahrs --suite generalisation``
does (:func:`strapdown.apps.ahrs_generalisation.seeds_rows`), with the sensor errors below.

``--hard-iron F --soft-iron F`` gives every filter an uncalibrated magnetometer instead
(:func:`uncalibrated`): the recorded field ``m`` becomes ``S m + F_h |m|_med d``, ``d`` a
random unit vector in the body, ``S = I + F_s U``, ``U`` uniform in (−1, 1) per entry, drawn
per seed and recording (docs/reproductions.md, "A magnetometer that is not calibrated").
``--gyro-scale SD --gyro-misalignment SD`` gives every filter an uncalibrated gyro: scale-factor
and cross-axis errors of these standard deviations drawn per seed and recording
(``Sensors.gyro_scale_sd``, ``gyro_misalignment_sd``; a consumer MEMS gyro untrimmed: about
0.01 and 0.005; docs/reproductions.md, "A gyro that is not calibrated").
``--acc-scale SD --acc-misalignment SD`` does the same to the accelerometer
(``Sensors.acc_scale_sd``, ``acc_misalignment_sd``; a consumer MEMS accelerometer trimmed:
about 0.005 and 0.005; docs/reproductions.md, "An accelerometer that is not calibrated").
``--gyro-clip F`` gives every filter a gyro clipped at ``F`` times each recording's largest
|rate| (:func:`clipped_gyro`; a gyro past its range, docs/reproductions.md, "A gyro past its
range": the 0.3 m pendulum at 0.6 and 0.8; the other scenarios' peaks lie below 2 rad/s, under
any gyro's range, or their plateaus are not found).
``--set FIELD=VALUE`` (repeatable) changes our filters' options (an ``AhrsConfig`` field,
typed by it; e.g. ``--set gyro_scale_sigma=0.01``); VQF's stay its defaults.
``--acc-sample interval`` records every accelerometer sample as the mean specific force over
its period, like the gyro's (``Sensors.acc_sample``; the suite's are point samples).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

from strapdown.ahrs import AhrsConfig
from strapdown.apps.ahrs_generalisation import FILTERS, PAIRS, SEEDS, evaluate, ratios, seeds_rows
from strapdown.cli._common import ahrs_config_fields
from strapdown.io.files import markdown_table
from strapdown.truth.scenarios import SimulatedRecording, suite


def uncalibrated(rec: SimulatedRecording, hard: float, soft: float,
                 rng: np.random.Generator) -> SimulatedRecording:
    """``rec`` with its recorded field ``m`` (noise included) turned into ``S m + b``: ``b``
    of ``hard`` times the median of ``|m|`` along a random body direction, ``S = I + soft U``
    with ``U`` uniform in (−1, 1) per entry."""
    d = rng.standard_normal(3)
    d /= np.linalg.norm(d)
    S = np.eye(3) + soft * rng.uniform(-1.0, 1.0, (3, 3))
    b = hard * float(np.median(np.linalg.norm(rec.mag, axis=1))) * d
    return dataclasses.replace(rec, mag=rec.mag @ S.T + b)


def clipped_gyro(rec: SimulatedRecording, fraction: float) -> SimulatedRecording:
    """``rec`` with its recorded gyro (noise and bias included) clipped at ``fraction`` of
    its largest |rate| on any axis, as a gyro whose range is that is."""
    level = fraction * float(np.abs(rec.gyro).max())
    return dataclasses.replace(rec, gyro=np.clip(rec.gyro, -level, level))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=list(range(SEEDS)))
    ap.add_argument("--aligned", action="store_true",
                    help="score after fitting a constant world and body rotation")
    ap.add_argument("--hard-iron", type=float, default=0.0,
                    help="a hard-iron offset, a fraction of the field's norm (e.g. 0.3)")
    ap.add_argument("--soft-iron", type=float, default=0.0,
                    help="soft-iron scaling: entries of S - I uniform within ± this (e.g. 0.1)")
    ap.add_argument("--gyro-scale", type=float, default=0.0,
                    help="the gyro's scale-factor errors, standard deviation (e.g. 0.01)")
    ap.add_argument("--gyro-misalignment", type=float, default=0.0,
                    help="its cross-axis sensitivities, standard deviation (e.g. 0.005)")
    ap.add_argument("--acc-scale", type=float, default=0.0,
                    help="the accelerometer's scale-factor errors, standard deviation "
                    "(e.g. 0.005)")
    ap.add_argument("--acc-misalignment", type=float, default=0.0,
                    help="its cross-axis sensitivities, standard deviation (e.g. 0.005)")
    ap.add_argument("--acc-sample", choices=["point", "interval"], default="point",
                    help="the simulated accelerometer's samples: at the stamps (the suite's) "
                    "or means over each period, like the gyro's")
    ap.add_argument("--gyro-clip", type=float, default=0.0,
                    help="clip the gyro at this fraction of each recording's peak rate "
                    "(e.g. 0.6; default: not clipped)")
    ap.add_argument("--set", dest="config", action="append", default=[],
                    metavar="FIELD=VALUE", help="an AhrsConfig field of our filters (repeatable)")
    ap.add_argument("--out", default=None, help="write every figure as JSON here")
    args = ap.parse_args(argv)
    try:
        config = AhrsConfig(**ahrs_config_fields(args.config))
    except ValueError as exc:
        ap.error(str(exc))
    if not 0.0 <= args.gyro_clip < 1.0:
        ap.error(f"--gyro-clip must lie in [0, 1): a fraction of the peak rate, got "
                 f"{args.gyro_clip}")
    per_seed = {}
    names: list[str] = []
    for seed in args.seeds:
        print(f"seed {seed}", file=sys.stderr)
        scenarios = [dataclasses.replace(sc, sensors=dataclasses.replace(
            sc.sensors, acc_sample=args.acc_sample, gyro_scale_sd=args.gyro_scale,
            gyro_misalignment_sd=args.gyro_misalignment, acc_scale_sd=args.acc_scale,
            acc_misalignment_sd=args.acc_misalignment)) for sc in suite(seed)]
        names = [s.name for s in scenarios]
        alter = None
        if args.hard_iron or args.soft_iron or args.gyro_clip:
            def alter(rec, k, seed=seed):
                if args.hard_iron or args.soft_iron:
                    rng = np.random.default_rng(1000 + 17 * seed + k)
                    rec = uncalibrated(rec, args.hard_iron, args.soft_iron, rng)
                return clipped_gyro(rec, args.gyro_clip) if args.gyro_clip else rec
        per_seed[seed] = evaluate(scenarios, seed=seed, aligned=args.aligned, alter=alter,
                                  config=config)
    print(markdown_table(*seeds_rows(per_seed, names)), end="")
    record = []
    for n in names:
        entry: dict = {"scenario": n}
        for f in FILTERS:
            entry[f] = {k: [r[(n, f)][k] for r in per_seed.values() if (n, f) in r]
                        for k in ("total_deg", "inclination_deg")}
        for a, b in PAIRS:
            entry[f"{a} / {b}"] = ratios(per_seed, n, a, b)
        record.append(entry)
    metric = ("after fitting a constant world and body rotation" if args.aligned
              else "BROAD's metric")
    print(f"\ncells: mean over seeds {args.seeds} of total / inclination RMSE (°, {metric}, "
          "from 5 s); ratios: geometric mean over the seeds ±its standard error (worst seed; "
          "seeds on which ours lost)")
    if args.hard_iron or args.soft_iron:
        print(f"magnetometer uncalibrated: hard iron {args.hard_iron:g} of the field's norm, "
              f"soft iron ±{args.soft_iron:g}")
    if args.gyro_scale or args.gyro_misalignment:
        print(f"gyro uncalibrated: scale factors ±{args.gyro_scale:g}, cross-axis "
              f"±{args.gyro_misalignment:g} (standard deviations)")
    if args.acc_scale or args.acc_misalignment:
        print(f"accelerometer uncalibrated: scale factors ±{args.acc_scale:g}, cross-axis "
              f"±{args.acc_misalignment:g} (standard deviations)")
    if args.gyro_clip:
        print(f"gyro clipped at {args.gyro_clip:g} of each recording's peak rate")
    if args.config:
        print("our filters with " + ", ".join(args.config))
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps({"seeds": args.seeds, "scenarios": record},
                                             indent=2, ensure_ascii=False), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
