"""``strapdown sweep``: a TOML scenario's parameter grid, resumable."""

from __future__ import annotations

import argparse

from strapdown.cli._common import input_args, progress, progress_args, say

__all__ = ["INCOMPLETE", "add_parser", "run"]

#: Exit status of a sweep stopped (``--max-cases``) before its grid is complete.
INCOMPLETE = 3
#: Exit status of any command stopped by Ctrl-C (128 + SIGINT; :func:`strapdown.cli.main`
#: prints the :class:`~strapdown.apps.sweep.SweepInterrupted` line).
INTERRUPTED = 130


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``sweep`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "sweep", arguments=_arguments,
        help="run a TOML scenario's parameter grid (resumable)",
        description="Run every case of a scenario file's grid; each finished case is saved at "
        "once, so an interrupted sweep resumes where it stopped. Writes OUT/results.csv (and "
        "OUT/results.parquet when pyarrow is installed) when the grid is complete. Exit "
        "status: 0 complete, "
        f"{INCOMPLETE} when --max-cases stops it first, {INTERRUPTED} on Ctrl-C (one line "
        "says how many cases are saved; rerun the same command to resume), 2 bad input. "
        "A scenario with motion = \"sculling\" (angle_amplitude_deg, accel_amplitude, "
        "frequency_hz, phase_deg) sweeps velocity algorithms (rotvec:N=1..6, conventional or "
        "single-chain) by the velocity metrics: velocity_error_rate_m_s2, "
        "predicted_velocity_error_rate_m_s2, velocity_rate_over_law, max_velocity_error_m_s, "
        "max_position_error_m.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", help="scenario file (.toml); see strapdown.apps.sweep")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--scheduler", default="local",
                   help="local (process pool) or dask://HOST:PORT")
    p.add_argument("--workers", type=int, default=None,
                   help="local pool size (default: CPU count; 1 runs in this process)")
    p.add_argument("--format", default=None,
                   help="table formats, comma-separated: csv, parquet (default: csv, plus "
                   "parquet when pyarrow is installed: pip install 'strapdown[parquet]')")
    p.add_argument("--max-cases", type=int, default=None,
                   help="compute at most this many new cases, then stop")
    input_args(p, delimiter=False)
    progress_args(p)


def run(args: argparse.Namespace) -> int:
    """Run (or finish) the grid; exit status :data:`INCOMPLETE` if cases remain.

    Ctrl-C raises :class:`~strapdown.apps.sweep.SweepInterrupted` (a ``KeyboardInterrupt``),
    which :func:`strapdown.cli.main` turns into its line and :data:`INTERRUPTED`.
    """
    from strapdown.apps.sweep import sweep

    res = sweep(args.scenario, args.out, scheduler=args.scheduler, workers=args.workers,
                formats=None if args.format is None
                else [f.strip() for f in args.format.split(",") if f.strip()],
                max_cases=args.max_cases, progress=progress(args), log=say)
    if not res.complete:
        print(f"{res.skipped + res.computed} of {res.total} cases done; rerun to finish")
        return INCOMPLETE
    print(f"wrote {res.csv}" + (f" and {res.parquet}" if res.parquet else "")
          + f" ({res.total} cases, {res.skipped} reused)")
    if args.format is None and res.parquet is None:
        say("note: no results.parquet: pyarrow is not installed (pip install "
            "'strapdown[parquet]', or --format csv to say CSV is all you want)")
    return 0
