"""``strapdown reproduce``: a paper's tables and figures."""

from __future__ import annotations

import argparse

from strapdown.cli._common import progress, progress_args, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``reproduce`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "reproduce", arguments=_arguments,
        help="reproduce a paper's tables and figures",
        description="Reproduce a paper: write report.md, CSV and Markdown tables and PNG "
        "figures into --out. See docs/reproductions.md for what each found.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.reproduce import REPRODUCTIONS

    p.add_argument("paper", choices=tuple(REPRODUCTIONS),
                   help="; ".join(f"{name}: {r.subject}" for name, r in REPRODUCTIONS.items()))
    p.add_argument("--out", required=True, help="output directory (created; files replaced)")
    progress_args(p, "a line as each table or figure starts")


def run(args: argparse.Namespace) -> int:
    """Run the reproduction and print where its report is; with progress, a line on stderr
    as each table or figure starts."""
    from strapdown.reproduce import reproduction

    path = reproduction(args.paper).reproduce(args.out, progress=say if progress(args) else None)
    print(f"wrote {path}")
    return 0
