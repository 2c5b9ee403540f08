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


@pytest.mark.parametrize("command", ["run", "advise", "export-c", "sweep"])
def test_a_bad_option_of_a_subcommand_prints_that_subcommands_usage(capsys, command):
    with pytest.raises(SystemExit) as exc:
        main([command, "--bogus", "1"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"usage: strapdown {command} ")
    # the subcommand's own line: unknown options when nothing is missing, else what is missing
    assert f"strapdown {command}: error: " in err.splitlines()[-1]
    with pytest.raises(SystemExit):
        main(["evaluate", "--bogus", "1"])  # evaluate needs nothing: the unknown option named
    err = capsys.readouterr().err
    assert err.startswith("usage: strapdown evaluate ")
    assert err.splitlines()[-1] == "strapdown evaluate: error: unrecognized arguments: --bogus 1"


def test_every_long_command_takes_no_progress(tmp_path, capsys):
    from strapdown.cli import build_parser

    long = {"run": ["--imu", "x", "--out", "y"], "nav": ["--imu", "x", "--out", "y",
            "--init-lat", "0", "--init-lon", "0", "--init-height", "0"],
            "sweep": ["s.toml", "--out", "o"], "reproduce": ["li2017", "--out", "o"],
            "bench": [], "benchmark-ahrs": ["d", "--out", "o"],
            "ahrs": ["--imu", "x", "--out", "y"], "compare": ["--algorithms", "rk4", "--out", "o"],
            "advise": ["--imu", "x"]}
    for command, args in long.items():
        for flag, shown in (("--no-progress", False), ("--progress", True)):
            assert build_parser().parse_args([command, *args, flag]).progress is shown, command
    # compare: a line per algorithm with --progress, none with --no-progress or by default
    # (captured stderr is no terminal); the results on stdout either way
    cmp = ["compare", "--algorithms", "rotvec:N=2", "rk4", "--sample-rate-hz", "600",
           "--duration", "0.5", "--out", str(tmp_path / "c")]
    assert main([*cmp, "--progress"]) == 0
    shown = capsys.readouterr()
    assert "[1/2] rotvec:N=2" in shown.err and "[2/2] rk4" in shown.err
    for quiet in (["--no-progress"], []):
        assert main([*cmp, *quiet]) == 0
        got = capsys.readouterr()
        assert got.err == "" and got.out == shown.out


def _psd(path):
    f = np.arange(0.0, 60.5, 1.0)
    im = np.where(f == 20.0, -1e-3, 0.0)
    path.write_text("f_hz,im_gyz,im_gzx,im_gxy\n" + "\n".join(
        f"{a},{b},0,0" for a, b in zip(f, im, strict=True)) + "\n")
    return str(path)


def test_advise_json_writes_no_figure_unless_asked(tmp_path, monkeypatch, capsys):
    import json

    psd = _psd(tmp_path / "psd.csv")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    args = ["advise", "--psd", psd, "--sample-rate-hz", "400", "--budget-deg-h", "0.05"]
    assert main([*args, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["recommended"]
    assert list(work.iterdir()) == []  # before: advise.png in the current directory
    assert main([*args, "--json", "--figure", "fig.png"]) == 0  # asked for: written
    assert [p.name for p in work.iterdir()] == ["fig.png"]
    (work / "fig.png").unlink()
    assert main(args) == 0  # the table: its figure by default, and says where
    assert [p.name for p in work.iterdir()] == ["advise.png"]
    assert "figure: advise.png" in capsys.readouterr().err


SCENARIO = ('algorithms = ["rotvec:N=2", "rk4"]\n[sensor]\nsample_rate_hz = 600.0\n'
            'duration = 0.5\n[grid]\ncone_rate_hz = [1.0, 2.0]\n')


def test_sweep_defaults_run_on_the_core_install(tmp_path, monkeypatch, capsys):
    """Without pyarrow (not in the core install) the default writes the CSV table and says
    how to get Parquet; asking for Parquet is refused, nothing written."""
    monkeypatch.setitem(__import__("sys").modules, "pyarrow", None)  # import pyarrow fails
    scn = tmp_path / "scn.toml"
    scn.write_text(SCENARIO)
    out = tmp_path / "sweep"
    assert main(["sweep", str(scn), "--out", f"{out}/", "--workers", "1"]) == 0
    got = capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["cases", "results.csv"]
    assert "results.parquet" not in got.out and "strapdown[parquet]" in got.err
    code, err = _exit(capsys, "sweep", str(scn), "--out", str(tmp_path / "pq"),
                      "--format", "csv,parquet", "--workers", "1")
    assert code == 2 and "needs pyarrow" in err and not (tmp_path / "pq").exists()


def _exit(capsys, *args) -> tuple[int, str]:
    with pytest.raises(SystemExit) as exc:
        main(list(args))
    return exc.value.code, capsys.readouterr().err


def test_a_failed_dask_sweep_leaves_nothing_behind(tmp_path, monkeypatch, capsys):
    """Status 2 promises nothing written: no empty cases/ (nor OUT) after a Dask sweep that
    could not start — dask not installed, or no scheduler at the address."""
    import sys

    scn = tmp_path / "scn.toml"
    scn.write_text(SCENARIO)
    dask = ["--scheduler", "dask://127.0.0.1:9", "--format", "csv"]
    monkeypatch.setitem(sys.modules, "distributed", None)  # the core install: no dask
    code, err = _exit(capsys, "sweep", str(scn), "--out", str(tmp_path / "a"), *dask)
    assert code == 2 and "strapdown[dask]" in err and not (tmp_path / "a").exists()
    monkeypatch.delitem(sys.modules, "distributed")
    distributed = pytest.importorskip("distributed")

    def unreachable(address, timeout=None):
        raise OSError(f"Timed out trying to connect to {address}")

    monkeypatch.setattr(distributed, "Client", unreachable)
    (tmp_path / "b").mkdir()  # an existing, empty OUT stays as it was
    code, err = _exit(capsys, "sweep", str(scn), "--out", str(tmp_path / "b"), *dask)
    assert code == 2 and "cannot reach the Dask scheduler" in err
    assert list((tmp_path / "b").iterdir()) == []


def test_broad_path_messages_name_strapdown_broad(tmp_path, monkeypatch, capsys):
    """The README's BROAD commands with $STRAPDOWN_BROAD unset ("" and "/01_….mat"), a
    wrong folder and an empty one: each refusal says which variable names the trials."""
    monkeypatch.delenv("STRAPDOWN_BROAD", raising=False)
    empty = tmp_path / "empty"
    empty.mkdir()
    for args in (["benchmark-ahrs", "", "--out", str(tmp_path / "r")],
                 ["benchmark-ahrs", str(tmp_path / "nowhere"), "--out", str(tmp_path / "r")],
                 ["benchmark-ahrs", str(empty), "--out", str(tmp_path / "r")],
                 ["ahrs", "--imu", "/01_undisturbed_slow_rotation_A.mat",
                  "--out", str(tmp_path / "b.csv")]):
        code, err = _exit(capsys, *args)
        assert code == 2, err
        assert "export STRAPDOWN_BROAD=" in err and "not set here" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty"]  # nothing written
    monkeypatch.setenv("STRAPDOWN_BROAD", str(empty))
    code, err = _exit(capsys, "benchmark-ahrs", str(empty), "--out", str(tmp_path / "r"))
    assert "no BROAD trials (*.mat); " in err and repr(str(empty)) in err


API_DRIVER = """
import math
from strapdown import AlgorithmSpec, ClassicalConing
from strapdown.truth import sensors

m = ClassicalConing(half_angle=math.radians(1.0), cone_rate=2 * math.pi)
rec = sensors.increments(m, m.period / 60, 120)
AlgorithmSpec.parse("rotvec:N=2").run(rec)
AlgorithmSpec.parse("rotvec:N=2:structure=realtime").run(rec)
"""


def test_compile_notice_is_said_where_a_compile_happens_python_too(tmp_path):
    """The command line's line no longer promises "once" (each command compiles the kernels
    it needs on their first use); a Python call on a cold cache logs a notice naming what
    compiles and strapdown.warmup(), a warm one says nothing."""
    import os
    import sys

    import strapdown
    from strapdown._core.compile_notice import API_MESSAGE, MESSAGE

    assert "once" not in MESSAGE and "first use" in MESSAGE
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    runs = [subprocess.run([sys.executable, "-c", API_DRIVER], env=env, capture_output=True,
                           text=True, timeout=600) for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    line = API_MESSAGE.format(what="the attitude algorithms")
    assert runs[0].stderr == line + "\n"  # two kernels compiled, one line
    assert "strapdown.warmup()" in line
    assert runs[1].stderr == ""  # loaded from numba's cache: silent
    took = strapdown.warmup(["navigation"])
    assert set(took) == {"navigation"} and took["navigation"] >= 0
    with pytest.raises(ValueError, match="unknown warm-up part"):
        strapdown.warmup(["everything"])
