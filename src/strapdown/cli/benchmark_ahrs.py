"""``strapdown benchmark-ahrs``: our AHRS against VQF and Fusion on BROAD trials, or against
VQF on the simulated generalisation suite (``--suite generalisation``)."""

from __future__ import annotations

import argparse

from strapdown.cli._common import progress, progress_args, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``benchmark-ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "benchmark-ahrs", arguments=_arguments,
        help="our AHRS against VQF and Fusion on BROAD trials (BROAD's metric), or on "
        "simulated scenarios with truth (--suite generalisation)",
        description="Run strapdown's EKF, the open peers VQF (causal: VQF.updateBatch; "
        "acausal: offlineVQF) and Fusion (pip install 'strapdown[bench]'), and our filter's "
        "gating ablations on every BROAD trial in DIR; write per-trial and mean total, heading "
        "and inclination RMSE (BROAD's metric as published), each filter labelled causal or "
        "acausal, its throughput, and a bar chart. With --suite generalisation (no DIR): our "
        "filter and VQF, causal and offline, on simulated recordings with exact truth "
        "(pendulums, a turning vehicle, a loitering aircraft, spin-coning, hand-held shaking, "
        "a steel door frame, stationary rests); prints the per-scenario RMSE table.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", nargs="?", default=None,
                   help="directory of BROAD .mat trials (not with --suite generalisation)")
    p.add_argument("--suite", choices=("broad", "generalisation"), default="broad",
                   help="broad (default): the BROAD trials in DIR; generalisation: the "
                   "simulated scenarios of strapdown.truth.scenarios (needs no data)")
    p.add_argument("--out", default=None, help="output directory (default "
                   "reports/benchmark-ahrs, or reports/benchmark-ahrs-generalisation)")
    p.add_argument("--algorithm", default="rate-single",
                   help="our propagation algorithm (a spec, as for strapdown ahrs; BROAD only)")
    p.add_argument("--heading-offset-removed", action="store_true",
                   help="add a column with the total error after removing a constant heading "
                   "offset (not BROAD's metric; BROAD only)")
    p.add_argument("--seed", type=int, default=0,
                   help="generalisation: seed of the sensor errors and random motions")
    p.add_argument("--short", action="store_true",
                   help="generalisation: the first 12 s of each scenario only (a quick check)")
    progress_args(p, "a line as each trial and filter runs")


def _generalisation(args: argparse.Namespace) -> int:
    from strapdown.apps.ahrs_generalisation import generalisation, summary_table

    if args.dir is not None:
        raise ValueError("--suite generalisation takes no DIR (its recordings are simulated)")
    out = args.out or "reports/benchmark-ahrs-generalisation"
    res = generalisation(out, seed=args.seed, short=args.short,
                         progress=say if progress(args) else None)
    print(summary_table(res, list(dict.fromkeys(n for n, _ in res))), end="")
    print("cells: total / inclination RMSE (°, BROAD's metric, from 5 s); ratio: ours/VQF "
          "of the same kind, total")
    print(f"wrote {out}/report.md")
    return 0


def run(args: argparse.Namespace) -> int:
    """Run the benchmark and print each filter's mean RMSE and throughput (BROAD) or the
    per-scenario table (generalisation)."""
    if args.suite == "generalisation":
        return _generalisation(args)
    from strapdown.apps.ahrs_benchmark import FILTERS, KIND, benchmark, mean_of

    out = args.out or "reports/benchmark-ahrs"
    res = benchmark("" if args.dir is None else args.dir, out, algorithm=args.algorithm,
                    heading_offset_removed=args.heading_offset_removed,
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
