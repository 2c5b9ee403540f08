"""``strapdown benchmark-ahrs --suite openaxes``: the table's arithmetic on given errors
(medians over the recordings not suspect, ratios of the medians, counts, suspect rows
apart), the command on one shared motion (both links; skipped without the data), a
recording whose accelerometer our filter could not use, and the directory's default and
refusal."""

from __future__ import annotations

import csv
import math

import pytest

from conftest import OPENAXES
from strapdown.apps.ahrs_openaxes import FILTERS, rows, summary_table
from strapdown.cli import main
from strapdown.io.openaxes import ENV

_SHARED = OPENAXES


def _errors(total: float, incl: float) -> dict:
    return {"total_deg": total, "heading_deg": 0.0, "inclination_deg": incl}


def test_rows_take_medians_over_the_recordings_not_suspect():
    # ours causal, VQF, ours offline, offlineVQF: (total, inclination) per recording
    table = {"a": [(1.0, 0.5), (2.0, 1.0), (1.0, 0.1), (1.0, 0.2)],
             "b": [(3.0, 0.7), (1.0, 0.3), (2.0, 0.4), (4.0, 0.8)],
             "c": [(5.0, 0.9), (6.0, 0.2), (3.0, 0.3), (2.0, 0.6)],
             "circle-200-radius": [(40.0, 30.0), (50.0, 45.0), (40.0, 30.0), (50.0, 45.0)],
             "d": [(90.0, 80.0), (99.0, 90.0), (90.0, 80.0), (99.0, 90.0)]}
    results = {(n, f): _errors(*v) for n, vals in table.items()
               for f, v in zip(FILTERS, vals, strict=True)}
    suspects = {"a": None, "b": None, "c": None, "circle-200-radius": "named by the notes",
                "d": "rates correlate -0.07"}
    header, body = rows(results, suspects)
    assert header[0] == "recording" and len(header) == 1 + len(FILTERS) + 2
    assert [r[0] for r in body] == ["a", "b", "c", "**median (3)**",
                                    "median (4: the notes' split)", "**ours worse on**",
                                    "circle-200-radius (suspect)", "d (suspect)"]
    assert body[0][1:] == ["1.00 / 0.50", "2.00 / 1.00", "1.00 / 0.10", "1.00 / 0.20",
                           "0.50 / 0.50", "1.00 / 0.50"]
    # medians of a, b, c: ours causal 3 / 0.7, VQF 2 / 0.3, ours offline 2 / 0.3, offline 2 / 0.6
    assert body[3][1:] == ["3.00 / 0.70", "2.00 / 0.30", "2.00 / 0.30", "2.00 / 0.60",
                           "1.50 / 2.33", "1.00 / 0.50"]
    assert body[4][1] == "4.00 / 0.80"  # a, b, c and d: the notes name only circle-200-radius
    # ours worse: causal total on b, inclination on b, c; offline total on c, inclination on —
    assert body[5][-2:] == ["1 / 2 of 3", "1 / 0 of 3"]
    md = summary_table(results, suspects)
    assert md.count("\n") == 2 + len(body) and md.startswith("| recording |")


def test_a_missing_directory_says_where_the_recordings_are_looked_for(tmp_path, monkeypatch,
                                                                      capsys):
    monkeypatch.delenv(ENV, raising=False)
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "--suite", "openaxes", "--out", str(tmp_path), "--no-progress"])
    assert exc.value.code == 2
    assert f"export {ENV}=" in capsys.readouterr().err
    monkeypatch.setenv(ENV, str(tmp_path / "nothing"))
    with pytest.raises(SystemExit) as exc:
        main(["benchmark-ahrs", "--suite", "openaxes", "--out", str(tmp_path), "--no-progress"])
    assert "not a directory" in capsys.readouterr().err


@pytest.mark.skipif(not (_SHARED / "circle-250").is_dir(), reason=f"no OpenAXES data (${ENV})")
def test_one_shared_motion_through_the_command(tmp_path, monkeypatch, capsys):
    """circle-250, both links, the directory from $STRAPDOWN_OPENAXES: every filter gives
    finite errors, well below the suspect recordings' 20–60° (measured: 0.2–1.1°)."""
    pytest.importorskip("vqf")
    data = tmp_path / "data"
    data.mkdir()
    (data / "circle-250").symlink_to(_SHARED / "circle-250", target_is_directory=True)
    monkeypatch.setenv(ENV, str(data))
    main(["benchmark-ahrs", "--suite", "openaxes", "--out", str(tmp_path / "out"),
          "--no-progress"])
    out = capsys.readouterr().out
    with open(tmp_path / "out" / "errors.csv", encoding="utf-8") as f:
        long = list(csv.DictReader(f))
    names = ["circle-250-carpus", "circle-250-radius"]
    assert {(r["recording"], r["filter"]) for r in long} == {(n, f) for n in names
                                                             for f in FILTERS}
    for r in long:
        for key in ("total (°)", "heading (°)", "inclination (°)"):
            v = float(r[key])
            assert math.isfinite(v) and 0 < v < 5, (r, key)
        assert float(r["inclination (°)"]) <= float(r["total (°)"])
    table = [line for line in out.splitlines() if line.startswith("| ")]
    assert [c.split(" | ")[0] for c in table[1:]] == [
        "| circle-250-carpus", "| circle-250-radius", "| **median (2)**",
        "| **ours worse on**"]
    first = [c.strip() for c in table[1].strip("| ").split("|")]
    ours, vqf = (float(r["total (°)"]) for f in FILTERS[:2] for r in long
                 if r["recording"] == names[0] and r["filter"] == f)
    assert float(first[5].split(" / ")[0]) == pytest.approx(ours / vqf, abs=0.006)
    report = (tmp_path / "out" / "report.md").read_text(encoding="utf-8")
    assert report.count("circle-250") >= 4
    assert "Accelerometer not used" not in report  # both start still: gravity measured


@pytest.mark.skipif(not (_SHARED / "circle-200").is_dir(), reason=f"no OpenAXES data (${ENV})")
def test_a_recording_whose_accelerometer_goes_unused_is_marked():
    """circle-200-carpus starts in motion (not even its first quarter second is still),
    never rests before its end and reads 3.4 % below the nominal g: our filter skips its
    accelerometer updates and says so (``AccelerometerUnusedWarning``), which the
    evaluation records instead of letting it reach the terminal; circle-250-carpus starts
    still and is used, and so is circle-150-carpus (3.4 % low), whose window is not still
    but whose first quarter second is (``AhrsConfig.init_still_min_s``): gravity's norm is
    measured there."""
    from strapdown.apps.ahrs_openaxes import evaluate

    names = ["circle-200-carpus", "circle-250-carpus", "circle-150-carpus"]
    results, _ = evaluate(_SHARED, names=names, filters=("strapdown EKF",))
    assert results[("circle-200-carpus", "strapdown EKF")]["accelerometer_unused"] is True
    assert results[("circle-250-carpus", "strapdown EKF")]["accelerometer_unused"] is False
    assert results[("circle-150-carpus", "strapdown EKF")]["accelerometer_unused"] is False
