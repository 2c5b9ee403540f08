"""``strapdown benchmark-ahrs --set FIELD=VALUE`` hands the BROAD and OpenAXES runs our filters'
changed AhrsConfig, and none without it (the generalisation suite's run is checked with its
filters in tests/apps/test_ahrs_generalisation.py)."""

from __future__ import annotations

import pytest

from strapdown.cli import main


@pytest.fixture
def given(monkeypatch, fake_benchmark):
    """The ``config`` of each BROAD (``fake_benchmark``, tests/conftest.py) or OpenAXES
    run, in order."""
    from strapdown.apps import ahrs_openaxes

    def openaxes(directory, out, *, names=None, config=None, progress=None):
        fake_benchmark.append({"config": config, "progress": progress})
        return {}, {}

    monkeypatch.setattr(ahrs_openaxes, "openaxes", openaxes)
    monkeypatch.setattr(ahrs_openaxes, "summary_table", lambda *_a: "")
    return fake_benchmark


@pytest.mark.parametrize("suite", [["d"], ["--suite", "openaxes", "d"]])
def test_set_reaches_the_run_and_is_said(given, capsys, suite):
    assert main(["benchmark-ahrs", *suite, "--no-progress", "--set", "mag_gate=6.63",
                 "--set", "acc_sample=point"]) == 0
    assert main(["benchmark-ahrs", *suite, "--no-progress"]) == 0
    changed, default = (c["config"] for c in given)
    assert (changed.mag_gate, changed.acc_sample) == (6.63, "point") and default is None
    out = capsys.readouterr().out
    assert out.count("our filters with their defaults but mag_gate=6.63, "
                     "acc_sample='point'") == 1
