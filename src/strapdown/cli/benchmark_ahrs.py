"""``strapdown benchmark-ahrs``: our AHRS against VQF and Fusion on BROAD trials."""

from __future__ import annotations

import argparse

from strapdown.cli._common import progress, progress_args, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``benchmark-ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "benchmark-ahrs", arguments=_arguments,
        help="our AHRS against VQF and Fusion on BROAD trials (BROAD's metric)",
        description="Run strapdown's EKF, the open peers VQF (causal: VQF.updateBatch; "
        "acausal: offlineVQF) and Fusion (pip install 'strapdown[bench]'), and our filter's "
        "gating ablations on every BROAD trial in DIR; write per-trial and mean total, heading "
        "and inclination RMSE (BROAD's metric as published), each filter labelled causal or "
        "acausal, its throughput, and a bar chart.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", help="directory of BROAD .mat trials")
    p.add_argument("--out", default="reports/benchmark-ahrs", help="output directory")
    p.add_argument("--algorithm", default="rate-single",
                   help="our propagation algorithm (a spec, as for strapdown ahrs)")
    p.add_argument("--heading-offset-removed", action="store_true",
                   help="add a column with the total error after removing a constant heading "
                   "offset (not BROAD's metric)")
    progress_args(p, "a line as each trial and filter runs")


def run(args: argparse.Namespace) -> int:
    """Run the benchmark and print each filter's mean RMSE and throughput."""
    from strapdown.apps.ahrs_benchmark import FILTERS, KIND, benchmark, mean_of

    res = benchmark(args.dir, args.out, algorithm=args.algorithm,
                    heading_offset_removed=args.heading_offset_removed,
                    progress=say if progress(args) else None)
    for f in FILTERS:
        m = mean_of(res, f)
        if m == m:  # NaN: the filter did not run (peer not installed)
            rate = next(e["samples_per_s"] for (_, g), e in res.items() if g == f)
            print(f"{f:34s} {KIND[f]:8s} mean RMSE total {m:.3f}°, heading "
                  f"{mean_of(res, f, 'heading_deg'):.3f}°, inclination "
                  f"{mean_of(res, f, 'inclination_deg'):.3f}°; {rate:.3g} samples/s")
    print(f"wrote {args.out}/report.md")
    return 0
