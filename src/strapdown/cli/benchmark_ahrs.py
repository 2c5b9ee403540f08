"""``strapdown benchmark-ahrs``: our AHRS against VQF and Fusion on BROAD trials, against VQF
on the simulated generalisation suite (``--suite generalisation``) or on the OpenAXES robot
recordings (``--suite openaxes``, 6-axis)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from strapdown.cli._common import progress, progress_args, say

if TYPE_CHECKING:
    from strapdown.ahrs import AhrsConfig

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``benchmark-ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "benchmark-ahrs", arguments=_arguments,
        help="our AHRS against VQF and Fusion on BROAD trials (BROAD's metric), on "
        "simulated scenarios with truth (--suite generalisation) or on the OpenAXES robot "
        "recordings (--suite openaxes)",
        description="Run strapdown's EKF, the open peers VQF (causal: VQF.updateBatch; "
        "acausal: offlineVQF) and Fusion (pip install 'strapdown[bench]'), and our filter's "
        "gating ablations on every BROAD trial in DIR; write per-trial and mean total, heading "
        "and inclination RMSE (BROAD's metric as published), each filter labelled causal or "
        "acausal, its throughput, and a bar chart. With --suite generalisation (no DIR): our "
        "filter and VQF, causal and offline, on simulated recordings with exact truth "
        "(pendulums, a turning vehicle, a loitering aircraft, spin-coning, hand-held shaking, "
        "a steel door frame, stationary rests); prints the per-scenario RMSE table. With "
        "--suite openaxes [DIR]: our filter and VQF's 6-axis filter, causal and offline, on "
        "every OpenAXES robot recording in DIR (default $STRAPDOWN_OPENAXES), each estimate "
        "aligned to the reference by a fitted constant world and body rotation; prints the "
        "per-recording table with the medians.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", nargs="?", default=None,
                   help="directory of BROAD .mat trials, or with --suite openaxes of the "
                   "OpenAXES motion folders (default $STRAPDOWN_OPENAXES); not with --suite "
                   "generalisation")
    p.add_argument("--suite", choices=("broad", "generalisation", "openaxes"), default="broad",
                   help="broad (default): the BROAD trials in DIR; generalisation: the "
                   "simulated scenarios of strapdown.truth.scenarios (needs no data); "
                   "openaxes: the OpenAXES robot recordings in DIR (6-axis)")
    p.add_argument("--out", default=None, help="output directory (default "
                   "reports/benchmark-ahrs, reports/benchmark-ahrs-generalisation or "
                   "reports/benchmark-ahrs-openaxes)")
    p.add_argument("--algorithm", default="rate-single",
                   help="our propagation algorithm (a spec, as for strapdown ahrs; BROAD only)")
    p.add_argument("--heading-offset-removed", action="store_true",
                   help="add a column with the total error after removing a constant heading "
                   "offset (not BROAD's metric; BROAD only)")
    seeds = p.add_mutually_exclusive_group()
    seeds.add_argument("--seeds", type=_seeds, default=None, metavar="SEEDS",
                       help="generalisation: the seeds of the sensor errors and random "
                       "motions, as FIRST-LAST or a comma list (e.g. 0-19, 3,7); the table "
                       "gives each scenario's mean errors and the geometric mean of the "
                       "ratios over them, its standard error, the worst seed and how many "
                       "ours lost (default: 0-19)")
    seeds.add_argument("--seed", type=int, default=None,
                       help="generalisation: one seed only (one draw of the sensor errors: "
                       "a ratio on one recording spreads by about 1.4x from seed to seed)")
    p.add_argument("--short", action="store_true",
                   help="generalisation: the first 12 s of each scenario only (a quick check)")
    p.add_argument("--set", dest="config", action="append", default=[], metavar="FIELD=VALUE",
                   help="an AhrsConfig field of our filters (repeatable; every suite), e.g. "
                   "--set gyro_scale_sigma=0.01; the peers keep their defaults and the report "
                   "names what was changed (default: none, our filters' defaults)")
    progress_args(p, "a line as each trial and filter runs")


def _seeds(text: str) -> list[int]:
    """``--seeds``: ``FIRST-LAST`` (inclusive) or a comma list of non-negative integers."""
    try:
        if "-" in text.strip().lstrip("-"):
            first, last = (int(x) for x in text.split("-"))
            out = list(range(first, last + 1))
        else:
            out = [int(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected FIRST-LAST or a comma list of seeds (e.g. 0-19 or 3,7), got {text!r}"
        ) from None
    if not out or min(out) < 0 or len(set(out)) != len(out):
        raise argparse.ArgumentTypeError(
            f"expected distinct non-negative seeds, FIRST <= LAST, got {text!r}")
    return out


def _config(args: argparse.Namespace) -> AhrsConfig | None:
    """Our filters' AhrsConfig from ``--set`` (None: no option given, the defaults)."""
    from strapdown.ahrs import AhrsConfig
    from strapdown.cli._common import ahrs_config_fields

    return AhrsConfig(**ahrs_config_fields(args.config)) if args.config else None


def _generalisation(args: argparse.Namespace, config: AhrsConfig | None) -> int:
    from strapdown.apps.ahrs_generalisation import SEEDS, generalisation, seeds_rows, summary_table
    from strapdown.io.files import markdown_table

    if args.dir is not None:
        raise ValueError("--suite generalisation takes no DIR (its recordings are simulated)")
    seeds = ([args.seed] if args.seed is not None else
             args.seeds if args.seeds is not None else list(range(SEEDS)))
    out = args.out or "reports/benchmark-ahrs-generalisation"
    res = generalisation(out, seeds=seeds, short=args.short, config=config,
                         progress=say if progress(args) else None)
    names = list(dict.fromkeys(n for n, _ in res[seeds[0]]))
    if len(seeds) == 1:
        print(summary_table(res[seeds[0]], names), end="")
        print(f"seed {seeds[0]}; cells: total / inclination RMSE (°, BROAD's metric, from "
              "5 s); ratio: ours/VQF of the same kind, total")
    else:
        print(markdown_table(*seeds_rows(res, names)), end="")
        print(f"{len(seeds)} seeds; cells: mean total / inclination RMSE (°, BROAD's metric, "
              "from 5 s); ratios: ours/VQF of the same kind, total, geometric mean over the "
              "seeds ±its standard error (worst seed; seeds on which ours lost)")
    print(f"wrote {out}/report.md")
    return 0


def _openaxes(args: argparse.Namespace, config: AhrsConfig | None) -> int:
    import os

    from strapdown.apps.ahrs_openaxes import SETTLE_S, openaxes, summary_table
    from strapdown.io.openaxes import ENV

    directory = args.dir if args.dir is not None else os.environ.get(ENV, "")
    out = args.out or "reports/benchmark-ahrs-openaxes"
    results, suspects = openaxes(directory, out, config=config,
                                 progress=say if progress(args) else None)
    print(summary_table(results, suspects), end="")
    print(f"cells: total / inclination RMSE (°) after fitting a constant world and body "
          f"rotation to each estimate, from {SETTLE_S:g} s on; ratios: ours / VQF of the same "
          "kind, total / inclination (median rows: ratio of the medians)")
    print(f"wrote {out}/report.md")
    return 0


def run(args: argparse.Namespace) -> int:
    """Run the benchmark and print each filter's mean RMSE and throughput (BROAD) or the
    per-scenario (generalisation) or per-recording (openaxes) table."""
    config = _config(args)
    if config is not None:
        from strapdown.apps.ahrs_benchmark import config_note

        print(f"our filters with {config_note(config)}")
    if args.suite == "generalisation":
        return _generalisation(args, config)
    if args.suite == "openaxes":
        return _openaxes(args, config)
    from strapdown.apps.ahrs_benchmark import FILTERS, KIND, benchmark, mean_of

    out = args.out or "reports/benchmark-ahrs"
    res = benchmark("" if args.dir is None else args.dir, out, algorithm=args.algorithm,
                    heading_offset_removed=args.heading_offset_removed, config=config,
                    progress=say if progress(args) else None)
    for f in FILTERS:
        m = mean_of(res, f)
        if m == m:  # NaN: the filter did not run (peer not installed)
            rate = next(e["samples_per_s"] for (_, g), e in res.items() if g == f)
            print(f"{f:34s} {KIND[f]:8s} mean RMSE total {m:.3f}°, heading "
                  f"{mean_of(res, f, 'heading_deg'):.3f}°, inclination "
                  f"{mean_of(res, f, 'inclination_deg'):.3f}°; {rate:.3g} samples/s")
    print(f"wrote {out}/report.md")
    return 0
