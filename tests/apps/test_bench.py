"""`strapdown bench`: a line per benchmark as it starts, skipped peers listed with the reason
(the numbers themselves are reported, never asserted)."""

from __future__ import annotations

import sys

import pytest

from strapdown.apps import bench
from strapdown.cli import main

PEERS = {"ahrs": "ahrs-angularrate", "smsfusion": "smsfusion-strapdownins",
         "vqf": "vqf-offline-9d", "imufusion": "imufusion-ahrs"}


def _tiny(log=None) -> list[dict]:
    return bench.run_benchmarks(60, 20, 1, 0, 400, nav_samples=60, log=log)


def test_every_benchmark_announced_before_it_runs_and_missing_peers_skipped(monkeypatch):
    for package in PEERS:
        monkeypatch.setitem(sys.modules, package, None)  # import fails: not installed
    lines: list[str] = []
    recs = _tiny(lines.append)
    skipped = {r["name"]: r for r in recs if "skipped" in r}
    sculling = {"smsfusion-strapdownins-sculling", "sculling-ours-over-smsfusion"}
    assert set(skipped) == set(PEERS.values()) | sculling
    why = f"smsfusion not installed ({bench.PEER_EXTRA})"
    assert skipped["smsfusion-strapdownins-sculling"]["skipped"] == why
    assert skipped["sculling-ours-over-smsfusion"]["skipped"] == why
    for package, name in PEERS.items():
        assert skipped[name]["peer"] == package and skipped[name]["samples_per_s"] is None
        assert skipped[name]["skipped"] == f"{package} not installed ({bench.PEER_EXTRA})"
    assert lines[0].startswith("skipping ") and all(n in lines[0] for n in PEERS.values())
    ran = [r["name"] for r in recs if "skipped" not in r]
    total = len(ran)
    assert lines[1:] == [f"[{k}/{total}] {name}" for k, name in enumerate(ran, 1)]
    assert ran[0] == "numpy-single-pass" and "scipy-rotation-loop" in ran
    assert all(r["samples_per_s"] > 0 for r in recs if "skipped" not in r)


def test_installed_peers_run_and_nothing_is_said_without_a_log():
    pytest.importorskip("vqf")
    recs = _tiny()
    (vqf,) = [r for r in recs if r["name"] == "vqf-offline-9d"]
    assert "skipped" not in vqf and vqf["samples_per_s"] > 0


def test_cli_lists_skipped_peers_and_progress_only_when_asked(monkeypatch, capsys):
    recs = [{"name": "numpy-single-pass", "samples_per_s": 2e9, "ratio_to_numpy_pass": 1.0,
             "peer": None},
            {"name": "vqf-offline-9d", "samples_per_s": None, "ratio_to_numpy_pass": None,
             "peer": "vqf", "skipped": f"vqf not installed ({bench.PEER_EXTRA})"}]
    calls = []

    def fake(*args, nav_samples=None, log=None):
        calls.append(log)
        if log is not None:
            log("[1/1] numpy-single-pass")
        return recs

    monkeypatch.setattr(bench, "run_benchmarks", fake)
    assert main(["bench", "--progress"]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines()[-1].split() == ["vqf-offline-9d", "skipped:", "vqf", "not",
                                            "installed", "(pip", "install",
                                            "'strapdown[bench]')"]
    assert err == "[1/1] numpy-single-pass\n"
    assert main(["bench", "--no-progress"]) == 0
    assert capsys.readouterr().err == "" and calls[-1] is None


def test_sculling_ratio_is_ours_over_smsfusion():
    pytest.importorskip("smsfusion")
    recs = {r["name"]: r for r in _tiny()}
    ours = recs["nav-sculling-N2-conventional"]["samples_per_s"]
    sms = recs["smsfusion-strapdownins-sculling"]["samples_per_s"]
    assert recs["sculling-ours-over-smsfusion"]["ratio"] == pytest.approx(ours / sms, rel=1e-12)
    assert recs["smsfusion-strapdownins-sculling"]["peer"] == "smsfusion"


def test_cli_prints_the_sculling_ratio(monkeypatch, capsys):
    recs = [{"name": "sculling-ours-over-smsfusion", "ratio": 2500.0, "peer": "smsfusion"}]
    monkeypatch.setattr(bench, "run_benchmarks", lambda *a, nav_samples=None, log=None: recs)
    assert main(["bench", "--no-progress"]) == 0
    assert "ours/smsfusion throughput 2500×" in capsys.readouterr().out
