"""``strapdown export-c``: allocation-free C99 for a configured algorithm."""

from __future__ import annotations

import argparse

from strapdown.cli._common import ahrs_config_fields, coefficients_help, structure_help

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``export-c`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "export-c", arguments=_arguments,
        help="generate allocation-free C99 for an algorithm",
        description="Write <name>.h and <name>.c: state struct, init, reset, update. Prints the "
        "operation counts per update.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.spec import STRUCTURES
    from strapdown.codegen.export_c import ALGORITHMS, ATTITUDE_ALGORITHMS, REALS

    p.add_argument("--algorithm", choices=ALGORITHMS, required=True,
                   help="the algorithm to generate (nav: the navigation update on the WGS-84 "
                   "Earth with coning and sculling compensation; ahrs: the AHRS filter of "
                   "strapdown ahrs, one update per IMU sample)")
    p.add_argument("--structure", choices=STRUCTURES, default=None,
                   help=structure_help(ATTITUDE_ALGORITHMS) + "; nav: conventional, single-chain "
                   "(default: the first each algorithm lists, conventional)")
    p.add_argument("--subsamples", type=int, default=None,
                   help="N, subsamples per update (rotvec and nav only, default 3; an error for "
                   "the other algorithms)")
    p.add_argument("--coefficients", default=None,
                   help="coefficient set; " + coefficients_help(ATTITUDE_ALGORITHMS)
                   + "; nav: table3 (default; its sculling set is the same)")
    from strapdown.algorithms.velocity import DEFAULT_VELOCITY_SET, VELOCITY_SETS

    p.add_argument("--velocity-set", choices=VELOCITY_SETS, default=None,
                   help="nav only: the conventional structure's sculling pairs, as "
                   f"navigate(velocity_set=...) (default: {DEFAULT_VELOCITY_SET}, what "
                   "strapdown nav runs; classical: the sculling target on the pairs with the "
                   "last subsample; the single chain has one set)")
    p.add_argument("--float", dest="real", choices=REALS, default="double",
                   help="C floating-point type of the state and the arithmetic")
    p.add_argument("--sample-rate-hz", type=float, default=None,
                   help="rate algorithms (required): the gyro's sample rate 1/td, baked into "
                   "the code; an error for rotvec, whose code does not depend on it")
    p.add_argument("--name", default=None,
                   help="C identifier prefix (default: derived from the configuration, e.g. "
                   "sd_rotvec_conventional_n3)")
    p.add_argument("--out", required=True, help="output directory")
    g = p.add_argument_group("ahrs (the filter options of strapdown ahrs)")
    g.add_argument("--propagation", default="rate-single",
                   help="the AHRS's attitude propagation (strapdown ahrs --algorithm): "
                   "rate-single (default), rate-two, rate-three, rk4")
    g.add_argument("--no-mag", action="store_true",
                   help="no magnetometer code (the filter without heading)")
    g.add_argument("--no-gating", action="store_true",
                   help="accept every measurement (no innovation gating or disturbance checks)")
    g.add_argument("--gyro-sample", choices=["interval", "point"], default="interval",
                   help="what a gyro sample is (as strapdown ahrs --gyro-sample)")
    g.add_argument("--declination-deg", type=float, default=0.0,
                   help="magnetic declination (deg, east positive)")
    g.add_argument("--set", dest="config", action="append", default=[], metavar="FIELD=VALUE",
                   help="any other AhrsConfig field (repeatable), e.g. --set rest_min_s=1.0 "
                   "--set acc_model=raw")
    g.add_argument("--no-count", action="store_true",
                   help="skip measuring the operations per update (needs a C++ compiler)")


def run(args: argparse.Namespace) -> int:
    """Write the C files and print the operation counts."""
    from strapdown.algorithms.spec import family
    from strapdown.codegen.export_c import NAV_ALGORITHMS, export_c

    if args.algorithm == "ahrs":
        return _run_ahrs(args)
    if args.algorithm in NAV_ALGORITHMS:  # the sample interval is an argument of its init
        if args.sample_rate_hz is not None:
            raise ValueError("--sample-rate-hz does not apply to nav (its init takes the "
                             "sample interval h)")
        from strapdown.algorithms.velocity import nav_structures

        e = export_c(args.out, algorithm=args.algorithm,
                     structure=args.structure or nav_structures()[0],
                     subsamples=3 if args.subsamples is None else args.subsamples,
                     coefficients=args.coefficients, real=args.real, name=args.name,
                     **({} if args.velocity_set is None
                        else {"velocity_set": args.velocity_set}))
        print(_wrote(args.out, e.name))
        print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
        return 0
    if args.velocity_set is not None:
        raise ValueError(f"--velocity-set belongs to --algorithm nav, not {args.algorithm}")
    fam = family(args.algorithm)
    if args.subsamples is not None and "subsamples" not in fam.options:
        raise ValueError(f"--subsamples does not apply to {args.algorithm} (only rotvec has "
                         "subsamples per update)")
    h = None
    if fam.input_kind == "rate":
        if args.sample_rate_hz is None:
            raise ValueError(f"{args.algorithm} bakes the sample period td into the code: pass "
                             "--sample-rate-hz (the gyro's rate, Hz)")
        if not args.sample_rate_hz > 0:
            raise ValueError(f"sample rate must be positive, got {args.sample_rate_hz}")
        h = 1.0 / args.sample_rate_hz
    elif args.sample_rate_hz is not None:
        raise ValueError(f"--sample-rate-hz does not apply to {args.algorithm} (its input is "
                         "increments; the generated code does not depend on the rate)")
    e = export_c(args.out, algorithm=args.algorithm,
                 structure=args.structure or fam.structures[0],  # the family's default
                 subsamples=3 if args.subsamples is None else args.subsamples,
                 coefficients=args.coefficients, real=args.real, name=args.name,
                 **({} if h is None else {"h": h}))
    print(_wrote(args.out, e.name))
    print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
    return 0


def _ahrs_config(args: argparse.Namespace):
    """The AhrsConfig of the options (``--set`` values parsed as the field's type)."""
    from strapdown.ahrs import AhrsConfig

    return AhrsConfig(**{"gating": not args.no_gating, "declination_deg": args.declination_deg,
                         "gyro_sample": args.gyro_sample, **ahrs_config_fields(args.config)})


def _run_ahrs(args: argparse.Namespace) -> int:
    """``--algorithm ahrs``: write the module, print its state size and operation counts."""
    from strapdown.codegen.ahrs_c import export_ahrs

    if args.sample_rate_hz is None or not args.sample_rate_hz > 0:
        raise ValueError("ahrs bakes the IMU's sample rate into the code: pass a positive "
                         "--sample-rate-hz (Hz)")
    for opt, given in (("--structure", args.structure is not None),
                       ("--subsamples", args.subsamples is not None),
                       ("--coefficients", args.coefficients is not None)):
        if given:
            raise ValueError(f"{opt} does not apply to ahrs (its propagation is --propagation)")
    e = export_ahrs(args.out, sample_rate_hz=args.sample_rate_hz, real=args.real,
                    mag=not args.no_mag, algorithm=args.propagation, config=_ahrs_config(args),
                    name=args.name)
    print(_wrote(args.out, e.name))
    print(f"initial window: {e.init_samples} samples (init_window_s); a start in motion's: "
          f"{e.moving_samples} (moving_start_window_s)")
    if args.no_count:
        return 0
    from strapdown.codegen.ahrs_count import count_operations, state_size

    try:
        print(f"state: {state_size(e)} bytes ({e.name}_state, this machine's C compiler)")
        c = count_operations(e)
    except RuntimeError as exc:
        print(f"not measured: {exc}")
        return 0
    print("operations per update, mean (max) over a simulated recording: " + ", ".join(
        f"{k} {c.mean[k]:.0f} ({c.max[k]})" for k in c.mean))
    print("the update that completes the initial window: " + ", ".join(
        f"{k} {v}" for k, v in c.window.items()))
    return 0


def _wrote(out: str, name: str) -> str:
    """``wrote DIR/NAME.h and DIR/NAME.c``: the paths as the files are, however ``--out``
    was typed (``flight/`` gives ``flight/NAME.h``, not ``flight//NAME.h``)."""
    from pathlib import Path

    return f"wrote {Path(out) / f'{name}.h'} and {Path(out) / f'{name}.c'}"
