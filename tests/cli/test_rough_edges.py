"""The rough edges a newcomer met (issue 28, items 4, 5 and 6), one test each: what the
command line says on a bad option, which commands take --no-progress, the compile notice,
the paths and help texts printed, the example scenario, the Python API's errors and record
types, the BROAD messages, the sweep's default formats on the core install and what a failed
sweep or ``advise --json`` leaves behind."""

from __future__ import annotations

import math
import re
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest

from strapdown.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_help_lists_end_without_empty_entries(capsys):
    # rate-two has one coefficient set: "derived (default)", not "derived (default), ,"
    for command in ("run", "evaluate", "export-c"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        sets = text[text.index("coefficient set;"):]
        sets = sets[:sets.index(" --")]
        assert "rate-two: derived (default)" in sets
        assert not re.search(r",\s*([,;]|$)", sets), (command, sets)


def test_export_c_prints_the_paths_it_wrote(tmp_path, capsys):
    out = f"{tmp_path}/flight/"  # typed with a trailing slash, as in the README
    assert main(["export-c", "--algorithm", "rotvec", "--structure", "single-chain",
                 "--subsamples", "3", "--out", out]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert "//" not in line
    h, c = re.fullmatch(r"wrote (\S+) and (\S+)", line).groups()
    assert Path(h).is_file() and Path(c).is_file()


def test_example_scenario_comment_counts_its_algorithms():
    path = ROOT / "examples" / "coning_sweep.toml"
    words = {2: "Two", 3: "Three", 4: "Four", 5: "Five", 6: "Six", 7: "Seven"}
    n = len(tomllib.loads(path.read_text())["algorithms"])
    assert f"# {words[n]} algorithms" in path.read_text()


def test_the_readme_working_directory_is_git_ignored():
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    res = subprocess.run(["git", "check-ignore", "-q", "work/attitude.csv"], cwd=ROOT,
                         capture_output=True)
    assert res.returncode == 0  # README: "mkdir -p work && cd work", everything written there


def test_ekf_error_names_python_remedies_not_command_line_flags():
    from strapdown.ahrs import ekf
    from strapdown.io.timing import fit_clock

    n = 400
    t = 5.0 + np.arange(n) * 0.01 + np.random.default_rng(0).uniform(-2e-3, 2e-3, n)
    gyro, acc = np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1))
    with pytest.raises(ValueError, match="non-uniform sampling") as exc:
        ekf(t, gyro, acc)
    msg = str(exc.value)
    assert not re.search(r"(^|\s|\()--[a-z]", msg)  # no command-line flag
    assert "resample=True" not in msg  # ekf has no such argument
    assert "fit_clock(t - t[0]).uniform_times() + t[0]" in msg
    # and the remedy it names works
    uniform = fit_clock(t - t[0]).uniform_times() + t[0]
    assert ekf(uniform, gyro, acc).q.shape == (n, 4)


def test_structures_take_a_gyro_record_as_spec_run_does():
    from strapdown import AlgorithmSpec, ClassicalConing
    from strapdown.algorithms.coning import coefficient_set
    from strapdown.algorithms.structures import conventional, realtime, single_chain
    from strapdown.truth import sensors

    motion = ClassicalConing(half_angle=math.radians(1.0), cone_rate=2 * math.pi)
    h = motion.period / 60
    rec = sensors.increments(motion, h, 600)
    rec.t[:] += 2.0  # a record that does not start at 0: its own start is used
    table3 = coefficient_set("table3", 2)
    by_spec = AlgorithmSpec.parse("rotvec:N=2").run(rec)
    sol = conventional(rec, table3)
    assert np.array_equal(sol.q, by_spec.q) and np.array_equal(sol.t, by_spec.t)
    arrays = conventional(rec.data, table3, h=h, t0=2.0)
    assert np.array_equal(sol.q, arrays.q) and np.array_equal(sol.t, arrays.t)
    assert np.array_equal(realtime(rec, table3).q, realtime(rec.data, table3, h=h).q)
    assert np.array_equal(single_chain(rec, 2).t, single_chain(rec.data, 2, h=h, t0=2.0).t)
    with pytest.raises(ValueError, match="contradicts the record"):
        conventional(rec, table3, h=2 * h)
    with pytest.raises(ValueError, match="needs h"):
        conventional(rec.data, table3)
    rates = sensors.rate_samples(motion, h, 60)
    with pytest.raises(ValueError, match="takes angular increments; this record holds rates"):
        conventional(rates, table3)
