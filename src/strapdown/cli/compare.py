"""``strapdown compare``: several algorithms on one reference motion or one gyro log."""

from __future__ import annotations

import argparse

from strapdown.cli._common import (
    columns,
    log_args,
    log_check_args,
    motion_args,
    progress,
    progress_args,
    say,
    timing_options,
)
from strapdown.cli.evaluate import sculling_args

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``compare`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "compare", arguments=_arguments,
        help="several algorithms on one motion or one log",
        description="Run several algorithms on one reference motion (errors against exact "
        "truth) or on one gyro log (against --truth, or else relative to the first spec); "
        "write error_vs_time.png and summary.md/.csv.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.spec import ALGORITHMS, SPEC_KEYS

    p.add_argument("--algorithms", nargs="+", required=True, metavar="SPEC",
                   help="algorithm specs, e.g. rotvec:N=3 rotvec:N=3:structure=realtime "
                   f"rate-three:structure=sliding rk4 (algorithms: {', '.join(ALGORITHMS)}; "
                   f"keys: N, {', '.join(k for k in SPEC_KEYS if k != 'subsamples')}). With "
                   "--motion sculling: velocity algorithms rotvec:N=1..6 with "
                   "structure=conventional or single-chain, compared by their rectified "
                   "velocity-error rate against the sculling law")
    motion_args(p, rate_default=None)
    sculling_args(p)
    log_args(p, imu_help="compare on this log instead of a motion", required=False,
             sample_rate=False)
    log_check_args(p, saturation=False)
    p.add_argument("--truth", default=None,
                   help="log only: reference attitude file with t,qw,qx,qy,qz (CSV or .npz)")
    progress_args(p, "a line as each algorithm runs, the log's time base and the files "
                  "written")
    p.add_argument("--out", required=True, help="output directory")


def run(args: argparse.Namespace) -> int:
    """Compare the specs and print each one's maximum and RMS error."""
    from strapdown.apps import compare

    lines = say if progress(args) else None
    if args.imu is None:
        log_only = (args.kind or args.truth or args.units or args.columns or args.resample
                    or args.delimiter
                    or args.accept_unit_warning or args.on_gap != "report"
                    or args.gap_tolerance != 1.5)
        if log_only:
            raise ValueError("--rates/--increments, --units, --columns, --truth and the log "
                             "checks (--on-gap, --gap-tolerance, --resample, "
                             "--accept-unit-warning) belong to --imu")
        from strapdown.analysis.evaluate import EvaluationConfig

        base = EvaluationConfig(
            motion=args.motion, half_angle_deg=args.half_angle_deg,
            cone_rate_hz=args.cone_rate_hz, spin_rate_dps=args.spin_rate_dps,
            sample_rate_hz=args.sample_rate_hz or 10_000.0, duration=args.duration,
            krylov_rates=tuple(args.krylov_rates),
            angle_amplitude_deg=args.angle_amplitude_deg, accel_amplitude=args.accel_amplitude,
            frequency_hz=args.frequency_hz, phase_deg=args.phase_deg)
        runs = compare.compare_motion(base, args.algorithms, args.out, progress=lines)
    else:
        from strapdown.io.readers import log_kind

        cols = None if args.columns is None else columns(args.columns)
        kind = args.kind or log_kind(args.imu, cols, delimiter=args.delimiter)
        if kind is None:
            raise ValueError("--imu needs --rates or --increments (its header does not say: "
                             "a unit such as gx[rad/s] or gx[rad] would)")
        runs = compare.compare_log(
            args.imu, args.algorithms, args.out, kind=kind, units=args.units,
            columns=cols, sample_rate_hz=args.sample_rate_hz, truth=args.truth, progress=lines,
            note=say,
            on_gap=args.on_gap, gap_tolerance=args.gap_tolerance,
            accept_unit_warning=args.accept_unit_warning, delimiter=args.delimiter,
            **timing_options(args))
    for r in runs:
        if "velocity_error_rate_z_m_s2" in r.summary:
            ratio = r.summary["velocity_rate_over_law"]
            print(f"{r.label:40s} velocity rate {r.summary['velocity_error_rate_z_m_s2']:.3e} "
                  f"m/s² (z)  law ×{'n/a' if ratio is None else f'{ratio:.4f}'}  "
                  f"max |δv| {r.summary['max_velocity_error_m_s']:.3e} m/s")
            continue
        print(f"{r.label:40s} max {r.summary['max_error_rad']:.3e} rad  "
              f"rms {r.summary['rms_error_rad']:.3e} rad")
    return 0
