"""Every shell command of docs/tutorial.md and of the README's command-line section runs as
written and exits with status 0.

Each document's ```sh blocks run in order in one fresh temporary directory that holds only a
link to the checkout's ``examples/`` (as a fresh clone would), in one simulated shell whose
working directory carries over from command to command (``cd work`` stays in effect);
``python`` and ``strapdown`` are this interpreter's (a plain ``strapdown …`` or
``python SCRIPT.py …`` line runs in this process, as tests/inprocess.py says). A command is
skipped only when its trailing comment marks it, and the skip says why:

- ``# long: …`` — a long run (benchmarks, the slower reproductions, each also covered by its
  own test); set ``STRAPDOWN_DOCS_LONG=1`` to run them too (then a quoted ``about N s`` or
  ``about N min`` must be within a factor of 3 of the measured run time);
- ``# needs STRAPDOWN_BROAD`` — the BROAD trials: ``$STRAPDOWN_BROAD``, else
  ``shared/data/broad`` beside the checkout (as for the BROAD tests);
- ``# needs a Dask scheduler`` — a running scheduler at the address the command names.

Any other ``# needs …`` fails: a command is never skipped by guessing. After the last
command, nothing but ``work/`` may have been written (the docs promise it).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from conftest import BROAD
from inprocess import in_process_argvs, run_in_process
from shared_runs import recording, succeeded

REPO = Path(__file__).resolve().parents[2]
LONG = os.environ.get("STRAPDOWN_DOCS_LONG") == "1"


@dataclass(frozen=True)
class Command:
    """One logical command line of a document (continuations joined)."""

    doc: str
    index: int
    line: str
    comment: str

    @property
    def needs(self) -> str | None:
        """What the trailing comment says the command needs (None: nothing)."""
        c = self.comment
        if c.startswith("long"):
            return "long"
        if c.startswith("needs"):
            return c.split(";")[0].strip()
        return None


def _split_comment(line: str) -> tuple[str, str]:
    """``cmd  # comment`` → ``("cmd", "comment")``; a ``#`` inside quotes is not one."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip(), line[i + 1:].strip()
    return line.rstrip(), ""


def _blocks(text: str) -> list[str]:
    return re.findall(r"^```sh\n(.*?)^```", text, flags=re.S | re.M)


def _commands(doc: str, text: str) -> list[Command]:
    out: list[Command] = []
    for block in _blocks(text):
        logical = re.sub(r"\\\n\s*", " ", block)  # join continuation lines
        for raw in logical.splitlines():
            line, comment = _split_comment(raw.strip())
            if line:
                out.append(Command(doc, len(out), line, comment))
    return out


def _readme_cli() -> str:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    start = text.index("\n## Command line\n")
    end = text.index("\n## ", start + 1)
    return text[start:end]


DOCS = {
    "tutorial": _commands("tutorial", (REPO / "docs" / "tutorial.md").read_text("utf-8")),
    "README": _commands("README", _readme_cli()),
}
ALL = [c for cmds in DOCS.values() for c in cmds]


def _skip_reason(cmd: Command) -> str | None:
    need = cmd.needs
    if need is None:
        return None
    if need == "long":
        return None if LONG else f"{cmd.comment} (STRAPDOWN_DOCS_LONG=1 runs it)"
    if need == "needs STRAPDOWN_BROAD":
        return None if BROAD is not None and BROAD.is_dir() else (
            "no BROAD trials: set STRAPDOWN_BROAD or put them in shared/data/broad beside the "
            "checkout")
    if need == "needs a Dask scheduler":
        return "needs a running Dask scheduler at the address it names"
    pytest.fail(f"{cmd.doc}: unknown requirement {need!r} in the comment of: {cmd.line}")


@dataclass
class Result:
    returncode: int
    stdout: str
    stderr: str
    seconds: float


@dataclass
class Session:
    """One document's commands run in order in one directory, ``cd`` carried over."""

    root: Path
    cwd: Path
    env: dict
    results: dict[int, Result | None] = field(default_factory=dict)

    def run_through(self, cmds: list[Command], index: int) -> None:
        for cmd in cmds[:index + 1]:
            if cmd.index not in self.results:
                self.results[cmd.index] = None if _skip_reason(cmd) else self._run(cmd.line)

    def _run(self, line: str) -> Result:
        argvs = in_process_argvs(line, self.env)
        if argvs is not None:  # no shell needed: the same argv, without a new interpreter
            t0 = time.perf_counter()
            with recording():  # what a test would compute again (tests/shared_runs.py)
                code, out, err = run_in_process(argvs, self.cwd, self.env)
            if code == 0:
                for argv in argvs:
                    succeeded(argv, self.cwd)
            return Result(code, out, err, time.perf_counter() - t0)
        state = self.root / ".cwd"
        script = f"cd {shlex.quote(str(self.cwd))} || exit 99\n{line}\nrc=$?\n" \
                 f"pwd > {shlex.quote(str(state))}\nexit $rc\n"
        t0 = time.perf_counter()
        proc = subprocess.run(["bash", "-c", script], env=self.env, capture_output=True,
                              text=True, timeout=900)
        if state.is_file():
            self.cwd = Path(state.read_text().strip())
            state.unlink()
        return Result(proc.returncode, proc.stdout, proc.stderr, time.perf_counter() - t0)


def _shims(bin_dir: Path) -> None:
    """``python`` and ``strapdown`` that run this interpreter (with its environment)."""
    bin_dir.mkdir()
    for name, tail in (("python", '"$@"'), ("strapdown", '-m strapdown.cli "$@"')):
        shim = bin_dir / name
        shim.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} {tail}\n")
        shim.chmod(0o755)


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    bin_dir = tmp_path_factory.mktemp("bin")
    bin_dir.rmdir()
    _shims(bin_dir)
    env = {k: v for k, v in os.environ.items() if k != "STRAPDOWN_BROAD"}
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    if BROAD is not None:
        env["STRAPDOWN_BROAD"] = str(BROAD)
    out = {}
    for doc in DOCS:
        root = tmp_path_factory.mktemp(f"docs-{doc}")
        (root / "examples").symlink_to(REPO / "examples", target_is_directory=True)
        out[doc] = Session(root, root, env)
    return out


@pytest.mark.parametrize("cmd", ALL, ids=[f"{c.doc}-{c.index:02d}-{c.line[:50]}" for c in ALL])
def test_documented_command_exits_0(sessions, cmd):
    reason = _skip_reason(cmd)
    if reason:
        pytest.skip(reason)
    session = sessions[cmd.doc]
    session.run_through(DOCS[cmd.doc], cmd.index)
    res = session.results[cmd.index]
    assert res is not None
    assert res.returncode == 0, (f"{cmd.doc}: `{cmd.line}` exited {res.returncode} after "
                                 f"{res.seconds:.1f} s\nstderr:\n{res.stderr[-3000:]}")


@pytest.mark.parametrize("doc", list(DOCS))
def test_documents_write_only_into_work(sessions, doc):
    session = sessions[doc]
    session.run_through(DOCS[doc], len(DOCS[doc]) - 1)
    assert {p.name for p in session.root.iterdir()} <= {"examples", "work"}
    assert (session.root / "work").is_dir()
    written = [p.name for p in (REPO / "examples").iterdir()  # examples/ is the checkout's
               if p.suffix in {".csv", ".npy", ".npz"}]
    assert written == []


def test_every_command_block_was_found():
    """The parser sees the blocks (a changed fence would otherwise test nothing)."""
    assert len(DOCS["tutorial"]) >= 8 and len(DOCS["README"]) >= 25
    assert DOCS["README"][0].line == "mkdir -p work && cd work"
    assert DOCS["tutorial"][0].line == "mkdir -p work && cd work"
    assert all(c.needs in (None, "long", "needs STRAPDOWN_BROAD", "needs a Dask scheduler")
               for c in ALL)


def test_readme_lists_every_exit_status():
    from strapdown.cli import EXIT_STATUS

    table = re.findall(r"^\| (\d+) \| (.+) \|$", _readme_cli(), flags=re.M)
    assert [int(code) for code, _ in table] == list(EXIT_STATUS)


#: How far a quoted duration may be from the measured one (either way): the quotes were
#: measured on the reference machine when idle, a loaded test run is slower.
DURATION_FACTOR = 3.0
_ABOUT = re.compile(r"about (\d+(?:\.\d+)?) (s|min)\b")
TIMED = [c for c in ALL if c.needs == "long" and _ABOUT.search(c.comment)]


def quoted_seconds(comment: str) -> float:
    m = _ABOUT.search(comment)
    assert m is not None
    return float(m.group(1)) * (60.0 if m.group(2) == "min" else 1.0)


@pytest.mark.parametrize("cmd", TIMED, ids=[f"{c.doc}-{c.index:02d}-{c.line[:50]}"
                                            for c in TIMED])
def test_quoted_duration_is_measured(sessions, cmd):
    """A `# long: about N s` comment is within DURATION_FACTOR of the command's run time."""
    reason = _skip_reason(cmd)
    if reason:
        pytest.skip(reason)
    session = sessions[cmd.doc]
    session.run_through(DOCS[cmd.doc], cmd.index)
    res = session.results[cmd.index]
    assert res is not None and res.returncode == 0
    quoted = quoted_seconds(cmd.comment)
    assert quoted / DURATION_FACTOR <= res.seconds <= quoted * DURATION_FACTOR, (
        f"{cmd.doc}: `{cmd.line}` says {cmd.comment!r} but took {res.seconds:.0f} s")


def test_durations_are_parsed():
    assert len(TIMED) >= 5
    assert quoted_seconds("long: about 3.5 min") == 210.0
