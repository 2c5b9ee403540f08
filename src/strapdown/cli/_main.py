"""Command line: ``strapdown evaluate`` and ``strapdown reproduce``.

Every subcommand validates its flags and exits with status 2 and a message
naming the problem on bad input (no traceback).
"""

from __future__ import annotations

import argparse
import json
import sys

from strapdown.algorithms.coning import coefficient_set_names

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)


def _add_evaluate(sub) -> None:
    p = sub.add_parser(
        "evaluate",
        help="run one algorithm on one motion and report its accuracy",
        description="Run one configuration (motion → ideal gyro → algorithm) and report drift "
        "and error against exact truth. Human-readable by default, --json for machines.",
    )
    _motion_args(p)
    p.add_argument("--algorithm",
                   choices=["rotvec", "rate-single", "rate-three", "rk4", "miller", "panov",
                            "power"],
                   default="rotvec",
                   help="rotvec: increments; rate-single, rate-three, rk4: rate samples; "
                   "miller, panov, power: Plaksiy's A1-A3 on sub-step increments")
    p.add_argument("--alpha", type=float, default=None, help="miller/panov/power: α")
    p.add_argument("--beta", type=float, default=None, help="miller: β")
    p.add_argument("--step", type=float, default=None,
                   help="miller/panov/power: computation step ΔT (s)")
    p.add_argument("--exact-exp", action="store_true",
                   help="miller/panov/power: exact exponential map instead of the truncated "
                   "series (eq. 7)")
    p.add_argument("--subsamples", type=int, default=3, help="N, subsamples per update (rotvec)")
    p.add_argument("--coefficients", choices=[*coefficient_set_names(), "derived", "paper"],
                   default=None,
                   help="rotvec: a named set (default table3, the classical-coning optimum); "
                   "rate algorithms: derived (default) or paper")
    p.add_argument("--structure",
                   choices=["conventional", "realtime", "single-chain", "sliding"],
                   default="conventional",
                   help="update structure (single-chain: rotvec every h; sliding: rate-three "
                   "every td)")
    p.add_argument("--rk4-step", choices=["2td", "td-interp"], default="2td",
                   help="rk4: step 2 td with the middle sample, or td with an interpolated middle")
    p.add_argument("--precision", type=int, default=None, metavar="DIGITS",
                   help="run in arbitrary precision with DIGITS significant digits")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _motion_args(p, rate_default: float | None = 10_000.0) -> None:
    p.add_argument("--motion", choices=["coning", "spin", "spin-coning", "krylov"],
                   default="coning")
    p.add_argument("--krylov-rates", type=float, nargs=3, metavar=("K1", "K2", "K3"),
                   default=(0.15, 0.25, 0.05),
                   help="krylov motion: angle rates (rad/s), angles k_i·t (Plaksiy)")
    p.add_argument("--half-angle-deg", type=float, default=1.0, help="half cone angle (deg)")
    p.add_argument("--cone-rate-hz", type=float, default=1.0, help="cone frequency Ω/2π (Hz)")
    p.add_argument("--spin-rate-dps", type=float, default=0.0, help="spin rate (deg/s)")
    p.add_argument("--sample-rate-hz", type=float, default=rate_default,
                   help="gyro increment rate 1/h (Hz; default 10000 for motions)")
    p.add_argument("--duration", type=float, default=2.0, help="simulated time (s)")


def _add_coefficients(sub) -> None:
    from strapdown.design import FORMS, RULES, TARGETS

    p = sub.add_parser(
        "coefficients",
        help="derive coning coefficients exactly for an algorithm structure",
        description="Derive a structure's coefficients in exact rational arithmetic and print "
        "them with the classical-coning drift law they achieve: drift about the cone axis = "
        "−drift_constant · a²Ω(Ωh)^order.",
    )
    p.add_argument("--form", choices=FORMS, required=True, help="algorithm structure")
    p.add_argument("--subsamples", type=int, required=True, help="N")
    p.add_argument("--target", choices=TARGETS, default="coning")
    p.add_argument("--rule", choices=RULES, default="polynomial",
                   help="how to settle coefficients the target leaves free")
    p.add_argument("--previous", type=int, default=None,
                   help="uncompressed form: increments from earlier intervals (default N)")
    p.add_argument("--ignore-quadrature", action="store_true",
                   help="rate input: fit β only, ignoring the α quadrature error (shows what "
                   "such a derivation claims; the true drift is printed beside it)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _cmd_coefficients(args) -> int:
    from strapdown.design import classical_coning_drift, derive, structure_by_name

    st = structure_by_name(args.form, args.subsamples, previous=args.previous)
    d = derive(st, target=args.target, rule=args.rule, quadrature=not args.ignore_quadrature)
    rec = d.to_dict()
    if args.ignore_quadrature and st.input == "rate":
        order, const = classical_coning_drift(st, d.coefficients)
        rec["true_order"] = order
        rec["true_drift_constant"] = None if const is None else _fs(const)
    if args.json:
        print(json.dumps(rec, indent=2, ensure_ascii=False))
        return 0
    width = max((len(t) for t in rec["terms"]), default=4)
    lines = [f"form          {rec['form']} ({rec['input']} input)",
             f"target        {rec['target']} (free coefficients settled by {rec['rule']})"]
    for term, frac, dec in zip(rec["terms"], rec["coefficients"], rec["decimals"], strict=True):
        lines.append(f"  {term:{width}s}  {frac:>14s}  {dec: .17g}")
    if not rec["terms"]:
        lines.append("  (no cross-product terms)")
    lines.append(f"drift         {_law(d.drift_constant, d.order)} about the cone axis")
    if "true_order" in rec:
        order, const = classical_coning_drift(st, d.coefficients)
        lines.append(f"true drift    {_law(const, order)} (with the quadrature error)")
    print("\n".join(lines))
    return 0


def _fs(f) -> str:
    return f"{f.numerator}/{f.denominator}"


def _law(const, order) -> str:
    """``drift = −c · a²Ω(Ωh)^order`` written with its sign resolved."""
    if order is None:
        return "none up to the series length examined"
    sign = "−" if const > 0 else "+"
    return f"{sign}{_fs(abs(const))} · a²Ω(Ωh)^{order}"


def _add_export(sub) -> None:
    p = sub.add_parser("export-c", help="generate allocation-free C99 for an algorithm",
                       description="Write <name>.h and <name>.c: state struct, init, reset, "
                       "update. Prints the operation counts per update.")
    p.add_argument("--algorithm", choices=["rotvec", "rate-single", "rate-three", "rk4"],
                   required=True)
    p.add_argument("--structure", choices=["conventional", "realtime", "single-chain",
                                           "sliding"], default="conventional")
    p.add_argument("--subsamples", type=int, default=3, help="N (rotvec)")
    p.add_argument("--coefficients", default=None,
                   help="rotvec: a named set (default table3); rate: derived or paper")
    p.add_argument("--float", dest="real", choices=["double", "float"], default="double")
    p.add_argument("--sample-rate-hz", type=float, default=10_000.0,
                   help="rate algorithms: 1/td, baked into the code")
    p.add_argument("--name", default=None, help="C identifier prefix (default derived)")
    p.add_argument("--out", required=True, help="output directory")


def _cmd_export(args) -> int:
    from strapdown.codegen.export_c import export_c

    if not args.sample_rate_hz > 0:
        raise ValueError(f"sample rate must be positive, got {args.sample_rate_hz}")
    e = export_c(args.out, algorithm=args.algorithm, structure=args.structure,
                 subsamples=args.subsamples, coefficients=args.coefficients, real=args.real,
                 h=1.0 / args.sample_rate_hz, name=args.name)
    print(f"wrote {args.out}/{e.name}.h and {e.name}.c")
    print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
    return 0


def _progress_args(p) -> None:
    prog = p.add_mutually_exclusive_group()
    prog.add_argument("--progress", dest="progress", action="store_true", default=None,
                      help="progress bar on stderr (default: when stderr is a terminal)")
    prog.add_argument("--no-progress", dest="progress", action="store_false")


def _progress(args) -> bool:
    return sys.stderr.isatty() if args.progress is None else args.progress


def _add_run(sub) -> None:
    p = sub.add_parser("run", help="attitude from a gyro log (CSV, .npy, .npz, .mat)",
                       description="Validate a gyro log, run an algorithm over it (streamed "
                       "for increment logs) and write the attitude atomically.")
    p.add_argument("--imu", required=True, help="input log")
    kind = p.add_mutually_exclusive_group(required=True)
    kind.add_argument("--rates", dest="kind", action="store_const", const="rate")
    kind.add_argument("--increments", dest="kind", action="store_const", const="increment")
    p.add_argument("--units", default=None,
                   choices=["rad/s", "deg/s", "rad", "deg"],
                   help="rates: rad/s or deg/s; increments: rad or deg (required unless the "
                   "CSV header declares it, e.g. gx[deg/s])")
    p.add_argument("--columns", default="t,gx,gy,gz",
                   help="CSV columns for time and the three axes (default t,gx,gy,gz)")
    p.add_argument("--sample-rate-hz", type=float, default=None)
    p.add_argument("--algorithm", choices=["rotvec", "rate-single", "rate-three", "rk4"],
                   default="rotvec")
    p.add_argument("--structure", choices=["conventional", "realtime", "single-chain",
                                           "sliding"], default="conventional")
    p.add_argument("--subsamples", type=int, default=3)
    p.add_argument("--coefficients", default=None)
    p.add_argument("--angles", choices=["ypr", "cone", "none"], default="ypr")
    p.add_argument("--on-gap", choices=["report", "error", "split"], default="report",
                   help="gaps (intervals > --gap-tolerance samples): report them (default), "
                   "fail, or run each gap-free segment separately")
    p.add_argument("--gap-tolerance", type=float, default=1.5,
                   help="gap threshold in median sample intervals (default 1.5)")
    p.add_argument("--saturation", type=float, default=None,
                   help="sensor range in the declared unit; saturated rows are reported")
    _progress_args(p)
    p.add_argument("--out", required=True, help="output .csv or .npz")


def _cmd_run(args) -> int:
    from strapdown.apps.run import run_log

    cols = tuple(c.strip() for c in args.columns.split(","))
    res = run_log(args.imu, args.out, kind=args.kind, units=args.units,
                  algorithm=args.algorithm, structure=args.structure,
                  subsamples=args.subsamples, coefficients=args.coefficients, columns=cols,
                  sample_rate_hz=args.sample_rate_hz, angles=args.angles, on_gap=args.on_gap,
                  gap_tolerance=args.gap_tolerance, saturation=args.saturation,
                  progress=_progress(args))
    for w in res["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    if res["gaps"]:
        how = "split into segments" if args.on_gap == "split" else "bridged"
        print(f"warning: {len(res['gaps'])} gap(s) ({how}), first at data row {res['gaps'][0]}",
              file=sys.stderr)
    if res["saturated"]:
        print(f"warning: {len(res['saturated'])} saturated row(s), first at data row "
              f"{res['saturated'][0]}", file=sys.stderr)
    print(f"wrote {args.out}: {res['outputs']} attitudes from {res['samples']} samples")
    return 0


def _add_compare(sub) -> None:
    p = sub.add_parser("compare", help="several algorithms on one motion or one log",
                       description="Run several algorithms on one reference motion (errors "
                       "against exact truth) or on one gyro log (against --truth, or else "
                       "relative to the first spec); write error_vs_time.png and summary.md/.csv.")
    p.add_argument("--algorithms", nargs="+", required=True, metavar="SPEC",
                   help="algorithm specs, e.g. rotvec:N=3 rotvec:N=3:structure=realtime "
                   "rate-three:structure=sliding rk4 (keys: N, coefficients, structure, rk4_step, "
                   "alpha, beta, step, exact_exp)")
    _motion_args(p, rate_default=None)
    p.add_argument("--imu", default=None, help="compare on this log instead of a motion")
    kind = p.add_mutually_exclusive_group()
    kind.add_argument("--rates", dest="kind", action="store_const", const="rate")
    kind.add_argument("--increments", dest="kind", action="store_const", const="increment")
    p.add_argument("--units", default=None, choices=["rad/s", "deg/s", "rad", "deg"])
    p.add_argument("--columns", default="t,gx,gy,gz")
    p.add_argument("--truth", default=None,
                   help="log only: reference attitude file with t,qw,qx,qy,qz (CSV or .npz)")
    p.add_argument("--out", required=True, help="output directory")


def _cmd_compare(args) -> int:
    from strapdown.apps import compare

    say = lambda msg: print(msg, file=sys.stderr)  # noqa: E731
    if args.imu is None:
        if args.kind or args.truth or args.units:
            raise ValueError("--rates/--increments, --units and --truth belong to --imu")
        from strapdown.analysis.evaluate import EvaluationConfig

        base = EvaluationConfig(
            motion=args.motion, half_angle_deg=args.half_angle_deg,
            cone_rate_hz=args.cone_rate_hz, spin_rate_dps=args.spin_rate_dps,
            sample_rate_hz=args.sample_rate_hz or 10_000.0, duration=args.duration,
            krylov_rates=tuple(args.krylov_rates))
        runs = compare.compare_motion(base, args.algorithms, args.out, progress=say)
    else:
        if args.kind is None:
            raise ValueError("--imu needs --rates or --increments")
        cols = tuple(c.strip() for c in args.columns.split(","))
        runs = compare.compare_log(args.imu, args.algorithms, args.out, kind=args.kind,
                                   units=args.units, columns=cols,
                                   sample_rate_hz=args.sample_rate_hz, truth=args.truth,
                                   progress=say)
    for r in runs:
        print(f"{r.label:40s} max {r.summary['max_error_rad']:.3e} rad  "
              f"rms {r.summary['rms_error_rad']:.3e} rad")
    return 0


def _add_sweep(sub) -> None:
    p = sub.add_parser("sweep", help="run a TOML scenario's parameter grid (resumable)",
                       description="Run every case of a scenario file's grid; each finished case "
                       "is saved at once, so an interrupted sweep resumes where it stopped. "
                       "Writes OUT/results.csv and OUT/results.parquet when the grid is complete.")
    p.add_argument("scenario", help="scenario file (.toml); see strapdown.apps.sweep")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--scheduler", default="local",
                   help="local (process pool, default) or dask://HOST:PORT")
    p.add_argument("--workers", type=int, default=None,
                   help="local pool size (default: CPU count; 1 runs in this process)")
    p.add_argument("--format", default="csv,parquet",
                   help="table formats, comma-separated: csv, parquet (default both)")
    p.add_argument("--max-cases", type=int, default=None,
                   help="compute at most this many new cases, then stop")
    _progress_args(p)


def _cmd_sweep(args) -> int:
    from strapdown.apps.sweep import sweep

    res = sweep(args.scenario, args.out, scheduler=args.scheduler, workers=args.workers,
                formats=[f.strip() for f in args.format.split(",") if f.strip()],
                max_cases=args.max_cases,
                progress=_progress(args),
                log=lambda msg: print(msg, file=sys.stderr))
    if not res.complete:
        print(f"{res.skipped + res.computed} of {res.total} cases done; rerun to finish")
        return 3
    print(f"wrote {res.csv}" + (f" and {res.parquet}" if res.parquet else "")
          + f" ({res.total} cases, {res.skipped} reused)")
    return 0


def _add_ahrs(sub) -> None:
    p = sub.add_parser("ahrs", help="attitude and heading from gyro, accelerometer and "
                       "magnetometer (error-state EKF)",
                       description="Run the AHRS filter over a recording (BROAD .mat or CSV "
                       "with t,gx,gy,gz,ax,ay,az[,mx,my,mz]) and write t,qw,qx,qy,qz (q_n_b) and "
                       "the gyro bias, plus OUT.meta.json. Without magnetometer columns heading "
                       "is not observed (said on stderr and in the metadata).")
    p.add_argument("--imu", required=True, help="recording (.mat BROAD, .csv)")
    p.add_argument("--out", required=True, help="output .csv or .npz")
    p.add_argument("--algorithm", default="rate-single",
                   help="attitude propagation: rate-single (default), rate-three, "
                   "rate-three:structure=sliding, rk4, rotvec:N=3, ...")
    p.add_argument("--frame", choices=["ENU", "NED"], default="ENU")
    p.add_argument("--gyro-units", choices=["rad/s", "deg/s"], default="rad/s")
    p.add_argument("--acc-units", choices=["m/s2", "g"], default="m/s2")
    p.add_argument("--columns", default=",".join(
        ("t", "gx", "gy", "gz", "ax", "ay", "az", "mx", "my", "mz")),
        help="CSV columns: time, gyro xyz, accelerometer xyz[, magnetometer xyz]")
    p.add_argument("--no-mag", action="store_true", help="ignore the magnetometer")
    p.add_argument("--no-gating", action="store_true",
                   help="accept every measurement (no innovation gating or disturbance checks)")
    p.add_argument("--declination-deg", type=float, default=0.0)


def _cmd_ahrs(args) -> int:
    from strapdown.ahrs import AhrsConfig
    from strapdown.apps.ahrs_log import run_ahrs

    cfg = AhrsConfig(gating=not args.no_gating, declination_deg=args.declination_deg)
    cols = tuple(c.strip() for c in args.columns.split(","))
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res, meta = run_ahrs(args.imu, args.out, algorithm=args.algorithm, frame=args.frame,
                             config=cfg, gyro_units=args.gyro_units, acc_units=args.acc_units,
                             columns=cols, use_magnetometer=not args.no_mag)
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    if not res.heading_observed:
        print("warning: no magnetometer: heading is not observed (gyro integral from yaw 0)",
              file=sys.stderr)
    print(f"wrote {args.out} ({meta['outputs']} attitudes, q_n_b with n = {args.frame}; "
          f"accelerometer used {meta['accelerometer_used']:.0%}, magnetometer "
          f"{meta['magnetometer_used']:.0%}) and {args.out}.meta.json")
    return 0


def _add_benchmark_ahrs(sub) -> None:
    p = sub.add_parser("benchmark-ahrs", help="our EKF against VQF and Fusion on BROAD trials",
                       description="Run strapdown's EKF (with and without gating) and the "
                       "open peers VQF and Fusion (pip install 'strapdown[bench]') on every "
                       "BROAD trial in DIR; write one table and one bar chart.")
    p.add_argument("dir", help="directory of BROAD .mat trials")
    p.add_argument("--out", default="reports/benchmark-ahrs", help="output directory")
    p.add_argument("--algorithm", default="rate-single", help="our propagation algorithm")


def _cmd_benchmark_ahrs(args) -> int:
    from strapdown.apps.ahrs_benchmark import benchmark, mean_total

    res = benchmark(args.dir, args.out, algorithm=args.algorithm,
                    progress=lambda msg: print(msg, file=sys.stderr))
    from strapdown.apps.ahrs_benchmark import FILTERS

    for f in FILTERS:
        m = mean_total(res, f)
        if m == m:
            print(f"{f:34s} mean total RMSE {m:.3f}°")
    print(f"wrote {args.out}/report.md")
    return 0


def _add_reproduce(sub) -> None:
    p = sub.add_parser("reproduce", help="reproduce a paper's tables and figures")
    p.add_argument("paper", choices=["li2017", "wang-rate", "wang-sliding", "plaksiy2024",
                                     "zhang2021"],
                   help="li2017: Li & Zhang 2017; wang-rate: the rate-input algorithms of "
                   "Wang, Wang & Wang (seed 001); wang-sliding: their three-filter EKF "
                   "comparison on the loiter flight; plaksiy2024: Plaksiy's Krylov-model study; "
                   "zhang2021: Zhang & Yu's cone angles")
    p.add_argument("--out", required=True, help="output directory (created; files replaced)")


def _fmt(x, unit="") -> str:
    if x is None:
        return "n/a"
    return f"{x:.6e}{unit}"


def _cmd_evaluate(args) -> int:
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
        print(json.dumps(res, indent=2, ensure_ascii=False))
        return 0
    arith = f"mpmath, {args.precision} digits" if args.precision else "float64"
    lines = [
        f"motion        {args.motion}",
        f"algorithm     {args.algorithm}" + (f", N = {args.subsamples}" if args.algorithm ==
                                               "rotvec" else "")
        + (f", coefficients {res['coefficients']}" if res["coefficients"] else ""),
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
    if res["predicted_drift_rad_s"] and res["cone_axis_drift_rad_s"] is not None:
        ratio = res["cone_axis_drift_rad_s"] / res["predicted_drift_rad_s"]
        lines.append(f"measured/law  {ratio:.6f}")
    print("\n".join(lines))
    return 0


def _cmd_reproduce(args) -> int:
    from strapdown.reproduce import li2017, plaksiy2024, wang_rate, wang_sliding, zhang2021

    module = {"li2017": li2017, "wang-rate": wang_rate, "wang-sliding": wang_sliding,
              "plaksiy2024": plaksiy2024, "zhang2021": zhang2021}[args.paper]
    path = module.reproduce(args.out, progress=lambda msg: print(msg, file=sys.stderr))
    print(f"wrote {path}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="strapdown", description="Strapdown attitude algorithms for high-dynamic "
                "bodies: evaluate algorithms against exact motions, reproduce papers.")
    from strapdown import __version__

    p.add_argument("--version", action="version", version=f"strapdown {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add_evaluate(sub)
    _add_coefficients(sub)
    _add_export(sub)
    _add_run(sub)
    _add_compare(sub)
    _add_sweep(sub)
    _add_ahrs(sub)
    _add_benchmark_ahrs(sub)
    _add_reproduce(sub)
    b = sub.add_parser("bench", help="throughput benchmarks (ratios to a NumPy pass, peers)",
                       add_help=False)
    b.add_argument("args", nargs=argparse.REMAINDER)
    return p


def main(argv: list[str] | None = None) -> int:
    if argv is None:
        argv = sys.argv[1:]
    if argv and argv[0] == "bench":  # its own parser (strapdown.apps.bench)
        from strapdown.apps import bench

        return bench.main(argv[1:])
    parser = build_parser()
    args = parser.parse_args(argv)
    handlers = {"evaluate": _cmd_evaluate, "coefficients": _cmd_coefficients,
                "reproduce": _cmd_reproduce, "export-c": _cmd_export, "run": _cmd_run,
                "compare": _cmd_compare, "sweep": _cmd_sweep, "ahrs": _cmd_ahrs,
                "benchmark-ahrs": _cmd_benchmark_ahrs}
    try:
        return handlers[args.command](args)
    except ValueError as exc:
        parser.exit(2, f"strapdown {args.command}: error: {exc}\n")
    return 1  # pragma: no cover


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
