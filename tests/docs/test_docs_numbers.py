"""Every number README.md and docs/*.md quote from a command is what that command prints.

A document declares the commands its numbers come from, each in an HTML comment on a line of
its own (invisible on GitHub and on the site)::

    <!-- source eval-n3: strapdown evaluate --subsamples 3 ... --json -->
    <!-- source sculling (long): strapdown reproduce sculling --out out -->

and marks each quoted number with a comment written right after its last digit::

    measured/law −3.84<!--= eval-n3 json measured_over_law --> here
    0.00126<!--= sculling csv static.csv "at rest 2 h" measured --> mm

The marker names the source, then where the value is:

``json KEY[.KEY…]``
    the source's standard output is JSON; a dotted path (integers index lists);
``csv FILE ROW COLUMN [K]``
    a CSV file the command wrote (relative to its working directory): the row whose first
    cell is ROW, else the first whose first cell starts with ROW; the column whose header
    starts with COLUMN; the K-th number in that cell (default the first: cells such as
    ``0.00126 mm`` or ``9.71, 11.97, 7.55``);
``re PATTERN [FILE]``
    the first group of a regular expression searched in the standard output (or FILE).

(arguments are split as by a shell: quote those with spaces.) The quoted number passes when
the printed value rounded to the quoted number of significant digits is the quoted number
(``−`` is a minus; trailing zeros count: ``0.9970`` is four digits).

Each source runs once, in a fresh temporary directory that holds only a link to the checkout's
``examples/``, with ``python`` and ``strapdown`` this interpreter's (a plain command line in
this process, tests/inprocess.py; as
``tests/docs/test_docs_commands.py`` runs the documented commands). A source marked
``(long)`` — a reproduction of minutes — runs only with ``STRAPDOWN_DOCS_LONG=1``; its
numbers are skipped otherwise, saying so. Adding a number is adding a marker after it (and a
source line if its command is new); a marker without a source, a source without a marker,
a comment that looks like a marker but does not parse, all fail.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest

from inprocess import in_process_argvs, run_in_process

REPO = Path(__file__).resolve().parents[2]
LONG = os.environ.get("STRAPDOWN_DOCS_LONG") == "1"
DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]

_SOURCE = re.compile(r"^<!-- source (?P<name>[\w.-]+)(?P<long> \(long\))?: (?P<cmd>.+?) -->$",
                     re.M)
_NUMBER = r"[-−+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-−+]?\d+)?"
_MARKER = re.compile(rf"(?P<num>{_NUMBER})?<!--= (?P<spec>.*?) -->")
_FLOAT = re.compile(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?|nan|inf")


@dataclass(frozen=True)
class Source:
    doc: str
    name: str
    command: str
    long: bool


@dataclass(frozen=True)
class Quote:
    doc: str
    line: int
    quoted: str | None  # None: no number right before the marker (a parse error)
    source: str
    where: tuple[str, ...]

    @property
    def id(self) -> str:
        return f"{self.doc}:{self.line}-{self.source}-{self.quoted}"


def _rel(path: Path) -> str:
    return path.relative_to(REPO).as_posix()


def parse(doc: str, text: str) -> tuple[dict[str, Source], list[Quote]]:
    sources = {m["name"]: Source(doc, m["name"], m["cmd"], bool(m["long"]))
               for m in _SOURCE.finditer(text)}
    quotes = []
    for m in _MARKER.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        try:
            parts = tuple(shlex.split(m["spec"]))
        except ValueError:
            parts = ()
        quotes.append(Quote(doc, line, m["num"], parts[0] if parts else "", parts[1:]))
    return sources, quotes


SOURCES: dict[tuple[str, str], Source] = {}
QUOTES: list[Quote] = []
for _path in DOCUMENTS:
    _s, _q = parse(_rel(_path), _path.read_text("utf-8"))
    SOURCES.update({(_rel(_path), k): v for k, v in _s.items()})
    QUOTES += _q


def significant_digits(quoted: str) -> int:
    mantissa = re.split(r"[eE]", quoted.lstrip("-−+"))[0].replace(".", "")
    return max(len(mantissa.lstrip("0")), 1)


def to_float(quoted: str) -> float:
    return float(quoted.replace("−", "-"))


def agrees(quoted: str, printed: float) -> bool:
    """``printed`` rounded to the quoted significant digits is the quoted value."""
    if not math.isfinite(printed):
        return False
    rounded = float(f"{printed:.{significant_digits(quoted) - 1}e}")
    return math.isclose(rounded, to_float(quoted), rel_tol=1e-9, abs_tol=0.0)


@dataclass
class Output:
    cwd: Path
    stdout: str
    error: str | None = None  # the command failed: why (kept, so that it runs only once)


def _shims(bin_dir: Path) -> None:
    bin_dir.mkdir(parents=True)
    for name, tail in (("python", '"$@"'), ("strapdown", '-m strapdown.cli "$@"')):
        shim = bin_dir / name
        shim.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} {tail}\n")
        shim.chmod(0o755)


@pytest.fixture(scope="module")
def run_source(tmp_path_factory):
    bin_dir = tmp_path_factory.mktemp("numbers-bin") / "bin"
    _shims(bin_dir)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}",
               MPLBACKEND="Agg")

    @cache
    def run_command(command: str, name: str) -> Output:
        cwd = tmp_path_factory.mktemp(f"numbers-{name}")
        (cwd / "examples").symlink_to(REPO / "examples", target_is_directory=True)
        argvs = in_process_argvs(command, env)
        if argvs is not None:  # no shell needed: the same argv, without a new interpreter
            code, stdout, stderr = run_in_process(argvs, cwd, env)
            if code:
                return Output(cwd, stdout, f"source {name}: `{command}` exited {code}:\n"
                                           f"{stderr[-3000:]}")
            return Output(cwd, stdout)
        try:
            proc = subprocess.run(["bash", "-c", command], cwd=cwd, env=env,
                                  capture_output=True, text=True, timeout=1800)
        except subprocess.TimeoutExpired:
            return Output(cwd, "", f"source {name}: `{command}` ran over 1800 s")
        if proc.returncode:
            return Output(cwd, proc.stdout, f"source {name}: `{command}` exited "
                                            f"{proc.returncode}:\n{proc.stderr[-3000:]}")
        return Output(cwd, proc.stdout)

    def run(key: tuple[str, str]) -> Output:
        """The source's output; documents that declare the same command share one run."""
        return run_command(SOURCES[key].command, SOURCES[key].name)

    return run


def extract(out: Output, where: tuple[str, ...]) -> float:
    """The printed value a marker's location names (see the module docstring)."""
    kind, args = where[0], where[1:]
    if kind == "json":
        value = json.loads(out.stdout)
        for key in args[0].split("."):
            value = value[int(key)] if isinstance(value, list) else value[key]
        return float(value)
    if kind == "csv":
        file, row, column = args[:3]
        k = int(args[3]) if len(args) > 3 else 1
        with open(out.cwd / file, newline="", encoding="utf-8") as fh:
            table = list(csv.reader(fh))
        header = table[0]
        col = next(i for i, h in enumerate(header) if h.startswith(column))
        cells = ([r for r in table[1:] if r and r[0] == row]
                 or [r for r in table[1:] if r and r[0].startswith(row)])
        assert cells, f"no row starting with {row!r} in {file}: {[r[0] for r in table[1:]]}"
        numbers = _FLOAT.findall(cells[0][col].replace("−", "-"))
        return float(numbers[k - 1])
    if kind == "re":
        text = (out.cwd / args[1]).read_text("utf-8") if len(args) > 1 else out.stdout
        m = re.search(args[0], text)
        assert m, f"{args[0]!r} not found in the output:\n{text[-2000:]}"
        return float(m.group(1).replace("−", "-"))
    raise AssertionError(f"unknown location kind {kind!r} (json, csv, re)")


def _key(q: Quote) -> tuple[str, str]:
    return (q.doc, q.source)


@pytest.mark.parametrize("quote", QUOTES, ids=[q.id for q in QUOTES])
def test_quoted_number_is_what_the_command_prints(run_source, quote):
    assert quote.quoted is not None, (f"{quote.doc}:{quote.line}: a marker must follow the "
                                      "last digit of the number it checks")
    assert _key(quote) in SOURCES, (f"{quote.doc}:{quote.line}: no `<!-- source "
                                    f"{quote.source}: … -->` line in {quote.doc}")
    assert quote.where and quote.where[0] in ("json", "csv", "re"), (
        f"{quote.doc}:{quote.line}: the marker says where the number is: json, csv or re")
    src = SOURCES[_key(quote)]
    if src.long and not LONG:
        pytest.skip(f"source {src.name} is long: `{src.command}` (STRAPDOWN_DOCS_LONG=1 "
                    "runs it)")
    out = run_source(_key(quote))
    assert out.error is None, out.error
    printed = extract(out, quote.where)
    assert agrees(quote.quoted, printed), (
        f"{quote.doc}:{quote.line} quotes {quote.quoted}; `{src.command}` prints {printed!r}"
        f" (rounded to the quoted digits: {printed:.{significant_digits(quote.quoted) - 1}e})")


def test_every_source_is_quoted():
    used = {_key(q) for q in QUOTES}
    unused = [f"{d}: {n}" for (d, n) in SOURCES if (d, n) not in used]
    assert not unused, f"sources nothing quotes: {unused}"


def test_markers_are_found():
    """The parser sees the markers (a changed syntax would otherwise test nothing), and every
    comment that starts like one parses as one."""
    for path in DOCUMENTS:
        text = path.read_text("utf-8")
        assert text.count("<!--=") == len(_MARKER.findall(text)), _rel(path)
        assert text.count("<!-- source ") == len(_SOURCE.findall(text)), _rel(path)
    assert len(QUOTES) >= 10
    docs = {q.doc for q in QUOTES}
    assert {"README.md", "docs/algorithms.md"} <= docs


@pytest.mark.parametrize(("quoted", "printed", "ok"), [
    ("0.9970", 0.9970277768631463, True), ("0.9985", 0.9970277768631463, False),
    ("−3.84", -3.840617, True), ("-3.85", -3.840617, False), ("153", 153.11364, True),
    ("6.16e-5", 6.156e-05, True), ("6.17e-5", 6.156e-05, False), ("0.00126", 0.00126, True),
    ("2.0e-4", 6.156e-05, False), ("1.0006", 1.000582, True),
])
def test_rounding_rule(quoted, printed, ok):
    assert agrees(quoted, printed) is ok
