"""``strapdown export-c``: allocation-free C99 for a configured algorithm."""

from __future__ import annotations

import argparse

from strapdown.cli._common import coefficients_help, structure_help

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
                   "Earth with coning and sculling compensation)")
    p.add_argument("--structure", choices=STRUCTURES, default="conventional",
                   help=structure_help(ATTITUDE_ALGORITHMS) + "; nav: conventional, single-chain")
    p.add_argument("--subsamples", type=int, default=None,
                   help="N, subsamples per update (rotvec and nav only, default 3; an error for "
                   "the other algorithms)")
    p.add_argument("--coefficients", default=None,
                   help="coefficient set; " + coefficients_help(ATTITUDE_ALGORITHMS)
                   + "; nav: table3 (default; its sculling set is the same)")
    p.add_argument("--float", dest="real", choices=REALS, default="double",
                   help="C floating-point type of the state and the arithmetic")
    p.add_argument("--sample-rate-hz", type=float, default=None,
                   help="rate algorithms (required): the gyro's sample rate 1/td, baked into "
                   "the code; an error for rotvec, whose code does not depend on it")
    p.add_argument("--name", default=None,
                   help="C identifier prefix (default: derived from the configuration, e.g. "
                   "sd_rotvec_conventional_n3)")
    p.add_argument("--out", required=True, help="output directory")


def run(args: argparse.Namespace) -> int:
    """Write the C files and print the operation counts."""
    from strapdown.algorithms.spec import family
    from strapdown.codegen.export_c import NAV_ALGORITHMS, export_c

    if args.algorithm in NAV_ALGORITHMS:  # the sample interval is an argument of its init
        if args.sample_rate_hz is not None:
            raise ValueError("--sample-rate-hz does not apply to nav (its init takes the "
                             "sample interval h)")
        e = export_c(args.out, algorithm=args.algorithm, structure=args.structure,
                     subsamples=3 if args.subsamples is None else args.subsamples,
                     coefficients=args.coefficients, real=args.real, name=args.name)
        print(_wrote(args.out, e.name))
        print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
        return 0
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
    e = export_c(args.out, algorithm=args.algorithm, structure=args.structure,
                 subsamples=3 if args.subsamples is None else args.subsamples,
                 coefficients=args.coefficients, real=args.real, name=args.name,
                 **({} if h is None else {"h": h}))
    print(_wrote(args.out, e.name))
    print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
    return 0


def _wrote(out: str, name: str) -> str:
    """``wrote DIR/NAME.h and DIR/NAME.c``: the paths as the files are, however ``--out``
    was typed (``flight/`` gives ``flight/NAME.h``, not ``flight//NAME.h``)."""
    from pathlib import Path

    return f"wrote {Path(out) / f'{name}.h'} and {Path(out) / f'{name}.c'}"
