"""`strapdown sweep`: scenario parsing, resumability after a kill, local pool == Dask."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from cli_helpers import default_sigint
from strapdown._core.compile_notice import MESSAGE
from strapdown.apps.sweep import cases, load_scenario, sweep

SCENARIO = textwrap.dedent("""
    algorithms = ["rotvec:N=2", "rotvec:N=3:structure=realtime", "rate-three", "rk4"]
    metrics = ["max_error_rad", "cone_axis_drift_rad_s", "predicted_drift_rad_s",
               "drift_rate_rad_s"]
    seed = 11

    [motion]
    motion = "coning"
    half_angle_deg = 1.0

    [sensor]
    sample_rate_hz = 600.0
    duration = {duration}

    [grid]
    cone_rate_hz = [1.0, 2.0, 5.0]
    "gyro.white_noise" = [0.0, 1e-5]
""")


def _scenario(tmp_path, duration=2.0) -> Path:
    p = tmp_path / "scn.toml"
    p.write_text(SCENARIO.format(duration=duration))
    return p


def test_scenario_cases_and_errors(tmp_path):
    scn = load_scenario(_scenario(tmp_path))
    cs = cases(scn)
    assert len(cs) == 3 * 2 * 4
    assert [c.algorithm for c in cs[:4]] == list(scn.algorithms)
    # common random numbers: one seed per grid point, shared by its algorithms
    assert len({c.config.seed for c in cs[4:8]}) == 1 and cs[4].config.seed is not None
    assert cs[0].config.seed is None  # ideal gyro: no noise, no seed
    assert len({c.key for c in cs}) == len(cs)
    bad = tmp_path / "bad.toml"
    bad.write_text('algorithms = ["rk4"]\n[motion]\nhalf_angel_deg = 1.0\n')
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['half_angel_deg'\]"):
        load_scenario(bad)
    bad.write_text('algorithms = ["rk4"]\nmetrics = ["max_eror_rad"]\n')
    with pytest.raises(ValueError, match="unknown metric"):
        load_scenario(bad)
    bad.write_text('algorithms = ["rk4"]\n[gyro]\nwhite_noise = 1e-5\n')
    with pytest.raises(ValueError, match="give a top-level seed"):
        load_scenario(bad)
    bad.write_text('algorithms = ["rotvec:N=9"]\n')
    with pytest.raises(ValueError, match=r"case 0 .*subsamples N must be at most"):
        load_scenario(bad)


def test_interrupted_sweep_resumes_without_recomputing(tmp_path):
    scn = _scenario(tmp_path)
    full = sweep(scn, tmp_path / "full", workers=1)
    assert full.complete and full.computed == 24
    part = sweep(scn, tmp_path / "part", workers=1, max_cases=5)
    assert not part.complete and part.computed == 5
    assert not (tmp_path / "part" / "results.csv").exists()
    rest = sweep(scn, tmp_path / "part", workers=2)
    assert (rest.skipped, rest.computed) == (5, 19)
    assert (tmp_path / "part" / "results.csv").read_bytes() == full.csv.read_bytes()
    import pyarrow.parquet as pq

    assert pq.read_table(rest.parquet).equals(pq.read_table(full.parquet))
    again = sweep(scn, tmp_path / "part", workers=2)
    assert (again.skipped, again.computed) == (24, 0)


def test_killed_sweep_process_resumes(tmp_path):
    """SIGKILL a real `strapdown sweep` mid-way; the rerun finishes the grid."""
    scn = _scenario(tmp_path, duration=20.0)  # slow enough to be killed mid-way
    ref = sweep(scn, tmp_path / "ref", workers=2)
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "strapdown.cli", "sweep", str(scn), "--out", str(out),
           "--workers", "1", "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            # finished cases only: pathlib's glob also matches the hidden temporary files
            if sum(not f.name.startswith(".") for f in (out / "cases").glob("*.json")) >= 3:
                break
            time.sleep(0.01)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    done = sum(not f.name.startswith(".") for f in (out / "cases").glob("*.json"))
    assert 3 <= done < 24, "the sweep finished before it could be killed"
    # SIGKILL can leave a hidden temp file, never a half-written case under its final name
    finished = [f for f in (out / "cases").glob("*.json") if not f.name.startswith(".")]
    assert all(json.loads(f.read_text())["metrics"] for f in finished)
    res = sweep(scn, out, workers=2)
    assert not list((out / "cases").glob(".*"))  # the rerun removed the killed run's temp files
    assert (res.skipped, res.computed) == (done, 24 - done)
    assert res.csv.read_bytes() == ref.csv.read_bytes()


def test_local_pool_and_dask_localcluster_give_identical_tables(tmp_path):
    distributed = pytest.importorskip("distributed")
    scn = _scenario(tmp_path)
    local = sweep(scn, tmp_path / "local")  # default: process pool
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=":0") as cluster:
        address = cluster.scheduler_address.removeprefix("tcp://")
        assert address.startswith("127.0.0.1:")
        remote = sweep(scn, tmp_path / "dask", scheduler=f"dask://{address}")
    assert remote.computed == 24
    assert remote.csv.read_bytes() == local.csv.read_bytes()
    import pyarrow.parquet as pq

    assert pq.read_table(remote.parquet).equals(pq.read_table(local.parquet))


def test_cli_sweep_and_bad_scheduler(tmp_path, capsys):
    from strapdown.cli import main

    scn = _scenario(tmp_path)
    assert main(["sweep", str(scn), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--max-cases", "2"]) == 3
    assert "2 of 24 cases done; rerun to finish" in capsys.readouterr().out
    assert main(["sweep", str(scn), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--format", "csv"]) == 0
    assert "24 cases, 2 reused" in capsys.readouterr().out
    assert not (tmp_path / "o" / "results.parquet").exists()
    with pytest.raises(SystemExit) as exc:
        main(["sweep", str(scn), "--out", str(tmp_path / "o"), "--scheduler", "dask:/x"])
    assert exc.value.code == 2
    assert "local' or 'dask://HOST:PORT'" in capsys.readouterr().err


@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_stops_sweep_with_one_line_and_status_130(tmp_path, workers):
    """SIGINT to the process group (what Ctrl-C sends): one line, no traceback, exit 130,
    the pool's workers gone, and the line's count is the number of saved cases."""
    scn = _scenario(tmp_path, duration=20.0)
    out = tmp_path / "interrupted"
    cmd = [sys.executable, "-m", "strapdown.cli", "sweep", str(scn), "--out", str(out),
           "--workers", workers, "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_sigint)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if len(list((out / "cases").glob("[!.]*.json"))) >= 2:
            break
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr and stdout == ""
    lines = [ln for ln in stderr.strip().splitlines() if ln != MESSAGE]  # cold cache: + notice
    assert lines[0] == "24 cases: 0 already done, 24 to run (local pool)"
    done = len(list((out / "cases").glob("[!.]*.json")))
    assert lines[-1] == (f"strapdown sweep: interrupted, {done}/24 cases done; "
                         "rerun the same command to resume")
    assert 2 <= done < 24
    time.sleep(0.5)
    with pytest.raises(ProcessLookupError):  # no worker left running in the group
        os.killpg(proc.pid, 0)


def _deaf_to_sigterm() -> None:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)


def test_a_pool_worker_that_ignores_sigterm_is_killed_not_waited_for():
    """sweep._terminate: pool.terminate() alone waits for ever on a worker SIGTERM does not
    end (seen under test: a worker blocked on its queue's lock, the signal never handled)."""
    import multiprocessing
    import threading

    from strapdown.apps.sweep import _terminate

    ctx = multiprocessing.get_context("fork")
    pool = ctx.Pool(1, initializer=_deaf_to_sigterm)
    pool.apply_async(time.sleep, (0.05,)).get(timeout=30)  # the worker is up
    pool.apply_async(time.sleep, (600,))  # and busy: it will not read the pool's sentinel
    time.sleep(0.2)
    th = threading.Thread(target=_terminate, args=(pool, ctx), daemon=True)
    th.start()
    th.join(timeout=60)
    assert not th.is_alive(), "the pool's terminate() still waits for its worker"
    assert ctx.active_children() == []


def test_cli_sweep_status_lines_printed_once(tmp_path, capsys):
    from strapdown.cli import main

    scn = _scenario(tmp_path, duration=1.0)
    assert main(["sweep", str(scn), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--max-cases", "3", "--format", "csv"]) == 3
    got = capsys.readouterr()
    assert got.out == "3 of 24 cases done; rerun to finish\n"
    quiet = got.err.replace(MESSAGE + "\n", "")  # a cold cache adds the compile notice
    assert quiet == "24 cases: 0 already done, 3 to run (local pool)\n"
    assert main(["sweep", str(scn), "--out", str(tmp_path / "o"), "--workers", "2",
                 "--format", "csv"]) == 0
    got = capsys.readouterr()
    assert got.out == f"wrote {tmp_path / 'o' / 'results.csv'} (24 cases, 3 reused)\n"
    quiet = got.err.replace(MESSAGE + "\n", "")
    assert quiet == "24 cases: 3 already done, 21 to run (local pool)\n"
