"""What the subcommands share: the parser classes, help formatting and argument groups.

Nothing here imports numpy or the algorithm registry at module level. A subcommand's
options are added by a function given to :class:`CommandParser`, which runs only when that
subcommand is parsed or its help is shown, so ``strapdown --version`` and
``strapdown --help`` never build the option lists (nor import what their choices come from).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    from strapdown.algorithms.family import Family
    from strapdown.algorithms.spec import AlgorithmName

__all__ = [
    "CommandParser",
    "HelpFormatter",
    "Parser",
    "ahrs_config_fields",
    "algorithm_help",
    "coefficients_help",
    "columns",
    "input_args",
    "json_arg",
    "log_args",
    "log_check_args",
    "motion_args",
    "print_json",
    "progress",
    "progress_args",
    "say",
    "size",
    "structure_help",
]

#: Where options go: a parser or one of its argument groups.
Options = argparse.ArgumentParser | argparse._ArgumentGroup
_K = TypeVar("_K")


class HelpFormatter(argparse.HelpFormatter):
    """Appends ``(default: …)`` to an option's help when it has a default worth showing.

    Not for flags (``store_true``), options defaulting to ``None`` and help that already
    states its default; a sequence default is shown space-separated, as it is typed.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (not action.option_strings or default is None or default is argparse.SUPPRESS
                or isinstance(action, argparse._StoreConstAction) or "default" in text):
            return text
        if isinstance(default, (list, tuple)):
            default = " ".join(str(v) for v in default)
        return f"{text} (default: {str(default).replace('%', '%%')})"


class Parser(argparse.ArgumentParser):
    """The command line's parser: no abbreviated options, defaults shown in help."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)


#: Every subcommand's help ends by pointing to the conventions page.
CONVENTIONS_EPILOG = ("conventions (frames, units, time stamps, quaternion order w x y z, "
                      "q_n_b): docs/conventions.md, or the reference site's Conventions page")


class CommandParser(Parser):
    """A subcommand's parser that adds its options on first use.

    Parameters
    ----------
    arguments : callable, optional
        ``arguments(parser)`` adds the options; it runs once, before the first parse or
        help text, so the imports its choice lists need happen only for that subcommand.
    """

    def __init__(self, *args, arguments: Callable[[Parser], None] | None = None,
                 **kwargs) -> None:
        kwargs.setdefault("epilog", CONVENTIONS_EPILOG)
        super().__init__(*args, **kwargs)
        self._arguments = arguments

    def populate(self) -> CommandParser:
        """Add the options now if not yet added (idempotent); returns the parser."""
        if self._arguments is not None:
            add, self._arguments = self._arguments, None
            add(self)
        return self

    def parse_known_args(self, args=None, namespace=None):
        """Parse this subcommand's options; an unknown one is this subcommand's error.

        argparse hands a subparser's leftovers to the top-level parser, which would print
        ``strapdown``'s usage for ``strapdown run --bogus``; nothing can follow a
        subcommand's arguments, so leftovers are refused here, with this command's usage.
        """
        self.populate()
        namespace, extras = super().parse_known_args(args, namespace)
        if extras:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        return namespace, extras

    def format_usage(self) -> str:
        self.populate()
        return super().format_usage()

    def format_help(self) -> str:
        self.populate()
        return super().format_help()


# ------------------------------------------------------------------------------ output
def ahrs_config_fields(items: Iterable[str]) -> dict[str, Any]:
    """``--set FIELD=VALUE`` items as AhrsConfig keyword arguments, each value parsed as
    its field's type (bool: true/false/1/0; str; else float). Raises ValueError naming the
    item on one that is not FIELD=VALUE with an AhrsConfig field, a bad bool or a bad
    number."""
    import dataclasses

    from strapdown.ahrs import AhrsConfig

    fields = [f.name for f in dataclasses.fields(AhrsConfig)]
    defaults = AhrsConfig()
    kw: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or key not in fields:
            raise ValueError(f"--set {item!r}: expected FIELD=VALUE with an AhrsConfig field "
                             f"({', '.join(fields)})")
        default = getattr(defaults, key)
        if isinstance(default, bool):
            if value.lower() not in ("true", "false", "1", "0"):
                raise ValueError(f"--set {key}: expected true or false, got {value!r}")
            kw[key] = value.lower() in ("true", "1")
        elif isinstance(default, str):
            kw[key] = value
        else:
            try:
                kw[key] = float(value)
            except ValueError:
                raise ValueError(f"--set {key}: expected a number, got {value!r}") from None
    return kw


def say(msg: str) -> None:
    """One line on stderr (progress and warnings; stdout carries the results)."""
    print(msg, file=sys.stderr)


def print_json(record: dict) -> None:
    """``record`` as indented JSON on stdout (non-ASCII kept)."""
    print(json.dumps(record, indent=2, ensure_ascii=False))


def json_arg(p: argparse.ArgumentParser) -> None:
    """``--json``: machine-readable output."""
    p.add_argument("--json", action="store_true",
                   help="print one JSON object instead of the human-readable text")


def columns(text: str) -> tuple[str, ...]:
    """``"t, gx,gy"`` → ``("t", "gx", "gy")``."""
    return tuple(c.strip() for c in text.split(","))


# ------------------------------------------------------------------------------ groups
def motion_args(p: argparse.ArgumentParser, rate_default: float | None = 10_000.0) -> None:
    """The reference motion and its ideal gyro: ``--motion`` … ``--duration``.

    ``rate_default=None`` (``compare``) leaves ``--sample-rate-hz`` unset so a log's own
    rate applies; motions then run at 10000 Hz.
    """
    from strapdown.analysis.evaluate import MOTIONS

    g = p.add_argument_group("motion")
    g.add_argument("--motion", choices=MOTIONS, default="coning",
                   help="reference motion: classical coning, pure spin, spin with coning, or "
                   "Plaksiy's Krylov-angle model")
    g.add_argument("--krylov-rates", type=float, nargs=3, metavar=("K1", "K2", "K3"),
                   default=(0.15, 0.25, 0.05),
                   help="krylov motion: angle rates (rad/s), angles k_i·t (Plaksiy)")
    g.add_argument("--half-angle-deg", type=float, default=1.0, help="half cone angle (deg)")
    g.add_argument("--cone-rate-hz", type=float, default=1.0, help="cone frequency Ω/2π (Hz)")
    g.add_argument("--spin-rate-dps", type=float, default=0.0, help="spin rate (deg/s)")
    rate_help = "gyro increment rate 1/h (Hz)"
    if rate_default is None:
        rate_help += ("; motions default to 10000; with --imu the sensor's rate: the nominal "
                      "period of jittered time stamps (default: from the stamps)")
    g.add_argument("--sample-rate-hz", type=float, default=rate_default, help=rate_help)
    g.add_argument("--duration", type=float, default=2.0, help="simulated time (s)")


def log_args(p: argparse.ArgumentParser, *, imu_help: str, required: bool,
             sample_rate: bool) -> None:
    """A gyro log: ``--imu``, ``--rates``/``--increments``, ``--units``, ``--columns`` and,
    with ``sample_rate``, ``--sample-rate-hz``.

    ``required`` makes ``--imu`` mandatory (``run``; the kind comes from the header's unit
    when neither ``--rates`` nor ``--increments`` is given); otherwise the log is
    optional (``compare`` runs on a motion without one, and its ``--sample-rate-hz`` is the
    motion's, see :func:`motion_args`).
    """
    from strapdown.io.readers import INCREMENT_UNITS, RATE_UNITS

    g = p.add_argument_group("gyro log")
    g.add_argument("--imu", required=required, help=imu_help)
    kind = g.add_mutually_exclusive_group()
    kind.add_argument("--rates", dest="kind", action="store_const", const="rate",
                      help="the log holds angular rates (default: what the header's unit "
                      "says, gx[rad/s] rates, gx[rad] increments)")
    kind.add_argument("--increments", dest="kind", action="store_const", const="increment",
                      help="the log holds angular increments")
    g.add_argument("--units", default=None, choices=(*RATE_UNITS, *INCREMENT_UNITS),
                   help=f"rates: {' or '.join(RATE_UNITS)}; increments: "
                   f"{' or '.join(INCREMENT_UNITS)}. Required unless the file declares it: a "
                   "CSV header (gx[deg/s]) or a known format (BROAD .mat: rad/s); a unit that "
                   "contradicts the file's is an error")
    g.add_argument("--columns", default=None,
                   help="CSV columns for time and the three axes, comma-separated, e.g. "
                   "time,wx,wy,wz (default: found in the header — time t, time, timestamp, "
                   "time_s, t[ms] …; axes gx,gy,gz, wx,wy,wz, gyro_x,… )")
    input_args(g)
    if sample_rate:
        g.add_argument("--sample-rate-hz", type=float, default=None,
                       help="the sensor's sample rate (Hz): the nominal period of a rate log's "
                       "jittered time stamps, the increment interval of an increment log, the "
                       "time base of a log without time stamps (default: from the stamps or "
                       "the file's stated rate)")


def input_args(g: Options, *, delimiter: bool = True) -> None:
    """``--delimiter`` (with ``delimiter``: a CSV's, default detected) and ``--max-memory``
    (the budget of what an input file may decode to; :mod:`strapdown._core.limits`)."""
    if delimiter:
        g.add_argument("--delimiter", default=None, choices=(",", ";", "tab", "|"),
                       help="CSV delimiter (default: detected from the header row: the first "
                       "of , ; tab | it contains)")
    g.add_argument("--max-memory", default=None, type=size, metavar="SIZE",
                   help="memory budget for what an input file decodes to, e.g. 512M or 8G; a "
                   "file declaring more is refused before anything is allocated (default: "
                   "$STRAPDOWN_MAX_BYTES, else 2G)")


def size(text: str) -> int:
    """``--max-memory``'s type: bytes of ``512M``, ``2G``, ``1e9`` (argparse reports a bad one)."""
    from strapdown._core.limits import parse_size

    return parse_size(text)


def log_check_args(p: argparse.ArgumentParser, *, saturation: bool = True) -> None:
    """What to do about a log's faults and time base: ``--on-gap``, ``--gap-tolerance``,
    ``--saturation`` (with ``saturation``), the time base (:func:`timing_args`),
    ``--accept-unit-warning``."""
    from strapdown.apps.run import RUN_GAP_POLICIES

    g = p.add_argument_group("log checks and time base")
    g.add_argument("--on-gap", choices=RUN_GAP_POLICIES, default="report",
                   help="gaps (samples missing on the fitted clock; without one, intervals over "
                   "--gap-tolerance periods): report them (the AHRS and an increment log bridge "
                   "them; a rate algorithm cannot and fails), fail, or run each gap-free "
                   "segment on its own from the previous one's last attitude (a segment column "
                   "is added)")
    g.add_argument("--gap-tolerance", type=float, default=1.5,
                   help="gap threshold in sample periods when the samples are not on a fitted "
                   "clock (--timing stamps or resample, irregular sampling)")
    if saturation:
        g.add_argument("--saturation", type=float, default=None,
                       help="sensor range in the declared unit; saturated rows are reported")
    timing_args(g)
    g.add_argument("--accept-unit-warning", action="store_true",
                   help="run although the magnitudes suggest another unit than declared "
                   "(e.g. a 99th-percentile rate over 200 rad/s declared as rad/s); without it "
                   "that is an error and nothing is written")


def timing_args(g: Options) -> None:
    """The time base of a recording (:mod:`strapdown.io.timing`): ``--timing``,
    ``--jitter-tolerance``, ``--held``, ``--duplicate-stamps`` and ``--resample``."""
    from strapdown.io.timing import (
        DUPLICATE_POLICIES,
        HELD_POLICIES,
        JITTER_TOLERANCE,
        TIMING_MODES,
    )

    g.add_argument("--timing", choices=TIMING_MODES, default="auto",
                   help="how the time stamps are taken. The sensor's own clock is fitted to "
                   "them (period, offset, slow drift; gaps are whole missing periods). auto: "
                   "samples on that clock when the stamps are noise, rounding or drift around "
                   "it, resampled when the sampling is irregular; nominal: on the clock "
                   "whatever the residuals; stamps: the stamps are the sample times (rate "
                   "algorithms then need them uniform); resample: the samples were taken at the "
                   "stamps, interpolated onto a uniform grid (default: auto)")
    g.add_argument("--jitter-tolerance", type=float, default=JITTER_TOLERANCE,
                   metavar="PERIODS",
                   help="largest stamp deviation from the fitted clock (99th percentile, in "
                   f"sample periods, below 0.5) that is stamp noise (default {JITTER_TOLERANCE:g})")
    g.add_argument("--held", choices=HELD_POLICIES, default="auto",
                   help="held samples (rows repeating every sensor value of the row before, "
                   "written by a logger faster than its sensor): collapse them to their first "
                   "stamp when the fitted clock confirms it (auto), always, or keep them")
    g.add_argument("--duplicate-stamps", choices=DUPLICATE_POLICIES, default="error",
                   help="a time stamp repeated with different values: an error naming the rows, "
                   "or keep the first or the last (a repeat with identical values is dropped)")
    g.add_argument("--resample", action="store_true",
                   help="the same as --timing resample")


def timing_options(args: argparse.Namespace) -> dict[str, Any]:
    """The :func:`timing_args` options as keywords of the readers and commands."""
    return {"timing": "resample" if getattr(args, "resample", False) else args.timing,
            "jitter_tolerance": args.jitter_tolerance, "held": args.held,
            "duplicates": args.duplicate_stamps}


def progress_args(p: Options, what: str = "a progress bar") -> None:
    """``--progress`` / ``--no-progress``; neither: ``what`` when stderr is a terminal.

    ``what`` says what the command shows, e.g. ``"a line per table or figure"``.
    """
    prog = p.add_mutually_exclusive_group()
    prog.add_argument("--progress", dest="progress", action="store_true", default=None,
                      help=f"show {what} (on stderr; default: when stderr is a terminal)")
    prog.add_argument("--no-progress", dest="progress", action="store_false",
                      help=f"do not show {what}")


def progress(args: argparse.Namespace) -> bool:
    """Whether to show a progress bar (see :func:`progress_args`)."""
    return sys.stderr.isatty() if args.progress is None else args.progress


# ------------------------------------------------------------------------------ registry help
def _by_family(names: Iterable[AlgorithmName], key: Callable[[Family], _K]
               ) -> list[tuple[str, _K]]:
    """``[("a, b", value), …]``: the families among ``names`` grouped by ``key(family)``."""
    from strapdown.algorithms.spec import REGISTRY

    groups: dict[_K, list[str]] = {}
    for n in names:
        groups.setdefault(key(REGISTRY[n]), []).append(n)
    return [(", ".join(ns), value) for value, ns in groups.items()]


def algorithm_help(names: Iterable[AlgorithmName]) -> str:
    """What each of ``names`` (registered families) takes as input."""
    def kind(f: Family) -> str:
        if f.stepped:
            return "whole computation steps (--step) of sub-step increments"
        return "increments" if f.input_kind == "increment" else "rate samples"

    return "; ".join(f"{ns}: {what}" for ns, what in _by_family(names, kind))


def coefficients_help(names: Iterable[AlgorithmName]) -> str:
    """The coefficient sets each of ``names`` takes, its default first."""
    def sets(f: Family) -> tuple[tuple[str, ...], str | None]:
        return tuple(f.coefficient_names()), f.default_coefficients

    parts = []
    for ns, (choices, default) in _by_family(names, sets):
        listed = [f"{c} (default)" if c == default else c
                  for c in (default, *(c for c in choices if c != default)) if c]
        parts.append(f"{ns}: " + (", ".join(listed) or "none"))
    return "; ".join(parts)


def structure_help(names: Iterable[AlgorithmName]) -> str:
    """The update structures each of ``names`` runs in, its default first."""
    groups = _by_family(names, lambda f: f.structures)
    return ("update structure; " + "; ".join(f"{ns}: {', '.join(st)}" for ns, st in groups)
            + " (single-chain: an attitude every h; sliding: every td)")
