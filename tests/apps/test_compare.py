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
    base = EvaluationConfig(half_angle_deg=1.0, cone_rate_hz=2.0, sample_rate_hz=1200.0,
                            duration=2.0)
    runs = compare_motion(base, ["rotvec:N=2", "rk4"], tmp_path / "cmp")
    for r, alg in zip(runs, [{"subsamples": 2}, {"algorithm": "rk4"}], strict=True):
        import dataclasses

        ev = evaluate(dataclasses.replace(base, **alg))
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
    # without truth the first spec is the reference: its own difference is round-off
    runs = compare_log(tmp_path / "log.csv", ["rk4", "rate-three"], tmp_path / "cmp2",
                       kind="rate", units="rad/s")
    assert runs[0].summary["max_error_rad"] < 2e-15  # slerp at its own knots: round-off
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
