"""The ``strapdown`` command line: one module per subcommand.

Each subcommand module (:mod:`.evaluate`, :mod:`.coefficients`, :mod:`.export_c`,
:mod:`.run`, :mod:`.nav`, :mod:`.compare`, :mod:`.sweep`, :mod:`.ahrs`, :mod:`.benchmark_ahrs`,
:mod:`.reproduce`, :mod:`.bench`) has ``add_parser(subparsers)`` and ``run(args) -> int``;
argument groups several of them share are in :mod:`._common`. Choice lists come from the
registries (algorithm families, coefficient sets, designer forms, reproductions), imported
only when their subcommand is parsed, so ``strapdown --version`` and ``--help`` load no
numerical library of their own.

Every subcommand validates its flags and exits with status 2 and one line on stderr naming
the problem on bad input (no traceback). Ctrl-C, and a file that cannot be read or written,
likewise end in one line and their own status (:data:`EXIT_STATUS`, documented in the README
and in ``strapdown --help``). A command that is about to compile the numba kernels on a cold
cache says so on stderr first (:mod:`strapdown._core.compile_notice`).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import textwrap

from strapdown._core.signals import OutsideLlvmlite, interrupts_kept, replaced_handlers
from strapdown.cli import (
    advise,
    ahrs,
    bench,
    benchmark_ahrs,
    coefficients,
    compare,
    evaluate,
    export_c,
    nav,
    reproduce,
    run,
    sweep,
)
from strapdown.cli._common import CommandParser, HelpFormatter, Parser, say

__all__ = ["COMMANDS", "EXIT_STATUS", "build_parser", "main"]

#: The subcommand modules, in the order ``strapdown --help`` lists them.
COMMANDS = (evaluate, coefficients, export_c, run, nav, compare, sweep, ahrs, benchmark_ahrs,
            reproduce, bench, advise)

EXIT_OK, EXIT_USAGE, EXIT_IO, EXIT_INTERRUPTED, EXIT_PIPE = 0, 2, 74, sweep.INTERRUPTED, 141
#: An internal error (a bug; sysexits' EX_SOFTWARE) and SIGTERM (128 + 15, as a shell reports).
EXIT_INTERNAL, EXIT_TERMINATED = 70, 128 + signal.SIGTERM

#: Where an internal error asks to be reported (with the command line).
REPORT_TO = "the strapdown issue tracker"
#: Longest message of an internal error (characters), so one line stays one line.
MAX_MESSAGE = 300

#: Every exit status of every command and what it means (README, ``strapdown --help``).
EXIT_STATUS = {
    EXIT_OK: "success",
    EXIT_USAGE: "bad input: an option, a value or an input file is wrong (one line on stderr "
    "names it; nothing is written)",
    sweep.INCOMPLETE: "sweep only: stopped by --max-cases before the grid was complete "
    "(rerun to finish)",
    EXIT_INTERNAL: "an internal error (a bug): one line names it, please report it with the "
    "command line; STRAPDOWN_TRACEBACK=1 prints the traceback instead",
    EXIT_IO: "a file or directory could not be read or written (one line names the path)",
    EXIT_INTERRUPTED: "interrupted (Ctrl-C); a sweep keeps its finished cases, rerun the same "
    "command to resume",
    EXIT_PIPE: "stdout closed early (e.g. piped into head); nothing more is printed",
    EXIT_TERMINATED: "terminated (SIGTERM): as Ctrl-C, temporary files are removed",
}

#: Commands that never run a numba kernel: no compile notice (numba is not even imported).
_NO_KERNELS = frozenset({"coefficients"})


class _LinesFormatter(HelpFormatter):
    """Wraps each line of the description and epilog on its own (one exit status a line)."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        return "\n".join(textwrap.fill(line, width, initial_indent=indent, subsequent_indent=(
            indent + " " * 7 if line.startswith("  ") else indent)) for line in text.splitlines())


def build_parser() -> argparse.ArgumentParser:
    """The ``strapdown`` parser; each subcommand's options are added when it is used."""
    from strapdown import __version__

    p = Parser(prog="strapdown", description="Strapdown attitude algorithms for high-dynamic "
               "bodies: evaluate algorithms against exact motions, reproduce papers.",
               formatter_class=_LinesFormatter,
               epilog="exit status:\n" + "\n".join(f"  {code:<5d}{text}"
                                                    for code, text in EXIT_STATUS.items()))
    p.add_argument("--version", action="version", version=f"strapdown {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=CommandParser)
    for command in COMMANDS:
        command.add_parser(sub)
    return p


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the process is so that cleanup (temporary files) runs as on Ctrl-C."""


def main(argv: list[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    Bad input exits with status 2 and ``strapdown COMMAND: error: …`` on stderr; Ctrl-C with
    130 and ``strapdown COMMAND: interrupted``, SIGTERM likewise with 143 (both after the
    temporary files are removed); an unreadable or unwritable file with 74 and the path; any
    other exception (a bug) with 70 and one line asking to report it, or its traceback when
    the environment has ``STRAPDOWN_TRACEBACK=1`` (see :data:`EXIT_STATUS`). These exits
    raise ``SystemExit`` as argparse does.
    """
    got: list[int] = []
    owner = os.getpid()

    def on_sigterm(signum, frame) -> None:
        # one SIGTERM is enough: a second one (a pool's terminate() after the process
        # group's signal) must not interrupt the cleanup the first one started
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        if os.getpid() != owner:  # a forked pool worker (a sweep's): exit, quietly, releasing
            # its locks (the pool's queues) on the way out (should a finaliser drop it, the
            # sweep kills the worker: apps.sweep._terminate)
            raise SystemExit(EXIT_TERMINATED)
        got.append(signum)
        raise Terminated()

    # neither signal's exception is raised inside llvmlite (numba loading or compiling a
    # kernel): held back there, it comes a moment later, or at the latest at the end
    guards = {signal.SIGTERM: OutsideLlvmlite(on_sigterm)}
    previous = {}
    try:
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not if ignored
            guards[signal.SIGINT] = OutsideLlvmlite(signal.default_int_handler)
        for s, guard in guards.items():
            previous[s] = signal.signal(s, guard)
    except ValueError:  # not the main thread: signals stay as they are
        guards = {}
    try:
        with interrupts_kept():  # Ctrl-C landing in a finaliser: delivered again, no traceback
            return _main(argv, got, list(guards.values()))
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def _main(argv: list[str] | None, got: list[int], guards: list[OutsideLlvmlite]) -> int:
    """:func:`main` once the signal handlers are in place; ``got`` lists the signals
    received; a signal ``guards`` still hold back when the command is done is raised then."""
    prog = "strapdown"
    try:
        parser = build_parser()
        args = parser.parse_args(sys.argv[1:] if argv is None else argv)
        prog = f"strapdown {args.command}"
        from strapdown._core.limits import memory_budget

        with memory_budget(getattr(args, "max_memory", None)):  # --max-memory, where it is
            if args.command in _NO_KERNELS:
                status = args.handler(args)
            else:
                from strapdown._core.compile_notice import notice

                with notice(say):
                    status = args.handler(args)
        for guard in guards:
            guard.settle()
        return status
    except ValueError as exc:
        _exit(EXIT_USAGE, f"{prog}: error: {exc}\n")
    except KeyboardInterrupt as exc:  # a sweep's says how far it got
        status = EXIT_TERMINATED if got or isinstance(exc, Terminated) else EXIT_INTERRUPTED
        text = str(exc) or "interrupted"
        _exit(status, f"{prog}: {text if status == EXIT_INTERRUPTED else _terminated(text)}\n")
    except BrokenPipeError:
        _silence_stdout()
        _exit(EXIT_PIPE)
    except OSError as exc:
        _exit(EXIT_IO, f"{prog}: error: {_os_error(exc)}\n")
    except Exception as exc:
        if os.environ.get("STRAPDOWN_TRACEBACK", "") not in ("", "0"):
            raise
        _exit(EXIT_INTERNAL, f"{prog}: {_internal(exc)}\n")
    return 1  # pragma: no cover


def _exit(status: int, message: str | None = None) -> None:
    """Print ``message`` on stderr and raise ``SystemExit(status)`` (argparse's ``exit``)."""
    if message:
        with replaced_handlers(signal.SIG_IGN):  # a second Ctrl-C adds nothing
            sys.stderr.write(message)
            sys.stderr.flush()
    raise SystemExit(status)


def _terminated(text: str) -> str:
    """The interruption line, saying it was SIGTERM."""
    return text.replace("interrupted", "interrupted (SIGTERM)", 1)


def _internal(exc: Exception) -> str:
    """One bounded line naming an unexpected exception and where to report it."""
    msg = " ".join(str(exc).split())
    if len(msg) > MAX_MESSAGE:
        msg = msg[:MAX_MESSAGE - 1] + "…"
    return (f"internal error: {type(exc).__name__}: {msg}; please report it to {REPORT_TO} "
            "with the command line (STRAPDOWN_TRACEBACK=1 shows the traceback)")


def _os_error(exc: OSError) -> str:
    """``path: reason`` (both paths of a rename or copy), or the error's own text."""
    paths = [str(p) for p in (exc.filename, exc.filename2) if p is not None]
    if not paths:
        return str(exc)
    return f"{' -> '.join(paths)}: {exc.strerror or type(exc).__name__}"


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush into a closed pipe is quiet."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no real stdout (captured): nothing to silence
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
