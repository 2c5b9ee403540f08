"""Command-line structure: one module per subcommand, choices from the registries, every option
documented, bench an ordinary subcommand, and no numerical library loaded for --version/--help.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

import pytest

from strapdown import cli
from strapdown.cli import build_parser, main

#: The subcommands README.md and docs/tutorial.md document (the contract scripts rely on).
DOCUMENTED = ("evaluate", "coefficients", "export-c", "run", "nav", "compare", "sweep", "ahrs",
              "benchmark-ahrs", "reproduce", "bench", "advise")
HEAVY = ("numpy", "scipy", "numba", "sympy", "matplotlib")


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(action.choices)


def _subparser(name: str) -> argparse.ArgumentParser:
    return _subcommands(build_parser())[name].populate()


def _option(name: str, flag: str) -> argparse.Action:
    (action,) = [a for a in _subparser(name)._actions if flag in a.option_strings]
    return action


def _loaded_after(args: list[str]) -> tuple[list[str], str]:
    """Heavy modules loaded by running the CLI on ``args`` in a fresh interpreter, and stdout."""
    code = ("import json, sys\nfrom strapdown.cli import main\ntry:\n    main(sys.argv[1:])\n"
            "except SystemExit:\n    pass\n"
            f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stderr.strip().splitlines()[-1]), out.stdout


def test_every_documented_subcommand_is_one_module():
    assert tuple(_subcommands(build_parser())) == DOCUMENTED
    assert len(cli.COMMANDS) == len(DOCUMENTED)
    for module in cli.COMMANDS:
        assert callable(module.add_parser) and callable(module.run)


@pytest.mark.parametrize("args", [["--version"], ["--help"]])
def test_version_and_help_load_no_numerical_library(args):
    loaded, out = _loaded_after(args)
    assert loaded == []
    assert out.startswith("strapdown ") if args == ["--version"] else "evaluate" in out


def test_evaluate_help_loads_neither_sympy_nor_matplotlib():
    loaded, out = _loaded_after(["evaluate", "--help"])
    assert "sympy" not in loaded and "matplotlib" not in loaded
    assert "--algorithm" in out


def test_python_dash_m_runs_the_command_line():
    out = subprocess.run([sys.executable, "-m", "strapdown.cli", "--version"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.startswith("strapdown ")


def test_algorithm_and_structure_choices_come_from_the_registry():
    from strapdown.algorithms import spec
    from strapdown.algorithms.coning import coefficient_set_names
    from strapdown.codegen import export_c

    assert tuple(_option("evaluate", "--algorithm").choices) == spec.ALGORITHMS
    for name in ("evaluate", "export-c", "run"):
        assert tuple(_option(name, "--structure").choices) == spec.STRUCTURES
    rate_sets = {c for n in spec.algorithms_taking("rate")
                 for c in spec.REGISTRY[n].coefficient_names()}
    assert set(_option("evaluate", "--coefficients").choices) == {*coefficient_set_names(),
                                                                  *rate_sets}
    assert tuple(_option("export-c", "--algorithm").choices) == export_c.ALGORITHMS
    run_choices = _option("run", "--algorithm").choices
    assert all(not spec.REGISTRY[n].stepped for n in run_choices)
    # what the README documents stays accepted
    assert {"rotvec", "rate-three", "rk4", "miller"} <= set(spec.ALGORITHMS)
    assert {"rotvec", "rate-single", "rate-three", "rk4"} <= set(run_choices)
    assert {"conventional", "realtime", "single-chain", "sliding"} <= set(spec.STRUCTURES)


def test_designer_and_reproduction_choices_come_from_their_lists():
    from strapdown.design import FORMS, RULES, TARGETS
    from strapdown.reproduce import REPRODUCTIONS

    assert tuple(_option("coefficients", "--form").choices) == FORMS
    assert tuple(_option("coefficients", "--target").choices) == TARGETS
    assert tuple(_option("coefficients", "--rule").choices) == RULES
    (paper,) = [a for a in _subparser("reproduce")._actions if a.dest == "paper"]
    assert tuple(paper.choices) == tuple(REPRODUCTIONS)
    assert {"li2017", "wang-rate", "wang-sliding", "plaksiy2024", "zhang2021"} <= set(paper.choices)


@pytest.mark.parametrize("name", DOCUMENTED)
def test_every_option_has_help(name):
    for action in _subparser(name)._actions:
        assert action.help, f"{name} {action.option_strings or action.dest} has no help"


def test_help_shows_defaults(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["evaluate", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "(default: 10000.0)" in out and "(default: conventional)" in out
    assert "(default: 0.15 0.25 0.05)" in out
    assert "(default: False)" not in out and "(default: None)" not in out


def test_reproduction_registry_resolves_every_name():
    from strapdown.reproduce import REPRODUCTIONS, reproduction

    for name in REPRODUCTIONS:
        assert callable(reproduction(name).reproduce)
    with pytest.raises(ValueError, match="unknown reproduction 'nope'; choose one of li2017"):
        reproduction("nope")


def test_unknown_reproduction_exits_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "nope", "--out", "x"])
    assert exc.value.code == 2
    assert "invalid choice: 'nope'" in capsys.readouterr().err


FAKE_RECORDS = [
    {"name": "numpy-single-pass", "samples_per_s": 2e9, "ratio_to_numpy_pass": 1.0, "peer": None},
    {"name": "scipy-loop", "samples_per_s": None, "ratio_to_numpy_pass": None, "peer": "scipy",
     "error": "TypeError: x"},
    {"name": "stream-conventional-N3", "peak_rss_mb": 150.4, "seconds": 12.2, "chunk": 65536,
     "peer": None},
]


@pytest.fixture
def fake_bench(monkeypatch):
    from strapdown.apps import bench

    calls = []

    def run_benchmarks(*args, nav_samples, log=None):
        calls.append((*args, nav_samples))
        if log is not None:
            log("[1/1] numpy-single-pass")
        return FAKE_RECORDS

    monkeypatch.setattr(bench, "run_benchmarks", run_benchmarks)
    return calls


def test_bench_is_an_ordinary_subcommand_with_every_option(fake_bench, capsys):
    assert main(["bench", "--samples", "100", "--peer-samples", "7", "--stream-samples", "0",
                 "--ekf-samples", "0", "--nav-samples", "0", "--repeat", "1", "--json"]) == 0
    assert fake_bench == [(100, 7, 1, 0, 0, 0)]  # samples, peer, repeat, stream, ekf, nav
    assert json.loads(capsys.readouterr().out) == FAKE_RECORDS


def test_bench_defaults_and_table(fake_bench, capsys):
    assert main(["bench"]) == 0
    assert fake_bench == [(10_000_000, 20_000, 3, 100_000_000, 1_000_000, 2_000_000)]
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["name", "samples/s", "×", "numpy", "pass", "peer"]
    assert lines[1].split() == ["numpy-single-pass", "2.000e+09", "1.0000"]
    assert lines[2].endswith("failed: TypeError: x")
    assert lines[3].endswith("peak RSS 150 MB in 12 s")


def test_bench_rejects_unknown_option(fake_bench, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--sample", "3"])
    assert exc.value.code == 2 and fake_bench == []
