"""Exit statuses: Ctrl-C, unwritable files and a closed stdout end in one line (or none) and
their documented status, never a traceback; ``strapdown --help`` lists every status."""

from __future__ import annotations

import subprocess
import sys

import pytest

from cli_helpers import evaluate_raises, exit_of
from strapdown.cli import EXIT_STATUS, main


def test_ctrl_c_is_one_line_and_status_130(monkeypatch, capsys):
    evaluate_raises(monkeypatch, KeyboardInterrupt())
    assert exit_of(capsys, "evaluate", "--duration", "0.1") == (
        130, "strapdown evaluate: interrupted\n")


def test_sweep_interruption_says_how_far_it_got(monkeypatch, capsys):
    from strapdown.apps import sweep

    def interrupted(*args, **kwargs):
        raise sweep.SweepInterrupted(9, 30)

    monkeypatch.setattr(sweep, "sweep", interrupted)
    assert exit_of(capsys, "sweep", "scenario.toml", "--out", "o") == (
        130, "strapdown sweep: interrupted, 9/30 cases done; rerun the same command to resume\n")


@pytest.mark.parametrize(("error", "line"), [
    (PermissionError(13, "Permission denied", "out/att.csv"), "out/att.csv: Permission denied"),
    (OSError(28, "No space left on device", "a.tmp", None, "a.csv"),
     "a.tmp -> a.csv: No space left on device"),
    (OSError("no path given"), "no path given"),
])
def test_os_error_names_the_path_with_status_74(monkeypatch, capsys, error, line):
    evaluate_raises(monkeypatch, error)
    assert exit_of(capsys, "evaluate", "--duration", "0.1") == (
        74, f"strapdown evaluate: error: {line}\n")


def test_unwritable_output_names_the_target_not_a_temp_file(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")  # a file where the output directory should be
    code, err = exit_of(capsys, "export-c", "--algorithm", "rotvec", "--structure",
                      "single-chain", "--subsamples", "3", "--out", str(blocker / "flight"))
    assert code == 74 and err.startswith("strapdown export-c: error: ")
    assert str(blocker) in err and "/." not in err and "Traceback" not in err


def test_closed_stdout_is_quiet_with_status_141():
    proc = subprocess.Popen([sys.executable, "-m", "strapdown.cli", "coefficients", "--form",
                             "cross-with-last", "--subsamples", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdout.close()  # the reader is gone before the command prints
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 141 and err == ""


def test_help_lists_every_exit_status(capsys):
    assert exit_of(capsys, "--help")[0] == 0
    # (help goes to stdout; exit_of read stderr, so read the help again)
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    epilog = text[text.index("exit status:"):].splitlines()[1:]
    listed = [int(line.split()[0]) for line in epilog if line.startswith("  ") and
              line.split()[0].isdigit()]
    assert listed == list(EXIT_STATUS) == sorted(EXIT_STATUS)
    assert {0, 2, 3, 74, 130} <= set(EXIT_STATUS)


def _log(tmp_path):
    import numpy as np

    t = np.arange(100) * 1e-3
    path = tmp_path / "a.npy"
    np.save(path, np.column_stack([t, np.full(100, 0.5), np.zeros(100), np.zeros(100)]))
    return str(path)


@pytest.mark.parametrize(("out", "reason"), [
    ("outdir.csv", "outdir.csv: Is a directory"),
    ("afile/x.csv", "afile: Not a directory (a file, where the output directory should be)"),
])
def test_output_path_errors_are_one_line_with_status_74(tmp_path, capsys, out, reason):
    (tmp_path / "outdir.csv").mkdir()
    (tmp_path / "afile").write_text("")
    code, err = exit_of(capsys, "run", "--imu", _log(tmp_path), "--rates", "--units", "rad/s",
                      "--out", str(tmp_path / out))
    assert code == 74 and err.strip().endswith(reason) and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npy", "afile", "outdir.csv"]
    assert not list((tmp_path / "outdir.csv").iterdir())


def test_unwritable_output_directory_is_status_74(tmp_path, capsys, monkeypatch):
    import tempfile

    def refuse(*, prefix, suffix, dir):
        raise PermissionError(13, "Permission denied", dir)

    log = _log(tmp_path)
    monkeypatch.setattr(tempfile, "mkstemp", refuse)  # as a read-only directory does
    code, err = exit_of(capsys, "run", "--imu", log, "--rates", "--units", "rad/s", "--out",
                      str(tmp_path / "ro" / "x.csv"))
    assert code == 74 and err.strip().endswith("x.csv.meta.json: Permission denied")


def test_unreadable_input_is_status_74_naming_it(tmp_path, capsys, monkeypatch):
    import builtins

    log = _log(tmp_path)
    real_open = builtins.open

    def guarded(file, *args, **kwargs):
        if str(file) == log:
            raise PermissionError(13, "Permission denied", log)
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", guarded)
    code, err = exit_of(capsys, "run", "--imu", log, "--rates", "--units", "rad/s", "--out",
                      str(tmp_path / "x.csv"))
    assert (code, err) == (74, f"strapdown run: error: {log}: Permission denied\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npy"]


def test_an_input_directory_is_bad_input(tmp_path, capsys):
    code, err = exit_of(capsys, "run", "--imu", str(tmp_path), "--rates", "--units", "rad/s",
                      "--out", str(tmp_path / "x.csv"))
    assert code == 2 and "is a directory; expected a log file" in err
