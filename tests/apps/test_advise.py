"""strapdown advise: ranking by the spectral drift prediction and cost, the no-coning case,
malformed input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.analysis.spectrum import coning_kernel
from strapdown.apps import advise as A
from strapdown.cli import main
from strapdown.truth import sensors
from strapdown.truth.vibration import random_tone_vibration

FS = 400.0


def _log(path, coning: bool, n=4000):
    amp = (1e-3, 4e-3, 4e-3) if coning else (0.0, 4e-3, 0.0)
    vib = random_tone_vibration((5.0, 40.0), 8, amp, (0.0, 1.2, 0.0), np.random.default_rng(3))
    inc = sensors.increments(vib.motion(), 1 / FS, n).data
    t = np.arange(1, n + 1) / FS
    rows = "\n".join(f"{a:.9f},{r[0]:.17g},{r[1]:.17g},{r[2]:.17g}" for a, r in zip(t, inc,
                                                                                     strict=True))
    path.write_text("t,gx[rad],gy[rad],gz[rad]\n" + rows + "\n")
    return path


def _line_psd(f0=20.0, power=1e-3, df=1.0, fmax=60.0):
    f = np.arange(0.0, fmax + df / 2, df)
    im = np.zeros_like(f)
    im[np.argmin(abs(f - f0))] = -power / df  # C = −Im G: counter-clockwise about x
    return f, im


def test_prediction_of_a_line_is_the_kernel_and_the_budget_rule(tmp_path):
    f, im = _line_psd()
    p = tmp_path / "psd.csv"
    p.write_text("f_hz,im_gyz,im_gzx,im_gxy\n" + "\n".join(
        f"{a},{b},0,0" for a, b in zip(f, im, strict=True)))
    fr, g = A.read_psd(p)
    h = 1 / FS
    specs = A.candidate_specs("increment")
    adv = A.advise(fr, g, h, specs, lambda s, h: 1.0 / s.update_period(h), budget_deg_h=0.1)
    by = {str(c.spec): c for c in adv.candidates}
    k = coning_kernel(AlgorithmSpec.parse("rotvec:N=2"), [2 * np.pi * 20.0], h)[0]
    assert by["rotvec:N=2"].predicted_drift_deg_h == pytest.approx(
        abs(k) * 1e-3 * 180 / np.pi * 3600, rel=1e-9)
    ok = [c for c in adv.candidates if c.predicted_drift_deg_h <= 0.1]
    assert adv.recommended.ops_per_s == min(c.ops_per_s for c in ok)
    assert adv.recommended.predicted_drift_deg_h <= 0.1
    assert A.coning_content(fr, g, None)
    none = A.advise(fr, g, h, specs, lambda s, h: 1.0, budget_deg_h=1e-30)
    assert none.reason.startswith("none meets")
    with pytest.raises(ValueError, match="--max-ops"):
        A.advise(fr, g, h, specs, lambda s, h: 10.0, max_ops=1.0)


def test_candidates_follow_the_input_kind():
    inc = {s.algorithm for s in A.candidate_specs("increment")}
    rate = {s.algorithm for s in A.candidate_specs("rate")}
    assert inc == {"rotvec"} and "rotvec" not in rate and "rk4" in rate
    assert len(A.candidate_specs(None)) == len(A.candidate_specs("increment")) + len(
        A.candidate_specs("rate"))


def test_cli_on_a_coning_log(tmp_path, capsys):
    log = _log(tmp_path / "cone.csv", True)
    fig = tmp_path / "a.png"
    assert main(["advise", "--imu", str(log), "--increments", "--budget-deg-h", "0.05",
                 "--figure", str(fig), "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert rec["coning_detected"] is True
    cands = {c["spec"]: c for c in rec["candidates"]}
    best = cands[rec["recommended"]]
    assert best["predicted_drift_deg_h"] <= 0.05
    assert best["ops_per_s"] == min(c["ops_per_s"] for c in cands.values()
                                    if c["predicted_drift_deg_h"] <= 0.05)
    assert AlgorithmSpec.parse(rec["recommended"])  # the grammar of compare
    assert fig.stat().st_size > 10_000


def test_cli_without_coning_recommends_the_cheapest(tmp_path, capsys):
    log = _log(tmp_path / "planar.csv", False)
    assert main(["advise", "--imu", str(log), "--increments", "--figure",
                 str(tmp_path / "b.png")]) == 0
    out = capsys.readouterr().out
    assert "no coning content" in out
    assert "recommended   rotvec:N=6 (no coning content" in out


@pytest.mark.parametrize(("args", "msg"), [
    (["--psd", "{bad}", "--sample-rate-hz", "100"], "four values"),
    (["--psd", "{bad}"], "needs --sample-rate-hz"),
    (["--imu", "{missing}", "--increments"], "no such log file"),
    ([], "one of --imu LOG or --psd FILE"),
    (["--imu", "{log}"], "--rates or --increments"),
])
def test_cli_malformed_input(tmp_path, capsys, args, msg):
    bad = tmp_path / "bad.csv"
    bad.write_text("f_hz,im_gyz,im_gzx,im_gxy\n1,2,3\n")
    log = _log(tmp_path / "l.csv", True, n=200)
    subst = {"bad": bad, "missing": tmp_path / "none.csv", "log": log}
    with pytest.raises(SystemExit) as exc:
        main(["advise", *[a.format(**subst) for a in args], "--figure",
              str(tmp_path / "c.png")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and msg in err[0]
    assert not (tmp_path / "c.png").exists()
