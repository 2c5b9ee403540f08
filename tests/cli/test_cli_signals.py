"""Internal errors, SIGTERM, SIGINT and SIGKILL on the command line (issue 16): one line and
a documented status, never a traceback; temporary files removed, or — after SIGKILL, where
nothing can run — removed by the next write into the same directory."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from strapdown.cli import EXIT_INTERNAL, EXIT_STATUS, EXIT_TERMINATED, MAX_MESSAGE, main
from strapdown.io.files import atomic_path, remove_stale_temps

EXPORT = ["export-c", "--algorithm", "rotvec", "--structure", "single-chain", "--subsamples",
          "3"]


def _exit(capsys, *args) -> tuple[int, str]:
    with pytest.raises(SystemExit) as exc:
        main(list(args))
    return exc.value.code, capsys.readouterr().err


def _evaluate_raises(monkeypatch, error: BaseException) -> None:
    from strapdown.analysis import evaluate

    def boom(cfg):
        raise error

    monkeypatch.setattr(evaluate, "evaluate", boom)


def test_internal_error_is_one_bounded_line_with_status_70(monkeypatch, capsys):
    monkeypatch.delenv("STRAPDOWN_TRACEBACK", raising=False)
    _evaluate_raises(monkeypatch, RuntimeError("boom\n" + "x" * 5000))
    code, err = _exit(capsys, "evaluate", "--duration", "0.1")
    assert code == EXIT_INTERNAL == 70 and code in EXIT_STATUS
    assert err.startswith("strapdown evaluate: internal error: RuntimeError: boom x")
    assert "please report it" in err and "with the command line" in err
    assert err.count("\n") == 1 and len(err) < MAX_MESSAGE + 250 and "Traceback" not in err


def test_strapdown_traceback_reraises_the_internal_error(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_TRACEBACK", "1")
    _evaluate_raises(monkeypatch, RuntimeError("boom"))
    with pytest.raises(RuntimeError, match="boom"):
        main(["evaluate", "--duration", "0.1"])


def test_input_error_is_still_status_2(monkeypatch, capsys):
    from strapdown import InputError

    _evaluate_raises(monkeypatch, InputError("scenario.toml: bad"))
    assert _exit(capsys, "evaluate", "--duration", "0.1") == (
        2, "strapdown evaluate: error: scenario.toml: bad\n")


# A command stopped in the middle of writing its output: export-c's first file is held open
# in its temporary name (printed) until a signal arrives.
_HELD = textwrap.dedent("""
    import sys, time
    import strapdown.codegen.export_c as e
    from strapdown.io.files import atomic_path

    def held(path, text):
        with atomic_path(path) as tmp:
            tmp.write_text(text)
            print(tmp, flush=True)
            time.sleep(120)

    e.write_text = held
    from strapdown.cli import main
    sys.exit(main(sys.argv[1:]))
""")


def _held(out: Path) -> tuple[subprocess.Popen, Path]:
    proc = subprocess.Popen([sys.executable, "-c", _HELD, *EXPORT, "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    tmp = Path(proc.stdout.readline().strip())
    assert tmp.is_file() and tmp.parent == out, proc.stderr.read()
    return proc, tmp


@pytest.mark.parametrize(("sig", "status", "line"), [
    (signal.SIGTERM, EXIT_TERMINATED, "strapdown export-c: interrupted (SIGTERM)\n"),
    (signal.SIGINT, 130, "strapdown export-c: interrupted\n"),
])
def test_sigterm_and_sigint_remove_the_temporary_file(tmp_path, sig, status, line):
    out = tmp_path / "flight"
    proc, _tmp = _held(out)
    proc.send_signal(sig)
    assert proc.wait(timeout=60) == status
    assert proc.stderr.read() == line
    assert list(out.iterdir()) == []  # neither the output nor its temporary file


def test_a_sigkilled_runs_temporary_file_is_removed_by_the_next_run(tmp_path):
    out = tmp_path / "flight"
    proc, tmp = _held(out)
    assert f".{proc.pid}." in tmp.name  # the temporary name says whose it is
    proc.kill()
    assert proc.wait(timeout=60) == -signal.SIGKILL
    assert tmp.is_file()  # SIGKILL: nothing could clean up
    done = subprocess.run([sys.executable, "-m", "strapdown.cli", *EXPORT, "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    left = sorted(p.name for p in out.iterdir())
    assert not tmp.exists() and not any(n.startswith(".") for n in left) and len(left) == 2


def test_stale_temps_of_live_processes_and_other_files_are_kept(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    keep = [f".a.csv.{os.getpid()}.abcdefgh.csv",  # this process
            f".a.csv.{os.getppid()}.abcdefgh.csv",  # a live one
            f".a.csv.{dead.pid}.abc.csv",  # not mkstemp's 8 characters
            f".a.csv.{dead.pid}.abcdefgh.txt",  # not the target's suffix
            ".a.csv.abcdefgh.csv",  # no process id (an older version's)
            "a.csv"]
    gone = [f".a.csv.{dead.pid}.abcdefgh.csv", f".report.{dead.pid}.k2_9zzzz"]
    for n in keep + gone:
        (tmp_path / n).write_text("")
    assert sorted(p.name for p in remove_stale_temps(tmp_path, again=True)) == sorted(gone)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(keep)
    with atomic_path(tmp_path / "b.csv") as tmp:  # names its own temp with this pid
        assert tmp.name.startswith(f".b.csv.{os.getpid()}.") and tmp.suffix == ".csv"
        tmp.write_text("x")
    assert (tmp_path / "b.csv").read_text() == "x"
