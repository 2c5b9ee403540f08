"""``strapdown bench``: throughput benchmarks, as ratios to a NumPy pass and against peers.

An ordinary subcommand over :func:`strapdown.apps.bench.run_benchmarks`; the numbers
are reported, never asserted.
"""

from __future__ import annotations

import argparse
import json

from strapdown.cli._common import progress, progress_args, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``bench`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "bench", arguments=_arguments,
        help="throughput benchmarks (ratios to a NumPy pass, peers)")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.apps import bench

    p.description = bench.__doc__
    p.add_argument("--samples", type=int, default=10_000_000,
                   help="samples per timed run of our algorithms")
    p.add_argument("--peer-samples", type=int, default=20_000,
                   help="samples per timed run of the per-sample peers")
    p.add_argument("--stream-samples", type=int, default=100_000_000,
                   help="samples of the streaming memory test (0 skips it)")
    p.add_argument("--ekf-samples", type=int, default=1_000_000,
                   help="samples for the AHRS EKF and its peers (0 skips them)")
    p.add_argument("--nav-samples", type=int, default=2_000_000,
                   help="samples of the velocity/sculling update (ours; smsfusion gets "
                   "--peer-samples of the same motion) and, up to 10^6, of the Earth "
                   "navigation; 0 skips them")
    p.add_argument("--repeat", type=int, default=3, help="timed runs; the best is reported")
    p.add_argument("--json", action="store_true", help="print the records as JSON")
    progress_args(p, "a line as each benchmark starts")


def run(args: argparse.Namespace) -> int:
    """Run the benchmarks and print the table (or ``--json``); with progress, a line per
    benchmark on stderr as it starts. Skipped peers are rows of the table (and records)."""
    from strapdown.apps.bench import run_benchmarks

    recs = run_benchmarks(args.samples, args.peer_samples, args.repeat, args.stream_samples,
                          args.ekf_samples, nav_samples=args.nav_samples,
                          log=say if progress(args) else None)
    if args.json:
        print(json.dumps(recs, indent=2))
        return 0
    print(f"{'name':34s} {'samples/s':>12s} {'× numpy pass':>13s}  peer")
    for r in recs:
        if "ratio" in r:
            print(f"{r['name']:34s} " + (f"skipped: {r['skipped']}" if r["ratio"] is None
                                         else f"ours/smsfusion throughput {r['ratio']:.0f}×"))
        elif "peak_rss_mb" in r:
            print(f"{r['name']:34s} peak RSS {r['peak_rss_mb']:.0f} MB in {r['seconds']:.0f} s")
        elif r.get("skipped"):
            print(f"{r['name']:34s} skipped: {r['skipped']}")
        elif r["samples_per_s"] is None:
            print(f"{r['name']:34s} failed: {r['error']}")
        else:
            print(f"{r['name']:34s} {r['samples_per_s']:12.3e} {r['ratio_to_numpy_pass']:13.4f}"
                  f"  {r['peer'] or ''}")
    return 0
