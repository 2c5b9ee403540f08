"""``strapdown advise``: which algorithm to fly in a measured vibration environment."""

from __future__ import annotations

import argparse

from strapdown.cli._common import (
    columns,
    json_arg,
    log_args,
    print_json,
    progress,
    progress_args,
    say,
)

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``advise`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "advise", arguments=_arguments,
        help="rank the algorithms by predicted drift and cost for a vibration environment",
        description="Estimate the cross-spectrum of the body rates from a gyro log (Welch) or "
        "read it from a file, predict each candidate algorithm's drift by summing its exact "
        "coning response over the spectrum, count its operations per second in the C export, "
        "and name the cheapest one within the drift budget (with no coning content: the "
        "cheapest). Prints a table and writes a figure of drift against cost with the Pareto "
        "front (--figure), or --json: {candidates: [{spec, predicted_drift_deg_h, "
        "measured_drift_deg_h, ops_per_s}], recommended} and no figure unless --figure is "
        "given. With --imu the cheapest candidates are verified on the log itself (--verify).")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.apps.advise import PSD_COLUMNS

    log_args(p, imu_help="gyro log whose vibration the algorithm must fly in", required=False,
             sample_rate=True)
    g = p.add_argument_group("advice")
    g.add_argument("--psd", default=None,
                   help=f"a cross-spectrum CSV instead of a log: {','.join(PSD_COLUMNS)} "
                   "(imaginary parts of the one-sided CSDs, rad²/s²/Hz, conj(X)·Y); needs "
                   "--sample-rate-hz")
    g.add_argument("--budget-deg-h", type=float, default=None,
                   help="drift budget (deg/h): the cheapest candidate within it is recommended")
    g.add_argument("--max-ops", type=float, default=None,
                   help="processor budget: candidates above this many operations per second "
                   "are not recommended")
    g.add_argument("--nperseg", type=int, default=256, help="Welch segment length (samples)")
    g.add_argument("--verify", type=int, default=8, metavar="N",
                   help="with --imu: run up to N candidates (the cheapest within the budget "
                   "predicted, in order of cost) on the log against a band-limited reference "
                   "attitude (FFT upsampling ×16, single chain N = 6) and recommend the "
                   "cheapest whose measured drift meets the budget too (default: 8; 0 = off)")
    g.add_argument("--no-verify", dest="verify", action="store_const", const=0,
                   help="rank by the spectral prediction alone (same as --verify 0)")
    g.add_argument("--figure", default=None,
                   help="figure of predicted drift against cost (default: advise.png; with "
                   "--json none unless given)")
    json_arg(p)
    progress_args(p, "a line as each stage starts and each candidate is verified")


def _ops_per_s(spec, h: float) -> float:
    """Operations per second of ``spec`` at samples every ``h``: the C exporter's counts per
    update (every arithmetic operation and libm call, triple terms included) times the
    updates per second."""
    from strapdown.codegen.export_c import generate

    exp = generate(spec.algorithm, structure=spec.structure, subsamples=spec.subsamples,
                   coefficients=spec.coefficients, h=h)
    return sum(exp.ops.values()) / spec.update_period(h)


def _spectrum(args: argparse.Namespace):
    """(frequencies, CSDs, h, Welch segments or None, input kind or None, log or None)."""
    import numpy as np

    from strapdown._core.errors import InputError
    from strapdown.apps.advise import (
        SPECTRUM_MIN_SAMPLES,
        VERIFY_MIN_SAMPLES,
        log_spectrum,
        read_psd,
    )

    if args.verify < 0:
        raise InputError(f"--verify must be ≥ 0, got {args.verify}")
    if (args.imu is None) == (args.psd is None):
        raise ValueError("give one of --imu LOG or --psd FILE")
    if args.psd is not None:
        if args.sample_rate_hz is None or not args.sample_rate_hz > 0:
            raise ValueError("--psd needs --sample-rate-hz (the rate the algorithm runs at)")
        f, g = read_psd(args.psd, sample_rate_hz=args.sample_rate_hz)
        return f, g, 1.0 / args.sample_rate_hz, None, None, None
    if args.nperseg < 16:
        raise ValueError(f"--nperseg must be at least 16, got {args.nperseg}")
    from strapdown.io import read_imu

    cols = None if args.columns is None else columns(args.columns)
    # kind None: read_imu takes it from the header's unit (gx[rad/s]), else asks for it
    with np.errstate(over="ignore", invalid="ignore"):  # values beyond float64 (a float128
        log = read_imu(args.imu, kind=args.kind, units=args.units,  # .npy) read as
                       columns=cols, sample_rate_hz=args.sample_rate_hz,  # infinity and are
                       delimiter=args.delimiter)  # refused with their row
    n = log.data.shape[0]
    need = VERIFY_MIN_SAMPLES if args.verify > 0 else SPECTRUM_MIN_SAMPLES
    if n < need:
        raise InputError(f"{args.imu}: {n} samples; " + (
            f"verifying on the log needs at least {need} (--no-verify ranks by the spectrum "
            f"alone, which needs {SPECTRUM_MIN_SAMPLES})" if args.verify > 0
            else f"a spectrum needs at least {need}"))
    f, g, segments = log_spectrum(log, nperseg=args.nperseg)
    return f, g, log.h, segments, log.kind, log


def run(args: argparse.Namespace) -> int:
    """Rank the candidates, print the table (or ``--json``) and write the figure."""
    from strapdown.apps.advise import (
        advise,
        candidate_specs,
        log_reference,
        unresolved_fraction,
        verified_drift_deg_h,
        write_figure,
    )

    stage = say if progress(args) else (lambda _line: None)
    figure = args.figure if args.figure is not None or args.json else "advise.png"
    stage(f"spectrum of {args.imu or args.psd}")
    f, g, h, segments, kind, log = _spectrum(args)
    if log is not None:
        _warn_if_clipped(log)
    if log is not None and args.verify > 0:
        stage("band-limited reference attitude of the log")
    ref = log_reference(log) if log is not None and args.verify > 0 else None

    def measure(spec) -> float:
        assert ref is not None  # measure is passed only with a reference
        stage(f"verifying {spec} on the log")
        return verified_drift_deg_h(spec, log, ref)

    specs = candidate_specs(kind)
    stage(f"ranking {len(specs)} candidates (predicted drift, operations per second)")
    adv = advise(f, g, h, specs, _ops_per_s, budget_deg_h=args.budget_deg_h,
                 max_ops=args.max_ops, segments=segments,
                 measure=None if ref is None else measure,
                 unresolved=0.0 if log is None else unresolved_fraction(log, f, g),
                 verify=args.verify, accuracy_deg_h=0.0 if ref is None else ref.accuracy_deg_h)
    if figure is not None:
        write_figure(adv, figure)
    reference = None if ref is None else {
        "upsample": ref.upsample, "accuracy_deg_h": ref.accuracy_deg_h,
        "window_s": list(ref.window), "segments": segments}
    if args.json:
        print_json({**adv.to_dict(), "reference": reference})
        return 0
    print("\n".join(_table(adv, ref)))
    say(f"figure: {figure}")
    return 0


def _warn_if_clipped(log) -> None:
    """Say so when the log's gyro looks clipped at its range
    (:func:`strapdown.ahrs.saturation.gyro_plateaus` on its rates): the spectrum, and so
    every candidate's predicted drift, misses the rate beyond the range."""
    from strapdown.ahrs.saturation import gyro_plateaus

    rates = log.data if log.kind == "rate" else log.data / log.h
    for p in gyro_plateaus(rates):
        say(f"warning: gyro axis {'xyz'[p.axis]} stops at {p.level:.3g} rad/s on {p.samples} "
            f"samples in {p.runs} plateaus, each entered by a step: it looks clipped at its "
            "range, and the spectrum, so every predicted drift, misses the rate beyond it")


def _table(adv, ref) -> list[str]:
    """The printed ranking: predicted and (where verified) measured drift, cost, marks."""
    w = max(len(str(c.spec)) for c in adv.candidates)
    lines = [f"{'':2s}{'spec':{w}s} {'predicted':>11s} {'measured':>11s} {'ops/s':>11s}",
             f"{'':2s}{'':{w}s} {'(deg/h)':>11s} {'(deg/h)':>11s}"]
    for c in adv.candidates:
        mark = ("*" if c is adv.recommended else " ") + ("P" if str(c.spec) in adv.pareto
                                                         else " ")
        meas = "-" if c.measured_drift_deg_h is None else f"{c.measured_drift_deg_h:.4g}"
        lines.append(f"{mark}{c.spec!s:{w}s} {c.predicted_drift_deg_h:11.4g} {meas:>11s} "
                     f"{c.ops_per_s:11.4g}")
    lines.append(adv.coning_note)
    if ref is not None:
        lines.append(f"measured: on the log against a band-limited reference (FFT ×"
                     f"{ref.upsample}, single chain N = 6), {ref.window[0]:.3g}–"
                     f"{ref.window[1]:.3g} s; reference accurate to {ref.accuracy_deg_h:.2g} "
                     f"deg/h (×{ref.upsample // 2} against ×{ref.upsample})")
    lines += [f"prediction against measurement, {n}" for n in adv.gap_notes]
    lines.append(f"recommended   {adv.recommended.spec} ({adv.reason})")
    lines.append("(* recommended, P Pareto front: no other candidate is both cheaper and "
                 "better predicted)")
    return lines
