"""`strapdown reproduce sculling` on a reduced grid: every table and figure written, the
law and the duality as measured, smsfusion said to be skipped when it cannot be imported."""

from __future__ import annotations

import csv
import sys

import pytest

from strapdown.cli import main
from strapdown.reproduce import sculling
from strapdown.truth.trajectory import EarthSegment


@pytest.fixture
def reduced(monkeypatch):
    monkeypatch.setattr(sculling, "NS", (1, 2))
    monkeypatch.setattr(sculling, "SPP", (40, 30))
    monkeypatch.setattr(sculling, "DIGITS", 40)  # θ0 = 1e-20: the rate needs ~30 digits
    monkeypatch.setitem(sculling.REAL, "spp", 40)
    monkeypatch.setattr(sculling, "STATIC_S", 6000.0)  # more than one Schuler period
    monkeypatch.setattr(sculling, "FLIGHT", [EarthSegment(12.0), EarthSegment(12.0, 3.0),
                                             EarthSegment(12.0)])
    monkeypatch.setattr(sculling, "NAV_ALGORITHMS", (("conventional", 2),))
    monkeypatch.setitem(sys.modules, "smsfusion", None)  # import fails: the skip is reported


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_reduced_reproduction(tmp_path, reduced, capsys):
    assert main(["reproduce", "sculling", "--out", str(tmp_path), "--no-progress"]) == 0
    report = (tmp_path / "report.md").read_text()
    for name in ("sculling_law.png", "static.png", "flight.png", "duality.md",
                 "sculling_realistic.md", "flight_cosine.md", "coning_force.md"):
        assert (tmp_path / name).is_file(), name
        assert name in report
    assert "Skipped: smsfusion is not installed" in report
    law = _rows(tmp_path / "sculling_law.csv")
    assert len(law) == 4
    for row in law:
        assert float(row["fitted order"]) == pytest.approx(2 * int(row["N"]), abs=0.02)
        for key in ("measured/law Ωh=2π/40", "measured/law Ωh=2π/30"):
            assert abs(float(row[key]) - 1) < 0.01
    assert {row["verdict"] for row in _rows(tmp_path / "duality.csv")} == {"equal"}
    coning = _rows(tmp_path / "coning_force.csv")
    assert [row["N"] for row in coning] == ["1", "2"]
    assert coning[1]["at rest: single chain (m/s²)"].endswith(")")  # measured (law …)
    static = {row["case"]: row for row in _rows(tmp_path / "static.csv")}
    period = next(v for k, v in static.items() if "Schuler period" in k)
    assert abs(float(period["relative"])) < 1e-5
