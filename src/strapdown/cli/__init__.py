"""The ``strapdown`` command line: one module per subcommand.

Each subcommand module (:mod:`.evaluate`, :mod:`.coefficients`, :mod:`.export_c`,
:mod:`.run`, :mod:`.compare`, :mod:`.sweep`, :mod:`.ahrs`, :mod:`.benchmark_ahrs`,
:mod:`.reproduce`, :mod:`.bench`) has ``add_parser(subparsers)`` and ``run(args) -> int``;
argument groups several of them share are in :mod:`._common`. Choice lists come from the
registries (algorithm families, coefficient sets, designer forms, reproductions), imported
only when their subcommand is parsed, so ``strapdown --version`` and ``--help`` load no
numerical library of their own.

Every subcommand validates its flags and exits with status 2 and one line on stderr naming
the problem on bad input (no traceback).
"""

from __future__ import annotations

import argparse
import sys

from strapdown.cli import (
    ahrs,
    bench,
    benchmark_ahrs,
    coefficients,
    compare,
    evaluate,
    export_c,
    reproduce,
    run,
    sweep,
)
from strapdown.cli._common import CommandParser, Parser

__all__ = ["COMMANDS", "build_parser", "main"]

#: The subcommand modules, in the order ``strapdown --help`` lists them.
COMMANDS = (evaluate, coefficients, export_c, run, compare, sweep, ahrs, benchmark_ahrs,
            reproduce, bench)


def build_parser() -> argparse.ArgumentParser:
    """The ``strapdown`` parser; each subcommand's options are added when it is used."""
    from strapdown import __version__

    p = Parser(prog="strapdown", description="Strapdown attitude algorithms for high-dynamic "
               "bodies: evaluate algorithms against exact motions, reproduce papers.")
    p.add_argument("--version", action="version", version=f"strapdown {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=CommandParser)
    for command in COMMANDS:
        command.add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    Bad input exits with status 2 and ``strapdown COMMAND: error: …`` on stderr.
    """
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        return args.handler(args)
    except ValueError as exc:
        parser.exit(2, f"strapdown {args.command}: error: {exc}\n")
    return 1  # pragma: no cover


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
