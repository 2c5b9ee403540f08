"""`strapdown compare`: specs, motion comparisons against truth, log comparisons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.spec import parse_spec
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.apps.compare import compare_log, compare_motion
from strapdown.cli import main
from strapdown.truth.motions import SpinConing


def test_parse_spec():
    assert parse_spec("rotvec:N=3:structure=realtime") == {
        "algorithm": "rotvec", "subsamples": 3, "structure": "realtime"}
    assert parse_spec("miller:step=0.01:exact_exp=true")["exact_exp"] is True
    with pytest.raises(ValueError, match="unknown algorithm 'rotvek'"):
        parse_spec("rotvek:N=3")
    with pytest.raises(ValueError, match="'subsample=3' is not key=value with a key among"):
        parse_spec("rotvec:subsample=3")
    with pytest.raises(ValueError, match="bad value 'three' for subsamples"):
        parse_spec("rotvec:N=three")


def test_compare_motion_matches_evaluate(tmp_path):
    base = EvaluationConfig.of(half_angle_deg=1.0, cone_rate_hz=2.0, sample_rate_hz=1200.0,
                               duration=2.0)
    runs = compare_motion(base, ["rotvec:N=2", "rk4"], tmp_path / "cmp")
    for r, alg in zip(runs, [{"subsamples": 2}, {"algorithm": "rk4"}], strict=True):
        import dataclasses

        ev = evaluate(dataclasses.replace(base, spec=dataclasses.replace(base.spec, **alg)))
        assert r.summary["max_error_rad"] == float(ev.angle.max())
    assert runs[0].summary["measured_over_law"] == pytest.approx(1.0, abs=2e-3)
    files = sorted(p.name for p in (tmp_path / "cmp").iterdir())
    assert files == ["error_vs_time.png", "summary.csv", "summary.md"]
    assert "rotvec:N=2" in (tmp_path / "cmp" / "summary.md").read_text()


def test_compare_log_against_truth(tmp_path, capsys):
    m = SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(720.0))
    h = 1e-3
    t = np.arange(2001) * h
    w = m.rate(t)
    with open(tmp_path / "log.csv", "w") as f:
        f.write("t,gx,gy,gz\n")
        for ti, wi in zip(t, w, strict=True):
            f.write(",".join(repr(float(v)) for v in (ti, *wi)) + "\n")
    q = m.attitude(t)  # truth at the log's own times: every output time is a truth sample
    np.savez(tmp_path / "truth.npz", t=t, qw=q[:, 0], qx=q[:, 1], qy=q[:, 2], qz=q[:, 3])
    specs = ["rate-three", "rk4", "rate-single"]
    runs = compare_log(tmp_path / "log.csv", specs, tmp_path / "cmp", kind="rate",
                       units="rad/s", truth=tmp_path / "truth.npz")
    from strapdown.algorithms.rate import rate_attitude
    from strapdown.analysis import attitude_errors

    for r, alg in zip(runs, specs, strict=True):
        sol = rate_attitude(t, w, algorithm=alg, q0=m.attitude(0.0))
        _, ang = attitude_errors(sol.t, sol.q, m)
        assert np.array_equal(r.t, sol.t)
        assert np.allclose(r.angle, ang, rtol=0, atol=5e-15)
        assert r.summary["max_error_rad"] > 1e-12  # far above the comparison's round-off
    # without truth the finest output grid (rk4: 2 h, rate-three: 3 h) is the reference
    runs = compare_log(tmp_path / "log.csv", ["rate-three", "rk4"], tmp_path / "cmp2",
                       kind="rate", units="rad/s")
    assert runs[1].summary["reference"] == "itself (the reference)"
    assert runs[1].summary["max_error_rad"] == 0.0
    assert runs[0].summary["reference"] == "rk4 at 334 of 667 outputs"  # common every 6 ms
    with pytest.raises(ValueError, match="rotvec takes increments; this log holds rates"):
        compare_log(tmp_path / "log.csv", ["rotvec:N=2"], tmp_path / "cmp3", kind="rate",
                    units="rad/s")


def test_cli_compare_motion(tmp_path, capsys):
    assert main(["compare", "--algorithms", "rotvec:N=1", "rotvec:N=3:structure=realtime",
                 "--sample-rate-hz", "600", "--duration", "2", "--out",
                 str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert "rotvec:N=3:structure=realtime" in out
    with pytest.raises(SystemExit) as exc:
        main(["compare", "--algorithms", "rk4", "--truth", "x.csv", "--out", str(tmp_path)])
    assert exc.value.code == 2


# -- compare on a log without truth: no interpolation, a reference that does not depend on
# -- the order of the specs ----------------------------------------------------------------


@pytest.fixture(scope="module")
def tutorial_log(tmp_path_factory):
    """gyro.csv and truth.csv exactly as the tutorial makes them."""
    import subprocess
    import sys
    from pathlib import Path

    d = tmp_path_factory.mktemp("tutorial")
    script = Path(__file__).resolve().parents[2] / "examples" / "make_example_log.py"
    subprocess.run([sys.executable, str(script)], cwd=d, check=True, capture_output=True)
    return d


def _max(runs, label):
    return next(r for r in runs if r.label == label).summary["max_error_rad"]


def test_no_truth_difference_matches_truth(tutorial_log, tmp_path):
    """Acceptance (issue 15): rk4 vs rate-single without truth within 20 % of against it."""
    log = tutorial_log / "gyro.csv"
    kw = dict(kind="rate", units=None, columns=None)
    specs = ["rate-three", "rate-three:structure=sliding", "rk4", "rate-single"]
    truth = compare_log(log, specs, tmp_path / "t", truth=tutorial_log / "truth.csv", **kw)
    against_truth = _max(truth, "rate-single") - _max(truth, "rk4")  # 6.80e-7 rad
    assert _max(truth, "rate-single") > 50 * _max(truth, "rk4")  # they differ 75×
    pair = compare_log(log, ["rk4", "rate-single"], tmp_path / "p", **kw)
    ref = next(r for r in pair if r.summary["reference"] != "itself (the reference)")
    assert ref.summary["max_error_rad"] == pytest.approx(against_truth, rel=0.2)
    # the order of the specs changes nothing
    swapped = compare_log(log, ["rate-single", "rk4"], tmp_path / "s", **kw)
    assert {r.label: r.summary["max_error_rad"] for r in swapped} == {
        r.label: r.summary["max_error_rad"] for r in pair}
    four = compare_log(log, specs, tmp_path / "f", **kw)
    back = compare_log(log, specs[::-1], tmp_path / "b", **kw)
    assert {r.label: r.summary["max_error_rad"] for r in four} == {
        r.label: r.summary["max_error_rad"] for r in back}
    # sliding: finest grid (with rate-single) and closest to the others
    assert next(r for r in four if r.label == specs[1]).summary["reference"] == (
        "itself (the reference)")
    # the pairwise table holds rk4 vs rate-single whatever the reference
    import csv

    with open(tmp_path / "f" / "differences.csv", newline="") as f:
        rows = {r[0]: r[1:] for r in list(csv.reader(f))[1:]}
    assert float(rows["rk4"][3]) == pytest.approx(against_truth, rel=0.2)
    assert float(rows["rk4"][3]) == float(rows["rate-single"][2])


def test_no_truth_compares_at_common_times_without_interpolation(tutorial_log, tmp_path):
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.io import read_imu
    from strapdown.rotation.error import attitude_error_angle

    log_path = tutorial_log / "gyro.csv"
    runs = compare_log(log_path, ["rate-three", "rk4"], tmp_path / "c", kind="rate",
                       units=None, columns=None)
    log = read_imu(log_path, kind="rate", units=None, columns=None)
    s3 = AlgorithmSpec.parse("rate-three").run(log)
    rk = AlgorithmSpec.parse("rk4").run(log)
    # rate-three every 3 ms, rk4 every 2 ms: common every 6 ms, compared there only
    common = np.intersect1d(np.round(s3.t * 1e3).astype(int), np.round(rk.t * 1e3).astype(int))
    r3 = runs[0]
    assert r3.t.size == common.size == 667
    assert np.array_equal(np.round(r3.t * 1e3).astype(int), common)
    i3 = np.searchsorted(np.round(s3.t * 1e3), common)
    ik = np.searchsorted(np.round(rk.t * 1e3), common)
    assert np.array_equal(r3.angle, attitude_error_angle(s3.q[i3], rk.q[ik]))


def _spin_coning():
    return SpinConing(math.radians(2.0), 2 * math.pi * 3, math.radians(720.0))


def test_truth_start_round_off_and_npy_truth(tmp_path):
    """A truth from t = 0 against a log whose start t[0] − h computes to −4.3e-19 s."""
    from strapdown.truth import sensors

    m, h, n = _spin_coning(), 5e-4, 1000
    rec = sensors.increments(m, h, n)
    t_end = np.arange(1, n + 1) * h  # interval ends as a logger writes them
    assert t_end[0] - np.median(np.diff(t_end)) == pytest.approx(-4.3e-19, rel=0.01)
    np.save(tmp_path / "inc.npy", np.column_stack([t_end, rec.data]))
    t = np.arange(n + 1) * h
    q = m.attitude(t)
    np.save(tmp_path / "truth.npy", np.column_stack([t, q]))
    with open(tmp_path / "truth.csv", "w") as f:
        f.write("t,qw,qx,qy,qz\n")
        for row in np.column_stack([t, q]):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    runs = {}
    for name in ("truth.npy", "truth.csv"):
        runs[name] = compare_log(tmp_path / "inc.npy", ["rotvec:N=2"], tmp_path / f"o-{name}",
                                 kind="increment", units="rad", truth=tmp_path / name)
    a, b = runs["truth.npy"][0], runs["truth.csv"][0]
    assert np.array_equal(a.angle, b.angle) and a.summary["max_error_rad"] < 1e-9
    assert a.summary["reference"] == "truth.npy (at its samples)"


@pytest.mark.parametrize(("name", "write", "msg"), [
    ("bad.npy", lambda p: np.save(p, np.zeros((5, 4))), r"shape \(n, 5\)"),
    ("bad.csv", lambda p: p.write_bytes(b"\x93NUMPY\x00\xff binary"),
     "not UTF-8 text .* expected a CSV"),
    ("bad.mat", lambda p: p.write_text("x"), "unknown truth format '.mat'"),
    ("back.csv", lambda p: p.write_text("t,qw,qx,qy,qz\n0,1,0,0,0\n0,1,0,0,0\n"),
     "times must increase strictly; row 2"),
    ("norm.csv", lambda p: p.write_text("t,qw,qx,qy,qz\n0,1,0,0,0\n1,2,0,0,0\n"),
     "row 2 is not a unit quaternion"),
    ("cols.csv", lambda p: p.write_text("t,w,x,y,z\n0,1,0,0,0\n1,1,0,0,0\n"),
     r"columns \['qw', 'qx', 'qy', 'qz'\] not in the header"),
    ("late.csv", lambda p: p.write_text("t,qw,qx,qy,qz\n0.0005,1,0,0,0\n1,1,0,0,0\n"),
     "not the log's start"),
])
def test_bad_truth_files(tmp_path, name, write, msg):
    m, h = _spin_coning(), 1e-3
    t = np.arange(11) * h
    np.save(tmp_path / "log.npy", np.column_stack([t, m.rate(t)]))
    write(tmp_path / name)
    with pytest.raises(ValueError, match=msg):
        compare_log(tmp_path / "log.npy", ["rk4"], tmp_path / "o", kind="rate", units="rad/s",
                    truth=tmp_path / name)


def test_figure_labels_and_all_four_curves(tutorial_log, tmp_path, monkeypatch):
    """The tutorial's figure draws all four algorithms; without truth it says 'difference
    from <reference>', never 'attitude error'."""
    from strapdown.io.report import ReportWriter

    seen = {}
    original = ReportWriter.figure

    def capture(self, name, fig):
        ax = fig.axes[0]
        seen["ylabel"] = ax.get_ylabel()
        seen["title"] = ax.get_title()
        seen["legend"] = [x.get_text() for x in ax.get_legend().get_texts()]
        seen["ylim"] = ax.get_ylim()
        return original(self, name, fig)

    monkeypatch.setattr(ReportWriter, "figure", capture)
    specs = ["rate-three", "rate-three:structure=sliding", "rk4", "rate-single"]
    kw = dict(kind="rate", units=None, columns=None)
    compare_log(tutorial_log / "gyro.csv", specs, tmp_path / "t",
                truth=tutorial_log / "truth.csv", **kw)
    assert seen["ylabel"] == "attitude error against truth.csv (rad)"
    assert len(seen["legend"]) == 4 and not any("not drawn" in x for x in seen["legend"])
    assert seen["legend"][1].startswith(specs[1] + ": range over 3 outputs")
    assert seen["ylim"][0] > 1e-11  # start-up points do not stretch the axis
    compare_log(tutorial_log / "gyro.csv", specs, tmp_path / "n", **kw)
    assert seen["ylabel"] == f"difference from {specs[1]} (rad)"
    assert "attitude error" not in seen["ylabel"] + seen["title"]
    assert f"difference from {specs[1]}" in seen["title"]
    assert seen["legend"][0].startswith("rate-three (equal to the reference to round-off")
    assert seen["legend"][1] == f"{specs[1]} (the reference, not drawn)"
