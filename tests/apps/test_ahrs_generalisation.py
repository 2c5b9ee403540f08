"""``strapdown benchmark-ahrs --suite generalisation``: our AHRS and VQF, causal and offline,
on short versions of every simulated scenario give finite errors and a table (no thresholds
on the ratios here: what they are is docs/reproductions.md's business)."""

from __future__ import annotations

import csv
import math

import pytest

from strapdown.apps.ahrs_generalisation import FILTERS, SHORT_S, trial
from strapdown.cli import main
from strapdown.truth.scenarios import SCENARIO_KINDS, record, suite


def test_short_suite_runs_every_filter_on_every_scenario(tmp_path, capsys):
    pytest.importorskip("vqf")
    main(["benchmark-ahrs", "--suite", "generalisation", "--short", "--seed", "0", "--out",
          str(tmp_path), "--no-progress"])
    out = capsys.readouterr().out
    names = [s.name for s in suite(0)]
    with open(tmp_path / "errors.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert {(r["scenario"], r["filter"]) for r in rows} == {(n, f) for n in names
                                                            for f in FILTERS}
    for r in rows:
        for key in ("total (°)", "heading (°)", "inclination (°)"):
            v = float(r[key])
            assert math.isfinite(v) and 0 <= v < 180, (r, key)
    table = [line for line in out.splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(names) + 1  # header, scenarios, mean
    for line, name in zip(table[1:], names, strict=False):
        cells = [c.strip() for c in line.strip("| ").split("|")]
        assert cells[0] == name
        ratios = [float(c) for c in cells[-2:]]
        assert all(math.isfinite(x) and x > 0 for x in ratios)
    assert (tmp_path / "report.md").read_text(encoding="utf-8").count("pendulum-") >= 3


def test_trial_scores_from_five_seconds_with_the_truth_as_reference():
    sc = suite(0)[0]
    rec = record(sc, 0, duration_s=SHORT_S)
    tr = trial(rec)
    assert tr.movement.sum() == (rec.t >= 5.0).sum() and not tr.movement[0]
    assert tr.q_ref is rec.q_n_b and tr.h == pytest.approx(1 / sc.sensors.rate_hz)
    assert {s.kind for s in suite(0)} == set(SCENARIO_KINDS)


def test_generalisation_takes_no_directory(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "somewhere", "--suite", "generalisation", "--no-progress"])
    assert exc.value.code == 2
    assert "takes no DIR" in capsys.readouterr().err


def test_alter_replaces_each_recording_before_the_filters_run():
    """``evaluate(alter=...)`` gets every recording with its index in the suite, and what it
    returns is what the filters see: the field scaled by 1000 (µT → nT) scores to within
    0.01° of the field as recorded (the filter uses the field's direction), while a field
    turned by 90° about the body's z axis does not."""
    import dataclasses

    import numpy as np

    from strapdown.apps.ahrs_generalisation import evaluate

    sc = [s for s in suite(0) if s.kind == "rests"]
    seen = []

    def scaled(rec, k):
        seen.append((rec.name, k))
        return dataclasses.replace(rec, mag=1000.0 * rec.mag)

    def turned(rec, k):
        return dataclasses.replace(rec, mag=rec.mag[:, [1, 0, 2]] * [-1.0, 1.0, 1.0])

    run = dict(seed=0, duration_s=SHORT_S, filters=("strapdown EKF",))
    base = evaluate(sc, **run)[("rests", "strapdown EKF")]["total_deg"]
    assert seen == [] and np.isfinite(base)
    assert evaluate(sc, alter=scaled, **run)[("rests", "strapdown EKF")]["total_deg"] == (
        pytest.approx(base, abs=0.01))
    assert seen == [("rests", 0)]
    assert evaluate(sc, alter=turned, **run)[("rests", "strapdown EKF")]["total_deg"] > 45.0


def test_config_reaches_our_filters_causal_and_offline():
    """``evaluate(config=...)`` runs our filters with it, causal and offline: without the
    magnetometer the rests' heading is the gyro's alone, the error differs from the
    default's; VQF is not ours and ignores it."""
    from strapdown.ahrs import AhrsConfig
    from strapdown.apps.ahrs_generalisation import evaluate

    sc = [s for s in suite(0) if s.kind == "rests"]
    run = dict(seed=0, duration_s=SHORT_S, filters=("strapdown EKF", "strapdown EKF offline"))
    base = evaluate(sc, **run)
    six = evaluate(sc, config=AhrsConfig(use_magnetometer=False), **run)
    for f in run["filters"]:
        assert six[("rests", f)]["total_deg"] != base[("rests", f)]["total_deg"]


def test_set_reaches_our_filters_only_and_is_named(tmp_path, capsys, monkeypatch):
    """``--set FIELD=VALUE``: every run of our filters gets the changed AhrsConfig (the peers
    get none), and the output and the report name the change."""
    import numpy as np

    import strapdown.apps.ahrs_generalisation as gen

    seen = []

    def fake(name, tr, *, config=None):
        seen.append((name, config))
        return np.tile([1.0, 0.0, 0.0, 0.0], (tr.t.size, 1))

    monkeypatch.setattr(gen, "run_filter", fake)
    monkeypatch.setattr(gen, "_available", lambda _f: None)
    main(["benchmark-ahrs", "--suite", "generalisation", "--short", "--seed", "0", "--out",
          str(tmp_path), "--no-progress", "--set", "heading_noise=0.05", "--set",
          "gating=false"])
    ours = [c for f, c in seen if f.startswith("strapdown")]
    assert len(ours) == 2 * len(suite(0)) and len(seen) == len(FILTERS) * len(suite(0))
    assert all(c.heading_noise == 0.05 and c.gating is False for c in ours)
    note = "their defaults but heading_noise=0.05, gating=False"
    assert note in capsys.readouterr().out
    assert note in (tmp_path / "report.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("item, said", [("heading_nois=0.05", "AhrsConfig field"),
                                        ("gating=maybe", "expected true or false"),
                                        ("heading_noise=abc", "--set heading_noise: expected a "
                                         "number, got 'abc'")])
def test_a_bad_set_is_refused_before_anything_runs(tmp_path, capsys, item, said):
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "--suite", "generalisation", "--out", str(tmp_path / "r"),
              "--no-progress", "--set", item])
    assert exc.value.code == 2
    assert said in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


def test_several_seeds_give_the_mean_errors_and_the_ratios_spread(tmp_path, capsys,
                                                                  monkeypatch):
    """``--seeds 3,5``: every scenario run once per seed (its own draw), the table's cells
    the mean over the seeds and its ratios the geometric mean with its standard error, the
    worst seed and the seeds lost; every seed's ratio in ``ratios.csv``. The filters are
    replaced by stubs whose errors are known: ours 2° then 0.5°, VQF 1°."""
    import numpy as np

    import strapdown.apps.ahrs_generalisation as gen

    calls = []

    def fake(name, tr, *, config=None):
        calls.append(name)
        return np.tile([1.0, 0.0, 0.0, 0.0], (tr.t.size, 1))

    seen_seeds = []

    def errors(q, q_ref, movement):
        seed = seen_seeds[-1]
        ours = calls[-1].startswith("strapdown")
        e = (2.0 if seed == 3 else 0.5) if ours else 1.0
        return {"total_deg": e, "heading_deg": e, "inclination_deg": e / 2}

    real_suite = gen.suite

    def suite(seed):
        seen_seeds.append(seed)
        return real_suite(seed)

    monkeypatch.setattr(gen, "run_filter", fake)
    monkeypatch.setattr(gen, "_available", lambda _f: None)
    monkeypatch.setattr(gen, "broad_errors", errors)
    monkeypatch.setattr(gen, "suite", suite)
    main(["benchmark-ahrs", "--suite", "generalisation", "--short", "--seeds", "3,5",
          "--out", str(tmp_path), "--no-progress"])
    out = capsys.readouterr().out
    assert seen_seeds[-2:] == [3, 5]
    names = [s.name for s in real_suite(0)]
    table = [line for line in out.splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(names)
    # ratios 2 and 0.5: geometric mean 1, logs ±ln 2, standard error ln 2 → +100 %
    cells = [c.strip() for c in table[1].strip("| ").split("|")]
    assert cells[1] == "1.25 / 0.62" and cells[2] == "1.00 / 0.50"
    assert cells[-1] == cells[-2] == "1.00 ±100% (2.00; 1/2)"
    assert "2 seeds" in out
    with open(tmp_path / "ratios.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert [(r["seed"], r["ours/VQF causal"]) for r in rows[:: len(names)]] == [
        ("3", "2.000"), ("5", "0.500")]
    assert (tmp_path / "ratios.png").stat().st_size > 0
    assert "Seeds 3, 5 (2)" in (tmp_path / "report.md").read_text(encoding="utf-8")


def test_ratio_cell_from_known_ratios():
    from strapdown.apps.ahrs_generalisation import ratio_cell

    # logs −ln 2, ln 2, 0: sample standard deviation ln 2, standard error ln 2 / √3
    assert ratio_cell([0.5, 2.0, 1.0]) == "1.00 ±49% (2.00; 1/3)"
    assert ratio_cell([0.8]) == "0.80 (0.80; 0/1)"
    assert ratio_cell([]) == "—"


@pytest.mark.parametrize("spec, said", [("0-", "FIRST-LAST or a comma list"),
                                        ("5-2", "FIRST <= LAST"),
                                        ("1,1", "distinct"),
                                        ("a", "FIRST-LAST or a comma list")])
def test_bad_seeds_are_refused(capsys, spec, said):
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "--suite", "generalisation", "--seeds", spec,
              "--no-progress"])
    assert exc.value.code == 2
    assert said in capsys.readouterr().err


def test_seed_and_seeds_exclude_each_other(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "--suite", "generalisation", "--seed", "1", "--seeds", "0-3"])
    assert exc.value.code == 2
    assert "not allowed with" in capsys.readouterr().err
