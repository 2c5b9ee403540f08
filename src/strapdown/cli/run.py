"""``strapdown run``: attitude from a gyro log, validated, streamed, written atomically."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from strapdown.cli._common import (
    algorithm_help,
    coefficients_help,
    columns,
    log_args,
    log_check_args,
    progress,
    progress_args,
    say,
    structure_help,
)

if TYPE_CHECKING:
    from strapdown.algorithms.family import AlgorithmName

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``run`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "run", arguments=_arguments,
        help="attitude from a gyro log (CSV, .npy, .npz, .mat)",
        description="Validate a gyro log, run an algorithm over it (streamed for increment "
        "logs) and write the attitude atomically.")
    p.set_defaults(handler=run)
    return p


def log_algorithms() -> tuple[AlgorithmName, ...]:
    """The families that run on a log (not the quaternion algorithms' whole steps)."""
    from strapdown.algorithms.spec import REGISTRY

    return tuple(n for n, f in REGISTRY.items() if not f.stepped)


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.spec import STRUCTURES
    from strapdown.apps.run import ANGLES

    log_args(p, imu_help="input log", required=True, sample_rate=True)
    log_check_args(p)
    algorithms = log_algorithms()
    g = p.add_argument_group("algorithm")
    g.add_argument("--algorithm", choices=algorithms, default="rotvec",
                   help=algorithm_help(algorithms))
    g.add_argument("--structure", choices=STRUCTURES, default="conventional",
                   help=structure_help(algorithms))
    g.add_argument("--subsamples", type=int, default=3, help="N, subsamples per update (rotvec)")
    g.add_argument("--coefficients", default=None,
                   help="coefficient set; " + coefficients_help(algorithms))
    o = p.add_argument_group("output")
    o.add_argument("--angles", choices=ANGLES, default="ypr",
                   help="angles written beside the quaternion: yaw/pitch/roll, cone angles, or "
                   "none (deg)")
    progress_args(o)
    o.add_argument("--out", required=True, help="output .csv or .npz")


def run(args: argparse.Namespace) -> int:
    """Run the log and write the attitude; gaps, saturation and warnings go to stderr."""
    from strapdown.apps.run import run_log

    res = run_log(args.imu, args.out, kind=args.kind, units=args.units,
                  algorithm=args.algorithm, structure=args.structure,
                  subsamples=args.subsamples, coefficients=args.coefficients,
                  columns=columns(args.columns), sample_rate_hz=args.sample_rate_hz,
                  angles=args.angles, on_gap=args.on_gap, gap_tolerance=args.gap_tolerance,
                  saturation=args.saturation, progress=progress(args))
    for w in res["warnings"]:
        say(f"warning: {w}")
    if res["gaps"]:
        how = "split into segments" if args.on_gap == "split" else "bridged"
        say(f"warning: {len(res['gaps'])} gap(s) ({how}), first at data row {res['gaps'][0]}")
    if res["saturated"]:
        say(f"warning: {len(res['saturated'])} saturated row(s), first at data row "
            f"{res['saturated'][0]}")
    print(f"wrote {args.out}: {res['outputs']} attitudes from {res['samples']} samples")
    return 0
