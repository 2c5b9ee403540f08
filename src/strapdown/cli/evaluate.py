"""``strapdown evaluate``: one algorithm on one reference motion, its drift and error."""

from __future__ import annotations

import argparse

from strapdown.cli._common import (
    algorithm_help,
    coefficients_help,
    json_arg,
    motion_args,
    print_json,
    structure_help,
)

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``evaluate`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "evaluate", arguments=_arguments,
        help="run one algorithm on one motion and report its accuracy",
        description="Run one configuration (motion → ideal gyro → algorithm) and report drift "
        "and error against exact truth. Human-readable by default, --json for machines.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.rate import RK4_STEPS
    from strapdown.algorithms.spec import ALGORITHMS, REGISTRY, STRUCTURES

    motion_args(p)
    g = p.add_argument_group("algorithm")
    g.add_argument("--algorithm", choices=ALGORITHMS, default="rotvec",
                   help=algorithm_help(ALGORITHMS))
    g.add_argument("--alpha", type=float, default=None,
                   help="miller/panov/power: α (default: the paper's value)")
    g.add_argument("--beta", type=float, default=None,
                   help="miller: β (default: the paper's value)")
    g.add_argument("--step", type=float, default=None,
                   help="miller/panov/power: computation step ΔT (s)")
    g.add_argument("--exact-exp", action="store_true",
                   help="miller/panov/power: exact exponential map instead of the truncated "
                   "series (eq. 7)")
    g.add_argument("--subsamples", type=int, default=3, help="N, subsamples per update (rotvec)")
    coefficients = tuple(dict.fromkeys(c for f in REGISTRY.values()
                                       for c in f.coefficient_names()))
    g.add_argument("--coefficients", choices=coefficients, default=None,
                   help="coefficient set; " + coefficients_help(ALGORITHMS))
    g.add_argument("--structure", choices=STRUCTURES, default="conventional",
                   help=structure_help(ALGORITHMS))
    g.add_argument("--rk4-step", choices=RK4_STEPS, default="2td",
                   help="rk4: step 2 td with the middle sample, or td with an interpolated middle")
    g.add_argument("--precision", type=int, default=None, metavar="DIGITS",
                   help="run in arbitrary precision with DIGITS significant digits (default: "
                   "float64)")
    json_arg(p)


def _fmt(x, unit="") -> str:
    return "n/a" if x is None else f"{x:.6e}{unit}"


def run(args: argparse.Namespace) -> int:
    """Evaluate the configuration and print the result (text or ``--json``)."""
    from strapdown.analysis.evaluate import EvaluationConfig, evaluate

    cfg = EvaluationConfig(
        motion=args.motion, half_angle_deg=args.half_angle_deg, cone_rate_hz=args.cone_rate_hz,
        spin_rate_dps=args.spin_rate_dps, sample_rate_hz=args.sample_rate_hz,
        duration=args.duration, algorithm=args.algorithm, subsamples=args.subsamples,
        coefficients=args.coefficients, structure=args.structure, precision=args.precision,
        rk4_step=args.rk4_step, krylov_rates=tuple(args.krylov_rates), alpha=args.alpha,
        beta=args.beta, step=args.step, exact_exp=args.exact_exp,
    )
    res = evaluate(cfg).to_dict()
    if args.json:
        print_json(res)
        return 0
    print("\n".join(_text(args, res)))
    return 0


def _text(args: argparse.Namespace, res: dict) -> list[str]:
    arith = f"mpmath, {args.precision} digits" if args.precision else "float64"
    n = f", N = {args.subsamples}" if args.algorithm == "rotvec" else ""
    coeffs = f", coefficients {res['coefficients']}" if res["coefficients"] else ""
    lines = [
        f"motion        {args.motion}",
        f"algorithm     {args.algorithm}{n}{coeffs}",
        f"structure     {args.structure} (update period {res['update_period_s']:.6g} s)",
        f"arithmetic    {arith}; {res['samples']} increments",
        f"drift rate    [{', '.join(f'{v:.6e}' for v in res['drift_rate_rad_s'])}] rad/s "
        f"({res['drift_method']}, {res['drift_points']} points)",
        f"cone axis     {_fmt(res['cone_axis_drift_rad_s'], ' rad/s')}",
        f"predicted     {_fmt(res['predicted_drift_rad_s'], ' rad/s')}",
        f"max error     {res['max_error_rad']:.6e} rad",
        f"rms error     {res['rms_error_rad']:.6e} rad",
    ]
    if res["accumulated_drift_rad"] is not None:
        lines.append(f"accum. drift  {res['accumulated_drift_rad']:.6e} rad (max 2|vec δq|)")
    if res["measured_over_law"] is not None:
        lines += _law_lines(res)
    return lines


def _law_lines(res: dict) -> list[str]:
    """measured/law with its status, and what the status means here (analysis.law)."""
    import textwrap

    arith = "float64" if res["precision_digits"] is None else "mpmath"
    floor = f"{arith} floor {res['law_floor_rad_s']:.1e} rad/s"
    lines = [f"measured/law  {res['measured_over_law']:.6f}  ({res['law_status']}; {floor})"]
    if res["law_note"]:
        lines += textwrap.wrap(res["law_note"], width=92, initial_indent=" " * 14,
                               subsequent_indent=" " * 14, break_on_hyphens=False)
    return lines
