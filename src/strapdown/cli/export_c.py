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
    from strapdown.codegen.export_c import ALGORITHMS, REALS

    p.add_argument("--algorithm", choices=ALGORITHMS, required=True,
                   help="the algorithm to generate")
    p.add_argument("--structure", choices=STRUCTURES, default="conventional",
                   help=structure_help(ALGORITHMS))
    p.add_argument("--subsamples", type=int, default=3, help="N, subsamples per update (rotvec)")
    p.add_argument("--coefficients", default=None,
                   help="coefficient set; " + coefficients_help(ALGORITHMS))
    p.add_argument("--float", dest="real", choices=REALS, default="double",
                   help="C floating-point type of the state and the arithmetic")
    p.add_argument("--sample-rate-hz", type=float, default=10_000.0,
                   help="rate algorithms: 1/td, baked into the code")
    p.add_argument("--name", default=None,
                   help="C identifier prefix (default: derived from the configuration, e.g. "
                   "sd_rotvec_conventional_n3)")
    p.add_argument("--out", required=True, help="output directory")


def run(args: argparse.Namespace) -> int:
    """Write the C files and print the operation counts."""
    from strapdown.codegen.export_c import export_c

    if not args.sample_rate_hz > 0:
        raise ValueError(f"sample rate must be positive, got {args.sample_rate_hz}")
    e = export_c(args.out, algorithm=args.algorithm, structure=args.structure,
                 subsamples=args.subsamples, coefficients=args.coefficients, real=args.real,
                 h=1.0 / args.sample_rate_hz, name=args.name)
    print(f"wrote {args.out}/{e.name}.h and {e.name}.c")
    print("operations per update: " + ", ".join(f"{k} {v}" for k, v in e.ops.items()))
    return 0
