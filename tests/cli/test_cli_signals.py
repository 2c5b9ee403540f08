"""Internal errors, SIGTERM, SIGINT and SIGKILL on the command line (issue 16): one line and
a documented status, never a traceback; temporary files removed, or — after SIGKILL, where
nothing can run — removed by the next write into the same directory."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from cli_helpers import default_sigint, evaluate_raises, exit_of
from strapdown.cli import EXIT_INTERNAL, EXIT_STATUS, EXIT_TERMINATED, MAX_MESSAGE, main
from strapdown.io.files import atomic_path, remove_stale_temps

EXPORT = ["export-c", "--algorithm", "rotvec", "--structure", "single-chain", "--subsamples",
          "3"]


def test_internal_error_is_one_bounded_line_with_status_70(monkeypatch, capsys):
    monkeypatch.delenv("STRAPDOWN_TRACEBACK", raising=False)
    evaluate_raises(monkeypatch, RuntimeError("boom\n" + "x" * 5000))
    code, err = exit_of(capsys, "evaluate", "--duration", "0.1")
    assert code == EXIT_INTERNAL == 70 and code in EXIT_STATUS
    assert err.startswith("strapdown evaluate: internal error: RuntimeError: boom x")
    assert "please report it" in err and "with the command line" in err
    assert err.count("\n") == 1 and len(err) < MAX_MESSAGE + 250 and "Traceback" not in err


def test_strapdown_traceback_reraises_the_internal_error(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_TRACEBACK", "1")
    evaluate_raises(monkeypatch, RuntimeError("boom"))
    with pytest.raises(RuntimeError, match="boom"):
        main(["evaluate", "--duration", "0.1"])


def test_input_error_is_still_status_2(monkeypatch, capsys):
    from strapdown import InputError

    evaluate_raises(monkeypatch, InputError("scenario.toml: bad"))
    assert exit_of(capsys, "evaluate", "--duration", "0.1") == (
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
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_sigint)
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


def test_ctrl_c_while_the_kernels_compile_is_one_line(tmp_path):
    from fuzz import corpus

    imu = tmp_path / "log.csv"
    imu.write_bytes(corpus.valid_seeds(tmp_path)["csv"])
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cold")}  # compiles
    proc = subprocess.Popen([sys.executable, "-m", "strapdown.cli", "run", "--imu", str(imu),
                             "--rates", "--units", "rad/s", "--out", str(tmp_path / "o.csv")],
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                            env=env, preexec_fn=default_sigint)
    assert "compiling the numba kernels" in proc.stderr.readline()
    proc.send_signal(signal.SIGINT)
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 130 and err == "strapdown run: interrupted\n"
    assert not list(tmp_path.glob("o.csv*")) and not list(tmp_path.glob(".o.csv*"))


_SCENARIO = """\
algorithms = ["rotvec:N=2", "rotvec:N=3"]
metrics = ["max_error_rad"]
seed = 1
[motion]
motion = "coning"
half_angle_deg = 1.0
[sensor]
sample_rate_hz = 2000.0
duration = 20.0
[grid]
cone_rate_hz = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
"gyro.white_noise" = [0.0, 1e-6, 2e-6, 3e-6]
"""


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_to_a_pooled_sweeps_process_group_is_one_line(tmp_path, sig):
    """As a terminal's Ctrl-C or a service manager's stop: every process gets the signal.
    The workers exit quietly (no "Process ForkPoolWorker" traceback, no hang), the parent
    says how far it got; no temporary file is left."""
    scn = tmp_path / "s.toml"
    scn.write_text(_SCENARIO)
    proc = subprocess.Popen([sys.executable, "-m", "strapdown.cli", "sweep", str(scn), "--out",
                             str(tmp_path / "sw"), "--workers", "2", "--format", "csv"],
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                            start_new_session=True, preexec_fn=default_sigint)
    assert "64 cases" in proc.stderr.readline()
    done = tmp_path / "sw" / "cases"
    for _ in range(1200):  # until the pool has finished a case
        if done.is_dir() and any(p.suffix == ".json" for p in done.iterdir()):
            break
        time.sleep(0.05)
    os.killpg(proc.pid, sig)
    try:
        _, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        raise
    status = EXIT_TERMINATED if sig == signal.SIGTERM else 130
    assert proc.returncode == status, err
    assert re.fullmatch(r"strapdown sweep: interrupted( \(SIGTERM\))?, \d+/64 cases done; "
                        r"rerun the same command to resume\n", err), err
    assert not [p for p in (tmp_path / "sw").rglob(".*")]
