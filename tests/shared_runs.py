"""Expensive runs that a documented command and a test both make, made once per process.

The README's ``strapdown benchmark-ahrs "$STRAPDOWN_BROAD" --out …`` runs every filter on
the fifteen BROAD trials, and so did tests/ahrs/test_ahrs.py's acceptance test, with the same
arguments; the README's ``strapdown reproduce plaksiy2024 --out …`` is what
tests/cli/test_cli.py's report test ran. tests/docs/test_docs_commands.py runs the documented
commands in this process (tests/inprocess.py) under :func:`recording`, which keeps what they
computed; a test then takes the documented run's results when this process made it with the
arguments the test needs, and makes the run itself otherwise (run alone, or the command
failed: that test fails on its own). The command and the function are the real ones either
way; only the second run is gone.

tests/conftest.py (``RUN_AFTER``) runs those tests after the documented commands, on the same
pytest-xdist worker.
"""

from __future__ import annotations

import copy
import inspect
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["broad_benchmark", "documented_out", "recording", "succeeded"]

#: ``(BROAD directory, algorithm, heading_offset_removed)`` → (results, report directory)
_BROAD: dict[tuple[str, str, bool], tuple[dict, Path]] = {}
#: ``(argv, working directory)`` of every in-process command that exited 0, in order
_RAN: list[tuple[tuple[str, ...], Path]] = []


@contextmanager
def recording() -> Iterator[None]:
    """In-process commands with :func:`strapdown.apps.ahrs_benchmark.benchmark` recorded (it
    runs as always); the caller says :func:`succeeded` of each command that exited 0."""
    from strapdown.apps import ahrs_benchmark as ab

    real = ab.benchmark
    signature = inspect.signature(real)

    def spy(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        res = real(*args, **kwargs)
        a = bound.arguments
        if a["config"] is not None:  # not the defaults a test takes the results for
            return res
        key = (str(Path(a["directory"]).resolve()), a["algorithm"],
               bool(a["heading_offset_removed"]))
        _BROAD[key] = (copy.deepcopy(res), Path(a["out"]).resolve())
        return res

    ab.benchmark = spy
    try:
        yield
    finally:
        ab.benchmark = real


def succeeded(argv: list[str], cwd: Path) -> None:
    """Note an in-process command that exited 0."""
    _RAN.append((tuple(argv), Path(cwd).resolve()))


def broad_benchmark(directory: Path, out: Path) -> tuple[dict, Path]:
    """``benchmark(directory, out)`` with its defaults (rate-single, BROAD's metric): the
    results and the report's directory, the documented command's if this process ran it."""
    from strapdown.apps.ahrs_benchmark import benchmark

    default = inspect.signature(benchmark).parameters
    key = (str(Path(directory).resolve()), default["algorithm"].default,
           bool(default["heading_offset_removed"].default))
    if key in _BROAD:
        return _BROAD[key]
    return benchmark(directory, out), out


def documented_out(*argv: str) -> Path | None:
    """The output directory of an in-process ``strapdown ARGV… --out DIR`` run (nothing
    else on its line) that exited 0 in this process, the last one; None if there was none."""
    for args, cwd in reversed(_RAN):
        if len(args) == len(argv) + 3 and args[:-2] == ("strapdown", *argv) \
                and args[-2] == "--out":
            return cwd / args[-1]
    return None
