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
    timing_options,
)

if TYPE_CHECKING:
    from strapdown.algorithms.spec import AlgorithmName

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``run`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "run", arguments=_arguments,
        help="attitude from a gyro log (CSV, .npy, .npz, .mat)",
        description="Validate a gyro log, run an algorithm over it (streamed for increment "
        "logs and for .npy rate logs with uniform stamps) and write the attitude atomically: "
        "t,qw,qx,qy,qz (q_n_b) and the --angles columns, one row per attitude update "
        "(rate-three: every 3 samples, rk4: every 2), and beside it OUT.meta.json (input, "
        "algorithm, initial attitude, samples, update and sample period, jitter, gaps, "
        "saturation, peak rate, total rotation, warnings, version). Frame: q_n_b takes body "
        "vectors into n, the frame the initial attitude is given in (--init-attitude; "
        "identity by default, so n is the body frame at the first sample). The summary line "
        "gives the peak rate |w| (deg/s) and the total rotation (deg, the sum of the rotation "
        "angles between successive attitudes): a rad/s log declared as deg/s shows as "
        "'max 0.52 deg/s'. Jittered time stamps run on their nominal period (or --resample); "
        "nothing is written on invalid input, on magnitudes that suggest another unit "
        "(unless --accept-unit-warning) or on a non-finite result.")
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
    g.add_argument("--algorithm", choices=algorithms, default=None,
                   help=algorithm_help(algorithms) + " (default: rate-three for --rates, "
                   "rotvec for --increments)")
    g.add_argument("--structure", choices=STRUCTURES, default="conventional",
                   help=structure_help(algorithms))
    g.add_argument("--subsamples", type=int, default=None,
                   help="N, subsamples per update (rotvec only, default 3; an error for the "
                   "other algorithms)")
    g.add_argument("--coefficients", default=None,
                   help="coefficient set; " + coefficients_help(algorithms))
    g.add_argument("--init-attitude", type=float, nargs="+", default=None,
                   metavar="A",
                   help="attitude at the first sample: YAW PITCH ROLL (deg, z-y-x, as nav "
                   "--init-attitude) or a quaternion W X Y Z (q_n_b, normalised); default "
                   "identity (n = the body frame at the first sample)")
    o = p.add_argument_group("output")
    o.add_argument("--angles", choices=ANGLES, default="ypr",
                   help="angles written beside the quaternion: yaw/pitch/roll, cone angles, or "
                   "none (deg)")
    progress_args(o)
    o.add_argument("--out", required=True, help="output .csv or .npz")


def run(args: argparse.Namespace) -> int:
    """Run the log and write the attitude and its metadata; gaps, saturation and warnings go
    to stderr."""
    from strapdown.apps.run import initial_attitude, run_log

    q0 = initial_attitude(args.init_attitude)
    res = run_log(args.imu, args.out, kind=args.kind, units=args.units,
                  algorithm=args.algorithm, structure=args.structure,
                  subsamples=args.subsamples, coefficients=args.coefficients,
                  columns=None if args.columns is None else columns(args.columns),
                  sample_rate_hz=args.sample_rate_hz, angles=args.angles, q0=q0,
                  on_gap=args.on_gap,
                  gap_tolerance=args.gap_tolerance, saturation=args.saturation,
                  progress=progress(args),
                  accept_unit_warning=args.accept_unit_warning, delimiter=args.delimiter,
                  **timing_options(args))
    for w in res["warnings"]:
        say(f"warning: {w}")
    gaps, saturated = res["gaps"], res["saturated"]
    if gaps["count"]:
        how = "split into segments" if args.on_gap == "split" else "bridged"
        say(f"warning: {gaps['count']} gap(s) ({how}), first at data row "
            f"{gaps['first_rows'][0]}")
    if saturated["count"]:
        say(f"warning: {saturated['count']} saturated row(s), first at data row "
            f"{saturated['first_rows'][0]}")
    base = f"; {res['time_base']}" if res["time_base"] else ""
    print(f"wrote {args.out}: {res['outputs']} attitudes from {res['samples']} samples "
          f"({res['algorithm']}{base}; max {res['peak_rate_deg_s']:.3g} deg/s, total rotation "
          f"{res['total_rotation_deg']:.4g} deg summed over the updates) and "
          f"{args.out}.meta.json")
    return 0
