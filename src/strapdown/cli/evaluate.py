"""``strapdown evaluate``: one algorithm on one reference motion, its drift and error."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from strapdown.cli._common import (
    algorithm_help,
    coefficients_help,
    json_arg,
    motion_args,
    print_json,
    structure_help,
)

if TYPE_CHECKING:
    from strapdown.algorithms.spec import AlgorithmSpec

__all__ = ["add_parser", "run", "sculling_args"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``evaluate`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "evaluate", arguments=_arguments,
        help="run one algorithm on one motion and report its accuracy",
        description="Run one configuration (motion → ideal gyro → algorithm) and report drift "
        "and error against exact truth. Human-readable by default, --json for machines. "
        "--motion sculling is classical sculling (θ0 sin Ωt about body x, A sin(Ωt + ψ) m/s² "
        "along body y, no gravity) through the velocity algorithm (rotvec, --subsamples N = "
        "1-6, --structure conventional or single-chain; or the rate-input duals --algorithm "
        "rate-single|rate-three, float64); it reports the rectified velocity-"
        "error rate (velocity_error_rate_m_s2, navigation frame) and the sculling law's "
        "(predicted_velocity_error_rate_m_s2).")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.rate import RK4_STEPS
    from strapdown.algorithms.spec import ALGORITHMS, REGISTRY, STRUCTURES

    motion_args(p)
    sculling_args(p)
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


def sculling_args(p: argparse.ArgumentParser) -> None:
    """The classical-sculling motion's options (``--motion sculling``; evaluate, compare)."""
    sc = p.add_argument_group("sculling motion (--motion sculling)")
    sc.add_argument("--angle-amplitude-deg", type=float, default=1.0,
                    help="θ0, angular vibration amplitude about body x (deg)")
    sc.add_argument("--accel-amplitude", type=float, default=10.0,
                    help="A, linear vibration amplitude along body y (m/s²); --motion "
                    "coning-force: the constant specific force along the cone axis")
    sc.add_argument("--frequency-hz", type=float, default=10.0,
                    help="vibration frequency Ω/2π (Hz)")
    sc.add_argument("--phase-deg", type=float, default=0.0,
                    help="ψ, phase of the linear vibration ahead of the angular one (deg)")


def _fmt(x, unit="") -> str:
    return "n/a" if x is None else f"{x:.6e}{unit}"


def run(args: argparse.Namespace) -> int:
    """Evaluate the configuration and print the result (text or ``--json``)."""
    from strapdown.analysis.evaluate import EvaluationConfig, run_evaluation

    cfg = EvaluationConfig.of(
        motion=args.motion, half_angle_deg=args.half_angle_deg, cone_rate_hz=args.cone_rate_hz,
        spin_rate_dps=args.spin_rate_dps, sample_rate_hz=args.sample_rate_hz,
        duration=args.duration, algorithm=args.algorithm, subsamples=args.subsamples,
        coefficients=args.coefficients, structure=args.structure, precision=args.precision,
        rk4_step=args.rk4_step, krylov_rates=tuple(args.krylov_rates), alpha=args.alpha,
        beta=args.beta, step=args.step, exact_exp=args.exact_exp,
        angle_amplitude_deg=args.angle_amplitude_deg, accel_amplitude=args.accel_amplitude,
        frequency_hz=args.frequency_hz, phase_deg=args.phase_deg,
    )
    res = run_evaluation(cfg).to_dict()
    if args.json:
        print_json(res)
        return 0
    velocity = cfg.kind.has_metric("velocity_error_rate_m_s2")  # the motion's own record
    text = _sculling_text if velocity else _text
    print("\n".join(text(args, res, cfg.spec)))
    return 0


def _vec(v) -> str:
    return "n/a" if v is None else "[" + ", ".join(f"{x:.6e}" for x in v) + "]"


def _sculling_text(args: argparse.Namespace, res: dict, spec: AlgorithmSpec) -> list[str]:
    arith = f"mpmath, {args.precision} digits" if args.precision else "float64"
    ratio = res["velocity_rate_over_law"]
    axis = "navigation z"
    motion = (f"sculling: θ0 = {args.angle_amplitude_deg:g}°, A = {args.accel_amplitude:g} "
              f"m/s², {args.frequency_hz:g} Hz, ψ = {args.phase_deg:g}°")
    velocity_set = res.get("velocity_set", "rate-input dual")
    if "force_along_cone_axis_m_s2" in res:  # coning in a constant specific force
        axis = "cone axis, navigation x"
        motion = (f"coning in a force: a = {args.half_angle_deg:g}°, {args.cone_rate_hz:g} Hz, "
                  f"f = {args.accel_amplitude:g} m/s² along the cone axis")
    return [
        f"motion        {motion}",
        f"algorithm     velocity update, N = {args.subsamples} (coning table3, velocity set "
        f"{velocity_set})",
        f"structure     {args.structure} (update period {res['update_period_s']:.6g} s)",
        f"arithmetic    {arith}; {res['samples']} increments",
        f"velocity rate {_vec(res['velocity_error_rate_m_s2'])} m/s² "
        f"({res['velocity_rate_method']}, {res['velocity_rate_points']} points)",
        f"predicted     {_vec(res['predicted_velocity_error_rate_m_s2'])} m/s²",
        f"measured/law  {'n/a' if ratio is None else f'{ratio:.6f}'} ({axis})",
        f"max |δv|      {res['max_velocity_error_m_s']:.6e} m/s",
        f"max |δp|      {res['max_position_error_m']:.6e} m",
    ]


def _text(args: argparse.Namespace, res: dict, spec: AlgorithmSpec) -> list[str]:
    arith = f"mpmath, {args.precision} digits" if args.precision else "float64"
    n = f", N = {args.subsamples}" if "subsamples" in spec.family.options else ""
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
