"""``strapdown benchmark-ahrs``: our EKF against VQF and Fusion on BROAD trials."""

from __future__ import annotations

import argparse

from strapdown.cli._common import progress, progress_args, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``benchmark-ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "benchmark-ahrs", arguments=_arguments,
        help="our EKF against VQF and Fusion on BROAD trials",
        description="Run strapdown's EKF (with and without gating) and the open peers VQF and "
        "Fusion (pip install 'strapdown[bench]') on every BROAD trial in DIR; write one table "
        "and one bar chart.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", help="directory of BROAD .mat trials")
    p.add_argument("--out", default="reports/benchmark-ahrs", help="output directory")
    p.add_argument("--algorithm", default="rate-single",
                   help="our propagation algorithm (a spec, as for strapdown ahrs)")
    progress_args(p, "a line as each trial and filter runs")


def run(args: argparse.Namespace) -> int:
    """Run the benchmark and print each filter's mean total RMSE."""
    from strapdown.apps.ahrs_benchmark import FILTERS, benchmark, mean_total

    res = benchmark(args.dir, args.out, algorithm=args.algorithm,
                    progress=say if progress(args) else None)
    for f in FILTERS:
        m = mean_total(res, f)
        if m == m:  # NaN: the filter did not run (peer not installed)
            print(f"{f:34s} mean total RMSE {m:.3f}°")
    print(f"wrote {args.out}/report.md")
    return 0
