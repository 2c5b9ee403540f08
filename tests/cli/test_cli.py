"""Command line: JSON contract, human output, clear errors, reproduction output."""

from __future__ import annotations

import json
import math

import pytest

from shared_runs import documented_out
from strapdown.cli import main

KEYS = {"drift_rate_rad_s", "cone_axis_drift_rad_s", "predicted_drift_rad_s", "max_error_rad",
        "rms_error_rad", "update_period_s", "samples"}


def run(capsys, *args):
    code = main(list(args))
    return code, capsys.readouterr()


def test_evaluate_json_contract(capsys):
    code, out = run(capsys, "evaluate", "--subsamples", "2", "--sample-rate-hz", "60",
                    "--duration", "10", "--json")
    assert code == 0
    d = json.loads(out.out)
    assert KEYS <= set(d)
    assert len(d["drift_rate_rad_s"]) == 3
    assert d["samples"] == 600
    assert d["update_period_s"] == pytest.approx(2 / 60)
    assert d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"] == pytest.approx(1, abs=0.01)


def test_evaluate_realtime_and_precision(capsys):
    code, out = run(capsys, "evaluate", "--subsamples", "3", "--sample-rate-hz", "60",
                    "--duration", "2", "--half-angle-deg", str(math.degrees(1e-6)),
                    "--structure", "realtime", "--precision", "40", "--json")
    d = json.loads(out.out)
    assert code == 0 and d["precision_digits"] == 40
    assert d["update_period_s"] == pytest.approx(1 / 60)
    assert d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"] == pytest.approx(1, abs=0.02)


def test_evaluate_spin_has_null_cone_keys(capsys):
    _, out = run(capsys, "evaluate", "--motion", "spin", "--spin-rate-dps", "3600",
                 "--duration", "0.5", "--json")
    d = json.loads(out.out)
    assert d["cone_axis_drift_rad_s"] is None and d["predicted_drift_rad_s"] is None


def test_evaluate_human_readable(capsys):
    code, out = run(capsys, "evaluate", "--duration", "1")
    assert code == 0
    assert "drift rate" in out.out and "predicted" in out.out and "measured/law" in out.out


@pytest.mark.parametrize(
    ("args", "msg"),
    [
        (["--subsamples", "0"], "subsamples N must be a positive integer"),
        (["--subsamples", "9"], "at most 6"),
        (["--sample-rate-hz", "-5"], "sample rate"),
        (["--duration", "0"], "duration"),
        (["--half-angle-deg", "nan"], "half angle must be finite"),
        (["--cone-rate-hz", "0"], "cone rate"),
        (["--duration", "0.0001", "--subsamples", "3"], "fewer than N = 3"),
        (["--coefficients", "miller", "--subsamples", "2"], "N = 3 only"),
        (["--precision", "10"], "at least 17"),
        (["--motion", "spin"], "spin-rate-dps"),
    ],
)
def test_evaluate_bad_input_exits_2_with_message(capsys, args, msg):
    with pytest.raises(SystemExit) as exc:
        main(["evaluate", *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert msg in err and "Traceback" not in err


def test_unknown_flag_is_rejected(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["evaluate", "--subsample", "3"])  # abbreviations are not accepted
    assert exc.value.code == 2


def test_reproduce_refuses_file_as_out(tmp_path, capsys):
    f = tmp_path / "x"
    f.write_text("keep me")
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "li2017", "--out", str(f)])
    assert exc.value.code == 2
    assert f.read_text() == "keep me"


@pytest.mark.slow
def test_reproduce_li2017_writes_report(tmp_path, capsys, monkeypatch):
    from strapdown.reproduce import li2017

    # the drift-versus-Ωh sweep on two of its five sample rates (the 1200 and 480 samples
    # per period runs were over half of the command's time): its table and figure are
    # written all the same, and nothing below reads their values
    monkeypatch.setattr(li2017, "SPP_GRID", (240, 60))
    code, _ = run(capsys, "reproduce", "li2017", "--out", str(tmp_path))
    assert code == 0
    report = (tmp_path / "report.md").read_text()
    for name in ("table1", "table2", "table3", "table4", "table5", "float64_vs_mp",
                 "drift_vs_omega_h", "single_chain"):
        assert (tmp_path / f"{name}.csv").is_file() and (tmp_path / f"{name}.md").is_file()
    for png in ("drift_vs_omega_h.png", "update_period.png", "realtime_sawtooth.png"):
        assert (tmp_path / png).stat().st_size > 10_000
        assert png in report
    assert "Table 2 does not reproduce" in report
    t1 = (tmp_path / "table1.csv").read_text().splitlines()
    assert sum("reproduced" in line for line in t1[1:]) == 5
    t4 = (tmp_path / "table4.csv").read_text()
    assert t4.count("differs") == 10  # the 3600 and 7200 °/s rows
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def test_coefficients_json_contract(capsys):
    code, out = run(capsys, "coefficients", "--form", "cross-with-last", "--subsamples", "4",
                    "--json")
    d = json.loads(out.out)
    assert code == 0
    assert d["coefficients"] == ["214/105", "92/105", "18/35"]
    assert d["terms"] == ["θ3×θ4", "θ2×θ4", "θ1×θ4"]
    assert d["drift_constant"] == "1/1260" and d["order"] == 8


def test_coefficients_polynomial_target_human(capsys):
    code, out = run(capsys, "coefficients", "--form", "all-pairs", "--subsamples", "3",
                    "--target", "polynomial")
    assert code == 0
    assert "57/80" in out.out and "33/80" in out.out and "+1/80 · a²Ω(Ωh)^4" in out.out


def test_coefficients_rate_three_reports_true_order(capsys):
    _, out = run(capsys, "coefficients", "--form", "rate-three", "--subsamples", "3",
                 "--ignore-quadrature", "--json")
    d = json.loads(out.out)
    assert d["order"] == 8 and d["true_order"] == 4 and d["true_drift_constant"] == "-1/80"


def test_coefficients_bad_input(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["coefficients", "--form", "lag", "--subsamples", "0"])
    assert exc.value.code == 2
    assert "positive integer" in capsys.readouterr().err


def test_evaluate_single_chain(capsys):
    _, out = run(capsys, "evaluate", "--structure", "single-chain", "--subsamples", "2",
                 "--sample-rate-hz", "240", "--duration", "20", "--json")
    d = json.loads(out.out)
    assert d["update_period_s"] == pytest.approx(1 / 240)
    assert d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"] == pytest.approx(1, abs=0.01)


@pytest.mark.slow
def test_reproduce_wang_rate_writes_report(tmp_path, capsys, monkeypatch):
    from strapdown.reproduce import wang_rate

    # the drift-order fits on two of their four sample rates (the 600 and 240 samples per
    # period were over 80 % of the orders' time): the same seven algorithms, rows and
    # verdicts; the fits on all four, at the same 80 digits, and their measured/law ratios are
    # tests/algorithms/test_rate.py::test_measured_order_matches_derived_order's
    monkeypatch.setattr(wang_rate, "SPP", (120, 60))
    code, _ = run(capsys, "reproduce", "wang-rate", "--out", str(tmp_path))
    assert code == 0
    report = (tmp_path / "report.md").read_text()
    orders = (tmp_path / "orders.csv").read_text().splitlines()
    assert len(orders) == 8 and all(line.endswith("agrees") for line in orders[1:])
    for png in ("drift_vs_omega_td.png", "sliding_sawtooth.png"):
        assert (tmp_path / png).stat().st_size > 10_000 and png in report
    assert (tmp_path / "rate_vs_increment.csv").is_file()


def test_evaluate_rate_algorithm_json(capsys):
    _, out = run(capsys, "evaluate", "--algorithm", "rate-three", "--structure", "sliding",
                 "--sample-rate-hz", "120", "--duration", "4", "--json")
    d = json.loads(out.out)
    assert d["coefficients"] == "derived"
    assert d["update_period_s"] == pytest.approx(1 / 120)
    assert len(d["chain_cone_axis_drift_rad_s"]) == 3


def test_reproduce_plaksiy_writes_report(tmp_path, capsys):
    # the README's `strapdown reproduce plaksiy2024 --out DIR` when this process ran it
    # (tests/docs/test_docs_commands.py, before this test: conftest.RUN_AFTER), else here
    out = documented_out("reproduce", "plaksiy2024")
    if out is None:
        code, _ = run(capsys, "reproduce", "plaksiy2024", "--out", str(tmp_path))
        assert code == 0
        out = tmp_path
    t1 = (out / "table1.csv").read_text().splitlines()
    assert sum(line.endswith("reproduced") for line in t1[1:]) == 3
    t3 = (out / "table3.csv").read_text().splitlines()
    assert sum(line.endswith("reproduced") for line in t3[1:]) == 3
    assert "drift_vs_time.png" in (out / "report.md").read_text()


def test_evaluate_krylov_cli(capsys):
    _, out = run(capsys, "evaluate", "--motion", "krylov", "--krylov-rates", "0.3", "0.5", "0.1",
                 "--algorithm", "power", "--step", "0.1", "--duration", "200", "--json")
    d = json.loads(out.out)
    assert d["accumulated_drift_rad"] == pytest.approx(0.78e-6, rel=0.005)


@pytest.mark.slow
def test_reproduce_zhang2021_writes_report(tmp_path, capsys, monkeypatch):
    from strapdown.reproduce import zhang2021

    # 3 s of the simulations instead of 30 (at the same 10 kHz): every table, figure and
    # report section is written all the same, and nothing below reads their values (the
    # 30 s accuracy of the methods: tests/algorithms/test_cone_angles.py)
    monkeypatch.setattr(zhang2021, "DURATION", 3.0)
    code, _ = run(capsys, "reproduce", "zhang2021", "--out", str(tmp_path))
    assert code == 0
    for name in ("flight_control", "navigation", "typos"):
        assert (tmp_path / f"{name}.csv").is_file()
    report = (tmp_path / "report.md").read_text()
    assert "flight_control_errors.png" in report and "navigation_errors.png" in report


def test_export_c_cli(tmp_path, capsys):
    code, out = run(capsys, "export-c", "--algorithm", "rotvec", "--structure", "realtime",
                    "--subsamples", "4", "--out", str(tmp_path))
    assert code == 0 and "operations per update" in out.out
    assert (tmp_path / "sd_rotvec_realtime_n4.c").is_file()
    assert (tmp_path / "sd_rotvec_realtime_n4.h").is_file()


def test_evaluate_says_what_measured_over_law_means(capsys):
    """The README's first command: the ratio −3.84 comes with its status and a remedy."""
    code, out = run(capsys, "evaluate", "--motion", "coning", "--half-angle-deg", "1",
                    "--cone-rate-hz", "1", "--sample-rate-hz", "600", "--duration", "20",
                    "--subsamples", "3", "--structure", "realtime")
    assert code == 0
    line = next(x for x in out.out.splitlines() if x.startswith("measured/law"))
    assert "-3.84" in line and "(higher order in a dominates; float64 floor" in line
    assert "--half-angle-deg" in out.out
    code, out = run(capsys, "evaluate", "--duration", "1")  # N = 3 at 10 kHz: round-off
    assert "(below float64 floor;" in out.out and "--precision 30" in out.out
    code, out = run(capsys, "evaluate", "--subsamples", "2", "--sample-rate-hz", "60",
                    "--duration", "10", "--json")
    d = json.loads(out.out)
    assert d["law_status"] == "resolved" and d["law_note"] is None
    assert d["measured_over_law"] == d["cone_axis_drift_rad_s"] / d["predicted_drift_rad_s"]
    _, out = run(capsys, "evaluate", "--motion", "spin", "--spin-rate-dps", "3600",
                 "--duration", "0.5")
    assert "measured/law" not in out.out  # no law, no ratio
